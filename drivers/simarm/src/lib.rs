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
//! | `simarm/gripper/0` | the chain's parallel gripper: OPEN, CLOSE, STOP; beam bit 0 sees the simulated object between the fingers |
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
//! Power off stops everything; motion commands are then refused with BUSY until power
//! is on again. Unsupported: CURRENT/MULTI_CURRENT, BRAKES, ACCEL, gripper STORE and
//! RETRIEVE. An unreachable limb target is refused with OUT_OF_REACH and the limb
//! state is OUT_OF_REACH until the next valid limb command. A limb motion that brings a
//! joint frame or the tool point below the floor or into an obstacle
//! ([`SimArmOptions::obstacles`]) stops there, and the limb state is COLLISION until the
//! next limb command.
//!
//! In steady state nothing allocates: the states are written in place, the IK works
//! on the stack, the VECMOVE plan has a fixed capacity ([`model::MAX_WAYPOINTS`]).

mod driver;
pub mod model;

pub use driver::{DRIVER_NAME, SimArm, SimArmError, SimArmFailures};
pub use model::{
    ArmModel, Contact, Obstacles, OptionsError, SimArmOptions, SimObject, SimObstacle,
};
