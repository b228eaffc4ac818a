//! simarm: a simulated arm for any serial chain, serving the same interfaces as the
//! Pioneer driver so the same client programs run on it unchanged.
//!
//! Devices (robot name `simarm` by default), every state flagged
//! `SIMULATED | LINK_UP | CALIBRATED`:
//!
//! | device | what |
//! |---|---|
//! | `simarm/actarray/0` | actuators `0..dof` are the chain's joints (rad or m); actuator `dof` (the last) is the gripper opening (linear, 0 closed to the stroke open, m) |
//! | `simarm/limb/0` | the tool: HOME, STOP, SETPOSE (full-pose numeric IK), SETPOSITION (position-only IK), VECMOVE (a straight line with the orientation kept, streamed as 5 mm waypoints) |
//! | `simarm/gripper/0` | the chain's parallel gripper: OPEN, CLOSE, STOP; beam bit 0 sees the simulated object between the fingers; STORE and RETRIEVE with a store of [`SimArmOptions::store_capacity`] objects (0, the default: unsupported) |
//!
//! Time: each joint moves toward its target at its configured speed (the chain's
//! `max_speed` unless changed by the SPEED request) in simulated time, advanced on
//! every tick (10 ms) and before each batch of commands by the real elapsed time times
//! the time scale. Limb moves are coordinated: every joint arrives at the same moment.
//! The limb SPEED request (m/s) caps rotary joints at `speed / reach` and linear ones
//! at `speed`, and VECMOVE segments at `speed`.
//!
//! Commands are validated completely before anything moves (finite, known joint,
//! inside the limits; a MULTI_POS is refused whole). SPEED/MULTI_SPEED move toward the
//! limit in the sign's direction at |speed| capped at the joint's maximum (0 stops).
//! Power off stops everything; motion commands are then refused with POWERED_OFF until
//! power is on again. An unreachable limb target is refused with OUT_OF_REACH and the
//! limb state is OUT_OF_REACH until the next valid limb command.
//!
//! The rest of the paper's Tables 1, 2 and 4:
//! - BRAKES (the actarray's and the limb's request, one set of brakes on the chain's
//!   joints, `has_brakes` in the geometry): on stops the joints, every chain joint's
//!   state is BRAKED and the limb's BRAKED, and a command that would move a chain joint
//!   is refused BRAKED until they are off; the gripper has no brakes.
//! - ACCEL (request): the joint's later actarray moves (POS, MULTI_POS, SPEED, HOME)
//!   ramp their speed up and down at this acceleration (a trapezoidal profile); the
//!   state's `acceleration` is the last step's. Limb moves stay coordinated at constant
//!   speeds.
//! - CURRENT and MULTI_CURRENT: the current mode of [`MotorModel`]; the state's
//!   `current` is the model's, STALLED when a pushed joint does not move.
//! - STORE and RETRIEVE: the object between the fingers leaves the world into the store
//!   (`stored` rises), and comes back between the fingers, held; refused STORE_FULL,
//!   NOTHING_TO_STORE, NOTHING_STORED.
//!
//! A limb motion that brings a joint frame or the tool point below the floor or into an
//! obstacle ([`SimArmOptions::obstacles`]) stops there, and the limb state is COLLISION
//! until the next limb command.
//!
//! In steady state nothing allocates: the states are written in place, the IK works
//! on the stack, the VECMOVE plan has a fixed capacity ([`model::MAX_WAYPOINTS`]).

mod driver;
pub mod model;
mod thread;

pub use driver::{DRIVER_NAME, SimArm, SimArmError, SimArmFailures};
pub use model::{
    ArmModel, Contact, MAX_STORE_CAPACITY, MotorModel, Obstacles, OptionsError, SimArmOptions,
    SimObject, SimObstacle,
};
pub use thread::{SimArmThread, SimArmThreadError};
