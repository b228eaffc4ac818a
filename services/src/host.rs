//! The driver side: [`DeviceHost`] offers one device and [`DeviceHandler`] is what a driver
//! implements for each interface it serves.

use core::marker::PhantomData;
use core::mem::MaybeUninit;

use iceoryx2::active_request::ActiveRequest;
use iceoryx2::node::NodeView;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::server::Server;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::port::update_connections::UpdateConnections;
use iceoryx2::port::{LoanError, ReceiveError, SendError};
use iceoryx2::prelude::*;
use iceoryx2::sample_mut_uninit::SampleMutUninit;
use iceoryx2::service::attribute::{AttributeKey, AttributeValue};
use limber_interfaces::control::{get_name, put_name};
use limber_interfaces::prelude::*;
use thiserror::Error;

use crate::context::{Context, monotonic_ns};
use crate::error::Iox2Error;
use crate::naming::{Channel, DeviceName, NameError, attr};
use crate::qos;

/// Who sent a command or request.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Origin {
    /// The client's id.
    pub client_id: u64,
    /// The client's sequence number of this message.
    pub seq: u64,
    /// When the client sent it (`CLOCK_MONOTONIC` ns).
    pub sent_ns: u64,
    /// When the driver took it from the channel (`CLOCK_MONOTONIC` ns; 0 for the driver's
    /// own commands): what the driver does from here on is its own cost.
    pub received_ns: u64,
}

/// What a driver implements for each interface it serves: `DeviceHandler<ActArray>`,
/// `DeviceHandler<Limb>`, `DeviceHandler<Gripper>`. The Pioneer driver, the simulated arm
/// and test doubles plug into a [`DeviceHost`] the same way.
pub trait DeviceHandler<I: Interface> {
    /// Carries out (or refuses) a validated command; `state` is the device state the host
    /// publishes next. The returned status reaches the sender in the next state sample's
    /// `last_cmd`. Must not block.
    fn command(&mut self, cmd: &I::Command, from: &Origin, state: &mut I::Data) -> Status;

    /// Answers a validated request: `Ok` is an ACK with that payload, `Err` a NACK with
    /// the reason. Must not block.
    fn request(
        &mut self,
        req: &I::Request,
        from: &Origin,
        state: &mut I::Data,
    ) -> Result<I::Reply, Status>;

    /// Asked before `cmd` is carried out: which parts of the device it drives, and which
    /// of those are still moving from an earlier command (a new motion of the same joints
    /// or a stop cuts that one short). The host remembers which client's command drives
    /// each part and tells a client whose motion another client's command cut short that
    /// it was [`Status::Preempted`]. Default: [`Motion::NONE`] (nothing runs on by itself).
    fn motion(&mut self, cmd: &I::Command, state: &I::Data) -> Motion {
        let _ = (cmd, state);
        Motion::NONE
    }

    /// Stops every motion of the device now (the deadman: the holder of the device's
    /// lease died or missed its heartbeat). Must not block. Default: unsupported (logged
    /// by the host); every driver of moving hardware implements it.
    fn stop(&mut self, state: &mut I::Data) -> Status {
        let _ = state;
        Status::Unsupported
    }
}

/// The parts of a device a command drives, and those of them still moving
/// ([`DeviceHandler::motion`]). Bit i is a part that moves on its own: joint i of an arm;
/// a limb's joints; bit 0 for a gripper.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Motion {
    /// The parts the command drives (a new target, a speed, a stop).
    pub drives: u64,
    /// Those of them still moving now: the command cuts their motion short.
    pub cuts: u64,
}

impl Motion {
    /// Drives nothing that runs on by itself.
    pub const NONE: Motion = Motion { drives: 0, cuts: 0 };

    /// `drives`, of which the parts in `running` are still moving.
    pub const fn of(drives: u64, running: u64) -> Motion {
        Motion {
            drives,
            cuts: drives & running,
        }
    }
}

/// Who holds a device's control lease ([`DeviceHost::holder`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Holder {
    /// The holder's client id (its commands carry it).
    pub client_id: u64,
    /// The holder's iceoryx2 node id (when that node dies, the lease ends).
    pub node_id: u128,
    /// The heartbeat timeout (ns): no renewal for this long ends the lease.
    pub timeout_ns: u64,
    /// When the holder last renewed (`CLOCK_MONOTONIC` ns).
    pub last_renewal_ns: u64,
    name: [u8; 32],
}

impl Holder {
    /// The holder's name, as it gave it (empty if it is not UTF-8).
    pub fn name(&self) -> &str {
        get_name(&self.name).unwrap_or("")
    }
}

/// The shortest heartbeat timeout a lease may ask for.
pub const MIN_LEASE_TIMEOUT_NS: u64 = 10_000_000;
/// The longest heartbeat timeout a lease may ask for (one hour).
pub const MAX_LEASE_TIMEOUT_NS: u64 = 3_600_000_000_000;
/// How often the host looks whether the holder's node is still alive (listing the nodes
/// of a service costs tens of microseconds: not on every cycle).
pub const HOLDER_CHECK_NS: u64 = 20_000_000;

/// Offering a device failed ([`DeviceHost::new`], [`crate::DeviceSet::new`]).
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
    /// only its user (or root) may clean up after it (README, Security).
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

/// Publishing the state failed ([`DeviceHost::publish`]).
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

