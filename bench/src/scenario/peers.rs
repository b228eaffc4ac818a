//! `peers`: the command round trip with the same bytes (a 296 B `ActArrayCmdMsg` out, a
//! 1376 B `ActArrayData` back) over a Unix domain stream socket and over TCP loopback
//! (Player's transport, `TCP_NODELAY`), between two processes, each both blocking
//! (blocking `read`) and spinning (non-blocking `read` in a loop).
//!
//! Round trip by the parent; one-way parent→echo by the echo child from the stamp in
//! `meta.stamp_ns`.

use std::io::{ErrorKind, Read, Write};
use std::net::{TcpListener, TcpStream};
use std::os::unix::net::{UnixListener, UnixStream};
use std::time::{Duration, Instant};

use limber_interfaces::prelude::*;
use limber_services::monotonic_ns;
use zerocopy::IntoBytes;

use super::floor::BYTES;
use super::{READY_TIMEOUT, RunCtx, SAMPLE_TIMEOUT, Scenario};
use crate::child::{ChildProc, ChildSpec, read_histogram};
use crate::progress::Progress;
use crate::roles;
use crate::stats::{Measurement, Metric, Strategy, new_histogram};
use crate::{BenchArgs, BenchError};

/// The socket family.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Transport {
    /// Unix domain stream socket.
    Uds,
    /// TCP over the loopback interface.
    Tcp,
}

impl Transport {
    fn key(self) -> &'static str {
        match self {
            Transport::Uds => "uds",
            Transport::Tcp => "tcp",
        }
    }
    fn label(self) -> &'static str {
        match self {
            Transport::Uds => "Unix socket",
            Transport::Tcp => "TCP loopback",
        }
    }
}

/// The `peers` scenario.
#[derive(Debug, Clone, Copy)]
pub struct Peers;

impl Scenario for Peers {
    fn name(&self) -> &'static str {
        "peers"
    }
    fn description(&self) -> &'static str {
        "the command round trip with the same bytes over a Unix socket and TCP loopback, blocking and spinning"
    }
    fn run(&self, ctx: &mut RunCtx) -> Result<(), BenchError> {
        let spin = ctx.spin_enabled();
        for t in [Transport::Uds, Transport::Tcp] {
            if spin {
                run_peer(ctx, t, true)?;
            }
            if ctx.blocking_enabled() {
                run_peer(ctx, t, false)?;
            }
        }
        Ok(())
    }
}

/// A connected stream socket of either family.
trait Sock: Read + Write {
    fn nonblocking(&self, on: bool) -> std::io::Result<()>;
    fn read_timeout(&self, t: Option<Duration>) -> std::io::Result<()>;
}

impl Sock for TcpStream {
    fn nonblocking(&self, on: bool) -> std::io::Result<()> {
        self.set_nonblocking(on)
    }
    fn read_timeout(&self, t: Option<Duration>) -> std::io::Result<()> {
        self.set_read_timeout(t)
    }
}

impl Sock for UnixStream {
    fn nonblocking(&self, on: bool) -> std::io::Result<()> {
        self.set_nonblocking(on)
    }
    fn read_timeout(&self, t: Option<Duration>) -> std::io::Result<()> {
        self.set_read_timeout(t)
    }
}

/// What a full read ended with.
enum ReadEnd {
    Full,
    Eof,
}

/// Reads exactly `buf.len()` bytes: spinning on `WouldBlock` (non-blocking socket) or
/// blocking with the socket's read timeout. Gives up after `timeout`.
fn read_full<S: Sock>(
    s: &mut S,
    buf: &mut [u8],
    spin: bool,
    timeout: Duration,
) -> Result<ReadEnd, BenchError> {
    let mut off = 0;
    let mut spins = 0u32;
    let mut deadline: Option<Instant> = None;
    while off < buf.len() {
        match s.read(&mut buf[off..]) {
            Ok(0) if off == 0 => return Ok(ReadEnd::Eof),
            Ok(0) => {
                return Err(BenchError::io(
                    "socket read",
                    std::io::Error::from(ErrorKind::UnexpectedEof),
                ));
            }
            Ok(k) => off += k,
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) if e.kind() == ErrorKind::WouldBlock || e.kind() == ErrorKind::TimedOut => {
                if spin {
                    spins = spins.wrapping_add(1);
                    if spins & 0x3fff != 0 {
                        core::hint::spin_loop();
                        continue;
                    }
                }
                let d = *deadline.get_or_insert_with(|| Instant::now() + timeout);
                if Instant::now() >= d {
                    return Err(BenchError::Timeout {
                        what: "socket read".into(),
                        timeout,
                    });
                }
            }
            Err(e) => return Err(BenchError::io("socket read", e)),
        }
    }
    Ok(ReadEnd::Full)
}

