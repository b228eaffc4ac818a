//! `limber bridge expose`: a domain's devices on Zenoh.
//!
//! The bridge joins the domain as a client of every device it finds (as `limber list`
//! does, skipping devices that a mirror hosts), and per device:
//! publishes each state sample on `.../state`; takes commands from `.../cmd` and sends them
//! to the driver under a client id of its own per remote client (so the driver tells
//! remote clients apart: their outcomes and preemptions, which the driver sends on this
//! process's own outcome stream, come back to each one on `.../outcome/<origin>`); answers queries on `.../req` with the driver's reply, or with
//! an error carrying a status code when the driver does not answer in time; and holds a
//! liveliness token `.../alive` while the driver lives.
//!
//! Slightly over 800 lines, for a stated reason: the issue "Nobody moves the arm who may
//! not" (items 1, 2 and 5: who may reach the bridge, identities from the authenticated
//! session) reworks this file; the split follows that rework rather than preceding it.

use std::collections::HashMap;
use std::rc::Rc;
use std::time::{Duration, Instant};

use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::ipc;

use limber_interfaces::Interface;
use limber_interfaces::message::Message;
use limber_interfaces::prelude::*;
use limber_services::diagnostics::StatsReader;
use limber_services::relay::{PendingLease, PendingRelay};
use limber_services::{Client, Context, DeviceName, Domain, Role, list_devices};
use thiserror::Error;
use zenoh::Session;
use zenoh::Wait;
use zenoh::liveliness::LivelinessToken;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::query::{Query, Queryable};
use zenoh::sample::Sample;
use zerocopy::{FromBytes, IntoBytes};

use crate::access;
use crate::allow::Allow;
use crate::dirwatch::DirWatch;
use crate::inbox::{Inbox, InboxError, Sender};
use crate::keys::{self, TypeNames};
use crate::malformed;
use crate::session::{self, ControlPublishers, NetConfig, SessionError};
use crate::waiting::{Attached, Owed, with_waitset};

/// How often each exposed device's driver is checked for life (a dead driver's token is
/// withdrawn after two checks in a row find it dead, within a second). A check probes every
/// node of the device's service (a few files each): ten a second were most of an idle
/// bridge's cost.
const LIVENESS_PERIOD: Duration = Duration::from_millis(500);

/// The driver name a mirror hosts its devices under; `expose` skips such devices so that a
/// mirror and an exposing bridge in one domain do not loop.
pub const MIRROR_DRIVER: &str = "bridge";

/// How `expose` runs.
#[derive(Debug, Clone)]
pub struct ExposeConfig {
    /// The network side.
    pub net: NetConfig,
    /// How long the driver has to answer a relayed request.
    pub request_timeout: Duration,
    /// How often the domain is looked at for new devices.
    pub discovery_period: Duration,
    /// What passes: devices, commands, requests that change a device.
    pub allow: Allow,
    /// The principals (Zenoh user names or TLS client certificate common names) that may
    /// send commands and requests, besides every user of the user/password dictionary and
    /// the owner on the Unix socket ([`crate::access`]).
    pub peers: Vec<String>,
}

impl Default for ExposeConfig {
    fn default() -> Self {
        ExposeConfig {
            net: NetConfig::default(),
            request_timeout: Duration::from_millis(1500),
            // Listing a domain reads every service file of iceoryx2's root (those of every
            // domain of the user): done only when its directories changed (`DirWatch`).
            discovery_period: Duration::from_secs(1),
            allow: Allow::default(),
            peers: Vec::new(),
        }
    }
}

/// What `expose` reports as it runs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ExposeEvent {
    /// The Zenoh session is open.
    Ready {
        /// This bridge's Zenoh id.
        zid: String,
        /// The endpoints it listens on.
        listen: Vec<String>,
    },
    /// A device is on Zenoh now.
    Exposed(DeviceName),
    /// A device's driver is gone: its token is withdrawn.
    Gone(DeviceName),
}