/// Receiving commands or requests failed ([`DeviceHost::process`] and its variants).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum ProcessError {
    /// Receiving from shared memory failed.
    #[error("cannot receive: {0}")]
    Receive(#[source] ReceiveError),
    /// The state carrying a command's outcome could not be published.
    #[error("cannot publish the outcome: {0}")]
    Publish(#[from] PublishError),
}

/// Counters of a host since it started.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct HostStats {
    /// Commands received.
    pub commands: u64,
    /// Commands refused (any status but ok and clamped: see `Status::is_carried_out`).
    pub refused: u64,
    /// Commands lost before the driver saw them: gaps in the sequence numbers of one of
    /// the [`CLIENT_SLOTS`] most recently active clients (only gaps that can be proven).
    pub overflows: u64,
    /// Requests answered.
    pub requests: u64,
    /// Replies that could not be delivered (client gone).
    pub undelivered_replies: u64,
    /// State samples published.
    pub published: u64,
    /// Outcome samples published (one per command, and one per preemption).
    pub outcomes: u64,
    /// Notifications to waiting clients that failed (new state or reply ready; a client
    /// waiting with a timeout re-checks anyway, so each is a delay, not a loss).
    pub failed_notifies: u64,
    /// Failed attempts to connect the state publisher to new clients (retried at the
    /// next publication or `process` call).
    pub failed_connection_updates: u64,
    /// Outcomes that could not be published on the `outcome` channel (that client then
    /// waits for it in vain, up to its timeout).
    pub failed_outcomes: u64,
    /// Commands whose motion another client's command cut short (told `Preempted`).
    pub preempted: u64,
    /// Commands and requests refused because another client held the device.
    pub leased_refusals: u64,
    /// Lease requests answered.
    pub lease_requests: u64,
    /// Deadman stops: the holder of the lease died or missed its heartbeat.
    pub deadman_stops: u64,
}

impl core::ops::AddAssign for HostStats {
    fn add_assign(&mut self, o: HostStats) {
        self.commands += o.commands;
        self.refused += o.refused;
        self.overflows += o.overflows;
        self.requests += o.requests;
        self.undelivered_replies += o.undelivered_replies;
        self.published += o.published;
        self.outcomes += o.outcomes;
        self.failed_notifies += o.failed_notifies;
        self.failed_connection_updates += o.failed_connection_updates;
        self.failed_outcomes += o.failed_outcomes;
        self.preempted += o.preempted;
        self.leased_refusals += o.leased_refusals;
        self.lease_requests += o.lease_requests;
        self.deadman_stops += o.deadman_stops;
    }
}

impl core::ops::AddAssign for Activity {
    fn add_assign(&mut self, o: Activity) {
        self.commands += o.commands;
        self.requests += o.requests;
    }
}

impl Activity {
    /// Commands plus requests.
    pub fn total(&self) -> usize {
        self.commands + self.requests
    }
}

/// How many commands and requests one call of [`DeviceHost::process`] handled.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Activity {
    /// Commands handled.
    pub commands: usize,
    /// Requests answered.
    pub requests: usize,
}

/// Clients per device whose sequence numbers are followed (the most recently active).
pub const CLIENT_SLOTS: usize = 64;

/// [`DeviceHost::process_spin`] looks for requests on every this many calls.
pub const SPIN_REQUEST_EVERY: u32 = 16;

/// Per-client last sequence number, to detect lost commands: a bounded table of the
/// [`CLIENT_SLOTS`] most recently active clients, least recently active evicted first. Fixed
/// size, no allocation.
///
/// Only gaps that can be proven are counted: a gap between two commands of a client in the
/// table. A client not in the table (new, evicted after [`CLIENT_SLOTS`] others commanded,
/// or from before a driver restart) starts a new entry and counts nothing: its earlier
/// sequence numbers may have been delivered before the entry was evicted.
struct ClientTable {
    /// (client id, last sequence number, last use); client id 0 marks a free slot.
    slots: [(u64, u64, u64); CLIENT_SLOTS],
    /// Use counter (the LRU clock).
    clock: u64,
}

impl ClientTable {
    fn new() -> Self {
        ClientTable {
            slots: [(0, 0, 0); CLIENT_SLOTS],
            clock: 0,
        }
    }

    /// Records `seq` from `client`; returns how many of its commands provably went missing
    /// since its previous one.
    fn record(&mut self, client: u64, seq: u64) -> u64 {
        self.clock += 1;
        if let Some(slot) = self.slots.iter_mut().find(|s| s.0 == client && client != 0) {
            let lost = seq.saturating_sub(slot.1.saturating_add(1));
            slot.1 = slot.1.max(seq);
            slot.2 = self.clock;
            return lost;
        }
        // Unknown: take a free slot, else the least recently active client's.
        let victim = self
            .slots
            .iter_mut()
            .min_by_key(|s| if s.0 == 0 { 0 } else { s.2 })
            .expect("CLIENT_SLOTS > 0");
        *victim = (client, seq, self.clock);
        0
    }
}

/// Loans a sample ahead of its use: a loan (taking back the samples that clients released,
/// allocating the chunk, iceoryx2's bookkeeping) costs about as much as the send, so a
/// host loans the next outcome and state samples right after it published, and a command
/// finds them ready. A failure is logged; the publication then loans for itself (and
/// reports its own failure). Clients loan their next command sample so too.
pub(crate) fn loan_ahead<T: core::fmt::Debug + ZeroCopySend>(
    port: &Publisher<ipc::Service, T, ()>,
    device: &DeviceName,
    what: &'static str,
) -> Option<SampleMutUninit<ipc::Service, MaybeUninit<T>, ()>> {
    match port.loan_uninit() {
        Ok(l) => Some(l),
        Err(e) => {
            tracing::debug!(device = %device, error = %e, "cannot loan the next {what} sample ahead");
            None
        }
    }
}

