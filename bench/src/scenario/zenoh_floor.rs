//! The bridge's floor (part of `bridge`): raw Zenoh between two processes, with the zenoh
//! version and features of `limber-bridge`, peer to peer over the link the bridge pair uses
//! (a Unix socket, as `bridge expose` listens on by default), no limber in between:
//!
//! * `put`: a 296 B put on a declared publisher → the echo's subscriber → a 1376 B put
//!   back → the pinger's subscriber (the path of a command and its outcome through a
//!   bridge pair);
//! * `get`: a `get` with a 296 B payload → the echo's queryable replies 1376 B (the path of
//!   a request), consolidation off as a mirror asks.
//!
//! Round trips only, measured by the pinging parent (`bridge.raw.put.rtt`,
//! `bridge.raw.get.rtt`). The echo answers from Zenoh's callbacks. The get exchanges run
//! back to back; the put ping-pong is the bridge's floor and runs in blocks that alternate
//! with the bridge's own (`bridge`), so that both see the same moments of the machine.

use std::time::{Duration, Instant};

use hdrhistogram::Histogram;
use limber_services::monotonic_ns;
use zenoh::handlers::FifoChannelHandler;
use zenoh::pubsub::{Publisher, Subscriber};
use zenoh::query::ConsolidationMode;
use zenoh::sample::Sample;
use zenoh::{Config, Session, Wait};

use super::floor::BYTES;
use super::{READY_TIMEOUT, RunCtx, SAMPLE_TIMEOUT};
use crate::child::{ChildProc, ChildSpec};
use crate::progress::Progress;
use crate::stats::{Measurement, Metric, Strategy, new_histogram};
use crate::{BenchArgs, BenchError, roles};

const PING: &str = "limber-bench/ping";
const PONG: &str = "limber-bench/pong";
const QUERY: &str = "limber-bench/query";

/// The environment variable naming a Zenoh configuration file (JSON5) for the `bridge`
/// scenario: both bridges get it (`--zenoh-config`) and the floor's two sessions start from
/// it, so that the floor stays the same transport as the pair (e.g. Zenoh's LowLatency
/// transport, docs/guide/bridge.md).
pub const ZENOH_CONFIG_ENV: &str = "LIMBER_BENCH_ZENOH_CONFIG";

/// The file [`ZENOH_CONFIG_ENV`] names, if set and not empty.
pub fn zenoh_config() -> Option<std::path::PathBuf> {
    std::env::var_os(ZENOH_CONFIG_ENV)
        .filter(|v| !v.is_empty())
        .map(std::path::PathBuf::from)
}

fn zerr(what: &str) -> impl Fn(zenoh::Error) -> BenchError + '_ {
    move |e| BenchError::transport(what, e)
}

/// A peer session listening on `listen` and connecting to `connect`, multicast scouting
/// off (as a bridge's).
fn open(listen: &[&str], connect: &[&str]) -> Result<Session, BenchError> {
    let list = |v: &[&str]| {
        let q: Vec<String> = v.iter().map(|e| format!("\"{e}\"")).collect();
        format!("[{}]", q.join(","))
    };
    let mut config = match zenoh_config() {
        Some(path) => Config::from_file(&path).map_err(|e| {
            BenchError::transport(format!("the Zenoh configuration {}", path.display()), e)
        })?,
        None => Config::default(),
    };
    for (key, value) in [
        ("mode", "\"peer\"".to_string()),
        ("listen/endpoints", list(listen)),
        ("connect/endpoints", list(connect)),
        ("scouting/multicast/enabled", "false".into()),
        ("scouting/gossip/autoconnect", "[]".into()),
    ] {
        config
            .insert_json5(key, &value)
            .map_err(|e| BenchError::transport(format!("zenoh setting {key} = {value}"), e))?;
    }
    zenoh::open(config).wait().map_err(zerr("zenoh session"))
}

/// A payload of `len` bytes carrying `seq` in its first 8.
fn payload(seq: u64, len: usize) -> Vec<u8> {
    let mut p = vec![0u8; len.max(8)];
    p[..8].copy_from_slice(&seq.to_le_bytes());
    p
}

fn seq_of(bytes: &[u8]) -> Option<u64> {
    Some(u64::from_le_bytes(bytes.get(..8)?.try_into().ok()?))
}

