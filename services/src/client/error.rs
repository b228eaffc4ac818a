//! What can go wrong on the client side, one enum per operation: connecting
//! ([`ConnectError`]), sending a command ([`CommandError`]), a request ([`RequestError`])
//! and waiting for a state or an outcome ([`WaitError`]).

use core::time::Duration;

use limber_interfaces::prelude::*;
use thiserror::Error;

use crate::context::ContextError;
use crate::error::Iox2Error;
use crate::naming::NameError;

/// Connecting to a device failed.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum ConnectError {
    /// The device or domain name is invalid.
    #[error(transparent)]
    Name(#[from] NameError),
    /// Joining the domain failed.
    #[error(transparent)]
    Context(#[from] ContextError),
    /// No driver offers this device in this domain.
    #[error(
        "no driver offers {device} in domain {domain} (is the driver running? is LIMBER_DOMAIN the same?){elsewhere}"
    )]
    NoDriver {
        /// The device.
        device: String,
        /// The domain.
        domain: String,
        /// Empty, or a sentence naming the other users who have a domain of this name on
        /// this machine (a domain is its owner's alone: README, Security).
        elsewhere: String,
    },
    /// Every client slot of the device that this client may take is taken: `max` ordinary
    /// clients are connected (the driver's `max_clients`), and the `reserved` slots beyond
    /// them are kept for priority clients (taken too, when `priority`).
    #[error("{}", full_text(.device, *.max, *.reserved, *.priority))]
    Full {
        /// The device.
        device: String,
        /// The ordinary clients it admits.
        max: usize,
        /// The slots beyond them kept for priority clients.
        reserved: usize,
        /// Whether the refused client was a priority client (the reserved slots are taken).
        priority: bool,
    },
    /// The device is of another interface, or speaks another layout version.
    #[error("{device} is incompatible: {reason}")]
    Incompatible {
        /// The device.
        device: String,
        /// Why.
        #[source]
        reason: Incompatibility,
    },
    /// iceoryx2 may not open a service's files: another user's (a domain is its owner's
    /// alone), or in group mode a member's file that is still not opened to the group
    /// (after the bounded wait of [`crate::Client::connect`]).
    #[error(
        "{device}: cannot open the {channel} channel: its files are not open to you ({source}); {hint}"
    )]
    Permission {
        /// The device.
        device: String,
        /// The channel.
        channel: &'static str,
        /// What to do.
        hint: String,
        /// iceoryx2's error.
        #[source]
        source: Iox2Error,
    },
    /// iceoryx2 failed to open a service or create a port.
    #[error("{device}: cannot open the {channel} channel: {source}")]
    Transport {
        /// The device.
        device: String,
        /// The channel.
        channel: &'static str,
        /// iceoryx2's error.
        #[source]
        source: Iox2Error,
    },
}

/// The sentence of [`ConnectError::Full`].
fn full_text(device: &str, max: usize, reserved: usize, priority: bool) -> String {
    let clients = if max == 1 { "client" } else { "clients" };
    let taken = if priority {
        format!(
            "its driver admits {max} {clients} and {reserved} priority clients at once, and all are connected"
        )
    } else {
        format!(
            "its driver admits {max} {clients} at once and all are connected ({reserved} more slots are kept for priority clients)"
        )
    };
    format!(
        "{device} is full: {taken}; end a client you do not need (`limber list` counts each \
         device's processes), restart the driver with a larger --max-clients (max_clients in \
         its configuration), or connect the robot's control program as a priority client \
         (LIMBER_PRIORITY=1, or --priority)"
    )
}

/// Why a device is incompatible with a client ([`ConnectError::Incompatible`]).
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum Incompatibility {
    /// The device is of another interface than the client's.
    #[error("it is {} device, not {}", .actual.with_article(), .expected.with_article())]
    Interface {
        /// The device's interface.
        actual: InterfaceKind,
        /// The client's interface.
        expected: InterfaceKind,
    },
    /// A service of the device has other attributes, types or qualities of service
    /// (another layout version).
    #[error("{channel}: {source} (another layout version?)")]
    Layout {
        /// The channel.
        channel: &'static str,
        /// iceoryx2's error.
        #[source]
        source: Iox2Error,
    },
}