/// Offers one device of interface `I`: publishes its state, drains its commands in
/// arrival order, answers its requests, and wakes its clients.
///
/// Steady state allocates nothing: state samples are loaned from shared memory and written
/// in place, commands and requests are read in place.
pub struct DeviceHost<I: Interface> {
    device: DeviceName,
    data_svc:
        iceoryx2::service::port_factory::publish_subscribe::PortFactory<ipc::Service, I::Data, ()>,
    publisher: Publisher<ipc::Service, I::Data, ()>,
    commands: Subscriber<ipc::Service, I::CmdMsg, ()>,
    server: Server<ipc::Service, I::ReqMsg, (), I::ReplyMsg, ()>,
    wake: Option<Listener<ipc::Service>>,
    notify: Notifier<ipc::Service>,
    outcomes: Publisher<ipc::Service, OutcomeMsg, ()>,
    lease_svc: iceoryx2::service::port_factory::request_response::PortFactory<
        ipc::Service,
        LeaseReq,
        (),
        LeaseReply,
        (),
    >,
    lease_server: Server<ipc::Service, LeaseReq, (), LeaseReply, ()>,
    lease: Option<Holder>,
    next_holder_check_ns: u64,
    /// Per part of the device (bit i of [`Motion`]): the command that drives it now
    /// (client, command seq, kind); client 0: none.
    drivers: [(u64, u64, u32); 64],
    state: I::Data,
    seq: u64,
    outcome: CmdOutcome,
    flags: u32,
    clients: ClientTable,
    stats: HostStats,
    publish_each_outcome: bool,
    spin_calls: u32,
    /// A state sample loaned ahead, for the next publication (see `loan_ahead`).
    state_loan: Option<SampleMutUninit<ipc::Service, MaybeUninit<I::Data>, ()>>,
    /// An outcome sample loaned ahead, for the next command's outcome.
    outcome_loan: Option<SampleMutUninit<ipc::Service, MaybeUninit<OutcomeMsg>, ()>>,
    _i: PhantomData<I>,
    /// The domain (group mode decides whose dead processes this host may clean up). Last:
    /// dropped after the ports, so a test's domain whose last handle this is finds them gone.
    domain: crate::naming::Domain,
}

impl<I: Interface> core::fmt::Debug for DeviceHost<I> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("DeviceHost")
            .field("device", &self.device.to_string())
            .field("stats", &self.stats)
            .finish()
    }
}

fn attribute_verifier(device: &DeviceName, driver: &str) -> Result<AttributeVerifier, HostError> {
    let err = |e: Iox2Error| HostError::Transport {
        device: device.to_string(),
        channel: "attributes",
        source: e,
    };
    let kv = |k: &str, v: &str| -> Result<(AttributeKey, AttributeValue), HostError> {
        Ok((
            AttributeKey::new(k.as_bytes()).map_err(|e| err(e.into()))?,
            AttributeValue::new(v.as_bytes()).map_err(|e| err(e.into()))?,
        ))
    };
    let mut v = AttributeVerifier::new();
    for (k, val) in [
        (attr::ROBOT, device.robot().to_string()),
        (attr::INTERFACE, device.interface().name().to_string()),
        (attr::INDEX, device.index().to_string()),
        (attr::DRIVER, driver.to_string()),
        (attr::LAYOUT, limber_interfaces::LAYOUT_VERSION.to_string()),
    ] {
        let (k, val) = kv(k, &val)?;
        v = v.require(&k, &val).map_err(|e| err(e.into()))?;
    }
    Ok(v)
}

impl<I: Interface> DeviceHost<I> {
    /// Offers `device` in the context's domain, as driver `driver` (shown by
    /// `limber list`). The initial state is all zero: set it with [`DeviceHost::state_mut`]
    /// and [`DeviceHost::publish`] before clients act on it.
    pub fn new(ctx: &Context, device: &DeviceName, driver: &str) -> Result<Self, HostError> {
        if device.interface() != I::KIND {
            return Err(HostError::WrongInterface {
                device: device.to_string(),
                expected: I::KIND,
            });
        }
        let node = ctx.node();
        let dev = device.to_string();
        let verifier = attribute_verifier(device, driver)?;
        let transport = |channel: &'static str, e: Iox2Error| {
            if e.is_incompatible_attributes_or_types() {
                HostError::Incompatible {
                    device: dev.clone(),
                    source: e,
                }
            } else {
                HostError::Transport {
                    device: dev.clone(),
                    channel,
                    source: e,
                }
            }
        };

        let data_svc = node
            .service_builder(&device.service_name(Channel::Data))
            .publish_subscribe::<I::Data>()
            .history_size(1)
            .subscriber_max_buffer_size(qos::DATA_BUFFER)
            .subscriber_max_borrowed_samples(qos::DATA_BORROWED)
            .max_publishers(qos::DATA_PUBLISHERS)
            .max_subscribers(qos::MAX_CLIENTS)
            .max_nodes(qos::MAX_NODES)
            .enable_safe_overflow(true)
            .open_or_create_with_attributes(&verifier)
            .map_err(|e| transport("data", e.into()))?;
        // A live driver already publishing this device: refuse to serve it twice.
        if data_svc.dynamic_config().number_of_publishers() > 0 {
            crate::widen::cleanup_dead_nodes(&data_svc, ctx.domain());
            if data_svc.dynamic_config().number_of_publishers() > 0 {
                if let Some(owner) = dead_node_of_another_user(&data_svc, ctx) {
                    return Err(HostError::DeadDriverOfAnotherMember { device: dev, owner });
                }
                return Err(HostError::AlreadyServed { device: dev });
            }
        }
        // One sample loaned ahead for the next publication, one for anybody else.
        let publisher = data_svc
            .publisher_builder()
            .max_loaned_samples(2)
            .create()
            .map_err(|e| transport("data", e.into()))?;

