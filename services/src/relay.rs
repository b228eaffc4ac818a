//! Relaying: the raw side of a [`DeviceHost`] and of a [`Client`], for a bridge that carries
//! a device's channels to another domain (e.g. over a network) without decoding them.
//!
//! A bridge on the driver's side uses a [`Client`] to take every state sample and the
//! outcomes of the commands it relayed (on its process's own stream,
//! [`Client::relay_own_outcomes`]; a recorder takes every client's,
//! [`Client::relay_outcomes`]) and to send commands and requests whose metadata it fills
//! in itself; a bridge on the far side hosts the device with a [`DeviceHost`] whose state and
//! outcomes come from the relay and whose commands and requests go to it. The messages are
//! the fixed layouts of the interfaces, unchanged.

use iceoryx2::active_request::ActiveRequest;
use iceoryx2::pending_response::PendingResponse;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::prelude::*;
use limber_interfaces::prelude::*;
use thiserror::Error;

use crate::client::{Client, CommandError, LeaseError, RequestError};
use crate::error::Iox2Error;
use crate::host::{DeviceHost, ProcessError, PublishError};
use crate::naming::DRIVER_NODE_PREFIX;
use crate::qos;

/// A request taken from a hosted device's clients, to be answered later
/// ([`DeviceHost::relay_take_request`], [`DeviceHost::relay_answer`]). Dropping it without
/// an answer leaves the client to its timeout.
pub struct RelayedRequest<I: Interface> {
    active: ActiveRequest<ipc::Service, I::ReqMsg, (), I::ReplyMsg, ()>,
}

impl<I: Interface> core::fmt::Debug for RelayedRequest<I> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("RelayedRequest")
            .field("request", self.active.payload())
            .finish()
    }
}

impl<I: Interface> RelayedRequest<I> {
    /// The request as the client sent it.
    pub fn message(&self) -> &I::ReqMsg {
        self.active.payload()
    }
}

/// Answering a relayed request failed ([`DeviceHost::relay_answer`]).
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum AnswerError {
    /// The reply could not be delivered (the client gave up or died).
    #[error("cannot deliver the reply: {0}")]
    Undelivered(#[source] Iox2Error),
}

impl<I: Interface> DeviceHost<I> {
    /// Publishes `state` exactly as given (header included: sequence number, last command,
    /// flags and stamp are the relayed device's) and notifies the clients.
    pub fn relay_publish(&mut self, state: &I::Data) -> Result<(), PublishError> {
        *self.state_mut() = *state;
        self.publish_verbatim()
    }

    /// Takes the pending commands without decoding them, fairly across clients as the
    /// driver does ([`DeviceHost::process_commands`]: a flooding client delays no
    /// other client's command by more than a round, and one call takes at most
    /// [`CMD_BUFFER`](crate::qos::CMD_BUFFER)).
    pub fn relay_commands(
        &mut self,
        mut each: impl FnMut(&I::CmdMsg),
    ) -> Result<usize, ProcessError> {
        self.take_commands_fairly(|_, sample, _| {
            each(&sample);
            Ok(true)
        })
    }

    /// Takes one pending request, to answer with [`DeviceHost::relay_answer`].
    pub fn relay_take_request(&mut self) -> Result<Option<RelayedRequest<I>>, ProcessError> {
        match self.server_port().receive() {
            Ok(Some(active)) => Ok(Some(RelayedRequest { active })),
            Ok(None) => Ok(None),
            Err(e) => Err(ProcessError::Receive(e)),
        }
    }

    /// Answers a relayed request with `reply` as given, and wakes the clients.
    pub fn relay_answer(
        &mut self,
        req: RelayedRequest<I>,
        reply: &I::ReplyMsg,
    ) -> Result<(), AnswerError> {
        let sent = match req.active.loan_uninit() {
            Ok(loan) => loan.write_payload(*reply).send().map_err(Iox2Error::from),
            Err(e) => Err(e.into()),
        };
        self.notify_clients_of(qos::EVENT_REPLY);
        sent.map_err(AnswerError::Undelivered)
    }

    /// Publishes one outcome exactly as given but for its stamp (its `client_id` picks
    /// the client: on that client's stream, and to every watcher), and wakes the clients.
    pub fn relay_outcome(&mut self, msg: &OutcomeMsg) -> Result<(), PublishError> {
        self.relay_outcome_message(msg)?;
        self.notify_clients_of(qos::EVENT_STATE);
        Ok(())
    }

    /// Connects the state and outcome publishers to clients that came since the last call
    /// and consumes the clients' wake-ups (a relaying host polls instead).
    pub fn relay_housekeeping(&mut self) {
        if let Err(e) = self.data_port().update_connections() {
            tracing::debug!(device = %self.device(), error = %e, "cannot connect new clients");
        }
        if let Err(e) = self.update_outcome_connections() {
            tracing::debug!(device = %self.device(), error = %e, "cannot connect new clients");
        }
        self.consume_wakeups();
    }
}

/// A request sent by [`Client::relay_request`], waiting for its reply.
pub struct PendingRelay<I: Interface> {
    pending: PendingResponse<ipc::Service, I::ReqMsg, (), I::ReplyMsg, ()>,
}

impl<I: Interface> core::fmt::Debug for PendingRelay<I> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("PendingRelay").finish_non_exhaustive()
    }
}