/// Sending a command failed; nothing was sent.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum CommandError {
    /// A value is invalid (NaN, bad joint index, too many values, zero vector).
    #[error("invalid command: {0}")]
    Invalid(#[from] ValueError),
    /// No driver receives commands for this device (not started, or gone and cleaned up).
    #[error("no driver receives commands")]
    NoDriver,
    /// iceoryx2 failed to loan or send the command sample.
    #[error("cannot send the command: {0}")]
    Transport(#[source] Iox2Error),
}

/// Sending a joint trajectory failed ([`Client::follow_trajectory`](super::Client)).
#[derive(Debug, Clone, PartialEq, Error)]
pub enum TrajectorySendError {
    /// The trajectory is invalid; nothing was sent.
    #[error("invalid trajectory: {0}")]
    Invalid(#[from] TrajectoryError),
    /// A command of its upload could not be sent (the driver refuses the `TRAJ` of an
    /// incomplete upload).
    #[error(transparent)]
    Send(#[from] CommandError),
}

/// A request failed.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum RequestError {
    /// The driver refused (NACK) and said why.
    #[error("refused: {0}")]
    Nack(Status),
    /// No reply within the timeout (the driver is alive but did not answer).
    #[error("no reply within {0:?}")]
    Timeout(Duration),
    /// No driver serves requests for this device.
    #[error("no driver serves requests")]
    NoDriver,
    /// The driver died while the request was pending.
    #[error("the driver is gone")]
    DriverGone,
    /// A value is invalid; nothing was sent.
    #[error("invalid request: {0}")]
    Invalid(#[from] ValueError),
    /// The reply could not be decoded (driver of another layout, or corrupted).
    #[error("undecodable reply: {0}")]
    Decode(#[source] DecodeError),
    /// The reply was an ACK of an unexpected kind.
    #[error("unexpected reply")]
    Unexpected,
    /// iceoryx2 failed (loaning, sending, receiving, or waiting for the reply).
    #[error("request transport failed: {0}")]
    Transport(#[source] Iox2Error),
}

/// Waiting for a state or an outcome failed.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum WaitError {
    /// Nothing arrived within the timeout (the driver is alive).
    #[error("nothing within {0:?}")]
    Timeout(Duration),
    /// The driver died (or was never there).
    #[error("the driver is gone")]
    DriverGone,
    /// The outcome of this command was published but overwritten before it was read
    /// (a later command of this client has been applied since).
    #[error("outcome missed; a later command (seq {newer_seq}) was applied since")]
    Missed {
        /// The newer command's sequence number.
        newer_seq: u64,
    },
    /// iceoryx2 failed (receiving states, or waiting for a notification).
    #[error("receiving failed: {0}")]
    Transport(#[source] Iox2Error),
}

/// A lease operation failed ([`super::Client::acquire`], `renew`, `release`, `holder`).
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum LeaseError {
    /// Another client holds the device.
    #[error("held by another client ({})", if .name.is_empty() { "unnamed" } else { .name.as_str() })]
    Held {
        /// The holder's client id.
        client_id: u64,
        /// The holder's name.
        name: String,
    },
    /// The lease ended (its heartbeat was missed): the driver stopped the device.
    #[error("the lease was lost (heartbeat missed)")]
    Lost,
    /// The driver refused the request (e.g. a heartbeat out of range).
    #[error("refused: {0}")]
    Refused(Status),
    /// No reply within the request timeout.
    #[error("no reply within {0:?}")]
    Timeout(Duration),
    /// No driver serves the device's lease channel.
    #[error("no driver serves leases")]
    NoDriver,
    /// The driver is gone.
    #[error("the driver is gone")]
    DriverGone,
    /// The reply does not decode.
    #[error("undecodable reply: {0}")]
    Decode(#[source] DecodeError),
    /// iceoryx2 failed.
    #[error("lease transport failed: {0}")]
    Transport(#[source] Iox2Error),
}
