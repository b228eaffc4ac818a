//! `many`: many robots and many clients in one domain. With 1, 4 and 16 driver children
//! (the `command` scenario's event-driven driver, each its own device
//! `bench<i>/actarray/0`) and 64 clients (each its own node, as 64 programs would have,
//! spread over the devices; in this process), measures:
//!
//! * listing the domain as `limber list` does (`limber_services::list_devices`):
//!   `many.<n>.list`; goal in time: at most 100 ms with 16 drivers;
//! * a command's round trip (`move_to` then `wait_outcome`, one a millisecond) from one
//!   client to the first driver while the others are connected: `many.<n>.rtt`; goal: at
//!   most 1.2x from 1 to 16 drivers, at p50 and p99;
//! * memory: each driver's resident set (`VmRSS`) and its proportional share of shared
//!   memory (`Pss_Shmem` of `/proc/<pid>/smaps_rollup`), and what one more client adds to
//!   this process's (the growth over the clients, divided by their number); in the
//!   scenario's notes.
//!
//! Quick mode: 1 and 4 drivers, 16 clients.

use std::time::{Duration, Instant};

use hdrhistogram::Histogram;
use limber_services::prelude::*;
use limber_services::{Role, list_devices, monotonic_ns};

use super::floor::BYTES;
use super::{Pace, READY_TIMEOUT, RunCtx, Scenario, timed_command};
use crate::BenchError;
use crate::child::{ChildProc, ChildSpec};
use crate::progress::Progress;
use crate::stats::{Measurement, Metric, Strategy, new_histogram};

/// The numbers of drivers measured.
pub const DRIVERS: [usize; 3] = [1, 4, 16];
/// Clients (default counts).
pub const CLIENTS: usize = 64;

/// The `many` scenario.
#[derive(Debug, Clone, Copy)]
pub struct Many;

