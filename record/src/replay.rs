//! `limber replay`: a recorded file republished into a domain as if its devices were live.
//!
//! Each recorded device is hosted under its name (driver `replay`), as a bridge's mirror
//! hosts a remote device: its states are published as recorded (header included, the stamp
//! made this host's time of publication, so that clients judge their age as a live
//! state's), its outcomes too, its recorded geometry answers geometry requests, and each
//! robot's driver statistics are published on its `driver` channel. Commands are refused
//! `UNSUPPORTED` (a recording is not an arm: nothing moves), other requests too, lease
//! requests likewise. Messages keep their recorded spacing, scaled by
//! `rate`.

use std::collections::BTreeMap;
use std::fs::File;
use std::path::Path;
use std::time::{Duration, Instant};

use limber_interfaces::control::{LeaseReply, OutcomeMsg};
use limber_interfaces::diagnostics::DriverStats;
use limber_interfaces::prelude::*;
use limber_interfaces::{
    Envelope, HasHeader, Interface, InterfaceVisitor, Message, ReplyBody, ReplyEnvelope, WireStruct,
};
use limber_services::diagnostics::{DiagnosticsError, StatsPublisher};
use limber_services::{
    Context, DeviceHost, DeviceName, Domain, HostError, PublishError, Role, monotonic_ns,
};
use thiserror::Error;
use zerocopy::FromBytes;

use crate::mcap::{Channel, McapReader, ReadError, Record};

/// The driver name replayed devices are hosted under.
pub const REPLAY_DRIVER: &str = "replay";

/// How `replay` runs.
#[derive(Debug, Clone)]
pub struct ReplayConfig {
    /// Speed: 1 as recorded, 2 twice as fast (more than 0).
    pub rate: f64,
    /// Start again at the end, until stopped.
    pub looped: bool,
}

impl Default for ReplayConfig {
    fn default() -> Self {
        ReplayConfig {
            rate: 1.0,
            looped: false,
        }
    }
}

/// What `replay` reports as it runs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ReplayEvent {
    /// A recorded device is hosted in the domain now.
    Hosting(DeviceName),
    /// A robot's driver statistics are published now.
    Driver(String),
    /// A pass over the file begins (1, 2, ... with `looped`).
    Pass(u64),
}

