//! One Player client's session: a limber client of its own (its own iceoryx2 node and a
//! `Client<I>` per subscribed device, so its commands carry its own identity and a lease
//! it takes is its own), reading Player messages from its socket and writing replies and
//! data back. Everything it holds goes with it when it ends.

use std::collections::{HashSet, VecDeque};
use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::Duration;

use limber_interfaces::prelude::*;
use limber_services::{
    ConnectError, Context, ContextError, Role, Ticket, WaitError, connect_device, list_devices,
};
use thiserror::Error;

use crate::header::{DevAddr, HEADER_SIZE, HeaderError, MsgHeader, message, msg_type, now};
use crate::map::{Mapped, assign};
use crate::player::{self, BoolProp, DataMode, DevReq, PLAYER_CODE, access, universal};
use crate::queue::OutQueue;
use crate::server::Shared;
use crate::translate::{PlayerDevice, translator};
use crate::xdr::XdrWriter;

/// How long the session waits for its client before looking at its devices again: the
/// pace of its DATA (Player's own server runs at 100 Hz).
pub const TICK: Duration = Duration::from_millis(10);

/// Why a session ended with an error.
#[derive(Debug, Error)]
pub enum SessionError {
    /// The session could not join the domain.
    #[error("cannot join the domain: {0}")]
    Context(#[from] ContextError),
    /// The client sent a header that is not Player's (or too large a body).
    #[error("not a Player message: {0}")]
    Header(#[from] HeaderError),
    /// The socket failed (or a write timed out).
    #[error("the connection failed: {0}")]
    Io(#[from] std::io::Error),
}

/// How a session ended without error.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SessionEnd {
    /// The client closed its connection.
    Closed,
    /// The gateway is stopping.
    Stopped,
}

/// A subscription could not be made.
#[derive(Debug, Error)]
pub enum SubscribeError {
    /// No device of the domain has this address.
    #[error("no device at {interf}:{index}")]
    NoDevice {
        /// Player's interface code.
        interf: u16,
        /// Player's index.
        index: u16,
    },
    /// The device could not be connected.
    #[error("cannot connect {device}: {source}")]
    Connect {
        /// The device.
        device: String,
        /// Why.
        #[source]
        source: ConnectError,
    },
}

struct Sub {
    addr: DevAddr,
    driver: String,
    dev: Box<dyn PlayerDevice>,
    last_seq: u64,
    /// `(type, subtype)` the driver refused as unsupported to this session.
    unsupported: HashSet<(u8, u8)>,
    /// Commands sent whose outcome has not been seen yet, oldest first.
    pending: VecDeque<(Ticket, u8)>,
}

/// The most commands whose outcomes a session follows per device (as many as a limber
/// client remembers).
const PENDING_MAX: usize = 16;

/// A session.
pub(crate) struct Session<'a> {
    shared: &'a Shared,
    stream: TcpStream,
    id: u64,
    subs: Vec<Sub>,
    mode: DataMode,
    data_requested: bool,
    queue: OutQueue,
    inbuf: Vec<u8>,
    /// Last: dropped after the clients.
    ctx: Context,
}

impl<'a> Session<'a> {
    /// Joins the domain as client `player-gateway-<id>` for `stream`.
    pub(crate) fn new(
        shared: &'a Shared,
        stream: TcpStream,
        id: u64,
    ) -> Result<Self, SessionError> {
        let ctx = Context::new(
            &shared.domain,
            Role::Client,
            &format!("player-gateway-{id}"),
        )?;
        stream.set_nodelay(true)?;
        stream.set_write_timeout(Some(shared.config.write_timeout))?;
        Ok(Session {
            shared,
            stream,
            id,
            subs: Vec::new(),
            mode: DataMode::Push,
            data_requested: false,
            queue: OutQueue::default(),
            inbuf: Vec::new(),
            ctx,
        })
    }

    /// Sends the banner, then serves the client until it leaves or the gateway stops.
    pub(crate) fn run(mut self) -> Result<SessionEnd, SessionError> {
        self.stream.write_all(&player::banner())?;
        let mut chunk = vec![0u8; 64 * 1024];
        loop {
            if self.shared.stopping() {
                return Ok(SessionEnd::Stopped);
            }
            if readable(&self.stream, TICK) {
                let n = match self.stream.read(&mut chunk) {
                    Ok(0) => return Ok(SessionEnd::Closed),
                    Ok(n) => n,
                    Err(e) if e.kind() == std::io::ErrorKind::Interrupted => 0,
                    Err(e) if e.kind() == std::io::ErrorKind::ConnectionReset => {
                        return Ok(SessionEnd::Closed);
                    }
                    Err(e) => return Err(e.into()),
                };
                self.inbuf.extend_from_slice(&chunk[..n]);
                self.handle_input()?;
            }
            self.poll_devices();
            self.flush()?;
        }
    }

