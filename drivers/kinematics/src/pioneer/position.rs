//! SETPOSITION: a position without an orientation. The 5-DOF arm reaches most positions
//! with many approach vectors; [`PioneerGeometry::solve_position`] picks one
//! deterministically, preferring the caller's approach, then the arm's vertical plane,
//! then θ1 held on a yaw limit, then cones around the preferred approach.

use std::cell::Cell;
use std::f64::consts::{PI, TAU};
use std::sync::OnceLock;

use nalgebra::Vector3;

use super::ik::{Reach, WristGoal};
use super::{
    EXACT_ORIENTATION, EXACT_POSITION, IkCandidate, LIMIT_TOLERANCE, PioneerGeometry,
    PioneerIkError, PioneerIkOptions, Theta, joint_distance,
};
use crate::pose::{FrameError, all_finite, fit_angle_to_limits};

/// Where SETPOSITION should look for an approach vector.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ApproachPreference {
    /// Keep the current approach (FK of the current joints) if possible.
    Current,
    /// Point the gripper straight down (−z).
    Down,
    /// Prefer this direction (any non-zero length).
    Direction(Vector3<f64>),
}

impl PioneerGeometry {
    /// SETPOSITION (position only, relative to the arm base). The approach is chosen
    /// deterministically, in this order:
    ///
    /// 1. the preferred approach itself, if an in-limit solution attains it;
    /// 2. the approach *in the arm's vertical plane* (through the yaw axis and the
    ///    target, so the wrist roll is 0 or π and the gripper stays level) nearest in
    ///    angle to the preferred one: elevations are scanned outward from the preferred
    ///    approach's elevation in steps of [`PioneerIkOptions::approach_search_step`],
    ///    alternately up and down, and the first feasible one is refined by bisection
    ///    towards the preferred elevation to 1e-9 rad;
    /// 3. if that plane lies beyond the base yaw limits, θ1 held on a limit, with the
    ///    wrist centre scanned (same step) around the circle where that arm plane cuts
    ///    the sphere of radius L5 about the target, keeping the feasible approach
    ///    closest to the preferred one;
    /// 4. failing that, approaches out of the plane, on cones around the preferred one
    ///    five search steps apart, and finally the direction from the shoulder circle to
    ///    the target (the only approach at full stretch).
    ///
    /// The search tests each approach by the closed form alone, without scoring
    /// its candidates by the FK and without an inverse trigonometric function (the
    /// limits are tested on sines and cosines); the approach it keeps is scored and
    /// checked by the FK like any other answer.
    ///
    /// For the chosen approach the in-limit solution nearest to `current` wins. The
    /// result's `orientation_error` is the error to the chosen approach. Fails with
    /// [`PioneerIkError::OutOfReach`] when the position is beyond L2 + L4 + L5 from the
    /// shoulder circle or no approach reaches it, and with
    /// [`PioneerIkError::OutsideJointLimits`] when solutions exist only outside the
    /// limits.
    pub fn solve_position(
        &self,
        position: &Vector3<f64>,
        preference: ApproachPreference,
        current: &Theta,
        options: &PioneerIkOptions,
    ) -> Result<IkCandidate, PioneerIkError> {
        self.check_inputs(current, options)?;
        if !all_finite(position) {
            return Err(PioneerIkError::NonFinite);
        }
        let preferred = match preference {
            ApproachPreference::Current => self.fk_raw(current).approach(),
            ApproachPreference::Down => -Vector3::z(),
            ApproachPreference::Direction(d) => {
                if !all_finite(&d) {
                    return Err(PioneerIkError::NonFinite);
                }
                let n = d.norm();
                if n < 1e-12 {
                    return Err(FrameError::ZeroApproach.into());
                }
                d / n
            }
        };
        let h = position.x.hypot(position.y);
        let from_circle = (h - self.l1).hypot(position.z);
        let max = self.l2 + self.l4 + self.l5;
        if from_circle > max + options.position_tolerance {
            return Err(PioneerIkError::OutOfReach {
                distance: from_circle,
                min: 0.0,
                max,
            });
        }
        // Whether an exact solution outside the limits has been seen: then only the
        // in-limit candidates can change the answer, and once every approach has
        // failed the cause is the limits, not the reach.
        let any_exact = Cell::new(false);
        // The search accepts only exact solutions (round-off), so that the bisection
        // cannot settle on a reach boundary blurred by the tolerance; the last resort
        // (full stretch) accepts the tolerances.
        let strict = PioneerIkOptions {
            position_tolerance: EXACT_POSITION,
            orientation_tolerance: EXACT_ORIENTATION,
            ..*options
        };
        // The candidates for approach `a`, scored by the FK, and the selection.
        let attempt_with = |a: &Vector3<f64>, opts: &PioneerIkOptions| {
            let cands = self
                .candidates(
                    position,
                    WristGoal::Approach(a),
                    current,
                    opts.position_tolerance,
                    any_exact.get(),
                )
                .ok()?;
            match cands.select(current, opts) {
                Ok(c) => Some(c),
                Err(PioneerIkError::OutsideJointLimits) => {
                    any_exact.set(true);
                    None
                }
                Err(_) => None,
            }
        };
        // The closed form without the FK scoring (a fraction of the cost): whether an
        // in-limit solution attains approach `a`. The search tests every approach this
        // way first and scores only those that pass.
        let arcs = self.limit_arcs();
        let reaches = |a: &Vector3<f64>| match self.reach_with_approach(
            position,
            a,
            current,
            EXACT_POSITION,
            any_exact.get(),
            &arcs,
        ) {
            Reach::Within => true,
            Reach::Outside => {
                any_exact.set(true);
                false
            }
            Reach::None => false,
        };
        let attempt = |a: &Vector3<f64>| {
            if reaches(a) {
                attempt_with(a, &strict)
            } else {
                None
            }
        };
        // 1. The preferred approach.
        if let Some(c) = attempt(&preferred) {
            return Ok(c);
        }
        // 2. In the vertical plane through the yaw axis and the target.
        let yaw = if h > 1e-12 {
            position.y.atan2(position.x)
        } else {
            current[0]
        };
        let radial = Vector3::new(yaw.cos(), yaw.sin(), 0.0);
        let in_plane = |phi: f64| radial * phi.cos() + Vector3::z() * phi.sin();
        let phi0 = preferred.z.atan2(preferred.dot(&radial));
        let step = options.approach_search_step;
        let steps = (PI / step).ceil() as usize;
        let per_circle = steps * 2;
        // The cosines and sines of j·step (j < per_circle) for both scans: the
        // default step's are made once per process, another step's on the stack.
        let made: [(f64, f64); CIRCLE_SCAN_CAPACITY / 2];
        let trig: &[(f64, f64)] = if per_circle > CIRCLE_SCAN_CAPACITY / 2 {
            &[]
        } else if let Some(t) = default_step_trig(step) {
            &t[..per_circle]
        } else {
            made = step_trig(step, per_circle);
            &made[..per_circle]
        };
        if let Some(c) = attempt(&in_plane(phi0)) {
            return Ok(c);
        }
        let (s0, c0) = phi0.sin_cos();
        for k in 1..=steps {
            for sign in [1.0, -1.0] {
                let phi = phi0 + sign * (k as f64 * step).min(PI);
                // The scan tests φ0 ± k·step by the sum formulas on the shared
                // cosines and sines (within an ulp or two of `in_plane(phi)`); what
                // it keeps is computed from φ itself.
                let a = match trig.get(k) {
                    Some(&(ck, sk)) if k as f64 * step <= PI => {
                        let sk = sign * sk;
                        radial * (c0 * ck - s0 * sk) + Vector3::z() * (s0 * ck + c0 * sk)
                    }
                    _ => in_plane(phi),
                };
                if !reaches(&a) {
                    continue;
                }
                let bad = phi0 + sign * ((k - 1) as f64 * step);
                // The boundary by the closed form alone, then the FK check there; if
                // round-off makes the two disagree, the bisection again with the check
                // at every step.
                let (edge, ()) = bisect((phi, ()), bad, |m| reaches(&in_plane(m)).then_some(()));
                if let Some(c) = attempt_with(&in_plane(edge), &strict) {
                    return Ok(c);
                }
                if let Some(found) = attempt_with(&in_plane(phi), &strict) {
                    let (_, c) = bisect((phi, found), bad, |m| attempt_with(&in_plane(m), &strict));
                    return Ok(c);
                }
            }
        }
        // 3. Targets whose vertical plane lies beyond the base yaw limits: hold θ1 on
        //    a limit; the wrist centre then lies on the circle where that arm plane
        //    cuts the sphere of radius L5 around the target. Take the feasible approach
        //    on it closest to the preferred one.
        let yaw_limit = self.limits[0];
        let yaw_ok = |y: f64| {
            fit_angle_to_limits(y, yaw_limit.min, yaw_limit.max, current[0], LIMIT_TOLERANCE)
                .is_some()
        };
        if !yaw_ok(yaw) || !yaw_ok(yaw + PI) {
            let circles = [yaw_limit.min, yaw_limit.max].map(|t1| {
                let (s1, c1) = t1.sin_cos();
                let normal = Vector3::new(-s1, c1, 0.0);
                let off = position.dot(&normal);
                (off.abs() < self.l5).then(|| {
                    let r = (self.l5 * self.l5 - off * off).sqrt();
                    (position - normal * off, Vector3::new(c1, s1, 0.0), r)
                })
            });
            // The approach with the wrist centre at angle ψ (cosine, sine) on a circle.
            let approach_on = |circle: usize, (c, s): (f64, f64)| {
                circles[circle].map(|(centre, e1, r)| {
                    let w = centre + (e1 * c + Vector3::z() * s) * r;
                    (position - w) / self.l5
                })
            };
            if 2 * per_circle <= CIRCLE_SCAN_CAPACITY {
                // Every approach on both circles, scored, then tried best first: the
                // first feasible one is the one a full scan keeps (smallest score, ties
                // to the earlier circle and angle), after a fraction of the attempts.
                // The cosines and sines are shared by the circles and the two passes;
                // the order is made a chunk at a time (most targets need the first).
                let mut order = [(0.0f64, 0u16); CIRCLE_SCAN_CAPACITY];
                let mut len = 0;
                for circle in 0..2 {
                    for (j, t) in trig.iter().enumerate() {
                        if let Some(a) = approach_on(circle, *t) {
                            order[len] = (-a.dot(&preferred), (circle * per_circle + j) as u16);
                            len += 1;
                        }
                    }
                }
                let by = |x: &(f64, u16), y: &(f64, u16)| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1));
                let mut rest = &mut order[..len];
                while !rest.is_empty() {
                    let chunk = CIRCLE_CHUNK.min(rest.len());
                    if chunk < rest.len() {
                        rest.select_nth_unstable_by(chunk - 1, by);
                    }
                    let (first, others) = rest.split_at_mut(chunk);
                    first.sort_unstable_by(by);
                    for &(_, index) in first.iter() {
                        let index = usize::from(index);
                        let a = approach_on(index / per_circle, trig[index % per_circle]);
                        if let Some(c) = a.and_then(|a| attempt(&a)) {
                            return Ok(c);
                        }
                    }
                    rest = others;
                }
            } else {
                let mut best: Option<(f64, IkCandidate)> = None;
                for circle in 0..2 {
                    for j in 0..per_circle {
                        let psi = j as f64 * step;
                        let Some(a) = approach_on(circle, (psi.cos(), psi.sin())) else {
                            break;
                        };
                        if let Some(c) = attempt(&a) {
                            let score = -a.dot(&preferred);
                            if best.is_none_or(|(bs, _)| score < bs) {
                                best = Some((score, c));
                            }
                        }
                    }
                }
                if let Some((_, c)) = best {
                    return Ok(c);
                }
            }
        }
        // 4. Out of the plane: cones around the preferred approach.
        let (u, v) = perpendicular_basis(&preferred);
        let coarse = (5.0 * step).min(PI / 4.0);
        let rings = (PI / coarse).ceil() as usize;
        for k in 1..=rings {
            let cone = (k as f64 * coarse).min(PI);
            let (sc, cc) = cone.sin_cos();
            let count = if k == rings {
                1
            } else {
                ((TAU * sc / coarse).ceil() as usize).max(1)
            };
            let mut best: Option<(f64, IkCandidate)> = None;
            for j in 0..count {
                let phi = TAU * j as f64 / count as f64;
                let (sp, cp) = phi.sin_cos();
                let a = preferred * cc + (u * cp + v * sp) * sc;
                if let Some(c) = attempt(&a) {
                    let d = joint_distance(&c.theta, current);
                    if best.is_none_or(|(bd, _)| d < bd) {
                        best = Some((d, c));
                    }
                }
            }
            if let Some((_, c)) = best {
                return Ok(c);
            }
        }
        if from_circle > 1e-12 {
            let c = radial * self.l1;
            let toward = (position - c) / from_circle;
            if let Some(c) = attempt_with(&toward, options) {
                return Ok(c);
            }
        }
        if any_exact.get() {
            Err(PioneerIkError::OutsideJointLimits)
        } else {
            Err(PioneerIkError::OutOfReach {
                distance: from_circle,
                min: 0.0,
                max,
            })
        }
    }
}

