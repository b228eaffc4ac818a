//! The lease channel and the deadman around the arbiter's lease state machine: lease
//! requests answered, the holder's node looked up when the arbiter asks, the device stopped
//! when a lease ends.

use iceoryx2::node::NodeView;
use iceoryx2::prelude::*;
use limber_interfaces::prelude::*;

use super::arbiter::{Deadman, LeaseEvent};
use super::{DeviceHandler, DeviceHost, Holder, ProcessError, PublishError};
use crate::context::monotonic_ns;
use crate::error::Iox2Error;
use crate::qos;

impl<I: Interface> DeviceHost<I> {
    /// The deadman: ends the lease and stops the device (with [`DeviceHandler::stop`]) when
    /// its holder's node died or its heartbeat is overdue. [`DeviceHost::process`] calls
    /// it; a driver that processes only when clients wake it calls it on its ticks too.
    /// Cheap unless a lease is held (then the holder's node is looked up at most every
    /// [`HOLDER_CHECK_NS`](super::HOLDER_CHECK_NS)).
    pub fn check_lease<H: DeviceHandler<I>>(
        &mut self,
        handler: &mut H,
    ) -> Result<(), ProcessError> {
        let (ended, why) = match self.arbiter.deadman(monotonic_ns()) {
            Deadman::Fine => return Ok(()),
            Deadman::Expired(l) => (l, "it missed its heartbeat"),
            Deadman::CheckNode(node) => {
                if !self.holder_node_gone(node) {
                    return Ok(());
                }
                match self.arbiter.holder_died(node) {
                    Some(l) => (l, "its process died"),
                    None => return Ok(()),
                }
            }
        };
        self.lease_ended = Some((ended, why));
        self.deadman_stop(handler, &ended, why)
    }

    /// Stops the device whose lease ended, says so, and publishes the state.
    fn deadman_stop<H: DeviceHandler<I>>(
        &mut self,
        handler: &mut H,
        ended: &Holder,
        why: &str,
    ) -> Result<(), ProcessError> {
        let status = handler.stop(&mut self.state);
        tracing::warn!(device = %self.device, holder = ended.name(), client = ended.client_id,
            stop = %status, "lease ended because {why}: device stopped");
        self.stats.deadman_stops += 1;
        self.publish()?;
        self.end_motions(MotionResult::Stopped, Status::Leased);
        Ok(())
    }

    /// The lease as this device holds it, for the other devices that share it
    /// ([`DeviceSet::share_lease`](crate::DeviceSet::share_lease)).
    pub(crate) fn shared_lease(&self) -> Option<Holder> {
        self.arbiter.shared()
    }

    /// The lease the deadman ended on this device since the last call, and why: the other
    /// devices that shared it must stop too ([`DeviceHost::stop_with_group`]).
    pub(crate) fn take_lease_ended(&mut self) -> Option<(Holder, &'static str)> {
        self.lease_ended.take()
    }

    /// Joins the lease of the group this device was just put in: a lease that ended on
    /// this device before is forgotten (the group's lease is the one that counts now), and
    /// the group's is followed ([`DeviceHost::follow_lease`]).
    pub(crate) fn join_lease(&mut self, lease: Option<Holder>) -> Result<(), PublishError> {
        self.lease_ended = None;
        self.follow_lease(lease)
    }

    /// Takes the lease of its group, changed on another device of it (acquired, renewed,
    /// released); publishes the state when the holder changed, so the `LEASED` flag follows
    /// at once.
    pub(crate) fn follow_lease(&mut self, lease: Option<Holder>) -> Result<(), PublishError> {
        if self.arbiter.shared() == lease {
            return Ok(());
        }
        if self.arbiter.share(lease) {
            self.publish()?;
        }
        Ok(())
    }

    /// The deadman ended the group's lease on another device (`ended`, because `why`): this
    /// device stops too ([`DeviceHandler::stop`]) and publishes its state.
    pub(crate) fn stop_with_group<H: DeviceHandler<I>>(
        &mut self,
        handler: &mut H,
        ended: &Holder,
        why: &str,
    ) -> Result<(), ProcessError> {
        self.arbiter.ended_elsewhere();
        self.deadman_stop(handler, ended, why)
    }

    /// True when the node `id` is dead or no longer attached to the lease channel.
    fn holder_node_gone(&self, id: u128) -> bool {
        use iceoryx2::service::port_factory::PortFactory;
        let (mut alive, mut dead) = (false, false);
        if let Err(e) = self.lease_svc.nodes(|n| {
            match &n {
                NodeState::Alive(v) if v.id().value() == id => alive = true,
                NodeState::Dead(v) if v.id().value() == id => dead = true,
                NodeState::Inaccessible(n) | NodeState::Undefined(n) if n.value() == id => {
                    alive = true
                }
                _ => {}
            }
            CallbackProgression::Continue
        }) {
            // Not known to be dead: the heartbeat timeout still ends the lease.
            tracing::warn!(device = %self.device, error = %e, "cannot list the holder's node");
            return false;
        }
        dead || !alive
    }

    /// Answers every pending lease request (acquire, renew, release, query).
    pub(super) fn process_leases(&mut self) -> Result<usize, ProcessError> {
        let mut n = 0;
        let mut changed = false;
        loop {
            let active = match self.lease_server.receive() {
                Ok(Some(a)) => a,
                Ok(None) => break,
                Err(e) => return Err(ProcessError::Receive(e)),
            };
            let req: LeaseReq = *active.payload();
            // The holder is the node the transport names, not the one the request carries.
            let node = self
                .lease_senders
                .client(active.header().client_id().value(), &self.lease_svc);
            let answer = self.arbiter.lease_request(&req, node, monotonic_ns());
            changed |= answer.holder_changed;
            match answer.event {
                Some(LeaseEvent::Acquired) => {
                    tracing::info!(device = %self.device,
                        holder = self.arbiter.holder().map_or("", |h| h.name()),
                        client = req.client_id, "lease acquired");
                }
                Some(LeaseEvent::Released) => {
                    tracing::info!(device = %self.device, client = req.client_id, "lease released");
                }
                None => {}
            }
            let reply = self.arbiter.lease_reply(&req, answer.status);
            let sent = match active.loan_uninit() {
                Ok(loan) => loan.write_payload(reply).send().map_err(Iox2Error::from),
                Err(e) => Err(e.into()),
            };
            if let Err(e) = sent {
                self.stats.undelivered_replies += 1;
                tracing::debug!(device = %self.device, client = req.client_id, error = %e,
                    "lease reply not delivered");
            }
            self.stats.lease_requests += 1;
            n += 1;
        }
        if n > 0 {
            self.notify_clients(qos::EVENT_REPLY);
        }
        // The LEASED flag of the state follows the lease at once.
        if changed {
            self.publish()?;
        }
        Ok(n)
    }
}
