//! `cpu`: what each way of waiting costs, beside the latency it buys. For each mode of the
//! `command` scenario's driver child and client — event-driven (both block: no linger,
//! no client spin), linger (the defaults: the driver polls `qos::DRIVER_LINGER` after
//! activity, the client `qos::default_spin_budget()` after a send) and spin (both
//! busy-poll; only with 2 cores or more) — the CPU time of the driver and of the client
//! (this process) per second of wall time: idle (connected, nothing sent) and at 1 kHz of
//! commands (`move_to` then `wait_outcome`, one per millisecond from a sleeping client,
//! whose round trips are `cpu.<mode>.rtt`). Goal: an idle event-driven driver under 1 % of
//! a core.

use std::time::{Duration, Instant};

use limber_services::Role;
use limber_services::prelude::*;

use super::command::DEVICE;
use super::floor::BYTES;
use super::{Pace, READY_TIMEOUT, RunCtx, Scenario, timed_command};
use crate::BenchError;
use crate::child::{ChildProc, ChildSpec};
use crate::cpu::{self, CpuCost, Window};
use crate::stats::{Measurement, Metric, Strategy, new_histogram};

/// The rate of commands under load.
pub const PERIOD: Duration = Duration::from_millis(1);
/// The most an idle event-driven driver may cost, percent of a core.
pub const IDLE_DRIVER_GOAL: f64 = 1.0;

/// The `cpu` scenario.
#[derive(Debug, Clone, Copy)]
pub struct Cpu;

impl Scenario for Cpu {
    fn name(&self) -> &'static str {
        "cpu"
    }
    fn description(&self) -> &'static str {
        "CPU time of the driver and the client per second, idle and at 1 kHz of commands, event-driven, linger and spin, beside the round trip"
    }
    fn run(&self, ctx: &mut RunCtx) -> Result<(), BenchError> {
        if ctx.blocking_enabled() {
            mode(ctx, Mode::EventDriven)?;
            mode(ctx, Mode::Linger)?;
        }
        if ctx.spin_enabled() {
            mode(ctx, Mode::Spin)?;
        }
        Ok(())
    }
}

/// How the driver and the client wait.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    /// Both block; no linger, no client spin.
    EventDriven,
    /// The defaults: the driver lingers, the client spins a little after a send.
    Linger,
    /// Both busy-poll.
    Spin,
}

impl Mode {
    fn key(self) -> &'static str {
        match self {
            Mode::EventDriven => "event",
            Mode::Linger => "linger",
            Mode::Spin => "spin",
        }
    }
    fn name(self) -> &'static str {
        match self {
            Mode::EventDriven => "event-driven",
            Mode::Linger => "linger",
            Mode::Spin => "spin",
        }
    }
}

fn err(what: &str, reason: impl std::fmt::Display) -> BenchError {
    BenchError::Transport {
        context: what.to_string(),
        reason: reason.to_string(),
    }
}

fn cpu_err(e: cpu::CpuError) -> BenchError {
    err("cpu time", e)
}

fn mode(ctx: &mut RunCtx, mode: Mode) -> Result<(), BenchError> {
    let domain = ctx.domain();
    let window = ctx.window(Duration::from_secs(3), Duration::from_millis(500));
    let spin = mode == Mode::Spin;
    let linger = match mode {
        Mode::EventDriven => Duration::ZERO,
        Mode::Linger => limber_services::qos::DRIVER_LINGER,
        Mode::Spin => Duration::ZERO,
    };
    let child = ChildProc::spawn(&ChildSpec {
        role: format!("cmd-driver-{}", if spin { "spin" } else { "event" }),
        domain: Some(domain.name().to_string()),
        out: Some(ctx.tmp_file(&format!("cpu-{}.hdr", mode.key()))),
        cpu: ctx.child_cpu(),
        deadline: Duration::from_secs(60) + window * 4,
        linger: (!spin).then_some(linger),
        ..Default::default()
    });
    let mut child = child?;
    child.expect("ready", READY_TIMEOUT)?;
    let cctx = Context::new(&domain, Role::Client, "bench-cpu").map_err(|e| err("context", e))?;
    let mut client = ActArrayClient::connect_timeout(&cctx, DEVICE, READY_TIMEOUT)
        .map_err(|e| err("connect", e))?;
    match mode {
        Mode::EventDriven => client.set_spin_budget(Duration::ZERO),
        Mode::Linger => {}
        Mode::Spin => {
            client.set_wait_mode(WaitMode::Spin);
            client.set_wake_driver(false);
        }
    }
    let r = measure(ctx, &mut client, &child, mode, window);
    // HOME all joints stops the driver child (if it cannot be sent, its deadline does).
    if let Err(e) = client.home(None) {
        tracing::warn!("cannot tell the driver child to stop: {e}");
    }
    child.finish(Duration::from_secs(10))?;
    r
}

fn measure(
    ctx: &mut RunCtx,
    client: &mut ActArrayClient,
    child: &ChildProc,
    mode: Mode,
    window: Duration,
) -> Result<(), BenchError> {
    client
        .current(READY_TIMEOUT)
        .map_err(|e| err("first state", e))?;
    let procs = [("driver", child.pid()), ("client", std::process::id())];
    ctx.say(format_args!(
        "  cpu {}: idle, then 1 kHz, {window:?} each",
        mode.name()
    ));
    let idle = cpu::idle(&procs, window).map_err(cpu_err)?;
    let pace = Pace::Paced {
        period: PERIOD,
        scenario: "cpu",
        beside: None,
        turns: 1,
    };
    let mut rtt = new_histogram()?;
    let w = Window::start(&procs).map_err(cpu_err)?;
    let start = Instant::now();
    let mut i = 0u64;
    while start.elapsed() < window {
        i += 1;
        pace.wait_turn(start, i);
        rtt.saturating_record(timed_command(client, i, "cpu")?);
    }
    let loaded = w.end().map_err(cpu_err)?;
    let rtt_id = format!("cpu.{}.rtt", mode.key());
    ctx.push(Measurement {
        scenario: "cpu",
        id: rtt_id.clone(),
        label: format!("command→outcome at 1 kHz, {}", mode.name()),
        strategy: if mode == Mode::Spin {
            Strategy::Spin
        } else {
            Strategy::Blocking
        },
        metric: Metric::RoundTrip,
        bytes: Some(BYTES),
        hist: rtt,
    });
    for (load, shares, latency) in [
        ("idle", idle, None),
        ("1 kHz commands", loaded, Some(rtt_id)),
    ] {
        for (process, percent) in shares {
            let goal = (mode == Mode::EventDriven && load == "idle" && process == "driver")
                .then_some(IDLE_DRIVER_GOAL);
            ctx.push_cpu(CpuCost {
                id: format!(
                    "cpu.{}.{}.{process}",
                    mode.key(),
                    if latency.is_some() { "1khz" } else { "idle" }
                ),
                scenario: "cpu",
                mode: mode.name().into(),
                load: load.into(),
                process,
                percent,
                window_s: window.as_secs_f64(),
                latency_id: latency.clone(),
                at_most_percent: goal,
            });
        }
    }
    Ok(())
}
