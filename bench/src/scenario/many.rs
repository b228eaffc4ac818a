//! `many`: many robots and many clients in one domain. Each robot is a driver process of
//! its own, the real drivers ([`many_drivers`](super::many_drivers)): simarm and the
//! Pioneer driver on an emulated Pioneer, alternating (`bench0` simarm, `bench1` a Pioneer,
//! `bench2` simarm, ...), with 64 clients (each its own node, as 64 programs would have,
//! spread over the devices; in this process). Four passes, one after the other:
//! 1 driver (simarm), 1 driver (an emulated Pioneer), 4 drivers, 16 drivers. Each
//! measures, with the others running:
//!
//! * listing the domain as `limber list` does (`limber_services::list_devices`):
//!   `many.<n>.list`; goal in time: at most 100 ms with 16 drivers; its floor, in turn with
//!   it: iceoryx2's own listing of the domain's services (`ipc::Service::list`, which reads
//!   every service's nodes; nothing done with them), `many.<n>.list.raw`;
//! * a command's round trip (`move_to` then `wait_outcome`, one a millisecond) from one
//!   client to the first simarm: `many.<n>.rtt`; goal: at most 1.2x from 1 to 16 drivers,
//!   at p50 and p99;
//! * its floor at that rate beside the same drivers: the raw iceoryx2 event ping-pong at
//!   1 kHz (`many.<n>.paced.event.*`), whose own growth from 1 to 16 drivers is what the
//!   machine adds to any exchange when 16 robots share its 2 cores;
//! * the loop period of the first simarm and of the first Pioneer (`many.<n>.simarm.period`,
//!   `many.<n>.pioneer.period`; the 1-driver figure of each from its own pass): the
//!   periods between the timer cycles of its 10 ms tick, the latest 512 (5.1 s: the round
//!   trips and the floor; in the Pioneer's own pass, which has no simarm, the round trips'
//!   time with nothing sent) as the driver keeps them, written when the pass ends, before
//!   its clients leave; goal: p99 at most 1.2x from 1 to 16 drivers. Their floor, beside
//!   the same drivers: limber's event loop on a 10 ms timer with no device
//!   (`many.<n>.ticker.period`);
//! * memory: each driver's resident set (`VmRSS`) and its proportional share of shared
//!   memory (`Pss_Shmem` of `/proc/<pid>/smaps_rollup`), by kind, and what one more client
//!   adds to this process's (the growth over the clients, divided by their number); in the
//!   scenario's notes.
//!
//! Quick mode: the 1-driver passes and 4 drivers, 16 clients.

use std::time::{Duration, Instant};

use hdrhistogram::Histogram;
use limber_services::prelude::*;
use limber_services::{Role, list_devices, monotonic_ns};

use super::floor::{self, BYTES, Echo};
use super::many_drivers::{PIONEER_ROLE, SIMARM_ROLE, TICKER_ROLE};
use super::{Pace, READY_TIMEOUT, RunCtx, Scenario, timed_command};
use crate::BenchError;
use crate::child::{ChildProc, ChildSpec, read_histogram};
use crate::progress::Progress;
use crate::stats::{Measurement, Metric, Strategy, new_histogram};

/// Clients (default counts).
pub const CLIENTS: usize = 64;

/// The period of the round trips and of their floor.
const PERIOD: Duration = Duration::from_millis(1);

/// A driver of the scenario.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// simarm.
    SimArm,
    /// The Pioneer driver on the emulator.
    Pioneer,
}

impl Kind {
    fn role(self) -> &'static str {
        match self {
            Kind::SimArm => SIMARM_ROLE,
            Kind::Pioneer => PIONEER_ROLE,
        }
    }
    /// The ids' part.
    fn key(self) -> &'static str {
        match self {
            Kind::SimArm => "simarm",
            Kind::Pioneer => "pioneer",
        }
    }
    fn label(self) -> &'static str {
        match self {
            Kind::SimArm => "simarm",
            Kind::Pioneer => "emulated Pioneer",
        }
    }
}

/// One pass: `n` drivers, all of one kind (`alone`) or alternating from simarm.
#[derive(Debug, Clone, Copy)]
pub struct Pass {
    /// The ids' part (`many.<tag>.*`).
    pub tag: &'static str,
    /// What the labels say runs.
    pub label: &'static str,
    /// Drivers.
    pub n: usize,
    /// All drivers of this kind; `None`: simarm, a Pioneer, simarm, ...
    pub alone: Option<Kind>,
}

