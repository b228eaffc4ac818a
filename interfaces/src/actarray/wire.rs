//! The actarray wire structs: fixed layouts, versioned type names, envelopes.

use crate::common::{MsgMeta, Orientation3, ReplyMeta, StateHeader, Vec3};
use crate::message::{envelope, reply_envelope};
#[allow(unused_imports)]
use crate::wire::{ZeroCopySend, wire_struct};

wire_struct! {
    /// The state of one actuator.
    pub struct ActuatorState : "limber.v6.ActuatorState", size = 40, align = 8 {
        /// Position, rad or m.
        pub position: f64,
        /// Current speed, rad/s or m/s (NaN-free; 0 when unknown).
        pub speed: f64,
        /// Current acceleration, rad/s² or m/s²; -1 when the device does not know it (the
        /// Pioneer; simarm for a joint without an ACCEL setting).
        pub acceleration: f64,
        /// Current in A; -1 when the device does not measure it (the Pioneer arm and lift).
        pub current: f64,
        /// `ACTSTATE` bits.
        pub state: u32,
        /// Reserved, zero.
        pub _pad: u32,
    }
}

wire_struct! {
    /// The feedback of the device's joint trajectory (control_msgs': the current point,
    /// the error), in its state.
    pub struct TrajFeedback : "limber.v6.TrajFeedback", size = 40, align = 8 {
        /// 0: no trajectory has run; 1: one runs (or waits for its start time); 2: the last
        /// one ended (`result` says how).
        pub active: u32,
        /// The point it heads for (0-based; `points` once past the last).
        pub point: u32,
        /// Its points.
        pub points: u32,
        /// How the last one ended: a `RESULT` code (0 while one runs).
        pub result: u32,
        /// The largest |actual − desired| of its joints at the last tick, rad or m.
        pub max_error: f64,
        /// Trajectory time at the last tick, s (advancing at `scale` times real time).
        pub time: f64,
        /// The speed scaling: 0 paused, 1 nominal.
        pub scale: f64,
    }
}

wire_struct! {
    /// The state of an actuator array (channel `data`).
    pub struct ActArrayData : "limber.v6.ActArrayData", size = 1376, align = 8 {
        /// Common header.
        pub header: StateHeader,
        /// Number of valid entries in `actuators`.
        pub actuators_count: u32,
        /// Power state: 0 off, 1 on.
        pub motor_state: u32,
        /// The actuators.
        pub actuators: [ActuatorState; 32],
        /// The joint trajectory's feedback (all zero on a device without trajectories).
        pub trajectory: TrajFeedback,
    }
}

wire_struct! {
    /// CMD POS: move one joint to a position.
    pub struct ActArrayPositionCmd : "limber.v6.ActArrayPositionCmd", size = 16, align = 8 {
        /// Joint index (0-based).
        pub joint: i32,
        /// Reserved, zero.
        pub _pad: u32,
        /// Target position, rad or m.
        pub position: f64,
    }
}

wire_struct! {
    /// CMD MULTI_POS: move every joint to a position.
    pub struct ActArrayMultiPositionCmd : "limber.v6.ActArrayMultiPositionCmd", size = 264, align = 8 {
        /// Number of valid entries.
        pub count: u32,
        /// Reserved, zero.
        pub _pad: u32,
        /// Targets, joint 0 first.
        pub positions: [f64; 32],
    }
}

wire_struct! {
    /// CMD SPEED: move one joint at a speed.
    pub struct ActArraySpeedCmd : "limber.v6.ActArraySpeedCmd", size = 16, align = 8 {
        /// Joint index.
        pub joint: i32,
        /// Reserved, zero.
        pub _pad: u32,
        /// Speed, rad/s or m/s.
        pub speed: f64,
    }
}

wire_struct! {
    /// CMD MULTI_SPEED: move every joint at a speed.
    pub struct ActArrayMultiSpeedCmd : "limber.v6.ActArrayMultiSpeedCmd", size = 264, align = 8 {
        /// Number of valid entries.
        pub count: u32,
        /// Reserved, zero.
        pub _pad: u32,
        /// Speeds, joint 0 first.
        pub speeds: [f64; 32],
    }
}