    fn handle_input(&mut self) -> Result<(), SessionError> {
        while self.inbuf.len() >= HEADER_SIZE {
            let h = MsgHeader::decode(&self.inbuf[..HEADER_SIZE])?;
            let total = HEADER_SIZE + h.size as usize;
            if self.inbuf.len() < total {
                break;
            }
            let body: Vec<u8> = self.inbuf[HEADER_SIZE..total].to_vec();
            self.inbuf.drain(..total);
            self.handle(h, &body)?;
        }
        Ok(())
    }

    fn handle(&mut self, h: MsgHeader, body: &[u8]) -> Result<(), SessionError> {
        match h.mtype {
            msg_type::REQ if h.addr.interf == PLAYER_CODE => self.player_request(h, body),
            msg_type::REQ => self.device_request(h, body),
            msg_type::CMD => {
                self.device_command(h, body);
                Ok(())
            }
            t => {
                tracing::debug!(
                    session = self.id,
                    mtype = t,
                    "ignored a message of this type"
                );
                Ok(())
            }
        }
    }

    /// ACK (with `body`) or NACK, on the request's address and subtype, written at once.
    fn reply(&mut self, h: MsgHeader, ack: Option<Vec<u8>>) -> Result<(), SessionError> {
        let (mtype, body) = match ack {
            Some(b) => (msg_type::RESP_ACK, b),
            None => (msg_type::RESP_NACK, Vec::new()),
        };
        let r = MsgHeader {
            addr: h.addr,
            mtype,
            subtype: h.subtype,
            timestamp: now(),
            ..MsgHeader::default()
        };
        self.stream.write_all(&message(r, &body))?;
        Ok(())
    }

    fn devices(&self) -> Vec<Mapped> {
        match list_devices(&self.shared.domain) {
            Ok(d) => assign(&d, &self.shared.config.map, |k| translator(k).is_some()),
            Err(e) => {
                tracing::warn!(session = self.id, error = %e, "cannot list the devices");
                Vec::new()
            }
        }
    }

    fn addr_of(&self, interf: u16, index: u16) -> DevAddr {
        DevAddr {
            host: 0,
            robot: self.shared.port.into(),
            interf,
            index,
        }
    }

    fn player_request(&mut self, h: MsgHeader, body: &[u8]) -> Result<(), SessionError> {
        let answer = match h.subtype {
            player::req::DEVLIST => {
                let addrs: Vec<DevAddr> = self
                    .devices()
                    .iter()
                    .map(|m| self.addr_of(m.interf(), m.index))
                    .collect();
                Some(player::devlist(&addrs))
            }
            player::req::DRIVERINFO => player::read_driverinfo(body).ok().and_then(|a| {
                self.devices()
                    .into_iter()
                    .find(|m| m.interf() == a.interf && m.index == a.index)
                    .map(|m| player::driverinfo(a, &m.info.driver))
            }),
            player::req::DEV => self.dev_request(body),
            player::req::DATA => {
                self.reply(h, Some(Vec::new()))?;
                self.data_requested = true;
                return Ok(());
            }
            player::req::DATAMODE => player::read_datamode(body)
                .ok()
                .and_then(DataMode::from_code)
                .map(|m| {
                    self.mode = m;
                    Vec::new()
                }),
            player::req::ADD_REPLACE_RULE => player::ReplaceRule::read(body).ok().map(|r| {
                self.queue.add_rule(r);
                Vec::new()
            }),
            universal::CAPABILITY => player::read_capability(body).ok().and_then(|(t, s)| {
                (t == u32::from(msg_type::REQ) && matches!(s, 1..=5 | 10 | 255)).then(Vec::new)
            }),
            _ => None,
        };
        if answer.is_none() {
            tracing::debug!(
                session = self.id,
                subtype = h.subtype,
                "player request NACKed"
            );
        }
        self.reply(h, answer)
    }

    fn dev_request(&mut self, body: &[u8]) -> Option<Vec<u8>> {
        let req = match DevReq::read(body) {
            Ok(r) => r,
            Err(e) => {
                tracing::debug!(session = self.id, error = %e, "malformed DEV request");
                return None;
            }
        };
        let (interf, index) = (req.addr.interf, req.addr.index);
        match req.access {
            access::OPEN => match self.subscribe(interf, index) {
                Ok(driver) => Some(
                    DevReq {
                        addr: req.addr,
                        access: access::OPEN,
                        driver_name: driver,
                    }
                    .write(),
                ),
                Err(e) => {
                    tracing::info!(session = self.id, error = %e, "subscription refused");
                    None
                }
            },
            access::CLOSE => {
                let driver = self.unsubscribe(interf, index).unwrap_or_default();
                Some(
                    DevReq {
                        addr: req.addr,
                        access: access::CLOSE,
                        driver_name: driver,
                    }
                    .write(),
                )
            }
            _ => None,
        }
    }

