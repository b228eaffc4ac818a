//! `limber bridge mirror`: remote devices hosted in a local domain.
//!
//! Every device whose liveliness token (`.../alive`) a remote `expose` holds is hosted in
//! this domain under the same name (the robot name prefixed with `--prefix`, if given), as
//! driver `bridge`: its state is the remote state (stamped with this host's clock when it
//! arrives), its clients' commands go to `.../cmd/<origin>`, their outcomes (refusals with
//! their reason, preemptions) come back from `.../outcome/<origin>` to the client that sent
//! the command, and their requests become queries on `.../req/<origin>` with a timeout. The
//! origin is this mirror's principal (who the exposing bridge's authentication says it is:
//! [`crate::access`]) and its Zenoh id. It listens on nothing and scouts for nobody: it
//! talks only to the bridge it connects to, and hosts [`MirrorConfig::max_devices`] devices
//! at most. When the token goes (the remote driver died, or
//! the remote bridge, or the network for longer than the Zenoh lease), the device is no
//! longer hosted here: its clients see its driver gone.
//!
//! Slightly over 800 lines, for a stated reason: the issue "Nobody moves the arm who may
//! not" reworks who the mirror trusts and how many devices it hosts; the split follows that
//! rework rather than preceding it.

use std::collections::HashMap;
use std::rc::Rc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::{Duration, Instant};

use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::ipc;
use limber_interfaces::diagnostics::DriverStats;
use limber_interfaces::prelude::*;
use limber_interfaces::{HasHeader, Interface};
use limber_services::diagnostics::StatsPublisher;
use limber_services::relay::{RelayedLease, RelayedRequest};
use limber_services::{Context, DeviceHost, DeviceName, Domain, Role, monotonic_ns};
use thiserror::Error;
use zenoh::Wait;
use zenoh::handlers::CallbackDrop;
use zenoh::query::{ConsolidationMode, Reply, ReplyError};
use zenoh::sample::{Sample, SampleKind};
use zenoh::{Session, bytes::ZBytes};
use zerocopy::{FromBytes, IntoBytes};

use crate::access;
use crate::expose::MIRROR_DRIVER;
use crate::inbox::{Inbox, InboxError, Sender};
use crate::keys::{self, TypeNames};
use crate::session::{self, ControlPublishers, NetConfig, SessionError};
use crate::waiting::{Attached, Owed, with_waitset};

/// The longest the loop sleeps with nothing to do, between two looks at `stop` (a signal
/// wakes it at once).
const IDLE_WAIT: Duration = Duration::from_millis(250);

/// How `mirror` runs.
#[derive(Debug, Clone)]
pub struct MirrorConfig {
    /// The network side.
    pub net: NetConfig,
    /// Prepended to each remote robot name (where local names would collide).
    pub prefix: String,
    /// How long a relayed request may take before its client is told `Timeout`.
    pub request_timeout: Duration,
    /// Who this mirror is to the exposing bridge: its principal (the certificate common
    /// name of its TLS client certificate); None: the user of its user/password
    /// authentication, else `local` (the owner's Unix socket). See [`crate::access`].
    pub principal: Option<String>,
    /// The most remote devices hosted at once; more are refused (a peer that announces
    /// thousands of devices does not make this process take their memory).
    pub max_devices: usize,
}

/// The default of [`MirrorConfig::max_devices`].
pub const DEFAULT_MAX_DEVICES: usize = 64;

impl Default for MirrorConfig {
    fn default() -> Self {
        MirrorConfig {
            net: NetConfig::default(),
            prefix: String::new(),
            request_timeout: Duration::from_millis(1800),
            principal: None,
            max_devices: DEFAULT_MAX_DEVICES,
        }
    }
}

/// What `mirror` reports as it runs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum MirrorEvent {
    /// The Zenoh session is open.
    Ready {
        /// This bridge's Zenoh id.
        zid: String,
        /// The principal it acts as (see [`crate::access`]).
        principal: String,
    },
    /// A remote device is hosted here now, under `local`.
    Mirrored {
        /// Its name on the robot.
        remote: DeviceName,
        /// Its name here.
        local: DeviceName,
    },
    /// A remote device went away (its driver, its bridge or the network): no longer hosted.
    Gone {
        /// Its name here.
        local: DeviceName,
    },
    /// A remote device could not be hosted here.
    Refused {
        /// Its name on the robot.
        remote: DeviceName,
        /// Why.
        reason: String,
    },
}