wire_struct! {
    /// CMD HOME: home one joint, or all (`joint = -1`).
    pub struct ActArrayHomeCmd : "limber.v6.ActArrayHomeCmd", size = 8, align = 4 {
        /// Joint index, or -1 for all.
        pub joint: i32,
        /// Reserved, zero.
        pub _pad: u32,
    }
}

wire_struct! {
    /// CMD CURRENT: drive one joint, or all (`joint = -1`), with a current.
    pub struct ActArrayCurrentCmd : "limber.v6.ActArrayCurrentCmd", size = 16, align = 8 {
        /// Joint index, or -1 for all.
        pub joint: i32,
        /// Reserved, zero.
        pub _pad: u32,
        /// Current in A.
        pub current: f64,
    }
}

wire_struct! {
    /// CMD MULTI_CURRENT: drive every joint with a current.
    pub struct ActArrayMultiCurrentCmd : "limber.v6.ActArrayMultiCurrentCmd", size = 264, align = 8 {
        /// Number of valid entries.
        pub count: u32,
        /// Reserved, zero.
        pub _pad: u32,
        /// Currents in A, joint 0 first.
        pub currents: [f64; 32],
    }
}

wire_struct! {
    /// CMD TRAJ_CHUNK: one piece of a joint trajectory being uploaded (see
    /// `ActArrayTrajCmd`): up to 32 values of one field. `TIME`, `POSITION`, `VELOCITY` and
    /// `ACCELERATION` carry the values of points `first .. first + count` (of joint column
    /// `column` for the last three); `PATH_TOLERANCE` and `GOAL_TOLERANCE` one value per
    /// joint column (`first` and `column` zero).
    pub struct ActArrayTrajChunkCmd : "limber.v6.ActArrayTrajChunkCmd", size = 264, align = 8 {
        /// A `TRAJ_FIELD` code.
        pub field: u16,
        /// The trajectory's joint column (0-based) for per-point joint values.
        pub column: u16,
        /// The index of the first point of `values`.
        pub first: u16,
        /// Valid entries of `values`.
        pub count: u16,
        /// The values (s, rad or m, rad/s or m/s, rad/s² or m/s²).
        pub values: [f64; 32],
    }
}

wire_struct! {
    /// CMD TRAJ: run the joint trajectory uploaded by this client's `TRAJ_CHUNK`s since its
    /// last TRAJ (control_msgs' FollowJointTrajectory goal). It replaces the trajectory
    /// running from its start time.
    pub struct ActArrayTrajCmd : "limber.v6.ActArrayTrajCmd", size = 64, align = 8 {
        /// `CLOCK_MONOTONIC` ns at which point times count from; 0 = when it arrives.
        pub start_ns: u64,
        /// How long after the last point's time the joints may take to come within the goal
        /// tolerance, s (0: the device's default).
        pub goal_time_tolerance: f64,
        /// The joint columns (1 to 32).
        pub joint_count: u32,
        /// The points (1 to `TRAJ_MAX_POINTS`).
        pub point_count: u32,
        /// `TRAJ_HAS` bits: which optional fields the points carry.
        pub fields: u32,
        /// Reserved, zero.
        pub _pad: u32,
        /// The actarray joint each column drives.
        pub joints: [u8; 32],
    }
}

wire_struct! {
    /// CMD TRAJ_SCALE: the speed scaling of the running (and later) trajectories: 0
    /// pauses, 1 is nominal.
    pub struct ActArrayTrajScaleCmd : "limber.v6.ActArrayTrajScaleCmd", size = 8, align = 8 {
        /// The factor, 0 to 1.
        pub scale: f64,
    }
}