/// `expose` failed.
#[derive(Debug, Error)]
pub enum ExposeError {
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
    /// The loop's wake-up could not be made.
    #[error(transparent)]
    Inbox(#[from] InboxError),
    /// The loop's WaitSet could not be set up or waited on.
    #[error(transparent)]
    Loop(#[from] limber_services::event_loop::LoopError),
}

enum Event {
    Command {
        device: DeviceName,
        origin: String,
        payload: Vec<u8>,
    },
    Query {
        device: DeviceName,
        query: Query,
    },
    Lease {
        device: DeviceName,
        query: Query,
    },
}

/// The origin (`<principal>/<session>`) of a query on `channel` of `device`: from its key,
/// which Zenoh's access control lets a session use only under its own principal.
fn query_origin(query: &Query, device: &DeviceName, channel: &str) -> Option<String> {
    keys::origin_of(query.key_expr().as_str(), device, channel).map(str::to_string)
}

/// Replies to `query` with an error carrying `status` (4 bytes, little-endian).
/// Answers `query` with `bytes` of the type `type_name`; a failure is logged.
fn answer(query: &Query, bytes: &[u8], type_name: &str) {
    if let Err(e) = query
        .reply(query.key_expr().clone(), bytes.to_vec())
        .encoding(keys::encoding(type_name))
        .wait()
    {
        tracing::warn!(key = %query.key_expr(), error = %e, "cannot answer a query");
    }
}

fn refuse(query: &Query, status: Status) {
    let payload = status.code().to_le_bytes().to_vec();
    if let Err(e) = query
        .reply_err(payload)
        .encoding(keys::encoding(keys::STATUS_TYPE))
        .wait()
    {
        tracing::warn!(key = %query.key_expr(), error = %e, "cannot answer a query");
    }
}

/// The ids remote clients have in the domain: one local client id per (origin, remote
/// client id), so the driver tells them apart.
struct Ids {
    ctx: Context,
    to_local: HashMap<(String, u64), u64>,
    to_remote: HashMap<u64, (String, u64)>,
}

/// At most this many remote clients are remembered per device; past it the table starts
/// anew (outcomes of the forgotten ones' earlier commands are dropped).
const MAX_REMOTE_CLIENTS: usize = 4096;

impl Ids {
    fn local(&mut self, origin: &str, remote: u64) -> u64 {
        if let Some(id) = self.to_local.get(&(origin.to_string(), remote)) {
            return *id;
        }
        if self.to_local.len() >= MAX_REMOTE_CLIENTS {
            tracing::warn!("more than {MAX_REMOTE_CLIENTS} remote clients: forgetting them");
            self.to_local.clear();
            self.to_remote.clear();
        }
        let id = self.ctx.new_client_id();
        self.to_local.insert((origin.to_string(), remote), id);
        self.to_remote.insert(id, (origin.to_string(), remote));
        id
    }
}

/// While relaying a burst of commands, their outcomes are taken after every this many.
const DRAIN_EVERY: usize = limber_services::qos::TOLD_BUFFER / 4;

/// One device put on Zenoh.
struct Exposed<I: Interface> {
    device: DeviceName,
    client: Client<I>,
    state_pub: Publisher<'static>,
    names: TypeNames,
    allow: Allow,
    ids: Ids,
    /// The outcomes' publishers, one per origin.
    outcomes: ControlPublishers,
    /// Commands relayed since the outcomes were last taken.
    relayed: usize,
    pending: Vec<(Query, PendingRelay<I>, Instant, u64)>,
    /// The last liveness check found the driver dead.
    doubted: bool,
    leases: Vec<(Query, PendingLease, Instant)>,
    /// Notified when the driver published a state or an outcome, or answered.
    listener: Rc<Listener<ipc::Service>>,
    _token: LivelinessToken,
    _commands: Subscriber<()>,
    _queries: Queryable<()>,
    _leases: Queryable<()>,
}

trait ExposedDevice {
    fn command(&mut self, session: &Session, origin: &str, payload: &[u8]);
    fn query(&mut self, query: Query, timeout: Duration);
    fn lease(&mut self, query: Query, timeout: Duration);
    /// Forwards what arrived (states, outcomes, replies); says whether anything owed to a
    /// remote client was answered.
    fn poll(&mut self, session: &Session) -> bool;
    /// The earliest deadline of a relayed request or lease request.
    fn next_deadline(&self) -> Option<Instant>;
    fn listener(&self) -> Rc<Listener<ipc::Service>>;
    fn alive(&self) -> bool;
    fn doubted(&self) -> bool;
    fn set_doubted(&mut self, on: bool);
}

impl<I: Interface> Exposed<I> {
    /// Sends the outcomes of the remote clients' commands that arrived back to each one;
    /// returns how many.
    fn forward_outcomes(&mut self, session: &Session) -> usize {
        self.relayed = 0;
        let mut outcomes = Vec::new();
        if let Err(e) = self.client.relay_own_outcomes(|o| outcomes.push(*o)) {
            tracing::warn!(device = %self.device, error = %e, "cannot take the outcomes");
        }
        let mut n = 0;
        for mut o in outcomes {
            let Some((origin, remote)) = self.ids.to_remote.get(&o.client_id).cloned() else {
                continue; // an id forgotten (more than MAX_REMOTE_CLIENTS)
            };
            o.client_id = remote;
            if let Some((_, other)) = self.ids.to_remote.get(&o.other_client) {
                o.other_client = *other;
            }
            put_outcome(&mut self.outcomes, session, &self.device, &origin, &o);
            n += 1;
        }
        n
    }
}

impl<I: Interface> ExposedDevice for Exposed<I> {
    fn command(&mut self, session: &Session, origin: &str, payload: &[u8]) {
        let Ok(mut cmd) = I::CmdMsg::read_from_bytes(payload) else {
            malformed::note(
                &self.device,
                origin,
                &format!(
                    "a command of the wrong size ({} bytes, {} expected): dropped",
                    payload.len(),
                    self.names.cmd
                ),
            );
            return;
        };
        let meta = *cmd.meta();
        if !self.allow.command(I::KIND, meta.kind) {
            tracing::warn!(device = %self.device, origin, kind = meta.kind,
                "a command this bridge does not let through: refused");
            let o = OutcomeMsg {
                client_id: meta.client_id,
                cmd_seq: meta.seq,
                stamp_ns: limber_services::monotonic_ns(),
                kind: meta.kind,
                status: Status::Unsupported.code(),
                ..OutcomeMsg::default()
            };
            put_outcome(&mut self.outcomes, session, &self.device, origin, &o);
            return;
        }
        let meta = cmd.meta_mut();
        meta.client_id = self.ids.local(origin, meta.client_id);
        if let Err(e) = self.client.relay_send(&cmd) {
            tracing::warn!(device = %self.device, origin, error = %e, "cannot relay a command");
        }
        // A burst of relayed commands: their outcomes taken between them, so that this
        // process's outcome stream (TOLD_BUFFER deep) does not overflow behind it.
        self.relayed += 1;
        if self.relayed >= DRAIN_EVERY {
            // Counted as answers by the loop's next look at the device, not here.
            let _forwarded = self.forward_outcomes(session);
        }
    }

    fn query(&mut self, query: Query, timeout: Duration) {
        let Some(origin) = query_origin(&query, &self.device, "req") else {
            malformed::note(
                &self.device,
                "?",
                "a request without a valid origin: refused",
            );
            refuse(&query, Status::InvalidArgument);
            return;
        };
        let bytes = query.payload().map(|p| p.to_bytes().into_owned());
        let Some(Ok(mut req)) = bytes.as_deref().map(I::ReqMsg::read_from_bytes) else {
            malformed::note(
                &self.device,
                &origin,
                "a request of the wrong size: refused",
            );
            refuse(&query, Status::InvalidArgument);
            return;
        };
        let remote = req.meta().client_id;
        let read_only = I::Request::read(&req).is_ok_and(|r| r.is_read_only());
        if !self.allow.request(I::KIND, req.meta().kind, read_only) {
            tracing::warn!(device = %self.device, origin, kind = req.meta().kind,
                "a request that changes the device: refused (not let through by this bridge)");
            let out = keys::nack::<I>(&req, Status::Unsupported);
            if let Err(e) = query
                .reply(query.key_expr().clone(), out.as_bytes().to_vec())
                .encoding(keys::encoding(self.names.reply))
                .wait()
            {
                tracing::warn!(key = %query.key_expr(), error = %e, "cannot answer a query");
            }
            return;
        }
        req.meta_mut().client_id = self.ids.local(&origin, remote);
        match self.client.relay_request(&req) {
            Ok(p) => self
                .pending
                .push((query, p, Instant::now() + timeout, remote)),
            Err(e) => {
                tracing::warn!(device = %self.device, error = %e, "cannot relay a request");
                refuse(&query, Status::LinkDown);
            }
        }
    }

    fn lease(&mut self, query: Query, timeout: Duration) {
        let Some(origin) = query_origin(&query, &self.device, "lease") else {
            malformed::note(
                &self.device,
                "?",
                "a lease request without a valid origin: refused",
            );
            refuse(&query, Status::InvalidArgument);
            return;
        };
        let bytes = query.payload().map(|p| p.to_bytes().into_owned());
        let Some(Ok(mut req)) = bytes.as_deref().map(LeaseReq::read_from_bytes) else {
            malformed::note(
                &self.device,
                &origin,
                "a lease request of the wrong size: refused",
            );
            refuse(&query, Status::InvalidArgument);
            return;
        };
        if self.allow.read_only || self.allow.filtered() {
            // A lease would let a remote client refuse the robot's own clients: only a
            // bridge that lets every command through carries leases.
            refuse(&query, Status::Unsupported);
            return;
        }
        req.client_id = self.ids.local(&origin, req.client_id);
        match self.client.relay_lease(&req) {
            Ok(p) => self.leases.push((query, p, Instant::now() + timeout)),
            Err(e) => {
                tracing::warn!(device = %self.device, error = %e, "cannot relay a lease request");
                refuse(&query, Status::LinkDown);
            }
        }
    }

    fn poll(&mut self, session: &Session) -> bool {
        let owed = self.pending.len() + self.leases.len();
        self.poll_leases();
        let (device, state_pub) = (&self.device, &self.state_pub);
        if let Err(e) = self.client.relay_states(|d| {
            if let Err(e) = state_pub.put(d.as_bytes().to_vec()).wait() {
                tracing::warn!(device = %device, error = %e, "cannot publish a state on Zenoh");
            }
        }) {
            tracing::warn!(device = %self.device, error = %e, "cannot take the states");
        }
        let forwarded = self.forward_outcomes(session);
        let now = Instant::now();
        let names = self.names;
        self.pending.retain(|(query, p, deadline, remote)| {
            match p.try_reply() {
                Ok(Some(mut reply)) => {
                    reply.meta_mut().client_id = *remote;
                    answer(query, reply.as_bytes(), names.reply);
                    false
                }
                Ok(None) if now < *deadline => true,
                Ok(None) => {
                    refuse(query, Status::Timeout);
                    false
                }
                Err(e) => {
                    tracing::warn!(key = %query.key_expr(), error = %e, "the driver did not answer");
                    refuse(query, Status::LinkDown);
                    false
                }
            }
        });
        forwarded > 0 || self.pending.len() + self.leases.len() < owed
    }

    fn next_deadline(&self) -> Option<Instant> {
        let requests = self.pending.iter().map(|(_, _, t, _)| *t);
        let leases = self.leases.iter().map(|(_, _, t)| *t);
        requests.chain(leases).min()
    }

    fn listener(&self) -> Rc<Listener<ipc::Service>> {
        Rc::clone(&self.listener)
    }

    fn alive(&self) -> bool {
        self.client.relay_driver_alive()
    }

    fn doubted(&self) -> bool {
        self.doubted
    }

    fn set_doubted(&mut self, on: bool) {
        self.doubted = on;
    }
}

/// Puts outcome `o` for the commands of `origin` through `publishers`.
fn put_outcome(
    publishers: &mut ControlPublishers,
    session: &Session,
    device: &DeviceName,
    origin: &str,
    o: &OutcomeMsg,
) {
    let key = keys::outcome_key(device, origin);
    if let Err(e) = publishers.put(session, &key, o.as_bytes().to_vec()) {
        tracing::warn!(device = %device, error = %e, "cannot publish an outcome");
    }
}

impl<I: Interface> Exposed<I> {
    /// Answers the lease queries whose reply arrived (holder ids told as the remote
    /// clients know them).
    fn poll_leases(&mut self) {
        let now = Instant::now();
        let ids = &self.ids;
        self.leases.retain(|(query, p, deadline)| {
            match p.try_reply() {
                Ok(Some(mut reply)) => {
                    reply.holder_client = match ids.to_remote.get(&reply.holder_client) {
                        Some((_, r)) => *r,
                        None => reply.holder_client,
                    };
                    reply.set_holder_node(0);
                    answer(query, reply.as_bytes(), keys::lease_reply_type());
                    false
                }
                Ok(None) if now < *deadline => true,
                Ok(None) => {
                    refuse(query, Status::Timeout);
                    false
                }
                Err(e) => {
                    tracing::warn!(key = %query.key_expr(), error = %e, "the driver did not answer a lease request");
                    refuse(query, Status::LinkDown);
                    false
                }
            }
        });
    }
}

/// [`expose_device`] for a device of any interface.
struct Expose<'a> {
    allow: &'a Allow,
    ctx: &'a Context,
    session: &'a Session,
    device: &'a DeviceName,
    tx: &'a Sender<Event>,
}

impl InterfaceVisitor for Expose<'_> {
    type Output = Result<Box<dyn ExposedDevice>, String>;
    fn visit<I: Interface>(self) -> Self::Output {
        expose_device::<I>(self.allow, self.ctx, self.session, self.device, self.tx)
    }
}

