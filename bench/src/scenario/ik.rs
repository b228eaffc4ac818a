//! `ik`: inverse kinematics solve times, in this process (pinned with `--pin`).
//!
//! The same solvers and deterministic targets as
//! `the kinematics tests (FK of random configurations
//! inside the limits, so every target is reachable), but every solve is recorded into a
//! histogram: Pioneer closed form (SETPOSE full pose; SETPOSITION keeping the current
//! approach) and the numeric IK of the generic 6- and 7-joint chains.

use std::hint::black_box;

use limber_kinematics::Pose;
use limber_kinematics::chain::{Chain, DeterministicRng, IkTarget, NumericIkOptions};
use limber_kinematics::pioneer::{ApproachPreference, PioneerGeometry, PioneerIkOptions, Theta};
use limber_services::monotonic_ns;

use super::{RunCtx, Scenario};
use crate::BenchError;
use crate::progress::Progress;
use crate::stats::{Measurement, Metric, Strategy, new_histogram};

/// The `ik` scenario.
#[derive(Debug, Clone, Copy)]
pub struct Ik;

impl Scenario for Ik {
    fn name(&self) -> &'static str {
        "ik"
    }
    fn description(&self) -> &'static str {
        "IK solve time: Pioneer closed form (pose, position) and numeric IK (6- and 7-joint chains)"
    }
    fn run(&self, ctx: &mut RunCtx) -> Result<(), BenchError> {
        let n = ctx.count(5_000, 500) as usize;
        let mut rng = DeterministicRng::new(0xB0A7_5EED);
        let geometry = PioneerGeometry::default();
        let popts = PioneerIkOptions::default();
        let zero: Theta = [0.0; 5];
        let pioneer_targets: Vec<Pose> = (0..n)
            .map(|_| {
                let theta: Theta = std::array::from_fn(|i| {
                    rng.uniform(geometry.limits[i].min, geometry.limits[i].max)
                });
                geometry.fk(&theta).unwrap_or_else(|_| Pose::identity())
            })
            .collect();
        time(
            ctx,
            "ik.pioneer.pose",
            "Pioneer closed form, SETPOSE",
            &pioneer_targets,
            |t| geometry.solve_pose(t, &zero, &popts).is_ok(),
        )?;
        time(
            ctx,
            "ik.pioneer.position",
            "Pioneer closed form, SETPOSITION",
            &pioneer_targets,
            |t| {
                geometry
                    .solve_position(&t.position, ApproachPreference::Current, &zero, &popts)
                    .is_ok()
            },
        )?;
        let copts = NumericIkOptions::default();
        let c6 = Chain::default_6dof();
        let c7 = Chain::default_7dof();
        let mut targets = |chain: &Chain| -> Vec<Pose> {
            (0..n)
                .map(|_| {
                    let q = chain.random_configuration(&mut rng);
                    chain.fk(q.as_slice()).unwrap_or_else(|_| Pose::identity())
                })
                .collect()
        };
        let t6 = targets(&c6);
        let t7 = targets(&c7);
        let h6 = c6.home();
        let h7 = c7.home();
        time(
            ctx,
            "ik.chain6.pose",
            "numeric IK, 6 joints, pose",
            &t6,
            |t| c6.ik(&IkTarget::Pose(*t), h6.as_slice(), &copts).is_ok(),
        )?;
        time(
            ctx,
            "ik.chain6.position",
            "numeric IK, 6 joints, position",
            &t6,
            |t| {
                c6.ik(&IkTarget::Position(t.position), h6.as_slice(), &copts)
                    .is_ok()
            },
        )?;
        time(
            ctx,
            "ik.chain7.pose",
            "numeric IK, 7 joints, pose",
            &t7,
            |t| c7.ik(&IkTarget::Pose(*t), h7.as_slice(), &copts).is_ok(),
        )?;
        Ok(())
    }
}

fn time<T>(
    ctx: &mut RunCtx,
    id: &str,
    label: &str,
    targets: &[T],
    mut solve: impl FnMut(&T) -> bool,
) -> Result<(), BenchError> {
    let mut h = new_histogram()?;
    let mut ok = 0usize;
    // Warm-up: the first tenth, not recorded.
    for t in targets.iter().take(targets.len() / 10) {
        black_box(solve(black_box(t)));
    }
    let progress = Progress::new(ctx.progress, label, targets.len() as u64);
    for (i, t) in targets.iter().enumerate() {
        let t0 = monotonic_ns();
        let good = black_box(solve(black_box(t)));
        let t1 = monotonic_ns();
        h.saturating_record(t1.saturating_sub(t0));
        ok += usize::from(good);
        progress.tick(i as u64);
    }
    progress.finish();
    if ok < targets.len() {
        ctx.notes.push(format!(
            "{id}: {ok}/{} solves succeeded (failed solves are timed too)",
            targets.len()
        ));
    }
    ctx.push(Measurement {
        scenario: "ik",
        id: id.to_string(),
        label: label.to_string(),
        strategy: Strategy::Compute,
        metric: Metric::Solve,
        bytes: None,
        hist: h,
    });
    Ok(())
}