wire_struct! {
    /// The command envelope (channel `cmd`): `body` holds the struct `meta.kind` names.
    pub struct ActArrayCmdMsg : "limber.v6.ActArrayCmdMsg", size = 296, align = 8 {
        /// Sender, sequence, time, kind, body length.
        pub meta: MsgMeta,
        /// One of the `ActArray*Cmd` structs.
        pub body: [u8; 264],
    }
}

wire_struct! {
    /// REQ POWER: power on (1) or off (0).
    pub struct ActArrayPowerReq : "limber.v6.ActArrayPowerReq", size = 4, align = 4 {
        /// 0 off, 1 on.
        pub value: u32,
    }
}

wire_struct! {
    /// REQ BRAKES: brakes on (1) or off (0).
    pub struct ActArrayBrakesReq : "limber.v6.ActArrayBrakesReq", size = 4, align = 4 {
        /// 0 off, 1 on.
        pub value: u32,
    }
}

wire_struct! {
    /// REQ SPEED: the speed of one joint for later moves.
    pub struct ActArraySpeedReq : "limber.v6.ActArraySpeedReq", size = 16, align = 8 {
        /// Joint index.
        pub joint: i32,
        /// Reserved, zero.
        pub _pad: u32,
        /// Speed, rad/s or m/s.
        pub speed: f64,
    }
}

wire_struct! {
    /// REQ ACCEL: the acceleration of one joint for later moves.
    pub struct ActArrayAccelReq : "limber.v6.ActArrayAccelReq", size = 16, align = 8 {
        /// Joint index.
        pub joint: i32,
        /// Reserved, zero.
        pub _pad: u32,
        /// Acceleration, rad/s² or m/s².
        pub accel: f64,
    }
}

wire_struct! {
    /// The request envelope (channel `req`). GET_GEOM has an empty body.
    pub struct ActArrayReqMsg : "limber.v6.ActArrayReqMsg", size = 48, align = 8 {
        /// Sender, sequence, time, kind, body length.
        pub meta: MsgMeta,
        /// One of the `ActArray*Req` structs.
        pub body: [u8; 16],
    }
}

wire_struct! {
    /// The geometry of one actuator.
    pub struct ActuatorGeom : "limber.v6.ActuatorGeom", size = 104, align = 8 {
        /// `ACTUATOR_KIND`: 1 linear, 2 rotary.
        pub kind: u32,
        /// 1 when the actuator has brakes.
        pub has_brakes: u32,
        /// Length of the link to the next actuator, m (linear: the length at position 0).
        pub length: f64,
        /// Rest orientation (direction to the next actuator).
        pub orientation: Orientation3,
        /// Rotation or travel axis.
        pub axis: Vec3,
        /// Lower limit, rad or m (always `min <= max`).
        pub min: f64,
        /// Centre position.
        pub centre: f64,
        /// Upper limit.
        pub max: f64,
        /// Home position.
        pub home: f64,
        /// Configured speed for moves, rad/s or m/s.
        pub config_speed: f64,
    }
}

wire_struct! {
    /// The geometry of the array (the GET_GEOM reply).
    pub struct ActArrayGeom : "limber.v6.ActArrayGeom", size = 3384, align = 8 {
        /// Number of valid entries.
        pub actuators_count: u32,
        /// Reserved, zero.
        pub _pad: u32,
        /// The actuators.
        pub actuators: [ActuatorGeom; 32],
        /// Position of the base in the robot frame, m.
        pub base_pos: Vec3,
        /// Orientation of the base in the robot frame.
        pub base_orientation: Orientation3,
    }
}

wire_struct! {
    /// The reply envelope (channel `req`): an ACK carries the body of the request's reply.
    pub struct ActArrayReplyMsg : "limber.v6.ActArrayReplyMsg", size = 3416, align = 8 {
        /// Client, sequence, time, kind, status.
        pub meta: ReplyMeta,
        /// `ActArrayGeom` for GET_GEOM, empty otherwise.
        pub body: [u8; 3384],
    }
}

envelope!(ActArrayCmdMsg);
envelope!(ActArrayReqMsg);
reply_envelope!(ActArrayReplyMsg);