/// Replaying failed.
#[derive(Debug, Error)]
pub enum ReplayError {
    /// The rate is not a positive number.
    #[error("the rate must be a number above 0, not {0}")]
    Rate(f64),
    /// The file could not be opened.
    #[error("cannot open {path}: {source}")]
    Open {
        /// The file.
        path: String,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// The file is not a readable MCAP file.
    #[error("{path}: {source}")]
    Read {
        /// The file.
        path: String,
        /// Why.
        #[source]
        source: ReadError,
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
    /// A recorded device could not be hosted (a live driver offers it?).
    #[error("cannot host {device}: {source}")]
    Host {
        /// The device.
        device: String,
        /// Why.
        #[source]
        source: HostError,
    },
    /// A robot's driver statistics could not be offered or published.
    #[error("driver statistics of {robot}: {source}")]
    Stats {
        /// The robot.
        robot: String,
        /// Why.
        #[source]
        source: DiagnosticsError,
    },
    /// A channel was recorded with another layout than this limber's.
    #[error("channel {topic} holds {found:?}, this limber speaks {expected:?}")]
    Layout {
        /// The channel's topic.
        topic: String,
        /// Its type name in the file.
        found: String,
        /// This limber's.
        expected: &'static str,
    },
    /// A message does not have its struct's size.
    #[error("a message of {len} bytes on {topic} ({expected} expected)")]
    Size {
        /// The channel's topic.
        topic: String,
        /// Its length.
        len: usize,
        /// Its struct's size.
        expected: usize,
    },
    /// Publishing a state or an outcome failed.
    #[error("cannot publish on {topic}: {source}")]
    Publish {
        /// The channel's topic.
        topic: String,
        /// Why.
        #[source]
        source: PublishError,
    },
}

/// One replayed device, whatever its interface.
trait Replayed {
    fn state(&mut self, topic: &str, data: &[u8]) -> Result<(), ReplayError>;
    fn outcome(&mut self, topic: &str, data: &[u8]) -> Result<(), ReplayError>;
    fn geometry(&mut self, topic: &str, data: &[u8]) -> Result<(), ReplayError>;
    /// Serves the clients: new connections, commands (dropped), requests, leases.
    fn serve(&mut self);
    /// Checks the layout of one of its channels.
    fn check(&self, channel: &Channel, kind: &str) -> Result<(), ReplayError>;
}

struct Hosted<I: Interface> {
    host: DeviceHost<I>,
    geometry: Option<I::ReplyMsg>,
}

fn read_exact<T: FromBytes>(topic: &str, data: &[u8]) -> Result<T, ReplayError> {
    T::read_from_bytes(data).map_err(|_| ReplayError::Size {
        topic: topic.to_string(),
        len: data.len(),
        expected: size_of::<T>(),
    })
}

fn check_type(channel: &Channel, expected: &'static str) -> Result<(), ReplayError> {
    let found = channel
        .metadata
        .iter()
        .find(|(k, _)| k == "type_name")
        .map(|(_, v)| v.as_str())
        .unwrap_or("");
    if found != expected {
        return Err(ReplayError::Layout {
            topic: channel.topic.clone(),
            found: found.to_string(),
            expected,
        });
    }
    Ok(())
}

impl<I: Interface> Replayed for Hosted<I> {
    fn state(&mut self, topic: &str, data: &[u8]) -> Result<(), ReplayError> {
        let mut d: I::Data = read_exact(topic, data)?;
        d.header_mut().stamp_ns = monotonic_ns();
        self.host
            .relay_publish(&d)
            .map_err(|source| ReplayError::Publish {
                topic: topic.to_string(),
                source,
            })
    }
    fn outcome(&mut self, topic: &str, data: &[u8]) -> Result<(), ReplayError> {
        let mut o: OutcomeMsg = read_exact(topic, data)?;
        o.stamp_ns = monotonic_ns();
        self.host
            .relay_outcome(&o)
            .map_err(|source| ReplayError::Publish {
                topic: topic.to_string(),
                source,
            })
    }
    fn geometry(&mut self, topic: &str, data: &[u8]) -> Result<(), ReplayError> {
        self.geometry = Some(read_exact(topic, data)?);
        Ok(())
    }
    fn serve(&mut self) {
        let device = self.host.device().clone();
        self.host.relay_housekeeping();
        let mut commands = Vec::new();
        if let Err(e) = self.host.relay_commands(|c| commands.push(*c.meta())) {
            tracing::warn!(device = %device, error = %e, "cannot take the commands");
        }
        // A recording does not move: each command is refused, so its client is told at once.
        for meta in commands {
            let refusal = OutcomeMsg {
                client_id: meta.client_id,
                cmd_seq: meta.seq,
                stamp_ns: monotonic_ns(),
                kind: meta.kind,
                status: Status::Unsupported.code(),
                ..OutcomeMsg::default()
            };
            if let Err(e) = self.host.relay_outcome(&refusal) {
                tracing::warn!(device = %device, error = %e, "cannot refuse a command");
            }
        }
        loop {
            let req = match self.host.relay_take_request() {
                Ok(Some(r)) => r,
                Ok(None) => break,
                Err(e) => {
                    tracing::warn!(device = %device, error = %e, "cannot take the requests");
                    break;
                }
            };
            let meta = *req.message().meta();
            let is_geometry =
                I::Request::read(req.message()).is_ok_and(|r| r.kind() == I::GEOMETRY.kind());
            let mut out = match (is_geometry, self.geometry) {
                (true, Some(g)) => g,
                _ => {
                    let mut out = I::ReplyMsg::default();
                    I::Reply::write(meta.kind, Err(Status::Unsupported), &mut out);
                    out
                }
            };
            let m = out.meta_mut();
            m.client_id = meta.client_id;
            m.seq = meta.seq;
            m.stamp_ns = monotonic_ns();
            if let Err(e) = self.host.relay_answer(req, &out) {
                tracing::debug!(device = %device, error = %e, "reply not delivered");
            }
        }
        loop {
            let req = match self.host.relay_take_lease() {
                Ok(Some(r)) => r,
                Ok(None) => break,
                Err(e) => {
                    tracing::warn!(device = %device, error = %e, "cannot take the lease requests");
                    break;
                }
            };
            let reply = LeaseReply {
                seq: req.message().seq,
                status: Status::Unsupported.code(),
                ..LeaseReply::default()
            };
            if let Err(e) = self.host.relay_answer_lease(req, &reply) {
                tracing::debug!(device = %device, error = %e, "lease reply not delivered");
            }
        }
    }
    fn check(&self, channel: &Channel, kind: &str) -> Result<(), ReplayError> {
        match kind {
            "state" => check_type(channel, I::Data::LAYOUT.type_name),
            "outcome" => check_type(channel, OutcomeMsg::LAYOUT.type_name),
            "geometry" => check_type(channel, I::ReplyMsg::LAYOUT.type_name),
            _ => Ok(()),
        }
    }
}

struct Host<'a> {
    ctx: &'a Context,
    name: &'a DeviceName,
}

impl InterfaceVisitor for Host<'_> {
    type Output = Result<Box<dyn Replayed>, HostError>;
    fn visit<I: Interface>(self) -> Self::Output {
        let host = DeviceHost::<I>::new(self.ctx, self.name, REPLAY_DRIVER)?;
        Ok(Box::new(Hosted::<I> {
            host,
            geometry: None,
        }))
    }
}

