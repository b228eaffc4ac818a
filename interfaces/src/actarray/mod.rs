//! `actarray`: an array of actuators (joints), Player interface 53.
//!
//! State: [`ActArrayData`]. Commands ([`ActArrayCommand`], envelope [`ActArrayCmdMsg`]):
//! POS, MULTI_POS, SPEED, MULTI_SPEED, HOME, CURRENT, MULTI_CURRENT. Requests
//! ([`ActArrayRequest`], envelope [`ActArrayReqMsg`]): POWER, BRAKES, GET_GEOM, SPEED, ACCEL;
//! replies in [`ActArrayReplyMsg`] ([`ActArrayReply`]). Positions in rad (rotary) or m
//! (linear), speeds in rad/s or m/s, currents in A.
//!
//! The module's files: `wire.rs` holds the fixed-layout structs (the contract shared with
//! C, C++ and Python), `views.rs` their typed views and validation, `command.rs` the typed
//! commands and their encoding, `request.rs` the typed requests and replies.

use bitflags::bitflags;

use crate::error::DecodeError;
use crate::manifest::{Constant, ConstantGroup};

mod command;
mod request;
mod trajectory;
mod upload;
mod views;
mod wire;

pub use command::{ActArrayCommand, JointSel, JointValues};
pub(crate) use request::on_off;
pub use request::{ActArrayReply, ActArrayRequest};
pub use trajectory::{Interpolation, JointTrajectory, MAX_TRAJ_POINTS, TrajectoryError};
pub use upload::TrajectoryUpload;
pub use wire::*;

/// Command kinds (Player's `PLAYER_ACTARRAY_CMD_*` numbers).
pub mod cmd {
    /// Move one joint to a position.
    pub const POS: u32 = 1;
    /// Move every joint to a position.
    pub const MULTI_POS: u32 = 2;
    /// Move one joint at a speed.
    pub const SPEED: u32 = 3;
    /// Move every joint at a speed.
    pub const MULTI_SPEED: u32 = 4;
    /// Home one joint or all.
    pub const HOME: u32 = 5;
    /// Drive one joint (or all) with a current.
    pub const CURRENT: u32 = 6;
    /// Drive every joint with a current.
    pub const MULTI_CURRENT: u32 = 7;
    /// One piece of a joint trajectory being uploaded (limber's own).
    pub const TRAJ_CHUNK: u32 = 8;
    /// Run the joint trajectory uploaded (limber's own).
    pub const TRAJ: u32 = 9;
    /// The speed scaling of trajectories (limber's own).
    pub const TRAJ_SCALE: u32 = 10;
}

/// `ActArrayTrajChunkCmd::field` codes: what a chunk carries.
pub mod traj_field {
    /// Points' times from start, s.
    pub const TIME: u16 = 1;
    /// One column's positions.
    pub const POSITION: u16 = 2;
    /// One column's velocities.
    pub const VELOCITY: u16 = 3;
    /// One column's accelerations.
    pub const ACCELERATION: u16 = 4;
    /// The path tolerance of each column.
    pub const PATH_TOLERANCE: u16 = 5;
    /// The goal tolerance of each column.
    pub const GOAL_TOLERANCE: u16 = 6;
}

/// `ActArrayTrajCmd::fields` bits: the optional fields the points carry.
pub mod traj_has {
    /// Velocities (cubic interpolation).
    pub const VELOCITIES: u32 = 1;
    /// Accelerations too (quintic interpolation).
    pub const ACCELERATIONS: u32 = 2;
}

/// Request kinds (Player's `PLAYER_ACTARRAY_REQ_*` numbers).
pub mod req {
    /// Power on or off.
    pub const POWER: u32 = 1;
    /// Brakes on or off.
    pub const BRAKES: u32 = 2;
    /// Get the geometry.
    pub const GET_GEOM: u32 = 3;
    /// Set a joint's speed for later moves.
    pub const SPEED: u32 = 4;
    /// Set a joint's acceleration for later moves.
    pub const ACCEL: u32 = 5;
}

/// `joint` value meaning "every joint" (HOME, CURRENT), as in Player.
pub const ALL_JOINTS: i32 = -1;

bitflags! {
    /// Actuator state bits (Player's `PLAYER_ACTARRAY_ACTSTATE_*`).
    #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
    pub struct ActuatorFlags: u32 {
        /// Not moving, at its target.
        const IDLE = 1;
        /// Moving.
        const MOVING = 2;
        /// Brakes applied.
        const BRAKED = 4;
        /// Stopped short of its target.
        const STALLED = 8;
        /// The speed is estimated from successive positions (the hardware does not
        /// report it), not measured.
        const SPEED_ESTIMATED = 16;
    }
}

/// Actuator type (Player's `PLAYER_ACTARRAY_TYPE_*`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum ActuatorKind {
    /// Linear: positions in m.
    Linear = 1,
    /// Rotary: positions in rad.
    Rotary = 2,
}

