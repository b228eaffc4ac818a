//! `traj`: the joint trajectory executor (`limber_trajectory`) in a driver.
//!
//! * `traj.tick`: the time of one `Executor::tick` (6 joints, 64 quintic points), in this
//!   process: the cost a driver's loop pays per cycle while a trajectory runs.
//! * `traj.period` and `traj.jitter`: simarm (on a thread of this process, its 10 ms tick)
//!   runs a trajectory; a client takes every state it publishes while the trajectory moves
//!   the arm, and records the time between successive states' `header.stamp_ns` (taken
//!   by the driver when it ticked the trajectory and published): the period of the
//!   driver's trajectory tick, and its deviation from the nominal 10 ms (the jitter).

use std::hint::black_box;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use limber_interfaces::actarray::JointTrajectory;
use limber_services::prelude::*;
use limber_services::{Role, monotonic_ns};
use limber_trajectory::{Config, Executor, JointLimit, Tick};

use super::{READY_TIMEOUT, RunCtx, SAMPLE_TIMEOUT, Scenario};
use crate::BenchError;
use crate::stats::{Measurement, Metric, Strategy, new_histogram};

/// The nominal tick of simarm, the driver measured.
const NOMINAL: Duration = Duration::from_millis(10);

/// The `traj` scenario.
#[derive(Debug, Clone, Copy)]
pub struct Traj;

impl Scenario for Traj {
    fn name(&self) -> &'static str {
        "traj"
    }
    fn description(&self) -> &'static str {
        "joint trajectory executor: one tick's time (6 joints, 64 quintic points); the driver's trajectory tick period and jitter (simarm, 10 ms)"
    }
    fn run(&self, ctx: &mut RunCtx) -> Result<(), BenchError> {
        tick_time(ctx)?;
        driver_period(ctx)
    }
}

/// 6 joints, 64 points over 6.4 s, quintic.
fn trajectory(from: &[f64]) -> Result<Box<JointTrajectory>, BenchError> {
    let bad = |e| BenchError::transport("building the trajectory", e);
    let mut t = JointTrajectory::new(&[0, 1, 2, 3, 4, 5]).map_err(bad)?;
    for i in 1..=64 {
        let f = i as f64 / 64.0;
        let p: Vec<f64> = from.iter().map(|x| x + 0.3 * f).collect();
        let v = if i == 64 { 0.0 } else { 0.03 };
        t.push(0.1 * i as f64, &p, Some(&[v; 6]), Some(&[0.0; 6]))
            .map_err(bad)?;
    }
    Ok(t)
}

fn tick_time(ctx: &mut RunCtx) -> Result<(), BenchError> {
    let n = ctx.count(100_000, 5_000);
    let mut config = Config::new(6);
    for l in config.limits.iter_mut().take(6) {
        *l = JointLimit {
            min: -10.0,
            max: 10.0,
            ..JointLimit::default()
        };
    }
    let mut x = Executor::new(config);
    let t = trajectory(&[0.0; 6])?;
    let mut h = new_histogram()?;
    let mut now = 0u64;
    let actual = [0.0; 6];
    x.accept(&t, now, &actual)
        .map_err(|e| BenchError::transport("accepting the trajectory", e))?;
    for _ in 0..n {
        // 1 ms of trajectory per tick: a fresh one when it ends.
        now += 1_000_000;
        let t0 = monotonic_ns();
        let tick = black_box(x.tick(black_box(now), black_box(&actual)));
        h.saturating_record(monotonic_ns().saturating_sub(t0));
        if let Tick::Ended(_) = tick {
            x.accept(&t, now, &actual)
                .map_err(|e| BenchError::transport("accepting the trajectory", e))?;
        }
    }
    ctx.push(Measurement {
        scenario: "traj",
        id: "traj.tick".to_string(),
        label: "trajectory executor tick (6 joints, quintic)".to_string(),
        strategy: Strategy::Compute,
        metric: Metric::Solve,
        bytes: None,
        hist: h,
    });
    Ok(())
}

