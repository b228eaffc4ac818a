//! The numeric inverse kinematics of a chain: damped least squares with restarts.

use nalgebra::{Vector3, Vector6};

use super::*;

impl Chain {
    /// Tool pose and the geometric Jacobian (rows: linear velocity, then angular
    /// velocity scaled by `w`). Only the first `dof()` columns are written: the
    /// others keep what `jac` had (zeros, from [`Jacobian::zeros`]).
    pub(super) fn fk_jacobian(&self, q: &[f64], w: f64, jac: &mut Jacobian) -> Pose {
        // During the walk each column holds its joint's origin (rows 0-2) and axis
        // (rows 3-5) in the world frame; the tip then turns them into velocities.
        // The walk gives each frame after its joint's motion: a rotary joint's motion
        // moves neither its origin nor its axis, a linear joint's moves only its origin,
        // which its column does not use.
        let tip = self.walk(q, |i, p, r| {
            jac.fixed_view_mut::<3, 1>(0, i).copy_from(p);
            jac.fixed_view_mut::<3, 1>(3, i)
                .copy_from(&self.turns[i].1.in_frame(r));
        });
        for (i, j) in self.joints.iter().enumerate() {
            let z: Vector3<f64> = jac.fixed_view::<3, 1>(3, i).into_owned();
            let (lin, ang) = match j.kind {
                JointKind::Rotary => {
                    let point: Vector3<f64> = jac.fixed_view::<3, 1>(0, i).into_owned();
                    (z.cross(&(tip.position - point)), z * w)
                }
                JointKind::Linear => (z, Vector3::zeros()),
            };
            jac.fixed_view_mut::<3, 1>(0, i).copy_from(&lin);
            jac.fixed_view_mut::<3, 1>(3, i).copy_from(&ang);
        }
        tip
    }

