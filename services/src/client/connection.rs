//! The connection to one device: the iceoryx2 ports of its channels (data, cmd, req, wake,
//! notify, told; outcome when watching every client's, lease when asked), opened by
//! [`Client::connect`], and the driver's liveness.

use core::time::Duration;
use std::time::Instant;

use iceoryx2::node::NodeView;
use iceoryx2::pending_response::PendingResponse;
use iceoryx2::port::client::Client as IoxClient;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::prelude::*;
use iceoryx2::sample::Sample;
use iceoryx2::service::attribute::{AttributeKey, AttributeValue};
use iceoryx2::service::port_factory::PortFactory;
use limber_interfaces::prelude::*;

use super::{
    ConnectError, DEFAULT_REQUEST_TIMEOUT, DriverStatus, Incompatibility, Outcome, WaitMode,
};
use crate::context::Context;
use crate::error::Iox2Error;
use crate::host::told::OutcomeSvc;
use crate::naming::{Channel, DRIVER_NODE_PREFIX, DeviceName, attr};
use crate::qos;

/// In group mode, how long [`Client::connect`] tries again a service whose files are not
/// open to the group yet (they are widened within milliseconds of being made; iceoryx2
/// itself waits up to its `creation_timeout`, 1 s, for segments).
pub const GROUP_PERMISSION_WAIT: Duration = Duration::from_secs(2);

pub(super) const OUTCOME_SLOTS: usize = 16;

/// A client's own outcomes: its port on the device's `told` channel and the stream it
/// opened there (see `crate::host` `told.rs`).
pub(crate) struct ToldSide {
    pub(super) port: IoxClient<ipc::Service, u64, (), OutcomeMsg, ()>,
    /// Open while the driver that took it keeps it (a restarted driver needs a new one).
    pub(super) stream: Option<ToldStream>,
    /// This process's stream, for a relay (`Client::relay_own_outcomes`), and when it was
    /// last looked at.
    pub(crate) process: Option<ToldStream>,
    pub(crate) process_checked: Option<Instant>,
}

/// A client's outcome stream: its request on `told`, answered with every outcome of its
/// commands.
pub(crate) type ToldStream = PendingResponse<ipc::Service, u64, (), OutcomeMsg, ()>;