fn expose_device<I: Interface>(
    allow: &Allow,
    ctx: &Context,
    session: &Session,
    device: &DeviceName,
    tx: &Sender<Event>,
) -> Result<Box<dyn ExposedDevice>, String> {
    let mut client = Client::<I>::connect(ctx, &device.to_string()).map_err(|e| e.to_string())?;
    // The outcomes of the remote clients' commands (relayed under ids of this process), on
    // this process's own stream: nobody else's commands fill it.
    if !client.relay_open_stream(true) {
        return Err("its driver does not take an outcome stream".into());
    }
    let listener = client.relay_listener().map_err(|e| e.to_string())?;
    // The same test as the one that withdraws it: a driver found dead is not exposed.
    if !client.relay_driver_alive() {
        return Err("its driver is not alive".into());
    }
    let names = keys::type_names::<I>();
    let state_pub = session
        .declare_publisher(keys::device_key(device, "state"))
        .encoding(keys::encoding(names.data))
        .wait()
        .map_err(|e| e.to_string())?;
    let (d, t) = (device.clone(), tx.clone());
    let commands = session
        .declare_subscriber(keys::all_senders(device, "cmd"))
        .callback(move |s: Sample| {
            let Some(origin) = keys::origin_of(s.key_expr().as_str(), &d, "cmd") else {
                malformed::note(&d, "?", "a command without a valid origin: dropped");
                return;
            };
            let ev = Event::Command {
                device: d.clone(),
                origin: origin.to_string(),
                payload: s.payload().to_bytes().into_owned(),
            };
            if t.send(ev).is_err() {
                tracing::debug!(device = %d, "the bridge is ending: command dropped");
            }
        })
        .wait()
        .map_err(|e| e.to_string())?;
    let (d, t) = (device.clone(), tx.clone());
    let queries = session
        .declare_queryable(keys::all_senders(device, "req"))
        .callback(move |query: Query| {
            if let Err(Event::Query { query, .. }) = t.send(Event::Query {
                device: d.clone(),
                query,
            }) {
                refuse(&query, Status::LinkDown);
            }
        })
        .wait()
        .map_err(|e| e.to_string())?;
    let (d, t) = (device.clone(), tx.clone());
    let lease_queries = session
        .declare_queryable(keys::all_senders(device, "lease"))
        .callback(move |query: Query| {
            if let Err(Event::Lease { query, .. }) = t.send(Event::Lease {
                device: d.clone(),
                query,
            }) {
                refuse(&query, Status::LinkDown);
            }
        })
        .wait()
        .map_err(|e| e.to_string())?;
    let token = session
        .liveliness()
        .declare_token(keys::device_key(device, "alive"))
        .wait()
        .map_err(|e| e.to_string())?;
    Ok(Box::new(Exposed::<I> {
        device: device.clone(),
        client,
        state_pub,
        names,
        allow: allow.clone(),
        ids: Ids {
            ctx: ctx.clone(),
            to_local: HashMap::new(),
            to_remote: HashMap::new(),
        },
        outcomes: ControlPublishers::new(keys::outcome_type()),
        relayed: 0,
        pending: Vec::new(),
        doubted: false,
        leases: Vec::new(),
        listener: Rc::new(listener),
        _leases: lease_queries,
        _token: token,
        _commands: commands,
        _queries: queries,
    }))
}