    /// Numeric IK: joint values inside the limits that bring the tool to `target`.
    /// The first attempt starts at `seed` (clamped into the limits), then up to
    /// `max_restarts` attempts start elsewhere: the first 16 at the configurations of
    /// the chain's atlas (256 drawn at load) whose tool poses are nearest the target,
    /// the others at deterministic random configurations. Each
    /// attempt is Levenberg–Marquardt on the damped least-squares step
    /// `Δq = Jᵀ(JJᵀ + λI)⁻¹e` with λ adapted to the cost (from `INITIAL_DAMPING`),
    /// the step limited to `MAX_STEP` rad (or m) per joint, joints pushing against a limit frozen for that step, and the
    /// result clamped into the limits. An attempt has stalled when the cost falls by
    /// less than half in 10 iterations, or by less than a fifth in 3 while a joint
    /// sits on a limit. The first time it stalls, rotary joints on a limit whose
    /// range leaves a gap of at most 0.4π (or none) to a full turn are moved across
    /// it (by a full turn, clamped into the limits: the same angle when the range
    /// spans a turn) and the attempt goes on; the second time, the next attempt
    /// starts. No allocation.
    // The error carries the best configuration on the stack (136 bytes) so that a
    // failed solve does not allocate either.
    #[allow(clippy::result_large_err)]
    pub fn ik(
        &self,
        target: &IkTarget,
        seed: &[f64],
        options: &NumericIkOptions,
    ) -> Result<ChainSolution, ChainIkError> {
        let n = self.dof();
        if seed.len() != n {
            return Err(ChainIkError::WrongJointCount {
                expected: n,
                got: seed.len(),
            });
        }
        let (target_p, target_r) = match target {
            IkTarget::Position(p) => (*p, None),
            IkTarget::Pose(pose) => (pose.position, Some(pose.rotation)),
        };
        let finite_target = all_finite(&target_p)
            && target_r.is_none_or(|r| r.matrix().iter().all(|v| v.is_finite()));
        if !finite_target || !seed.iter().all(|v| v.is_finite()) {
            return Err(ChainIkError::NonFinite);
        }
        let pos = |v: f64| v.is_finite() && v > 0.0;
        if !(pos(options.position_tolerance)
            && pos(options.orientation_tolerance)
            && pos(options.orientation_weight)
            && options.max_iterations > 0)
        {
            return Err(ChainIkError::InvalidOptions);
        }
        // Reach bound from the first joint's origin, which no joint moves.
        let j0 = &self.joints[0];
        let first = self.base.position + self.base.rotation * j0.origin;
        let d = target_p - first;
        let distance = d.x.hypot(d.y).hypot(d.z);
        if distance > self.reach + options.position_tolerance {
            return Err(ChainIkError::OutOfReach {
                distance,
                reach: self.reach,
            });
        }

        let w = if target_r.is_some() {
            options.orientation_weight
        } else {
            0.0
        };
        let residual = |pose: &Pose| -> Vector6<f64> {
            let dp = target_p - pose.position;
            let dw = match target_r {
                Some(r) => (r * pose.rotation.inverse()).scaled_axis() * w,
                None => Vector3::zeros(),
            };
            Vector6::new(dp.x, dp.y, dp.z, dw.x, dw.y, dw.z)
        };
        let errors = |pose: &Pose| -> (f64, f64) {
            let pe = (target_p - pose.position).norm();
            let oe = match target_r {
                Some(r) => crate::pose::angle_between_rotations(&r, &pose.rotation),
                None => 0.0,
            };
            (pe, oe)
        };
        let converged = |(pe, oe): (f64, f64)| {
            pe <= options.position_tolerance && oe <= options.orientation_tolerance
        };

        // Four times the cost of a residual exactly at both tolerances: above it, the
        // tolerances cannot both be met whatever the round-off in either measure.
        let near_cost = 4.0
            * (options.position_tolerance.powi(2) + (w * options.orientation_tolerance).powi(2));
        let mut rng = DeterministicRng::new(options.seed);
        let mut q = JointVec::from_slice(seed).ok_or(ChainIkError::WrongJointCount {
            expected: n,
            got: seed.len(),
        })?;
        self.clamp_to_limits(&mut q);
        // The current Jacobian and the trial's; `flipped` when the second is current
        // (an accepted trial flips it instead of copying 768 bytes).
        let mut jacs = (Jacobian::zeros(), Jacobian::zeros());
        let mut flipped = false;
        let mut best_q = q;
        let mut best_cost = f64::INFINITY;
        let mut iterations = 0u32;
        // The atlas seeds nearest the target, made the first time a restart is needed.
        let mut nearest: Option<[u16; ATLAS_RESTARTS]> = None;
        for attempt in 0..=options.max_restarts {
            if attempt > 0 {
                let order = nearest
                    .get_or_insert_with(|| self.atlas_order(&target_p, target_r.as_ref(), w));
                q = match order.get(attempt as usize - 1) {
                    Some(&k) if usize::from(k) < self.atlas.len() => self.atlas[usize::from(k)].0,
                    _ => self.random_configuration(&mut rng),
                };
            }
            let jac = if flipped { &mut jacs.1 } else { &mut jacs.0 };
            let mut pose = self.fk_jacobian(&q, w, jac);
            // JJᵀ, for every λ tried on this Jacobian.
            let mut gram = Gram::of(jac, n);
            let mut e = residual(&pose);
            let mut cost = e.norm_squared();
            let mut lambda = INITIAL_DAMPING;
            let mut checkpoint = cost;
            let mut recent = cost;
            let mut crossed = false;
            let mut q_new = q;
            for it in 0..=options.max_iterations {
                let (jac, jac_new) = if flipped {
                    (&mut jacs.1, &mut jacs.0)
                } else {
                    (&mut jacs.0, &mut jacs.1)
                };
                // Stalled: less than half the cost gone in 10 iterations, or less than a
                // fifth in 3 while a joint sits on a limit (a minimum on the boundary).
                let mut stalled = false;
                if it > 0 && it % PINNED_EVERY == 0 {
                    stalled = cost > PINNED_STALL * recent && self.on_a_limit(&q);
                    recent = cost;
                }
                if it > 0 && it % 10 == 0 {
                    stalled |= cost > STALL * checkpoint;
                    checkpoint = cost;
                }
                // Within a few tolerances of the target (slow near a singularity, where
                // the damping holds the step back) the attempt goes on to the end.
                if stalled && cost > POLISH * near_cost {
                    // Once per attempt, wide joints on a limit cross their gap and the
                    // attempt goes on from there; otherwise the next restart.
                    if cost < best_cost {
                        best_cost = cost;
                        best_q = q;
                    }
                    if crossed || !self.cross_gaps(&mut q) {
                        break;
                    }
                    crossed = true;
                    pose = self.fk_jacobian(&q, w, jac);
                    gram = Gram::of(jac, n);
                    e = residual(&pose);
                    cost = e.norm_squared();
                    // Small: the crossed joint is near its goal more often than not
                    // (INITIAL_DAMPING here cost more restarts).
                    lambda = CROSSED_DAMPING;
                    checkpoint = cost;
                    recent = cost;
                }
                if !cost.is_finite() {
                    break;
                }
                // (The best configuration is kept when the attempt ends or crosses a
                // gap: in between, only a lower cost moves q.)
                // The residual bounds both errors (‖e‖² = pe² + (w·oe)²), so the exact
                // errors are worth computing only once it is small.
                if cost <= near_cost {
                    let errs = errors(&pose);
                    if converged(errs) {
                        return Ok(ChainSolution {
                            q,
                            position_error: errs.0,
                            orientation_error: errs.1,
                            iterations,
                            restarts: attempt,
                        });
                    }
                }
                if it == options.max_iterations {
                    break;
                }
                iterations += 1;
                let Some(mut dq) = gram.step(jac, &e, lambda, n, 0) else {
                    lambda *= 10.0;
                    continue;
                };
                // Freeze joints that sit on a limit and would be pushed beyond it.
                let pushed_out = |i: usize, j: &JointSpec| {
                    (q[i] <= j.min && dq[i] < 0.0) || (q[i] >= j.max && dq[i] > 0.0)
                };
                let frozen = self
                    .joints
                    .iter()
                    .enumerate()
                    .filter(|(i, j)| pushed_out(*i, j))
                    .fold(0u32, |m, (i, _)| m | 1 << i);
                if frozen != 0 {
                    // Their columns of the Jacobian count as zero.
                    match Gram::without(jac, n, frozen).step(jac, &e, lambda, n, frozen) {
                        Some(d) => dq = d,
                        None => {
                            lambda *= 10.0;
                            continue;
                        }
                    }
                }
                let biggest = dq.iter().take(n).fold(0.0_f64, |m, v| m.max(v.abs()));
                let scale = if biggest > MAX_STEP {
                    MAX_STEP / biggest
                } else {
                    1.0
                };
                for (i, (v, j)) in q_new.iter_mut().zip(&self.joints).enumerate() {
                    *v = (q[i] + dq[i] * scale).clamp(j.min, j.max);
                }
                let pose_new = self.fk_jacobian(&q_new, w, jac_new);
                let e_new = residual(&pose_new);
                let cost_new = e_new.norm_squared();
                if cost_new < cost {
                    // The values only (a fixed-size copy, inlined).
                    q.values = q_new.values;
                    pose = pose_new;
                    e = e_new;
                    cost = cost_new;
                    gram = Gram::of(jac_new, n);
                    flipped = !flipped;
                    lambda = (lambda * 0.3).max(1e-12);
                } else {
                    lambda *= 5.0;
                    if lambda > 1e6 {
                        break;
                    }
                }
            }
            if cost < best_cost {
                best_cost = cost;
                best_q = q;
            }
        }
        let pose = self.walk(&best_q, |_, _, _| {});
        let (position_error, orientation_error) = errors(&pose);
        if converged((position_error, orientation_error)) {
            return Ok(ChainSolution {
                q: best_q,
                position_error,
                orientation_error,
                iterations,
                restarts: options.max_restarts,
            });
        }
        Err(ChainIkError::NotConverged {
            position_error,
            orientation_error,
            best: best_q,
        })
    }
}

