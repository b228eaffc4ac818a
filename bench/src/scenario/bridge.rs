//! `bridge`: the command round trip (`move_to` then a blocking `wait_outcome`, as a client
//! does) through a `limber bridge expose` + `limber bridge mirror` pair over the private Unix socket of `expose`
//! (Zenoh), beside the same client against the driver directly, in the same run.
//!
//! The driver is the `command` scenario's event-driven driver child (`cmd-driver-event`,
//! its default linger) in domain A, with `bridge expose` in A; `bridge mirror` hosts the
//! arm in domain B, where this process is the client. The client in A runs first (the
//! direct row), then the one in B (the bridge row); the report sets the bridge row beside
//! the TCP loopback peer row of the same run (`peers`).
//!
//! Its floor, in the same run: raw Zenoh between two processes over a Unix socket, a
//! get/queryable exchange first and a put/subscribe ping-pong ([`zenoh_floor`]) whose
//! blocks alternate with the bridge row's (`interleaved`), so that the goal's ratio is of
//! the same moments of the machine (on this VM the pace of wake-ups changes by up to 2x for
//! seconds at a time: a floor measured first and the bridge after could fall in
//! different ones).
//!
//! The bridges are the `limber` executable: `$LIMBER_BIN` if set, else this executable if
//! it is `limber`, else `limber` beside it. If none can run `limber bridge` (e.g.
//! `limber-bench` alone, or a `limber` built without its `bridge` feature), the scenario
//! is skipped with the reason, printed and noted in the report.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use hdrhistogram::Histogram;
use limber_services::Role;
use limber_services::prelude::*;

use super::command::{DEVICE, start_event_driver};
use super::floor::BYTES;
use super::lang::run_bounded;
use super::{READY_TIMEOUT, RunCtx, Scenario, timed_command, zenoh_floor};
use crate::BenchError;
use crate::child::ChildProc;
use crate::cpu::{self, CpuCost};
use crate::progress::Progress;
use crate::stats::{Measurement, Metric, Strategy, new_histogram};

/// The `bridge` scenario.
#[derive(Debug, Clone, Copy)]
pub struct Bridge;

impl Scenario for Bridge {
    fn name(&self) -> &'static str {
        "bridge"
    }
    fn description(&self) -> &'static str {
        "command round trip through limber bridge expose + mirror (Zenoh, Unix socket), beside the same client direct"
    }
    fn run(&self, ctx: &mut RunCtx) -> Result<(), BenchError> {
        if !ctx.blocking_enabled() {
            ctx.notes
                .push("bridge runs blocking clients; skipped by --strategy spin".into());
            return Ok(());
        }
        match limber_exe() {
            Ok(exe) => run(ctx, &exe),
            Err(why) => {
                let note = format!("bridge skipped: {why}");
                tracing::warn!("{note}");
                ctx.notes.push(note);
                Ok(())
            }
        }
    }
}

fn err(what: &str, reason: impl std::fmt::Display) -> BenchError {
    BenchError::Transport {
        context: what.to_string(),
        reason: reason.to_string(),
    }
}

/// The `limber` executable that runs the bridges; `Err(why)` when there is none that can.
fn limber_exe() -> Result<PathBuf, String> {
    let exe = if let Some(p) = std::env::var_os("LIMBER_BIN") {
        PathBuf::from(p)
    } else {
        let me =
            std::env::current_exe().map_err(|e| format!("cannot find this executable: {e}"))?;
        if me.file_name().is_some_and(|n| n == "limber") {
            me
        } else {
            me.with_file_name("limber")
        }
    };
    let mut probe = Command::new(&exe);
    probe.args(["bridge", "--help"]);
    let out = run_bounded(probe, Duration::from_secs(30))
        .map_err(|why| format!("no limber executable with `bridge` ({why})"))?;
    if !out.status.success() {
        return Err(format!(
            "{} cannot run `limber bridge` ({}; built without its `bridge` feature?)",
            exe.display(),
            out.status
        ));
    }
    Ok(exe)
}

/// `limber --domain <domain> bridge <args>`, started as a child that must print `line`.
fn start_bridge(
    exe: &Path,
    role: &str,
    domain: &Domain,
    args: &[&str],
    line: &str,
    deadline: Duration,
) -> Result<ChildProc, BenchError> {
    let mut cmd = Command::new(exe);
    cmd.arg("--domain")
        .arg(domain.name())
        .arg("bridge")
        .args(args)
        .env_remove("LIMBER_DOMAIN");
    if let Some(path) = zenoh_floor::zenoh_config() {
        cmd.arg("--zenoh-config").arg(path);
    }
    let mut child = ChildProc::spawn_program(role, cmd, deadline)?;
    child.expect(line, READY_TIMEOUT)?;
    Ok(child)
}