impl Pass {
    fn kind(&self, i: usize) -> Kind {
        self.alone.unwrap_or(if i.is_multiple_of(2) {
            Kind::SimArm
        } else {
            Kind::Pioneer
        })
    }
    /// The first driver of `kind`.
    fn first(&self, kind: Kind) -> Option<usize> {
        (0..self.n).find(|i| self.kind(*i) == kind)
    }
}

/// The passes, in order.
pub const PASSES: [Pass; 4] = [
    Pass {
        tag: "1",
        label: "1 driver (simarm)",
        n: 1,
        alone: Some(Kind::SimArm),
    },
    Pass {
        tag: "1p",
        label: "1 driver (an emulated Pioneer)",
        n: 1,
        alone: Some(Kind::Pioneer),
    },
    Pass {
        tag: "4",
        label: "4 drivers",
        n: 4,
        alone: None,
    },
    Pass {
        tag: "16",
        label: "16 drivers",
        n: 16,
        alone: None,
    },
];

/// The `many` scenario.
#[derive(Debug, Clone, Copy)]
pub struct Many;

impl Scenario for Many {
    fn name(&self) -> &'static str {
        "many"
    }
    fn description(&self) -> &'static str {
        "1, 4 and 16 drivers (simarm and emulated Pioneers) with 64 clients in one domain: listing the domain, a command's round trip at 1 kHz and its floor, the drivers' loop periods and theirs, memory per driver and per client"
    }
    fn run(&self, ctx: &mut RunCtx) -> Result<(), BenchError> {
        if !ctx.blocking_enabled() {
            ctx.notes
                .push("many runs event-driven drivers; skipped by --strategy spin".into());
            return Ok(());
        }
        let (passes, clients): (&[Pass], usize) = if ctx.quick {
            (&PASSES[..3], 16)
        } else {
            (&PASSES, CLIENTS)
        };
        for pass in passes {
            run(ctx, pass, clients)?;
        }
        Ok(())
    }
}

fn err(what: &str, reason: impl std::fmt::Display) -> BenchError {
    BenchError::Transport {
        context: what.to_string(),
        reason: reason.to_string(),
    }
}

fn device(i: usize) -> String {
    format!("bench{i}/actarray/0")
}

/// Kibibytes of `key` (e.g. `VmRSS:`) in a `/proc` file of `key: N kB` lines.
fn kib(path: &str, key: &str) -> Option<u64> {
    let text = std::fs::read_to_string(path).ok()?;
    let line = text.lines().find(|l| l.starts_with(key))?;
    line[key.len()..].split_whitespace().next()?.parse().ok()
}

/// What a pass measured through its clients (the periods come from the children).
struct Measured {
    list: Histogram<u64>,
    list_raw: Histogram<u64>,
    rtt: Option<Histogram<u64>>,
    rss_after: Option<u64>,
}

