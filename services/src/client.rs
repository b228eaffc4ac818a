//! The client side, in the spirit of Player's proxies: [`Client<I>`] for any interface, with
//! typed conveniences for each ([`ActArrayClient`], [`LimbClient`], [`GripperClient`]).

use core::time::Duration;
use std::time::Instant;

use iceoryx2::node::NodeView;
use iceoryx2::port::client::Client as IoxClient;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use iceoryx2::sample::Sample;
use iceoryx2::service::attribute::{AttributeKey, AttributeValue};
use iceoryx2::service::port_factory::PortFactory;
use limber_interfaces::prelude::*;
use thiserror::Error;

use crate::context::{Context, ContextError, monotonic_ns};
use crate::naming::{Channel, DRIVER_NODE_PREFIX, DeviceName, NameError, attr};
use crate::qos;

/// Default time a request waits for its reply.
pub const DEFAULT_REQUEST_TIMEOUT: Duration = Duration::from_secs(2);
/// How often a waiting client checks that the driver is still alive.
pub const LIVENESS_PERIOD: Duration = Duration::from_millis(20);

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
        "no driver offers {device} in domain {domain} (is the driver running? is LIMBER_DOMAIN the same?)"
    )]
    NoDriver {
        /// The device.
        device: String,
        /// The domain.
        domain: String,
    },
    /// The device exists but speaks another layout version or interface.
    #[error("{device} is incompatible: {reason}")]
    Incompatible {
        /// The device.
        device: String,
        /// Why.
        reason: String,
    },
    /// iceoryx2 failed to open a service or create a port.
    #[error("{device}: cannot open the {channel} channel: {reason}")]
    Transport {
        /// The device.
        device: String,
        /// The channel.
        channel: &'static str,
        /// iceoryx2's reason.
        reason: String,
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
    /// iceoryx2 failed.
    #[error("cannot send the command: {0}")]
    Transport(String),
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
    Decode(DecodeError),
    /// The reply was an ACK of an unexpected kind.
    #[error("unexpected reply")]
    Unexpected,
    /// iceoryx2 failed.
    #[error("request transport failed: {0}")]
    Transport(String),
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
    /// iceoryx2 failed.
    #[error("receiving failed: {0}")]
    Transport(String),
}

/// Whether the driver of a device is running.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DriverStatus {
    /// Its process is alive.
    Alive,
    /// Its process died without cleaning up (found dead and cleaned up now).
    Dead,
    /// No driver is attached.
    Absent,
}

/// How fresh the latest state is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Freshness {
    /// Younger than the limit.
    Fresh,
    /// Older than the limit, but the driver is alive.
    Stale,
    /// The driver is gone.
    Gone,
    /// No state received yet.
    NoData,
}

/// How a client waits for states and replies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WaitMode {
    /// Block on the driver's notification (default; costs a wake-up, frees the CPU).
    Event,
    /// Busy-poll shared memory (lowest latency; takes a whole core).
    Spin,
}

/// A command that was sent, to wait for its outcome.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Ticket {
    /// The command's sequence number.
    pub seq: u64,
    /// How many driver processes received it (normally 1).
    pub receivers: usize,
}

const OUTCOME_SLOTS: usize = 16;

type DataSvc<I> = iceoryx2::service::port_factory::publish_subscribe::PortFactory<
    ipc::Service,
    <I as Interface>::Data,
    (),
>;

/// A connection to one device, for any interface `I`.
///
/// Reading the state and sending a command allocate nothing; requests allocate nothing
/// either. Not `Send`: create it on the thread that uses it.
pub struct Client<I: Interface> {
    ctx: Context,
    device: DeviceName,
    client_id: u64,
    data_svc: DataSvc<I>,
    states: Subscriber<ipc::Service, I::Data, ()>,
    latest: Option<Sample<ipc::Service, I::Data, ()>>,
    commands: Publisher<ipc::Service, I::CmdMsg, ()>,
    requests: IoxClient<ipc::Service, I::ReqMsg, (), I::ReplyMsg, ()>,
    wake: Notifier<ipc::Service>,
    notify_svc: iceoryx2::service::port_factory::event::PortFactory<ipc::Service>,
    notify: Option<Listener<ipc::Service>>,
    cmd_seq: u64,
    req_seq: u64,
    outcomes: [(u64, u32); OUTCOME_SLOTS],
    max_seen_seq: u64,
    wake_driver: bool,
    wait_mode: WaitMode,
    request_timeout: Duration,
}

