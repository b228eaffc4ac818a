//! SETPOSE on a 5-DOF arm as people write it: the position and the approach met within
//! tolerances (of the order of a millimetre and a degree), the orientation the nearest
//! one the joints can hold, and by how much it was adjusted.
//!
//! Five joints reach a 5-dimensional set of frames: once the wrist centre and the
//! approach are fixed, the wrist's pitch axis (the frame's normal `n`) must be
//! perpendicular to the forearm, which leaves the orientation vector `o` no freedom
//! (except when the approach lies along the forearm, where the roll turns freely). An
//! orientation typed with two or three decimals is therefore almost never exactly one
//! the arm can hold; Player's KineCalc let the error fall where it must. Here the
//! candidates of both closed forms (the full frame, and the approach with the roll
//! following) are scored by the FK: a candidate is acceptable when its position is
//! within [`PioneerIkOptions::position_tolerance`] and its approach within
//! [`PioneerIkOptions::orientation_tolerance`] of the request. Among the acceptable
//! ones inside the joint limits, those that meet the position and the approach exactly
//! (to round-off) come first; the tolerances admit the others only when none does
//! (at the edge of the reach, near a singularity). Within that, the one whose frame is
//! nearest the requested frame wins (ties, to [`ADJUSTMENT_TIE`], go to the one nearest
//! the current joints).

use nalgebra::Vector3;

use super::{IkCandidate, vector_angle};
use super::{PioneerGeometry, PioneerIkError, PioneerIkOptions, Theta, joint_distance};
use crate::pose::Pose;

/// Position (m) and approach (rad) errors up to this are round-off: the candidate
/// meets them exactly.
const EXACT: f64 = 1e-9;

/// Orientation differences below this (rad) count as equal when candidates are ranked.
pub const ADJUSTMENT_TIE: f64 = 1e-9;

/// An orientation adjustment up to this (rad, 0.0006°) is round-off of the request (a
/// unit vector typed with six decimals is that far from the exact one), not an
/// adjustment: the command is carried out as asked.
pub const ADJUSTMENT_REPORTED: f64 = 1e-5;

/// A SETPOSE solution and what it changed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PoseSolution {
    /// The joints and their branch.
    pub candidate: IkCandidate,
    /// The pose the joints put the end effector at (FK), robot frame.
    pub achieved: Pose,
    /// Distance between the requested and the achieved position, m.
    pub position_error: f64,
    /// Angle between the requested and the achieved approach, rad.
    pub approach_error: f64,
    /// Angle of the rotation between the requested frame (orientation made perpendicular
    /// to the approach) and the achieved one, rad: how much the orientation was adjusted.
    pub adjustment: f64,
}

impl PoseSolution {
    /// True when the orientation was adjusted by more than [`ADJUSTMENT_REPORTED`].
    pub fn adjusted(&self) -> bool {
        self.adjustment > ADJUSTMENT_REPORTED
    }

    /// The joints θ1..θ5.
    pub fn theta(&self) -> &Theta {
        &self.candidate.theta
    }
}

impl PioneerGeometry {
    /// SETPOSE with 5-DOF semantics (see the module docs): position in the **robot**
    /// frame, approach and orientation vectors as Player sends them (normalised; the
    /// orientation must be within `orientation_tolerance` of perpendicular to the
    /// approach, then it is made exactly perpendicular). `options.position_tolerance`
    /// bounds the position, `options.orientation_tolerance` the approach.
    ///
    /// Errors: [`PioneerIkError::OutOfReach`] when the wrist centre is beyond the arm's
    /// reach, [`PioneerIkError::OutsideJointLimits`] when every acceptable candidate
    /// needs a joint beyond its limit, [`PioneerIkError::UnreachableOrientation`] when no
    /// candidate meets the approach (numerically degenerate requests only).
    pub fn solve_setpose_nearest(
        &self,
        position_robot: &Vector3<f64>,
        approach: &Vector3<f64>,
        orientation: &Vector3<f64>,
        current: &Theta,
        options: &PioneerIkOptions,
    ) -> Result<PoseSolution, PioneerIkError> {
        options.check()?;
        let request = Pose::from_approach_orientation(
            *position_robot,
            *approach,
            *orientation,
            options.orientation_tolerance,
        )?;
        let target = self.robot_to_base(&request);
        let frame = self.pose_candidates(&target, current, options)?;
        let free_roll =
            self.approach_candidates(&target.position, &target.approach(), current, options)?;
        // (tier, adjustment, joint distance, solution): tier 0 meets the position and the
        // approach to round-off, tier 1 only within the tolerances.
        let mut best: Option<(u8, f64, f64, PoseSolution)> = None;
        let mut any_acceptable = false;
        let mut min_approach = f64::INFINITY;
        for c in frame.as_slice().iter().chain(free_roll.as_slice()) {
            let Ok(fk) = self.fk(&c.theta) else {
                continue;
            };
            let position_error = (fk.position - target.position).norm();
            let approach_error = vector_angle(&fk.approach(), &target.approach());
            let adjustment = fk.orientation_error(&target);
            if !(position_error.is_finite() && approach_error.is_finite() && adjustment.is_finite())
            {
                continue;
            }
            min_approach = min_approach.min(approach_error);
            if position_error > options.position_tolerance
                || approach_error > options.orientation_tolerance
            {
                continue;
            }
            any_acceptable = true;
            if !c.within_limits {
                continue;
            }
            let distance = joint_distance(&c.theta, current);
            let tier = u8::from(position_error > EXACT || approach_error > EXACT);
            let better = best.as_ref().is_none_or(|(t, adj, dist, _)| {
                tier < *t
                    || (tier == *t
                        && (adjustment < adj - ADJUSTMENT_TIE
                            || (adjustment <= adj + ADJUSTMENT_TIE && distance < *dist)))
            });
            if better {
                best = Some((
                    tier,
                    adjustment,
                    distance,
                    PoseSolution {
                        candidate: *c,
                        achieved: self.base_to_robot(&fk),
                        position_error,
                        approach_error,
                        adjustment,
                    },
                ));
            }
        }
        match best {
            Some((_, _, _, s)) => Ok(s),
            None if any_acceptable => Err(PioneerIkError::OutsideJointLimits),
            None => Err(PioneerIkError::UnreachableOrientation {
                error: min_approach,
            }),
        }
    }
}
