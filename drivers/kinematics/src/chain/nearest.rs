//! SETPOSE with the rules of a 5-joint arm, for any chain: the position and the approach
//! met within tolerances, the orientation the nearest one the joints can hold.
//!
//! A chain that can hold the requested frame gets it ([`Chain::ik`], exact). One that
//! cannot (fewer than six joints, or limits in the way) is solved again with the
//! orientation error split in two: the tilt of the approach, weighted like the
//! position, and the roll about the approach, weighted by
//! [`NearestOptions::roll_weight`] only, so that the least-squares optimum trades roll
//! for nothing else; a polishing pass without the roll then meets the position and the
//! approach to round-off. Each attempt (the seed, then deterministic random
//! configurations, [`NearestOptions::attempts`] in all) that meets them within
//! [`NearestOptions::position_tolerance`] and [`NearestOptions::approach_tolerance`]
//! inside the limits is a candidate; the one with the smallest orientation adjustment
//! wins (ties to the one nearest the seed).

use nalgebra::{Matrix3, Vector3, Vector6};

use super::*;
use crate::pose::angle_between_rotations;

/// Options of [`Chain::ik_nearest_orientation`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NearestOptions {
    /// How far from the requested position the tool may end, m (1 mm).
    pub position_tolerance: f64,
    /// How far from the requested approach the tool may point, rad (1°).
    pub approach_tolerance: f64,
    /// Weight of the roll about the approach relative to the approach's tilt (0.1).
    pub roll_weight: f64,
    /// Attempts: the seed, then random configurations (9).
    pub attempts: u32,
}

impl Default for NearestOptions {
    fn default() -> Self {
        Self {
            position_tolerance: 1e-3,
            approach_tolerance: 1f64.to_radians(),
            roll_weight: 0.1,
            attempts: 9,
        }
    }
}

/// A solution of [`Chain::ik_nearest_orientation`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NearestSolution {
    /// The joint values, inside the limits.
    pub q: JointVec,
    /// The tool pose they give (FK).
    pub achieved: Pose,
    /// Distance from the requested position, m.
    pub position_error: f64,
    /// Angle from the requested approach, rad.
    pub approach_error: f64,
    /// Angle between the requested and the achieved frame, rad.
    pub adjustment: f64,
}

impl Chain {
    /// SETPOSE with 5-DOF semantics (see the module docs). Errors: those of
    /// [`Chain::ik`]; [`ChainIkError::NotConverged`] when no attempt met the position and
    /// the approach within the tolerances inside the limits.
    #[allow(clippy::result_large_err)]
    pub fn ik_nearest_orientation(
        &self,
        target: &Pose,
        seed: &[f64],
        ik: &NumericIkOptions,
        near: &NearestOptions,
    ) -> Result<NearestSolution, ChainIkError> {
        let first = match self.ik(&IkTarget::Pose(*target), seed, ik) {
            Ok(s) => {
                let achieved = self.walk(&s.q, |_, _, _| {});
                return Ok(NearestSolution {
                    q: s.q,
                    achieved,
                    position_error: s.position_error,
                    approach_error: angle(&achieved.approach(), &target.approach()),
                    adjustment: s.orientation_error,
                });
            }
            Err(e @ ChainIkError::NotConverged { .. }) => e,
            Err(e) => return Err(e),
        };
        let ok = |v: f64| v.is_finite() && v > 0.0;
        if !(ok(near.position_tolerance)
            && ok(near.approach_tolerance)
            && ok(near.roll_weight)
            && near.attempts > 0)
        {
            return Err(ChainIkError::InvalidOptions);
        }
        let a = target.approach();
        let along = a * a.transpose();
        let tilt_only = Matrix3::identity() - along;
        let with_roll = tilt_only + along * near.roll_weight;
        let mut rng = DeterministicRng::new(ik.seed ^ 0xA7_7A);
        let mut best: Option<(f64, f64, NearestSolution)> = None;
        for attempt in 0..near.attempts {
            let mut q = if attempt == 0 {
                JointVec::from_slice(seed).ok_or(ChainIkError::WrongJointCount {
                    expected: self.dof(),
                    got: seed.len(),
                })?
            } else {
                self.random_configuration(&mut rng)
            };
            self.clamp_to_limits(&mut q);
            // The roll weighed lightly, then polished away.
            self.lm_run(&mut q, target, &with_roll, ik, |_| false);
            self.lm_run(&mut q, target, &tilt_only, ik, |pose| {
                (pose.position - target.position).norm() <= ik.position_tolerance
                    && angle(&pose.approach(), &a) <= ik.orientation_tolerance
            });
            if !self.within_limits(&q) {
                continue;
            }
            let achieved = self.walk(&q, |_, _, _| {});
            let position_error = (achieved.position - target.position).norm();
            let approach_error = angle(&achieved.approach(), &a);
            if !(position_error <= near.position_tolerance
                && approach_error <= near.approach_tolerance)
            {
                continue;
            }
            let adjustment = angle_between_rotations(&achieved.rotation, &target.rotation);
            let distance: f64 = q.iter().zip(seed).map(|(x, y)| (x - y) * (x - y)).sum();
            let better = best.as_ref().is_none_or(|(adj, dist, _)| {
                adjustment < adj - 1e-9 || (adjustment <= adj + 1e-9 && distance < *dist)
            });
            if better {
                best = Some((
                    adjustment,
                    distance,
                    NearestSolution {
                        q,
                        achieved,
                        position_error,
                        approach_error,
                        adjustment,
                    },
                ));
            }
        }
        best.map(|(_, _, s)| s).ok_or(first)
    }