impl<I: Interface> core::fmt::Debug for Client<I> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Client")
            .field("device", &self.device.to_string())
            .field("client_id", &self.client_id)
            .finish()
    }
}

/// A client of an actuator array.
pub type ActArrayClient = Client<ActArray>;
/// A client of a limb.
pub type LimbClient = Client<Limb>;
/// A client of a gripper.
pub type GripperClient = Client<Gripper>;

impl<I: Interface> Client<I> {
    /// Connects to `device` ("robot/interface/index") in the context's domain. Fails with
    /// [`ConnectError::NoDriver`] at once if nobody offers it.
    pub fn connect(ctx: &Context, device: &str) -> Result<Self, ConnectError> {
        let device: DeviceName = device.parse()?;
        if device.interface() != I::KIND {
            return Err(ConnectError::Incompatible {
                device: device.to_string(),
                reason: format!("it is a {} device, not a {}", device.interface(), I::KIND),
            });
        }
        Self::open_device(ctx, &device)
    }

    /// Like [`Client::connect`], but waits up to `timeout` for a driver to offer the device.
    pub fn connect_timeout(
        ctx: &Context,
        device: &str,
        timeout: Duration,
    ) -> Result<Self, ConnectError> {
        let deadline = Instant::now() + timeout;
        loop {
            match Self::connect(ctx, device) {
                Err(ConnectError::NoDriver { .. }) if Instant::now() < deadline => {
                    std::thread::sleep(Duration::from_millis(20));
                }
                other => return other,
            }
        }
    }