/// `mirror` failed.
#[derive(Debug, Error)]
pub enum MirrorError {
    /// The Zenoh session could not be opened.
    #[error(transparent)]
    Session(#[from] SessionError),
    /// The domain could not be joined.
    #[error("cannot join domain {domain}: {source}")]
    Domain {
        /// The domain.
        domain: String,
        /// Why.
        #[source]
        source: limber_services::ContextError,
    },
    /// The prefix would not make valid robot names.
    #[error("invalid prefix {0:?}: use characters of [A-Za-z0-9_-]")]
    Prefix(String),
    /// A Zenoh subscription could not be declared.
    #[error("cannot subscribe to {key}: {source}")]
    Subscribe {
        /// The key expression.
        key: String,
        /// Zenoh's error.
        #[source]
        source: zenoh::Error,
    },
    /// The loop's wake-up could not be made.
    #[error(transparent)]
    Inbox(#[from] InboxError),
    /// The loop's WaitSet could not be set up or waited on.
    #[error(transparent)]
    Loop(#[from] limber_services::event_loop::LoopError),
}

/// Which kind of query a reply belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Exchange {
    /// A request (`.../req`).
    Request,
    /// A lease request (`.../lease`).
    Lease,
}

/// What Zenoh delivers to the loop (remote device names).
enum Event {
    Alive {
        device: DeviceName,
        present: bool,
    },
    State {
        device: DeviceName,
        payload: Vec<u8>,
    },
    Outcome {
        device: DeviceName,
        payload: Vec<u8>,
    },
    /// A reply to relayed query `id`.
    Reply {
        device: DeviceName,
        exchange: Exchange,
        id: u64,
        reply: Reply,
    },
    /// A robot's driver statistics.
    Stats {
        robot: String,
        payload: Vec<u8>,
    },
    /// Relayed query `id` is over: answered, timed out, or nobody was there to ask.
    Done {
        device: DeviceName,
        exchange: Exchange,
        id: u64,
    },
}

struct Mirrored<I: Interface> {
    local: DeviceName,
    remote: DeviceName,
    host: DeviceHost<I>,
    cmd_key: String,
    /// The commands' publisher.
    commands: ControlPublishers,
    req_key: String,
    lease_key: String,
    names: TypeNames,
    tx: Sender<Event>,
    requests: HashMap<u64, (RelayedRequest<I>, Instant)>,
    leases: HashMap<u64, (RelayedLease, Instant)>,
    /// Notified when a local client sent a command, a request or a lease request, or came.
    listener: Rc<Listener<ipc::Service>>,
}

trait MirroredDevice {
    fn state(&mut self, payload: &[u8]);
    fn outcome(&mut self, payload: &[u8]);
    /// Relays what the local clients sent: commands, requests, lease requests; says whether
    /// it put anything on Zenoh that an answer comes back for.
    fn relay(&mut self, session: &Session, timeout: Duration) -> bool;
    fn reply(&mut self, exchange: Exchange, id: u64, reply: &Reply);
    fn done(&mut self, exchange: Exchange, id: u64);
    fn listener(&self) -> Rc<Listener<ipc::Service>>;
}

/// The status of a relayed query that got no reply: `Timeout` once its deadline has
/// passed, `LinkDown` before (nobody was there to ask).
fn unanswered(deadline: Instant) -> Status {
    if Instant::now() >= deadline {
        Status::Timeout
    } else {
        Status::LinkDown
    }
}

/// The status an error reply carries: `expose`'s is a `Status` code (4 bytes,
/// little-endian, schema `limber.Status`); Zenoh's own (its timeout) counts as no reply.
fn status_of(err: &ReplyError, deadline: Instant) -> Status {
    if *err.encoding() != keys::encoding(keys::STATUS_TYPE) {
        return unanswered(deadline);
    }
    let bytes: &ZBytes = err.payload();
    <[u8; 4]>::try_from(bytes.to_bytes().as_ref())
        .ok()
        .and_then(|b| Status::try_from(u32::from_le_bytes(b)).ok())
        .unwrap_or(Status::LinkDown)
}

/// A new id for a relayed query, never given before in this process (so that the end of
/// a query of a device that went and came back is never taken for a new one's).
fn next_query_id() -> u64 {
    static NEXT: AtomicU64 = AtomicU64::new(1);
    NEXT.fetch_add(1, Ordering::Relaxed)
}

/// Sends query `id` of `device` on `key`; its replies and its end come back through `tx`.
fn ask(
    session: &Session,
    tx: &Sender<Event>,
    (device, exchange, id): (&DeviceName, Exchange, u64),
    key: &str,
    (payload, type_name): (&[u8], &str),
    timeout: Duration,
) -> Result<(), zenoh::Error> {
    let (on_reply, on_done) = (tx.clone(), tx.clone());
    let (d1, d2) = (device.clone(), device.clone());
    session
        .get(key)
        .payload(payload.to_vec())
        .encoding(keys::encoding(type_name))
        .timeout(timeout)
        // One reply is expected: delivered as it arrives, not held until the query ends.
        .consolidation(ConsolidationMode::None)
        .with(CallbackDrop {
            callback: move |reply: Reply| {
                let ev = Event::Reply {
                    device: d1.clone(),
                    exchange,
                    id,
                    reply,
                };
                if on_reply.send(ev).is_err() {
                    tracing::debug!("the bridge is ending: reply dropped");
                }
            },
            drop: move || {
                let ev = Event::Done {
                    device: d2.clone(),
                    exchange,
                    id,
                };
                if on_done.send(ev).is_err() {
                    tracing::debug!("the bridge is ending: end of a query dropped");
                }
            },
        })
        .wait()
}

impl<I: Interface> MirroredDevice for Mirrored<I> {
    fn state(&mut self, payload: &[u8]) {
        let Ok(mut data) = I::Data::read_from_bytes(payload) else {
            tracing::warn!(device = %self.local, len = payload.len(),
                "a state of the wrong size ({} expected): dropped", self.names.data);
            return;
        };
        // The remote clock means nothing here: the state is as old as its arrival.
        data.header_mut().stamp_ns = monotonic_ns();
        if let Err(e) = self.host.relay_publish(&data) {
            tracing::warn!(device = %self.local, error = %e, "cannot publish a state");
        }
    }

    fn outcome(&mut self, payload: &[u8]) {
        let Ok(mut o) = OutcomeMsg::read_from_bytes(payload) else {
            tracing::warn!(device = %self.local, len = payload.len(),
                "an outcome of the wrong size: dropped");
            return;
        };
        o.stamp_ns = monotonic_ns();
        if let Err(e) = self.host.relay_outcome(&o) {
            tracing::warn!(device = %self.local, error = %e, "cannot publish an outcome");
        }
    }

    fn relay(&mut self, session: &Session, timeout: Duration) -> bool {
        self.host.relay_housekeeping();
        let mut commands = Vec::new();
        if let Err(e) = self
            .host
            .relay_commands(|c| commands.push(c.as_bytes().to_vec()))
        {
            tracing::warn!(device = %self.local, error = %e, "cannot take the commands");
        }
        let mut asked = !commands.is_empty();
        for c in commands {
            if let Err(e) = self.commands.put(session, &self.cmd_key, c) {
                tracing::warn!(device = %self.local, error = %e, "cannot relay a command");
            }
        }
        loop {
            let req = match self.host.relay_take_request() {
                Ok(Some(r)) => r,
                Ok(None) => break,
                Err(e) => {
                    tracing::warn!(device = %self.local, error = %e, "cannot take the requests");
                    break;
                }
            };
            let id = next_query_id();
            let deadline = Instant::now() + timeout;
            match ask(
                session,
                &self.tx,
                (&self.remote, Exchange::Request, id),
                &self.req_key,
                (req.message().as_bytes(), self.names.req),
                timeout,
            ) {
                Ok(()) => {
                    self.requests.insert(id, (req, deadline));
                    asked = true;
                }
                Err(e) => {
                    tracing::warn!(device = %self.local, error = %e, "cannot relay a request");
                    let out = keys::nack::<I>(req.message(), Status::LinkDown);
                    if let Err(e) = self.host.relay_answer(req, &out) {
                        tracing::debug!(device = %self.local, error = %e, "reply not delivered");
                    }
                }
            }
        }
        loop {
            let req = match self.host.relay_take_lease() {
                Ok(Some(r)) => r,
                Ok(None) => break,
                Err(e) => {
                    tracing::warn!(device = %self.local, error = %e, "cannot take the lease requests");
                    break;
                }
            };
            let id = next_query_id();
            let deadline = Instant::now() + timeout;
            match ask(
                session,
                &self.tx,
                (&self.remote, Exchange::Lease, id),
                &self.lease_key,
                (req.message().as_bytes(), keys::lease_req_type()),
                timeout,
            ) {
                Ok(()) => {
                    self.leases.insert(id, (req, deadline));
                    asked = true;
                }
                Err(e) => {
                    tracing::warn!(device = %self.local, error = %e, "cannot relay a lease request");
                    let out = lease_nack(req.message(), Status::LinkDown);
                    if let Err(e) = self.host.relay_answer_lease(req, &out) {
                        tracing::debug!(device = %self.local, error = %e, "reply not delivered");
                    }
                }
            }
        }
        asked
    }

    fn reply(&mut self, exchange: Exchange, id: u64, reply: &Reply) {
        match exchange {
            Exchange::Request => {
                let Some((req, deadline)) = self.requests.remove(&id) else {
                    return; // answered already
                };
                let answer = match reply.result() {
                    Ok(sample) => I::ReplyMsg::read_from_bytes(&sample.payload().to_bytes())
                        .unwrap_or_else(|_| {
                            tracing::warn!(device = %self.local, "a reply of the wrong size");
                            keys::nack::<I>(req.message(), Status::LinkDown)
                        }),
                    Err(err) => keys::nack::<I>(req.message(), status_of(err, deadline)),
                };
                self.answer(req, &answer);
            }
            Exchange::Lease => {
                let Some((req, deadline)) = self.leases.remove(&id) else {
                    return;
                };
                let answer = match reply.result() {
                    Ok(sample) => LeaseReply::read_from_bytes(&sample.payload().to_bytes())
                        .unwrap_or_else(|_| lease_nack(req.message(), Status::LinkDown)),
                    Err(err) => lease_nack(req.message(), status_of(err, deadline)),
                };
                self.answer_lease(req, &answer);
            }
        }
    }

    fn done(&mut self, exchange: Exchange, id: u64) {
        match exchange {
            Exchange::Request => {
                if let Some((req, deadline)) = self.requests.remove(&id) {
                    let out = keys::nack::<I>(req.message(), unanswered(deadline));
                    self.answer(req, &out);
                }
            }
            Exchange::Lease => {
                if let Some((req, deadline)) = self.leases.remove(&id) {
                    let out = lease_nack(req.message(), unanswered(deadline));
                    self.answer_lease(req, &out);
                }
            }
        }
    }

    fn listener(&self) -> Rc<Listener<ipc::Service>> {
        Rc::clone(&self.listener)
    }
}

/// The refusal of lease request `req` with `status`.
fn lease_nack(req: &LeaseReq, status: Status) -> LeaseReply {
    LeaseReply {
        seq: req.seq,
        status: status.code(),
        ..LeaseReply::default()
    }
}

impl<I: Interface> Mirrored<I> {
    fn answer(&mut self, req: RelayedRequest<I>, reply: &I::ReplyMsg) {
        if let Err(e) = self.host.relay_answer(req, reply) {
            tracing::debug!(device = %self.local, error = %e, "reply not delivered");
        }
    }

    fn answer_lease(&mut self, req: RelayedLease, reply: &LeaseReply) {
        if let Err(e) = self.host.relay_answer_lease(req, reply) {
            tracing::debug!(device = %self.local, error = %e, "lease reply not delivered");
        }
    }
}

/// [`host_device`] for a device of any interface.
struct Host<'a> {
    ctx: &'a Context,
    remote: &'a DeviceName,
    local: &'a DeviceName,
    origin: &'a str,
    tx: &'a Sender<Event>,
}

impl InterfaceVisitor for Host<'_> {
    type Output = Result<Box<dyn MirroredDevice>, String>;
    fn visit<I: Interface>(self) -> Self::Output {
        host_device::<I>(self.ctx, (self.remote, self.local), self.origin, self.tx)
    }
}