/// The round trips of one run: the floor's put and get, the client direct and through the
/// bridge pair.
struct RoundTrips {
    put: Histogram<u64>,
    get: Histogram<u64>,
    direct: Histogram<u64>,
    bridge: Histogram<u64>,
}

fn run(ctx: &mut RunCtx, exe: &Path) -> Result<(), BenchError> {
    let (warm, n) = (ctx.count(300, 50), ctx.count(3_000, 300));
    // The floor: raw Zenoh over the same kind of link, same payloads; its echo lives through
    // the run (its ping-pong alternates with the bridge's commands). Through the bridge an
    // exchange takes ~1 ms or less; four series of `warm + n`.
    let deadline = ctx.deadline_for(4 * (warm + n), Duration::from_millis(1));
    if let Some(path) = zenoh_floor::zenoh_config() {
        ctx.notes.push(format!(
            "the bridges and the raw Zenoh floor started from the Zenoh configuration {} ({})",
            path.display(),
            zenoh_floor::ZENOH_CONFIG_ENV
        ));
    }
    let floor = zenoh_floor::Floor::start(ctx, deadline)?;
    let r = with_floor(ctx, exe, &floor, (warm, n), deadline);
    let finished = floor.finish();
    let rt = r?;
    finished?;
    zenoh_floor::push(ctx, rt.put, rt.get);
    push(
        ctx,
        "bridge.direct.rtt",
        "command→outcome, client in the driver's domain",
        rt.direct,
    );
    push(
        ctx,
        "bridge.zenoh.rtt",
        "command→outcome through bridge expose+mirror (Zenoh, Unix socket)",
        rt.bridge,
    );
    Ok(())
}

/// The scenario with its floor's echo up: the floor's get exchanges, the driver and the
/// direct client, the bridge pair idle, then the floor's ping-pong and the command through
/// the pair in alternating blocks ([`interleaved`]).
fn with_floor(
    ctx: &mut RunCtx,
    exe: &Path,
    floor: &zenoh_floor::Floor,
    (warm, n): (u64, u64),
    deadline: Duration,
) -> Result<RoundTrips, BenchError> {
    let (a, b) = (ctx.domain(), ctx.domain());
    let get = floor.get_round_trips(ctx, warm, n)?;
    let driver = start_event_driver(ctx, &a, "bridge-driver.hdr", deadline)?;
    let cctx_a = Context::new(&a, Role::Client, "bench-bridge")
        .map_err(|e| err("client context in A", e))?;
    let mut direct = ActArrayClient::connect_timeout(&cctx_a, DEVICE, READY_TIMEOUT)
        .map_err(|e| err("connect in A", e))?;
    let r = (|| {
        // The default listener, A's private Unix socket (a TCP listener needs credentials).
        let expose = start_bridge(
            exe,
            "bridge expose",
            &a,
            &["expose"],
            &format!("exposed {DEVICE}"),
            deadline,
        )?;
        let mirror = start_bridge(
            exe,
            "bridge mirror",
            &b,
            &["mirror", "--from", a.name()],
            &format!("mirrored {DEVICE} as {DEVICE}"),
            deadline,
        )?;
        idle_cost(ctx, &driver, &expose, &mirror)?;
        let rtt_direct = round_trips(ctx, &mut direct, "bridge direct", warm, n)?;
        let cctx_b = Context::new(&b, Role::Client, "bench-bridge")
            .map_err(|e| err("client context in B", e))?;
        let mut remote = ActArrayClient::connect_timeout(&cctx_b, DEVICE, READY_TIMEOUT)
            .map_err(|e| err("connect in B", e))?;
        remote
            .current(READY_TIMEOUT)
            .map_err(|e| err("first state", e))?;
        let mut pinger = floor.pinger()?;
        // What the pair costs while it carries them, beside the latency: over the bridge's
        // blocks only.
        let mut busy = cpu::Stretches::new(&[
            ("bridge expose", expose.pid()),
            ("bridge mirror", mirror.pid()),
            ("driver", driver.pid()),
        ]);
        let (put, bridge) = interleaved(ctx, &mut pinger, &mut remote, (warm, n), &mut busy)?;
        for (process, percent) in busy.shares() {
            ctx.push_cpu(CpuCost {
                id: format!("bridge.busy.{}", process.replace(' ', "_")),
                scenario: "bridge",
                mode: "bridge pair".into(),
                load: "commands back to back".into(),
                process,
                percent,
                window_s: busy.wall().as_secs_f64(),
                latency_id: Some("bridge.zenoh.rtt".into()),
                at_most_percent: None,
            });
        }
        drop(remote);
        mirror.terminate(Duration::from_secs(10))?;
        expose.terminate(Duration::from_secs(10))?;
        Ok((rtt_direct, put, bridge))
    })();
    // HOME all joints stops the driver child (if it cannot be sent, its deadline does).
    if let Err(e) = direct.home(None) {
        tracing::warn!("cannot tell the driver child to stop: {e}");
    }
    driver.finish(Duration::from_secs(10))?;
    let (direct, put, bridge) = r?;
    Ok(RoundTrips {
        put,
        get,
        direct,
        bridge,
    })
}