impl Scenario for Many {
    fn name(&self) -> &'static str {
        "many"
    }
    fn description(&self) -> &'static str {
        "1, 4 and 16 drivers with 64 clients in one domain: listing the domain, a command's round trip at 1 kHz, memory per driver and per client"
    }
    fn run(&self, ctx: &mut RunCtx) -> Result<(), BenchError> {
        if !ctx.blocking_enabled() {
            ctx.notes
                .push("many runs event-driven drivers; skipped by --strategy spin".into());
            return Ok(());
        }
        let (drivers, clients): (&[usize], usize) = if ctx.quick {
            (&DRIVERS[..2], 16)
        } else {
            (&DRIVERS, CLIENTS)
        };
        for &n in drivers {
            run(ctx, n, clients)?;
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

fn run(ctx: &mut RunCtx, n: usize, clients: usize) -> Result<(), BenchError> {
    let domain = ctx.domain();
    let (warm, count) = (ctx.count(200, 50), ctx.count(2_000, 300));
    let deadline = Duration::from_secs(120) + Duration::from_millis(warm + count) * 3;
    ctx.say(format_args!("  many: {n} driver(s), {clients} clients"));
    let mut drivers = Vec::with_capacity(n);
    for i in 0..n {
        drivers.push(ChildProc::spawn(&ChildSpec {
            role: "cmd-driver-event".into(),
            domain: Some(domain.name().to_string()),
            out: Some(ctx.tmp_file(&format!("many-{n}-{i}.hdr"))),
            device: Some(device(i)),
            deadline,
            linger: Some(limber_services::qos::DRIVER_LINGER),
            ..Default::default()
        })?);
    }
    for d in &mut drivers {
        d.expect("ready", READY_TIMEOUT)?;
    }
    let me = format!("/proc/{}/status", std::process::id());
    let rss_before = kib(&me, "VmRSS:");
    let mut connected = Vec::with_capacity(clients);
    let r = (|| {
        for c in 0..clients {
            let cctx = Context::new(&domain, Role::Client, &format!("bench-many-{c}"))
                .map_err(|e| err("client context", e))?;
            let client = ActArrayClient::connect_timeout(&cctx, &device(c % n), READY_TIMEOUT)
                .map_err(|e| err("connect", e))?;
            connected.push((client, cctx));
        }
        let rss_after = kib(&me, "VmRSS:");
        let list = list_times(ctx, &domain, n)?;
        let rtt = round_trips(ctx, &mut connected[0].0, n, warm, count)?;
        Ok::<_, BenchError>((list, rtt, rss_after))
    })();
    let mut mem = Vec::new();
    for d in &drivers {
        let pid = d.pid();
        let rss = kib(&format!("/proc/{pid}/status"), "VmRSS:");
        let shm = kib(&format!("/proc/{pid}/smaps_rollup"), "Pss_Shmem:");
        mem.push((rss, shm));
    }
    // HOME all joints stops each driver child (if it cannot be sent, its deadline does).
    for (i, (client, _)) in connected.iter_mut().enumerate().take(n) {
        if let Err(e) = client.home(None) {
            tracing::warn!("cannot tell driver {i} to stop: {e}");
        }
    }
    drop(connected);
    let mut failed = None;
    for d in drivers {
        if let Err(e) = d.finish(Duration::from_secs(10)) {
            failed.get_or_insert(e);
        }
    }
    let (list, rtt, rss_after) = r?;
    if let Some(e) = failed {
        return Err(e);
    }
    let avg = |v: Vec<u64>| (!v.is_empty()).then(|| v.iter().sum::<u64>() / v.len() as u64);
    let rss = avg(mem.iter().filter_map(|m| m.0).collect());
    let shm = avg(mem.iter().filter_map(|m| m.1).collect());
    let per_client = match (rss_before, rss_after) {
        (Some(a), Some(b)) => format!("{} KiB", b.saturating_sub(a) / clients.max(1) as u64),
        _ => "unknown".into(),
    };
    let show = |k: Option<u64>| k.map_or("unknown".into(), |k| format!("{k} KiB"));
    ctx.notes.push(format!(
        "{n} driver(s), {clients} clients: per driver RSS {} (of it shared memory, proportional: {}), per client {per_client} of RSS (this process's growth)",
        show(rss),
        show(shm),
    ));
    for (id, label, metric, hist) in [
        (
            format!("many.{n}.list"),
            format!("list the domain, {n} driver(s), {clients} clients"),
            Metric::Read,
            list,
        ),
        (
            format!("many.{n}.rtt"),
            format!("command→outcome at 1 kHz, {n} driver(s), {clients} clients"),
            Metric::RoundTrip,
            rtt,
        ),
    ] {
        ctx.push(Measurement {
            scenario: "many",
            id,
            label,
            strategy: Strategy::Blocking,
            metric,
            bytes: (metric == Metric::RoundTrip).then_some(BYTES),
            hist,
        });
    }
    Ok(())
}

/// Lists the domain 20 times (5 in quick mode), checking that every driver is there.
fn list_times(ctx: &RunCtx, domain: &Domain, n: usize) -> Result<Histogram<u64>, BenchError> {
    let mut h = new_histogram()?;
    for _ in 0..ctx.count(20, 5) {
        let t0 = monotonic_ns();
        let list = list_devices(domain).map_err(|e| err("list the domain", e))?;
        let t1 = monotonic_ns();
        let alive = list.iter().filter(|d| d.alive).count();
        if alive != n {
            return Err(err(
                "list the domain",
                format!("{alive} live devices listed, {n} expected"),
            ));
        }
        h.saturating_record(t1.saturating_sub(t0));
    }
    Ok(h)
}

/// `warm` + `count` command round trips, one a millisecond; the last `count` recorded.
fn round_trips(
    ctx: &RunCtx,
    client: &mut ActArrayClient,
    n: usize,
    warm: u64,
    count: u64,
) -> Result<Histogram<u64>, BenchError> {
    client
        .current(READY_TIMEOUT)
        .map_err(|e| err("first state", e))?;
    let pace = Pace::Paced {
        period: Duration::from_millis(1),
        scenario: "many",
    };
    let mut rtt = new_histogram()?;
    let progress = Progress::new(ctx.progress, &format!("many {n}"), warm + count);
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