/// λ at the start of an attempt of [`Chain::ik`]. Against 1e-3 before (issue 16):
/// more first attempts succeed (6-joint pose 86 % instead of 78 % of the bench's
/// targets from home), in fewer iterations (p99 89 instead of 107).
const INITIAL_DAMPING: f64 = 0.3;

/// An attempt of [`Chain::ik`] whose cost is below this many times that of a
/// residual at both tolerances never counts as stalled: it is converging, slowly
/// (next to the wrist singularity of the 7-joint arm, 2 of 20,000 random poses ended
/// 2e-6 from the target when they were stopped).
const POLISH: f64 = 100.0;

/// λ after joints crossed their gaps in [`Chain::ik`].
const CROSSED_DAMPING: f64 = 1e-3;

/// Largest change of one joint in a step of [`Chain::ik`], rad or m (0.5 before issue
/// 16: with [`INITIAL_DAMPING`] this takes fewer iterations and no more restarts).
const MAX_STEP: f64 = 0.7;

/// Configurations in a chain's atlas of restart seeds.
const ATLAS_SIZE: usize = 256;

/// Restarts of [`Chain::ik`] that start at the atlas seeds nearest the target (the
/// others at random configurations).
const ATLAS_RESTARTS: usize = 16;

impl Chain {
    /// The atlas: [`ATLAS_SIZE`] configurations drawn like the restarts, with their
    /// tool poses.
    pub(super) fn make_atlas(&self) -> Vec<(JointVec, Pose)> {
        let mut rng = DeterministicRng::new(0xA71A5);
        (0..ATLAS_SIZE)
            .map(|_| {
                let q = self.random_configuration(&mut rng);
                (q, self.walk(&q, |_, _, _| {}))
            })
            .collect()
    }

