//! `limber view`: the domain's devices live in Foxglove, over the `foxglove.websocket.v1`
//! protocol (<https://github.com/foxglove/ws-protocol>, docs/spec.md).
//!
//! Read-only: the server offers no client publishing, parameters or services. Channels,
//! all JSON: per device `/<device>/state` (the state as `limber echo --json` prints it,
//! schema name its wire struct's type name), per actuator array `/<device>/joint_states`
//! (`foxglove.JointStates`) and, for an arm whose chain limber knows, `/<device>/
//! robot_description` (`std_msgs/String` holding its URDF, sent to each new subscriber) and
//! `/<device>/tf` (`foxglove.FrameTransforms` of the URDF's links at each state).
//!
//! Threads: this one takes the devices' states (iceoryx2 ports stay on the thread that made
//! them) and hands each message to every connection's writer through a bounded queue (a
//! client that reads slowly loses messages, never slows the others); one thread per
//! connection reads the client's subscriptions and one writes its frames.

use std::collections::{BTreeMap, HashMap};
use std::io::Write as _;
use std::net::{Shutdown, SocketAddr, TcpListener, TcpStream};
use std::rc::Rc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc::{Receiver, SyncSender, TrySendError, sync_channel};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::*;
use limber_interfaces::prelude::*;
use limber_interfaces::{HasHeader, Interface, InterfaceVisitor, WireStruct};
use limber_kinematics::chain::Chain;
use limber_services::event_loop::LoopError;
use limber_services::{Client, Context, DeviceName, Domain, Role, list_devices, monotonic_ns};
use serde_json::{Value, json};
use thiserror::Error;

use crate::schema;
use crate::urdf::{frame_transforms, urdf_with_signs};
use crate::ws::{self, Incoming, MessageReader, opcode};

/// How `view` runs.
#[derive(Debug, Clone)]
pub struct ViewConfig {
    /// Where to listen (default 127.0.0.1:8765, Foxglove's default port).
    pub listen: SocketAddr,
    /// The most clients at once; more are refused.
    pub max_clients: usize,
    /// The chain of simarm's arms, when not a built-in one (`simarm --chain FILE`).
    pub simarm_chain: Option<Chain>,
}

impl Default for ViewConfig {
    fn default() -> Self {
        ViewConfig {
            listen: SocketAddr::from(([127, 0, 0, 1], 8765)),
            max_clients: 16,
            simarm_chain: None,
        }
    }
}