/// The reply of `pending` if it arrived, `Ok(None)` while the driver may still answer;
/// `Err(None)` once the driver left without answering, `Err(Some(_))` if receiving failed.
fn poll_reply<Q, R>(
    pending: &PendingResponse<ipc::Service, Q, (), R, ()>,
) -> Result<Option<R>, Option<Iox2Error>>
where
    Q: core::fmt::Debug + ZeroCopySend,
    R: core::fmt::Debug + ZeroCopySend + Copy,
{
    match pending.receive() {
        Ok(Some(r)) => return Ok(Some(*r.payload())),
        Ok(None) => {}
        Err(e) => return Err(Some(e.into())),
    }
    if pending.is_connected() {
        return Ok(None);
    }
    // The driver may have answered and closed in between: look once more.
    match pending.receive() {
        Ok(Some(r)) => Ok(Some(*r.payload())),
        Ok(None) => Err(None),
        Err(e) => Err(Some(e.into())),
    }
}

impl<I: Interface> PendingRelay<I> {
    /// The reply, if it arrived; [`RequestError::DriverGone`] once the driver left
    /// without answering.
    pub fn try_reply(&self) -> Result<Option<I::ReplyMsg>, RequestError> {
        match poll_reply(&self.pending) {
            Ok(r) => Ok(r),
            Err(None) => Err(RequestError::DriverGone),
            Err(Some(e)) => Err(RequestError::Transport(e)),
        }
    }
}

impl<I: Interface> Client<I> {
    /// Sends `cmd` exactly as given (its metadata is the caller's) and wakes the driver;
    /// returns how many drivers received it.
    pub fn relay_send(&mut self, cmd: &I::CmdMsg) -> Result<usize, CommandError> {
        let loan = self
            .commands
            .loan_uninit()
            .map_err(|e| CommandError::Transport(e.into()))?;
        let receivers = loan
            .write_payload(*cmd)
            .send()
            .map_err(|e| CommandError::Transport(e.into()))?;
        self.wake_driver_with(qos::EVENT_COMMAND);
        if receivers == 0 {
            return Err(CommandError::NoDriver);
        }
        Ok(receivers)
    }

    /// Sends `req` exactly as given and returns at once; poll the reply with
    /// [`PendingRelay::try_reply`].
    pub fn relay_request(&mut self, req: &I::ReqMsg) -> Result<PendingRelay<I>, RequestError> {
        let loan = self
            .requests
            .loan_uninit()
            .map_err(|e| RequestError::Transport(e.into()))?;
        let pending = loan
            .write_payload(*req)
            .send()
            .map_err(|e| RequestError::Transport(e.into()))?;
        if pending.number_of_server_connections() == 0 {
            return Err(RequestError::NoDriver);
        }
        self.wake_driver_with(qos::EVENT_REQUEST);
        Ok(PendingRelay { pending })
    }