fn driver_period(ctx: &mut RunCtx) -> Result<(), BenchError> {
    let samples = ctx.count(2_000, 100);
    let domain = ctx.domain();
    let stop = Arc::new(AtomicBool::new(false));
    let (tx, rx) = std::sync::mpsc::channel();
    let (d, flag) = (domain.clone(), stop.clone());
    let sim = std::thread::spawn(move || -> Result<(), String> {
        let c = Context::new(&d, Role::Driver, "simarm").map_err(|e| e.to_string())?;
        let chain = limber_kinematics::chain::Chain::default_6dof();
        let options = limber_simarm::SimArmOptions::default();
        let arm = limber_simarm::SimArm::new(&c, chain, options).map_err(|e| e.to_string());
        let ready = arm.is_ok();
        if tx.send(ready).is_err() {
            tracing::warn!("traj: the scenario stopped waiting for simarm to start");
        }
        arm?.run(|| flag.load(Ordering::Relaxed))
            .map(|_| ())
            .map_err(|e| e.to_string())
    });
    let result = measure_period(ctx, &domain, samples, &rx);
    stop.store(true, Ordering::Relaxed);
    let ended = sim.join();
    result?;
    match ended {
        Ok(Ok(())) => Ok(()),
        Ok(Err(e)) => Err(BenchError::transport("simarm", e)),
        Err(_) => Err(BenchError::transport("simarm", "its thread panicked")),
    }
}

fn measure_period(
    ctx: &mut RunCtx,
    domain: &limber_services::Domain,
    samples: u64,
    ready: &std::sync::mpsc::Receiver<bool>,
) -> Result<(), BenchError> {
    match ready.recv_timeout(READY_TIMEOUT) {
        Ok(true) => {}
        _ => return Err(BenchError::transport("simarm", "did not start")),
    }
    let c = Context::new(domain, Role::Client, "bench-traj")
        .map_err(|e| BenchError::transport("client context", e))?;
    let mut a = ActArrayClient::connect_timeout(&c, "simarm/actarray/0", READY_TIMEOUT)
        .map_err(|e| BenchError::transport("connecting to simarm", e))?;
    let (mut period, mut jitter) = (new_histogram()?, new_histogram()?);
    let mut last: Option<u64> = None;
    while period.len() < samples {
        // One trajectory after another (each from where the last ended) until there are
        // enough periods.
        let s = *a
            .wait_state(SAMPLE_TIMEOUT)
            .map_err(|e| BenchError::transport("simarm's state", e))?;
        let from: Vec<f64> = s.actuators[..6].iter().map(|x| x.position).collect();
        let t = trajectory(&from)?;
        let ticket = a
            .follow_trajectory(&t)
            .map_err(|e| BenchError::transport("sending the trajectory", e))?;
        loop {
            let s = *a
                .wait_state(SAMPLE_TIMEOUT)
                .map_err(|e| BenchError::transport("simarm's state", e))?;
            if let Some(l) = last {
                let p = s.header.stamp_ns.saturating_sub(l);
                period.saturating_record(p);
                jitter.saturating_record((p as i64 - NOMINAL.as_nanos() as i64).unsigned_abs());
            }
            last = Some(s.header.stamp_ns);
            if period.len() >= samples
                || a.done(ticket)
                    .map_err(|e| BenchError::transport("the result", e))?
                    .is_some()
            {
                break;
            }
        }
        last = None;
    }
    for (id, label, hist) in [
        (
            "traj.period",
            "driver trajectory tick period (simarm, 10 ms)",
            period,
        ),
        (
            "traj.jitter",
            "driver trajectory tick |period - 10 ms|",
            jitter,
        ),
    ] {
        ctx.push(Measurement {
            scenario: "traj",
            id: id.to_string(),
            label: label.to_string(),
            strategy: Strategy::Blocking,
            metric: Metric::Period,
            bytes: None,
            hist,
        });
    }
    Ok(())
}