/// `view` failed.
#[derive(Debug, Error)]
pub enum ViewError {
    /// The listener could not be opened.
    #[error("cannot listen on {addr}: {source}")]
    Listen {
        /// The address.
        addr: SocketAddr,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// The domain could not be joined.
    #[error("cannot join domain {domain}: {source}")]
    Domain {
        /// The domain.
        domain: String,
        /// Why.
        #[source]
        source: limber_services::ContextError,
    },
    /// The domain's devices could not be listed.
    #[error(transparent)]
    List(#[from] limber_services::ListError),
    /// Waiting for the devices failed.
    #[error("cannot wait for the devices: {0}")]
    Wait(#[from] LoopError),
}

/// What `view` reports as it runs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ViewEvent {
    /// Listening.
    Listening(SocketAddr),
    /// A device's channels are advertised.
    Device(DeviceName),
    /// A client connected.
    Client(SocketAddr),
}

/// A message for one connection's writer.
enum Out {
    Text(String),
    /// A message of channel `channel`, for each subscription of it.
    Data {
        channel: u32,
        stamp: u64,
        payload: Arc<Vec<u8>>,
    },
    /// A message for subscription `sub` only (the latched URDF on subscribing).
    ForSub {
        sub: u32,
        stamp: u64,
        payload: Arc<Vec<u8>>,
    },
    Pong(Vec<u8>),
}

struct Conn {
    tx: SyncSender<Out>,
    /// Subscription id -> channel id.
    subs: Arc<Mutex<HashMap<u32, u32>>>,
}

/// What every thread shares: the channels advertised, the latched messages, the clients.
#[derive(Default)]
struct Shared {
    channels: BTreeMap<u32, Value>,
    latched: HashMap<u32, Arc<Vec<u8>>>,
    conns: Vec<Conn>,
}

fn lock(m: &Mutex<Shared>) -> MutexGuard<'_, Shared> {
    // A thread that panicked holding it left plain data behind: use it.
    m.lock().unwrap_or_else(|p| p.into_inner())
}

impl Shared {
    fn broadcast(&mut self, make: impl Fn() -> Out) {
        self.conns.retain(|c| match c.tx.try_send(make()) {
            Ok(()) | Err(TrySendError::Full(_)) => true,
            Err(TrySendError::Disconnected(_)) => false,
        });
    }
}

fn status(level: u8, message: &str) -> Out {
    Out::Text(json!({"op": "status", "level": level, "message": message}).to_string())
}

/// One connection's writer: frames out until the queue closes or the client goes.
fn write_loop(mut s: TcpStream, rx: Receiver<Out>, subs: Arc<Mutex<HashMap<u32, u32>>>) {
    let data = |sub: u32, stamp: u64, payload: &[u8]| {
        let mut b = Vec::with_capacity(13 + payload.len());
        b.push(1u8); // Message Data
        b.extend_from_slice(&sub.to_le_bytes());
        b.extend_from_slice(&stamp.to_le_bytes());
        b.extend_from_slice(payload);
        b
    };
    for out in rx {
        let written = match out {
            Out::Text(t) => ws::write_frame(&mut s, opcode::TEXT, t.as_bytes()),
            Out::Pong(p) => ws::write_frame(&mut s, opcode::PONG, &p),
            Out::ForSub {
                sub,
                stamp,
                payload,
            } => ws::write_frame(&mut s, opcode::BINARY, &data(sub, stamp, &payload)),
            Out::Data {
                channel,
                stamp,
                payload,
            } => {
                let ids: Vec<u32> = subs
                    .lock()
                    .map(|m| {
                        m.iter()
                            .filter(|(_, c)| **c == channel)
                            .map(|(s, _)| *s)
                            .collect()
                    })
                    .unwrap_or_default();
                ids.into_iter().try_for_each(|sub| {
                    ws::write_frame(&mut s, opcode::BINARY, &data(sub, stamp, &payload))
                })
            }
        };
        if let Err(e) = written.and_then(|()| s.flush()) {
            tracing::info!(error = %e, "a viewer went away");
            break;
        }
    }
    if let Err(e) = s.shutdown(Shutdown::Both) {
        tracing::debug!(error = %e, "cannot shut a viewer's connection down");
    }
}

/// One connection: the handshake, then the client's requests until it closes.
fn serve_client(mut s: TcpStream, shared: Arc<Mutex<Shared>>, max_clients: usize) {
    let peer = s.peer_addr().ok();
    if let Err(e) = ws::handshake(&mut s) {
        tracing::info!(?peer, error = %e, "a viewer's handshake was refused");
        return;
    }
    // A client that stops reading is dropped after this long rather than holding a writer.
    if let Err(e) = s.set_write_timeout(Some(Duration::from_secs(5))) {
        tracing::warn!(error = %e, "cannot set a write timeout");
    }
    let Ok(write_half) = s.try_clone() else {
        tracing::warn!(?peer, "cannot clone a viewer's connection");
        return;
    };
    let (tx, rx) = sync_channel::<Out>(1024);
    let subs: Arc<Mutex<HashMap<u32, u32>>> = Arc::default();
    let writer = {
        let subs = Arc::clone(&subs);
        std::thread::Builder::new()
            .name("limber-view-write".into())
            .spawn(move || write_loop(write_half, rx, subs))
    };
    if let Err(e) = writer {
        tracing::warn!(error = %e, "cannot start a viewer's writer");
        return;
    }
    {
        let mut sh = lock(&shared);
        if sh.conns.len() >= max_clients {
            if tx
                .try_send(status(2, "too many viewers connected"))
                .is_err()
            {
                tracing::debug!("a refused viewer is gone already");
            }
            drop(sh);
            drop(tx);
            return;
        }
        let info = json!({
            "op": "serverInfo",
            "name": "limber view",
            "capabilities": [],
            "metadata": {"layout_version": limber_interfaces::LAYOUT_VERSION.to_string()},
            "sessionId": monotonic_ns().to_string(),
        });
        let adv = json!({"op": "advertise", "channels": sh.channels.values().cloned().collect::<Vec<_>>()});
        if tx.try_send(Out::Text(info.to_string())).is_err()
            || tx.try_send(Out::Text(adv.to_string())).is_err()
        {
            return;
        }
        sh.conns.push(Conn {
            tx: tx.clone(),
            subs: Arc::clone(&subs),
        });
    }
    let mut reader = MessageReader::default();
    loop {
        let msg = match reader.read(&mut s) {
            Ok(m) => m,
            Err(e) => {
                tracing::info!(?peer, error = %e, "a viewer's connection ended");
                break;
            }
        };
        let reply = match msg {
            Incoming::Close => break,
            Incoming::Ping(p) => Some(Out::Pong(p)),
            Incoming::Binary(_) => Some(status(2, "this server is read-only")),
            Incoming::Text(t) => handle_op(&t, &shared, &subs, &tx),
        };
        if let Some(r) = reply
            && tx.try_send(r).is_err()
        {
            break;
        }
    }
    // Dropping the sender ends the writer once the shared list lets its copy go.
    lock(&shared).conns.retain(|c| !Arc::ptr_eq(&c.subs, &subs));
    if let Err(e) = s.shutdown(Shutdown::Both) {
        tracing::debug!(error = %e, "cannot shut a viewer's connection down");
    }
}

/// A client's JSON request; the status to answer it with, if any.
fn handle_op(
    text: &str,
    shared: &Mutex<Shared>,
    subs: &Mutex<HashMap<u32, u32>>,
    tx: &SyncSender<Out>,
) -> Option<Out> {
    let Ok(v) = serde_json::from_str::<Value>(text) else {
        return Some(status(2, "not a JSON object"));
    };
    let Ok(mut subs) = subs.lock() else {
        return Some(status(2, "internal error"));
    };
    match v["op"].as_str() {
        Some("subscribe") => {
            let Some(list) = v["subscriptions"].as_array() else {
                return Some(status(2, "subscribe: no subscriptions array"));
            };
            for s in list {
                let (Some(id), Some(channel)) = (s["id"].as_u64(), s["channelId"].as_u64()) else {
                    return Some(status(2, "subscribe: id and channelId are numbers"));
                };
                let (Ok(id), Ok(channel)) = (u32::try_from(id), u32::try_from(channel)) else {
                    return Some(status(2, "subscribe: id out of range"));
                };
                let sh = lock(shared);
                if !sh.channels.contains_key(&channel) {
                    return Some(status(1, &format!("no channel {channel}")));
                }
                if subs.len() >= MAX_SUBSCRIPTIONS && !subs.contains_key(&id) {
                    return Some(status(2, "too many subscriptions"));
                }
                subs.insert(id, channel);
                if let Some(p) = sh.latched.get(&channel) {
                    let latched = Out::ForSub {
                        sub: id,
                        stamp: 0,
                        payload: Arc::clone(p),
                    };
                    if tx.try_send(latched).is_err() {
                        tracing::debug!("a viewer's queue is full: latched message dropped");
                    }
                }
            }
            None
        }
        Some("unsubscribe") => {
            for id in v["subscriptionIds"].as_array().into_iter().flatten() {
                if let Some(id) = id.as_u64().and_then(|i| u32::try_from(i).ok()) {
                    subs.remove(&id);
                }
            }
            None
        }
        Some(op) => Some(status(
            1,
            &format!("{op} is not supported: this server is read-only"),
        )),
        None => Some(status(2, "a message without op")),
    }
}

/// One device shown, whatever its interface.
trait Shown {
    /// Sends what arrived to the clients.
    fn forward(&mut self, shared: &Mutex<Shared>, epoch: &dyn Fn(u64) -> u64);
    fn alive(&self) -> bool;
    /// Notified when the driver published.
    fn listener(&self) -> Rc<Listener<ipc::Service>>;
    /// Its channels' ids.
    fn channels(&self) -> &[u32];
}

struct Dev<I: Interface> {
    client: Client<I>,
    listener: Rc<Listener<ipc::Service>>,
    state: u32,
    joints: Option<u32>,
    /// The arm's frame transforms: their channel, its chain and its joints' signs.
    tf: Option<(u32, Arm)>,
    channels: Vec<u32>,
}

/// An arm limber knows the chain of: the chain and the sign of each device joint against
/// the chain's variable.
#[derive(Clone)]
struct Arm {
    chain: Chain,
    signs: Vec<f64>,
}

impl<I: Interface> Shown for Dev<I> {
    fn forward(&mut self, shared: &Mutex<Shared>, epoch: &dyn Fn(u64) -> u64) {
        if let Err(e) = self.listener.try_wait(|_| {}) {
            tracing::debug!(device = %self.client.device(), error = %e, "cannot consume notifications");
        }
        let mut states = Vec::new();
        if let Err(e) = self.client.relay_states(|d| states.push(*d)) {
            tracing::warn!(device = %self.client.device(), error = %e, "cannot take the states");
        }
        if states.is_empty() {
            return;
        }
        let mut sh = lock(shared);
        for d in states {
            let stamp = epoch(d.header().stamp_ns);
            let mut v = d.json();
            v["device"] = json!(self.client.device().to_string());
            let payload = Arc::new(v.to_string().into_bytes());
            let channel = self.state;
            sh.broadcast(|| Out::Data {
                channel,
                stamp,
                payload: Arc::clone(&payload),
            });
            if let (Some(channel), Some(joints)) = (self.joints, schema::joints_of(&d)) {
                let payload = Arc::new(
                    schema::joint_states(&joints, stamp)
                        .to_string()
                        .into_bytes(),
                );
                sh.broadcast(|| Out::Data {
                    channel,
                    stamp,
                    payload: Arc::clone(&payload),
                });
                if let Some((channel, arm)) = &self.tf {
                    let q: Vec<f64> = joints.iter().map(|(p, _)| *p).collect();
                    let v = frame_transforms(&arm.chain, &arm.signs, &q, stamp);
                    let payload = Arc::new(v.to_string().into_bytes());
                    sh.broadcast(|| Out::Data {
                        channel: *channel,
                        stamp,
                        payload: Arc::clone(&payload),
                    });
                }
            }
        }
    }
    fn alive(&self) -> bool {
        self.client.relay_driver_alive()
    }
    fn listener(&self) -> Rc<Listener<ipc::Service>> {
        Rc::clone(&self.listener)
    }
    fn channels(&self) -> &[u32] {
        &self.channels
    }
}

/// Advertises channel `topic` to every client; its id.
fn advertise(sh: &mut Shared, topic: String, schema_name: &str, schema: String) -> u32 {
    let id = sh.channels.keys().next_back().map_or(1, |k| k + 1);
    let ch = json!({
        "id": id,
        "topic": topic,
        "encoding": "json",
        "schemaName": schema_name,
        "schema": schema,
        "schemaEncoding": "jsonschema",
    });
    sh.channels.insert(id, ch.clone());
    let text = json!({"op": "advertise", "channels": [ch]}).to_string();
    sh.broadcast(|| Out::Text(text.clone()));
    id
}

struct Open<'a> {
    ctx: &'a Context,
    name: &'a DeviceName,
    shared: &'a Mutex<Shared>,
    arm: Option<Arm>,
}