    fn sub_index(&self, interf: u16, index: u16) -> Option<usize> {
        self.subs
            .iter()
            .position(|s| s.addr.interf == interf && s.addr.index == index)
    }

    fn subscribe(&mut self, interf: u16, index: u16) -> Result<String, SubscribeError> {
        if let Some(i) = self.sub_index(interf, index) {
            return Ok(self.subs[i].driver.clone());
        }
        let no_device = SubscribeError::NoDevice { interf, index };
        let m = self
            .devices()
            .into_iter()
            .find(|m| m.interf() == interf && m.index == index)
            .ok_or(no_device)?;
        let t = translator(m.info.interface()).ok_or(SubscribeError::NoDevice { interf, index })?;
        let name = m.info.name.to_string();
        let dev = connect_device(&self.ctx, &name, Duration::ZERO).map_err(|e| {
            SubscribeError::Connect {
                device: name.clone(),
                source: e,
            }
        })?;
        let dev = t.open(dev, self.shared.config.conventions);
        tracing::info!(session = self.id, device = %name, interf, index, "subscribed");
        self.subs.push(Sub {
            addr: self.addr_of(interf, index),
            driver: m.info.driver.clone(),
            dev,
            last_seq: 0,
            unsupported: HashSet::new(),
            pending: VecDeque::new(),
        });
        Ok(m.info.driver)
    }

    fn unsubscribe(&mut self, interf: u16, index: u16) -> Option<String> {
        let i = self.sub_index(interf, index)?;
        let sub = self.subs.remove(i);
        self.queue.forget(sub.addr);
        tracing::info!(session = self.id, interf, index, "closed");
        Some(sub.driver)
    }

    fn device_request(&mut self, h: MsgHeader, body: &[u8]) -> Result<(), SessionError> {
        let Some(i) = self.sub_index(h.addr.interf, h.addr.index) else {
            tracing::debug!(
                session = self.id,
                interf = h.addr.interf,
                index = h.addr.index,
                "a request to a device this session has not subscribed"
            );
            return self.reply(h, None);
        };
        let read_only = self.shared.config.read_only;
        let answer = match h.subtype {
            universal::CAPABILITY => player::read_capability(body)
                .ok()
                .and_then(|(t, s)| self.capable(i, t, s).then(Vec::new)),
            universal::GET_BOOLPROP | universal::SET_BOOLPROP => self.lease_property(i, h, body),
            universal::SET_INTPROP..=universal::GET_INTPROP => None,
            s if read_only && self.subs[i].dev.changes(s) => {
                tracing::info!(session = self.id, subtype = s, "read-only: request refused");
                None
            }
            s => match self.subs[i].dev.request(s, body) {
                Ok(b) => Some(b),
                Err(e) => {
                    if e.refusal() == Some(Status::Unsupported) {
                        self.subs[i].unsupported.insert((msg_type::REQ, s));
                    }
                    tracing::debug!(session = self.id, subtype = s, error = %e, "request NACKed");
                    None
                }
            },
        };
        self.reply(h, answer)
    }

    /// The capability query: what the gateway translates, the driver has not refused as
    /// unsupported, and a read-only gateway lets through.
    fn capable(&self, i: usize, t: u32, s: u32) -> bool {
        let (Ok(t), Ok(s)) = (u8::try_from(t), u8::try_from(s)) else {
            return false;
        };
        let sub = &self.subs[i];
        let read_only = self.shared.config.read_only;
        if t == msg_type::REQ {
            match s {
                universal::CAPABILITY | universal::GET_BOOLPROP => return true,
                universal::SET_BOOLPROP => return !read_only,
                _ => {}
            }
        }
        let refused = read_only && (t == msg_type::CMD || sub.dev.changes(s));
        sub.dev.translates(t, s) && !sub.unsupported.contains(&(t, s)) && !refused
    }

    /// GET/SET of the boolean property [`player::LEASE_KEY`].
    fn lease_property(&mut self, i: usize, h: MsgHeader, body: &[u8]) -> Option<Vec<u8>> {
        let prop = BoolProp::read(body).ok()?;
        if prop.key != player::LEASE_KEY {
            return None;
        }
        let dev = self.subs[i].dev.client();
        if h.subtype == universal::GET_BOOLPROP {
            return Some(
                BoolProp {
                    key: prop.key,
                    value: dev.holds_lease(),
                }
                .write(),
            );
        }
        if self.shared.config.read_only {
            tracing::info!(session = self.id, "read-only: lease refused");
            return None;
        }
        let result = if prop.value {
            let name = format!("player-session-{}", self.id);
            dev.acquire(&name, self.shared.config.lease_heartbeat)
        } else {
            dev.release()
        };
        match result {
            Ok(()) => Some(Vec::new()),
            Err(e) => {
                tracing::info!(session = self.id, error = %e, "lease property refused");
                None
            }
        }
    }