fn run(ctx: &mut RunCtx, pass: &Pass, clients: usize) -> Result<(), BenchError> {
    let domain = ctx.domain();
    let (warm, count) = (ctx.count(200, 50), ctx.count(2_000, 300));
    let deadline = Duration::from_secs(120) + PERIOD * ((warm + count) as u32 + 4_000) * 3;
    ctx.say(format_args!("  many: {}, {clients} clients", pass.label));
    let spawn = |role: &str, out: String, device: Option<String>| {
        ChildProc::spawn(&ChildSpec {
            role: role.into(),
            domain: Some(domain.name().to_string()),
            out: Some(ctx.tmp_file(&out)),
            device,
            deadline,
            ..Default::default()
        })
    };
    let mut drivers = Vec::with_capacity(pass.n);
    for i in 0..pass.n {
        let kind = pass.kind(i);
        let out = format!("many-{}-{i}.hdr", pass.tag);
        drivers.push((kind, out.clone(), spawn(kind.role(), out, Some(device(i)))?));
    }
    let ticker_out = format!("many-{}-ticker.hdr", pass.tag);
    let mut ticker = spawn(TICKER_ROLE, ticker_out.clone(), None)?;
    for (_, _, d) in &mut drivers {
        d.expect("ready", READY_TIMEOUT)?;
    }
    ticker.expect("ready", READY_TIMEOUT)?;
    let me = format!("/proc/{}/status", std::process::id());
    let rss_before = kib(&me, "VmRSS:");
    let mut connected = Vec::with_capacity(clients);
    let r = (|| {
        for c in 0..clients {
            let cctx = Context::new(&domain, Role::Client, &format!("bench-many-{c}"))
                .map_err(|e| err("client context", e))?;
            let client = ActArrayClient::connect_timeout(&cctx, &device(c % pass.n), READY_TIMEOUT)
                .map_err(|e| err("connect", e))?;
            connected.push((client, cctx));
        }
        let rss_after = kib(&me, "VmRSS:");
        let (list, list_raw) = list_times(ctx, &domain, pass.n)?;
        // Client 0 is on driver 0: the round trips when it is a simarm. Without one, the
        // same time with nothing sent, so that the loops' latest 512 periods (5.1 s) are
        // those of the measurements in every pass, not of the clients' connecting.
        let rtt = match pass.kind(0) {
            Kind::SimArm => Some(round_trips(ctx, &mut connected[0].0, pass, warm, count)?),
            Kind::Pioneer => {
                std::thread::sleep(PERIOD * (warm + count) as u32);
                None
            }
        };
        // The floor at the same rate, beside the same drivers and clients.
        floor::ping_pong(
            ctx,
            Echo::Listener,
            Pace::Paced {
                period: PERIOD,
                scenario: "many",
                beside: Some((pass.tag, pass.label)),
                turns: 1,
            },
        )?;
        Ok::<_, BenchError>(Measured {
            list,
            list_raw,
            rtt,
            rss_after,
        })
    })();
    let mut mem = Vec::new();
    for (kind, _, d) in &drivers {
        let pid = d.pid();
        let rss = kib(&format!("/proc/{pid}/status"), "VmRSS:");
        let shm = kib(&format!("/proc/{pid}/smaps_rollup"), "Pss_Shmem:");
        mem.push((*kind, rss, shm));
    }
    // `quit` before the clients go: each child writes its loop's periods and ends (64
    // clients leaving at once cost a driver's loop some 15-40 ms of iceoryx2's
    // disconnections, which are not what the periods measure).
    let mut failed = None;
    let mut outs = Vec::new();
    for (kind, out, mut d) in drivers {
        let ended = d
            .send_line("quit")
            .and_then(|()| d.finish(Duration::from_secs(20)));
        if let Err(e) = ended {
            failed.get_or_insert(e);
        }
        outs.push((kind, out));
    }
    let ended = ticker
        .send_line("quit")
        .and_then(|()| ticker.finish(Duration::from_secs(20)));
    if let Err(e) = ended {
        failed.get_or_insert(e);
    }
    drop(connected);
    let measured = r?;
    if let Some(e) = failed {
        return Err(e);
    }
    note_memory(ctx, pass, clients, &mem, rss_before, measured.rss_after);
    let blocking = |id: String, label: String, metric: Metric, hist: Histogram<u64>| Measurement {
        scenario: "many",
        id,
        label,
        strategy: Strategy::Blocking,
        metric,
        bytes: (metric == Metric::RoundTrip).then_some(BYTES),
        hist,
    };
    let (tag, label) = (pass.tag, pass.label);
    ctx.push(blocking(
        format!("many.{tag}.list"),
        format!("list the domain, {label}, {clients} clients"),
        Metric::Read,
        measured.list,
    ));
    ctx.push(blocking(
        format!("many.{tag}.list.raw"),
        format!("iceoryx2's own listing of the domain's services (the floor), {label}"),
        Metric::Read,
        measured.list_raw,
    ));
    if let Some(rtt) = measured.rtt {
        ctx.push(blocking(
            format!("many.{tag}.rtt"),
            format!("command→outcome at 1 kHz to simarm, {label}, {clients} clients"),
            Metric::RoundTrip,
            rtt,
        ));
    }
    for kind in [Kind::SimArm, Kind::Pioneer] {
        let Some(i) = pass.first(kind) else { continue };
        let hist = read_histogram(&ctx.tmp_file(&outs[i].1))?;
        ctx.push(blocking(
            format!("many.{tag}.{}.period", kind.key()),
            format!("{}'s loop period (10 ms tick), {label}", kind.label()),
            Metric::Period,
            hist,
        ));
    }
    let hist = read_histogram(&ctx.tmp_file(&ticker_out))?;
    ctx.push(blocking(
        format!("many.{tag}.ticker.period"),
        format!("event loop on a 10 ms timer, no device (the floor), beside {label}"),
        Metric::Period,
        hist,
    ));
    Ok(())
}