/// Puts the devices of `domain` on Zenoh until `stop` returns true; `report` hears of
/// each device that comes and goes.
///
/// The loop sleeps until Zenoh delivers something, a driver notifies (a state, an outcome,
/// a reply), or one of its deadlines comes: the next look for new devices
/// ([`ExposeConfig::discovery_period`]), the next check of the drivers' life, a relayed
/// request's timeout. `stop` is asked at each wake-up (a signal interrupts the wait).
pub fn expose(
    domain: &Domain,
    config: &ExposeConfig,
    stop: &dyn Fn() -> bool,
    report: &mut dyn FnMut(ExposeEvent),
) -> Result<(), ExposeError> {
    let ctx = Context::new(domain, Role::Client, "bridge-expose").map_err(|source| {
        ExposeError::Domain {
            domain: domain.name().to_string(),
            source,
        }
    })?;
    let (session, listen) = open_session(domain, config)?;
    report(ExposeEvent::Ready {
        zid: session.zid().to_string(),
        listen,
    });
    let (inbox, tx) = Inbox::<Event>::new()?;
    let mut exposer = Exposer {
        domain,
        config,
        ctx,
        session: &session,
        tx,
        devices: HashMap::new(),
        stats: HashMap::new(),
        next_discovery: Instant::now(),
        next_liveness: Instant::now(),
        watch: DirWatch::new(domain),
        owed: Owed::default(),
    };
    let result = exposer.run(&inbox, stop, report);
    malformed::summarise_now();
    drop(exposer);
    session::close(&session);
    result
}