/// The lease port of a client and the lease it holds.
pub(crate) struct LeaseSide {
    pub(crate) port: IoxClient<ipc::Service, LeaseReq, (), LeaseReply, ()>,
    pub(super) seq: u64,
    /// The heartbeat timeout and the time of the last renewal, while this client holds
    /// the device.
    pub(super) held: Option<(Duration, Instant)>,
}

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
    pub(crate) device: DeviceName,
    pub(super) client_id: u64,
    pub(crate) data_svc: DataSvc<I>,
    pub(crate) states: Subscriber<ipc::Service, I::Data, ()>,
    pub(super) latest: Option<Sample<ipc::Service, I::Data, ()>>,
    pub(crate) commands: Publisher<ipc::Service, I::CmdMsg, ()>,
    pub(crate) requests: IoxClient<ipc::Service, I::ReqMsg, (), I::ReplyMsg, ()>,
    /// Wakes the driver; replaced when a wake-up reaches no listener (see
    /// `Client::wake_driver_with`).
    pub(super) wake: core::cell::RefCell<Notifier<ipc::Service>>,
    pub(super) wake_svc: iceoryx2::service::port_factory::event::PortFactory<ipc::Service>,
    /// No new notifier before then.
    pub(super) wake_retry_at: core::cell::Cell<Option<std::time::Instant>>,
    pub(crate) notify_svc: iceoryx2::service::port_factory::event::PortFactory<ipc::Service>,
    pub(super) notify: Option<Listener<ipc::Service>>,
    /// The device's wake word, on which [`Client::wait_state`] sleeps ([`crate::wake`]),
    /// opened at its first wait.
    pub(super) state_wake: Option<crate::wake::WakeWord>,
    /// When opening the wake word last failed (tried again a liveness period later).
    pub(super) state_wake_tried: Option<Instant>,
    pub(super) cmd_seq: u64,
    pub(super) req_seq: u64,
    /// This client's own outcomes (see [`ToldSide`]).
    pub(crate) told: ToldSide,
    pub(crate) outcome_svc: OutcomeSvc,
    /// Every outcome of the device, once [`Client::watch_outcomes`] asked for them.
    pub(crate) outcome_sub: Option<Subscriber<ipc::Service, OutcomeMsg, ()>>,
    pub(super) outcomes: [Outcome; OUTCOME_SLOTS],
    pub(super) preemptions: [Outcome; OUTCOME_SLOTS],
    /// The motion results of this client's last commands (by sequence number).
    pub(super) results: [Option<super::Done>; OUTCOME_SLOTS],
    pub(super) max_seen_seq: u64,
    pub(super) lease: Option<LeaseSide>,
    pub(super) wake_driver: bool,
    pub(super) wait_mode: WaitMode,
    pub(super) request_timeout: Duration,
    /// In [`WaitMode::Event`], how long to busy-poll after sending before blocking.
    pub(super) spin_budget: Duration,
    /// Busy-poll until then (set by a send), then block.
    pub(super) spin_until: Option<std::time::Instant>,
    /// The next command's sample, loaned right after the previous command was sent
    /// (`crate::host::loan_ahead`).
    pub(super) cmd_loan: Option<CmdLoan<I>>,
    /// The driver's status as [`Client::freshness`] last looked, and when.
    pub(super) liveness_seen: Option<(Instant, DriverStatus)>,
    /// This client found the driver's process dead (and cleaned it up), and no driver is
    /// alive since: [`Client::driver_status`] says `Dead`, not `Absent`.
    pub(super) driver_died: core::cell::Cell<bool>,
    /// Last: dropped after the ports, so a test's domain whose last handle this is finds
    /// them gone ([`crate::Domain::unique_for_test`]).
    pub(super) ctx: Context,
}

/// A command sample loaned ahead of its command.
pub(super) type CmdLoan<I> = iceoryx2::sample_mut_uninit::SampleMutUninit<
    ipc::Service,
    core::mem::MaybeUninit<<I as Interface>::CmdMsg>,
    (),
>;

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
/// A client of a ranger (a laser scanner).
pub type RangerClient = Client<Ranger>;
/// Player's name for a planar laser's client: a [`RangerClient`].
pub type LaserClient = RangerClient;

impl<I: Interface> Client<I> {
    /// Connects to `device` ("robot/interface/index") in the context's domain. Fails with
    /// [`ConnectError::NoDriver`] at once if nobody offers it.
    ///
    /// In group mode (`LIMBER_GROUP`) a service whose files the member who made them has
    /// not opened to the group yet (the instant after they were made) is tried again for up
    /// to `GROUP_PERMISSION_WAIT` (2 s) before [`ConnectError::Permission`].
    pub fn connect(ctx: &Context, device: &str) -> Result<Self, ConnectError> {
        Self::connect_within(ctx, device, Instant::now() + GROUP_PERMISSION_WAIT)
    }

    fn connect_within(
        ctx: &Context,
        device: &str,
        deadline: Instant,
    ) -> Result<Self, ConnectError> {
        let grouped = ctx.domain().group().ok().flatten().is_some();
        let mut logged = false;
        loop {
            match Self::connect_once(ctx, device) {
                Err(ConnectError::Permission { channel, .. })
                    if grouped && Instant::now() < deadline =>
                {
                    if !logged {
                        tracing::info!(
                            device,
                            channel,
                            "group mode: the device's files are not open to the group yet; trying again"
                        );
                        logged = true;
                    }
                    std::thread::sleep(Duration::from_millis(10));
                }
                other => return other,
            }
        }
    }

