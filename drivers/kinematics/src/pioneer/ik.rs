//! The closed-form Pioneer IK (Gan, Oyama, Rosales, Hu, Robotica 2005): for a wrist
//! centre, up to two base yaws × two elbows (plus, near a straight or folded elbow, a
//! variant with θ2+θ3 taken from the frame), and for each either the wrist that attains
//! a full frame (SETPOSE) or the two wrists that attain an approach vector. Every
//! candidate is scored by the FK error and marked for the limits; [`IkCandidates::select`]
//! picks among them deterministically.

use std::f64::consts::{FRAC_PI_2, PI, TAU};
use std::ops::ControlFlow;

use nalgebra::Vector3;

use super::fk::Trig;
use super::{
    LIMIT_TOLERANCE, MAX_CANDIDATES, PIONEER_DOF, PioneerGeometry, PioneerIkError,
    PioneerIkOptions, Theta, joint_distance, vector_angle,
};
use crate::pose::{FrameError, Pose, all_finite, fit_angle_to_limits, wrap_pi};

/// Base yaw branch: θ1 points the shoulder towards the wrist (front) or away (back,
/// reaching over the top).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Shoulder {
    /// θ1 = atan2(w_y, w_x).
    Front,
    /// θ1 = atan2(w_y, w_x) ± π.
    Back,
}

/// Elbow branch.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Elbow {
    /// θ3 ≥ 0: the elbow lies below the shoulder–wrist line (Player's branch 1).
    Down,
    /// θ3 < 0: the elbow lies above it (Player's branch 2).
    Up,
}

/// Wrist branch (SETPOSITION only; SETPOSE fixes the wrist from the full frame).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrist {
    /// θ5 ≥ 0.
    Normal,
    /// The alternative (θ4 ± π, −θ5), same approach, roll flipped by π.
    Flipped,
}

/// Which closed-form branch a candidate came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Branch {
    /// Base yaw branch.
    pub shoulder: Shoulder,
    /// Elbow branch.
    pub elbow: Elbow,
    /// Wrist branch.
    pub wrist: Wrist,
}

/// One closed-form IK candidate and how well it does.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct IkCandidate {
    /// Joint angles θ1..θ5. Angles inside the limits are the representative (mod 2π)
    /// nearest to the current joints; the others are wrapped into (−π, π].
    pub theta: Theta,
    /// The branch.
    pub branch: Branch,
    /// Every angle lies inside its limit (with [`LIMIT_TOLERANCE`]).
    pub within_limits: bool,
    /// Distance between the FK of `theta` and the requested position, m (computed
    /// before an angle is clamped onto its limit, which moves it by at most
    /// [`LIMIT_TOLERANCE`]).
    pub position_error: f64,
    /// Orientation error of the FK of `theta`, rad (approach error for SETPOSITION).
    pub orientation_error: f64,
}

const EMPTY_BRANCH: Branch = Branch {
    shoulder: Shoulder::Front,
    elbow: Elbow::Down,
    wrist: Wrist::Normal,
};

const EMPTY_CANDIDATE: IkCandidate = IkCandidate {
    theta: [0.0; PIONEER_DOF],
    branch: EMPTY_BRANCH,
    within_limits: false,
    position_error: f64::INFINITY,
    orientation_error: f64::INFINITY,
};

/// All candidates of one closed-form solve (fixed capacity, no allocation).
#[derive(Clone, Copy, Debug)]
pub struct IkCandidates {
    len: usize,
    items: [IkCandidate; MAX_CANDIDATES],
}

impl IkCandidates {
    fn new() -> Self {
        Self {
            len: 0,
            items: [EMPTY_CANDIDATE; MAX_CANDIDATES],
        }
    }

    fn push(&mut self, c: IkCandidate) {
        if self.len < MAX_CANDIDATES {
            self.items[self.len] = c;
            self.len += 1;
        }
    }