fn host_device<I: Interface>(
    ctx: &Context,
    (remote, local): (&DeviceName, &DeviceName),
    origin: &str,
    tx: &Sender<Event>,
) -> Result<Box<dyn MirroredDevice>, String> {
    let mut host = DeviceHost::<I>::new(ctx, local, MIRROR_DRIVER).map_err(|e| e.to_string())?;
    let listener = host
        .take_wake_listener()
        .ok_or_else(|| "the host has no wake listener".to_string())?;
    Ok(Box::new(Mirrored::<I> {
        local: local.clone(),
        remote: remote.clone(),
        host,
        cmd_key: keys::sender_key(remote, "cmd", origin),
        commands: ControlPublishers::new(keys::type_names::<I>().cmd),
        req_key: keys::sender_key(remote, "req", origin),
        lease_key: keys::sender_key(remote, "lease", origin),
        names: keys::type_names::<I>(),
        tx: tx.clone(),
        requests: HashMap::new(),
        leases: HashMap::new(),
        listener: Rc::new(listener),
    }))
}

/// The local name of `remote` with `prefix` on its robot name.
fn local_name(remote: &DeviceName, prefix: &str) -> Option<DeviceName> {
    format!(
        "{prefix}{}/{}/{}",
        remote.robot(),
        remote.interface().name(),
        remote.index()
    )
    .parse()
    .ok()
}

