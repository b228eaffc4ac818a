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
    /// The chain's joints have brakes (the BRAKES request; `has_brakes` in the
    /// geometry); the gripper has none. Without, BRAKES is unsupported. (true)
    pub brakes: bool,
    /// How many objects the gripper can store (STORE and RETRIEVE; 0: it cannot, and
    /// both are unsupported as on the Pioneer). (0)
    pub store_capacity: u32,
    /// The motor model of the current mode (CURRENT, MULTI_CURRENT).
    pub motor: MotorModel,
    /// The floor and obstacles the limb stops at (state COLLISION); default none.
    pub obstacles: super::collision::Obstacles,
}

/// The motor model of the current mode: a joint driven with a current `I` feels the
/// motor's torque `torque_constant * I` (N·m, or N on a linear joint) and the torque of
/// gravity on `load_mass` at the tool, and moves at the speed where viscous friction
/// (`damping`) balances the two, at most its maximum speed; a linear joint likewise with
/// forces. A joint that is pushed (`I` not 0) but does not move (at a limit, on an
/// object, or held by gravity) is STALLED.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotorModel {
    /// Torque (or force) per ampere, N·m/A or N/A (> 0). (2.0)
    pub torque_constant: f64,
    /// Largest current, A: more is driven at this and answered CLAMPED (> 0). (5.0)
    pub max_current: f64,
    /// Viscous friction, N·m·s/rad or N·s/m (> 0). (2.0)
    pub damping: f64,
    /// Mass carried at the tool (the arm's own weight lumped there), kg (>= 0). (1.0)
    pub load_mass: f64,
    /// Gravity, m/s², along -z of the robot frame (>= 0). (9.81)
    pub gravity: f64,
}

impl Default for MotorModel {
    fn default() -> Self {
        MotorModel {
            torque_constant: 2.0,
            max_current: 5.0,
            damping: 2.0,
            load_mass: 1.0,
            gravity: 9.81,
        }
    }
}

impl MotorModel {
    fn valid(&self) -> bool {
        let pos = |v: f64| v.is_finite() && v > 0.0;
        let non_neg = |v: f64| v.is_finite() && v >= 0.0;
        pos(self.torque_constant)
            && pos(self.max_current)
            && pos(self.damping)
            && non_neg(self.load_mass)
            && non_neg(self.gravity)
    }

    /// Checks the values (see the fields).
    pub fn check(&self) -> Result<(), OptionsError> {
        if self.valid() {
            Ok(())
        } else {
            Err(OptionsError::Motor)
        }
    }
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
            brakes: true,
            store_capacity: 0,
            motor: MotorModel::default(),
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
    /// The store capacity is beyond
    /// [`MAX_STORE_CAPACITY`](super::store::MAX_STORE_CAPACITY).
    #[error("store capacity must be at most 1024")]
    StoreCapacity,
    /// A motor model value is out of its range (see [`MotorModel`]).
    #[error(
        "motor model: torque constant, max current and damping must be > 0, load mass and gravity >= 0"
    )]
    Motor,
    /// The chain has more joints than an actuator array can carry with the gripper.
    #[error("chain has too many joints")]
    TooManyJoints,
}