    fn device_command(&mut self, h: MsgHeader, body: &[u8]) {
        let Some(i) = self.sub_index(h.addr.interf, h.addr.index) else {
            tracing::debug!(session = self.id, "a command to a device not subscribed");
            return;
        };
        if self.shared.config.read_only {
            tracing::info!(
                session = self.id,
                subtype = h.subtype,
                "read-only: command refused"
            );
            return;
        }
        let sub = &mut self.subs[i];
        match sub.dev.command(h.subtype, body) {
            Ok(t) => {
                if sub.pending.len() >= PENDING_MAX {
                    sub.pending.pop_front();
                }
                sub.pending.push_back((t, h.subtype));
            }
            Err(e) => {
                tracing::warn!(session = self.id, subtype = h.subtype, error = %e, "command not sent")
            }
        }
    }

    /// Takes the devices' new states into the queue, and the outcomes of the commands
    /// sent (a refusal as unsupported is remembered for the capability query); renews
    /// leases.
    fn poll_devices(&mut self) {
        for s in &mut self.subs {
            let c = s.dev.client();
            if let Err(e) = c.refresh() {
                tracing::debug!(device = %c.device(), error = %e, "no state");
            }
            if c.holds_lease()
                && let Err(e) = c.keep_lease()
            {
                tracing::warn!(device = %c.device(), error = %e, "the lease was lost");
            }
            while let Some(&(t, subtype)) = s.pending.front() {
                match c.wait_outcome_detail(t, Duration::ZERO) {
                    Err(WaitError::Timeout(_)) => break,
                    Ok(o) if o.status.is_carried_out() => {}
                    Ok(o) => {
                        tracing::info!(device = %c.device(), subtype, status = %o.status,
                            "command refused");
                        if o.status == Status::Unsupported {
                            s.unsupported.insert((msg_type::CMD, subtype));
                        }
                    }
                    Err(e) => tracing::debug!(device = %c.device(), error = %e, "no outcome"),
                }
                s.pending.pop_front();
            }
            let Some(hd) = c.header().copied() else {
                continue;
            };
            if hd.seq == s.last_seq {
                continue;
            }
            s.last_seq = hd.seq;
            let Some(body) = s.dev.data() else { continue };
            let age = limber_services::monotonic_ns().saturating_sub(hd.stamp_ns);
            let h = MsgHeader {
                addr: s.addr,
                mtype: msg_type::DATA,
                subtype: 1,
                timestamp: now() - age as f64 / 1e9,
                ..MsgHeader::default()
            };
            self.queue
                .push(s.addr, msg_type::DATA, 1, message(h, &body));
        }
    }

    /// PUSH: everything waiting; PULL: everything waiting and a SYNCH once data was asked
    /// for and there is some.
    fn flush(&mut self) -> Result<(), SessionError> {
        if self.queue.is_empty() || (self.mode == DataMode::Pull && !self.data_requested) {
            return Ok(());
        }
        let (msgs, dropped) = self.queue.take();
        let mut out: Vec<u8> = msgs.concat();
        if self.mode == DataMode::Pull {
            self.data_requested = false;
            let (subtype, body) = if dropped > 0 {
                (
                    player::synch::OVERFLOW,
                    XdrWriter::new().u32(dropped).finish(),
                )
            } else {
                (player::synch::OK, Vec::new())
            };
            let h = MsgHeader {
                addr: self.addr_of(PLAYER_CODE, 0),
                mtype: msg_type::SYNCH,
                subtype,
                timestamp: now(),
                ..MsgHeader::default()
            };
            out.extend(message(h, &body));
        } else if dropped > 0 {
            tracing::warn!(
                session = self.id,
                dropped,
                "DATA dropped: the client reads too slowly"
            );
        }
        self.stream.write_all(&out)?;
        Ok(())
    }
}

/// Whether `stream` has something to read (or was closed) within `timeout`.
fn readable(stream: &TcpStream, timeout: Duration) -> bool {
    use rustix::event::{PollFd, PollFlags, Timespec, poll};
    let mut fds = [PollFd::new(stream, PollFlags::IN)];
    let t = Timespec {
        tv_sec: timeout.as_secs() as i64,
        tv_nsec: i64::from(timeout.subsec_nanos()),
    };
    match poll(&mut fds, Some(&t)) {
        Ok(n) => n > 0,
        Err(e) => {
            tracing::debug!(error = %e, "poll");
            false
        }
    }
}