/// Hosts the remote devices in `domain` until `stop` returns true; `report` hears of each
/// device that comes and goes.
///
/// The loop sleeps until Zenoh delivers something (a state, an outcome, a reply, a
/// liveliness change) or a local client wakes a hosted device (a command, a request, a
/// lease request, a new client); `stop` is asked at each wake-up and at least every
/// 250 ms (a signal interrupts the wait).
pub fn mirror(
    domain: &Domain,
    config: &MirrorConfig,
    stop: &dyn Fn() -> bool,
    report: &mut dyn FnMut(MirrorEvent),
) -> Result<(), MirrorError> {
    if !config
        .prefix
        .bytes()
        .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-')
    {
        return Err(MirrorError::Prefix(config.prefix.clone()));
    }
    let ctx = Context::new(domain, Role::Driver, "bridge-mirror").map_err(|source| {
        MirrorError::Domain {
            domain: domain.name().to_string(),
            source,
        }
    })?;
    let zconfig = session::base_config(&config.net)?;
    let principal = access::mirror_principal(&zconfig, config.principal.as_deref())
        .map_err(SessionError::from)?;
    // A mirror listens on nothing unless told: it talks to the bridge it connects to.
    let session = session::open(&config.net, zconfig, &config.net.listen)?;
    let zid = session.zid().to_string();
    let origin = keys::origin(&principal, &zid);
    let (inbox, tx) = Inbox::<Event>::new()?;

    let t = tx.clone();
    let key = keys::all_devices("state");
    let _states = session
        .declare_subscriber(&key)
        .callback(move |s: Sample| {
            if let Some((device, "state")) = keys::parse(s.key_expr().as_str()) {
                let payload = s.payload().to_bytes().into_owned();
                if t.send(Event::State { device, payload }).is_err() {
                    tracing::debug!("the bridge is ending: state dropped");
                }
            }
        })
        .wait()
        .map_err(|source| MirrorError::Subscribe { key, source })?;
    let t = tx.clone();
    let key = keys::all_devices(&format!("outcome/{origin}"));
    let _outcomes = session
        .declare_subscriber(&key)
        .callback(move |s: Sample| {
            if let Some((device, _)) = keys::parse(s.key_expr().as_str()) {
                let payload = s.payload().to_bytes().into_owned();
                if t.send(Event::Outcome { device, payload }).is_err() {
                    tracing::debug!("the bridge is ending: outcome dropped");
                }
            }
        })
        .wait()
        .map_err(|source| MirrorError::Subscribe { key, source })?;
    let t = tx.clone();
    let key = keys::all_devices("alive");
    let _alive = session
        .liveliness()
        .declare_subscriber(&key)
        .history(true)
        .callback(move |s: Sample| {
            if let Some((device, "alive")) = keys::parse(s.key_expr().as_str()) {
                let present = s.kind() == SampleKind::Put;
                if t.send(Event::Alive { device, present }).is_err() {
                    tracing::debug!("the bridge is ending: liveliness change dropped");
                }
            }
        })
        .wait()
        .map_err(|source| MirrorError::Subscribe { key, source })?;
    let t = tx.clone();
    let key = keys::all_driver_stats();
    let _stats = session
        .declare_subscriber(&key)
        .callback(move |s: Sample| {
            if let Some(robot) = keys::parse_driver_stats(s.key_expr().as_str()) {
                let (robot, payload) = (robot.to_string(), s.payload().to_bytes().into_owned());
                if t.send(Event::Stats { robot, payload }).is_err() {
                    tracing::debug!("the bridge is ending: driver statistics dropped");
                }
            }
        })
        .wait()
        .map_err(|source| MirrorError::Subscribe { key, source })?;
    report(MirrorEvent::Ready { zid, principal });

    let mut mirrorer = Mirrorer {
        config,
        ctx,
        session: &session,
        origin,
        tx,
        devices: HashMap::new(),
        stats: HashMap::new(),
        gone: Vec::new(),
        owed: Owed::default(),
    };
    let result = mirrorer.run(&inbox, stop, report);
    drop(mirrorer);
    session::close(&session);
    result
}