        let cmd_svc = node
            .service_builder(&device.service_name(Channel::Cmd))
            .publish_subscribe::<I::CmdMsg>()
            .history_size(0)
            .subscriber_max_buffer_size(qos::CMD_BUFFER)
            .subscriber_max_borrowed_samples(2)
            .max_publishers(qos::MAX_CLIENTS)
            .max_subscribers(qos::CMD_SUBSCRIBERS)
            .max_nodes(qos::MAX_NODES)
            .enable_safe_overflow(true)
            .open_or_create_with_attributes(&verifier)
            .map_err(|e| transport("cmd", e.into()))?;
        let commands = cmd_svc
            .subscriber_builder()
            .buffer_size(qos::CMD_BUFFER)
            .create()
            .map_err(|e| transport("cmd", e.into()))?;

        let req_svc = node
            .service_builder(&device.service_name(Channel::Req))
            .request_response::<I::ReqMsg, I::ReplyMsg>()
            .max_clients(qos::MAX_CLIENTS)
            .max_servers(qos::REQ_SERVERS)
            .max_nodes(qos::MAX_NODES)
            .max_active_requests_per_client(qos::MAX_ACTIVE_REQUESTS)
            .max_response_buffer_size(2)
            .enable_fire_and_forget_requests(false)
            .open_or_create_with_attributes(&verifier)
            .map_err(|e| transport("req", e.into()))?;
        let server = req_svc
            .server_builder()
            .create()
            .map_err(|e| transport("req", e.into()))?;

        let wake_svc = node
            .service_builder(&device.service_name(Channel::Wake))
            .event()
            .max_listeners(qos::WAKE_LISTENERS)
            .max_notifiers(qos::MAX_CLIENTS)
            .max_nodes(qos::MAX_NODES)
            .open_or_create_with_attributes(&verifier)
            .map_err(|e| transport("wake", e.into()))?;
        let wake = wake_svc
            .listener_builder()
            .create()
            .map_err(|e| transport("wake", e.into()))?;

        let notify_svc = node
            .service_builder(&device.service_name(Channel::Notify))
            .event()
            .max_listeners(qos::MAX_CLIENTS)
            .max_notifiers(qos::NOTIFY_NOTIFIERS)
            .max_nodes(qos::MAX_NODES)
            .open_or_create_with_attributes(&verifier)
            .map_err(|e| transport("notify", e.into()))?;
        let notify = notify_svc
            .notifier_builder()
            .create()
            .map_err(|e| transport("notify", e.into()))?;

        let outcomes = node
            .service_builder(&device.service_name(Channel::Outcome))
            .publish_subscribe::<OutcomeMsg>()
            .history_size(0)
            .subscriber_max_buffer_size(qos::OUTCOME_BUFFER)
            .subscriber_max_borrowed_samples(2)
            .max_publishers(qos::DATA_PUBLISHERS)
            .max_subscribers(qos::MAX_CLIENTS)
            .max_nodes(qos::MAX_NODES)
            .enable_safe_overflow(true)
            .open_or_create_with_attributes(&verifier)
            .map_err(|e| transport("outcome", e.into()))?
            .publisher_builder()
            .max_loaned_samples(2)
            .create()
            .map_err(|e| transport("outcome", e.into()))?;

        let lease_svc = node
            .service_builder(&device.service_name(Channel::Lease))
            .request_response::<LeaseReq, LeaseReply>()
            .max_clients(qos::MAX_CLIENTS)
            .max_servers(qos::REQ_SERVERS)
            .max_nodes(qos::MAX_NODES)
            .max_active_requests_per_client(qos::MAX_ACTIVE_REQUESTS)
            .max_response_buffer_size(2)
            .enable_fire_and_forget_requests(false)
            .open_or_create_with_attributes(&verifier)
            .map_err(|e| transport("lease", e.into()))?;
        let lease_server = lease_svc
            .server_builder()
            .create()
            .map_err(|e| transport("lease", e.into()))?;