/// Writes all of `buf`, spinning on `WouldBlock`.
fn write_full<S: Sock>(s: &mut S, buf: &[u8], timeout: Duration) -> Result<(), BenchError> {
    let mut off = 0;
    let mut deadline: Option<Instant> = None;
    while off < buf.len() {
        match s.write(&buf[off..]) {
            Ok(0) => {
                return Err(BenchError::io(
                    "socket write",
                    std::io::Error::from(ErrorKind::WriteZero),
                ));
            }
            Ok(k) => off += k,
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) if e.kind() == ErrorKind::WouldBlock => {
                let d = *deadline.get_or_insert_with(|| Instant::now() + timeout);
                if Instant::now() >= d {
                    return Err(BenchError::Timeout {
                        what: "socket write".into(),
                        timeout,
                    });
                }
                core::hint::spin_loop();
            }
            Err(e) => return Err(BenchError::io("socket write", e)),
        }
    }
    Ok(())
}

fn setup<S: Sock>(s: &S, spin: bool) -> Result<(), BenchError> {
    s.nonblocking(spin)
        .map_err(|e| BenchError::io("socket mode", e))?;
    if !spin {
        s.read_timeout(Some(Duration::from_millis(200)))
            .map_err(|e| BenchError::io("socket timeout", e))?;
    }
    Ok(())
}

fn run_peer(ctx: &mut RunCtx, t: Transport, spin: bool) -> Result<(), BenchError> {
    let mode = if spin { "spin" } else { "blocking" };
    let (warm, n) = if spin {
        (ctx.count(2_000, 500), ctx.count(50_000, 5_000))
    } else {
        (ctx.count(500, 100), ctx.count(5_000, 1_000))
    };
    let out = ctx.tmp_file(&format!("peer-{}-{mode}.hdr", t.key()));
    let mut spec = ChildSpec {
        role: format!("{}-echo-{mode}", t.key()),
        out: Some(out.clone()),
        cpu: ctx.child_cpu(),
        warmup: warm,
        deadline: ctx.deadline_for(warm + n, Duration::from_micros(200)),
        ..Default::default()
    };
    let accept_deadline = Instant::now() + READY_TIMEOUT;
    let (rtt, child) = match t {
        Transport::Tcp => {
            let l = TcpListener::bind("127.0.0.1:0").map_err(|e| BenchError::io("tcp bind", e))?;
            spec.addr = Some(
                l.local_addr()
                    .map_err(|e| BenchError::io("tcp addr", e))?
                    .to_string(),
            );
            let child = ChildProc::spawn(&spec)?;
            l.set_nonblocking(true)
                .map_err(|e| BenchError::io("tcp listener", e))?;
            let mut s = loop {
                match l.accept() {
                    Ok((s, _)) => break s,
                    Err(e)
                        if e.kind() == ErrorKind::WouldBlock
                            && Instant::now() < accept_deadline =>
                    {
                        std::thread::sleep(Duration::from_millis(1));
                    }
                    Err(e) => return Err(BenchError::io("tcp accept", e)),
                }
            };
            s.set_nodelay(true)
                .map_err(|e| BenchError::io("tcp nodelay", e))?;
            setup(&s, spin)?;
            let mut child = child;
            child.expect("ready", READY_TIMEOUT)?;
            (ping(ctx, &mut s, t, spin, warm, n)?, child)
        }
        Transport::Uds => {
            let path = ctx.tmp_file(&format!("peer-{mode}.sock"));
            remove_stale(&path);
            let l = UnixListener::bind(&path).map_err(|e| BenchError::io("uds bind", e))?;
            spec.addr = Some(path.display().to_string());
            let child = ChildProc::spawn(&spec)?;
            l.set_nonblocking(true)
                .map_err(|e| BenchError::io("uds listener", e))?;
            let mut s = loop {
                match l.accept() {
                    Ok((s, _)) => break s,
                    Err(e)
                        if e.kind() == ErrorKind::WouldBlock
                            && Instant::now() < accept_deadline =>
                    {
                        std::thread::sleep(Duration::from_millis(1));
                    }
                    Err(e) => return Err(BenchError::io("uds accept", e)),
                }
            };
            setup(&s, spin)?;
            let mut child = child;
            child.expect("ready", READY_TIMEOUT)?;
            let r = ping(ctx, &mut s, t, spin, warm, n)?;
            drop(s);
            remove_stale(&path);
            (r, child)
        }
    };
    child.finish(Duration::from_secs(10))?;
    let oneway = read_histogram(&out)?;
    let strategy = if spin {
        Strategy::Spin
    } else {
        Strategy::Blocking
    };
    ctx.push(Measurement {
        scenario: "peers",
        id: format!("peers.{}.{mode}.rtt", t.key()),
        label: format!("{} round trip", t.label()),
        strategy,
        metric: Metric::RoundTrip,
        bytes: Some(BYTES),
        hist: rtt,
    });
    ctx.push(Measurement {
        scenario: "peers",
        id: format!("peers.{}.{mode}.oneway", t.key()),
        label: format!("{} client→echo", t.label()),
        strategy,
        metric: Metric::OneWay,
        bytes: Some(BYTES),
        hist: oneway,
    });
    Ok(())
}