    fn open_device(ctx: &Context, device: &DeviceName) -> Result<Self, ConnectError> {
        let dev = device.to_string();
        let domain = ctx.domain().name().to_string();
        let map = |channel: &'static str, e: String| -> ConnectError {
            if e.contains("DoesNotExist") {
                ConnectError::NoDriver {
                    device: dev.clone(),
                    domain: domain.clone(),
                }
            } else if e.contains("Incompatible") {
                ConnectError::Incompatible {
                    device: dev.clone(),
                    reason: format!("{channel}: {e} (another layout version?)"),
                }
            } else {
                ConnectError::Transport {
                    device: dev.clone(),
                    channel,
                    reason: e,
                }
            }
        };
        let layout = AttributeVerifier::new()
            .require(
                &AttributeKey::new(attr::LAYOUT.as_bytes()).expect("valid key"),
                &AttributeValue::new(limber_interfaces::LAYOUT_VERSION.to_string().as_bytes())
                    .expect("valid value"),
            )
            .expect("one attribute fits");
        let node = ctx.node();
        let data_svc = node
            .service_builder(&device.service_name(Channel::Data))
            .publish_subscribe::<I::Data>()
            .open_with_attributes(&layout)
            .map_err(|e| map("data", format!("{e:?}")))?;
        let states = data_svc
            .subscriber_builder()
            .create()
            .map_err(|e| map("data", format!("{e:?}")))?;
        let commands = node
            .service_builder(&device.service_name(Channel::Cmd))
            .publish_subscribe::<I::CmdMsg>()
            .open_with_attributes(&layout)
            .map_err(|e| map("cmd", format!("{e:?}")))?
            .publisher_builder()
            .max_loaned_samples(1)
            .create()
            .map_err(|e| map("cmd", format!("{e:?}")))?;
        let requests = node
            .service_builder(&device.service_name(Channel::Req))
            .request_response::<I::ReqMsg, I::ReplyMsg>()
            .enable_fire_and_forget_requests(false)
            .open_with_attributes(&layout)
            .map_err(|e| map("req", format!("{e:?}")))?
            .client_builder()
            .create()
            .map_err(|e| map("req", format!("{e:?}")))?;
        let wake = node
            .service_builder(&device.service_name(Channel::Wake))
            .event()
            .open_with_attributes(&layout)
            .map_err(|e| map("wake", format!("{e:?}")))?
            .notifier_builder()
            .create()
            .map_err(|e| map("wake", format!("{e:?}")))?;
        let notify_svc = node
            .service_builder(&device.service_name(Channel::Notify))
            .event()
            .open_with_attributes(&layout)
            .map_err(|e| map("notify", format!("{e:?}")))?;
        // Wake the driver so that it hands this new subscriber the latest state at once.
        let _ = wake.notify_with_custom_event_id(EventId::new(qos::EVENT_HELLO));
        Ok(Client {
            ctx: ctx.clone(),
            device: device.clone(),
            client_id: ctx.new_client_id(),
            data_svc,
            states,
            latest: None,
            commands,
            requests,
            wake,
            notify_svc,
            notify: None,
            cmd_seq: 0,
            req_seq: 0,
            outcomes: [(0, 0); OUTCOME_SLOTS],
            max_seen_seq: 0,
            wake_driver: true,
            wait_mode: WaitMode::Event,
            request_timeout: DEFAULT_REQUEST_TIMEOUT,
        })
    }

    /// The device.
    pub fn device(&self) -> &DeviceName {
        &self.device
    }

    /// This client's id (carried in every command and request it sends).
    pub fn client_id(&self) -> u64 {
        self.client_id
    }

    /// The context.
    pub fn context(&self) -> &Context {
        &self.ctx
    }

    /// How to wait for states and replies (default [`WaitMode::Event`]).
    pub fn set_wait_mode(&mut self, mode: WaitMode) {
        self.wait_mode = mode;
    }

    /// Whether each command and request also wakes the driver with an event (default yes;
    /// a spinning driver does not need it).
    pub fn set_wake_driver(&mut self, on: bool) {
        self.wake_driver = on;
    }

    /// The timeout of requests (default [`DEFAULT_REQUEST_TIMEOUT`]).
    pub fn set_request_timeout(&mut self, timeout: Duration) {
        self.request_timeout = timeout;
    }

    // ----- state ------------------------------------------------------------------------

    /// Takes every state sample that arrived; returns true if there was a new one.
    pub fn refresh(&mut self) -> Result<bool, WaitError> {
        let mut got = false;
        loop {
            match self.states.receive() {
                Ok(Some(s)) => {
                    let d: &I::Data = &s;
                    let h = d.header();
                    if h.last_cmd.client_id == self.client_id {
                        let slot = (h.last_cmd.cmd_seq as usize) % OUTCOME_SLOTS;
                        self.outcomes[slot] = (h.last_cmd.cmd_seq, h.last_cmd.status);
                        self.max_seen_seq = self.max_seen_seq.max(h.last_cmd.cmd_seq);
                    }
                    self.latest = Some(s);
                    got = true;
                }
                Ok(None) => return Ok(got),
                Err(e) => return Err(WaitError::Transport(format!("{e:?}"))),
            }
        }
    }

    /// The latest state (read in place from shared memory), after taking what arrived.
    pub fn state(&mut self) -> Option<&I::Data> {
        let _ = self.refresh();
        self.latest.as_deref()
    }

    /// The latest state, waiting up to `timeout` for a first one if none arrived yet.
    pub fn current(&mut self, timeout: Duration) -> Result<&I::Data, WaitError> {
        self.refresh()?;
        if self.latest.is_none() {
            self.wait_state(timeout)?;
        }
        self.latest.as_deref().ok_or(WaitError::Timeout(timeout))
    }

    /// The latest state already taken, without looking for a newer one.
    pub fn last_state(&self) -> Option<&I::Data> {
        self.latest.as_deref()
    }

    /// Age of the latest state: now minus its acquisition time.
    pub fn state_age(&self) -> Option<Duration> {
        self.latest
            .as_deref()
            .map(|d| Duration::from_nanos(monotonic_ns().saturating_sub(d.header().stamp_ns)))
    }

    /// Fresh (younger than `max_age`), stale (older, driver alive), gone, or no data.
    pub fn freshness(&mut self, max_age: Duration) -> Freshness {
        let _ = self.refresh();
        match self.state_age() {
            None => Freshness::NoData,
            Some(a) if a <= max_age => Freshness::Fresh,
            Some(_) => match self.driver_status() {
                DriverStatus::Alive => Freshness::Stale,
                _ => Freshness::Gone,
            },
        }
    }

    /// Waits for a state sample newer than the latest one taken.
    pub fn wait_state(&mut self, timeout: Duration) -> Result<&I::Data, WaitError> {
        let deadline = Instant::now() + timeout;
        let mut next_check = Instant::now() + LIVENESS_PERIOD;
        loop {
            if self.refresh()? {
                break;
            }
            let now = Instant::now();
            if now >= deadline {
                return Err(WaitError::Timeout(timeout));
            }
            if now >= next_check {
                next_check = now + LIVENESS_PERIOD;
                if self.driver_status() != DriverStatus::Alive {
                    return Err(WaitError::DriverGone);
                }
            }
            self.pause(deadline.min(next_check))?;
        }
        Ok(self.latest.as_deref().expect("refresh returned a sample"))
    }

    /// Waits for the outcome of the command of `ticket`, as published by the driver.
    pub fn wait_outcome(&mut self, ticket: Ticket, timeout: Duration) -> Result<Status, WaitError> {
        let deadline = Instant::now() + timeout;
        let mut next_check = Instant::now() + LIVENESS_PERIOD;
        loop {
            self.refresh()?;
            let (seq, status) = self.outcomes[(ticket.seq as usize) % OUTCOME_SLOTS];
            if seq == ticket.seq {
                return Ok(Status::try_from(status).unwrap_or(Status::InvalidArgument));
            }
            // Commands of one client are applied in order: an outcome of a later one
            // means this one was applied too, its sample overwritten before it was read.
            if self.max_seen_seq > ticket.seq {
                return Err(WaitError::Missed {
                    newer_seq: self.max_seen_seq,
                });
            }
            let now = Instant::now();
            if now >= deadline {
                return Err(WaitError::Timeout(timeout));
            }
            if now >= next_check {
                next_check = now + LIVENESS_PERIOD;
                if self.driver_status() != DriverStatus::Alive {
                    return Err(WaitError::DriverGone);
                }
            }
            self.pause(deadline.min(next_check))?;
        }
    }

    /// Blocks (event mode) or spins once (spin mode) until `until` or a notification.
    fn pause(&mut self, until: Instant) -> Result<(), WaitError> {
        match self.wait_mode {
            WaitMode::Spin => {
                core::hint::spin_loop();
                Ok(())
            }
            WaitMode::Event => {
                if self.notify.is_none() {
                    let l = self
                        .notify_svc
                        .listener_builder()
                        .create()
                        .map_err(|e| WaitError::Transport(format!("{e:?}")))?;
                    self.notify = Some(l);
                    // Something may have arrived before the listener existed.
                    return Ok(());
                }
                let left = until.saturating_duration_since(Instant::now());
                if let Some(l) = &self.notify {
                    l.timed_wait(|_| {}, left)
                        .map_err(|e| WaitError::Transport(format!("{e:?}")))?;
                }
                Ok(())
            }
        }
    }

    // ----- liveness ---------------------------------------------------------------------

    /// Whether the device's driver process is alive. A dead driver's resources are
    /// cleaned up on the way, so that a restarted driver is picked up by this client.
    /// Costs tens of microseconds: not for every control cycle.
    pub fn driver_status(&self) -> DriverStatus {
        driver_status_of(&self.data_svc)
    }

    // ----- commands ---------------------------------------------------------------------

    /// Sends a typed command. Returns at once (commands are not acknowledged; see
    /// [`Client::wait_outcome`]).
    pub fn send(&mut self, cmd: &I::Command) -> Result<Ticket, CommandError> {
        let loan = self
            .commands
            .loan_uninit()
            .map_err(|e| CommandError::Transport(format!("{e:?}")))?;
        let mut sample = loan.write_payload(I::CmdMsg::default());
        let raw: &mut I::CmdMsg = sample.payload_mut();
        cmd.write(raw);
        self.cmd_seq += 1;
        let m = raw.meta_mut();
        m.client_id = self.client_id;
        m.seq = self.cmd_seq;
        m.stamp_ns = monotonic_ns();
        let receivers = sample
            .send()
            .map_err(|e| CommandError::Transport(format!("{e:?}")))?;
        if self.wake_driver {
            let _ = self
                .wake
                .notify_with_custom_event_id(EventId::new(qos::EVENT_COMMAND));
        }
        if receivers == 0 {
            return Err(CommandError::NoDriver);
        }
        Ok(Ticket {
            seq: self.cmd_seq,
            receivers,
        })
    }

    // ----- requests ---------------------------------------------------------------------

    /// Sends a typed request and waits for the reply (up to the request timeout).
    pub fn request(&mut self, req: &I::Request) -> Result<I::Reply, RequestError> {
        let timeout = self.request_timeout;
        self.request_with_timeout(req, timeout)
    }

    /// Sends a typed request and waits up to `timeout` for the reply.
    pub fn request_with_timeout(
        &mut self,
        req: &I::Request,
        timeout: Duration,
    ) -> Result<I::Reply, RequestError> {
        let loan = self
            .requests
            .loan_uninit()
            .map_err(|e| RequestError::Transport(format!("{e:?}")))?;
        let mut r = loan.write_payload(I::ReqMsg::default());
        let raw: &mut I::ReqMsg = r.payload_mut();
        req.write(raw);
        self.req_seq += 1;
        let m = raw.meta_mut();
        m.client_id = self.client_id;
        m.seq = self.req_seq;
        m.stamp_ns = monotonic_ns();
        let pending = r
            .send()
            .map_err(|e| RequestError::Transport(format!("{e:?}")))?;
        if pending.number_of_server_connections() == 0 {
            return Err(RequestError::NoDriver);
        }
        if self.wake_driver {
            let _ = self
                .wake
                .notify_with_custom_event_id(EventId::new(qos::EVENT_REQUEST));
        }
        let deadline = Instant::now() + timeout;
        let mut next_check = Instant::now() + LIVENESS_PERIOD;
        loop {
            match pending.receive() {
                Ok(Some(resp)) => {
                    return decode_reply::<I>(resp.payload());
                }
                Ok(None) => {}
                Err(e) => return Err(RequestError::Transport(format!("{e:?}"))),
            }
            if !pending.is_connected() {
                // The server may have answered and closed in between: look once more.
                if let Ok(Some(resp)) = pending.receive() {
                    return decode_reply::<I>(resp.payload());
                }
                return Err(RequestError::DriverGone);
            }
            let now = Instant::now();
            if now >= deadline {
                return Err(RequestError::Timeout(timeout));
            }
            if now >= next_check {
                next_check = now + LIVENESS_PERIOD;
                if self.driver_status() != DriverStatus::Alive {
                    return Err(RequestError::DriverGone);
                }
            }
            self.pause(deadline.min(next_check))
                .map_err(|e| RequestError::Transport(e.to_string()))?;
        }
    }
}

