//! `actarray`: an array of actuators (joints), Player interface 53.
//!
//! State: [`ActArrayData`]. Commands ([`ActArrayCommand`], envelope [`ActArrayCmdMsg`]):
//! POS, MULTI_POS, SPEED, MULTI_SPEED, HOME, CURRENT, MULTI_CURRENT. Requests
//! ([`ActArrayRequest`], envelope [`ActArrayReqMsg`]): POWER, BRAKES, GET_GEOM, SPEED, ACCEL;
//! replies in [`ActArrayReplyMsg`] ([`ActArrayReply`]). Positions in rad (rotary) or m
//! (linear), speeds in rad/s or m/s, currents in A.

use bitflags::bitflags;

use crate::common::{
    MAX_ACTUATORS, MsgMeta, Orientation3, ReplyMeta, StateHeader, Status, Vec3, finite, finite_vec,
};
use crate::error::{DecodeError, ValueError};
use crate::manifest::{Constant, ConstantGroup};
use crate::message::{self, Message, ReplyBody, envelope, reply_envelope};
#[allow(unused_imports)]
use crate::wire::{ZeroCopySend, wire_struct};

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

wire_struct! {
    /// The state of one actuator.
    pub struct ActuatorState : "limber.v1.ActuatorState", size = 40, align = 8 {
        /// Position, rad or m.
        pub position: f64,
        /// Current speed, rad/s or m/s (NaN-free; 0 when unknown).
        pub speed: f64,
        /// Current acceleration (negative when unknown).
        pub acceleration: f64,
        /// Current in A (negative when unknown).
        pub current: f64,
        /// `ACTSTATE` bits.
        pub state: u32,
        /// Reserved, zero.
        pub _pad: u32,
    }
}

wire_struct! {
    /// The state of an actuator array (channel `data`).
    pub struct ActArrayData : "limber.v1.ActArrayData", size = 1336, align = 8 {
        /// Common header.
        pub header: StateHeader,
        /// Number of valid entries in `actuators`.
        pub actuators_count: u32,
        /// Power state: 0 off, 1 on.
        pub motor_state: u32,
        /// The actuators.
        pub actuators: [ActuatorState; 32],
    }
}