impl InterfaceVisitor for Open<'_> {
    type Output = Result<Box<dyn Shown>, String>;
    fn visit<I: Interface>(self) -> Self::Output {
        let dev = self.name.to_string();
        let client = Client::<I>::connect(self.ctx, &dev).map_err(|e| e.to_string())?;
        let listener = Rc::new(client.relay_listener().map_err(|e| e.to_string())?);
        let mut sh = lock(self.shared);
        let state = advertise(
            &mut sh,
            format!("/{dev}/state"),
            I::Data::LAYOUT.type_name,
            json!({"type": "object", "description": "the state as `limber echo --json` prints it (docs/reference/echo-json.md)"}).to_string(),
        );
        let joints = schema::has_joints::<I::Data>().then(|| {
            advertise(
                &mut sh,
                format!("/{dev}/joint_states"),
                schema::JOINT_STATES,
                schema::joint_states_schema(),
            )
        });
        let mut channels: Vec<u32> = [Some(state), joints].into_iter().flatten().collect();
        let mut tf = None;
        if let Some(arm) = self.arm {
            let urdf = urdf_with_signs(&arm.chain, self.name.robot(), &arm.signs);
            let id = advertise(
                &mut sh,
                format!("/{dev}/tf"),
                "foxglove.FrameTransforms",
                json!({"type": "object", "description": "the URDF's frames, base_link to tool"})
                    .to_string(),
            );
            channels.push(id);
            tf = Some((id, arm));
            let id = advertise(
                &mut sh,
                format!("/{dev}/robot_description"),
                "std_msgs/String",
                json!({"type": "object", "properties": {"data": {"type": "string"}}}).to_string(),
            );
            let payload = json!({ "data": urdf }).to_string().into_bytes();
            sh.latched.insert(id, Arc::new(payload));
            channels.push(id);
        }
        Ok(Box::new(Dev::<I> {
            client,
            listener,
            state,
            joints,
            tf,
            channels,
        }))
    }
}