    /// Indices of the [`ATLAS_RESTARTS`] atlas seeds whose tool poses are nearest
    /// the target (position, and the orientation weighted by `w` as in the cost),
    /// nearest first.
    fn atlas_order(
        &self,
        p: &Vector3<f64>,
        r: Option<&nalgebra::Rotation3<f64>>,
        w: f64,
    ) -> [u16; ATLAS_RESTARTS] {
        let mut scored = [(f64::INFINITY, u16::MAX); ATLAS_SIZE];
        for (slot, (k, (_, pose))) in scored.iter_mut().zip(self.atlas.iter().enumerate()) {
            let mut d = (pose.position - p).norm_squared();
            if let Some(r) = r {
                // Half the squared chordal distance: θ² for small angles.
                d += w * w * 0.5 * (r.matrix() - pose.rotation.matrix()).norm_squared();
            }
            *slot = (d, k as u16);
        }
        let by = |x: &(f64, u16), y: &(f64, u16)| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1));
        let (best, nth, _) = scored.select_nth_unstable_by(ATLAS_RESTARTS - 1, by);
        let mut first = [(0.0, 0u16); ATLAS_RESTARTS];
        first[..ATLAS_RESTARTS - 1].copy_from_slice(best);
        first[ATLAS_RESTARTS - 1] = *nth;
        first.sort_unstable_by(by);
        first.map(|(_, k)| k)
    }
}

/// An attempt of [`Chain::ik`] has stalled when 10 iterations leave more than this
/// fraction of the cost: a start that creeps (towards a limit or a
/// local minimum) costs a restart less than it costs to follow (0.9 before, which let
/// failing attempts run several times longer than converging ones; 0.3 lost
/// solutions).
const STALL: f64 = 0.5;

/// An attempt of [`Chain::ik`] with a joint on a limit has stalled when, over
/// [`PINNED_EVERY`] iterations, the cost keeps more than this fraction: a minimum on
/// the boundary of the limits, which the rest of the attempt rarely leaves (checked
/// every 10 iterations instead, such attempts ran 20-40 iterations and made most of
/// the 7-joint chain's tail).
const PINNED_STALL: f64 = 0.8;

/// Iterations between two checks of [`PINNED_STALL`].
const PINNED_EVERY: u32 = 3;

/// Largest gap, rad, between a rotary joint's range and a full turn for
/// [`Chain::ik`] to move the joint across it when it stalls on a limit (0.4π: the
/// 7-joint arm's ±166° joints, not its ±101° one).
const CROSSABLE_GAP: f64 = 0.4 * std::f64::consts::PI;

impl Chain {
    /// True when a joint of `q` sits on one of its limits.
    fn on_a_limit(&self, q: &[f64]) -> bool {
        q.iter()
            .zip(&self.joints)
            .any(|(v, j)| *v <= j.min || *v >= j.max)
    }

    /// Moves every rotary joint of `q` that sits on a limit, and whose range leaves a
    /// gap of at most [`CROSSABLE_GAP`] to a full turn, by a full turn away from that
    /// limit, clamped into the limits. Returns whether one moved.
    fn cross_gaps(&self, q: &mut [f64]) -> bool {
        let mut moved = false;
        for (v, j) in q.iter_mut().zip(&self.joints) {
            let crossable = j.kind == JointKind::Rotary
                && j.max - j.min >= std::f64::consts::TAU - CROSSABLE_GAP;
            if !crossable {
                continue;
            }
            let turned = if *v >= j.max {
                *v - std::f64::consts::TAU
            } else if *v <= j.min {
                *v + std::f64::consts::TAU
            } else {
                continue;
            };
            *v = turned.clamp(j.min, j.max);
            moved = true;
        }
        moved
    }
}

