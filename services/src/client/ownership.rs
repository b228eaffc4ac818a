//! Who commands the device: the outcome of each of this client's commands (with the other
//! client involved, when another client preempted or held the device) and the control
//! lease (acquire, heartbeat, release, query).

use core::time::Duration;
use std::time::Instant;

use iceoryx2::prelude::*;
use limber_interfaces::control::{get_name, put_name};
use limber_interfaces::prelude::*;

use super::connection::LeaseSide;
use super::{Client, DriverStatus, LIVENESS_PERIOD, LeaseError, Ticket, WaitError};
use crate::error::Iox2Error;
use crate::naming::{Channel, attr};
use crate::qos;

/// The outcome of one of this client's commands.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Outcome {
    /// The command's sequence number (its [`super::Ticket::seq`]).
    pub seq: u64,
    /// What became of it.
    pub status: Status,
    /// The other client involved: the one whose command preempted it
    /// ([`Status::Preempted`]) or the one holding the device ([`Status::Leased`]); 0 if
    /// none.
    pub other_client: u64,
    /// When the driver published it (`CLOCK_MONOTONIC` ns; 0 for none yet); taken from
    /// the state that showed the command, that state's acquisition stamp.
    pub stamp_ns: u64,
    other_name: [u8; 32],
}

impl Outcome {
    pub(super) const NONE: Outcome = Outcome {
        seq: 0,
        status: Status::Ok,
        other_client: 0,
        stamp_ns: 0,
        other_name: [0; 32],
    };

    /// An outcome as a state showed it (`StateHeader::last_cmd`): no other client, the
    /// state's acquisition stamp.
    pub(super) fn shown(seq: u64, status: Status, stamp_ns: u64) -> Self {
        Outcome {
            seq,
            status,
            stamp_ns,
            ..Outcome::NONE
        }
    }

    pub(super) fn from_msg(m: &OutcomeMsg) -> Self {
        Outcome {
            seq: m.cmd_seq,
            status: m.status().unwrap_or_else(|e| {
                // A driver of another build: the outcome is not one we know.
                tracing::warn!(error = %e, "unknown outcome status");
                Status::InvalidArgument
            }),
            other_client: m.other_client,
            stamp_ns: m.stamp_ns,
            other_name: m.other_name,
        }
    }

    /// The other client's name, when it holds the device's lease (empty otherwise).
    pub fn other_name(&self) -> &str {
        get_name(&self.other_name).unwrap_or("")
    }
}

/// Who holds a device ([`Client::holder`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LeaseHolder {
    /// The holder's client id.
    pub client_id: u64,
    /// The holder's name.
    pub name: String,
    /// Its heartbeat timeout.
    pub timeout: Duration,
}

impl<I: Interface> Client<I> {
    /// Takes the device: until [`Client::release`] (or this client is dropped), other
    /// clients' commands, and their requests that change the device, are refused with
    /// [`Status::Leased`] naming `name`; readers are unaffected. The lease lives as long as
    /// this client renews it ([`Client::renew`], [`Client::keep_lease`]) at least every
    /// `heartbeat`, and as long as its process lives: otherwise the driver stops the device
    /// and frees it (the deadman). Acquiring a lease one holds sets a new heartbeat.
    pub fn acquire(&mut self, name: &str, heartbeat: Duration) -> Result<(), LeaseError> {
        let timeout_ns = u64::try_from(heartbeat.as_nanos()).unwrap_or(u64::MAX);
        let reply = self.lease_call(lease_op::ACQUIRE, timeout_ns, name)?;
        match reply.status() {
            Ok(Status::Ok) if reply.holder_client == self.client_id => {
                if let Some(l) = self.lease.as_mut() {
                    l.held = Some((heartbeat, Instant::now()));
                }
                Ok(())
            }
            Ok(Status::Leased) => Err(held_by(&reply)),
            Ok(s) => Err(LeaseError::Refused(s)),
            Err(e) => Err(LeaseError::Decode(e)),
        }
    }