/// The arm of actuator array `device` offered by `driver`, if limber knows its chain: the
/// Pioneer arm's (its actarray angles against the kinematic θ:
/// [`limber_kinematics::pioneer::DRIVER_SIGNS`]); simarm's built-in arm, or the chain
/// given.
fn arm_of(driver: &str, device: &DeviceName, config: &ViewConfig) -> Option<Arm> {
    if device.interface() != InterfaceKind::ActArray || device.index() != 0 {
        return None;
    }
    Some(match driver {
        "pioneer" => Arm {
            chain: Chain::pioneer5(),
            signs: limber_kinematics::pioneer::DRIVER_SIGNS.to_vec(),
        },
        "simarm" => Arm {
            chain: config
                .simarm_chain
                .clone()
                .unwrap_or_else(Chain::default_6dof),
            signs: Vec::new(),
        },
        _ => return None,
    })
}

/// No URDF for a device ([`urdf_of_device`]).
#[derive(Debug, Error)]
#[error("no URDF for {0}: limber knows the chains of actarray/0 of the pioneer and simarm drivers")]
pub struct NoUrdf(pub String);

/// The URDF `limber view` serves for `device`: its driver's (found in `domain`) arm chain, or
/// when no driver runs, the one its robot name suggests (`pioneer`, `simarm`).
pub fn urdf_of_device(domain: &Domain, device: &DeviceName) -> Result<String, NoUrdf> {
    let driver = list_devices(domain)
        .ok()
        .and_then(|l| l.into_iter().find(|d| &d.name == device))
        .map(|d| d.driver)
        .unwrap_or_else(|| device.robot().to_string());
    arm_of(&driver, device, &ViewConfig::default())
        .map(|a| urdf_with_signs(&a.chain, device.robot(), &a.signs))
        .ok_or_else(|| NoUrdf(device.to_string()))
}

