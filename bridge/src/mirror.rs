//! `limber bridge mirror`: remote devices hosted in a local domain.
//!
//! Every device whose liveliness token (`.../alive`) a remote `expose` holds is hosted in
//! this domain under the same name (the robot name prefixed with `--prefix`, if given), as
//! driver `bridge`: its state is the remote state (stamped with this host's clock when it
//! arrives), its clients' commands go to `.../cmd` with this bridge's Zenoh id as their
//! origin, their outcomes (refusals with their reason, preemptions) come back from
//! `.../outcome/<origin>` to the client that sent the command, and their requests become
//! queries on `.../req` with a timeout. When the token goes (the remote driver died, or
//! the remote bridge, or the network for longer than the Zenoh lease), the device is no
//! longer hosted here: its clients see its driver gone.

use std::collections::HashMap;
use std::sync::mpsc;
use std::time::{Duration, Instant};

use limber_interfaces::prelude::*;
use limber_interfaces::{HasHeader, Interface};
use limber_services::relay::{RelayedLease, RelayedRequest};
use limber_services::{Context, DeviceHost, DeviceName, Domain, Role, monotonic_ns};
use thiserror::Error;
use zenoh::Wait;
use zenoh::handlers::FifoChannelHandler;
use zenoh::query::Reply;
use zenoh::sample::{Sample, SampleKind};
use zenoh::{Session, bytes::ZBytes};
use zerocopy::{FromBytes, IntoBytes};

use crate::expose::MIRROR_DRIVER;
use crate::keys::{self, TypeNames};
use crate::session::{self, NetConfig, SessionError};

/// How `mirror` runs.
#[derive(Debug, Clone)]
pub struct MirrorConfig {
    /// The network side.
    pub net: NetConfig,
    /// Prepended to each remote robot name (where local names would collide).
    pub prefix: String,
    /// How long a relayed request may take before its client is told `Timeout`.
    pub request_timeout: Duration,
}

impl Default for MirrorConfig {
    fn default() -> Self {
        MirrorConfig {
            net: NetConfig {
                connect: vec!["tcp/127.0.0.1:7447".into()],
                ..NetConfig::default()
            },
            prefix: String::new(),
            request_timeout: Duration::from_millis(1800),
        }
    }
}

/// What `mirror` reports as it runs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum MirrorEvent {
    /// The Zenoh session is open.
    Ready {
        /// This bridge's Zenoh id (the origin of its commands).
        zid: String,
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
}

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
}

struct Mirrored<I: Interface> {
    local: DeviceName,
    host: DeviceHost<I>,
    cmd_key: String,
    req_key: String,
    lease_key: String,
    names: TypeNames,
    pending: Vec<(RelayedRequest<I>, FifoChannelHandler<Reply>, Instant)>,
    leases: Vec<(RelayedLease, FifoChannelHandler<Reply>, Instant)>,
}

trait MirroredDevice {
    fn state(&mut self, payload: &[u8]);
    fn outcome(&mut self, payload: &[u8]);
    fn poll(&mut self, session: &Session, origin: &str, timeout: Duration);
}