    /// Takes every state sample that arrived, oldest first.
    pub fn relay_states(&mut self, mut each: impl FnMut(&I::Data)) -> Result<usize, Iox2Error> {
        let mut n = 0;
        loop {
            match self.states.receive() {
                Ok(Some(s)) => {
                    each(&s);
                    n += 1;
                }
                Ok(None) => return Ok(n),
                Err(e) => return Err(e.into()),
            }
        }
    }

    /// Opens this process's outcome stream (if it is not open, or its driver no longer
    /// keeps it: a driver that started again), on which the driver sends the outcomes of
    /// every client id of this process that has no stream of its own: those of the
    /// commands relayed with [`Client::relay_send`] under ids of
    /// [`crate::Context::new_client_id`]. Only those commands fill it: another client
    /// flooding the device cannot push their outcomes out. Looks at most once per
    /// [`crate::client::LIVENESS_PERIOD`] unless `now`; returns whether it is open.
    pub fn relay_open_stream(&mut self, now: bool) -> bool {
        let t = std::time::Instant::now();
        let open = self.told.process.is_some();
        if open
            && !now
            && self
                .told
                .process_checked
                .is_some_and(|c| t < c + crate::client::LIVENESS_PERIOD)
        {
            return true;
        }
        self.told.process_checked = Some(t);
        self.keep_process_stream()
    }

    /// Takes the outcomes of the commands this process relayed that arrived on its outcome
    /// stream ([`Client::relay_open_stream`], opened or opened again here), oldest first.
    pub fn relay_own_outcomes(
        &mut self,
        mut each: impl FnMut(&OutcomeMsg),
    ) -> Result<usize, Iox2Error> {
        self.relay_open_stream(false);
        let Some(stream) = &self.told.process else {
            return Ok(0);
        };
        let mine = self.client_id();
        let pid = crate::context::process_of(mine);
        let mut n = 0;
        loop {
            match stream.receive() {
                Ok(Some(r)) => {
                    let m: &OutcomeMsg = r.payload();
                    // Only this process's come on it; a driver of another kind may say
                    // otherwise.
                    if crate::context::process_of(m.client_id) == pid && m.client_id != mine {
                        each(m);
                        n += 1;
                    }
                }
                Ok(None) => return Ok(n),
                Err(e) => return Err(e.into()),
            }
        }
    }

    /// Takes every outcome that arrived, of every client, since [`Client::watch_outcomes`]
    /// (called by the first call if not before).
    pub fn relay_outcomes(
        &mut self,
        mut each: impl FnMut(&OutcomeMsg),
    ) -> Result<usize, Iox2Error> {
        self.watch_outcomes()?;
        let Some(sub) = &self.outcome_sub else {
            return Ok(0);
        };
        let mut n = 0;
        loop {
            match sub.receive() {
                Ok(Some(s)) => {
                    each(&s);
                    n += 1;
                }
                Ok(None) => return Ok(n),
                Err(e) => return Err(e.into()),
            }
        }
    }

    /// A listener of its own on the device's notifications (the driver published a state
    /// or an outcome, or answered a request), for a relay's WaitSet: the relay sleeps until
    /// the driver has something for it instead of polling.
    pub fn relay_listener(&self) -> Result<Listener<ipc::Service>, Iox2Error> {
        Ok(self.notify_svc.listener_builder().create()?)
    }