/// Opens `expose`'s session: listening on the domain's private Unix socket unless told
/// otherwise, refusing a listener others reach without credentials, and with the access
/// rules that bind each sender's key to its authenticated principal
/// ([`crate::access`]).
fn open_session(
    domain: &Domain,
    config: &ExposeConfig,
) -> Result<(Session, Vec<String>), SessionError> {
    let mut zconfig = session::base_config(&config.net)?;
    let listen = if config.net.listen.is_empty() {
        let runtime = domain.runtime_dir().map_err(access::AccessError::from)?;
        vec![access::private_socket(runtime, domain.name())?]
    } else {
        config.net.listen.clone()
    };
    access::check_listeners(&zconfig, &listen)?;
    let principals = access::principals(&zconfig, &config.peers)?;
    session::set(
        &mut zconfig,
        "access_control",
        access::expose_acl(&principals),
    )?;
    Ok((session::open(&config.net, zconfig, &listen)?, listen))
}

/// The state of a running `expose`.
struct Exposer<'a> {
    domain: &'a Domain,
    config: &'a ExposeConfig,
    ctx: Context,
    session: &'a Session,
    tx: Sender<Event>,
    devices: HashMap<DeviceName, Box<dyn ExposedDevice>>,
    /// Per robot with an exposed device, its driver statistics and where they go.
    stats: HashMap<String, (StatsReader, Publisher<'static>)>,
    next_discovery: Instant,
    next_liveness: Instant,
    /// Whether the domain may have changed since the last listing.
    watch: DirWatch,
    /// An answer (an outcome, a reply) owed by a driver to what was relayed to it, looked
    /// for without sleeping (`waiting::await_linger`).
    owed: Owed,
}

