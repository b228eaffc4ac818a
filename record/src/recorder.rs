//! `limber record`: every state, outcome and driver statistics of a domain into an MCAP
//! file.
//!
//! The recorder is a client like any other, in a process of its own: drivers never wait
//! for it. Its main thread takes what the devices published (woken by their
//! notifications) and hands each message to a writer thread through a bounded queue; when
//! the disk is slower than the devices, messages beyond the queue are dropped and counted,
//! never buffered without bound. A state missed before it reached the recorder (the
//! subscriber's buffer overflowed) shows as a gap in the state header's sequence numbers,
//! counted as `missed`.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::rc::Rc;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{SyncSender, TrySendError, sync_channel};
use std::time::{Duration, Instant};

use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::*;
use limber_interfaces::control::OutcomeMsg;
use limber_interfaces::diagnostics::DriverStats;
use limber_interfaces::{HasHeader, Interface, InterfaceVisitor, Message, ReplyBody, WireStruct};
use limber_services::diagnostics::{StatsReader, list_drivers};
use limber_services::event_loop::LoopError;
use limber_services::{Client, Context, DeviceName, Domain, Role, list_devices, monotonic_ns};
use thiserror::Error;
use zerocopy::IntoBytes;

use crate::mcap::{Compression, LAYOUT_SCHEMA_ENCODING, WIRE_ENCODING, WriteError};
use crate::schema;

/// How `record` runs.
#[derive(Debug, Clone)]
pub struct RecordConfig {
    /// The devices to record (`robot/interface/index`); empty: every device of the domain,
    /// as they come.
    pub devices: Vec<String>,
    /// Stop after this long (None: until `stop`).
    pub duration: Option<Duration>,
    /// How chunks are compressed.
    pub compression: Compression,
    /// Uncompressed bytes per chunk.
    pub chunk_size: usize,
    /// Messages the writer thread may have waiting at most.
    pub queue: usize,
    /// Start a new file when this one has this many bytes (files `<stem>_0.mcap`,
    /// `<stem>_1.mcap`... once either split is set).
    pub split_bytes: Option<u64>,
    /// Start a new file when this one is this old.
    pub split_time: Option<Duration>,
}

impl Default for RecordConfig {
    fn default() -> Self {
        RecordConfig {
            devices: Vec::new(),
            duration: None,
            compression: Compression::Lz4,
            chunk_size: 1 << 20,
            queue: 4096,
            split_bytes: None,
            split_time: None,
        }
    }
}

