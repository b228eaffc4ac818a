//! Kinematics: the Pioneer 5-DOF arm in closed form, generic serial chains with a
//! numeric inverse.
//!
//! # Conventions
//!
//! * **Units**: metres, radians, seconds (speeds in rad/s or m/s). Nothing here uses
//!   degrees or servo ticks; tick conversion belongs to the P2OS layer.
//! * **Frames**: right-handed. Player's robot frame is x forward, y left, z up with the
//!   origin at the robot centre. The Pioneer solver works **relative to the arm base**
//!   ([`pioneer::PioneerGeometry::base_offset`], default (0.105, 0, 0.3185) m in the robot
//!   frame, no rotation); use [`pioneer::PioneerGeometry::robot_to_base`] and
//!   [`pioneer::PioneerGeometry::base_to_robot`] to move poses between the two. Generic
//!   chains ([`chain::Chain`]) report poses in the frame their `base` transform is given in
//!   (normally the robot frame).
//! * **End-effector frame** ([`Pose`]): a rotation matrix whose columns are Player's
//!   *approach* `a` (x, pointing forward out of the gripper), *normal* `n` (y) and
//!   *orientation* `o` (z, "up" from the gripper centre), so `n = o × a` and
//!   `(a, n, o)` is orthonormal and right-handed.
//! * **Pioneer joint angles** come in two conventions, converted in exactly one place,
//!   [`pioneer::DriverAngleMap`]: the *kinematic* angles θ1..θ5 of Gan et al. (2005),
//!   which every solver, limit and test here uses, and the *driver* (actarray) angles
//!   j0..j4 that the P2OS layer reports, with θ1 = −(j0−off0), θ2 = j1−off1,
//!   θ3 = j2−off2, θ4 = −(j3−off3), θ5 = −(j4−off4). Joint limits are stored and checked
//!   in θ only (Player compared θ against driver-convention limits, its pitfall 15).
//!
//! # What is corrected relative to Player's KineCalc
//!
//! * FK: Player's `a_y` (and so `p_y`) carries `+c1·s4·s5`; the correct term is
//!   `−c1·s4·s5`, which makes `(n, o, a)` orthonormal and right-handed. Here FK is the
//!   rotation product `Rz(θ1)·Ry(−(θ2+θ3))·Rx(θ4)·Ry(−θ5)`, so the sign is right by
//!   construction and checked against 40 reference vectors.
//! * IK checks reach explicitly (an unreachable target is an error, never a clamped
//!   arm pointing at it), checks limits in θ, and picks among the exact solutions
//!   deterministically (nearest to the current joints). An orientation a 5-DOF wrist
//!   cannot hold is either refused ([`pioneer::PioneerGeometry::solve_setpose`]) or
//!   turned to the nearest one it can, with the adjustment reported
//!   ([`pioneer::PioneerGeometry::solve_setpose_nearest`]); KineCalc spread the error
//!   over position and approach without saying so.
//! * No solver allocates; no solver panics or returns NaN on bad (NaN, infinite,
//!   degenerate) input: such input is a typed error.

#![warn(missing_docs)]

pub mod chain;
pub mod path;
pub mod pioneer;
mod pose;

pub use pose::{FrameError, Pose, angle_between_rotations, fit_angle_to_limits, unit_direction};