impl Exposer<'_> {
    /// The loop, until `stop`; the WaitSet is built anew whenever devices come or go.
    fn run(
        &mut self,
        inbox: &Inbox<Event>,
        stop: &dyn Fn() -> bool,
        report: &mut dyn FnMut(ExposeEvent),
    ) -> Result<(), ExposeError> {
        while !stop() {
            let attached: Attached = self
                .devices
                .iter()
                .map(|(n, d)| (n.clone(), d.listener()))
                .collect();
            with_waitset(inbox, &attached, |wait| -> Result<(), ExposeError> {
                loop {
                    // Devices came or went: the WaitSet is built anew.
                    if self.timers(report) {
                        return Ok(());
                    }
                    if stop() {
                        return Ok(());
                    }
                    let due = self
                        .devices
                        .values()
                        .filter_map(|d| d.next_deadline())
                        .fold(self.next_discovery.min(self.next_liveness), Instant::min);
                    let woken = wait(
                        due.saturating_duration_since(Instant::now()),
                        self.owed.until(),
                    )?;
                    for name in &woken.devices {
                        if let Some(d) = self.devices.get_mut(name)
                            && d.poll(self.session)
                        {
                            self.owed.answered(Instant::now());
                        }
                    }
                    if woken.mail {
                        let mut asked = false;
                        for ev in inbox.drain() {
                            asked |= self.handle(ev);
                        }
                        if asked {
                            self.owed
                                .asked(Instant::now(), crate::waiting::await_linger());
                        }
                    }
                    // Relayed requests whose time is up are answered "timeout".
                    let now = Instant::now();
                    for d in self.devices.values_mut() {
                        if d.next_deadline().is_some_and(|t| t <= now) && d.poll(self.session) {
                            self.owed.answered(Instant::now());
                        }
                    }
                }
            })??;
        }
        Ok(())
    }

    /// Looks for new devices and checks the drivers' life when their time has come;
    /// returns whether devices came or went.
    fn timers(&mut self, report: &mut dyn FnMut(ExposeEvent)) -> bool {
        malformed::summarise_if_due();
        let now = Instant::now();
        let mut changed = false;
        if now >= self.next_discovery {
            self.next_discovery = now + self.config.discovery_period;
            if self.watch.should_list(now) {
                changed |= self.discover(report);
            }
        }
        if now >= self.next_liveness {
            self.next_liveness = now + LIVENESS_PERIOD;
            // Withdrawn after two checks in a row find the driver dead, so a passing doubt
            // never makes a device flap.
            let gone: Vec<DeviceName> = self
                .devices
                .iter_mut()
                .filter_map(|(n, d)| {
                    let (alive, doubted) = (d.alive(), d.doubted());
                    d.set_doubted(!alive);
                    (!alive && doubted).then(|| n.clone())
                })
                .collect();
            for name in gone {
                // The token is withdrawn (dropped) before anybody is told so.
                drop(self.devices.remove(&name));
                tracing::info!(device = %name, "driver gone: withdrawn");
                report(ExposeEvent::Gone(name));
                // Its driver may come back into the same service files.
                self.watch.force();
                changed = true;
            }
            // What a notification could not tell: a driver that left without answering.
            for d in self.devices.values_mut() {
                d.poll(self.session);
            }
            self.relay_stats();
        }
        changed
    }

    /// Puts the driver statistics that arrived (about once a second) on Zenoh, for the
    /// robots with an exposed device; forgets the robots that have none left.
    fn relay_stats(&mut self) {
        let devices = &self.devices;
        self.stats
            .retain(|robot, _| devices.keys().any(|d| d.robot() == robot.as_str()));
        for robot in self.devices.keys().map(|d| d.robot().to_string()) {
            if self.stats.contains_key(&robot) {
                continue;
            }
            // A driver without statistics (not every driver has them) is asked again at
            // the next check.
            let Ok(reader) = StatsReader::open(&self.ctx, &robot) else {
                continue;
            };
            match self
                .session
                .declare_publisher(keys::driver_stats_key(&robot))
                .encoding(keys::encoding(keys::driver_stats_type()))
                .wait()
            {
                Ok(p) => {
                    self.stats.insert(robot, (reader, p));
                }
                Err(e) => {
                    tracing::warn!(robot, error = %e, "cannot put driver statistics on Zenoh")
                }
            }
        }
        for (robot, (reader, publisher)) in &mut self.stats {
            match reader.refresh() {
                Ok(true) => {
                    if let Some(s) = reader.latest()
                        && let Err(e) = publisher.put(s.as_bytes().to_vec()).wait()
                    {
                        tracing::warn!(robot, error = %e, "cannot publish driver statistics");
                    }
                }
                Ok(false) => {}
                Err(e) => tracing::warn!(robot, error = %e, "cannot read driver statistics"),
            }
        }
    }

    /// Exposes the devices of the domain not exposed yet; returns whether there were any.
    fn discover(&mut self, report: &mut dyn FnMut(ExposeEvent)) -> bool {
        let list = match list_devices(self.domain) {
            Ok(list) => list,
            Err(e) => {
                tracing::warn!(error = %e, "cannot list the devices");
                return false;
            }
        };
        let mut added = false;
        let config = self.config;
        for info in list {
            if !info.alive
                || info.driver == MIRROR_DRIVER
                || !config.allow.device(&info.name)
                || self.devices.contains_key(&info.name)
            {
                continue;
            }
            let (ctx, session, tx) = (&self.ctx, self.session, &self.tx);
            let made = info.interface().visit(Expose {
                allow: &config.allow,
                ctx,
                session,
                device: &info.name,
                tx,
            });
            match made {
                Ok(d) => {
                    tracing::info!(device = %info.name, "exposed");
                    self.devices.insert(info.name.clone(), d);
                    report(ExposeEvent::Exposed(info.name));
                    added = true;
                }
                Err(e) => tracing::warn!(device = %info.name, error = %e, "cannot expose"),
            }
        }
        added
    }

    /// Relays one command or query that came from Zenoh; says whether it went to a driver
    /// (an answer is then owed).
    fn handle(&mut self, ev: Event) -> bool {
        let timeout = self.config.request_timeout;
        match ev {
            Event::Command {
                device,
                origin,
                payload,
            } => match self.devices.get_mut(&device) {
                Some(d) => {
                    d.command(self.session, &origin, &payload);
                    true
                }
                None => {
                    tracing::debug!(device = %device, "command for a device gone");
                    false
                }
            },
            Event::Query { device, query } => match self.devices.get_mut(&device) {
                Some(d) => {
                    d.query(query, timeout);
                    true
                }
                None => {
                    refuse(&query, Status::LinkDown);
                    false
                }
            },
            Event::Lease { device, query } => match self.devices.get_mut(&device) {
                Some(d) => {
                    d.lease(query, timeout);
                    true
                }
                None => {
                    refuse(&query, Status::LinkDown);
                    false
                }
            },
        }
    }
}