/// Recording failed.
#[derive(Debug, Error)]
pub enum RecordError {
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
    /// A device named on the command line is not a device name.
    #[error(transparent)]
    Name(#[from] limber_services::NameError),
    /// The output file could not be created.
    #[error("cannot create {path}: {source}")]
    Create {
        /// The file.
        path: PathBuf,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// Writing the file failed.
    #[error(transparent)]
    Write(#[from] WriteError),
    /// The writer thread could not be started.
    #[error("cannot start the writer thread: {0}")]
    Thread(#[source] std::io::Error),
    /// The writer thread panicked (a bug).
    #[error("the writer thread panicked")]
    WriterPanicked,
    /// Waiting for the devices failed.
    #[error("cannot wait for the devices: {0}")]
    Wait(#[from] LoopError),
}

/// What `record` reports as it runs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum RecordEvent {
    /// A device is recorded from now on (its channels are declared, its geometry taken).
    Recording(DeviceName),
    /// How far it is (about once a second, and once at the end).
    Progress(Progress),
}

/// How far a recording is (for the progress line and the final report).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Progress {
    /// Messages written to the file.
    pub messages: u64,
    /// Bytes written to the file.
    pub bytes: u64,
    /// Messages dropped because the writer fell behind.
    pub dropped: u64,
    /// States that never reached the recorder (gaps in their sequence numbers).
    pub missed: u64,
    /// Channels.
    pub channels: u64,
    /// Time since the recording began.
    pub elapsed: Duration,
}

#[derive(Default)]
pub(crate) struct Counters {
    pub(crate) messages: AtomicU64,
    pub(crate) bytes: AtomicU64,
    dropped: AtomicU64,
    missed: AtomicU64,
    pub(crate) channels: AtomicU64,
}

/// What the receiving side hands to the writer thread.
pub(crate) enum Item {
    Channel {
        key: u32,
        topic: String,
        schema: (String, String, String),
        encoding: &'static str,
        metadata: Vec<(String, String)>,
    },
    Message {
        key: u32,
        log_time: u64,
        publish_time: u64,
        data: Vec<u8>,
    },
}

/// The receiving side's end of the queue, and the clock.
struct Sink {
    tx: SyncSender<Item>,
    counters: Arc<Counters>,
    next_key: u32,
    /// CLOCK_REALTIME minus CLOCK_MONOTONIC when the recording began.
    offset_ns: i128,
}

impl Sink {
    fn epoch_ns(&self, mono: u64) -> u64 {
        u64::try_from(i128::from(mono) + self.offset_ns).unwrap_or(0)
    }

    /// Declares a channel of limber's wire struct `L`.
    fn wire_channel<L: WireStruct>(&mut self, topic: String, meta: &[(&str, &str)]) -> Option<u32> {
        let mut metadata: Vec<(String, String)> = meta
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect();
        metadata.push(("type_name".into(), L::LAYOUT.type_name.into()));
        self.channel(
            topic,
            (
                L::LAYOUT.type_name.to_string(),
                LAYOUT_SCHEMA_ENCODING.to_string(),
                schema::layout_schema(&L::LAYOUT),
            ),
            WIRE_ENCODING,
            metadata,
        )
    }

    fn channel(
        &mut self,
        topic: String,
        schema: (String, String, String),
        encoding: &'static str,
        metadata: Vec<(String, String)>,
    ) -> Option<u32> {
        let key = self.next_key;
        self.next_key += 1;
        let item = Item::Channel {
            key,
            topic,
            schema,
            encoding,
            metadata,
        };
        // A channel is never dropped: its messages would have nowhere to go.
        match self.tx.send(item) {
            Ok(()) => Some(key),
            Err(_) => {
                tracing::warn!("the writer thread ended: channel not recorded");
                None
            }
        }
    }

    fn message(&self, key: Option<u32>, received: u64, acquired: u64, data: Vec<u8>) {
        let Some(key) = key else { return };
        let item = Item::Message {
            key,
            log_time: self.epoch_ns(received),
            publish_time: self.epoch_ns(if acquired == 0 { received } else { acquired }),
            data,
        };
        match self.tx.try_send(item) {
            Ok(()) => {}
            Err(TrySendError::Full(_)) | Err(TrySendError::Disconnected(_)) => {
                self.counters.dropped.fetch_add(1, Ordering::Relaxed);
            }
        }
    }
}

/// One recorded device, whatever its interface.
trait Recorded {
    fn drain(&mut self, sink: &Sink);
    fn listener(&self) -> Rc<Listener<ipc::Service>>;
    fn alive(&self) -> bool;
}

struct Dev<I: Interface> {
    client: Client<I>,
    listener: Rc<Listener<ipc::Service>>,
    state: Option<u32>,
    outcome: Option<u32>,
    joints: Option<u32>,
    last_seq: Option<u64>,
}

impl<I: Interface> Recorded for Dev<I> {
    fn drain(&mut self, sink: &Sink) {
        let received = monotonic_ns();
        let mut states = Vec::new();
        if let Err(e) = self.client.relay_states(|d| states.push(*d)) {
            tracing::warn!(device = %self.client.device(), error = %e, "cannot take the states");
        }
        for d in states {
            let h = d.header();
            if let Some(last) = self.last_seq
                && h.seq > last + 1
            {
                sink.counters
                    .missed
                    .fetch_add(h.seq - last - 1, Ordering::Relaxed);
            }
            self.last_seq = Some(h.seq);
            if let Some(joints) = schema::joints_of(&d) {
                let js = schema::joint_states(&joints, sink.epoch_ns(h.stamp_ns));
                sink.message(
                    self.joints,
                    received,
                    h.stamp_ns,
                    js.to_string().into_bytes(),
                );
            }
            sink.message(self.state, received, h.stamp_ns, d.as_bytes().to_vec());
        }
        let mut outcomes = Vec::new();
        if let Err(e) = self.client.relay_outcomes(|o| outcomes.push(*o)) {
            tracing::warn!(device = %self.client.device(), error = %e, "cannot take the outcomes");
        }
        for o in outcomes {
            sink.message(self.outcome, received, o.stamp_ns, o.as_bytes().to_vec());
        }
        if let Err(e) = self.listener.try_wait(|_| {}) {
            tracing::debug!(device = %self.client.device(), error = %e, "cannot consume notifications");
        }
    }
    fn listener(&self) -> Rc<Listener<ipc::Service>> {
        Rc::clone(&self.listener)
    }
    fn alive(&self) -> bool {
        self.client.relay_driver_alive()
    }
}

struct Open<'a> {
    ctx: &'a Context,
    name: &'a DeviceName,
    sink: &'a mut Sink,
}

impl InterfaceVisitor for Open<'_> {
    type Output = Result<Box<dyn Recorded>, String>;
    fn visit<I: Interface>(self) -> Self::Output {
        let dev = self.name.to_string();
        // No wait: a named device that is not there yet is looked for again next round.
        let mut client = Client::<I>::connect(self.ctx, &dev).map_err(|e| e.to_string())?;
        client.watch_outcomes().map_err(|e| e.to_string())?;
        let listener = client.relay_listener().map_err(|e| e.to_string())?;
        let iface = I::KIND.name();
        let meta = |kind: &'static str| {
            [
                ("device", dev.as_str()),
                ("interface", iface),
                ("channel", kind),
            ]
        };
        // The geometry first (its reply as the driver sent it): what replay answers with
        // and what a URDF is made from.
        match client.request_with_timeout(&I::GEOMETRY, Duration::from_millis(1500)) {
            Ok(reply) => {
                let mut raw = I::ReplyMsg::default();
                I::Reply::write(I::GEOMETRY.kind(), Ok(&reply), &mut raw);
                let key = self
                    .sink
                    .wire_channel::<I::ReplyMsg>(format!("/{dev}/geometry"), &meta("geometry"));
                let now = monotonic_ns();
                self.sink.message(key, now, now, raw.as_bytes().to_vec());
            }
            Err(e) => tracing::warn!(device = dev, error = %e, "no geometry recorded"),
        }
        let state = self
            .sink
            .wire_channel::<I::Data>(format!("/{dev}/state"), &meta("state"));
        let outcome = self
            .sink
            .wire_channel::<OutcomeMsg>(format!("/{dev}/outcome"), &meta("outcome"));
        let joints = if schema::has_joints::<I::Data>() {
            self.sink.channel(
                format!("/{dev}/joint_states"),
                (
                    schema::JOINT_STATES.into(),
                    "jsonschema".into(),
                    schema::joint_states_schema(),
                ),
                "json",
                meta("joint_states")
                    .iter()
                    .map(|(k, v)| (k.to_string(), v.to_string()))
                    .collect(),
            )
        } else {
            None
        };
        Ok(Box::new(Dev::<I> {
            client,
            listener: Rc::new(listener),
            state,
            outcome,
            joints,
            last_seq: None,
        }))
    }
}

