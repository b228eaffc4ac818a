//! A Player client written from the protocol's facts alone (the project's reference,
//! sections 1.1-1.4 and 2), independent of the gateway's own codec: it builds and reads
//! the bytes itself. Every read has a timeout.
#![allow(dead_code)] // each test file uses a part of it

use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

/// Message types.
pub const DATA: u32 = 1;
pub const CMD: u32 = 2;
pub const REQ: u32 = 3;
pub const ACK: u32 = 4;
pub const SYNCH: u32 = 5;
pub const NACK: u32 = 6;

/// Interface codes.
pub const PLAYER: u32 = 1;
pub const GRIPPER: u32 = 3;
pub const LASER: u32 = 6;
pub const ACTARRAY: u32 = 53;
pub const LIMB: u32 = 54;

/// How long one read may wait.
pub const READ_TIMEOUT: Duration = Duration::from_secs(10);

/// One message.
#[derive(Debug, Clone)]
pub struct Msg {
    pub interf: u32,
    pub index: u32,
    pub mtype: u32,
    pub subtype: u32,
    pub timestamp: f64,
    pub body: Vec<u8>,
}

/// A body under construction: big-endian words.
#[derive(Default)]
pub struct Body(pub Vec<u8>);

impl Body {
    pub fn u32(mut self, v: u32) -> Self {
        self.0.extend(v.to_be_bytes());
        self
    }
    pub fn i32(mut self, v: i32) -> Self {
        self.0.extend(v.to_be_bytes());
        self
    }
    pub fn f32(mut self, v: f32) -> Self {
        self.0.extend(v.to_be_bytes());
        self
    }
    pub fn f64(mut self, v: f64) -> Self {
        self.0.extend(v.to_be_bytes());
        self
    }
    /// A variable array's count, twice.
    pub fn count(self, n: u32) -> Self {
        self.u32(n).u32(n)
    }
    pub fn point(self, p: [f64; 3]) -> Self {
        self.f64(p[0]).f64(p[1]).f64(p[2])
    }
}

/// Reads big-endian words from a body.
pub struct Words<'a>(pub &'a [u8], pub usize);

impl Words<'_> {
    pub fn u32(&mut self) -> u32 {
        let v = u32::from_be_bytes(self.0[self.1..self.1 + 4].try_into().expect("4 bytes"));
        self.1 += 4;
        v
    }
    pub fn f32(&mut self) -> f32 {
        f32::from_bits(self.u32())
    }
    pub fn f64(&mut self) -> f64 {
        let v = f64::from_be_bytes(self.0[self.1..self.1 + 8].try_into().expect("8 bytes"));
        self.1 += 8;
        v
    }
}

/// A connection to a Player server.
pub struct PlayerClient {
    pub stream: TcpStream,
    pub port: u16,
    /// DATA and SYNCH that arrived while waiting for a reply.
    pub stash: Vec<Msg>,
}

impl PlayerClient {
    /// Connects and reads the 32-byte banner.
    pub fn connect(port: u16) -> (PlayerClient, [u8; 32]) {
        let mut stream = TcpStream::connect(("127.0.0.1", port)).expect("connect to the gateway");
        stream
            .set_read_timeout(Some(READ_TIMEOUT))
            .expect("a read timeout");
        let mut banner = [0u8; 32];
        stream.read_exact(&mut banner).expect("the 32-byte banner");
        (
            PlayerClient {
                stream,
                port,
                stash: Vec::new(),
            },
            banner,
        )
    }

    /// Sends one message, stamped with the wall clock as libplayerc does.
    pub fn send(&mut self, interf: u32, index: u32, mtype: u32, subtype: u32, body: &[u8]) {
        let stamp = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .expect("after 1970")
            .as_secs_f64();
        let mut m = Body::default()
            .u32(0)
            .u32(self.port.into())
            .u32(interf)
            .u32(index)
            .u32(mtype)
            .u32(subtype)
            .f64(stamp)
            .u32(0)
            .u32(body.len() as u32)
            .0;
        m.extend_from_slice(body);
        self.stream.write_all(&m).expect("send a message");
    }

    /// Reads one message (fails the test after [`READ_TIMEOUT`]).
    pub fn read(&mut self) -> Msg {
        let mut h = [0u8; 40];
        self.stream.read_exact(&mut h).expect("a 40-byte header");
        let mut w = Words(&h, 0);
        let (_host, _robot) = (w.u32(), w.u32());
        let (interf, index, mtype, subtype) = (w.u32(), w.u32(), w.u32(), w.u32());
        let timestamp = w.f64();
        let (_seq, size) = (w.u32(), w.u32());
        let mut body = vec![0u8; size as usize];
        self.stream.read_exact(&mut body).expect("the body");
        Msg {
            interf,
            index,
            mtype,
            subtype,
            timestamp,
            body,
        }
    }

    /// Sends a request and reads until its reply, which must echo its address and
    /// subtype (as libplayerc checks); DATA and SYNCH meanwhile are stashed.
    pub fn request(&mut self, interf: u32, index: u32, subtype: u32, body: &[u8]) -> Msg {
        self.send(interf, index, REQ, subtype, body);
        loop {
            let m = self.read();
            if m.mtype == ACK || m.mtype == NACK {
                assert_eq!(
                    (m.interf, m.index, m.subtype),
                    (interf, index, subtype),
                    "a reply to another request"
                );
                return m;
            }
            self.stash.push(m);
        }
    }