/// The memory per driver (by kind) and per client, in the notes.
fn note_memory(
    ctx: &mut RunCtx,
    pass: &Pass,
    clients: usize,
    mem: &[(Kind, Option<u64>, Option<u64>)],
    rss_before: Option<u64>,
    rss_after: Option<u64>,
) {
    let avg = |v: Vec<u64>| (!v.is_empty()).then(|| v.iter().sum::<u64>() / v.len() as u64);
    let show = |k: Option<u64>| k.map_or("unknown".into(), |k| format!("{k} KiB"));
    let mut per_kind = Vec::new();
    for kind in [Kind::SimArm, Kind::Pioneer] {
        let of: Vec<_> = mem.iter().filter(|m| m.0 == kind).collect();
        if of.is_empty() {
            continue;
        }
        let rss = avg(of.iter().filter_map(|m| m.1).collect());
        let shm = avg(of.iter().filter_map(|m| m.2).collect());
        per_kind.push(format!(
            "per {} RSS {} (of it shared memory, proportional: {})",
            kind.label(),
            show(rss),
            show(shm)
        ));
    }
    let per_client = match (rss_before, rss_after) {
        (Some(a), Some(b)) => format!("{} KiB", b.saturating_sub(a) / clients.max(1) as u64),
        _ => "unknown".into(),
    };
    ctx.notes.push(format!(
        "{}, {clients} clients: {}, per client {per_client} of RSS (this process's growth)",
        pass.label,
        per_kind.join(", "),
    ));
}

/// Lists the domain 20 times (5 in quick mode), checking that every driver is there, and
/// as many times, in turn, as iceoryx2 itself lists the domain's services (the same call,
/// which reads every service's nodes, with nothing done with what it finds): the floor.
fn list_times(
    ctx: &RunCtx,
    domain: &Domain,
    n: usize,
) -> Result<(Histogram<u64>, Histogram<u64>), BenchError> {
    use iceoryx2::prelude::*;
    let config = domain
        .config()
        .map_err(|e| err("the domain's configuration", e))?;
    let (mut h, mut raw) = (new_histogram()?, new_histogram()?);
    for _ in 0..ctx.count(20, 5) {
        let t0 = monotonic_ns();
        let mut services = 0usize;
        ipc::Service::list(config, |_| {
            services += 1;
            CallbackProgression::Continue
        })
        .map_err(|e| err("iceoryx2's listing of the domain", format!("{e:?}")))?;
        raw.saturating_record(monotonic_ns().saturating_sub(t0));
        if services == 0 {
            return Err(err("iceoryx2's listing of the domain", "no service"));
        }
        let t0 = monotonic_ns();
        let list = list_devices(domain).map_err(|e| err("list the domain", e))?;
        let t1 = monotonic_ns();
        // Every actarray of the drivers (a Pioneer serves a second one, its lift, when
        // the emulated robot has a body gripper).
        let alive = (0..n)
            .filter(|i| {
                list.iter()
                    .any(|d| d.alive && d.name.to_string() == device(*i))
            })
            .count();
        if alive != n {
            return Err(err(
                "list the domain",
                format!("{alive} of the {n} drivers' arms listed alive"),
            ));
        }
        h.saturating_record(t1.saturating_sub(t0));
    }
    Ok((h, raw))
}

/// `warm` + `count` command round trips, one a millisecond; the last `count` recorded.
fn round_trips(
    ctx: &RunCtx,
    client: &mut ActArrayClient,
    pass: &Pass,
    warm: u64,
    count: u64,
) -> Result<Histogram<u64>, BenchError> {
    client
        .current(READY_TIMEOUT)
        .map_err(|e| err("first state", e))?;
    let pace = Pace::Paced {
        period: PERIOD,
        scenario: "many",
        beside: None,
        turns: 1,
    };
    let mut rtt = new_histogram()?;
    let progress = Progress::new(ctx.progress, &format!("many {}", pass.tag), warm + count);
    let start = Instant::now();
    for i in 1..=warm + count {
        pace.wait_turn(start, i);
        let took = timed_command(client, i, "many")?;
        if i > warm {
            rtt.saturating_record(took);
        }
        progress.tick(i);
    }
    progress.finish();
    Ok(rtt)
}