/// Most approaches the yaw-limit scan of [`PioneerGeometry::solve_position`] orders
/// before trying them (both circles; 720 at the default 1° step). A finer step scans
/// in angle order instead, keeping the best.
const CIRCLE_SCAN_CAPACITY: usize = 1024;

/// The cosines and sines of j·`step` for j < `len` (at most half of
/// [`CIRCLE_SCAN_CAPACITY`]), as `(cos, sin)`.
fn step_trig(step: f64, len: usize) -> [(f64, f64); CIRCLE_SCAN_CAPACITY / 2] {
    let mut t = [(0.0, 0.0); CIRCLE_SCAN_CAPACITY / 2];
    for (j, t) in t.iter_mut().enumerate().take(len) {
        let psi = j as f64 * step;
        *t = (psi.cos(), psi.sin());
    }
    t
}

/// [`step_trig`] of the default search step for the whole table, made once per
/// process; `None` for any other step.
fn default_step_trig(step: f64) -> Option<&'static [(f64, f64); CIRCLE_SCAN_CAPACITY / 2]> {
    static TABLE: OnceLock<[(f64, f64); CIRCLE_SCAN_CAPACITY / 2]> = OnceLock::new();
    let default = PioneerIkOptions::default().approach_search_step;
    (step.to_bits() == default.to_bits())
        .then(|| TABLE.get_or_init(|| step_trig(default, CIRCLE_SCAN_CAPACITY / 2)))
}