/// The status an error reply of `expose` carries (4 bytes, little-endian).
fn status_of(payload: &ZBytes) -> Status {
    let bytes = payload.to_bytes();
    <[u8; 4]>::try_from(bytes.as_ref())
        .ok()
        .and_then(|b| Status::try_from(u32::from_le_bytes(b)).ok())
        .unwrap_or(Status::LinkDown)
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

    fn poll(&mut self, session: &Session, origin: &str, timeout: Duration) {
        self.host.relay_housekeeping();
        let mut commands = Vec::new();
        if let Err(e) = self
            .host
            .relay_commands(|c| commands.push(c.as_bytes().to_vec()))
        {
            tracing::warn!(device = %self.local, error = %e, "cannot take the commands");
        }
        for c in commands {
            if let Err(e) = session
                .put(&self.cmd_key, c)
                .encoding(keys::encoding(self.names.cmd))
                .attachment(origin)
                .wait()
            {
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
            match session
                .get(&self.req_key)
                .payload(req.message().as_bytes().to_vec())
                .encoding(keys::encoding(self.names.req))
                .attachment(origin)
                .timeout(timeout)
                .wait()
            {
                Ok(replies) => self.pending.push((req, replies, Instant::now() + timeout)),
                Err(e) => {
                    tracing::warn!(device = %self.local, error = %e, "cannot relay a request");
                    let out = crate::keys::nack::<I>(req.message(), Status::LinkDown);
                    if let Err(e) = self.host.relay_answer(req, &out) {
                        tracing::debug!(device = %self.local, error = %e, "reply not delivered");
                    }
                }
            }
        }
        self.poll_leases(session, origin, timeout);
        let now = Instant::now();
        let mut done = Vec::new();
        let mut i = 0;
        while i < self.pending.len() {
            let (req, replies, deadline) = &self.pending[i];
            let answer = match replies.try_recv() {
                Ok(Some(reply)) => Some(match reply.result() {
                    Ok(sample) => {
                        match I::ReplyMsg::read_from_bytes(&sample.payload().to_bytes()) {
                            Ok(r) => r,
                            Err(_) => {
                                tracing::warn!(device = %self.local, "a reply of the wrong size");
                                crate::keys::nack::<I>(req.message(), Status::LinkDown)
                            }
                        }
                    }
                    Err(err) => crate::keys::nack::<I>(req.message(), status_of(err.payload())),
                }),
                Ok(None) if now < *deadline => None,
                // Nobody answered: in time or not at all.
                Ok(None) | Err(_) => Some(crate::keys::nack::<I>(
                    req.message(),
                    if now >= *deadline {
                        Status::Timeout
                    } else {
                        Status::LinkDown
                    },
                )),
            };
            match answer {
                Some(a) => done.push((self.pending.swap_remove(i).0, a)),
                None => i += 1,
            }
        }
        for (req, reply) in done {
            if let Err(e) = self.host.relay_answer(req, &reply) {
                tracing::debug!(device = %self.local, error = %e, "reply not delivered");
            }
        }
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
    /// Relays the clients' lease requests and answers those whose reply came.
    fn poll_leases(&mut self, session: &Session, origin: &str, timeout: Duration) {
        loop {
            let req = match self.host.relay_take_lease() {
                Ok(Some(r)) => r,
                Ok(None) => break,
                Err(e) => {
                    tracing::warn!(device = %self.local, error = %e, "cannot take the lease requests");
                    break;
                }
            };
            match session
                .get(&self.lease_key)
                .payload(req.message().as_bytes().to_vec())
                .encoding(keys::encoding(keys::lease_req_type()))
                .attachment(origin)
                .timeout(timeout)
                .wait()
            {
                Ok(replies) => self.leases.push((req, replies, Instant::now() + timeout)),
                Err(e) => {
                    tracing::warn!(device = %self.local, error = %e, "cannot relay a lease request");
                    let out = lease_nack(req.message(), Status::LinkDown);
                    if let Err(e) = self.host.relay_answer_lease(req, &out) {
                        tracing::debug!(device = %self.local, error = %e, "reply not delivered");
                    }
                }
            }
        }
        let now = Instant::now();
        let mut done = Vec::new();
        let mut i = 0;
        while i < self.leases.len() {
            let (req, replies, deadline) = &self.leases[i];
            let answer = match replies.try_recv() {
                Ok(Some(reply)) => Some(match reply.result() {
                    Ok(sample) => LeaseReply::read_from_bytes(&sample.payload().to_bytes())
                        .unwrap_or_else(|_| lease_nack(req.message(), Status::LinkDown)),
                    Err(err) => lease_nack(req.message(), status_of(err.payload())),
                }),
                Ok(None) if now < *deadline => None,
                Ok(None) | Err(_) => Some(lease_nack(
                    req.message(),
                    if now >= *deadline {
                        Status::Timeout
                    } else {
                        Status::LinkDown
                    },
                )),
            };
            match answer {
                Some(a) => done.push((self.leases.swap_remove(i).0, a)),
                None => i += 1,
            }
        }
        for (req, reply) in done {
            if let Err(e) = self.host.relay_answer_lease(req, &reply) {
                tracing::debug!(device = %self.local, error = %e, "lease reply not delivered");
            }
        }
    }
}

fn host_device<I: Interface>(
    ctx: &Context,
    remote: &DeviceName,
    local: &DeviceName,
) -> Result<Box<dyn MirroredDevice>, String> {
    let host = DeviceHost::<I>::new(ctx, local, MIRROR_DRIVER).map_err(|e| e.to_string())?;
    Ok(Box::new(Mirrored::<I> {
        local: local.clone(),
        host,
        cmd_key: keys::device_key(remote, "cmd"),
        req_key: keys::device_key(remote, "req"),
        lease_key: keys::device_key(remote, "lease"),
        names: keys::type_names::<I>(),
        pending: Vec::new(),
        leases: Vec::new(),
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
    let session = session::open(&config.net)?;
    let origin = session.zid().to_string();
    let (tx, rx) = mpsc::channel::<Event>();

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
    report(MirrorEvent::Ready {
        zid: origin.clone(),
    });

    let mut devices: HashMap<DeviceName, (DeviceName, Box<dyn MirroredDevice>)> = HashMap::new();
    while !stop() {
        match rx.recv_timeout(Duration::from_millis(1)) {
            Ok(first) => {
                for ev in std::iter::once(first).chain(rx.try_iter()) {
                    match ev {
                        Event::Alive {
                            device,
                            present: true,
                        } => {
                            if devices.contains_key(&device) {
                                continue;
                            }
                            let Some(local) = local_name(&device, &config.prefix) else {
                                report(MirrorEvent::Refused {
                                    remote: device,
                                    reason: "the prefixed robot name is invalid".into(),
                                });
                                continue;
                            };
                            let made = match device.interface() {
                                InterfaceKind::ActArray => {
                                    host_device::<ActArray>(&ctx, &device, &local)
                                }
                                InterfaceKind::Limb => host_device::<Limb>(&ctx, &device, &local),
                                InterfaceKind::Gripper => {
                                    host_device::<Gripper>(&ctx, &device, &local)
                                }
                            };
                            match made {
                                Ok(d) => {
                                    tracing::info!(remote = %device, local = %local, "mirrored");
                                    devices.insert(device.clone(), (local.clone(), d));
                                    report(MirrorEvent::Mirrored {
                                        remote: device,
                                        local,
                                    });
                                }
                                Err(reason) => {
                                    tracing::warn!(remote = %device, error = %reason,
                                        "cannot host a remote device");
                                    report(MirrorEvent::Refused {
                                        remote: device,
                                        reason,
                                    });
                                }
                            }
                        }
                        Event::Alive {
                            device,
                            present: false,
                        } => {
                            if let Some((local, host)) = devices.remove(&device) {
                                // No longer offered before anybody is told so.
                                drop(host);
                                tracing::info!(local = %local, "remote device gone");
                                report(MirrorEvent::Gone { local });
                            }
                        }
                        Event::State { device, payload } => {
                            if let Some((_, d)) = devices.get_mut(&device) {
                                d.state(&payload);
                            }
                        }
                        Event::Outcome { device, payload } => {
                            if let Some((_, d)) = devices.get_mut(&device) {
                                d.outcome(&payload);
                            }
                        }
                    }
                }
            }
            Err(mpsc::RecvTimeoutError::Timeout) => {}
            // Not while `tx` lives.
            Err(mpsc::RecvTimeoutError::Disconnected) => break,
        }
        for (_, d) in devices.values_mut() {
            d.poll(&session, &origin, config.request_timeout);
        }
    }
    drop(devices);
    if let Err(e) = session.close().wait() {
        tracing::warn!(error = %e, "cannot close the Zenoh session");
    }
    Ok(())
}