fn realtime_minus_monotonic() -> i128 {
    let rt = rustix::time::clock_gettime(rustix::time::ClockId::Realtime);
    let mono = monotonic_ns();
    i128::from(rt.tv_sec) * 1_000_000_000 + i128::from(rt.tv_nsec) - i128::from(mono)
}

/// Records `domain` into `path` until `stop` returns true or the configured duration has
/// passed; `report` hears of each device recorded and of the progress.
pub fn record(
    domain: &Domain,
    path: &Path,
    config: &RecordConfig,
    stop: &dyn Fn() -> bool,
    report: &mut dyn FnMut(RecordEvent),
) -> Result<Progress, RecordError> {
    let named: Vec<DeviceName> = config
        .devices
        .iter()
        .map(|d| d.parse())
        .collect::<Result<_, _>>()?;
    let ctx = Context::new(domain, Role::Client, "limber-record").map_err(|source| {
        RecordError::Domain {
            domain: domain.name().to_string(),
            source,
        }
    })?;
    let counters = Arc::new(Counters::default());
    let (tx, rx) = sync_channel::<Item>(config.queue.max(16));
    let offset_ns = realtime_minus_monotonic();
    let metadata = vec![
        ("domain".to_string(), domain.name().to_string()),
        (
            "layout_version".to_string(),
            limber_interfaces::LAYOUT_VERSION.to_string(),
        ),
        (
            "realtime_minus_monotonic_ns".to_string(),
            offset_ns.to_string(),
        ),
    ];
    let writer = {
        let (path, config, counters) = (path.to_path_buf(), config.clone(), Arc::clone(&counters));
        std::thread::Builder::new()
            .name("limber-record-writer".into())
            .spawn(move || crate::files::write_all(&path, rx, &config, &counters, &metadata))
            .map_err(RecordError::Thread)?
    };
    let mut sink = Sink {
        tx,
        counters: Arc::clone(&counters),
        next_key: 0,
        offset_ns,
    };
    let started = Instant::now();
    let result = receive(&ctx, domain, &named, config, &mut sink, stop, &mut |ev| {
        report(ev.unwrap_or_else(|| RecordEvent::Progress(snapshot(&counters, started))))
    });
    drop(sink);
    let written = writer.join().map_err(|_| RecordError::WriterPanicked)?;
    result?;
    written?;
    let p = snapshot(&counters, started);
    report(RecordEvent::Progress(p));
    Ok(p)
}