wire_struct! {
    /// CMD POS: move one joint to a position.
    pub struct ActArrayPositionCmd : "limber.v1.ActArrayPositionCmd", size = 16, align = 8 {
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
    pub struct ActArrayMultiPositionCmd : "limber.v1.ActArrayMultiPositionCmd", size = 264, align = 8 {
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
    pub struct ActArraySpeedCmd : "limber.v1.ActArraySpeedCmd", size = 16, align = 8 {
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
    pub struct ActArrayMultiSpeedCmd : "limber.v1.ActArrayMultiSpeedCmd", size = 264, align = 8 {
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
    pub struct ActArrayHomeCmd : "limber.v1.ActArrayHomeCmd", size = 8, align = 4 {
        /// Joint index, or -1 for all.
        pub joint: i32,
        /// Reserved, zero.
        pub _pad: u32,
    }
}

wire_struct! {
    /// CMD CURRENT: drive one joint, or all (`joint = -1`), with a current.
    pub struct ActArrayCurrentCmd : "limber.v1.ActArrayCurrentCmd", size = 16, align = 8 {
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
    pub struct ActArrayMultiCurrentCmd : "limber.v1.ActArrayMultiCurrentCmd", size = 264, align = 8 {
        /// Number of valid entries.
        pub count: u32,
        /// Reserved, zero.
        pub _pad: u32,
        /// Currents in A, joint 0 first.
        pub currents: [f64; 32],
    }
}

wire_struct! {
    /// The command envelope (channel `cmd`): `body` holds the struct `meta.kind` names.
    pub struct ActArrayCmdMsg : "limber.v1.ActArrayCmdMsg", size = 296, align = 8 {
        /// Sender, sequence, time, kind, body length.
        pub meta: MsgMeta,
        /// One of the `ActArray*Cmd` structs.
        pub body: [u8; 264],
    }
}

wire_struct! {
    /// REQ POWER: power on (1) or off (0).
    pub struct ActArrayPowerReq : "limber.v1.ActArrayPowerReq", size = 4, align = 4 {
        /// 0 off, 1 on.
        pub value: u32,
    }
}

wire_struct! {
    /// REQ BRAKES: brakes on (1) or off (0).
    pub struct ActArrayBrakesReq : "limber.v1.ActArrayBrakesReq", size = 4, align = 4 {
        /// 0 off, 1 on.
        pub value: u32,
    }
}

wire_struct! {
    /// REQ SPEED: the speed of one joint for later moves.
    pub struct ActArraySpeedReq : "limber.v1.ActArraySpeedReq", size = 16, align = 8 {
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
    pub struct ActArrayAccelReq : "limber.v1.ActArrayAccelReq", size = 16, align = 8 {
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
    pub struct ActArrayReqMsg : "limber.v1.ActArrayReqMsg", size = 48, align = 8 {
        /// Sender, sequence, time, kind, body length.
        pub meta: MsgMeta,
        /// One of the `ActArray*Req` structs.
        pub body: [u8; 16],
    }
}

wire_struct! {
    /// The geometry of one actuator.
    pub struct ActuatorGeom : "limber.v1.ActuatorGeom", size = 104, align = 8 {
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
    pub struct ActArrayGeom : "limber.v1.ActArrayGeom", size = 3384, align = 8 {
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
    pub struct ActArrayReplyMsg : "limber.v1.ActArrayReplyMsg", size = 3416, align = 8 {
        /// Client, sequence, time, kind, status.
        pub meta: ReplyMeta,
        /// `ActArrayGeom` for GET_GEOM, empty otherwise.
        pub body: [u8; 3384],
    }
}

envelope!(ActArrayCmdMsg);
envelope!(ActArrayReqMsg);
reply_envelope!(ActArrayReplyMsg);

/// Up to [`MAX_ACTUATORS`] per-joint values (joint 0 first), without allocation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointValues {
    len: u8,
    values: [f64; MAX_ACTUATORS],
}

impl JointValues {
    /// Builds from a slice; every value must be finite and at most [`MAX_ACTUATORS`] given.
    pub fn new(field: &'static str, values: &[f64]) -> Result<Self, ValueError> {
        if values.len() > MAX_ACTUATORS {
            return Err(ValueError::TooMany {
                field,
                count: values.len(),
                max: MAX_ACTUATORS,
            });
        }
        if values.iter().any(|v| !v.is_finite()) {
            return Err(ValueError::NotFinite { field });
        }
        let mut out = [0.0; MAX_ACTUATORS];
        out[..values.len()].copy_from_slice(values);
        Ok(JointValues {
            len: values.len() as u8,
            values: out,
        })
    }

    /// The values.
    pub fn as_slice(&self) -> &[f64] {
        &self.values[..self.len as usize]
    }

    /// Number of values.
    pub fn len(&self) -> usize {
        self.len as usize
    }

    /// True when there are none.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    fn to_wire(self) -> (u32, [f64; MAX_ACTUATORS]) {
        (self.len as u32, self.values)
    }

    fn from_wire(field: &'static str, count: u32, values: &[f64; 32]) -> Result<Self, ValueError> {
        if count as usize > MAX_ACTUATORS {
            return Err(ValueError::TooMany {
                field,
                count: count as usize,
                max: MAX_ACTUATORS,
            });
        }
        JointValues::new(field, &values[..count as usize])
    }
}

/// A joint index validated against the array capacity.
fn joint(j: i64) -> Result<u16, ValueError> {
    if (0..MAX_ACTUATORS as i64).contains(&j) {
        Ok(j as u16)
    } else {
        Err(ValueError::BadJoint {
            joint: j,
            max: MAX_ACTUATORS,
        })
    }
}

/// One joint or every joint.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum JointSel {
    /// Every joint (`-1` on the wire).
    All,
    /// One joint.
    One(u16),
}

impl JointSel {
    fn to_wire(self) -> i32 {
        match self {
            JointSel::All => ALL_JOINTS,
            JointSel::One(j) => j as i32,
        }
    }
    fn from_wire(j: i32) -> Result<Self, ValueError> {
        if j == ALL_JOINTS {
            Ok(JointSel::All)
        } else {
            joint(j as i64).map(JointSel::One)
        }
    }
    /// Builds from Player's convention: -1 = all, otherwise a joint index.
    pub fn new(j: i64) -> Result<Self, ValueError> {
        if j == ALL_JOINTS as i64 {
            Ok(JointSel::All)
        } else {
            joint(j).map(JointSel::One)
        }
    }
}

/// A typed actarray command.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ActArrayCommand {
    /// Move `joint` to `position`.
    Position {
        /// Joint index.
        joint: u16,
        /// Target, rad or m.
        position: f64,
    },
    /// Move joints 0..n to these positions.
    MultiPosition(JointValues),
    /// Move `joint` at `speed`.
    Speed {
        /// Joint index.
        joint: u16,
        /// Speed, rad/s or m/s.
        speed: f64,
    },
    /// Move joints 0..n at these speeds.
    MultiSpeed(JointValues),
    /// Home a joint or all.
    Home(JointSel),
    /// Drive a joint (or all) with a current.
    Current {
        /// Which joint(s).
        joint: JointSel,
        /// Current in A.
        current: f64,
    },
    /// Drive joints 0..n with these currents.
    MultiCurrent(JointValues),
}

impl ActArrayCommand {
    /// POS, validated (joint index in the array capacity, finite position).
    pub fn position(joint_index: i64, position: f64) -> Result<Self, ValueError> {
        Ok(ActArrayCommand::Position {
            joint: joint(joint_index)?,
            position: finite_value("position", position)?,
        })
    }
    /// MULTI_POS, validated.
    pub fn multi_position(positions: &[f64]) -> Result<Self, ValueError> {
        JointValues::new("positions", positions).map(ActArrayCommand::MultiPosition)
    }
    /// SPEED, validated.
    pub fn speed(joint_index: i64, speed: f64) -> Result<Self, ValueError> {
        Ok(ActArrayCommand::Speed {
            joint: joint(joint_index)?,
            speed: finite_value("speed", speed)?,
        })
    }
    /// MULTI_SPEED, validated.
    pub fn multi_speed(speeds: &[f64]) -> Result<Self, ValueError> {
        JointValues::new("speeds", speeds).map(ActArrayCommand::MultiSpeed)
    }
    /// HOME; `-1` = all joints.
    pub fn home(joint_index: i64) -> Result<Self, ValueError> {
        JointSel::new(joint_index).map(ActArrayCommand::Home)
    }
    /// CURRENT, validated; `-1` = all joints.
    pub fn current(joint_index: i64, current: f64) -> Result<Self, ValueError> {
        Ok(ActArrayCommand::Current {
            joint: JointSel::new(joint_index)?,
            current: finite_value("current", current)?,
        })
    }
    /// MULTI_CURRENT, validated.
    pub fn multi_current(currents: &[f64]) -> Result<Self, ValueError> {
        JointValues::new("currents", currents).map(ActArrayCommand::MultiCurrent)
    }
}

fn finite_value(field: &'static str, v: f64) -> Result<f64, ValueError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(ValueError::NotFinite { field })
    }
}

impl Message for ActArrayCommand {
    type Raw = ActArrayCmdMsg;
    const CHANNEL: &'static str = "actarray command";

    fn kind(&self) -> u32 {
        match self {
            ActArrayCommand::Position { .. } => cmd::POS,
            ActArrayCommand::MultiPosition(_) => cmd::MULTI_POS,
            ActArrayCommand::Speed { .. } => cmd::SPEED,
            ActArrayCommand::MultiSpeed(_) => cmd::MULTI_SPEED,
            ActArrayCommand::Home(_) => cmd::HOME,
            ActArrayCommand::Current { .. } => cmd::CURRENT,
            ActArrayCommand::MultiCurrent(_) => cmd::MULTI_CURRENT,
        }
    }

    fn write(&self, raw: &mut ActArrayCmdMsg) {
        let b = &mut raw.body;
        let len = match *self {
            ActArrayCommand::Position { joint, position } => message::put(
                b,
                &ActArrayPositionCmd {
                    joint: joint as i32,
                    _pad: 0,
                    position,
                },
            ),
            ActArrayCommand::MultiPosition(v) => {
                let (count, positions) = v.to_wire();
                message::put(
                    b,
                    &ActArrayMultiPositionCmd {
                        count,
                        _pad: 0,
                        positions,
                    },
                )
            }
            ActArrayCommand::Speed { joint, speed } => message::put(
                b,
                &ActArraySpeedCmd {
                    joint: joint as i32,
                    _pad: 0,
                    speed,
                },
            ),
            ActArrayCommand::MultiSpeed(v) => {
                let (count, speeds) = v.to_wire();
                message::put(
                    b,
                    &ActArrayMultiSpeedCmd {
                        count,
                        _pad: 0,
                        speeds,
                    },
                )
            }
            ActArrayCommand::Home(j) => message::put(
                b,
                &ActArrayHomeCmd {
                    joint: j.to_wire(),
                    _pad: 0,
                },
            ),
            ActArrayCommand::Current { joint, current } => message::put(
                b,
                &ActArrayCurrentCmd {
                    joint: joint.to_wire(),
                    _pad: 0,
                    current,
                },
            ),
            ActArrayCommand::MultiCurrent(v) => {
                let (count, currents) = v.to_wire();
                message::put(
                    b,
                    &ActArrayMultiCurrentCmd {
                        count,
                        _pad: 0,
                        currents,
                    },
                )
            }
        };
        raw.meta.kind = self.kind();
        raw.meta.body_len = len;
    }

    fn read(raw: &ActArrayCmdMsg) -> Result<Self, DecodeError> {
        let (k, b, n) = (raw.meta.kind, &raw.body[..], raw.meta.body_len);
        let ch = Self::CHANNEL;
        Ok(match k {
            cmd::POS => {
                let c: ActArrayPositionCmd = message::get(ch, k, b, n)?;
                ActArrayCommand::position(c.joint as i64, c.position)?
            }
            cmd::MULTI_POS => {
                let c: ActArrayMultiPositionCmd = message::get(ch, k, b, n)?;
                ActArrayCommand::MultiPosition(JointValues::from_wire(
                    "positions",
                    c.count,
                    &c.positions,
                )?)
            }
            cmd::SPEED => {
                let c: ActArraySpeedCmd = message::get(ch, k, b, n)?;
                ActArrayCommand::speed(c.joint as i64, c.speed)?
            }
            cmd::MULTI_SPEED => {
                let c: ActArrayMultiSpeedCmd = message::get(ch, k, b, n)?;
                ActArrayCommand::MultiSpeed(JointValues::from_wire("speeds", c.count, &c.speeds)?)
            }
            cmd::HOME => {
                let c: ActArrayHomeCmd = message::get(ch, k, b, n)?;
                ActArrayCommand::Home(JointSel::from_wire(c.joint)?)
            }
            cmd::CURRENT => {
                let c: ActArrayCurrentCmd = message::get(ch, k, b, n)?;
                ActArrayCommand::Current {
                    joint: JointSel::from_wire(c.joint)?,
                    current: finite_value("current", c.current)?,
                }
            }
            cmd::MULTI_CURRENT => {
                let c: ActArrayMultiCurrentCmd = message::get(ch, k, b, n)?;
                ActArrayCommand::MultiCurrent(JointValues::from_wire(
                    "currents",
                    c.count,
                    &c.currents,
                )?)
            }
            _ => {
                return Err(DecodeError::UnknownKind {
                    channel: ch,
                    kind: k,
                });
            }
        })
    }
}

/// A typed actarray request.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ActArrayRequest {
    /// Power on (`true`) or off.
    Power(bool),
    /// Brakes on (`true`) or off.
    Brakes(bool),
    /// Get the geometry.
    GetGeom,
    /// Set a joint's speed for later moves.
    Speed {
        /// Joint index.
        joint: u16,
        /// Speed, rad/s or m/s (finite, > 0).
        speed: f64,
    },
    /// Set a joint's acceleration for later moves.
    Accel {
        /// Joint index.
        joint: u16,
        /// Acceleration (finite).
        accel: f64,
    },
}

impl ActArrayRequest {
    /// REQ SPEED, validated.
    pub fn speed(joint_index: i64, speed: f64) -> Result<Self, ValueError> {
        Ok(ActArrayRequest::Speed {
            joint: joint(joint_index)?,
            speed: finite_value("speed", speed)?,
        })
    }
    /// REQ ACCEL, validated.
    pub fn accel(joint_index: i64, accel: f64) -> Result<Self, ValueError> {
        Ok(ActArrayRequest::Accel {
            joint: joint(joint_index)?,
            accel: finite_value("accel", accel)?,
        })
    }
}

pub(crate) fn on_off(field: &'static str, v: u32) -> Result<bool, DecodeError> {
    match v {
        0 => Ok(false),
        1 => Ok(true),
        _ => Err(DecodeError::UnknownCode {
            field,
            value: v as i64,
        }),
    }
}

impl Message for ActArrayRequest {
    type Raw = ActArrayReqMsg;
    const CHANNEL: &'static str = "actarray request";

    fn kind(&self) -> u32 {
        match self {
            ActArrayRequest::Power(_) => req::POWER,
            ActArrayRequest::Brakes(_) => req::BRAKES,
            ActArrayRequest::GetGeom => req::GET_GEOM,
            ActArrayRequest::Speed { .. } => req::SPEED,
            ActArrayRequest::Accel { .. } => req::ACCEL,
        }
    }

    fn write(&self, raw: &mut ActArrayReqMsg) {
        let b = &mut raw.body;
        let len = match *self {
            ActArrayRequest::Power(on) => message::put(b, &ActArrayPowerReq { value: on as u32 }),
            ActArrayRequest::Brakes(on) => message::put(b, &ActArrayBrakesReq { value: on as u32 }),
            ActArrayRequest::GetGeom => {
                b.fill(0);
                0
            }
            ActArrayRequest::Speed { joint, speed } => message::put(
                b,
                &ActArraySpeedReq {
                    joint: joint as i32,
                    _pad: 0,
                    speed,
                },
            ),
            ActArrayRequest::Accel { joint, accel } => message::put(
                b,
                &ActArrayAccelReq {
                    joint: joint as i32,
                    _pad: 0,
                    accel,
                },
            ),
        };
        raw.meta.kind = self.kind();
        raw.meta.body_len = len;
    }

    fn read(raw: &ActArrayReqMsg) -> Result<Self, DecodeError> {
        let (k, b, n) = (raw.meta.kind, &raw.body[..], raw.meta.body_len);
        let ch = Self::CHANNEL;
        Ok(match k {
            req::POWER => {
                let r: ActArrayPowerReq = message::get(ch, k, b, n)?;
                ActArrayRequest::Power(on_off("power value", r.value)?)
            }
            req::BRAKES => {
                let r: ActArrayBrakesReq = message::get(ch, k, b, n)?;
                ActArrayRequest::Brakes(on_off("brakes value", r.value)?)
            }
            req::GET_GEOM => {
                message::empty(ch, k, n)?;
                ActArrayRequest::GetGeom
            }
            req::SPEED => {
                let r: ActArraySpeedReq = message::get(ch, k, b, n)?;
                ActArrayRequest::speed(r.joint as i64, r.speed)?
            }
            req::ACCEL => {
                let r: ActArrayAccelReq = message::get(ch, k, b, n)?;
                ActArrayRequest::accel(r.joint as i64, r.accel)?
            }
            _ => {
                return Err(DecodeError::UnknownKind {
                    channel: ch,
                    kind: k,
                });
            }
        })
    }
}

/// The payload of an actarray ACK.
// Deliberately unboxed: a reply is built and read without touching the heap.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ActArrayReply {
    /// A plain ACK (POWER, BRAKES, SPEED, ACCEL).
    Done,
    /// The geometry (GET_GEOM).
    Geom(ActArrayGeom),
}

impl ReplyBody for ActArrayReply {
    type Raw = ActArrayReplyMsg;

    fn write(kind: u32, reply: Result<&Self, Status>, raw: &mut ActArrayReplyMsg) {
        raw.meta.kind = kind;
        match reply {
            Ok(ActArrayReply::Done) => {
                raw.meta.status = Status::Ok.code();
                raw.body.fill(0);
            }
            Ok(ActArrayReply::Geom(g)) => {
                raw.meta.status = Status::Ok.code();
                message::put(&mut raw.body, g);
            }
            Err(s) => {
                raw.meta.status = s.code();
                raw.body.fill(0);
            }
        }
    }

    fn read(raw: &ActArrayReplyMsg) -> Result<Result<Self, Status>, DecodeError> {
        let status = message::reply_status(&raw.meta)?;
        if !status.is_ok() {
            return Ok(Err(status));
        }
        match raw.meta.kind {
            req::GET_GEOM => {
                let g: ActArrayGeom = message::get(
                    "actarray reply",
                    req::GET_GEOM,
                    &raw.body,
                    core::mem::size_of::<ActArrayGeom>() as u32,
                )?;
                g.validate()?;
                Ok(Ok(ActArrayReply::Geom(g)))
            }
            req::POWER | req::BRAKES | req::SPEED | req::ACCEL => Ok(Ok(ActArrayReply::Done)),
            k => Err(DecodeError::UnknownKind {
                channel: "actarray reply",
                kind: k,
            }),
        }
    }
}

impl ActArrayData {
    /// The valid actuators (empty if `actuators_count` is beyond the capacity; call
    /// [`ActArrayData::validate`] to find out).
    pub fn actuators(&self) -> &[ActuatorState] {
        self.actuators
            .get(..self.actuators_count as usize)
            .unwrap_or(&[])
    }

    /// Checks the count, every state code and that every number is finite.
    pub fn validate(&self) -> Result<(), DecodeError> {
        if self.actuators_count as usize > MAX_ACTUATORS {
            return Err(ValueError::TooMany {
                field: "actuators_count",
                count: self.actuators_count as usize,
                max: MAX_ACTUATORS,
            }
            .into());
        }
        if self.motor_state > 1 {
            return Err(DecodeError::UnknownCode {
                field: "motor_state",
                value: self.motor_state as i64,
            });
        }
        for a in self.actuators() {
            a.flags()?;
            finite("position", a.position)?;
            finite("speed", a.speed)?;
            finite("acceleration", a.acceleration)?;
            finite("current", a.current)?;
        }
        Ok(())
    }
}

impl ActuatorState {
    /// The state bits, rejecting undefined bits.
    pub fn flags(&self) -> Result<ActuatorFlags, DecodeError> {
        ActuatorFlags::from_bits(self.state).ok_or(DecodeError::UnknownBits {
            field: "actuator state",
            bits: self.state & !ActuatorFlags::all().bits(),
        })
    }
}

impl ActuatorGeom {
    /// The actuator type, rejecting unknown codes.
    pub fn actuator_kind(&self) -> Result<ActuatorKind, DecodeError> {
        ActuatorKind::try_from(self.kind)
    }

    /// True when `v` lies within `[min, max]`.
    pub fn contains(&self, v: f64) -> bool {
        v >= self.min && v <= self.max
    }

    fn validate(&self) -> Result<(), DecodeError> {
        self.actuator_kind()?;
        for (f, v) in [
            ("length", self.length),
            ("min", self.min),
            ("centre", self.centre),
            ("max", self.max),
            ("home", self.home),
            ("config_speed", self.config_speed),
        ] {
            finite(f, v)?;
        }
        finite_vec("axis", self.axis)?;
        if !self.orientation.is_finite() {
            return Err(DecodeError::not_finite("orientation"));
        }
        Ok(())
    }
}

impl ActArrayGeom {
    /// The valid actuator geometries.
    pub fn actuators(&self) -> &[ActuatorGeom] {
        self.actuators
            .get(..self.actuators_count as usize)
            .unwrap_or(&[])
    }

    /// Checks the count, every code and that every number is finite.
    pub fn validate(&self) -> Result<(), DecodeError> {
        if self.actuators_count as usize > MAX_ACTUATORS {
            return Err(ValueError::TooMany {
                field: "actuators_count",
                count: self.actuators_count as usize,
                max: MAX_ACTUATORS,
            }
            .into());
        }
        for a in self.actuators() {
            a.validate()?;
        }
        finite_vec("base_pos", self.base_pos)?;
        if !self.base_orientation.is_finite() {
            return Err(DecodeError::not_finite("base_orientation"));
        }
        Ok(())
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
        ],
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
