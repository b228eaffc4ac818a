//! The driver side: [`DeviceHost`] offers one device and [`DeviceHandler`] is what a driver
//! implements for each interface it serves.
//!
//! The host does the port I/O; the decisions are the arbiter's, which does none:
//!
//! * [`handler`]: [`DeviceHandler`], [`Origin`], [`Motion`]: what a driver implements.
//! * [`error`], [`stats`]: how offering and processing fail, and what the host counts.
//! * `open`: opening the device's channels ([`DeviceHost::new`]).
//! * `arbiter`: who may command the device (leases, the deadman), preemption, the
//!   per-client gap table (`gaps`) and the outcome rules; plain data in, decisions out.
//! * `commands`, `requests`, `lease`: draining each channel around the arbiter.

use core::marker::PhantomData;
use core::mem::MaybeUninit;

use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::server::Server;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::port::update_connections::{ConnectionFailure, UpdateConnections};
use iceoryx2::prelude::*;
use iceoryx2::sample_mut_uninit::SampleMutUninit;
use limber_interfaces::prelude::*;

use crate::context::monotonic_ns;
use crate::domain::Domain;
use crate::naming::DeviceName;
use crate::qos;

mod arbiter;
mod commands;
pub mod error;
mod gaps;
pub mod handler;
mod lease;
mod motions;
mod open;
mod peers;
mod requests;
mod senders;
pub mod stats;
pub(crate) mod told;

use arbiter::Arbiter;
pub use arbiter::{HOLDER_CHECK_NS, Holder, MAX_LEASE_TIMEOUT_NS, MIN_LEASE_TIMEOUT_NS};
pub use error::{HostError, ProcessError, PublishError};
pub use gaps::CLIENT_SLOTS;
pub use handler::{DeviceHandler, Motion, Origin, Progress};
pub use motions::MAX_TRACKED;
pub use stats::{Activity, HostStats};

/// [`DeviceHost::process_spin`] looks for requests on every this many calls.
pub const SPIN_REQUEST_EVERY: u32 = 16;

/// [`DeviceHost::cleanup_dead`] looks at every node of the device's services at least this
/// often, whether or not a peer's process was seen gone.
pub const FULL_CLEANUP_EVERY: std::time::Duration = std::time::Duration::from_secs(60);

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

/// A command as the transport hands it to the driver, read in place.
type CmdSample<I> = iceoryx2::sample::Sample<ipc::Service, <I as Interface>::CmdMsg, ()>;

/// Offers one device of interface `I`: publishes its state, takes its clients' commands
/// fairly (in rounds across clients, each client's in its sending order), answers its
/// requests, and wakes its clients.
///
/// Steady state allocates nothing: state samples are loaned from shared memory and written
/// in place, commands and requests are read in place.
pub struct DeviceHost<I: Interface> {
    device: DeviceName,
    data_svc:
        iceoryx2::service::port_factory::publish_subscribe::PortFactory<ipc::Service, I::Data, ()>,
    publisher: Publisher<ipc::Service, I::Data, ()>,
    /// Bumped with every state published: the clients in `wait_state` sleep on it
    /// ([`crate::wake`]); None if it could not be made.
    state_wake: Option<crate::wake::WakeWord>,
    commands: Subscriber<ipc::Service, I::CmdMsg, ()>,
    /// One round of commands taken fairly (see `commands.rs`), each with when it was taken
    /// (`CLOCK_MONOTONIC` ns, its [`Origin::received_ns`]): allocated once, for every
    /// client's [`qos::CMD_BORROWED`].
    cmd_round: Vec<(CmdSample<I>, u64)>,
    /// The `cmd` service, whose registry says which node each command's publisher is.
    cmd_svc: iceoryx2::service::port_factory::publish_subscribe::PortFactory<
        ipc::Service,
        I::CmdMsg,
        (),
    >,
    /// The `req` service, whose registry says which node each request's client is.
    req_svc: iceoryx2::service::port_factory::request_response::PortFactory<
        ipc::Service,
        I::ReqMsg,
        (),
        I::ReplyMsg,
        (),
    >,
    /// Who sent each command, request and lease request (see `senders.rs`).
    cmd_senders: senders::PortNodes,
    /// Commands dropped because their client id named another process than their sender.
    forged: u64,
    /// How many peer ports the device's services had when last looked at
    /// ([`DeviceHost::guard_new_peers`]).
    peers_seen: usize,
    /// When [`DeviceHost::cleanup_dead`] looks at every node of the services again, a peer
    /// seen gone or not (`None`: at its first call).
    full_cleanup_at: std::cell::Cell<Option<std::time::Instant>>,
    req_senders: senders::PortNodes,
    lease_senders: senders::PortNodes,
    server: Server<ipc::Service, I::ReqMsg, (), I::ReplyMsg, ()>,
    wake: Option<Listener<ipc::Service>>,
    notify: Notifier<ipc::Service>,
    /// The outcome ports: each client's stream, and every outcome for watchers.
    out: told::Outcomes,
    lease_svc: iceoryx2::service::port_factory::request_response::PortFactory<
        ipc::Service,
        LeaseReq,
        (),
        LeaseReply,
        (),
    >,
    lease_server: Server<ipc::Service, LeaseReq, (), LeaseReply, ()>,
    /// Leases, preemption, the gap table and the outcome rules: no I/O.
    arbiter: Arbiter,
    /// The motions running, each to end with a result (see `motions.rs`).
    motions: motions::Motions,
    /// The lease the deadman ended here and why, until the [`DeviceSet`](crate::DeviceSet)
    /// stops the other devices that shared it (see `lease.rs`).
    lease_ended: Option<(Holder, &'static str)>,
    state: I::Data,
    seq: u64,
    outcome: CmdOutcome,
    flags: u32,
    stats: HostStats,
    publish_each_outcome: bool,
    spin_calls: u32,
    /// A state sample loaned ahead, for the next publication (see `loan_ahead`).
    state_loan: Option<SampleMutUninit<ipc::Service, MaybeUninit<I::Data>, ()>>,
    _i: PhantomData<I>,
    /// The domain (group mode decides whose dead processes this host may clean up). Last:
    /// dropped after the ports, so a test's domain whose last handle this is finds them gone.
    domain: Domain,
}

impl<I: Interface> core::fmt::Debug for DeviceHost<I> {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("DeviceHost")
            .field("device", &self.device.to_string())
            .field("stats", &self.stats)
            .finish()
    }
}