    /// The candidates, in branch order (front before back, elbow down before up,
    /// normal wrist before flipped).
    pub fn as_slice(&self) -> &[IkCandidate] {
        &self.items[..self.len]
    }

    /// Number of candidates.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True when there is no candidate.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// The candidate that reaches the target within the tolerances, lies inside the
    /// limits and is nearest (Euclidean, in θ) to `current`; ties go to the lower index.
    /// Candidates that reproduce the target to round-off ([`EXACT_POSITION`],
    /// [`EXACT_ORIENTATION`]) are preferred; only when no exact one lies inside the
    /// limits is one that is merely within the tolerances chosen (near a singularity,
    /// or for a slightly inconsistent target), and then the most accurate one (smallest
    /// sum of the errors relative to their tolerances).
    pub fn select(
        &self,
        current: &Theta,
        options: &PioneerIkOptions,
    ) -> Result<IkCandidate, PioneerIkError> {
        let mut best: [Option<(f64, IkCandidate)>; 2] = [None, None];
        let mut any_acceptable = false;
        let mut min_orientation = f64::INFINITY;
        for c in self.as_slice() {
            let acceptable = c.position_error <= options.position_tolerance
                && c.orientation_error <= options.orientation_tolerance;
            let exact =
                c.position_error <= EXACT_POSITION && c.orientation_error <= EXACT_ORIENTATION;
            min_orientation = min_orientation.min(c.orientation_error);
            any_acceptable |= acceptable;
            if acceptable && c.within_limits {
                // Exact tier: nearest to current. Other tier: most accurate.
                let (tier, score) = if exact {
                    (&mut best[0], joint_distance(&c.theta, current))
                } else {
                    (
                        &mut best[1],
                        c.position_error / options.position_tolerance
                            + c.orientation_error / options.orientation_tolerance,
                    )
                };
                if tier.is_none_or(|(bs, _)| score < bs) {
                    *tier = Some((score, *c));
                }
            }
        }
        match best {
            [Some((_, c)), _] | [None, Some((_, c))] => Ok(c),
            [None, None] if any_acceptable => Err(PioneerIkError::OutsideJointLimits),
            [None, None] => Err(PioneerIkError::UnreachableOrientation {
                error: min_orientation,
            }),
        }
    }
}

/// Position error, m, below which a candidate counts as exact (round-off).
pub const EXACT_POSITION: f64 = 1e-10;

/// Orientation error, rad, below which a candidate counts as exact (round-off).
pub const EXACT_ORIENTATION: f64 = 1e-10;

/// One shoulder-and-elbow solution with the sines and cosines the FK check needs.
#[derive(Clone, Copy)]
struct Arm {
    elbow: Elbow,
    t2: f64,
    t3: f64,
    s2: f64,
    c2: f64,
    s23: f64,
    c23: f64,
}

impl Default for Arm {
    fn default() -> Self {
        Self {
            elbow: Elbow::Down,
            t2: 0.0,
            t3: 0.0,
            s2: 0.0,
            c2: 1.0,
            s23: 0.0,
            c23: 1.0,
        }
    }
}

/// √(a² + b²): the plain formula for the arm's lengths and unit vectors' components,
/// `hypot` (slower: it guards every call) only when the squares overflow or underflow.
#[inline]
fn hyp(a: f64, b: f64) -> f64 {
    let s = a * a + b * b;
    if s.is_finite() && s >= f64::MIN_POSITIVE {
        s.sqrt()
    } else {
        a.hypot(b)
    }
}

/// (sin, cos) of `atan2(y, x)` by normalisation; (0, 1) for the zero vector, as
/// `atan2(0, 0) = 0`.
pub(super) fn unit(y: f64, x: f64) -> (f64, f64) {
    let h = hyp(y, x);
    if h > 0.0 { (y / h, x / h) } else { (0.0, 1.0) }
}