fn snapshot(c: &Counters, started: Instant) -> Progress {
    Progress {
        messages: c.messages.load(Ordering::Relaxed),
        bytes: c.bytes.load(Ordering::Relaxed),
        dropped: c.dropped.load(Ordering::Relaxed),
        missed: c.missed.load(Ordering::Relaxed),
        channels: c.channels.load(Ordering::Relaxed),
        elapsed: started.elapsed(),
    }
}

/// The longest the loop waits for a notification: driver statistics have none, and are
/// looked at this often.
const POLL: Duration = Duration::from_millis(100);
/// How often the domain is looked at for new devices and drivers.
const DISCOVERY: Duration = Duration::from_secs(1);

/// The receiving loop (this thread: iceoryx2's ports stay on the thread that made them).
fn receive(
    ctx: &Context,
    domain: &Domain,
    named: &[DeviceName],
    config: &RecordConfig,
    sink: &mut Sink,
    stop: &dyn Fn() -> bool,
    report: &mut dyn FnMut(Option<RecordEvent>),
) -> Result<(), RecordError> {
    let started = Instant::now();
    let end = config.duration.map(|d| started + d);
    let over = || stop() || end.is_some_and(|e| Instant::now() >= e);
    let mut devices: BTreeMap<DeviceName, Box<dyn Recorded>> = BTreeMap::new();
    let mut drivers: BTreeMap<String, (StatsReader, Option<u32>)> = BTreeMap::new();
    let mut refused: BTreeSet<DeviceName> = BTreeSet::new();
    let mut last_progress = Instant::now();
    while !over() {
        for name in discover(ctx, domain, named, sink, &mut devices, &mut refused)? {
            report(Some(RecordEvent::Recording(name)));
        }
        let robots: BTreeSet<String> = devices.keys().map(|d| d.robot().to_string()).collect();
        match list_drivers(domain) {
            Ok(list) => {
                for robot in list.into_iter().filter(|r| robots.contains(r)) {
                    if drivers.contains_key(&robot) {
                        continue;
                    }
                    if let Ok(r) = StatsReader::open(ctx, &robot) {
                        let key = sink.wire_channel::<DriverStats>(
                            format!("/{robot}/driver"),
                            &[("robot", robot.as_str()), ("channel", "driver")],
                        );
                        drivers.insert(robot, (r, key));
                    }
                }
            }
            Err(e) => tracing::warn!(error = %e, "cannot list the drivers"),
        }
        let ws = WaitSetBuilder::new()
            .signal_handling_mode(SignalHandlingMode::Disabled)
            .create::<ipc::Service>()
            .map_err(|e| LoopError::WaitSet(e.into()))?;
        let listeners: Vec<Rc<Listener<ipc::Service>>> =
            devices.values().map(|d| d.listener()).collect();
        let mut guards = Vec::new();
        for l in &listeners {
            guards.push(
                ws.attach_notification(l.as_ref())
                    .map_err(|e| LoopError::WaitSet(e.into()))?,
            );
        }
        let next_discovery = Instant::now() + DISCOVERY;
        while !over() && Instant::now() < next_discovery {
            ws.wait_and_process_once_with_timeout(|_| CallbackProgression::Continue, POLL)
                .map_err(LoopError::Wait)?;
            for d in devices.values_mut() {
                d.drain(sink);
            }
            for (robot, (r, key)) in drivers.iter_mut() {
                match r.refresh() {
                    Ok(true) => {
                        if let Some(s) = r.latest() {
                            let now = monotonic_ns();
                            sink.message(*key, now, s.header.stamp_ns, s.as_bytes().to_vec());
                        }
                    }
                    Ok(false) => {}
                    Err(e) => tracing::debug!(robot, error = %e, "cannot read driver statistics"),
                }
            }
            if last_progress.elapsed() >= Duration::from_secs(1) {
                last_progress = Instant::now();
                report(None);
            }
        }
        drop(guards);
        // Devices whose driver is gone are closed (a new driver is found again).
        devices.retain(|name, d| {
            let alive = d.alive();
            if !alive {
                tracing::info!(device = %name, "driver gone: no longer recorded");
            }
            alive
        });
    }
    // What arrived since the last wake-up.
    for d in devices.values_mut() {
        d.drain(sink);
    }
    Ok(())
}

/// Connects to the devices not recorded yet: the named ones, or every live one; returns
/// those it connected to.
fn discover(
    ctx: &Context,
    domain: &Domain,
    named: &[DeviceName],
    sink: &mut Sink,
    devices: &mut BTreeMap<DeviceName, Box<dyn Recorded>>,
    refused: &mut BTreeSet<DeviceName>,
) -> Result<Vec<DeviceName>, RecordError> {
    let mut added = Vec::new();
    let wanted: Vec<DeviceName> = if named.is_empty() {
        list_devices(domain)?
            .into_iter()
            .filter(|d| d.alive)
            .map(|d| d.name)
            .collect()
    } else {
        named.to_vec()
    };
    for name in wanted {
        if devices.contains_key(&name) {
            continue;
        }
        match name.interface().visit(Open {
            ctx,
            name: &name,
            sink,
        }) {
            Ok(d) => {
                tracing::info!(device = %name, "recording");
                refused.remove(&name);
                added.push(name.clone());
                devices.insert(name, d);
            }
            Err(e) => {
                if refused.insert(name.clone()) {
                    tracing::warn!(device = %name, error = %e, "cannot record the device");
                }
            }
        }
    }
    Ok(added)
}