/// A reply as the caller sees it: the ACK's payload, or the NACK's reason.
fn decode_reply<I: Interface>(raw: &I::ReplyMsg) -> Result<I::Reply, RequestError> {
    match I::Reply::read(raw) {
        Ok(Ok(reply)) => Ok(reply),
        Ok(Err(status)) => Err(RequestError::Nack(status)),
        Err(e) => Err(RequestError::Decode(e)),
    }
}

/// The status of the driver attached to a device's data service.
pub(crate) fn driver_status_of<P: PortFactory<Service = ipc::Service>>(svc: &P) -> DriverStatus {
    let mut alive = false;
    let mut dead = false;
    let is_driver = |d: &Option<iceoryx2::node::NodeDetails>| {
        d.as_ref()
            .map(|d| d.name().as_str().starts_with(DRIVER_NODE_PREFIX))
            .unwrap_or(false)
    };
    let _ = svc.nodes(|n| {
        match &n {
            NodeState::Alive(v) if is_driver(v.details()) => alive = true,
            NodeState::Dead(v) if is_driver(v.details()) => dead = true,
            _ => {}
        }
        CallbackProgression::Continue
    });
    if alive {
        DriverStatus::Alive
    } else if dead {
        svc.try_cleanup_dead_nodes();
        DriverStatus::Dead
    } else {
        DriverStatus::Absent
    }
}