/// One connection counted while its thread lives.
struct Live(Arc<AtomicUsize>);

impl Live {
    fn new(count: &Arc<AtomicUsize>) -> Live {
        count.fetch_add(1, Ordering::Relaxed);
        Live(Arc::clone(count))
    }
}

impl Drop for Live {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::Relaxed);
    }
}

/// Serves the domain's devices to Foxglove until `stop` returns true.
pub fn view(
    domain: &Domain,
    config: &ViewConfig,
    stop: &dyn Fn() -> bool,
    report: &mut dyn FnMut(ViewEvent),
) -> Result<(), ViewError> {
    let listener = TcpListener::bind(config.listen).map_err(|source| ViewError::Listen {
        addr: config.listen,
        source,
    })?;
    let local = listener.local_addr().map_err(|source| ViewError::Listen {
        addr: config.listen,
        source,
    })?;
    let ctx =
        Context::new(domain, Role::Client, "limber-view").map_err(|source| ViewError::Domain {
            domain: domain.name().to_string(),
            source,
        })?;
    let shared: Arc<Mutex<Shared>> = Arc::default();
    {
        let accepted = Arc::clone(&shared);
        let max = config.max_clients;
        let (tx, rx) = sync_channel::<SocketAddr>(16);
        // Connections being served or shaking hands: beyond twice the viewers admitted, a
        // new one is closed at once (a flood of idle connections costs no thread each).
        let live = Arc::new(AtomicUsize::new(0));
        std::thread::Builder::new()
            .name("limber-view-accept".into())
            .spawn(move || {
                for s in listener.incoming() {
                    match s {
                        Ok(s) if live.load(Ordering::Relaxed) >= 2 * max => {
                            tracing::warn!(peer = ?s.peer_addr().ok(), "too many connections: closed");
                        }
                        Ok(s) => {
                            if let Ok(p) = s.peer_addr()
                                && tx.try_send(p).is_err()
                            {
                                tracing::debug!(peer = %p, "a viewer not reported");
                            }
                            let shared = Arc::clone(&accepted);
                            let guard = Live::new(&live);
                            if let Err(e) = std::thread::Builder::new()
                                .name("limber-view-read".into())
                                .spawn(move || {
                                    serve_client(s, shared, max);
                                    drop(guard);
                                })
                            {
                                tracing::warn!(error = %e, "cannot serve a viewer");
                            }
                        }
                        Err(e) => tracing::warn!(error = %e, "cannot accept a viewer"),
                    }
                }
            })
            .map_err(|source| ViewError::Listen {
                addr: local,
                source,
            })?;
        report(ViewEvent::Listening(local));
        run(
            &ctx,
            domain,
            config,
            &shared,
            stop,
            &mut |ev| report(ev),
            &rx,
        )
    }
}