impl TryFrom<u32> for ActuatorKind {
    type Error = DecodeError;
    fn try_from(v: u32) -> Result<Self, DecodeError> {
        match v {
            1 => Ok(ActuatorKind::Linear),
            2 => Ok(ActuatorKind::Rotary),
            _ => Err(DecodeError::UnknownCode {
                field: "actuator kind",
                value: v as i64,
            }),
        }
    }
}

pub(crate) const GROUPS: &[ConstantGroup] = &[
    ConstantGroup {
        name: "ACTARRAY_CMD",
        doc: "actarray command kinds (MsgMeta.kind on the cmd channel)",
        constants: &[
            Constant {
                name: "POS",
                value: 1,
                doc: "ActArrayPositionCmd",
            },
            Constant {
                name: "MULTI_POS",
                value: 2,
                doc: "ActArrayMultiPositionCmd",
            },
            Constant {
                name: "SPEED",
                value: 3,
                doc: "ActArraySpeedCmd",
            },
            Constant {
                name: "MULTI_SPEED",
                value: 4,
                doc: "ActArrayMultiSpeedCmd",
            },
            Constant {
                name: "HOME",
                value: 5,
                doc: "ActArrayHomeCmd",
            },
            Constant {
                name: "CURRENT",
                value: 6,
                doc: "ActArrayCurrentCmd",
            },
            Constant {
                name: "MULTI_CURRENT",
                value: 7,
                doc: "ActArrayMultiCurrentCmd",
            },
            Constant {
                name: "TRAJ_CHUNK",
                value: 8,
                doc: "ActArrayTrajChunkCmd: a piece of a trajectory upload",
            },
            Constant {
                name: "TRAJ",
                value: 9,
                doc: "ActArrayTrajCmd: run the uploaded trajectory",
            },
            Constant {
                name: "TRAJ_SCALE",
                value: 10,
                doc: "ActArrayTrajScaleCmd: trajectory speed scaling",
            },
        ],
    },
    ConstantGroup {
        name: "TRAJ_FIELD",
        doc: "ActArrayTrajChunkCmd.field codes",
        constants: &[
            Constant {
                name: "TIME",
                value: 1,
                doc: "points' times from start, s",
            },
            Constant {
                name: "POSITION",
                value: 2,
                doc: "one column's positions",
            },
            Constant {
                name: "VELOCITY",
                value: 3,
                doc: "one column's velocities",
            },
            Constant {
                name: "ACCELERATION",
                value: 4,
                doc: "one column's accelerations",
            },
            Constant {
                name: "PATH_TOLERANCE",
                value: 5,
                doc: "each column's path tolerance",
            },
            Constant {
                name: "GOAL_TOLERANCE",
                value: 6,
                doc: "each column's goal tolerance",
            },
        ],
    },
    ConstantGroup {
        name: "TRAJ_HAS",
        doc: "ActArrayTrajCmd.fields bits",
        constants: &[
            Constant {
                name: "VELOCITIES",
                value: 1,
                doc: "points carry velocities (cubic)",
            },
            Constant {
                name: "ACCELERATIONS",
                value: 2,
                doc: "points carry accelerations too (quintic)",
            },
        ],
    },
    ConstantGroup {
        name: "TRAJ",
        doc: "joint trajectory capacity",
        constants: &[Constant {
            name: "MAX_POINTS",
            value: 64,
            doc: "points of one trajectory",
        }],
    },
    ConstantGroup {
        name: "ACTARRAY_REQ",
        doc: "actarray request kinds (MsgMeta.kind on the req channel)",
        constants: &[
            Constant {
                name: "POWER",
                value: 1,
                doc: "ActArrayPowerReq; reply empty",
            },
            Constant {
                name: "BRAKES",
                value: 2,
                doc: "ActArrayBrakesReq; reply empty",
            },
            Constant {
                name: "GET_GEOM",
                value: 3,
                doc: "empty; reply ActArrayGeom",
            },
            Constant {
                name: "SPEED",
                value: 4,
                doc: "ActArraySpeedReq; reply empty",
            },
            Constant {
                name: "ACCEL",
                value: 5,
                doc: "ActArrayAccelReq; reply empty",
            },
        ],
    },
    ConstantGroup {
        name: "ACTSTATE",
        doc: "ActuatorState.state bits",
        constants: &[
            Constant {
                name: "IDLE",
                value: 1,
                doc: "at its target",
            },
            Constant {
                name: "MOVING",
                value: 2,
                doc: "moving",
            },
            Constant {
                name: "BRAKED",
                value: 4,
                doc: "brakes applied",
            },
            Constant {
                name: "STALLED",
                value: 8,
                doc: "stopped short of its target",
            },
            Constant {
                name: "SPEED_ESTIMATED",
                value: 16,
                doc: "speed estimated from successive positions, not measured",
            },
        ],
    },
    ConstantGroup {
        name: "ACTUATOR_KIND",
        doc: "ActuatorGeom.kind",
        constants: &[
            Constant {
                name: "LINEAR",
                value: 1,
                doc: "linear, m",
            },
            Constant {
                name: "ROTARY",
                value: 2,
                doc: "rotary, rad",
            },
        ],
    },
];