fn joint_index(j: usize) -> i64 {
    j.min(i64::MAX as usize) as i64
}

/// Player's `ActArrayProxy`: every actarray command and request.
impl Client<ActArray> {
    /// CMD POS: move `joint` to `position` (rad or m).
    pub fn move_to(&mut self, joint: usize, position: f64) -> Result<Ticket, CommandError> {
        self.send(&ActArrayCommand::position(joint_index(joint), position)?)
    }
    /// CMD MULTI_POS: move joints 0..n to `positions`.
    pub fn move_to_multi(&mut self, positions: &[f64]) -> Result<Ticket, CommandError> {
        self.send(&ActArrayCommand::multi_position(positions)?)
    }
    /// CMD SPEED: move `joint` at `speed` (rad/s or m/s).
    pub fn move_at_speed(&mut self, joint: usize, speed: f64) -> Result<Ticket, CommandError> {
        self.send(&ActArrayCommand::speed(joint_index(joint), speed)?)
    }
    /// CMD MULTI_SPEED: move joints 0..n at `speeds`.
    pub fn move_at_speed_multi(&mut self, speeds: &[f64]) -> Result<Ticket, CommandError> {
        self.send(&ActArrayCommand::multi_speed(speeds)?)
    }
    /// CMD HOME: home `joint`, or every joint with `None`.
    pub fn home(&mut self, joint: Option<usize>) -> Result<Ticket, CommandError> {
        self.send(&ActArrayCommand::home(
            joint.map(joint_index).unwrap_or(-1),
        )?)
    }
    /// CMD CURRENT: drive `joint` (or all with `None`) with `current` A.
    pub fn set_current(
        &mut self,
        joint: Option<usize>,
        current: f64,
    ) -> Result<Ticket, CommandError> {
        self.send(&ActArrayCommand::current(
            joint.map(joint_index).unwrap_or(-1),
            current,
        )?)
    }
    /// CMD MULTI_CURRENT: drive joints 0..n with `currents` A.
    pub fn set_current_multi(&mut self, currents: &[f64]) -> Result<Ticket, CommandError> {
        self.send(&ActArrayCommand::multi_current(currents)?)
    }
    /// REQ POWER.
    pub fn power(&mut self, on: bool) -> Result<(), RequestError> {
        self.request(&ActArrayRequest::Power(on)).map(|_| ())
    }
    /// REQ BRAKES.
    pub fn brakes(&mut self, on: bool) -> Result<(), RequestError> {
        self.request(&ActArrayRequest::Brakes(on)).map(|_| ())
    }
    /// REQ SPEED: the speed of `joint` for later moves.
    pub fn set_speed_config(&mut self, joint: usize, speed: f64) -> Result<(), RequestError> {
        self.request(&ActArrayRequest::speed(joint_index(joint), speed)?)
            .map(|_| ())
    }
    /// REQ ACCEL: the acceleration of `joint` for later moves.
    pub fn set_accel_config(&mut self, joint: usize, accel: f64) -> Result<(), RequestError> {
        self.request(&ActArrayRequest::accel(joint_index(joint), accel)?)
            .map(|_| ())
    }
    /// REQ GET_GEOM.
    pub fn geometry(&mut self) -> Result<ActArrayGeom, RequestError> {
        match self.request(&ActArrayRequest::GetGeom)? {
            ActArrayReply::Geom(g) => Ok(g),
            ActArrayReply::Done => Err(RequestError::Unexpected),
        }
    }
}