/// One closed-form solution before the FK scores it.
pub(super) struct Solution {
    theta: Theta,
    branch: Branch,
    within_limits: bool,
    trig: Trig,
}

/// What [`PioneerGeometry::reach_with_approach`] found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Reach {
    /// A solution inside the limits.
    Within,
    /// Solutions, all outside the limits.
    Outside,
    /// No solution (the wrist centre is outside its annulus).
    None,
}

/// One joint's limits (widened by [`LIMIT_TOLERANCE`]) as an arc of the circle.
#[derive(Clone, Copy, Debug)]
struct LimitArc {
    sin_lo: f64,
    cos_lo: f64,
    cos_len: f64,
    len: f64,
}

/// The joint limits as arcs: an angle given by its sine and cosine is tested without
/// an inverse trigonometric function, modulo 2π like [`fit_angle_to_limits`].
#[derive(Clone, Copy, Debug)]
pub(super) struct LimitArcs([LimitArc; PIONEER_DOF]);

impl LimitArcs {
    /// Whether the angle of joint `i` with sine `s` and cosine `c` lies on its arc.
    fn contains(&self, i: usize, s: f64, c: f64) -> bool {
        let arc = &self.0[i];
        if arc.len >= TAU {
            return true;
        }
        // The angle from the arc's start, δ in [0, 2π): its sine and cosine.
        let sd = s * arc.cos_lo - c * arc.sin_lo;
        let cd = c * arc.cos_lo + s * arc.sin_lo;
        if sd >= 0.0 {
            // δ in [0, π], where the cosine falls.
            arc.len >= PI || cd >= arc.cos_len
        } else {
            // δ in (π, 2π), where it rises.
            arc.len > PI && cd <= arc.cos_len
        }
    }
}