impl<I: Interface> DeviceHost<I> {
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
        self.arbiter.holder()
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
        // A driver's tick: whoever began to watch the outcomes gets those from now on.
        self.out.look_for_watchers();
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
            | if self.arbiter.holder().is_some() {
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
        // The send connects to new clients first.
        self.guard_new_peers();
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
        // The clients asleep in `wait_state` first: one system call wakes them all.
        if let Some(w) = &self.state_wake {
            w.bump();
        }
        // A client that waits with a timeout re-checks anyway: counted, not fatal.
        self.notify_clients(qos::EVENT_STATE);
        self.state_loan = loan_ahead(&self.publisher, &self.device, "state");
    }

    pub(crate) fn server_port(&self) -> &Server<ipc::Service, I::ReqMsg, (), I::ReplyMsg, ()> {
        &self.server
    }

    /// Connects the `outcome` publisher to watchers that came, and looks whether anybody
    /// watches (a relay's housekeeping).
    pub(crate) fn update_outcome_connections(&mut self) -> Result<(), ConnectionFailure> {
        self.out.update_connections()
    }

    /// Sends an outcome as given to the client it names and to the watchers (a relay's).
    pub(crate) fn relay_outcome_message(&mut self, msg: &OutcomeMsg) -> Result<(), PublishError> {
        self.out.send(&mut self.stats, &self.device, msg)
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
        self.connect_state();
        self.accept_streams();
        self.connect_outcomes();
    }

    /// [`DeviceHost::update_connections`]' first part: the state publisher.
    fn connect_state(&mut self) {
        self.guard_new_peers();
        if let Err(e) = self.publisher.update_connections() {
            self.stats.failed_connection_updates += 1;
            tracing::debug!(device = %self.device, error = %e, "cannot connect new clients");
        }
    }

    /// [`DeviceHost::update_connections`]' second part: new streams. A client that found
    /// its stream closed (a restarted driver) asks again, without a command to bring the
    /// driver to it.
    fn accept_streams(&mut self) {
        self.out.accept(&self.device);
    }

    /// [`DeviceHost::update_connections`]' third part: the `outcome` publisher.
    fn connect_outcomes(&mut self) {
        if let Err(e) = self.out.update_connections() {
            self.stats.failed_connection_updates += 1;
            tracing::debug!(device = %self.device, error = %e, "cannot connect new clients");
        }
    }

    /// Takes the pending commands (fairly, in rounds across clients, each client's in its
    /// sending order: [`DeviceHost::process_commands`]) and
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

    /// For a busy-polling loop: drains the commands on every call, and does one of the
    /// looks that commands do not need on some of the calls, each look on a call of its
    /// own, each once every [`SPIN_REQUEST_EVERY`] calls: the three parts of connecting new
    /// clients, the lease's check, the requests, the lease operations. A look costs the
    /// loop some 35-110 ns (all four together took ~480 ns on the project's 2-core VM); a
    /// command that arrives meanwhile waits for one look, not for all of them. Never blocks.
    pub fn process_spin<H: DeviceHandler<I>>(
        &mut self,
        handler: &mut H,
    ) -> Result<Activity, ProcessError> {
        self.spin_calls = self.spin_calls.wrapping_add(1);
        let commands = self.process_commands(handler)?;
        // Six looks spread over the SPIN_REQUEST_EVERY calls.
        const STEP: u32 = SPIN_REQUEST_EVERY / 8;
        let phase = self.spin_calls % SPIN_REQUEST_EVERY;
        let requests = if !phase.is_multiple_of(STEP) {
            0
        } else {
            match phase / STEP {
                0 => {
                    self.connect_state();
                    0
                }
                1 => {
                    self.accept_streams();
                    0
                }
                2 => {
                    self.connect_outcomes();
                    0
                }
                3 => {
                    self.check_lease(handler)?;
                    0
                }
                4 => self.process_requests(handler)?,
                5 => self.process_leases()?,
                _ => 0,
            }
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

    /// Removes the resources of dead processes (crashed clients) from this device's
    /// services (in group mode, of this user's processes only: docs/guide/security.md), when
    /// a port of them names a process that is gone, and at least every
    /// [`FULL_CLEANUP_EVERY`] (a dead client's process id taken meanwhile by another
    /// process hides it from the first look). The look costs some 10-50 µs with 64
    /// clients; the cleanup itself reads every node's files (about 1 ms with 64 clients,
    /// up to 15 ms, on the project's 2-core VM), so it runs only when there is something
    /// to clean up. For a 1 Hz housekeeping tick, not for every cycle.
    pub fn cleanup_dead(&self) {
        let now = std::time::Instant::now();
        let due = self.full_cleanup_at.get().is_none_or(|at| now >= at);
        if !due && !self.a_peer_is_gone() {
            return;
        }
        self.full_cleanup_at.set(Some(now + FULL_CLEANUP_EVERY));
        self.domain.cleanup_dead_nodes(&self.data_svc);
        self.domain.cleanup_dead_nodes(&self.lease_svc);
        self.domain.cleanup_dead_nodes(&self.out.told_svc);
    }
}