/// Player's `LimbProxy`: every limb command and request.
impl Client<Limb> {
    /// CMD HOME.
    pub fn home(&mut self) -> Result<Ticket, CommandError> {
        self.send(&LimbCommand::Home)
    }
    /// CMD STOP: stop every joint now.
    pub fn stop(&mut self) -> Result<Ticket, CommandError> {
        self.send(&LimbCommand::Stop)
    }
    /// CMD SETPOSE: end effector to `position` (robot frame, m) with `approach` and
    /// `orientation` vectors.
    pub fn set_pose(
        &mut self,
        position: [f64; 3],
        approach: [f64; 3],
        orientation: [f64; 3],
    ) -> Result<Ticket, CommandError> {
        self.send(&LimbCommand::set_pose(
            position.into(),
            approach.into(),
            orientation.into(),
        )?)
    }
    /// CMD SETPOSITION: end effector to `position`, orientation chosen by the driver.
    pub fn set_position(&mut self, position: [f64; 3]) -> Result<Ticket, CommandError> {
        self.send(&LimbCommand::set_position(position.into())?)
    }
    /// CMD VECMOVE: move `length` m along `direction` in a straight line.
    pub fn vec_move(&mut self, direction: [f64; 3], length: f64) -> Result<Ticket, CommandError> {
        self.send(&LimbCommand::vec_move(direction.into(), length)?)
    }
    /// REQ POWER.
    pub fn power(&mut self, on: bool) -> Result<(), RequestError> {
        self.request(&LimbRequest::Power(on)).map(|_| ())
    }
    /// REQ BRAKES.
    pub fn brakes(&mut self, on: bool) -> Result<(), RequestError> {
        self.request(&LimbRequest::Brakes(on)).map(|_| ())
    }
    /// REQ SPEED: end-effector speed, m/s.
    pub fn set_speed(&mut self, speed: f64) -> Result<(), RequestError> {
        self.request(&LimbRequest::speed(speed)?).map(|_| ())
    }
    /// REQ GEOM.
    pub fn geometry(&mut self) -> Result<LimbGeom, RequestError> {
        match self.request(&LimbRequest::Geom)? {
            LimbReply::Geom(g) => Ok(g),
            LimbReply::Done => Err(RequestError::Unexpected),
        }
    }
}

/// Player's `GripperProxy`: every gripper command and request.
impl Client<Gripper> {
    /// CMD OPEN.
    pub fn open(&mut self) -> Result<Ticket, CommandError> {
        self.send(&GripperCommand::Open)
    }
    /// CMD CLOSE.
    pub fn close(&mut self) -> Result<Ticket, CommandError> {
        self.send(&GripperCommand::Close)
    }
    /// CMD STOP.
    pub fn stop(&mut self) -> Result<Ticket, CommandError> {
        self.send(&GripperCommand::Stop)
    }
    /// CMD STORE.
    pub fn store(&mut self) -> Result<Ticket, CommandError> {
        self.send(&GripperCommand::Store)
    }
    /// CMD RETRIEVE.
    pub fn retrieve(&mut self) -> Result<Ticket, CommandError> {
        self.send(&GripperCommand::Retrieve)
    }
    /// REQ GET_GEOM.
    pub fn geometry(&mut self) -> Result<GripperGeom, RequestError> {
        match self.request(&GripperRequest::GetGeom)? {
            GripperReply::Geom(g) => Ok(g),
        }
    }
}