    /// The heartbeat: tells the driver this holder is alive.
    pub fn renew(&mut self) -> Result<(), LeaseError> {
        let reply = self.lease_call(lease_op::RENEW, 0, "")?;
        match reply.status() {
            Ok(Status::Ok) if reply.holder_client == self.client_id => {
                if let Some((_, last)) = self.lease.as_mut().and_then(|l| l.held.as_mut()) {
                    *last = Instant::now();
                }
                Ok(())
            }
            Ok(Status::Ok) => {
                self.forget_lease();
                Err(LeaseError::Lost)
            }
            Ok(Status::Leased) => {
                self.forget_lease();
                Err(held_by(&reply))
            }
            Ok(s) => Err(LeaseError::Refused(s)),
            Err(e) => Err(LeaseError::Decode(e)),
        }
    }

    /// For a control loop: renews the lease when a third of its heartbeat has passed since
    /// the last renewal (returns whether it did); does nothing when no lease is held.
    pub fn keep_lease(&mut self) -> Result<bool, LeaseError> {
        match self.lease.as_ref().and_then(|l| l.held) {
            Some((hb, last)) if last.elapsed() >= hb / 3 => self.renew().map(|()| true),
            _ => Ok(false),
        }
    }

    /// Gives the device back (the motion in progress goes on). Releasing a lease not held
    /// is no error.
    pub fn release(&mut self) -> Result<(), LeaseError> {
        if self.lease.as_ref().and_then(|l| l.held).is_none() {
            return Ok(());
        }
        let reply = self.lease_call(lease_op::RELEASE, 0, "");
        self.forget_lease();
        let reply = reply?;
        match reply.status() {
            Ok(Status::Ok) => Ok(()),
            Ok(Status::Leased) => Err(held_by(&reply)),
            Ok(s) => Err(LeaseError::Refused(s)),
            Err(e) => Err(LeaseError::Decode(e)),
        }
    }

    /// Whether this client holds the device (as far as it knows: the driver may have ended
    /// a lease whose heartbeat was missed; [`Client::renew`] finds out).
    pub fn holds_lease(&self) -> bool {
        self.lease.as_ref().is_some_and(|l| l.held.is_some())
    }

    /// Who holds the device, if anybody (a request to the driver).
    pub fn holder(&mut self) -> Result<Option<LeaseHolder>, LeaseError> {
        let reply = self.lease_call(lease_op::QUERY, 0, "")?;
        if reply.holder_client == 0 {
            return Ok(None);
        }
        Ok(Some(LeaseHolder {
            client_id: reply.holder_client,
            name: get_name(&reply.holder_name)
                .map_err(LeaseError::Decode)?
                .to_string(),
            timeout: Duration::from_nanos(reply.timeout_ns),
        }))
    }

    fn forget_lease(&mut self) {
        if let Some(l) = self.lease.as_mut() {
            l.held = None;
        }
    }

    /// Opens the lease port on first use.
    pub(crate) fn lease_port(&mut self) -> Result<&mut LeaseSide, LeaseError> {
        if self.lease.is_none() {
            let layout = AttributeVerifier::new()
                .require(
                    &iceoryx2::service::attribute::AttributeKey::new(attr::LAYOUT.as_bytes())
                        .map_err(|e| LeaseError::Transport(e.into()))?,
                    &iceoryx2::service::attribute::AttributeValue::new(
                        limber_interfaces::LAYOUT_VERSION.to_string().as_bytes(),
                    )
                    .map_err(|e| LeaseError::Transport(e.into()))?,
                )
                .map_err(|e| LeaseError::Transport(e.into()))?;
            let port = self
                .ctx
                .node()
                .service_builder(&self.device.service_name(Channel::Lease))
                .request_response::<LeaseReq, LeaseReply>()
                .enable_fire_and_forget_requests(false)
                .open_with_attributes(&layout)
                .map_err(|e| {
                    let e = Iox2Error::from(e);
                    if e.is_missing_service() {
                        LeaseError::NoDriver
                    } else {
                        LeaseError::Transport(e)
                    }
                })?
                .client_builder()
                .create()
                .map_err(|e| LeaseError::Transport(e.into()))?;
            self.lease = Some(LeaseSide {
                port,
                seq: 0,
                held: None,
            });
        }
        Ok(self.lease.as_mut().expect("opened above"))
    }