/// The raw Zenoh floor: an echo child on a Unix socket in the scratch directory and this
/// process's session connected to it, open while the bridge's own exchanges run, so that
/// the floor's ping-pong can alternate with them ([`Pinger`]).
pub struct Floor {
    child: ChildProc,
    session: Session,
}

impl Floor {
    /// Starts the echo child (alive for `deadline` at most) and connects to it.
    pub fn start(ctx: &mut RunCtx, deadline: Duration) -> Result<Floor, BenchError> {
        let sock = ctx.tmp_file("zenoh-floor.sock");
        let endpoint = format!("unixsock-stream/{}", sock.display());
        let mut child = ChildProc::spawn(&ChildSpec {
            role: "zenoh-echo".into(),
            addr: Some(endpoint.clone()),
            cpu: ctx.child_cpu(),
            deadline,
            ..Default::default()
        })?;
        child.expect("ready", READY_TIMEOUT)?;
        match open(&[], &[&endpoint]) {
            Ok(session) => Ok(Floor { child, session }),
            Err(e) => {
                if let Err(k) = child.terminate(Duration::from_secs(10)) {
                    tracing::warn!("cannot stop the zenoh echo: {k}");
                }
                Err(e)
            }
        }
    }

    /// The put/subscribe ping-pong, once both sides see each other.
    pub fn pinger(&self) -> Result<Pinger, BenchError> {
        Pinger::new(&self.session)
    }

    /// `warm` + `n` get/queryable exchanges back to back; the last `n` recorded.
    pub fn get_round_trips(
        &self,
        ctx: &RunCtx,
        warm: u64,
        n: u64,
    ) -> Result<Histogram<u64>, BenchError> {
        get_round_trips(ctx, &self.session, warm, n)
    }

    /// Closes the session and tells the echo to end.
    pub fn finish(self) -> Result<(), BenchError> {
        let Floor { mut child, session } = self;
        if let Err(e) = session.close().wait() {
            tracing::warn!("cannot close the zenoh floor's session: {e}");
        }
        if let Err(e) = child.send_line("quit") {
            tracing::warn!("cannot tell the zenoh echo to quit: {e}");
        }
        child.finish(Duration::from_secs(10))
    }
}

/// Adds the floor's two measurements: the put ping-pong's round trips and the get
/// exchange's.
pub fn push(ctx: &mut RunCtx, put: Histogram<u64>, get: Histogram<u64>) {
    for (id, label, hist) in [
        (
            "bridge.raw.put.rtt",
            "raw Zenoh put→subscriber ping-pong (Unix socket)",
            put,
        ),
        (
            "bridge.raw.get.rtt",
            "raw Zenoh get→queryable reply (Unix socket)",
            get,
        ),
    ] {
        ctx.push(Measurement {
            scenario: "bridge",
            id: id.into(),
            label: label.into(),
            strategy: Strategy::Blocking,
            metric: Metric::RoundTrip,
            bytes: Some(BYTES),
            hist,
        });
    }
}

/// The pinging side of the put/subscribe ping-pong.
pub struct Pinger {
    ping: Publisher<'static>,
    pongs: Subscriber<FifoChannelHandler<Sample>>,
    seq: u64,
}

impl Pinger {
    fn new(session: &Session) -> Result<Pinger, BenchError> {
        let ping = session
            .declare_publisher(PING)
            .wait()
            .map_err(zerr("ping publisher"))?;
        let pongs = session
            .declare_subscriber(PONG)
            .wait()
            .map_err(zerr("pong subscriber"))?;
        // Until both sides see each other, a put goes nowhere: ping 0 until its pong comes.
        let until = Instant::now() + READY_TIMEOUT;
        'sync: loop {
            ping.put(payload(0, BYTES.0)).wait().map_err(zerr("ping"))?;
            let tick = Instant::now() + Duration::from_millis(100);
            while let Some(s) = pongs.recv_deadline(tick).map_err(zerr("pong"))? {
                if seq_of(&s.payload().to_bytes()) == Some(0) {
                    break 'sync;
                }
            }
            if Instant::now() > until {
                return Err(BenchError::Timeout {
                    what: "the zenoh echo's first pong".into(),
                    timeout: READY_TIMEOUT,
                });
            }
        }
        Ok(Pinger {
            ping,
            pongs,
            seq: 0,
        })
    }

    /// One ping and its pong: the round trip, ns.
    pub fn round_trip(&mut self) -> Result<u64, BenchError> {
        self.seq += 1;
        let seq = self.seq;
        let t0 = monotonic_ns();
        self.ping
            .put(payload(seq, BYTES.0))
            .wait()
            .map_err(zerr("ping"))?;
        let until = Instant::now() + SAMPLE_TIMEOUT;
        loop {
            let Some(s) = self.pongs.recv_deadline(until).map_err(zerr("pong"))? else {
                return Err(BenchError::Timeout {
                    what: format!("zenoh pong {seq}"),
                    timeout: SAMPLE_TIMEOUT,
                });
            };
            if seq_of(&s.payload().to_bytes()) == Some(seq) {
                break;
            }
        }
        Ok(monotonic_ns().saturating_sub(t0))
    }
}

