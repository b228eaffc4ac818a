//! The Pioneer 5-DOF arm in closed form (Gan, Oyama, Rosales, Hu, Robotica 2005), with
//! the sign of Player's FK corrected, explicit reach and orientation checks, joint
//! limits in the kinematic convention, deterministic branch choice, SETPOSE,
//! SETPOSITION and a straight-line VECMOVE planner. Nothing here allocates.
//!
//! Angles are the *kinematic* θ1..θ5 (see the module docs of
//! [`crate`]): θ1 base yaw about +z; θ2 shoulder and θ3 elbow pitch about −y
//! (positive lifts); θ4 wrist roll about the forearm; θ5 wrist pitch about −y. The
//! gripper (P2OS joint 6) is not part of the kinematics. Positions are relative to the
//! arm base unless a function says "robot".
//!
//! # Tolerances
//!
//! A solution is accepted when the FK of the returned angles is within
//! [`PioneerIkOptions::position_tolerance`] (default 1 µm) of the requested position and
//! within [`PioneerIkOptions::orientation_tolerance`] (default 1 µrad) of the requested
//! orientation (the angle of the rotation between the requested and the achieved frame;
//! for SETPOSITION, the angle between the requested and the achieved approach vector).
//! A 5-DOF arm reaches only frames whose normal `n` is perpendicular to its forearm; a
//! request that misses that by more than the tolerance is
//! [`PioneerIkError::UnreachableOrientation`], never silently approximated. The wrist
//! centre is accepted up to `position_tolerance` outside the annulus
//! `|L2 − L4| ≤ d ≤ L2 + L4` (the acos argument is clamped only then). Joint limits are
//! inclusive and accept round-off up to [`LIMIT_TOLERANCE`] (the returned angle is then
//! clamped onto the limit).

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use nalgebra::{Matrix3, Rotation3, Vector3};

use super::pose::{FrameError, Pose, all_finite, fit_angle_to_limits, unit_direction, wrap_pi};

/// Number of arm joints in the kinematics (the gripper is not one of them).
pub const PIONEER_DOF: usize = 5;

/// Kinematic joint angles θ1..θ5, radians.
pub type Theta = [f64; PIONEER_DOF];

/// Round-off accepted at a joint limit, radians.
pub const LIMIT_TOLERANCE: f64 = 1e-9;

/// Most candidates any Pioneer IK returns (2 base yaws × 2 elbows × 2 wrists).
pub const MAX_CANDIDATES: usize = 8;

/// An inclusive joint range, radians, in the kinematic convention.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointLimit {
    /// Lower bound.
    pub min: f64,
    /// Upper bound.
    pub max: f64,
}

impl JointLimit {
    /// A range; `min` should not exceed `max` ([`PioneerGeometry::validate`] checks).
    pub const fn new(min: f64, max: f64) -> Self {
        Self { min, max }
    }

    /// True when `v` lies in `[min, max]`.
    pub fn contains(&self, v: f64) -> bool {
        v >= self.min && v <= self.max
    }
}

/// The arm's geometry: link lengths (Gan et al. notation; L3 is zero and absent), the
/// base offset in the robot frame and the joint limits in θ.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PioneerGeometry {
    /// Horizontal offset from the yaw axis to the shoulder, m (0.06875).
    pub l1: f64,
    /// Upper arm, shoulder to elbow, m (0.16).
    pub l2: f64,
    /// Forearm, elbow to wrist, m (0.13775).
    pub l4: f64,
    /// Wrist to the end-effector point along the approach vector, m (0.11321).
    pub l5: f64,
    /// Arm base origin in the robot frame, m ((0.105, 0, 0.3185); no rotation).
    pub base_offset: Vector3<f64>,
    /// Joint limits θ1..θ5 in the kinematic convention, rad. The default ±π/2 is a
    /// placeholder: the driver should set them from ARMINFO with
    /// [`DriverAngleMap::limits_from_driver`].
    pub limits: [JointLimit; PIONEER_DOF],
}