    fn connect_once(ctx: &Context, device: &str) -> Result<Self, ConnectError> {
        let device: DeviceName = device.parse()?;
        if device.interface() != I::KIND {
            return Err(ConnectError::Incompatible {
                device: device.to_string(),
                reason: Incompatibility::Interface {
                    actual: device.interface(),
                    expected: I::KIND,
                },
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
        let permission_deadline = deadline.max(Instant::now() + GROUP_PERMISSION_WAIT);
        loop {
            match Self::connect_within(ctx, device, permission_deadline) {
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
        // The device's capacity as its driver published it (ordinary, reserved), once read.
        let capacity: core::cell::Cell<(usize, usize)> = core::cell::Cell::new((0, 0));
        let full = || {
            let (max, reserved) = capacity.get();
            ConnectError::Full {
                device: dev.clone(),
                max,
                reserved,
                priority: ctx.priority(),
            }
        };
        let no_driver = || ConnectError::NoDriver {
            device: dev.clone(),
            domain: domain.clone(),
            elsewhere: crate::domain::dir::elsewhere_note(&domain),
        };
        let map = |channel: &'static str, e: Iox2Error| -> ConnectError {
            if e.is_full() {
                full()
            } else if e.is_missing_service() {
                no_driver()
            } else if e.is_permission_denied() {
                let hint = match ctx.domain().group().ok().flatten() {
                    Some(g) => format!(
                        "in group mode ({}) the member who started the driver must run a limber with group mode, with LIMBER_GROUP={} set (docs/guide/security.md)",
                        g.name, g.name
                    ),
                    None => "they belong to another user; a domain is its owner's alone (docs/guide/security.md)".to_string(),
                };
                ConnectError::Permission {
                    device: dev.clone(),
                    channel,
                    hint,
                    source: e,
                }
            } else if e.is_incompatible() {
                ConnectError::Incompatible {
                    device: dev.clone(),
                    reason: Incompatibility::Layout { channel, source: e },
                }
            } else {
                ConnectError::Transport {
                    device: dev.clone(),
                    channel,
                    source: e,
                }
            }
        };
        let attribute = |e: Iox2Error| map("attributes", e);
        let layout = AttributeVerifier::new()
            .require(
                &AttributeKey::new(attr::LAYOUT.as_bytes()).map_err(|e| attribute(e.into()))?,
                &AttributeValue::new(limber_interfaces::LAYOUT_VERSION.to_string().as_bytes())
                    .map_err(|e| attribute(e.into()))?,
            )
            .map_err(|e| attribute(e.into()))?;
        let node = ctx.node();
        let data_svc = node
            .service_builder(&device.service_name(Channel::Data))
            .publish_subscribe::<I::Data>()
            .open_with_attributes(&layout)
            .map_err(|e| map("data", e.into()))?;
        // Services that another client keeps open outlive their driver: a device whose
        // driver died (or ended) is not offered, whoever still holds its files.
        if !driver_may_be_alive(&data_svc, ctx.domain()) {
            return Err(no_driver());
        }
        if let Some((max, reserved)) = advertised_capacity(&data_svc) {
            capacity.set((max, reserved));
            // The last `reserved` slots are the priority clients' (cooperative: see
            // `Context::set_priority`). Dead clients' slots are freed before refusing.
            let taken = || data_svc.dynamic_config().number_of_subscribers();
            if !ctx.priority() && taken() >= max {
                ctx.domain().cleanup_dead_nodes(&data_svc);
                if taken() >= max {
                    return Err(full());
                }
            }
        }
        let states = data_svc
            .subscriber_builder()
            .create()
            .map_err(|e| map("data", e.into()))?;
        let commands = node
            .service_builder(&device.service_name(Channel::Cmd))
            .publish_subscribe::<I::CmdMsg>()
            .open_with_attributes(&layout)
            .map_err(|e| map("cmd", e.into()))?
            .publisher_builder()
            // One sample loaned ahead for the next command, one for a relayed command.
            .max_loaned_samples(2)
            .create()
            .map_err(|e| map("cmd", e.into()))?;
        let requests = node
            .service_builder(&device.service_name(Channel::Req))
            .request_response::<I::ReqMsg, I::ReplyMsg>()
            .enable_fire_and_forget_requests(false)
            .open_with_attributes(&layout)
            .map_err(|e| map("req", e.into()))?
            .client_builder()
            .create()
            .map_err(|e| map("req", e.into()))?;
        let wake_svc = node
            .service_builder(&device.service_name(Channel::Wake))
            .event()
            .open_with_attributes(&layout)
            .map_err(|e| map("wake", e.into()))?;
        let wake = wake_svc
            .notifier_builder()
            .create()
            .map_err(|e| map("wake", e.into()))?;
        let notify_svc = node
            .service_builder(&device.service_name(Channel::Notify))
            .event()
            .open_with_attributes(&layout)
            .map_err(|e| map("notify", e.into()))?;
        let told = node
            .service_builder(&device.service_name(Channel::Told))
            .request_response::<u64, OutcomeMsg>()
            .enable_fire_and_forget_requests(false)
            .open_with_attributes(&layout)
            .map_err(|e| map("told", e.into()))?
            .client_builder()
            .create()
            .map_err(|e| map("told", e.into()))?;
        // Last: the driver makes its `outcome` publisher after every other port (see
        // `DeviceHost::new`). Without it the driver is still starting: no driver yet
        // (`connect_timeout` tries again), rather than a client whose first request or
        // lease would go to a server that is not there yet.
        let outcome_svc = node
            .service_builder(&device.service_name(Channel::Outcome))
            .publish_subscribe::<OutcomeMsg>()
            .open_with_attributes(&layout)
            .map_err(|e| map("outcome", e.into()))?;
        if outcome_svc.dynamic_config().number_of_publishers() == 0 {
            return Err(no_driver());
        }
        let client_id = ctx.new_client_id();
        // This client's outcome stream, asked for before any command can be sent.
        let stream = open_told_stream(&told, client_id).map_err(|e| map("told", e))?;
        if stream.is_none() {
            return Err(no_driver());
        }
        // Group mode: open the files these ports made to the group at once (the watch of
        // crate::widen would, a little later).
        ctx.domain().widen_now();
        // Wake the driver so that it hands this new subscriber the latest state at once
        // (otherwise it does at its next publication: a delay, not a failure).
        if let Err(e) = wake.notify_with_custom_event_id(EventId::new(qos::EVENT_HELLO)) {
            tracing::debug!(device = %dev, error = %e, "cannot wake the driver");
        }
        Ok(Client {
            ctx: ctx.clone(),
            device: device.clone(),
            client_id,
            data_svc,
            states,
            latest: None,
            commands,
            requests,
            wake: core::cell::RefCell::new(wake),
            wake_svc,
            wake_retry_at: core::cell::Cell::new(None),
            notify_svc,
            notify: None,
            state_wake: None,
            state_wake_tried: None,
            cmd_seq: 0,
            req_seq: 0,
            told: ToldSide {
                port: told,
                stream,
                process: None,
                process_checked: None,
            },
            outcome_svc,
            outcome_sub: None,
            outcomes: [Outcome::NONE; OUTCOME_SLOTS],
            preemptions: [Outcome::NONE; OUTCOME_SLOTS],
            results: [None; OUTCOME_SLOTS],
            max_seen_seq: 0,
            lease: None,
            wake_driver: true,
            wait_mode: WaitMode::Event,
            request_timeout: DEFAULT_REQUEST_TIMEOUT,
            spin_budget: crate::qos::default_spin_budget(),
            spin_until: None,
            cmd_loan: None,
            liveness_seen: None,
            driver_died: core::cell::Cell::new(false),
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

    /// In [`WaitMode::Event`], how long a wait for an outcome, a reply or a state that
    /// follows a command or request busy-polls before it blocks (default
    /// [`crate::qos::default_spin_budget`]; zero: block at once). The answer of a driver
    /// that is awake then arrives without a wake-up of this process, at the price of up to
    /// this much CPU time per exchange.
    pub fn set_spin_budget(&mut self, budget: Duration) {
        self.spin_budget = budget;
    }

    /// The spin budget (see [`Client::set_spin_budget`]).
    pub fn spin_budget(&self) -> Duration {
        self.spin_budget
    }

    /// Starts the busy-poll window of a send.
    pub(super) fn sent(&mut self) {
        if !self.spin_budget.is_zero() {
            self.spin_until = Some(std::time::Instant::now() + self.spin_budget);
        }
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

    // ----- liveness ---------------------------------------------------------------------

    /// Whether the device's driver process is alive. A dead driver's resources are
    /// cleaned up on the way, so that a restarted driver is picked up by this client; it
    /// reads [`DriverStatus::Dead`] all the same until a driver is alive again (a driver
    /// that another process cleaned up before this client looked reads `Absent`: iceoryx2
    /// keeps nothing of it to tell). Costs tens of microseconds: not for every control
    /// cycle.
    pub fn driver_status(&self) -> DriverStatus {
        let status = driver_status_of(&self.data_svc, self.ctx.domain());
        match status {
            DriverStatus::Alive => self.driver_died.set(false),
            DriverStatus::Dead => self.driver_died.set(true),
            DriverStatus::Absent if self.driver_died.get() => return DriverStatus::Dead,
            DriverStatus::Absent => {}
        }
        status
    }
}

/// Asks the driver of `port` for the outcomes of client `client_id`: the stream, or `None`
/// when no driver took the request.
fn open_told_stream(
    port: &IoxClient<ipc::Service, u64, (), OutcomeMsg, ()>,
    client_id: u64,
) -> Result<Option<ToldStream>, Iox2Error> {
    let pending = port.loan_uninit()?.write_payload(client_id).send()?;
    Ok((pending.number_of_server_connections() > 0).then_some(pending))
}

/// Makes sure the stream in `slot`, asked for with `id` on `port`, is open: one the driver no
/// longer keeps (a driver that started again) is asked for again. Returns whether it was
/// asked for anew and reached a driver (which the caller then wakes to take it).
fn keep_stream(
    port: &IoxClient<ipc::Service, u64, (), OutcomeMsg, ()>,
    slot: &mut Option<ToldStream>,
    id: u64,
    device: &DeviceName,
) -> bool {
    if let Err(e) = port.update_connections() {
        tracing::debug!(device = %device, error = %e, "cannot connect the outcome stream's port");
    }
    if slot.as_ref().is_some_and(|s| s.is_connected()) {
        return false;
    }
    // Dropped first: its slot is free for the new one.
    *slot = None;
    match open_told_stream(port, id) {
        Ok(s) => {
            *slot = s;
            slot.is_some()
        }
        Err(e) => {
            tracing::warn!(device = %device, error = %e, "cannot open an outcome stream");
            false
        }
    }
}

impl<I: Interface> Client<I> {
    /// Makes sure this client's outcome stream is open: a driver that restarted (or took
    /// over the device) knows nothing of the stream the client opened with the one before
    /// it, so a closed one is asked for again, and the driver woken to take it (it sends
    /// the outcomes of this client's commands it decided meanwhile, up to 64 of all
    /// clients without a stream, on the new stream). Called on the waits' liveness checks
    /// (not on the command's path: it costs a look at the port's connections).
    pub(super) fn keep_told_stream(&mut self) {
        if keep_stream(
            &self.told.port,
            &mut self.told.stream,
            self.client_id,
            &self.device,
        ) {
            tracing::debug!(device = %self.device, "outcome stream opened again");
            self.wake_driver_with(qos::EVENT_REQUEST);
        }
    }

    /// [`Client::keep_told_stream`] for this process's stream (`Client::relay_open_stream`);
    /// returns whether it is open.
    pub(crate) fn keep_process_stream(&mut self) -> bool {
        let id = crate::context::process_stream_id(self.client_id);
        if keep_stream(&self.told.port, &mut self.told.process, id, &self.device) {
            // The driver takes it at once (and sends what it kept meanwhile).
            self.wake_driver_with(qos::EVENT_REQUEST);
        }
        self.told.process.is_some()
    }

    /// Watches every outcome of the device, of every client, from now on (for a bridge or a
    /// recorder: [`Client::relay_outcomes`]); a client reads its own without it.
    pub fn watch_outcomes(&mut self) -> Result<(), Iox2Error> {
        if self.outcome_sub.is_none() {
            self.outcome_sub = Some(
                self.outcome_svc
                    .subscriber_builder()
                    .buffer_size(qos::OUTCOME_BUFFER)
                    .create()?,
            );
        }
        Ok(())
    }
}

/// Whether a driver's process may be attached to a device's data service: one is known
/// alive, or a live node's name cannot be read (in group mode, another member's). A dead
/// driver found on the way is cleaned up.
fn driver_may_be_alive<P: PortFactory<Service = ipc::Service>>(
    svc: &P,
    domain: &crate::domain::Domain,
) -> bool {
    let (mut alive, mut unknown, mut dead) = (false, false, false);
    if let Err(e) = svc.nodes(|n| {
        match &n {
            NodeState::Alive(v) => match v.details() {
                Some(d) if d.name().as_str().starts_with(DRIVER_NODE_PREFIX) => alive = true,
                Some(_) => {}
                None => unknown = true,
            },
            NodeState::Dead(v) => {
                if v.details()
                    .as_ref()
                    .is_some_and(|d| d.name().as_str().starts_with(DRIVER_NODE_PREFIX))
                {
                    dead = true;
                }
            }
            NodeState::Inaccessible(_) | NodeState::Undefined(_) => unknown = true,
        }
        CallbackProgression::Continue
    }) {
        // Not known to be dead: let the connection go on (its waits check again).
        tracing::warn!(error = %e, "cannot list the nodes of a device");
        return true;
    }
    if dead && !alive {
        domain.cleanup_dead_nodes(svc);
    }
    alive || unknown
}

/// The capacity a driver published for its device: (ordinary clients, reserved slots);
/// `None` from a driver that does not say.
fn advertised_capacity<P: PortFactory<Service = ipc::Service>>(svc: &P) -> Option<(usize, usize)> {
    let get = |key: &str| -> Option<usize> {
        svc.attributes()
            .iter()
            .find(|a| a.key().as_bytes() == key.as_bytes())
            .and_then(|a| a.value().to_string().parse().ok())
    };
    Some((get(attr::MAX_CLIENTS)?, get(attr::RESERVED_CLIENTS)?))
}

/// The status of the driver attached to a device's data service.
pub(super) fn driver_status_of<P: PortFactory<Service = ipc::Service>>(
    svc: &P,
    domain: &crate::domain::Domain,
) -> DriverStatus {
    let mut alive = false;
    let mut dead = false;
    let is_driver = |d: &Option<iceoryx2::node::NodeDetails>| {
        d.as_ref()
            .map(|d| d.name().as_str().starts_with(DRIVER_NODE_PREFIX))
            .unwrap_or(false)
    };
    if let Err(e) = svc.nodes(|n| {
        match &n {
            NodeState::Alive(v) if is_driver(v.details()) => alive = true,
            NodeState::Dead(v) if is_driver(v.details()) => dead = true,
            _ => {}
        }
        CallbackProgression::Continue
    }) {
        // Nodes not listed are not known to be alive: the caller sees the driver as
        // absent (or dead, if one was found before the failure).
        tracing::warn!(error = %e, "cannot list the nodes of a device");
    }
    if alive {
        DriverStatus::Alive
    } else if dead {
        domain.cleanup_dead_nodes(svc);
        DriverStatus::Dead
    } else {
        DriverStatus::Absent
    }
}