/// The loop: new devices every second, their states as they come.
fn run(
    ctx: &Context,
    domain: &Domain,
    config: &ViewConfig,
    shared: &Mutex<Shared>,
    stop: &dyn Fn() -> bool,
    report: &mut dyn FnMut(ViewEvent),
    clients: &Receiver<SocketAddr>,
) -> Result<(), ViewError> {
    let offset = {
        let rt = rustix::time::clock_gettime(rustix::time::ClockId::Realtime);
        i128::from(rt.tv_sec) * 1_000_000_000 + i128::from(rt.tv_nsec) - i128::from(monotonic_ns())
    };
    let epoch = move |mono: u64| u64::try_from(i128::from(mono) + offset).unwrap_or(0);
    let mut devices: BTreeMap<DeviceName, Box<dyn Shown>> = BTreeMap::new();
    while !stop() {
        for info in list_devices(domain)?.into_iter().filter(|d| d.alive) {
            if devices.contains_key(&info.name) {
                continue;
            }
            let arm = arm_of(&info.driver, &info.name, config);
            match info.name.interface().visit(Open {
                ctx,
                name: &info.name,
                shared,
                arm,
            }) {
                Ok(d) => {
                    report(ViewEvent::Device(info.name.clone()));
                    devices.insert(info.name, d);
                }
                Err(e) => tracing::warn!(device = %info.name, error = %e, "cannot show"),
            }
        }
        // A device whose driver is gone: its channels are withdrawn.
        devices.retain(|name, d| {
            if d.alive() {
                return true;
            }
            tracing::info!(device = %name, "driver gone: no longer shown");
            let mut sh = lock(shared);
            for id in d.channels() {
                sh.channels.remove(id);
                sh.latched.remove(id);
            }
            let text = json!({"op": "unadvertise", "channelIds": d.channels()}).to_string();
            sh.broadcast(|| Out::Text(text.clone()));
            false
        });
        // Until the next look at the domain: woken by the drivers' notifications.
        let ws = WaitSetBuilder::new()
            .signal_handling_mode(SignalHandlingMode::Disabled)
            .create::<ipc::Service>()
            .map_err(|e| LoopError::WaitSet(e.into()))?;
        let listeners: Vec<_> = devices.values().map(|d| d.listener()).collect();
        let mut guards = Vec::with_capacity(listeners.len());
        for l in &listeners {
            guards.push(
                ws.attach_notification(l.as_ref())
                    .map_err(|e| LoopError::WaitSet(e.into()))?,
            );
        }
        let next_discovery = Instant::now() + DISCOVERY;
        while !stop() && Instant::now() < next_discovery {
            ws.wait_and_process_once_with_timeout(|_| CallbackProgression::Continue, IDLE_WAIT)
                .map_err(LoopError::Wait)?;
            for d in devices.values_mut() {
                d.forward(shared, &epoch);
            }
            while let Ok(peer) = clients.try_recv() {
                report(ViewEvent::Client(peer));
            }
        }
        drop(guards);
    }
    Ok(())
}

/// The most subscriptions one viewer may hold (a hostile one cannot grow the server's
/// memory without bound).
const MAX_SUBSCRIPTIONS: usize = 1024;

/// How often the domain is looked at for new devices and drivers gone.
const DISCOVERY: Duration = Duration::from_secs(1);
/// The longest the loop waits without a notification (to look at `stop`).
const IDLE_WAIT: Duration = Duration::from_millis(100);