    /// Levenberg–Marquardt from `q` towards `target` with the orientation residual
    /// mapped by `m` (world frame), until `done`, a stall (less than 10 % progress in
    /// 10 iterations) or `max_iterations`. Keeps the best configuration in `q`.
    fn lm_run(
        &self,
        q: &mut JointVec,
        target: &Pose,
        m: &Matrix3<f64>,
        ik: &NumericIkOptions,
        done: impl Fn(&Pose) -> bool,
    ) {
        let n = self.dof();
        let w = ik.orientation_weight;
        let residual = |pose: &Pose| -> Vector6<f64> {
            let dp = target.position - pose.position;
            let dw: Vector3<f64> =
                m * (target.rotation * pose.rotation.inverse()).scaled_axis() * w;
            Vector6::new(dp.x, dp.y, dp.z, dw.x, dw.y, dw.z)
        };
        let jacobian = |q: &JointVec, jac: &mut Jacobian| -> Pose {
            let pose = self.fk_jacobian(q, w, jac);
            let ang = m * jac.fixed_rows::<3>(3);
            jac.fixed_rows_mut::<3>(3).copy_from(&ang);
            pose
        };
        let mut jac = Jacobian::zeros();
        let mut jac_new = Jacobian::zeros();
        let mut pose = jacobian(q, &mut jac);
        let mut e = residual(&pose);
        let mut cost = e.norm_squared();
        let mut lambda = 1e-3;
        let mut checkpoint = cost;
        for it in 0..ik.max_iterations {
            if done(&pose) || !cost.is_finite() {
                return;
            }
            if it > 0 && it % 10 == 0 {
                if cost > 0.9 * checkpoint {
                    return;
                }
                checkpoint = cost;
            }
            let Some(dq) = Gram::of(&jac, n).step(&jac, &e, lambda, n, 0) else {
                lambda *= 10.0;
                continue;
            };
            let biggest = dq.iter().take(n).fold(0.0_f64, |b, v| b.max(v.abs()));
            let scale = if biggest > 0.5 { 0.5 / biggest } else { 1.0 };
            let mut q_new = *q;
            for (i, v) in q_new.iter_mut().enumerate() {
                *v += dq[i] * scale;
            }
            self.clamp_to_limits(&mut q_new);
            let pose_new = jacobian(&q_new, &mut jac_new);
            let e_new = residual(&pose_new);
            let cost_new = e_new.norm_squared();
            if cost_new < cost {
                *q = q_new;
                pose = pose_new;
                e = e_new;
                cost = cost_new;
                std::mem::swap(&mut jac, &mut jac_new);
                lambda = (lambda * 0.3).max(1e-12);
            } else {
                lambda *= 5.0;
                if lambda > 1e6 {
                    return;
                }
            }
        }
    }
}

/// Angle between two vectors, rad.
fn angle(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}