impl Default for PioneerGeometry {
    fn default() -> Self {
        Self {
            l1: 0.06875,
            l2: 0.16,
            l4: 0.13775,
            l5: 0.11321,
            base_offset: Vector3::new(0.105, 0.0, 0.3185),
            limits: [JointLimit::new(-FRAC_PI_2, FRAC_PI_2); PIONEER_DOF],
        }
    }
}

/// Invalid [`PioneerGeometry`].
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum GeometryError {
    /// A link length or the base offset is NaN, infinite or negative, or L2/L4 is zero.
    #[error("invalid link length or base offset: {0}")]
    Link(&'static str),
    /// Joint `joint` (0-based) has a non-finite limit or min > max.
    #[error("invalid limits for joint {joint}")]
    Limit {
        /// 0-based joint index.
        joint: usize,
    },
}

/// Error of [`PioneerGeometry::fk`].
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum PioneerFkError {
    /// A joint angle was NaN or infinite.
    #[error("joint angle is NaN or infinite")]
    NonFinite,
}

/// Why a Pioneer IK request (SETPOSE, SETPOSITION) failed. The last three variants are
/// all "out of reach" for the limb interface ([`PioneerIkError::is_out_of_reach`]).
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum PioneerIkError {
    /// The target, the current joints or a vector was NaN or infinite.
    #[error("input contains NaN or an infinite value")]
    NonFinite,
    /// The geometry is invalid.
    #[error(transparent)]
    Geometry(#[from] GeometryError),
    /// A tolerance or search step in the options is not a finite positive number.
    #[error("invalid IK options")]
    InvalidOptions,
    /// Approach/orientation vectors do not make a frame.
    #[error(transparent)]
    Frame(#[from] FrameError),
    /// The target is geometrically out of reach: `distance` (from the shoulder to the
    /// wrist centre for SETPOSE; from the shoulder circle to the target for
    /// SETPOSITION) is outside `[min, max]` by more than the position tolerance.
    #[error("out of reach: distance {distance} m outside [{min}, {max}] m")]
    OutOfReach {
        /// Distance that failed, m.
        distance: f64,
        /// Smallest reachable distance, m.
        min: f64,
        /// Largest reachable distance, m.
        max: f64,
    },
    /// The position is reachable but no arm configuration attains the requested
    /// orientation (or approach) within the tolerance: `error` is the smallest
    /// orientation error, rad, among the candidates.
    #[error("orientation unreachable by the 5-DOF arm (best error {error} rad)")]
    UnreachableOrientation {
        /// Smallest orientation error among the candidates, rad.
        error: f64,
    },
    /// Exact solutions exist but none has every joint inside its limits.
    #[error("every exact solution violates a joint limit")]
    OutsideJointLimits,
}

impl PioneerIkError {
    /// True for the errors that mean "the arm cannot get there" (the limb's OOR
    /// state): out of reach, unreachable orientation and outside the joint limits.
    pub fn is_out_of_reach(&self) -> bool {
        matches!(
            self,
            Self::OutOfReach { .. }
                | Self::UnreachableOrientation { .. }
                | Self::OutsideJointLimits
        )
    }
}

/// Options of the Pioneer IK. See the module docs for what the tolerances mean.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PioneerIkOptions {
    /// Accepted distance between the requested and the achieved position, m (1e-6).
    pub position_tolerance: f64,
    /// Accepted orientation (or approach) error, rad (1e-6). Also the accepted
    /// deviation from perpendicular of Player's approach and orientation vectors.
    pub orientation_tolerance: f64,
    /// SETPOSITION approach search step, rad (1° = 0.01745); see
    /// [`PioneerGeometry::solve_position`].
    pub approach_search_step: f64,
}

impl Default for PioneerIkOptions {
    fn default() -> Self {
        Self {
            position_tolerance: 1e-6,
            orientation_tolerance: 1e-6,
            approach_search_step: 1f64.to_radians(),
        }
    }
}

impl PioneerIkOptions {
    fn check(&self) -> Result<(), PioneerIkError> {
        let ok = |v: f64| v.is_finite() && v > 0.0;
        if ok(self.position_tolerance)
            && ok(self.orientation_tolerance)
            && ok(self.approach_search_step)
        {
            Ok(())
        } else {
            Err(PioneerIkError::InvalidOptions)
        }
    }
}

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

/// Maps between the driver's actarray joint angles (radians, as the P2OS layer reports
/// them) and the kinematic θ: θ1 = −(j0−off0), θ2 = j1−off1, θ3 = j2−off2,
/// θ4 = −(j3−off3), θ5 = −(j4−off4). This is the only place that knows the signs.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DriverAngleMap {
    /// The limb offsets off0..off4, rad (default 0).
    pub offsets: [f64; PIONEER_DOF],
}

/// Sign of θi relative to the driver angle.
pub const DRIVER_SIGNS: [f64; PIONEER_DOF] = [-1.0, 1.0, 1.0, -1.0, -1.0];

impl DriverAngleMap {
    /// Driver (actarray) angles j0..j4 → kinematic θ1..θ5.
    pub fn theta_from_driver(&self, driver: &[f64; PIONEER_DOF]) -> Theta {
        std::array::from_fn(|i| DRIVER_SIGNS[i] * (driver[i] - self.offsets[i]))
    }

    /// Kinematic θ1..θ5 → driver (actarray) angles j0..j4.
    pub fn driver_from_theta(&self, theta: &Theta) -> [f64; PIONEER_DOF] {
        std::array::from_fn(|i| DRIVER_SIGNS[i] * theta[i] + self.offsets[i])
    }

    /// Joint limits in θ from the driver's per-joint min and max (as the ARMINFO
    /// geometry reports them, possibly reversed), swapping where needed.
    pub fn limits_from_driver(
        &self,
        min: &[f64; PIONEER_DOF],
        max: &[f64; PIONEER_DOF],
    ) -> [JointLimit; PIONEER_DOF] {
        std::array::from_fn(|i| {
            let a = DRIVER_SIGNS[i] * (min[i] - self.offsets[i]);
            let b = DRIVER_SIGNS[i] * (max[i] - self.offsets[i]);
            JointLimit::new(a.min(b), a.max(b))
        })
    }
}

/// Sines and cosines of θ1, θ2, θ2+θ3, θ4, θ5.
#[derive(Clone, Copy)]
struct Trig {
    s1: f64,
    c1: f64,
    s2: f64,
    c2: f64,
    s23: f64,
    c23: f64,
    s4: f64,
    c4: f64,
    s5: f64,
    c5: f64,
}

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

/// (sin, cos) of `atan2(y, x)` by normalisation; (0, 1) for the zero vector, as
/// `atan2(0, 0) = 0`.
fn unit(y: f64, x: f64) -> (f64, f64) {
    let h = y.hypot(x);
    if h > 0.0 { (y / h, x / h) } else { (0.0, 1.0) }
}

/// Which wrist solution to compute.
#[derive(Clone, Copy)]
enum WristGoal<'a> {
    /// Full frame: the wrist roll comes from the normal, the pitch from the approach.
    Frame(&'a Pose),
    /// Approach only: two wrist solutions, the roll follows.
    Approach(&'a Vector3<f64>),
}

impl PioneerGeometry {
    /// Checks link lengths, base offset and limits.
    pub fn validate(&self) -> Result<(), GeometryError> {
        let len_ok = |v: f64| v.is_finite() && v >= 0.0;
        if !(len_ok(self.l1) && len_ok(self.l5)) {
            return Err(GeometryError::Link("l1 and l5 must be finite and >= 0"));
        }
        if !(len_ok(self.l2) && len_ok(self.l4) && self.l2 > 0.0 && self.l4 > 0.0) {
            return Err(GeometryError::Link("l2 and l4 must be finite and > 0"));
        }
        if !all_finite(&self.base_offset) {
            return Err(GeometryError::Link("base offset must be finite"));
        }
        for (joint, l) in self.limits.iter().enumerate() {
            if !(l.min.is_finite() && l.max.is_finite() && l.min <= l.max) {
                return Err(GeometryError::Limit { joint });
            }
        }
        Ok(())
    }

    /// Shoulder-to-wrist-centre distances the arm can span: `(|L2 − L4|, L2 + L4)`.
    pub fn wrist_reach(&self) -> (f64, f64) {
        ((self.l2 - self.l4).abs(), self.l2 + self.l4)
    }

    /// A robot-frame pose expressed relative to the arm base.
    pub fn robot_to_base(&self, pose: &Pose) -> Pose {
        pose.translated(&-self.base_offset)
    }

    /// An arm-base pose expressed in the robot frame.
    pub fn base_to_robot(&self, pose: &Pose) -> Pose {
        pose.translated(&self.base_offset)
    }

    /// True when every θ lies inside its limit.
    pub fn within_limits(&self, theta: &Theta) -> bool {
        theta
            .iter()
            .zip(&self.limits)
            .all(|(t, l)| *t >= l.min - LIMIT_TOLERANCE && *t <= l.max + LIMIT_TOLERANCE)
    }

    /// Forward kinematics relative to the arm base, with the corrected sign
    /// (`a_y = s1c23c5 − c1s4s5 − s1s23c4s5`): R = Rz(θ1)·Ry(−(θ2+θ3))·Rx(θ4)·Ry(−θ5),
    /// p = L5·a + (c1ρ, s1ρ, L2s2 + L4s23) with ρ = L1 + L2c2 + L4c23.
    pub fn fk(&self, theta: &Theta) -> Result<Pose, PioneerFkError> {
        if !theta.iter().all(|t| t.is_finite()) {
            return Err(PioneerFkError::NonFinite);
        }
        Ok(self.fk_raw(theta))
    }

    /// [`fk`](Self::fk) in the robot frame (base offset added).
    pub fn fk_robot(&self, theta: &Theta) -> Result<Pose, PioneerFkError> {
        self.fk(theta).map(|p| self.base_to_robot(&p))
    }

    fn fk_raw(&self, t: &Theta) -> Pose {
        let (s1, c1) = t[0].sin_cos();
        let (s2, c2) = t[1].sin_cos();
        let (s23, c23) = (t[1] + t[2]).sin_cos();
        let (s4, c4) = t[3].sin_cos();
        let (s5, c5) = t[4].sin_cos();
        self.fk_trig(&Trig {
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
        })
    }

    /// FK from the sines and cosines (the IK reuses the ones it already has).
    fn fk_trig(&self, t: &Trig) -> Pose {
        let Trig {
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
        } = *t;
        let n = Vector3::new(-s1 * c4 - c1 * s23 * s4, c1 * c4 - s1 * s23 * s4, c23 * s4);
        let o = Vector3::new(
            -c1 * c23 * s5 + s1 * s4 * c5 - c1 * s23 * c4 * c5,
            -s1 * c23 * s5 - c1 * s4 * c5 - s1 * s23 * c4 * c5,
            -s23 * s5 + c23 * c4 * c5,
        );
        let a = Vector3::new(
            c1 * c23 * c5 + s1 * s4 * s5 - c1 * s23 * c4 * s5,
            s1 * c23 * c5 - c1 * s4 * s5 - s1 * s23 * c4 * s5,
            s23 * c5 + c23 * c4 * s5,
        );
        let rho = self.l1 + self.l2 * c2 + self.l4 * c23;
        let p = a * self.l5 + Vector3::new(c1 * rho, s1 * rho, self.l2 * s2 + self.l4 * s23);
        Pose::new(
            p,
            Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[a, n, o])),
        )
    }

    fn check_inputs(
        &self,
        current: &Theta,
        options: &PioneerIkOptions,
    ) -> Result<(), PioneerIkError> {
        self.validate()?;
        options.check()?;
        if !current.iter().all(|t| t.is_finite()) {
            return Err(PioneerIkError::NonFinite);
        }
        Ok(())
    }

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
        let na = approach.norm();
        if na < 1e-12 {
            return Err(FrameError::ZeroApproach.into());
        }
        let a = approach / na;
        self.candidates(
            position,
            WristGoal::Approach(&a),
            current,
            options.position_tolerance,
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
        let mut any_exact = false;
        // The search accepts only exact solutions (round-off), so that the bisection
        // cannot settle on a reach boundary blurred by the tolerance; the last resort
        // (full stretch) accepts the tolerances.
        let strict = PioneerIkOptions {
            position_tolerance: EXACT_POSITION,
            orientation_tolerance: EXACT_ORIENTATION,
            ..*options
        };
        let mut attempt_with = |a: &Vector3<f64>, opts: &PioneerIkOptions| {
            let cands = self
                .candidates(
                    position,
                    WristGoal::Approach(a),
                    current,
                    opts.position_tolerance,
                )
                .ok()?;
            match cands.select(current, opts) {
                Ok(c) => Some(c),
                Err(PioneerIkError::OutsideJointLimits) => {
                    any_exact = true;
                    None
                }
                Err(_) => None,
            }
        };
        let mut attempt = |a: &Vector3<f64>| attempt_with(a, &strict);
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
        for k in 0..=steps {
            for sign in [1.0, -1.0] {
                let phi = phi0 + sign * (k as f64 * step).min(PI);
                if let Some(found) = attempt(&in_plane(phi)) {
                    if k == 0 {
                        return Ok(found);
                    }
                    let mut good = (phi, found);
                    let mut bad = phi0 + sign * ((k - 1) as f64 * step);
                    for _ in 0..64 {
                        if (good.0 - bad).abs() <= 1e-9 {
                            break;
                        }
                        let mid = 0.5 * (good.0 + bad);
                        match attempt(&in_plane(mid)) {
                            Some(c) => good = (mid, c),
                            None => bad = mid,
                        }
                    }
                    return Ok(good.1);
                }
                if k == 0 {
                    break;
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
            let mut best: Option<(f64, IkCandidate)> = None;
            for t1 in [yaw_limit.min, yaw_limit.max] {
                let (s1, c1) = t1.sin_cos();
                let normal = Vector3::new(-s1, c1, 0.0);
                let off = position.dot(&normal);
                if off.abs() >= self.l5 {
                    continue;
                }
                let r = (self.l5 * self.l5 - off * off).sqrt();
                let centre = position - normal * off;
                let e1 = Vector3::new(c1, s1, 0.0);
                for j in 0..steps * 2 {
                    let psi = j as f64 * step;
                    let w = centre + (e1 * psi.cos() + Vector3::z() * psi.sin()) * r;
                    let a = (position - w) / self.l5;
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
        if any_exact {
            Err(PioneerIkError::OutsideJointLimits)
        } else {
            Err(PioneerIkError::OutOfReach {
                distance: from_circle,
                min: 0.0,
                max,
            })
        }
    }

    /// VECMOVE: plans a straight line from the current end-effector position along
    /// `direction` (arm-base frame, any non-zero length) for `length` metres, holding the
    /// current approach vector. The 5-DOF arm cannot hold a full orientation along an
    /// arbitrary line (the normal must stay perpendicular to the forearm, which turns
    /// with θ1), so the wrist roll follows the arm, continuously. The returned iterator
    /// yields joint waypoints such that linear joint interpolation between consecutive
    /// waypoints stays within [`VecMoveOptions::max_deviation`] of the line (checked at
    /// [`VecMoveOptions::samples`] interior points per segment). Validate a whole move
    /// before executing it by running a clone of the iterator.
    pub fn vecmove(
        &self,
        current: &Theta,
        direction: &Vector3<f64>,
        length: f64,
        options: &VecMoveOptions,
    ) -> Result<VecMove<'_>, VecMoveError> {
        self.validate().map_err(PioneerIkError::from)?;
        options.ik.check()?;
        if !(current.iter().all(|t| t.is_finite()) && all_finite(direction) && length.is_finite()) {
            return Err(VecMoveError::NonFinite);
        }
        let ok = |v: f64| v.is_finite() && v > 0.0;
        if !(ok(options.max_deviation)
            && ok(options.min_step)
            && ok(options.max_step)
            && options.min_step <= options.max_step
            && options.samples >= 1
            && options.samples <= 64)
            || length < 0.0
        {
            return Err(VecMoveError::InvalidOptions);
        }
        // Scaled by the largest component first: (1e308, 1e308, 0) is a direction too
        // (its norm overflows).
        let direction = unit_direction(direction).ok_or(VecMoveError::ZeroDirection)?;
        let start = self.fk_raw(current);
        Ok(VecMove {
            geometry: self,
            start: start.position,
            direction,
            approach: start.approach(),
            length,
            travelled: 0.0,
            theta: *current,
            options: *options,
            finished: length == 0.0,
        })
    }

    /// Closed-form candidates. `tol` widens the reachable annulus of the wrist centre.
    fn candidates(
        &self,
        p: &Vector3<f64>,
        goal: WristGoal<'_>,
        current: &Theta,
        tol: f64,
    ) -> Result<IkCandidates, PioneerIkError> {
        let a = match goal {
            WristGoal::Frame(pose) => pose.approach(),
            WristGoal::Approach(a) => *a,
        };
        let w = p - a * self.l5;
        let h = w.x.hypot(w.y);
        let yaw = if h < 1e-12 {
            current[0]
        } else {
            w.y.atan2(w.x)
        };
        let (dmin, dmax) = self.wrist_reach();
        let mut out = IkCandidates::new();
        let mut front_distance = f64::NAN;
        for (shoulder, t1) in [(Shoulder::Front, yaw), (Shoulder::Back, wrap_pi(yaw + PI))] {
            let (s1, c1) = t1.sin_cos();
            let r = c1 * w.x + s1 * w.y - self.l1;
            let z = w.z;
            let d = r.hypot(z);
            if shoulder == Shoulder::Front {
                front_distance = d;
            }
            if d > dmax + tol || d < dmin - tol {
                continue;
            }
            // |θ3| by the half-angle formula, tan²(θ3/2) = (1 − c3)/(1 + c3) with
            // 1 − c3 = ((L2+L4)² − d²)/(2·L2·L4) and 1 + c3 = (d² − (L2−L4)²)/(2·L2·L4),
            // each factored so that it keeps its precision near the straight (and the
            // folded) elbow, where acos(c3) would lose half the digits.
            let one_minus = (dmax - d).max(0.0) * (dmax + d);
            let one_plus = (d - dmin).max(0.0) * (d + dmin);
            let g = 2.0 * one_minus.sqrt().atan2(one_plus.sqrt());
            // sin and cos of g from the same half-angle quantities (no transcendental).
            let pm = one_plus + one_minus;
            let (sg, cg) = if pm > 0.0 {
                (
                    2.0 * (one_minus * one_plus).sqrt() / pm,
                    (one_plus - one_minus) / pm,
                )
            } else {
                g.sin_cos()
            };
            let (sa, ca) = unit(z, r);
            let mut arms = [Arm::default(); 4];
            let mut n_arms = 0;
            for (elbow, t3, s3, c3) in [(Elbow::Down, g, sg, cg), (Elbow::Up, -g, -sg, cg)] {
                // θ2 = atan2(z, r) − atan2(L4·s3, L2 + L4·c3), by the difference formulas.
                let (sb, cb) = unit(self.l4 * s3, self.l2 + self.l4 * c3);
                let (s2, c2) = (sa * cb - ca * sb, ca * cb + sa * sb);
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
                    if s3.abs() < 1e-3 && ax.hypot(bx) > 1e-2 {
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
                        let fk = self.fk_trig(&Trig {
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
                        });
                        let position_error = (fk.position - p).norm();
                        let orientation_error = match goal {
                            WristGoal::Frame(pose) => fk.orientation_error(pose),
                            WristGoal::Approach(a) => vector_angle(&fk.approach(), a),
                        };
                        let ok = |v: f64| if v.is_finite() { v } else { f64::INFINITY };
                        out.push(IkCandidate {
                            theta,
                            branch: Branch {
                                shoulder,
                                elbow,
                                wrist,
                            },
                            within_limits: within,
                            position_error: ok(position_error),
                            orientation_error: ok(orientation_error),
                        });
                    };
                match goal {
                    WristGoal::Frame(pose) => {
                        let nl = local(&pose.normal());
                        let t4 = nl.z.atan2(nl.y);
                        let (s4, c4) = unit(nl.z, nl.y);
                        // v = Rx(θ4)ᵀ·a_local = (c5, 0, s5) for a consistent frame.
                        let vx = al.x;
                        let vz = -s4 * al.y + c4 * al.z;
                        push(t4, (s4, c4), vz.atan2(vx), unit(vz, vx), Wrist::Normal);
                    }
                    WristGoal::Approach(_) => {
                        let s5 = al.y.hypot(al.z);
                        let t5 = s5.atan2(al.x);
                        let (t4, (s4, c4)) = if s5 < 1e-12 {
                            (current[3], current[3].sin_cos())
                        } else {
                            ((-al.y).atan2(al.z), (-al.y / s5, al.z / s5))
                        };
                        let (ss5, cs5) = unit(s5, al.x);
                        push(t4, (s4, c4), t5, (ss5, cs5), Wrist::Normal);
                        push(t4 + PI, (-s4, -c4), -t5, (-ss5, cs5), Wrist::Flipped);
                    }
                }
            }
        }
        if out.is_empty() {
            return Err(PioneerIkError::OutOfReach {
                distance: front_distance,
                min: dmin,
                max: dmax,
            });
        }
        Ok(out)
    }
}

/// Options of [`PioneerGeometry::vecmove`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VecMoveOptions {
    /// Largest accepted distance of the interpolated end effector from the line, m
    /// (default 1 mm).
    pub max_deviation: f64,
    /// Shortest segment the planner will subdivide to, m (default 0.1 mm); if the
    /// deviation cannot be met with it, the move fails.
    pub min_step: f64,
    /// Longest segment, m (default 2 cm): keeps the sampled deviation check meaningful.
    pub max_step: f64,
    /// Interior points per segment at which the deviation is checked (1..=64, default 4).
    pub samples: usize,
    /// IK options for every waypoint.
    pub ik: PioneerIkOptions,
}

impl Default for VecMoveOptions {
    fn default() -> Self {
        Self {
            max_deviation: 1e-3,
            min_step: 1e-4,
            max_step: 0.02,
            samples: 4,
            ik: PioneerIkOptions::default(),
        }
    }
}

/// Why a VECMOVE could not be planned or continued.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum VecMoveError {
    /// NaN or infinite input.
    #[error("input contains NaN or an infinite value")]
    NonFinite,
    /// The direction vector has zero length.
    #[error("direction has zero length")]
    ZeroDirection,
    /// Negative length, or invalid deviation/step/sample options.
    #[error("invalid VECMOVE options or length")]
    InvalidOptions,
    /// Geometry or IK options invalid.
    #[error(transparent)]
    Ik(#[from] PioneerIkError),
    /// The line leaves the reachable set at `distance` m from the start.
    #[error("line unreachable at {distance} m: {cause}")]
    Unreachable {
        /// Distance along the line, m.
        distance: f64,
        /// The IK failure there.
        cause: PioneerIkError,
    },
    /// Even the shortest segment deviates more than allowed (a singularity or a branch
    /// change) at `distance` m from the start.
    #[error("deviation {deviation} m exceeds the bound at {distance} m")]
    DeviationExceeded {
        /// Distance along the line, m.
        distance: f64,
        /// Deviation of the shortest segment tried, m.
        deviation: f64,
    },
}

/// One VECMOVE waypoint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Waypoint {
    /// Joint angles θ1..θ5 to command.
    pub theta: Theta,
    /// Distance along the line from the start, m.
    pub distance: f64,
    /// Largest sampled deviation from the line of the segment ending here, m.
    pub deviation: f64,
}

/// The VECMOVE planner: an iterator of waypoints (see [`PioneerGeometry::vecmove`]).
/// It ends after the waypoint at the full length, or after the first error.
#[derive(Clone, Debug)]
pub struct VecMove<'a> {
    geometry: &'a PioneerGeometry,
    start: Vector3<f64>,
    direction: Vector3<f64>,
    approach: Vector3<f64>,
    length: f64,
    travelled: f64,
    theta: Theta,
    options: VecMoveOptions,
    finished: bool,
}

impl VecMove<'_> {
    /// The line's start point (arm-base frame).
    pub fn start(&self) -> Vector3<f64> {
        self.start
    }

    /// The approach vector held along the line.
    pub fn approach(&self) -> Vector3<f64> {
        self.approach
    }

    fn deviation(&self, from: &Theta, to: &Theta) -> f64 {
        let m = self.options.samples;
        let mut worst: f64 = 0.0;
        for k in 1..=m {
            let t = k as f64 / (m + 1) as f64;
            let q: Theta = std::array::from_fn(|i| from[i] + (to[i] - from[i]) * t);
            let p = self.geometry.fk_raw(&q).position;
            let s = (p - self.start)
                .dot(&self.direction)
                .clamp(0.0, self.length);
            let d = (p - (self.start + self.direction * s)).norm();
            worst = worst.max(if d.is_finite() { d } else { f64::INFINITY });
        }
        worst
    }
}