        // Group mode: this device's files open to the group at once.
        ctx.domain().widen_now();
        Ok(DeviceHost {
            domain: ctx.domain().clone(),
            device: device.clone(),
            data_svc,
            publisher,
            commands,
            server,
            wake: Some(wake),
            notify,
            outcomes,
            lease_svc,
            lease_server,
            lease: None,
            next_holder_check_ns: 0,
            drivers: [(0, 0, 0); 64],
            state: I::Data::default(),
            seq: 0,
            outcome: CmdOutcome::default(),
            flags: 0,
            clients: ClientTable::new(),
            stats: HostStats::default(),
            publish_each_outcome: true,
            spin_calls: 0,
            state_loan: None,
            outcome_loan: None,
            _i: PhantomData,
        })
    }

    /// The device.
    pub fn device(&self) -> &DeviceName {
        &self.device
    }

    /// The state that [`DeviceHost::publish`] sends.
    pub fn state(&self) -> &I::Data {
        &self.state
    }

    /// The state, to update before publishing.
    pub fn state_mut(&mut self) -> &mut I::Data {
        &mut self.state
    }

    /// Sets the `DEVICE_FLAG` bits carried in every sample.
    pub fn set_flags(&mut self, flags: u32) {
        self.flags = flags;
    }

    /// The flags.
    pub fn flags(&self) -> u32 {
        self.flags
    }

    /// Whether a state sample is published after every command, so each sender sees its
    /// own outcome (default: yes). Turn off to publish only when the driver calls
    /// [`DeviceHost::publish`].
    pub fn set_publish_each_outcome(&mut self, on: bool) {
        self.publish_each_outcome = on;
    }

    /// Counters.
    pub fn stats(&self) -> HostStats {
        self.stats
    }

    /// Who holds the device's control lease, if anybody.
    pub fn holder(&self) -> Option<&Holder> {
        self.lease.as_ref()
    }

    /// The listener that a client's command or request wakes, while the host owns it.
    pub fn wake_listener(&self) -> Option<&Listener<ipc::Service>> {
        self.wake.as_ref()
    }

    /// Hands the wake listener to the driver's event loop (a WaitSet attachment borrows
    /// it, so the loop must own it while the host is processed mutably). See
    /// [`crate::event_loop::run`].
    pub fn take_wake_listener(&mut self) -> Option<Listener<ipc::Service>> {
        self.wake.take()
    }

    /// Consumes pending wake-up events (without blocking) while the host owns the
    /// listener; returns how many there were.
    pub fn consume_wakeups(&self) -> u64 {
        let Some(w) = self.wake.as_ref() else {
            return 0;
        };
        match w.try_wait(|_| {}) {
            Ok(n) => n,
            Err(e) => {
                tracing::warn!(device = %self.device, error = %e, "cannot consume wake-ups");
                0
            }
        }
    }

    /// Publishes the state acquired at `stamp_ns` (`CLOCK_MONOTONIC`).
    pub fn publish_acquired(&mut self, stamp_ns: u64) -> Result<(), PublishError> {
        self.state.header_mut().stamp_ns = stamp_ns;
        self.publish()
    }

    /// Publishes the current state (with a new sequence number, the last command's outcome,
    /// the flags and the overflow count) and notifies waiting clients.
    pub fn publish(&mut self) -> Result<(), PublishError> {
        self.send_state()?;
        self.state_sent();
        Ok(())
    }

    /// The sending half of [`DeviceHost::publish`]: the header filled in and the sample
    /// sent, without notifying clients or loaning the next sample.
    fn send_state(&mut self) -> Result<(), PublishError> {
        self.seq += 1;
        let h = self.state.header_mut();
        h.seq = self.seq;
        if h.stamp_ns == 0 {
            h.stamp_ns = monotonic_ns();
        }
        h.last_cmd = self.outcome;
        h.flags = self.flags
            | if self.lease.is_some() {
                device_flag::LEASED
            } else {
                0
            };
        h.cmd_overflows = self.stats.overflows.min(u32::MAX as u64) as u32;
        self.send_verbatim()
    }

    /// Publishes the state as it is, header included (a relayed device's), and notifies;
    /// then loans the sample of the next publication, off the clients' path.
    pub(crate) fn publish_verbatim(&mut self) -> Result<(), PublishError> {
        self.send_verbatim()?;
        self.state_sent();
        Ok(())
    }

    /// Sends the state as it is.
    fn send_verbatim(&mut self) -> Result<(), PublishError> {
        let sample = match self.state_loan.take() {
            Some(s) => s,
            None => self.publisher.loan_uninit().map_err(PublishError::Loan)?,
        };
        sample
            .write_payload(self.state)
            .send()
            .map_err(PublishError::Send)?;
        self.stats.published += 1;
        Ok(())
    }

    /// After a state was sent (and the outcome or reply it goes with): notifies waiting
    /// clients, then loans the sample of the next publication, off the clients' path.
    fn state_sent(&mut self) {
        // A client that waits with a timeout re-checks anyway: counted, not fatal.
        self.notify_clients(qos::EVENT_STATE);
        self.state_loan = loan_ahead(&self.publisher, &self.device, "state");
    }

    pub(crate) fn commands_port(&self) -> &Subscriber<ipc::Service, I::CmdMsg, ()> {
        &self.commands
    }

    pub(crate) fn server_port(&self) -> &Server<ipc::Service, I::ReqMsg, (), I::ReplyMsg, ()> {
        &self.server
    }

    pub(crate) fn outcome_port(&self) -> &Publisher<ipc::Service, OutcomeMsg, ()> {
        &self.outcomes
    }

    pub(crate) fn data_port(&self) -> &Publisher<ipc::Service, I::Data, ()> {
        &self.publisher
    }

    pub(crate) fn lease_port(&self) -> &Server<ipc::Service, LeaseReq, (), LeaseReply, ()> {
        &self.lease_server
    }

    pub(crate) fn notify_clients_of(&mut self, event: usize) {
        self.notify_clients(event);
    }

    /// Notifies waiting clients; a failure is counted and logged.
    fn notify_clients(&mut self, event: usize) {
        if let Err(e) = self.notify.notify_with_custom_event_id(EventId::new(event)) {
            self.stats.failed_notifies += 1;
            tracing::debug!(device = %self.device, error = %e, "cannot notify clients");
        }
    }

    /// Connects the state publisher to clients that came since the last call, so they
    /// get the latest state (history 1) now; a failure is counted and logged.
    fn update_connections(&mut self) {
        if let Err(e) = self.publisher.update_connections() {
            self.stats.failed_connection_updates += 1;
            tracing::debug!(device = %self.device, error = %e, "cannot connect new clients");
        }
        if let Err(e) = self.outcomes.update_connections() {
            self.stats.failed_connection_updates += 1;
            tracing::debug!(device = %self.device, error = %e, "cannot connect new clients");
        }
    }

    /// Drains every pending command (in arrival order, per client in sending order) and
    /// answers every pending request, calling `handler`. Never blocks.
    pub fn process<H: DeviceHandler<I>>(
        &mut self,
        handler: &mut H,
    ) -> Result<Activity, ProcessError> {
        // New clients get the latest state (history 1) now rather than at the next
        // publication; cheap when no client came or went.
        self.update_connections();
        self.check_lease(handler)?;
        let commands = self.process_commands(handler)?;
        let requests = self.process_requests(handler)? + self.process_leases()?;
        Ok(Activity { commands, requests })
    }

    /// For a busy-polling loop: drains the commands on every call, and looks for requests
    /// only on every [`SPIN_REQUEST_EVERY`]th call (a request costs the server a poll of
    /// ~100 ns; commands are the hot path). Never blocks.
    pub fn process_spin<H: DeviceHandler<I>>(
        &mut self,
        handler: &mut H,
    ) -> Result<Activity, ProcessError> {
        self.spin_calls = self.spin_calls.wrapping_add(1);
        let commands = self.process_commands(handler)?;
        let requests = if self.spin_calls.is_multiple_of(SPIN_REQUEST_EVERY) {
            self.update_connections();
            self.check_lease(handler)?;
            self.process_requests(handler)? + self.process_leases()?
        } else {
            0
        };
        Ok(Activity { commands, requests })
    }

    /// For the linger of an event-driven loop after activity ([`crate::event_loop::linger`]):
    /// drains the commands and answers the requests and lease operations on every call, so
    /// that a client's next request in a tight loop is answered within one poll instead of
    /// up to [`SPIN_REQUEST_EVERY`] polls; connects new clients and checks the lease only on
    /// every [`SPIN_REQUEST_EVERY`]th call. Never blocks.
    pub fn process_linger<H: DeviceHandler<I>>(
        &mut self,
        handler: &mut H,
    ) -> Result<Activity, ProcessError> {
        self.spin_calls = self.spin_calls.wrapping_add(1);
        if self.spin_calls.is_multiple_of(SPIN_REQUEST_EVERY) {
            self.update_connections();
            self.check_lease(handler)?;
        }
        let commands = self.process_commands(handler)?;
        let requests = self.process_requests(handler)? + self.process_leases()?;
        Ok(Activity { commands, requests })
    }

    /// Drains every pending command. A command that does not decode is refused with the
    /// matching status without reaching the handler.
    pub fn process_commands<H: DeviceHandler<I>>(
        &mut self,
        handler: &mut H,
    ) -> Result<usize, ProcessError> {
        let mut n = 0;
        loop {
            let sample = match self.commands.receive() {
                Ok(Some(s)) => s,
                Ok(None) => break,
                Err(e) => return Err(ProcessError::Receive(e)),
            };
            let raw: &I::CmdMsg = &sample;
            let meta = *raw.meta();
            let origin = Origin {
                client_id: meta.client_id,
                seq: meta.seq,
                sent_ns: meta.stamp_ns,
                received_ns: monotonic_ns(),
            };
            self.stats.overflows += self.clients.record(meta.client_id, meta.seq);
            let holder = self.lease.filter(|l| l.client_id != meta.client_id);
            let status = match I::Command::read(raw) {
                Ok(cmd) => {
                    drop(sample);
                    if holder.is_some() {
                        self.stats.leased_refusals += 1;
                        Status::Leased
                    } else {
                        self.apply(handler, &cmd, &origin, meta.kind)
                    }
                }
                Err(e) => e.status(),
            };
            self.outcome = CmdOutcome {
                client_id: meta.client_id,
                cmd_seq: meta.seq,
                kind: meta.kind,
                status: status.code(),
            };
            // The state that shows the command goes out before its outcome: a client that
            // has seen the outcome and then takes the state sees the command's effect.
            // (Clients are notified after both.)
            let state_sent = self.publish_each_outcome.then(|| self.send_state());
            match (status, holder) {
                (Status::Leased, Some(h)) => self.publish_outcome(
                    (meta.client_id, meta.seq, meta.kind),
                    status,
                    h.client_id,
                    Some(&h.name),
                ),
                _ => self.publish_outcome((meta.client_id, meta.seq, meta.kind), status, 0, None),
            }
            self.stats.commands += 1;
            if !status.is_carried_out() {
                self.stats.refused += 1;
            }
            n += 1;
            if let Some(sent) = state_sent {
                sent?;
                self.state_sent();
            }
            // The next command's outcome sample, loaned now rather than on its path.
            if self.outcome_loan.is_none() {
                self.outcome_loan = loan_ahead(&self.outcomes, &self.device, "outcome");
            }
        }
        Ok(n)
    }

    /// Carries out one decoded command of a client allowed to command the device, and
    /// tells the client whose running motion it cuts short that it was preempted.
    fn apply<H: DeviceHandler<I>>(
        &mut self,
        handler: &mut H,
        cmd: &I::Command,
        origin: &Origin,
        kind: u32,
    ) -> Status {
        let motion = handler.motion(cmd, &self.state);
        let status = handler.command(cmd, origin, &mut self.state);
        if !status.is_carried_out() {
            return status;
        }
        let name = self
            .lease
            .filter(|l| l.client_id == origin.client_id)
            .map(|l| l.name);
        // Each other client's command whose motion this one cut short, told once.
        for bit in 0..64 {
            if motion.cuts & (1 << bit) == 0 {
                continue;
            }
            let cut = self.drivers[bit];
            let told_already =
                (0..bit).any(|b| motion.cuts & (1 << b) != 0 && self.drivers[b] == cut);
            if cut.0 != 0 && cut.0 != origin.client_id && !told_already {
                self.stats.preempted += 1;
                self.publish_outcome(cut, Status::Preempted, origin.client_id, name.as_ref());
            }
        }
        for bit in 0..64 {
            if motion.drives & (1 << bit) != 0 {
                self.drivers[bit] = (origin.client_id, origin.seq, kind);
            }
        }
        status
    }

    /// Publishes one outcome on the `outcome` channel; a failure is counted and logged
    /// (that client then waits up to its timeout), never fatal to the loop.
    fn publish_outcome(
        &mut self,
        (client_id, cmd_seq, kind): (u64, u64, u32),
        status: Status,
        other_client: u64,
        other_name: Option<&[u8; 32]>,
    ) {
        let loan = match self.outcome_loan.take() {
            Some(l) => Ok(l),
            None => self.outcomes.loan_uninit(),
        };
        let sent = match loan {
            Ok(loan) => {
                let mut msg = OutcomeMsg {
                    client_id,
                    cmd_seq,
                    other_client,
                    stamp_ns: monotonic_ns(),
                    kind,
                    status: status.code(),
                    ..OutcomeMsg::default()
                };
                if let Some(n) = other_name {
                    msg.other_name = *n;
                }
                loan.write_payload(msg).send().map_err(Iox2Error::from)
            }
            Err(e) => Err(e.into()),
        };
        if sent.is_ok() {
            self.stats.outcomes += 1;
        }
        if let Err(e) = sent {
            self.stats.failed_outcomes += 1;
            tracing::warn!(device = %self.device, client = client_id, seq = cmd_seq,
                error = %e, "cannot publish an outcome");
        }
    }

    /// The deadman: ends the lease and stops the device (with [`DeviceHandler::stop`]) when
    /// its holder's node died or its heartbeat is overdue. [`DeviceHost::process`] calls
    /// it; a driver that processes only when clients wake it calls it on its ticks too.
    /// Cheap unless a lease is held (then the holder's node is looked up at most every
    /// [`HOLDER_CHECK_NS`]).
    pub fn check_lease<H: DeviceHandler<I>>(
        &mut self,
        handler: &mut H,
    ) -> Result<(), ProcessError> {
        let Some(l) = self.lease else {
            return Ok(());
        };
        let now = monotonic_ns();
        let overdue = now.saturating_sub(l.last_renewal_ns) > l.timeout_ns;
        let dead = !overdue && now >= self.next_holder_check_ns && {
            self.next_holder_check_ns = now + HOLDER_CHECK_NS;
            self.holder_node_gone(l.node_id)
        };
        if !(overdue || dead) {
            return Ok(());
        }
        let why = if dead {
            "its process died"
        } else {
            "it missed its heartbeat"
        };
        let status = handler.stop(&mut self.state);
        tracing::warn!(device = %self.device, holder = l.name(), client = l.client_id,
            stop = %status, "lease ended because {why}: device stopped");
        self.stats.deadman_stops += 1;
        self.lease = None;
        self.drivers = [(0, 0, 0); 64];
        self.publish()?;
        Ok(())
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
    fn process_leases(&mut self) -> Result<usize, ProcessError> {
        let mut n = 0;
        let mut changed = false;
        loop {
            let active = match self.lease_server.receive() {
                Ok(Some(a)) => a,
                Ok(None) => break,
                Err(e) => return Err(ProcessError::Receive(e)),
            };
            let req: LeaseReq = *active.payload();
            let before = self.lease.map(|l| l.client_id);
            let status = self.lease_op(&req);
            changed |= before != self.lease.map(|l| l.client_id);
            let mut reply = LeaseReply {
                seq: req.seq,
                status: status.code(),
                ..LeaseReply::default()
            };
            if let Some(l) = &self.lease {
                reply.holder_client = l.client_id;
                reply.set_holder_node(l.node_id);
                reply.timeout_ns = l.timeout_ns;
                reply.holder_name = l.name;
            }
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

    /// Applies one lease request.
    fn lease_op(&mut self, req: &LeaseReq) -> Status {
        let now = monotonic_ns();
        let other = self.lease.is_some_and(|l| l.client_id != req.client_id);
        match req.op {
            lease_op::ACQUIRE => {
                if other {
                    return Status::Leased;
                }
                if req.client_id == 0
                    || req.node_id() == 0
                    || !(MIN_LEASE_TIMEOUT_NS..=MAX_LEASE_TIMEOUT_NS).contains(&req.timeout_ns)
                    || get_name(&req.name).is_err()
                {
                    return Status::InvalidArgument;
                }
                let mut name = [0u8; 32];
                put_name(&mut name, get_name(&req.name).unwrap_or(""));
                self.lease = Some(Holder {
                    client_id: req.client_id,
                    node_id: req.node_id(),
                    timeout_ns: req.timeout_ns,
                    last_renewal_ns: now,
                    name,
                });
                tracing::info!(device = %self.device, holder = get_name(&name).unwrap_or(""),
                    client = req.client_id, "lease acquired");
                Status::Ok
            }
            lease_op::RENEW => {
                if other {
                    return Status::Leased;
                }
                // Not held (ended or never taken): the reply names no holder.
                if let Some(l) = self.lease.as_mut() {
                    l.last_renewal_ns = now;
                }
                Status::Ok
            }
            lease_op::RELEASE => {
                if other {
                    return Status::Leased;
                }
                if self.lease.take().is_some() {
                    tracing::info!(device = %self.device, client = req.client_id, "lease released");
                }
                Status::Ok
            }
            lease_op::QUERY => Status::Ok,
            _ => Status::InvalidArgument,
        }
    }

    /// Answers every pending request. A request that does not decode is NACKed with the
    /// matching status without reaching the handler.
    pub fn process_requests<H: DeviceHandler<I>>(
        &mut self,
        handler: &mut H,
    ) -> Result<usize, ProcessError> {
        let mut n = 0;
        let mut state_result: Option<Result<(), PublishError>> = None;
        loop {
            let active: ActiveRequest<ipc::Service, I::ReqMsg, (), I::ReplyMsg, ()> =
                match self.server.receive() {
                    Ok(Some(a)) => a,
                    Ok(None) => break,
                    Err(e) => return Err(ProcessError::Receive(e)),
                };
            let raw: &I::ReqMsg = active.payload();
            let meta = *raw.meta();
            let origin = Origin {
                client_id: meta.client_id,
                seq: meta.seq,
                sent_ns: meta.stamp_ns,
                received_ns: monotonic_ns(),
            };
            let holder = self.lease.filter(|l| l.client_id != meta.client_id);
            let parsed = I::Request::read(raw);
            let mutating = !matches!(&parsed, Ok(r) if r.is_read_only());
            let reply = match parsed {
                Ok(req) if holder.is_some() && !req.is_read_only() => {
                    self.stats.leased_refusals += 1;
                    Err(Status::Leased)
                }
                Ok(req) => handler.request(&req, &origin, &mut self.state),
                Err(e) => Err(e.status()),
            };
            // What a request that may change the device (power, brakes, ...) did is in
            // the state sent before its reply, as for commands (the first failure kept).
            if mutating && self.publish_each_outcome {
                let sent = self.send_state();
                if !matches!(state_result, Some(Err(_))) {
                    state_result = Some(sent);
                }
            }
            let sent = match active.loan_uninit() {
                Ok(loan) => {
                    let mut resp = loan.write_payload(I::ReplyMsg::default());
                    let out: &mut I::ReplyMsg = resp.payload_mut();
                    I::Reply::write(meta.kind, reply.as_ref().map_err(|s| *s), out);
                    let m = out.meta_mut();
                    m.client_id = meta.client_id;
                    m.seq = meta.seq;
                    m.stamp_ns = monotonic_ns();
                    resp.send().map_err(Iox2Error::from)
                }
                Err(e) => Err(e.into()),
            };
            if let Err(e) = sent {
                // The client is gone (or gave up): not fatal, counted.
                self.stats.undelivered_replies += 1;
                tracing::debug!(
                    device = %self.device,
                    client = meta.client_id,
                    seq = meta.seq,
                    error = %e,
                    "reply not delivered"
                );
            }
            drop(active);
            self.stats.requests += 1;
            n += 1;
            self.notify_clients(qos::EVENT_REPLY);
        }
        match state_result {
            Some(sent) => {
                sent?;
                self.state_sent();
            }
            // A read-only request's state, as before: the latest, published at once.
            None if n > 0 && self.publish_each_outcome => self.publish()?,
            None => {}
        }
        Ok(n)
    }

    /// Removes the resources of dead processes (crashed clients) from this device's
    /// services (in group mode, of this user's processes only: README, Security). Cheap
    /// enough for a 1 Hz housekeeping tick, not for every cycle.
    pub fn cleanup_dead(&self) {
        crate::widen::cleanup_dead_nodes(&self.data_svc, &self.domain);
        crate::widen::cleanup_dead_nodes(&self.lease_svc, &self.domain);
    }
}

/// In group mode, the user of a dead node of `svc` that belongs to another user (its node
/// directory is theirs: only they may clean it up), as `user NAME (uid N)`.
fn dead_node_of_another_user<
    P: iceoryx2::service::port_factory::PortFactory<Service = ipc::Service>,
>(
    svc: &P,
    ctx: &Context,
) -> Option<String> {
    use std::os::unix::fs::MetadataExt;
    ctx.domain().group().ok().flatten()?;
    let nodes = ctx.domain().root().ok()?.join("nodes");
    let mut owner = None;
    if let Err(e) = svc.nodes(|n| {
        if let NodeState::Dead(v) = &n
            && let Ok(md) = std::fs::symlink_metadata(nodes.join(v.id().value().to_string()))
            && md.uid() != crate::domain_dir::euid()
        {
            owner = Some(crate::domain_dir::describe_user(md.uid()));
        }
        CallbackProgression::Continue
    }) {
        tracing::warn!(error = %e, "cannot list the nodes of a device");
    }
    owner
}

#[cfg(test)]
mod tests {
    use super::{CLIENT_SLOTS, ClientTable};

    #[test]
    fn gaps_of_a_followed_client_are_counted_exactly() {
        let mut t = ClientTable::new();
        assert_eq!(t.record(7, 1), 0);
        assert_eq!(t.record(7, 2), 0);
        // 3 and 4 went missing.
        assert_eq!(t.record(7, 5), 2);
        // A late or repeated one is no loss and does not move the mark back.
        assert_eq!(t.record(7, 4), 0);
        assert_eq!(t.record(7, 6), 0);
    }

    /// Issue 12, item 11: after more than `CLIENT_SLOTS` other clients commanded, a
    /// long-lived client's next command counted `seq - 1` overflows.
    #[test]
    fn a_forgotten_client_is_not_counted_as_losing_its_history() {
        let mut t = ClientTable::new();
        let mut lost = 0;
        for seq in 1..=1000 {
            lost += t.record(1, seq);
        }
        for other in 0..70u64 {
            lost += t.record(1000 + other, 1);
        }
        // Client 1 was evicted (the least recently active): its next command proves no gap.
        lost += t.record(1, 1001);
        assert_eq!(lost, 0);
        // Followed again from there on.
        assert_eq!(t.record(1, 1003), 1);
    }

    #[test]
    fn an_active_client_is_never_evicted_by_many_one_shot_clients() {
        let mut t = ClientTable::new();
        let mut seq = 0;
        for other in 0..(10 * CLIENT_SLOTS as u64) {
            seq += 1;
            assert_eq!(t.record(1, seq), 0);
            assert_eq!(t.record(1000 + other, 1), 0);
        }
        // Still followed: a gap is still seen.
        assert_eq!(t.record(1, seq + 3), 2);
        // Bounded: the table holds CLIENT_SLOTS entries whatever the number of clients.
        assert_eq!(t.slots.len(), CLIENT_SLOTS);
    }
}