/// Where a channel's messages go.
#[derive(Debug, Clone)]
enum Target {
    Device(DeviceName, &'static str),
    Driver(String),
    Ignored,
}

fn meta<'c>(c: &'c Channel, key: &str) -> Option<&'c str> {
    c.metadata
        .iter()
        .find(|(k, _)| k == key)
        .map(|(_, v)| v.as_str())
}

/// The state of a running replay.
struct Replayer<'a> {
    ctx: Context,
    devices: BTreeMap<DeviceName, Box<dyn Replayed>>,
    drivers: BTreeMap<String, StatsPublisher>,
    report: &'a mut dyn FnMut(ReplayEvent),
}

impl Replayer<'_> {
    /// Where channel `c`'s messages go, hosting its device or driver if new.
    fn target(&mut self, c: &Channel) -> Result<Target, ReplayError> {
        let kind = meta(c, "channel").unwrap_or("");
        if kind == "driver" {
            check_type(c, DriverStats::LAYOUT.type_name)?;
            let Some(robot) = meta(c, "robot") else {
                return Ok(Target::Ignored);
            };
            if !self.drivers.contains_key(robot) {
                let p =
                    StatsPublisher::new(&self.ctx, robot).map_err(|source| ReplayError::Stats {
                        robot: robot.to_string(),
                        source,
                    })?;
                self.drivers.insert(robot.to_string(), p);
                (self.report)(ReplayEvent::Driver(robot.to_string()));
            }
            return Ok(Target::Driver(robot.to_string()));
        }
        let kind: &'static str = match kind {
            "state" => "state",
            "outcome" => "outcome",
            "geometry" => "geometry",
            _ => return Ok(Target::Ignored),
        };
        let Some(Ok(name)) = meta(c, "device").map(str::parse::<DeviceName>) else {
            return Ok(Target::Ignored);
        };
        if !self.devices.contains_key(&name) {
            let d = name
                .interface()
                .visit(Host {
                    ctx: &self.ctx,
                    name: &name,
                })
                .map_err(|source| ReplayError::Host {
                    device: name.to_string(),
                    source,
                })?;
            self.devices.insert(name.clone(), d);
            (self.report)(ReplayEvent::Hosting(name.clone()));
        }
        if let Some(d) = self.devices.get(&name) {
            d.check(c, kind)?;
        }
        Ok(Target::Device(name, kind))
    }

    fn serve(&mut self) {
        for d in self.devices.values_mut() {
            d.serve();
        }
    }

    fn deliver(&mut self, target: &Target, topic: &str, data: &[u8]) -> Result<(), ReplayError> {
        match target {
            Target::Device(name, kind) => {
                let Some(d) = self.devices.get_mut(name) else {
                    return Ok(());
                };
                match *kind {
                    "state" => d.state(topic, data),
                    "outcome" => d.outcome(topic, data),
                    _ => d.geometry(topic, data),
                }
            }
            Target::Driver(robot) => {
                let mut s: DriverStats = read_exact(topic, data)?;
                if let Some(p) = self.drivers.get_mut(robot) {
                    p.publish(&mut s).map_err(|source| ReplayError::Stats {
                        robot: robot.to_string(),
                        source,
                    })?;
                }
                Ok(())
            }
            Target::Ignored => Ok(()),
        }
    }

    /// Serves the clients until `due` (or `stop`), in slices short enough that a client's
    /// request is answered promptly.
    fn wait_until(&mut self, due: Instant, stop: &dyn Fn() -> bool) {
        loop {
            self.serve();
            let now = Instant::now();
            if now >= due || stop() {
                return;
            }
            std::thread::sleep((due - now).min(SERVE_SLICE));
        }
    }
}