impl Iterator for VecMove<'_> {
    type Item = Result<Waypoint, VecMoveError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.finished {
            return None;
        }
        let remaining = self.length - self.travelled;
        let mut step = remaining.min(self.options.max_step);
        loop {
            let last = step >= remaining;
            let s = if last {
                self.length
            } else {
                self.travelled + step
            };
            let p = self.start + self.direction * s;
            let can_halve = step * 0.5 >= self.options.min_step;
            match self.geometry.solve_position_approach(
                &p,
                &self.approach,
                &self.theta,
                &self.options.ik,
            ) {
                Err(cause) => {
                    if can_halve {
                        step *= 0.5;
                        continue;
                    }
                    self.finished = true;
                    return Some(Err(VecMoveError::Unreachable { distance: s, cause }));
                }
                Ok(c) => {
                    let deviation = self.deviation(&self.theta, &c.theta);
                    if deviation <= self.options.max_deviation {
                        self.theta = c.theta;
                        self.travelled = s;
                        self.finished = last;
                        return Some(Ok(Waypoint {
                            theta: c.theta,
                            distance: s,
                            deviation,
                        }));
                    }
                    if can_halve {
                        step *= 0.5;
                        continue;
                    }
                    self.finished = true;
                    return Some(Err(VecMoveError::DeviationExceeded {
                        distance: s,
                        deviation,
                    }));
                }
            }
        }
    }
}

fn joint_distance(a: &Theta, b: &Theta) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

fn vector_angle(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}

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