    /// Whether the device's driver process is alive. Unlike [`Client::driver_status`], a
    /// dead driver's resources are not cleaned up on the way (that can take seconds): a
    /// bridge must learn of the death at once.
    pub fn relay_driver_alive(&self) -> bool {
        use iceoryx2::node::NodeView;
        use iceoryx2::service::port_factory::PortFactory;
        let (mut alive, mut dead, mut unknown) = (false, false, false);
        let is_driver = |d: &Option<iceoryx2::node::NodeDetails>| {
            d.as_ref()
                .is_some_and(|d| d.name().as_str().starts_with(DRIVER_NODE_PREFIX))
        };
        if let Err(e) = self.data_svc.nodes(|n| {
            match &n {
                NodeState::Alive(v) if is_driver(v.details()) => alive = true,
                NodeState::Dead(v) if is_driver(v.details()) => dead = true,
                NodeState::Inaccessible(_) | NodeState::Undefined(_) => unknown = true,
                _ => {}
            }
            CallbackProgression::Continue
        }) {
            // Not known to be dead: asked again at the next check.
            tracing::warn!(device = %self.device, error = %e, "cannot list the nodes of a device");
            return true;
        }
        // A node whose state cannot be read (yet) may be the driver: not known to be dead.
        alive || (unknown && !dead)
    }
}

/// A lease request taken from a hosted device's clients, to be answered later
/// ([`DeviceHost::relay_take_lease`], [`DeviceHost::relay_answer_lease`]).
pub struct RelayedLease {
    active: ActiveRequest<ipc::Service, LeaseReq, (), LeaseReply, ()>,
}

impl core::fmt::Debug for RelayedLease {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("RelayedLease")
            .field("request", self.active.payload())
            .finish()
    }
}

impl RelayedLease {
    /// The lease request as the client sent it.
    pub fn message(&self) -> &LeaseReq {
        self.active.payload()
    }
}

impl<I: Interface> DeviceHost<I> {
    /// Takes one pending lease request, to answer with [`DeviceHost::relay_answer_lease`]
    /// (a relaying host keeps no lease of its own: the relayed device's driver does).
    pub fn relay_take_lease(&mut self) -> Result<Option<RelayedLease>, ProcessError> {
        match self.lease_port().receive() {
            Ok(Some(active)) => Ok(Some(RelayedLease { active })),
            Ok(None) => Ok(None),
            Err(e) => Err(ProcessError::Receive(e)),
        }
    }

    /// Answers a relayed lease request with `reply` as given, and wakes the clients.
    pub fn relay_answer_lease(
        &mut self,
        req: RelayedLease,
        reply: &LeaseReply,
    ) -> Result<(), AnswerError> {
        let sent = match req.active.loan_uninit() {
            Ok(loan) => loan.write_payload(*reply).send().map_err(Iox2Error::from),
            Err(e) => Err(e.into()),
        };
        self.notify_clients_of(qos::EVENT_REPLY);
        sent.map_err(AnswerError::Undelivered)
    }
}

/// A lease request sent by [`Client::relay_lease`], waiting for its reply.
pub struct PendingLease {
    pending: PendingResponse<ipc::Service, LeaseReq, (), LeaseReply, ()>,
}

impl core::fmt::Debug for PendingLease {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("PendingLease").finish_non_exhaustive()
    }
}

impl PendingLease {
    /// The reply, if it arrived; [`LeaseError::NoDriver`] once the driver left without
    /// answering.
    pub fn try_reply(&self) -> Result<Option<LeaseReply>, LeaseError> {
        match poll_reply(&self.pending) {
            Ok(r) => Ok(r),
            Err(None) => Err(LeaseError::NoDriver),
            Err(Some(e)) => Err(LeaseError::Transport(e)),
        }
    }
}

impl<I: Interface> Client<I> {
    /// Sends lease request `req` as given, but as this client's node (the driver watches
    /// the holder's node: a relayed holder's is the relay's), and returns at once. The
    /// lease lives as long as the relayed holder's renewals keep arriving in time.
    pub fn relay_lease(&mut self, req: &LeaseReq) -> Result<PendingLease, LeaseError> {
        let mut req = *req;
        req.set_node_id(self.context().node().id().value());
        let side = self.lease_port()?;
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
        self.wake_driver_with(qos::EVENT_REQUEST);
        Ok(PendingLease { pending })
    }
}