/// How many blocks of each path a run of `n` exchanges makes (fewer when blocks would be
/// shorter than [`MIN_BLOCK`]).
const BLOCKS: u64 = 15;

/// The fewest exchanges in a block.
const MIN_BLOCK: u64 = 20;

/// The floor's put ping-pong (`pinger`) and the command through the bridge pair
/// (`remote`), `warm` + `n` of each, alternating: `warm` pairs first, unrecorded, then
/// blocks of about `n / 15` of one path and then of the other, so that a change of the
/// machine's pace (a VM's vCPU placement changes its wake-ups by 2x for seconds) falls on
/// both and their ratio is of the same moments. Each block begins with one exchange not
/// recorded (the first after the other path's block finds its threads asleep). `busy`
/// measures the bridge's blocks. Returns (floor, bridge).
fn interleaved(
    ctx: &RunCtx,
    pinger: &mut zenoh_floor::Pinger,
    remote: &mut ActArrayClient,
    (warm, n): (u64, u64),
    busy: &mut cpu::Stretches,
) -> Result<(Histogram<u64>, Histogram<u64>), BenchError> {
    const WHAT: &str = "bridge zenoh";
    let mut i = 0u64;
    let mut command = |remote: &mut ActArrayClient| {
        i += 1;
        timed_command(remote, i, WHAT)
    };
    let progress = Progress::new(ctx.progress, "bridge + zenoh floor", warm + n);
    for k in 1..=warm {
        pinger.round_trip()?;
        command(remote)?;
        progress.tick(k);
    }
    let (mut floor, mut bridge) = (new_histogram()?, new_histogram()?);
    let block = (n / BLOCKS).max(MIN_BLOCK);
    let mut done = 0;
    while done < n {
        let len = block.min(n - done);
        pinger.round_trip()?;
        for _ in 0..len {
            floor.saturating_record(pinger.round_trip()?);
        }
        busy.measure(|| -> Result<(), BenchError> {
            command(remote)?;
            for _ in 0..len {
                bridge.saturating_record(command(remote)?);
            }
            Ok(())
        })
        .map_err(|e| err("cpu time", e))??;
        done += len;
        progress.tick(warm + done);
    }
    progress.finish();
    Ok((floor, bridge))
}

/// The most an idle bridge of the pair may cost, percent of a core.
pub const IDLE_BRIDGE_GOAL: f64 = 1.0;

/// The CPU time of the idle pair (both bridges up, the device mirrored, nothing sent) and
/// of the driver beside them, per second of wall time.
fn idle_cost(
    ctx: &mut RunCtx,
    driver: &ChildProc,
    expose: &ChildProc,
    mirror: &ChildProc,
) -> Result<(), BenchError> {
    let window = ctx.window(Duration::from_secs(5), Duration::from_secs(1));
    ctx.say(format_args!("  bridge idle: CPU over {window:?}"));
    let shares = cpu::idle(
        &[
            ("bridge expose", expose.pid()),
            ("bridge mirror", mirror.pid()),
            ("driver", driver.pid()),
        ],
        window,
    )
    .map_err(|e| err("cpu time", e))?;
    for (process, percent) in shares {
        let goal = process.starts_with("bridge").then_some(IDLE_BRIDGE_GOAL);
        ctx.push_cpu(CpuCost {
            id: format!("bridge.idle.{}", process.replace(' ', "_")),
            scenario: "bridge",
            mode: "bridge pair".into(),
            load: "idle".into(),
            process,
            percent,
            window_s: window.as_secs_f64(),
            latency_id: None,
            at_most_percent: goal,
        });
    }
    Ok(())
}

fn push(ctx: &mut RunCtx, id: &str, label: &str, hist: Histogram<u64>) {
    ctx.push(Measurement {
        scenario: "bridge",
        id: id.to_string(),
        label: label.to_string(),
        strategy: Strategy::Blocking,
        metric: Metric::RoundTrip,
        bytes: Some(BYTES),
        hist,
    });
}

/// `warm` + `n` command round trips of `client` with its defaults; the last `n` recorded.
fn round_trips(
    ctx: &RunCtx,
    client: &mut ActArrayClient,
    what: &str,
    warm: u64,
    n: u64,
) -> Result<Histogram<u64>, BenchError> {
    client
        .current(READY_TIMEOUT)
        .map_err(|e| err("first state", e))?;
    let mut rtt = new_histogram()?;
    let progress = Progress::new(ctx.progress, what, warm + n);
    for i in 1..=warm + n {
        let took = timed_command(client, i, what)?;
        if i > warm {
            rtt.saturating_record(took);
        }
        progress.tick(i);
    }
    progress.finish();
    Ok(rtt)
}