    /// One lease request and its reply, within the request timeout.
    fn lease_call(
        &mut self,
        op: u32,
        timeout_ns: u64,
        name: &str,
    ) -> Result<LeaseReply, LeaseError> {
        let client_id = self.client_id;
        let node_id = self.ctx.node().id().value();
        let timeout = self.request_timeout;
        let side = self.lease_port()?;
        side.seq += 1;
        let mut req = LeaseReq {
            client_id,
            seq: side.seq,
            timeout_ns,
            op,
            ..LeaseReq::default()
        };
        req.set_node_id(node_id);
        put_name(&mut req.name, name);
        let pending = side
            .port
            .loan_uninit()
            .map_err(|e| LeaseError::Transport(e.into()))?
            .write_payload(req)
            .send()
            .map_err(|e| LeaseError::Transport(e.into()))?;
        if pending.number_of_server_connections() == 0 {
            return Err(LeaseError::NoDriver);
        }
        if self.wake_driver {
            self.wake_driver_with(qos::EVENT_REQUEST);
        }
        let deadline = Instant::now() + timeout;
        let mut next_check = Instant::now() + LIVENESS_PERIOD;
        loop {
            match pending.receive() {
                Ok(Some(resp)) => return Ok(*resp.payload()),
                Ok(None) => {}
                Err(e) => return Err(LeaseError::Transport(e.into())),
            }
            let now = Instant::now();
            if now >= deadline {
                return Err(LeaseError::Timeout(timeout));
            }
            if now >= next_check {
                next_check = now + LIVENESS_PERIOD;
                if self.driver_status() != DriverStatus::Alive {
                    return Err(LeaseError::DriverGone);
                }
            }
            self.pause(deadline.min(next_check))
                .map_err(LeaseError::Transport)?;
        }
    }
}

fn held_by(reply: &LeaseReply) -> LeaseError {
    LeaseError::Held {
        client_id: reply.holder_client,
        name: get_name(&reply.holder_name).unwrap_or("").to_string(),
    }
}

/// How long a client that goes waits for the driver to take the commands it sent
/// ([`Client::settle`]); a driver found dead is not waited for.
pub const SETTLE_ON_DROP: Duration = Duration::from_secs(2);

impl<I: Interface> Client<I> {
    /// Waits (at most `timeout`) until the driver has taken every command this client sent:
    /// the outcome of the last one arrived. A command is in the client's publisher until the
    /// driver reads it; a client that went at once could take it along (a short-lived
    /// program, `limber ... --no-wait`), so [`Drop`] settles first. Returns whether they
    /// were all taken (true at once when nothing is outstanding).
    pub fn settle(&mut self, timeout: Duration) -> Result<bool, WaitError> {
        if self.cmd_seq == 0 || self.max_seen_seq >= self.cmd_seq {
            return Ok(true);
        }
        let last = Ticket {
            seq: self.cmd_seq,
            receivers: 1,
        };
        match self.wait_outcome_detail(last, timeout) {
            Ok(_) => Ok(true),
            Err(WaitError::Timeout(_)) => Ok(false),
            Err(e) => Err(e),
        }
    }
}

impl<I: Interface> Drop for Client<I> {
    fn drop(&mut self) {
        if !self.driver_died.get() {
            match self.settle(SETTLE_ON_DROP) {
                Ok(true) => {}
                Ok(false) => tracing::warn!(device = %self.device, seq = self.cmd_seq,
                    "closing with commands the driver has not taken after {SETTLE_ON_DROP:?}"),
                Err(e) => tracing::debug!(device = %self.device, error = %e,
                    "closing: the driver's outcomes cannot be waited for"),
            }
        }
        if self.holds_lease()
            && let Err(e) = self.release()
        {
            tracing::warn!(device = %self.device, error = %e, "cannot release the lease");
        }
    }
}
