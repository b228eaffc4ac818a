//! What the simulation is configured with: [`SimArmOptions`], the [`SimObject`] to grasp
//! and [`OptionsError`], the reason [`ArmModel::new`](super::ArmModel::new) refuses them.

use limber_kinematics::chain::{NearestOptions, NumericIkOptions};

/// An object the gripper can close on: it stops the fingers at its width, the gripper's
/// beam (bit 0) sees it while it is between the fingers, and it follows the tool while
/// held.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimObject {
    /// Centre, in the robot frame, m.
    pub position: [f64; 3],
    /// Width across the fingers, m (must be below the gripper's stroke to be gripped).
    pub width: f64,
    /// The object is between the fingers when the tool point is this close to its
    /// centre, m.
    pub capture_radius: f64,
}

impl SimObject {
    /// A block of `width` at `position`, captured within 2 cm.
    pub fn block(position: [f64; 3], width: f64) -> Self {
        SimObject {
            position,
            width,
            capture_radius: 0.02,
        }
    }
}

/// Options of the simulation.
#[derive(Debug, Clone, PartialEq)]
pub struct SimArmOptions {
    /// Robot name in the device names (`simarm`).
    pub robot: String,
    /// Period of the simulation and publishing tick (10 ms).
    pub tick: core::time::Duration,
    /// Simulated seconds per real second (1.0; 2.0 moves twice as fast). > 0.
    pub time_scale: f64,
    /// Distance between VECMOVE waypoints, m (5 mm).
    pub vecmove_step: f64,
    /// An object to grasp, if any.
    pub object: Option<SimObject>,
    /// Options of the numeric inverse kinematics.
    pub ik: NumericIkOptions,
    /// SETPOSE on a chain that cannot hold the requested frame: position and approach
    /// tolerances (1 mm, 1°), the orientation the nearest one the joints can hold.
    pub setpose: NearestOptions,
    /// The floor and obstacles the limb stops at (state COLLISION); default none.
    pub obstacles: super::collision::Obstacles,
}

impl Default for SimArmOptions {
    fn default() -> Self {
        SimArmOptions {
            robot: "simarm".to_string(),
            tick: core::time::Duration::from_millis(10),
            time_scale: 1.0,
            vecmove_step: 0.005,
            object: None,
            ik: NumericIkOptions::default(),
            setpose: NearestOptions::default(),
            obstacles: Default::default(),
        }
    }
}

/// Why the options cannot be used.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum OptionsError {
    /// The tick is zero or longer than one second.
    #[error("tick must be in (0, 1 s]")]
    Tick,
    /// The time scale is not a finite positive number.
    #[error("time scale must be finite and > 0")]
    TimeScale,
    /// The VECMOVE step is not a finite positive number.
    #[error("vecmove step must be finite and > 0")]
    VecMoveStep,
    /// The object's width or capture radius is not finite and positive, or its position
    /// is not finite.
    #[error("object position must be finite, width and capture radius > 0")]
    Object,
    /// The chain has more joints than an actuator array can carry with the gripper.
    #[error("chain has too many joints")]
    TooManyJoints,
}