    /// A request that must be ACKed; its body.
    pub fn ack(&mut self, interf: u32, index: u32, subtype: u32, body: &[u8]) -> Vec<u8> {
        let m = self.request(interf, index, subtype, body);
        assert_eq!(
            m.mtype, ACK,
            "request {interf}:{index} subtype {subtype} NACKed"
        );
        m.body
    }

    /// A request that must be NACKed.
    pub fn nack(&mut self, interf: u32, index: u32, subtype: u32, body: &[u8]) {
        let m = self.request(interf, index, subtype, body);
        assert_eq!(
            m.mtype, NACK,
            "request {interf}:{index} subtype {subtype} ACKed"
        );
        assert!(m.body.is_empty(), "a NACK has no body");
    }

    /// DATAMODE: 1 PUSH, 2 PULL.
    pub fn datamode(&mut self, mode: u32) {
        self.ack(PLAYER, 0, 5, &Body::default().u32(mode).0);
    }

    /// DEV OPEN; the driver name of the ACK, or None for a NACK.
    pub fn subscribe(&mut self, interf: u32, index: u32) -> Option<String> {
        let body = Body::default()
            .u32(0)
            .u32(self.port.into())
            .u32(interf)
            .u32(index)
            .u32(1) // OPEN
            .count(0)
            .0;
        let m = self.request(PLAYER, 0, 3, &body);
        if m.mtype == NACK {
            return None;
        }
        let mut w = Words(&m.body, 16);
        assert_eq!(w.u32(), 1, "the access granted");
        let n = w.u32() as usize;
        assert_eq!(w.u32() as usize, n, "the name's count twice");
        Some(String::from_utf8_lossy(&m.body[28..28 + n]).into_owned())
    }

    /// DEV CLOSE.
    pub fn close(&mut self, interf: u32, index: u32) {
        let body = Body::default()
            .u32(0)
            .u32(self.port.into())
            .u32(interf)
            .u32(index)
            .u32(2) // CLOSE
            .count(0)
            .0;
        self.ack(PLAYER, 0, 3, &body);
    }

    /// PULL: REQ DATA, its ACK (first), then the data up to the SYNCH.
    pub fn pull(&mut self) -> Vec<Msg> {
        let mut out = std::mem::take(&mut self.stash);
        self.ack(PLAYER, 0, 4, &[]);
        loop {
            let m = self.read();
            if m.mtype == SYNCH {
                assert_eq!((m.interf, m.index), (PLAYER, 0));
                return out;
            }
            out.push(m);
        }
    }

    /// Pulls (bounded) until a DATA of `interf:index` satisfies `pred`; that body.
    pub fn pull_until(
        &mut self,
        interf: u32,
        index: u32,
        what: &str,
        pred: impl Fn(&[u8]) -> bool,
    ) -> Vec<u8> {
        let deadline = Instant::now() + Duration::from_secs(30);
        let mut last = Vec::new();
        while Instant::now() < deadline {
            for m in self.pull() {
                if m.mtype == DATA && m.interf == interf && m.index == index {
                    if pred(&m.body) {
                        return m.body;
                    }
                    last = m.body;
                }
            }
        }
        panic!("{what}: not within 30 s; last data {last:?}");
    }
}

/// Joint `j`'s position in an actarray DATA body.
pub fn joint(body: &[u8], j: usize) -> f32 {
    Words(body, 8 + 20 * j).f32()
}

/// The end-effector position in a limb DATA body.
pub fn limb_position(body: &[u8]) -> [f64; 3] {
    let mut w = Words(body, 0);
    [w.f64(), w.f64(), w.f64()]
}

/// The state in a gripper DATA body.
pub fn gripper_state(body: &[u8]) -> u32 {
    Words(body, 0).u32()
}

/// A laser DATA SCAN body (Player's `player_laser_data_t`), read word by word.
#[derive(Debug, Clone, PartialEq)]
pub struct Scan {
    pub min_angle: f32,
    pub max_angle: f32,
    pub resolution: f32,
    pub max_range: f32,
    pub ranges: Vec<f32>,
    pub intensity: Vec<u8>,
    pub id: u32,
}

impl Scan {
    /// Reads a scan: four floats, the ranges (count twice, a float each), the
    /// intensities (count twice, bytes padded to a word), the id; None unless the body
    /// is exactly that.
    pub fn read(body: &[u8]) -> Option<Scan> {
        if body.len() < 16 + 8 {
            return None;
        }
        let mut w = Words(body, 0);
        let (min_angle, max_angle, resolution, max_range) = (w.f32(), w.f32(), w.f32(), w.f32());
        let n = w.u32() as usize;
        if w.u32() as usize != n || body.len() < w.1 + 4 * n + 8 {
            return None;
        }
        let ranges = (0..n).map(|_| w.f32()).collect();
        let k = w.u32() as usize;
        let padded = k.div_ceil(4) * 4;
        if w.u32() as usize != k || body.len() != w.1 + padded + 4 {
            return None;
        }
        let intensity = body[w.1..w.1 + k].to_vec();
        w.1 += padded;
        Some(Scan {
            min_angle,
            max_angle,
            resolution,
            max_range,
            ranges,
            intensity,
            id: w.u32(),
        })
    }
}
