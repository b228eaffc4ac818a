//! `loop`: the full control loop through the emulator over a pty. A client moves joint 0
//! of the Pioneer arm (driver and emulator in the `pioneer-driver` child process,
//! event-driven); the command goes to the driver, out as P2OS bytes on the pty, the
//! emulator (in fast mode, `EmulatorConfig::fast`: a real controller would answer at its
//! next 100 ms cycle) acts on it and answers with an ARMpac at once, the driver reads it and
//! publishes the arm state, and the client sees it. Split by stage with the stamps on
//! the way:
//!
//! * `command → robot reply read by the driver`: the client's send stamp to the state's
//!   acquisition stamp (`StateHeader::stamp_ns` = when the driver read the ARMpac):
//!   client → driver, validation, the serial write, the emulator, the ARMpac back;
//! * `command arrival → bytes on the pty`: inside that, the driver's own cost, from taking
//!   the command off its channel to the P2OS bytes written (validation, encoding, the
//!   write), measured by the driver (`LoopStats::arrival_to_wire`; the last 512 commands);
//! * `reply read → client sees the state`: acquisition stamp to the client's receipt
//!   (driver publish, notify, client wake-up);
//! * the total, client send → client receipt.
//!
//! Run twice when both strategies are enabled: with the event-driven driver (ids
//! `loop.*`), and with the busy-polling driver (`limber pioneer --spin`; ids `loop.spin.*`,
//! labels ending `[driver spinning]`), whose `driver` stage is the driver's own cost when
//! it is awake. The client waits on events in both, so the emulator thread keeps a core.

use std::time::{Duration, Instant};

use limber_interfaces::prelude::*;
use limber_services::prelude::*;
use limber_services::{Role, monotonic_ns};

use super::request::{DEVICE, START_TIMEOUT};
use super::{RunCtx, Scenario};
use crate::BenchError;
use crate::child::{ChildProc, ChildSpec, read_histogram};
use crate::progress::Progress;
use crate::stats::{Measurement, Metric, Strategy, new_histogram};

/// The `loop` scenario.
#[derive(Debug, Clone, Copy)]
pub struct Loop;

fn err(what: &str, reason: String) -> BenchError {
    BenchError::Transport {
        context: what.to_string(),
        reason,
    }
}

impl Scenario for Loop {
    fn name(&self) -> &'static str {
        "loop"
    }
    fn description(&self) -> &'static str {
        "full loop through the emulator over a pty, fast mode (command → P2OS → emulator → ARMpac → state), split by stage"
    }
    fn run(&self, ctx: &mut RunCtx) -> Result<(), BenchError> {
        if ctx.blocking_enabled() {
            run_variant(ctx, Variant::Event)?;
        }
        if ctx.spin_enabled() {
            run_variant(ctx, Variant::DriverSpin)?;
        }
        Ok(())
    }
}

/// How the driver child waits; the client always waits on events (its spin budget
/// included), so the emulator thread keeps a core when the driver spins on the other.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Variant {
    /// The event-driven driver (the default).
    Event,
    /// The busy-polling driver (`limber pioneer --spin`).
    DriverSpin,
}

impl Variant {
    /// The child role, the id prefix, the label suffix and the driver stage's strategy.
    fn parts(self) -> (&'static str, &'static str, &'static str, Strategy) {
        match self {
            Variant::Event => ("pioneer-driver", "loop", "", Strategy::Blocking),
            Variant::DriverSpin => (
                "pioneer-driver-spin",
                "loop.spin",
                " [driver spinning]",
                Strategy::Spin,
            ),
        }
    }
}

/// One run of the loop with the driver child of `variant`.
fn run_variant(ctx: &mut RunCtx, variant: Variant) -> Result<(), BenchError> {
    let (role, prefix, suffix, driver_strategy) = variant.parts();
    let domain = ctx.domain();
    let (warm, n) = (ctx.count(50, 20), ctx.count(1_000, 200));
    let out = ctx.tmp_file(&format!("{prefix}-driver.hdr"));
    let mut child = ChildProc::spawn(&ChildSpec {
        role: role.into(),
        domain: Some(domain.name().to_string()),
        out: Some(out.clone()),
        cpu: ctx.child_cpu(),
        // Pinned, the emulator thread runs on the client's core, not on the driver's:
        // the client waits on events, the driver may spin (and a reader woken on the
        // writer's core preempts it as its write returns, before its clock read).
        emulator_cpu: ctx.client_cpu(),
        deadline: ctx.deadline_for(warm + n, Duration::from_millis(20)),
        ..Default::default()
    })?;
    child.expect("ready", START_TIMEOUT)?;
    let cctx = Context::new(&domain, Role::Client, "bench-loop")
        .map_err(|e| err("client context", e.to_string()))?;
    let mut arm = ActArrayClient::connect_timeout(&cctx, DEVICE, START_TIMEOUT)
        .map_err(|e| err("connect", e.to_string()))?;
    arm.set_request_timeout(super::SAMPLE_TIMEOUT);
    arm.power(true).map_err(|e| err("power", e.to_string()))?;
    let (mut to_robot, mut to_client, mut total) =
        (new_histogram()?, new_histogram()?, new_histogram()?);
    let progress = Progress::new(
        ctx.progress,
        &format!("loop through the emulator{suffix}"),
        warm + n,
    );
    for i in 1..=warm + n {
        let target = if i % 2 == 0 { 0.15 } else { -0.15 };
        let t0 = monotonic_ns();
        arm.move_to(0, target)
            .map_err(|e| err("command", e.to_string()))?;
        // The first state acquired after the command was sent: the emulator's prompt
        // ARMpac, read by the driver.
        let deadline = Instant::now() + super::SAMPLE_TIMEOUT;
        let (stamp, seen) = loop {
            let s = arm
                .wait_state(deadline.saturating_duration_since(Instant::now()))
                .map_err(|e| err("state", e.to_string()))?;
            let stamp = s.header.stamp_ns;
            if stamp > t0 {
                break (stamp, monotonic_ns());
            }
        };
        if i > warm {
            to_robot.saturating_record(stamp.saturating_sub(t0));
            to_client.saturating_record(seen.saturating_sub(stamp));
            total.saturating_record(seen.saturating_sub(t0));
        }
        progress.tick(i);
    }
    progress.finish();
    drop(arm);
    if let Err(e) = child.send_line("quit") {
        tracing::warn!("cannot tell the client child to quit: {e}");
    }
    child.finish(Duration::from_secs(10))?;
    let driver = read_histogram(&out)?;
    let bytes = Some((
        core::mem::size_of::<ActArrayCmdMsg>(),
        core::mem::size_of::<ActArrayData>(),
    ));
    for (stage, label, strategy, metric, hist) in [
        (
            "to_robot",
            "command → robot reply read by the driver (emulator fast mode)",
            Strategy::Blocking,
            Metric::OneWay,
            to_robot,
        ),
        (
            "driver",
            "command arrival → bytes on the pty (the driver's own cost)",
            driver_strategy,
            Metric::OneWay,
            driver,
        ),
        (
            "to_client",
            "reply read → client sees the state",
            Strategy::Blocking,
            Metric::OneWay,
            to_client,
        ),
        (
            "total",
            "command → state, through the emulator (fast mode)",
            Strategy::Blocking,
            Metric::RoundTrip,
            total,
        ),
    ] {
        let label = format!("{label}{suffix}");
        ctx.push(Measurement {
            scenario: "loop",
            id: format!("{prefix}.{stage}"),
            label,
            strategy,
            metric,
            bytes,
            hist,
        });
    }
    Ok(())
}