fn get_round_trips(
    ctx: &RunCtx,
    session: &Session,
    warm: u64,
    n: u64,
) -> Result<Histogram<u64>, BenchError> {
    let mut rtt = new_histogram()?;
    let progress = Progress::new(ctx.progress, "zenoh get", warm + n);
    for seq in 1..=warm + n {
        let t0 = monotonic_ns();
        let replies = session
            .get(QUERY)
            .payload(payload(seq, BYTES.0))
            .timeout(SAMPLE_TIMEOUT)
            .consolidation(ConsolidationMode::None)
            .wait()
            .map_err(zerr("get"))?;
        let reply = replies
            .recv_timeout(SAMPLE_TIMEOUT)
            .map_err(zerr("reply"))?
            .ok_or_else(|| BenchError::Timeout {
                what: format!("zenoh reply {seq}"),
                timeout: SAMPLE_TIMEOUT,
            })?;
        let t1 = monotonic_ns();
        let sample = reply
            .result()
            .map_err(|e| BenchError::transport("reply", e))?;
        if seq_of(&sample.payload().to_bytes()) != Some(seq) {
            return Err(BenchError::transport(
                "reply",
                format!("not the answer to {seq}"),
            ));
        }
        if seq > warm {
            rtt.saturating_record(t1.saturating_sub(t0));
        }
        progress.tick(seq);
    }
    progress.finish();
    Ok(rtt)
}

/// The echo child (`zenoh-echo`): listens on `--addr`, answers each ping with a pong and
/// each query with a reply of the state's size, until `quit` or its deadline.
pub fn echo_role(args: &BenchArgs) -> Result<(), BenchError> {
    let endpoint = args
        .addr
        .as_deref()
        .ok_or_else(|| BenchError::Args("--addr is required for this role".into()))?;
    let deadline = roles::child_deadline(args);
    let session = open(&[endpoint], &[])?;
    let pong = session
        .declare_publisher(PONG)
        .wait()
        .map_err(zerr("pong publisher"))?;
    let _pings = session
        .declare_subscriber(PING)
        .callback(move |s| {
            let Some(seq) = seq_of(&s.payload().to_bytes()) else {
                return;
            };
            if let Err(e) = pong.put(payload(seq, BYTES.1)).wait() {
                tracing::warn!("zenoh echo: cannot answer ping {seq}: {e}");
            }
        })
        .wait()
        .map_err(zerr("ping subscriber"))?;
    let _queries = session
        .declare_queryable(QUERY)
        .callback(|q| {
            let Some(seq) = q.payload().and_then(|p| seq_of(&p.to_bytes())) else {
                return;
            };
            if let Err(e) = q.reply(q.key_expr().clone(), payload(seq, BYTES.1)).wait() {
                tracing::warn!("zenoh echo: cannot answer query {seq}: {e}");
            }
        })
        .wait()
        .map_err(zerr("queryable"))?;
    let lines = roles::stdin_lines();
    roles::announce("ready");
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            break;
        }
        match lines.recv_timeout(left) {
            Ok(l) if l.trim() == "quit" => break,
            Ok(_) => {}
            Err(_) => break,
        }
    }
    if let Err(e) = session.close().wait() {
        tracing::warn!("zenoh echo: cannot close the session: {e}");
    }
    Ok(())
}