/// The state of a running `mirror`.
struct Mirrorer<'a> {
    config: &'a MirrorConfig,
    ctx: Context,
    session: &'a Session,
    origin: String,
    tx: Sender<Event>,
    /// By remote name: the local name and the hosted device.
    devices: HashMap<DeviceName, (DeviceName, Box<dyn MirroredDevice>)>,
    /// Per remote robot with a hosted device, its driver statistics in this domain.
    stats: HashMap<String, StatsPublisher>,
    /// Devices no longer hosted, reported once the loop no longer waits on them.
    gone: Vec<DeviceName>,
    /// An answer (an outcome, a reply) owed to what was put on Zenoh, looked for without
    /// sleeping (`waiting::await_linger`).
    owed: Owed,
}

impl Mirrorer<'_> {
    /// The loop, until `stop`; the WaitSet is built anew whenever devices come or go.
    fn run(
        &mut self,
        inbox: &Inbox<Event>,
        stop: &dyn Fn() -> bool,
        report: &mut dyn FnMut(MirrorEvent),
    ) -> Result<(), MirrorError> {
        while !stop() {
            let attached: Attached = self
                .devices
                .iter()
                .map(|(remote, (_, d))| (remote.clone(), d.listener()))
                .collect();
            let ended = with_waitset(inbox, &attached, |wait| -> Result<(), MirrorError> {
                loop {
                    if stop() {
                        return Ok(());
                    }
                    let woken = wait(IDLE_WAIT, self.owed.until())?;
                    let timeout = self.config.request_timeout;
                    for remote in &woken.devices {
                        if let Some((_, d)) = self.devices.get_mut(remote)
                            && d.relay(self.session, timeout)
                        {
                            self.owed
                                .asked(Instant::now(), crate::waiting::await_linger());
                        }
                    }
                    let mut changed = false;
                    if woken.mail {
                        for ev in inbox.drain() {
                            changed |= self.handle(ev, report);
                        }
                    }
                    if changed {
                        return Ok(());
                    }
                }
            });
            drop(attached);
            // No longer waited on (nor offered) before anybody is told so.
            for local in self.gone.drain(..) {
                tracing::info!(local = %local, "remote device gone");
                report(MirrorEvent::Gone { local });
            }
            ended??;
        }
        Ok(())
    }

    /// Publishes a remote robot's driver statistics here (under the prefixed robot name),
    /// while one of its devices is hosted.
    fn stats_arrived(&mut self, robot: &str, payload: &[u8]) {
        if !self.devices.keys().any(|d| d.robot() == robot) {
            return;
        }
        let Ok(mut stats) = DriverStats::read_from_bytes(payload) else {
            tracing::warn!(
                robot,
                len = payload.len(),
                "driver statistics of the wrong size: dropped"
            );
            return;
        };
        if !self.stats.contains_key(robot) {
            let local = format!("{}{robot}", self.config.prefix);
            match StatsPublisher::new(&self.ctx, &local) {
                Ok(p) => {
                    self.stats.insert(robot.to_string(), p);
                }
                Err(e) => {
                    tracing::warn!(robot = local, error = %e, "cannot offer driver statistics");
                    return;
                }
            }
        }
        if let Some(p) = self.stats.get_mut(robot)
            && let Err(e) = p.publish(&mut stats)
        {
            tracing::warn!(robot, error = %e, "cannot publish driver statistics");
        }
    }

    /// Handles one delivery from Zenoh; returns whether devices came or went.
    fn handle(&mut self, ev: Event, report: &mut dyn FnMut(MirrorEvent)) -> bool {
        match ev {
            Event::Alive {
                device,
                present: true,
            } => {
                if self.devices.contains_key(&device) {
                    return false;
                }
                let Some(local) = local_name(&device, &self.config.prefix) else {
                    report(MirrorEvent::Refused {
                        remote: device,
                        reason: "the prefixed robot name is invalid".into(),
                    });
                    return false;
                };
                if self.devices.len() >= self.config.max_devices {
                    tracing::warn!(remote = %device, max = self.config.max_devices,
                        "a remote device beyond --max-devices: not hosted");
                    report(MirrorEvent::Refused {
                        remote: device,
                        reason: format!(
                            "this mirror hosts {} devices at most (--max-devices)",
                            self.config.max_devices
                        ),
                    });
                    return false;
                }
                let (ctx, tx) = (&self.ctx, &self.tx);
                let made = device.interface().visit(Host {
                    ctx,
                    remote: &device,
                    local: &local,
                    origin: &self.origin,
                    tx,
                });
                match made {
                    Ok(d) => {
                        tracing::info!(remote = %device, local = %local, "mirrored");
                        self.devices.insert(device.clone(), (local.clone(), d));
                        report(MirrorEvent::Mirrored {
                            remote: device,
                            local,
                        });
                        true
                    }
                    Err(reason) => {
                        tracing::warn!(remote = %device, error = %reason,
                            "cannot host a remote device");
                        report(MirrorEvent::Refused {
                            remote: device,
                            reason,
                        });
                        false
                    }
                }
            }
            Event::Alive {
                device,
                present: false,
            } => match self.devices.remove(&device) {
                Some((local, host)) => {
                    drop(host);
                    let devices = &self.devices;
                    self.stats
                        .retain(|robot, _| devices.keys().any(|d| d.robot() == robot.as_str()));
                    self.gone.push(local);
                    true
                }
                None => false,
            },
            Event::Stats { robot, payload } => {
                self.stats_arrived(&robot, &payload);
                false
            }
            Event::State { device, payload } => {
                if let Some((_, d)) = self.devices.get_mut(&device) {
                    d.state(&payload);
                }
                false
            }
            Event::Outcome { device, payload } => {
                if let Some((_, d)) = self.devices.get_mut(&device) {
                    d.outcome(&payload);
                }
                self.owed.answered(Instant::now());
                false
            }
            Event::Reply {
                device,
                exchange,
                id,
                reply,
            } => {
                if let Some((_, d)) = self.devices.get_mut(&device) {
                    d.reply(exchange, id, &reply);
                }
                self.owed.answered(Instant::now());
                false
            }
            Event::Done {
                device,
                exchange,
                id,
            } => {
                if let Some((_, d)) = self.devices.get_mut(&device) {
                    d.done(exchange, id);
                }
                false
            }
        }
    }
}
