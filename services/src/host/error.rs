//! How offering a device, publishing its state and processing its messages fail.

use iceoryx2::port::{LoanError, ReceiveError, SendError};
use limber_interfaces::prelude::*;
use thiserror::Error;

use crate::error::Iox2Error;
use crate::naming::NameError;

/// Offering a device failed ([`DeviceHost::new`](super::DeviceHost::new),
/// [`crate::DeviceSet::new`]).
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum HostError {
    /// The device name is invalid (a robot name made of other characters, ...).
    #[error(transparent)]
    Name(#[from] NameError),
    /// The device is of another interface than the host.
    #[error("device {device} is not {}", .expected.with_article())]
    WrongInterface {
        /// The device.
        device: String,
        /// The host's interface.
        expected: InterfaceKind,
    },
    /// A service of this device exists with other attributes or types: another driver
    /// (or another layout version) serves this name, or its clients still hold it.
    #[error("{device}: the name is held by an incompatible service ({source})")]
    Incompatible {
        /// The device.
        device: String,
        /// iceoryx2's error.
        #[source]
        source: Iox2Error,
    },
    /// A driver is already serving this device (its node is alive).
    #[error("{device}: already served by a running driver")]
    AlreadyServed {
        /// The device.
        device: String,
    },
    /// Group mode: the device's previous driver, a process of another member, died, and
    /// only its user (or root) may clean up after it (docs/guide/security.md).
    #[error(
        "{device}: its previous driver, a process of {owner}, died; in group mode only that user (or root) may clean up after it: run any limber command as that user (e.g. limber list), then start the driver again"
    )]
    DeadDriverOfAnotherMember {
        /// The device.
        device: String,
        /// The dead driver's user, `user NAME (uid N)`.
        owner: String,
    },
    /// iceoryx2 failed to create a service or port.
    #[error("{device}: cannot create the {channel} channel: {source}")]
    Transport {
        /// The device.
        device: String,
        /// The channel (`data`, `cmd`, `req`, `wake`, `notify`, `outcome`, `lease`, or
        /// `attributes`).
        channel: &'static str,
        /// iceoryx2's error.
        #[source]
        source: Iox2Error,
    },
}

/// Publishing the state failed ([`DeviceHost::publish`](super::DeviceHost::publish)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum PublishError {
    /// No shared-memory sample could be loaned (all held by slow readers: impossible with
    /// the QoS used, reported rather than hidden).
    #[error("cannot loan a state sample: {0}")]
    Loan(#[source] LoanError),
    /// The sample could not be delivered.
    #[error("cannot send the state sample: {0}")]
    Send(#[source] SendError),
}

/// Receiving commands or requests failed
/// ([`DeviceHost::process`](super::DeviceHost::process) and its variants).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum ProcessError {
    /// Receiving from shared memory failed.
    #[error("cannot receive: {0}")]
    Receive(#[source] ReceiveError),
    /// The state carrying a command's outcome could not be published.
    #[error("cannot publish the outcome: {0}")]
    Publish(#[from] PublishError),
}