/// The parent's side: `warm + n` exchanges; returns the round-trip histogram. Closing the
/// socket afterwards (by the caller) stops the echo.
fn ping<S: Sock>(
    ctx: &RunCtx,
    s: &mut S,
    t: Transport,
    spin: bool,
    warm: u64,
    n: u64,
) -> Result<hdrhistogram::Histogram<u64>, BenchError> {
    let mut rtt = new_histogram()?;
    let mut msg = ActArrayCmdMsg::default();
    let mut reply = ActArrayData::default();
    let label = format!("{} {}", t.label(), if spin { "spin" } else { "blocking" });
    let progress = Progress::new(ctx.progress, &label, warm + n);
    for seq in 1..=warm + n {
        let t0 = monotonic_ns();
        msg.meta.seq = seq;
        msg.meta.stamp_ns = t0;
        write_full(s, msg.as_bytes(), SAMPLE_TIMEOUT)?;
        match read_full(s, reply.as_mut_bytes(), spin, SAMPLE_TIMEOUT)? {
            ReadEnd::Full => {}
            ReadEnd::Eof => {
                return Err(BenchError::ChildFailed {
                    role: label,
                    reason: "the echo closed the socket".into(),
                });
            }
        }
        let t1 = monotonic_ns();
        if reply.header.seq != seq {
            return Err(BenchError::ChildFailed {
                role: label,
                reason: format!("answer {} to message {seq}", reply.header.seq),
            });
        }
        if seq > warm {
            rtt.saturating_record(t1.saturating_sub(t0));
        }
        progress.tick(seq);
    }
    progress.finish();
    Ok(rtt)
}

/// The echo child (`{uds,tcp}-echo-{spin,blocking}`): connects to `--addr`, answers every
/// 296 B message with 1376 B, records the one-way latency, stops at end of stream.
pub fn echo_role(args: &BenchArgs, t: Transport, spin: bool) -> Result<(), BenchError> {
    let addr = args
        .addr
        .clone()
        .ok_or_else(|| BenchError::Args("--addr is required for this role".into()))?;
    let deadline = roles::child_deadline(args);
    match t {
        Transport::Tcp => {
            let mut s = TcpStream::connect(&addr).map_err(|e| BenchError::io("tcp connect", e))?;
            s.set_nodelay(true)
                .map_err(|e| BenchError::io("tcp nodelay", e))?;
            echo(args, &mut s, spin, deadline)
        }
        Transport::Uds => {
            let mut s = UnixStream::connect(&addr).map_err(|e| BenchError::io("uds connect", e))?;
            echo(args, &mut s, spin, deadline)
        }
    }
}

fn echo<S: Sock>(
    args: &BenchArgs,
    s: &mut S,
    spin: bool,
    deadline: Instant,
) -> Result<(), BenchError> {
    setup(s, spin)?;
    let mut oneway = new_histogram()?;
    let mut msg = ActArrayCmdMsg::default();
    let mut reply = ActArrayData::default();
    roles::announce("ready");
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        match read_full(s, msg.as_mut_bytes(), spin, left)? {
            ReadEnd::Eof => return roles::write_histogram(args, &oneway),
            ReadEnd::Full => {}
        }
        let now = monotonic_ns();
        if msg.meta.seq > args.warmup {
            oneway.saturating_record(now.saturating_sub(msg.meta.stamp_ns));
        }
        reply.header.seq = msg.meta.seq;
        reply.header.stamp_ns = monotonic_ns();
        write_full(s, reply.as_bytes(), SAMPLE_TIMEOUT)?;
    }
}

/// Removes a socket file left by an earlier run; a missing file is the normal case.
fn remove_stale(path: &std::path::Path) {
    match std::fs::remove_file(path) {
        Ok(()) => {}
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {}
        Err(e) => tracing::warn!("cannot remove {}: {e}", path.display()),
    }
}
