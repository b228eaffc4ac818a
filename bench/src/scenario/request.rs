//! `request`: the GET_GEOM request round trip (`ActArrayClient::geometry`) against the
//! Pioneer driver (`limber_pioneer::PioneerDriver`, event-driven loop) talking
//! P2OS over a pty to the built-in emulator, both in one child process. The driver
//! answers requests from its own state: the round trip is client → driver → client,
//! and the serial link only adds load to the driver's loop (SIPs every 100 ms).

use std::time::{Duration, Instant};

use limber_emulator::EmulatorConfig;
use limber_interfaces::prelude::*;
use limber_pioneer::{LoopMode, PioneerConfig, RunOptions};
use limber_services::prelude::*;
use limber_services::{Role, monotonic_ns};

use super::{RunCtx, Scenario};
use crate::child::{ChildProc, ChildSpec};
use crate::progress::Progress;
use crate::roles;
use crate::stats::{Measurement, Metric, Strategy, new_histogram};
use crate::{BenchArgs, BenchError};

/// The arm of the Pioneer driver.
pub const DEVICE: &str = "pioneer/actarray/0";
/// How long the driver may take to start (emulator handshake, arm calibration).
pub const START_TIMEOUT: Duration = Duration::from_secs(30);

/// The `request` scenario.
#[derive(Debug, Clone, Copy)]
pub struct Request;

/// The event-driven Pioneer driver child on its emulator (fast mode) in `domain`, ready, its
/// deadline long enough for `exchanges` of `each` (the `request` and `gateway` scenarios).
pub(super) fn start_pioneer_driver(
    ctx: &RunCtx,
    domain: &Domain,
    exchanges: u64,
    each: Duration,
) -> Result<ChildProc, BenchError> {
    let mut child = ChildProc::spawn(&ChildSpec {
        role: "pioneer-driver".into(),
        domain: Some(domain.name().to_string()),
        cpu: ctx.child_cpu(),
        emulator_cpu: ctx.client_cpu(),
        deadline: ctx.deadline_for(exchanges, each),
        ..Default::default()
    })?;
    child.expect("ready", START_TIMEOUT)?;
    Ok(child)
}

fn err(what: &str, reason: String) -> BenchError {
    BenchError::Transport {
        context: what.to_string(),
        reason,
    }
}

impl Scenario for Request {
    fn name(&self) -> &'static str {
        "request"
    }
    fn description(&self) -> &'static str {
        "GET_GEOM request round trip against the Pioneer driver on the emulator (pty, fast mode), event-driven"
    }
    fn run(&self, ctx: &mut RunCtx) -> Result<(), BenchError> {
        if !ctx.blocking_enabled() {
            ctx.notes.push(
                "request runs the event-driven driver only; skipped by --strategy spin".into(),
            );
            return Ok(());
        }
        let domain = ctx.domain();
        let (warm, n) = (ctx.count(200, 50), ctx.count(3_000, 500));
        let mut child = start_pioneer_driver(ctx, &domain, warm + n, Duration::from_micros(500))?;
        let cctx = Context::new(&domain, Role::Client, "bench-request")
            .map_err(|e| err("client context", e.to_string()))?;
        let mut arm = ActArrayClient::connect_timeout(&cctx, DEVICE, START_TIMEOUT)
            .map_err(|e| err("connect", e.to_string()))?;
        arm.set_request_timeout(super::SAMPLE_TIMEOUT);
        let mut rtt = new_histogram()?;
        let progress = Progress::new(ctx.progress, "request GET_GEOM", warm + n);
        for i in 1..=warm + n {
            let t0 = monotonic_ns();
            let g = arm.geometry().map_err(|e| err("GET_GEOM", e.to_string()))?;
            let t1 = monotonic_ns();
            if g.actuators_count == 0 {
                return Err(err("GET_GEOM", "no actuators in the reply".into()));
            }
            if i > warm {
                rtt.saturating_record(t1.saturating_sub(t0));
            }
            progress.tick(i);
        }
        progress.finish();
        drop(arm);
        if let Err(e) = child.send_line("quit") {
            tracing::warn!("cannot tell the client child to quit: {e}");
        }
        child.finish(Duration::from_secs(10))?;
        ctx.push(Measurement {
            scenario: "request",
            id: "request.pioneer.rtt".into(),
            label: "GET_GEOM, Pioneer driver+emulator (fast mode)".into(),
            strategy: Strategy::Blocking,
            metric: Metric::RoundTrip,
            bytes: Some((
                core::mem::size_of::<ActArrayReqMsg>(),
                core::mem::size_of::<ActArrayReplyMsg>(),
            )),
            hist: rtt,
        });
        Ok(())
    }
}

/// The Pioneer driver child (`pioneer-driver`): the emulator on a pty and the driver on
/// it, until `quit` on stdin or the deadline.
pub fn driver_role(args: &BenchArgs, mode: LoopMode) -> Result<(), BenchError> {
    let domain = roles::child_domain(args)?;
    let deadline = roles::child_deadline(args);
    let ctx = Context::new(&domain, Role::Driver, "bench-pioneer")
        .map_err(|e| err("driver context", e.to_string()))?;
    // Fast mode: the emulator answers at once instead of at its 100 ms cycle boundary,
    // so the scenarios measure limber, not the controller's cycle (the labels say so).
    let (emu, mut driver) = roles::start_emulated_pioneer(
        args,
        &ctx,
        EmulatorConfig::fast(),
        PioneerConfig::default(),
    )?;
    let lines = roles::stdin_lines();
    roles::announce("ready");
    let r = driver.run_until(RunOptions { mode }, move || {
        use std::sync::mpsc::TryRecvError;
        match lines.try_recv() {
            Ok(l) if l.trim() == "quit" => true,
            Err(TryRecvError::Disconnected) => true,
            _ => Instant::now() > deadline,
        }
    });
    // The driver's own cost per command (arrival → bytes on the pty) and, inside it, the
    // link's send alone and the work before it, for `loop`.
    let written = match &args.out {
        Some(_) => {
            let stats = driver.loop_stats();
            let (mut own, mut send, mut work) =
                (new_histogram()?, new_histogram()?, new_histogram()?);
            for (ring, hist) in [
                (&stats.arrival_to_wire, &mut own),
                (&stats.link_write, &mut send),
                (&stats.arrival_to_send, &mut work),
            ] {
                for ns in ring.samples() {
                    hist.saturating_record(*ns);
                }
            }
            Some((own, send, work))
        }
        None => None,
    };
    drop(driver);
    if let Err(e) = emu.stop() {
        tracing::warn!("stopping the emulator: {e}");
    }
    r.map(|_| ())
        .map_err(|e| err("pioneer driver loop", e.to_string()))?;
    match (written, &args.out) {
        (Some((own, send, work)), Some(out)) => {
            roles::write_histogram_to(&link_write_path(out), &send)?;
            roles::write_histogram_to(&driver_work_path(out), &work)?;
            roles::write_histogram(args, &own)
        }
        _ => Ok(()),
    }
}

/// Where the Pioneer driver child writes the histogram of its link sends, beside `out`.
pub fn link_write_path(out: &std::path::Path) -> std::path::PathBuf {
    out.with_extension("send.hdr")
}

/// Where the Pioneer driver child writes the histogram of its own work before each send
/// (arrival → the send begins), beside `out`.
pub fn driver_work_path(out: &std::path::Path) -> std::path::PathBuf {
    out.with_extension("work.hdr")
}