/// Bisection between an elevation `good` that passes `test` (with what it returned)
/// and one `bad` that does not, until they are 1e-9 rad apart: the last elevation
/// that passed, and what `test` returned there.
fn bisect<T>(mut good: (f64, T), mut bad: f64, mut test: impl FnMut(f64) -> Option<T>) -> (f64, T) {
    for _ in 0..64 {
        if (good.0 - bad).abs() <= 1e-9 {
            break;
        }
        let mid = 0.5 * (good.0 + bad);
        match test(mid) {
            Some(t) => good = (mid, t),
            None => bad = mid,
        }
    }
    good
}

/// Approaches of the yaw-limit scan ordered at a time: the best this many, then the
/// next, ... (the order is that of a full sort).
const CIRCLE_CHUNK: usize = 48;

/// Two unit vectors that complete `a` (a unit vector) to an orthonormal basis.
fn perpendicular_basis(a: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let helper = if a.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let u = a.cross(&helper).normalize();
    let v = a.cross(&u);
    (u, v)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table shared by the searches at the default step is that step's cosines
    /// and sines, bit for bit (the yaw-limit scan then orders the approaches a full
    /// scan would); another step gets none.
    #[test]
    fn the_default_step_table_is_that_steps_trigonometry() {
        let step = PioneerIkOptions::default().approach_search_step;
        let table = default_step_trig(step).expect("the default step has a table");
        for (j, &(c, s)) in table.iter().enumerate() {
            let psi = j as f64 * step;
            assert_eq!(c.to_bits(), psi.cos().to_bits(), "cos at {j}");
            assert_eq!(s.to_bits(), psi.sin().to_bits(), "sin at {j}");
        }
        assert!(default_step_trig(step * 0.5).is_none());
        assert!(default_step_trig(f64::from_bits(step.to_bits() + 1)).is_none());
        let half = step_trig(step * 0.5, 3);
        assert_eq!(half[2], (step.cos(), step.sin()));
        assert_eq!(half[3], (0.0, 0.0));
    }
}