/// Which wrist solution to compute.
#[derive(Clone, Copy)]
pub(super) enum WristGoal<'a> {
    /// Full frame: the wrist roll comes from the normal, the pitch from the approach.
    Frame(&'a Pose),
    /// Approach only: two wrist solutions, the roll follows.
    Approach(&'a Vector3<f64>),
}

impl PioneerGeometry {
    /// All closed-form candidates for a full pose (SETPOSE) relative to the arm base:
    /// up to 4 (2 base yaws × 2 elbows; up to 8 within 1e-3 rad of a straight or folded
    /// elbow, where a variant with θ2+θ3 taken from the frame is added), each scored by
    /// the FK error and marked for the limits. `current` only picks the 2π representative of each angle and the base
    /// yaw when the wrist centre is on the yaw axis.
    pub fn pose_candidates(
        &self,
        target: &Pose,
        current: &Theta,
        options: &PioneerIkOptions,
    ) -> Result<IkCandidates, PioneerIkError> {
        self.check_inputs(current, options)?;
        if !target.is_finite() {
            return Err(PioneerIkError::NonFinite);
        }
        self.candidates(
            &target.position,
            WristGoal::Frame(target),
            current,
            options.position_tolerance,
            false,
        )
    }

    /// SETPOSE: the joints (θ) that put the end effector at `target` (relative to the
    /// arm base), inside the limits, nearest to `current`.
    pub fn solve_pose(
        &self,
        target: &Pose,
        current: &Theta,
        options: &PioneerIkOptions,
    ) -> Result<IkCandidate, PioneerIkError> {
        self.pose_candidates(target, current, options)?
            .select(current, options)
    }

    /// SETPOSE as Player's limb sends it: position in the **robot** frame, approach
    /// and orientation vectors (normalised here; they must be perpendicular within
    /// `orientation_tolerance`).
    pub fn solve_setpose(
        &self,
        position_robot: &Vector3<f64>,
        approach: &Vector3<f64>,
        orientation: &Vector3<f64>,
        current: &Theta,
        options: &PioneerIkOptions,
    ) -> Result<IkCandidate, PioneerIkError> {
        options.check()?;
        let pose = Pose::from_approach_orientation(
            *position_robot,
            *approach,
            *orientation,
            options.orientation_tolerance,
        )?;
        self.solve_pose(&self.robot_to_base(&pose), current, options)
    }

    /// All candidates for a position (relative to the arm base) with a given approach
    /// vector and free wrist roll: up to 8 (2 yaws × 2 elbows × 2 wrists).
    pub fn approach_candidates(
        &self,
        position: &Vector3<f64>,
        approach: &Vector3<f64>,
        current: &Theta,
        options: &PioneerIkOptions,
    ) -> Result<IkCandidates, PioneerIkError> {
        self.check_inputs(current, options)?;
        if !(all_finite(position) && all_finite(approach)) {
            return Err(PioneerIkError::NonFinite);
        }
        if approach.norm() < 1e-12 {
            return Err(FrameError::ZeroApproach.into());
        }
        // Scaled before it is normalised: a finite vector whose norm overflows is long.
        let a = crate::pose::unit_direction(approach).ok_or(FrameError::ZeroApproach)?;
        self.candidates(
            position,
            WristGoal::Approach(&a),
            current,
            options.position_tolerance,
            false,
        )
    }

    /// SETPOSITION with a given approach vector (relative to the arm base; the wrist
    /// roll follows from the arm's structure): the in-limit solution nearest `current`.
    pub fn solve_position_approach(
        &self,
        position: &Vector3<f64>,
        approach: &Vector3<f64>,
        current: &Theta,
        options: &PioneerIkOptions,
    ) -> Result<IkCandidate, PioneerIkError> {
        self.approach_candidates(position, approach, current, options)?
            .select(current, options)
    }

    /// Closed-form candidates, each scored by the FK. `tol` widens the reachable
    /// annulus of the wrist centre. With `in_limits_only`, see [`Self::solutions`].
    pub(super) fn candidates(
        &self,
        p: &Vector3<f64>,
        goal: WristGoal<'_>,
        current: &Theta,
        tol: f64,
        in_limits_only: bool,
    ) -> Result<IkCandidates, PioneerIkError> {
        let mut out = IkCandidates::new();
        self.solutions(p, goal, current, tol, in_limits_only, |s| {
            let fk = self.fk_trig(&s.trig);
            let position_error = (fk.position - p).norm();
            let orientation_error = match goal {
                WristGoal::Frame(pose) => fk.orientation_error(pose),
                WristGoal::Approach(a) => vector_angle(&fk.approach(), a),
            };
            let ok = |v: f64| if v.is_finite() { v } else { f64::INFINITY };
            out.push(IkCandidate {
                theta: s.theta,
                branch: s.branch,
                within_limits: s.within_limits,
                position_error: ok(position_error),
                orientation_error: ok(orientation_error),
            });
            ControlFlow::Continue(())
        })?;
        Ok(out)
    }

    /// Whether an approach vector `a` (unit) attains the position `p` in closed form,
    /// like [`Self::candidates`] but without scoring the candidates by the FK (the
    /// closed form is exact to round-off wherever the wrist centre lies within `tol`
    /// of its annulus) and without an inverse trigonometric function: the limits are
    /// tested on the sines and cosines ([`LimitArcs`]). `Within` as soon as one
    /// candidate lies inside the limits; with `in_limits_only`, `Within` or `None`.
    pub(super) fn reach_with_approach(
        &self,
        p: &Vector3<f64>,
        a: &Vector3<f64>,
        current: &Theta,
        tol: f64,
        in_limits_only: bool,
        arcs: &LimitArcs,
    ) -> Reach {
        let w = p - a * self.l5;
        let h = hyp(w.x, w.y);
        let (sy, cy) = if h < 1e-12 {
            current[0].sin_cos()
        } else {
            (w.y / h, w.x / h)
        };
        let (dmin, dmax) = self.wrist_reach();
        let mut reach = Reach::None;
        for (s1, c1) in [(sy, cy), (-sy, -cy)] {
            // The yaw first: it is cheaper than the reach.
            let in1 = arcs.contains(0, s1, c1);
            if in_limits_only && !in1 {
                continue;
            }
            let r = c1 * w.x + s1 * w.y - self.l1;
            let z = w.z;
            let d = hyp(r, z);
            if d > dmax + tol || d < dmin - tol {
                continue;
            }
            let (_, (sg, cg)) = self.elbow_half_angle(d);
            let (sa, ca) = unit(z, r);
            for (s3, c3) in [(sg, cg), (-sg, cg)] {
                let (s2, c2) = self.shoulder_pitch((sa, ca), s3, c3);
                let in123 = in1 && arcs.contains(1, s2, c2) && arcs.contains(2, s3, c3);
                if in_limits_only && !in123 {
                    continue;
                }
                let (s23, c23) = (s2 * c3 + c2 * s3, c2 * c3 - s2 * s3);
                // The approach in the forearm frame (see `solutions`).
                let al = Vector3::new(
                    c23 * (c1 * a.x + s1 * a.y) + s23 * a.z,
                    -s1 * a.x + c1 * a.y,
                    -s23 * (c1 * a.x + s1 * a.y) + c23 * a.z,
                );
                let s5 = hyp(al.y, al.z);
                let (s4, c4) = if s5 < 1e-12 {
                    current[3].sin_cos()
                } else {
                    (-al.y / s5, al.z / s5)
                };
                let (ss5, cs5) = unit(s5, al.x);
                for (s4, c4, s5, c5) in [(s4, c4, ss5, cs5), (-s4, -c4, -ss5, cs5)] {
                    if in123 && arcs.contains(3, s4, c4) && arcs.contains(4, s5, c5) {
                        return Reach::Within;
                    }
                    if !in_limits_only {
                        reach = Reach::Outside;
                    }
                }
            }
        }
        reach
    }

    /// The limits as arcs, for [`Self::reach_with_approach`].
    pub(super) fn limit_arcs(&self) -> LimitArcs {
        LimitArcs(self.limits.map(|l| {
            let lo = l.min - LIMIT_TOLERANCE;
            let len = (l.max - l.min) + 2.0 * LIMIT_TOLERANCE;
            let (s, c) = lo.sin_cos();
            LimitArc {
                sin_lo: s,
                cos_lo: c,
                cos_len: len.cos(),
                len,
            }
        }))
    }

    /// The elbow for a wrist centre at distance `d` from the shoulder: two numbers
    /// whose ratio is tan(|θ3|/2) (|θ3| = 2·atan2 of them), and the sine and cosine
    /// of |θ3|. By the half-angle formula, tan²(θ3/2) = (1 − c3)/(1 + c3) with
    /// 1 − c3 = ((L2+L4)² − d²)/(2·L2·L4) and 1 + c3 = (d² − (L2−L4)²)/(2·L2·L4),
    /// each factored so that it keeps its precision near the straight (and the
    /// folded) elbow, where acos(c3) would lose half the digits; the sine and cosine
    /// come from the same quantities (no transcendental function).
    fn elbow_half_angle(&self, d: f64) -> ((f64, f64), (f64, f64)) {
        let (dmin, dmax) = self.wrist_reach();
        let one_minus = (dmax - d).max(0.0) * (dmax + d);
        let one_plus = (d - dmin).max(0.0) * (d + dmin);
        let pm = one_plus + one_minus;
        let trig = if pm > 0.0 {
            (
                2.0 * (one_minus * one_plus).sqrt() / pm,
                (one_plus - one_minus) / pm,
            )
        } else {
            (0.0, 1.0)
        };
        ((one_minus.sqrt(), one_plus.sqrt()), trig)
    }

    /// Sine and cosine of θ2 for the elbow (`s3`, `c3`) and the direction (`sa`, `ca`)
    /// of the wrist centre from the shoulder: θ2 = atan2(z, r) − atan2(L4·s3,
    /// L2 + L4·c3), by the difference formulas.
    fn shoulder_pitch(&self, (sa, ca): (f64, f64), s3: f64, c3: f64) -> (f64, f64) {
        let (sb, cb) = unit(self.l4 * s3, self.l2 + self.l4 * c3);
        (sa * cb - ca * sb, ca * cb + sa * sb)
    }

    /// The closed-form solutions for a wrist centre, each handed to `visit` (which may
    /// stop the walk) with the sines and cosines the FK needs. Fails with
    /// [`PioneerIkError::OutOfReach`] when none was visited. With `in_limits_only`,
    /// solutions with an angle outside its limit are dropped as soon as that angle is
    /// known (before the FK check that scores them): the SETPOSITION search uses it
    /// once it knows that exact solutions exist, when only the in-limit candidates
    /// can change its answer.
    fn solutions(
        &self,
        p: &Vector3<f64>,
        goal: WristGoal<'_>,
        current: &Theta,
        tol: f64,
        in_limits_only: bool,
        mut visit: impl FnMut(&Solution) -> ControlFlow<()>,
    ) -> Result<(), PioneerIkError> {
        let a = match goal {
            WristGoal::Frame(pose) => pose.approach(),
            WristGoal::Approach(a) => *a,
        };
        let w = p - a * self.l5;
        let h = hyp(w.x, w.y);
        let yaw = if h < 1e-12 {
            current[0]
        } else {
            w.y.atan2(w.x)
        };
        let (dmin, dmax) = self.wrist_reach();
        let mut visited = 0usize;
        let mut front_distance = f64::NAN;
        let in_limit = |i: usize, v: f64| {
            let l = self.limits[i];
            fit_angle_to_limits(v, l.min, l.max, current[i], LIMIT_TOLERANCE).is_some()
        };
        'walk: for (shoulder, t1) in [(Shoulder::Front, yaw), (Shoulder::Back, wrap_pi(yaw + PI))] {
            let (s1, c1) = t1.sin_cos();
            let r = c1 * w.x + s1 * w.y - self.l1;
            let z = w.z;
            let d = hyp(r, z);
            if shoulder == Shoulder::Front {
                front_distance = d;
            }
            if d > dmax + tol || d < dmin - tol {
                continue;
            }
            if in_limits_only && !in_limit(0, t1) {
                continue;
            }
            let ((root_minus, root_plus), (sg, cg)) = self.elbow_half_angle(d);
            let g = 2.0 * root_minus.atan2(root_plus);
            let (sa, ca) = unit(z, r);
            let mut arms = [Arm::default(); 4];
            let mut n_arms = 0;
            for (elbow, t3, s3, c3) in [(Elbow::Down, g, sg, cg), (Elbow::Up, -g, -sg, cg)] {
                let (s2, c2) = self.shoulder_pitch((sa, ca), s3, c3);
                let t2 = s2.atan2(c2);
                arms[n_arms] = Arm {
                    elbow,
                    t2,
                    t3,
                    s2,
                    c2,
                    s23: s2 * c3 + c2 * s3,
                    c23: c2 * c3 - s2 * s3,
                };
                n_arms += 1;
                // Near a straight (or folded) elbow the position fixes θ2+θ3 only to
                // about √ε; a full frame fixes it better whenever the wrist rolls
                // (n·forearm = 0 gives (s4·s23, s4·c23) = (−(c1·n_x + s1·n_y), n_z)).
                // Add that variant; the FK check and the selection keep the better one.
                if let WristGoal::Frame(pose) = goal {
                    let n = pose.normal();
                    let (ax, bx) = (-(c1 * n.x + s1 * n.y), n.z);
                    if s3.abs() < 1e-3 && hyp(ax, bx) > 1e-2 {
                        let mut t23 = ax.atan2(bx);
                        if wrap_pi(t23 - (t2 + t3)).abs() > FRAC_PI_2 {
                            t23 = wrap_pi(t23 + PI);
                        }
                        let (s23, c23) = t23.sin_cos();
                        let (s2, c2) = unit(z - self.l4 * s23, r - self.l4 * c23);
                        let t2 = s2.atan2(c2);
                        arms[n_arms] = Arm {
                            elbow,
                            t2,
                            t3: wrap_pi(t23 - t2),
                            s2,
                            c2,
                            s23,
                            c23,
                        };
                        n_arms += 1;
                    }
                }
            }
            for arm in &arms[..n_arms] {
                let Arm {
                    elbow,
                    t2,
                    t3,
                    s2,
                    c2,
                    s23,
                    c23,
                } = *arm;
                if in_limits_only && !(in_limit(1, t2) && in_limit(2, t3)) {
                    continue;
                }
                // Columns of R0 = Rz(θ1)·Ry(−θ23).
                let fx = Vector3::new(c1 * c23, s1 * c23, s23);
                let fy = Vector3::new(-s1, c1, 0.0);
                let fz = Vector3::new(-c1 * s23, -s1 * s23, c23);
                let local = |v: &Vector3<f64>| Vector3::new(fx.dot(v), fy.dot(v), fz.dot(v));
                let al = local(&a);
                let mut push =
                    |t4: f64, (s4, c4): (f64, f64), t5: f64, (s5, c5): (f64, f64), wrist| {
                        let mut theta = [t1, t2, t3, wrap_pi(t4), wrap_pi(t5)];
                        let mut within = true;
                        for i in 0..PIONEER_DOF {
                            let l = self.limits[i];
                            match fit_angle_to_limits(
                                theta[i],
                                l.min,
                                l.max,
                                current[i],
                                LIMIT_TOLERANCE,
                            ) {
                                Some(v) => theta[i] = v,
                                None => within = false,
                            }
                        }
                        if in_limits_only && !within {
                            return ControlFlow::Continue(());
                        }
                        visited += 1;
                        visit(&Solution {
                            theta,
                            branch: Branch {
                                shoulder,
                                elbow,
                                wrist,
                            },
                            within_limits: within,
                            trig: Trig {
                                s1,
                                c1,
                                s2,
                                c2,
                                s23,
                                c23,
                                s4,
                                c4,
                                s5,
                                c5,
                            },
                        })
                    };
                match goal {
                    WristGoal::Frame(pose) => {
                        let nl = local(&pose.normal());
                        let t4 = nl.z.atan2(nl.y);
                        let (s4, c4) = unit(nl.z, nl.y);
                        // v = Rx(θ4)ᵀ·a_local = (c5, 0, s5) for a consistent frame.
                        let vx = al.x;
                        let vz = -s4 * al.y + c4 * al.z;
                        if push(t4, (s4, c4), vz.atan2(vx), unit(vz, vx), Wrist::Normal).is_break()
                        {
                            break 'walk;
                        }
                    }
                    WristGoal::Approach(_) => {
                        let s5 = hyp(al.y, al.z);
                        let t5 = s5.atan2(al.x);
                        let (t4, (s4, c4)) = if s5 < 1e-12 {
                            (current[3], current[3].sin_cos())
                        } else {
                            ((-al.y).atan2(al.z), (-al.y / s5, al.z / s5))
                        };
                        let (ss5, cs5) = unit(s5, al.x);
                        if push(t4, (s4, c4), t5, (ss5, cs5), Wrist::Normal).is_break()
                            || push(t4 + PI, (-s4, -c4), -t5, (-ss5, cs5), Wrist::Flipped)
                                .is_break()
                        {
                            break 'walk;
                        }
                    }
                }
            }
        }
        if visited == 0 {
            return Err(PioneerIkError::OutOfReach {
                distance: front_distance,
                min: dmin,
                max: dmax,
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests;
