//! The children of `many`: the real drivers, each robot a process of its own, and the
//! floor of their loops.
//!
//! * `many-simarm`: simarm (`limber_simarm::SimArm`, the built-in 6-joint arm, its 10 ms
//!   tick) serving the robot of `--device`;
//! * `many-pioneer`: the Pioneer emulator on a pty at its own 100 ms cycle (as `limber
//!   pioneer --emulated` starts it) and the Pioneer driver on it (its 10 ms tick), serving
//!   the robot of `--device`;
//! * `many-ticker`: the floor of a driver's loop: limber's event loop
//!   (`limber_services::event_loop::run`, an iceoryx2 WaitSet on a 10 ms timerfd, as both
//!   drivers wait) with no device at all.
//!
//! Each prints `ready`, runs until `quit` on stdin (or its deadline), then writes the
//! periods between its loop's timer cycles (the latest 512, `limber_services::loop_stats`,
//! as each driver keeps them) to `--out` as a histogram. Neither driver runs the simulated
//! world and laser that `limber simarm` and `limber pioneer --emulated` add.

use std::ops::ControlFlow;
use std::sync::mpsc::{Receiver, TryRecvError};
use std::time::{Duration, Instant};

use limber_emulator::EmulatorConfig;
use limber_pioneer::{LoopMode, PioneerConfig, RunOptions};
use limber_services::loop_stats::{Ring, TickStats};
use limber_services::{Context, Role, event_loop};

use crate::stats::new_histogram;
use crate::{BenchArgs, BenchError, roles};

/// The role of a simarm child.
pub const SIMARM_ROLE: &str = "many-simarm";
/// The role of an emulated Pioneer child.
pub const PIONEER_ROLE: &str = "many-pioneer";
/// The role of the loop floor's child.
pub const TICKER_ROLE: &str = "many-ticker";

/// The drivers' tick (simarm's default, the Pioneer driver's `tick_ms`), and the floor's.
pub const TICK: Duration = Duration::from_millis(10);

fn err(what: &str, reason: impl std::fmt::Display) -> BenchError {
    BenchError::Transport {
        context: what.to_string(),
        reason: reason.to_string(),
    }
}

/// The robot of `--device` (`bench3/actarray/0` → `bench3`).
fn robot(args: &BenchArgs) -> Result<String, BenchError> {
    let device = args
        .device
        .as_deref()
        .ok_or_else(|| BenchError::Args("--device is required for this role".into()))?;
    let name: limber_services::DeviceName = device
        .parse()
        .map_err(|e| BenchError::Args(format!("--device {device}: {e}")))?;
    Ok(name.robot().to_string())
}

/// A stop condition for a driver's loop: `quit` on stdin, stdin closed, or the deadline.
fn quit_or(lines: &Receiver<String>, deadline: Instant) -> bool {
    match lines.try_recv() {
        Ok(l) if l.trim() == "quit" => true,
        Err(TryRecvError::Disconnected) => true,
        _ => Instant::now() > deadline,
    }
}

/// Writes a ring of periods where the parent reads the child's histogram.
fn write_periods(args: &BenchArgs, periods: &Ring) -> Result<(), BenchError> {
    let mut h = new_histogram()?;
    for ns in periods.samples() {
        h.saturating_record(*ns);
    }
    roles::write_histogram(args, &h)
}

/// `many-simarm`.
pub fn simarm_role(args: &BenchArgs) -> Result<(), BenchError> {
    let domain = roles::child_domain(args)?;
    let deadline = roles::child_deadline(args);
    let options = limber_simarm::SimArmOptions {
        robot: robot(args)?,
        tick: TICK,
        ..Default::default()
    };
    let ctx = Context::new(&domain, Role::Driver, "bench-simarm")
        .map_err(|e| err("simarm context", e))?;
    let chain = limber_kinematics::chain::Chain::default_6dof();
    let mut arm = limber_simarm::SimArm::new(&ctx, chain, options).map_err(|e| err("simarm", e))?;
    let lines = roles::stdin_lines();
    roles::announce("ready");
    arm.run(|| quit_or(&lines, deadline))
        .map_err(|e| err("simarm's loop", e))?;
    write_periods(args, &arm.tick_stats().period)
}

/// `many-pioneer`.
pub fn pioneer_role(args: &BenchArgs) -> Result<(), BenchError> {
    let domain = roles::child_domain(args)?;
    let deadline = roles::child_deadline(args);
    let config = PioneerConfig {
        robot: robot(args)?,
        tick_ms: TICK.as_millis() as u64,
        ..PioneerConfig::default()
    };
    let ctx = Context::new(&domain, Role::Driver, "bench-pioneer")
        .map_err(|e| err("driver context", e))?;
    let (emu, mut driver) =
        roles::start_emulated_pioneer(args, &ctx, EmulatorConfig::default(), config)?;
    let lines = roles::stdin_lines();
    roles::announce("ready");
    let ran = driver.run_until(
        RunOptions {
            mode: LoopMode::Event,
        },
        || quit_or(&lines, deadline),
    );
    let periods = driver.loop_stats().ticks.period.clone();
    let report = driver.shutdown();
    tracing::debug!("many: pioneer driver: {report}");
    drop(driver);
    if let Err(e) = emu.stop() {
        tracing::warn!("stopping the emulator: {e}");
    }
    ran.map_err(|e| err("pioneer driver loop", e))?;
    write_periods(args, &periods)
}

/// `many-ticker`: limber's event loop on a [`TICK`] timer, no device.
pub fn ticker_role(args: &BenchArgs) -> Result<(), BenchError> {
    let deadline = roles::child_deadline(args);
    let nominal = TICK.as_nanos() as u64;
    let lines = roles::stdin_lines();
    let mut ticks = TickStats::default();
    roles::announce("ready");
    event_loop::run(&[], TICK, None, |wake| {
        if let event_loop::Wake::Tick(expirations) = wake {
            ticks.tick(Instant::now(), nominal, expirations);
        }
        if quit_or(&lines, deadline) {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    })
    .map_err(|e| err("the ticker's loop", e))?;
    write_periods(args, &ticks.period)
}
