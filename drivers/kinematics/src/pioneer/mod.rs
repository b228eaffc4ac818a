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
//! [`PioneerIkError::UnreachableOrientation`] for [`PioneerGeometry::solve_setpose`],
//! never silently approximated. [`PioneerGeometry::solve_setpose_nearest`] is SETPOSE as
//! people write it (the driver's): the position and the approach within the tolerances,
//! the orientation the nearest one the joints can hold, and the adjustment reported
//! ([`PoseSolution`]). The wrist
//! centre is accepted up to `position_tolerance` outside the annulus
//! `|L2 − L4| ≤ d ≤ L2 + L4` (the acos argument is clamped only then). Joint limits are
//! inclusive and accept round-off up to [`LIMIT_TOLERANCE`] (the returned angle is then
//! clamped onto the limit).
//!
//! # Layout
//!
//! This module holds the geometry, the joint limits, the IK errors and options and the
//! driver angle map; the solvers live in submodules and are re-exported here, so every
//! item is `limber_kinematics::pioneer::X`:
//!
//! * `fk`: forward kinematics ([`PioneerGeometry::fk`]);
//! * `ik`: the closed-form candidates, their selection and SETPOSE
//!   ([`PioneerGeometry::pose_candidates`], [`PioneerGeometry::solve_pose`],
//!   [`PioneerGeometry::solve_setpose`], [`PioneerGeometry::approach_candidates`]);
//! * `nearest`: SETPOSE with the nearest attainable orientation
//!   ([`PioneerGeometry::solve_setpose_nearest`]);
//! * `position`: the SETPOSITION approach search ([`PioneerGeometry::solve_position`]);
//! * `vecmove`: the straight-line VECMOVE planner ([`PioneerGeometry::vecmove`]).

use std::f64::consts::FRAC_PI_2;

use nalgebra::Vector3;

use crate::pose::{FrameError, Pose, all_finite};

mod fk;
mod ik;
mod nearest;
mod position;
mod vecmove;

pub use fk::PioneerFkError;
pub use ik::{
    Branch, EXACT_ORIENTATION, EXACT_POSITION, Elbow, IkCandidate, IkCandidates, Shoulder, Wrist,
};
pub use nearest::{ADJUSTMENT_REPORTED, ADJUSTMENT_TIE, PoseSolution};
pub use position::ApproachPreference;
pub use vecmove::{VecMove, VecMoveError, VecMoveOptions, Waypoint};

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
}

/// Squared Euclidean distance between two joint vectors (used only to rank).
fn joint_distance(a: &Theta, b: &Theta) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum()
}

/// Angle between two vectors, rad.
fn vector_angle(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    a.cross(b).norm().atan2(a.dot(b))
}