pub(super) fn sample_range(j: &JointSpec) -> (f64, f64) {
    use std::f64::consts::PI;
    if j.kind == JointKind::Rotary {
        let lo = j.min.max(-PI);
        let hi = j.max.min(PI);
        if lo < hi {
            return (lo, hi);
        }
    }
    (j.min, j.max)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A chain with every kind of joint and rotation the walk tells apart: a rotated
    /// base, a general (tilted) axis, a linear joint, a general rest orientation.
    const MIXED: &str = r#"
name = "mixed"
[base]
xyz = [0.1, -0.2, 0.3]
rpy = [0.2, -0.1, 0.4]
[[joints]]
name = "a"
type = "rotary"
axis = [0.0, 0.0, 1.0]
min = -3.0
max = 3.0
max_speed = 1.0
[[joints]]
name = "b"
type = "rotary"
xyz = [0.0, 0.05, 0.2]
rpy = [0.0, 1.5707963267948966, 0.0]
axis = [0.3, -0.5, 0.8]
min = -3.0
max = 3.0
max_speed = 1.0
[[joints]]
name = "c"
type = "linear"
xyz = [0.3, 0.0, 0.0]
rpy = [0.1, 0.2, 0.3]
axis = [0.0, 1.0, 0.0]
min = -0.2
max = 0.4
max_speed = 1.0
[[joints]]
name = "d"
type = "rotary"
xyz = [0.0, 0.0, 0.25]
axis = [-1.0, 0.0, 0.0]
min = -3.0
max = 3.0
max_speed = 1.0
[tool]
xyz = [0.05, 0.02, 0.1]
rpy = [0.3, 0.0, -0.2]
"#;

    /// The one-walk Jacobian (linear rows, then angular rows scaled by w) equals
    /// central differences of FK, and its pose is FK's.
    #[test]
    fn fk_jacobian_equals_finite_differences() {
        let mixed = Chain::from_toml_str(MIXED).unwrap();
        let chains = [
            Chain::default_6dof(),
            Chain::default_7dof(),
            Chain::pioneer5(),
            mixed,
        ];
        let mut rng = DeterministicRng::new(7);
        let w = 0.5;
        let h = 1e-5;
        for chain in &chains {
            for _ in 0..20 {
                let q = chain.random_configuration(&mut rng);
                let mut jac = Jacobian::zeros();
                let pose = chain.fk_jacobian(&q, w, &mut jac);
                assert_eq!(pose, chain.fk(&q).unwrap());
                for i in 0..chain.dof() {
                    let (mut plus, mut minus) = (q, q);
                    plus[i] += h;
                    minus[i] -= h;
                    let (a, b) = (chain.fk(&plus).unwrap(), chain.fk(&minus).unwrap());
                    let lin = (a.position - b.position) / (2.0 * h);
                    // sin(angle)·axis from the skew part of the relative rotation (its
                    // scaled_axis takes the angle from acos, 1e-7 off at 2e-5 rad).
                    let d = (a.rotation * b.rotation.inverse()).into_inner();
                    let skew = Vector3::new(d.m32 - d.m23, d.m13 - d.m31, d.m21 - d.m12) / 2.0;
                    let ang = skew * (w / (2.0 * h));
                    let col = jac.column(i);
                    for r in 0..3 {
                        assert!((col[r] - lin[r]).abs() < 1e-7, "{} {i}", chain.name());
                        assert!((col[r + 3] - ang[r]).abs() < 1e-7, "{} {i}", chain.name());
                    }
                }
                assert!(
                    jac.columns(chain.dof(), MAX_JOINTS - chain.dof())
                        .iter()
                        .all(|v| *v == 0.0)
                );
            }
        }
    }

    /// The restart seeds are the atlas entries nearest the target, nearest first: a
    /// target at an entry's pose puts that entry first, and the distances rise.
    #[test]
    fn atlas_order_puts_the_nearest_seeds_first() {
        for chain in [Chain::default_6dof(), Chain::default_7dof()] {
            assert_eq!(chain.atlas.len(), ATLAS_SIZE);
            for k in [0, 17, ATLAS_SIZE - 1] {
                let (_, pose) = chain.atlas[k];
                for rotation in [Some(&pose.rotation), None] {
                    let order = chain.atlas_order(&pose.position, rotation, 0.5);
                    assert_eq!(usize::from(order[0]), k);
                    let distance = |i: u16| {
                        let p = &chain.atlas[usize::from(i)].1;
                        let mut d = (p.position - pose.position).norm_squared();
                        if rotation.is_some() {
                            d += 0.125
                                * (p.rotation.matrix() - pose.rotation.matrix()).norm_squared();
                        }
                        d
                    };
                    assert!(order.windows(2).all(|w| distance(w[0]) <= distance(w[1])));
                    // No entry outside the order is nearer than its last one.
                    let last = distance(order[ATLAS_RESTARTS - 1]);
                    let nearer = (0..ATLAS_SIZE as u16)
                        .filter(|i| distance(*i) < last)
                        .count();
                    assert!(nearer < ATLAS_RESTARTS);
                }
            }
        }
    }
}