/// The longest a replay goes without serving its clients while it waits for the next
/// message's time.
const SERVE_SLICE: Duration = Duration::from_millis(5);

/// Replays `path` into `domain` until its end (or, with `looped`, until `stop`); returns
/// the messages published.
pub fn replay(
    domain: &Domain,
    path: &Path,
    config: &ReplayConfig,
    stop: &dyn Fn() -> bool,
    report: &mut dyn FnMut(ReplayEvent),
) -> Result<u64, ReplayError> {
    if !(config.rate.is_finite() && config.rate > 0.0) {
        return Err(ReplayError::Rate(config.rate));
    }
    let shown = path.display().to_string();
    let open = || -> Result<McapReader<File>, ReplayError> {
        let f = File::open(path).map_err(|source| ReplayError::Open {
            path: shown.clone(),
            source,
        })?;
        McapReader::new(f).map_err(|source| ReplayError::Read {
            path: shown.clone(),
            source,
        })
    };
    // The file is checked before anything is offered in the domain.
    let mut reader = open()?;
    let ctx = Context::new(domain, Role::Driver, "limber-replay").map_err(|source| {
        ReplayError::Domain {
            domain: domain.name().to_string(),
            source,
        }
    })?;
    let mut r = Replayer {
        ctx,
        devices: BTreeMap::new(),
        drivers: BTreeMap::new(),
        report,
    };
    let mut published = 0u64;
    let mut pass = 0u64;
    loop {
        pass += 1;
        (r.report)(ReplayEvent::Pass(pass));
        let mut targets: BTreeMap<u16, (Target, String)> = BTreeMap::new();
        let mut clock: Option<(u64, Instant)> = None;
        loop {
            if stop() {
                return Ok(published);
            }
            let rec = reader.next_record().map_err(|source| ReplayError::Read {
                path: shown.clone(),
                source,
            })?;
            match rec {
                None => break,
                Some(Record::Channel(c)) => {
                    let t = r.target(&c)?;
                    targets.insert(c.id, (t, c.topic));
                }
                Some(Record::Message {
                    channel,
                    log_time,
                    data,
                    ..
                }) => {
                    let Some((target, topic)) = targets.get(&channel).cloned() else {
                        continue;
                    };
                    let (t0, start) = *clock.get_or_insert((log_time, Instant::now()));
                    let offset = log_time.saturating_sub(t0) as f64 / 1e9 / config.rate;
                    r.wait_until(start + Duration::from_secs_f64(offset.min(1e9)), stop);
                    r.deliver(&target, &topic, &data)?;
                    published += 1;
                }
                Some(_) => {}
            }
        }
        if !config.looped {
            return Ok(published);
        }
        reader = open()?;
    }
}
