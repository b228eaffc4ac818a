//! `limb`: a multi-jointed limb commanded at the end effector, Player interface 54.
//!
//! State: [`LimbData`] (position, approach and orientation vectors in robot coordinates).
//! Commands ([`LimbCommand`], envelope [`LimbCmdMsg`]): HOME, STOP, SETPOSE, SETPOSITION,
//! VECMOVE. Requests ([`LimbRequest`], envelope [`LimbReqMsg`]): POWER, BRAKES, GEOM, SPEED,
//! and REACH (limber's own: where would a SETPOSE end, without moving); replies in
//! [`LimbReplyMsg`] ([`LimbReply`]).
//!
//! # SETPOSE on a limb with fewer than six joints
//!
//! Five joints cannot hold every frame: once the position and the approach are fixed,
//! the orientation vector is fixed too (up to a few branches). A SETPOSE therefore puts
//! the end effector at the position and the approach (within the driver's documented
//! tolerances) and turns the orientation to the nearest one the joints can hold. The
//! outcome is `Status::Adjusted` when that changed the orientation by more than round-off,
//! and [`LimbData::orientation_adjustment`] says by how much (rad). Poses beyond the
//! reach or the joint limits are refused with their cause.

use crate::actarray::on_off;
use crate::common::{MsgMeta, ReplyMeta, StateHeader, Status, Vec3, finite_vec};
use crate::error::{DecodeError, ValueError};
use crate::manifest::{Constant, ConstantGroup};
use crate::message::{self, Message, ReplyBody, envelope, reply_envelope};
#[allow(unused_imports)]
use crate::wire::{ZeroCopySend, wire_struct};

mod path;
pub use path::{LimbPath, LimbPathCmd, PathOrientation, path_orient};

/// Command kinds (Player's `PLAYER_LIMB_CMD_*`).
pub mod cmd {
    /// Go to the home pose.
    pub const HOME: u32 = 1;
    /// Stop every joint now.
    pub const STOP: u32 = 2;
    /// Go to a pose (position, approach, orientation).
    pub const SETPOSE: u32 = 3;
    /// Go to a position, orientation free.
    pub const SETPOSITION: u32 = 4;
    /// Move along a straight line.
    pub const VECMOVE: u32 = 5;
    /// A straight line of the tool to a position (limber's; [`LimbPathCmd`](super::LimbPathCmd)).
    pub const LINE: u32 = 6;
    /// A point-to-point move, the joints interpolated (limber's; [`LimbPathCmd`](super::LimbPathCmd)).
    pub const PTP: u32 = 7;
}

/// Request kinds (Player's `PLAYER_LIMB_REQ_*`).
pub mod req {
    /// Power on or off.
    pub const POWER: u32 = 1;
    /// Brakes on or off.
    pub const BRAKES: u32 = 2;
    /// Get the geometry.
    pub const GEOM: u32 = 3;
    /// Set the end-effector speed.
    pub const SPEED: u32 = 4;
    /// Where would a SETPOSE to this pose end? Nothing moves (limber's own).
    pub const REACH: u32 = 5;
}

/// The limb's state (Player's `PLAYER_LIMB_STATE_*`): plain values, not bits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum LimbState {
    /// At rest.
    Idle = 1,
    /// Brakes applied.
    Braked = 2,
    /// Moving.
    Moving = 3,
    /// The last target was out of reach (cleared by the next valid command).
    OutOfReach = 4,
    /// Blocked (a joint stalled short of its target).
    Collision = 5,
}

impl TryFrom<u32> for LimbState {
    type Error = DecodeError;
    fn try_from(v: u32) -> Result<Self, DecodeError> {
        Ok(match v {
            1 => LimbState::Idle,
            2 => LimbState::Braked,
            3 => LimbState::Moving,
            4 => LimbState::OutOfReach,
            5 => LimbState::Collision,
            _ => {
                return Err(DecodeError::UnknownCode {
                    field: "limb state",
                    value: v as i64,
                });
            }
        })
    }
}

wire_struct! {
    /// The limb's state (channel `data`).
    pub struct LimbData : "limber.v6.LimbData", size = 184, align = 8 {
        /// Common header.
        pub header: StateHeader,
        /// End-effector position, robot coordinates, m.
        pub position: Vec3,
        /// Approach vector (unit, forward along the gripper).
        pub approach: Vec3,
        /// Orientation vector (unit, fingertip to fingertip / "up" from the gripper).
        pub orientation: Vec3,
        /// `LIMB_STATE` value.
        pub state: u32,
        /// Reserved, zero.
        pub _pad: u32,
        /// How much the last SETPOSE turned the requested orientation to the nearest one
        /// the joints can hold, rad (0 when it was held as asked; cleared by the next
        /// limb command).
        pub orientation_adjustment: f64,
        /// How far the running LINE or PTP has got, 0 to 1 (the fraction of its
        /// trajectory's time; valid when `path_kind` is not 0).
        pub path_progress: f64,
        /// Where the last LINE or PTP refused before it started first failed its check:
        /// the tool point there, m (valid when `refused_kind` is not 0).
        pub refused_at: Vec3,
        /// That point's fraction of the path, 0 (start) to 1 (goal).
        pub refused_fraction: f64,
        /// The kind of the running path (`LIMB_CMD_LINE`, `LIMB_CMD_PTP`); 0 when none.
        pub path_kind: u32,
        /// The kind of the path the last limb command refused (`LIMB_CMD_LINE`,
        /// `LIMB_CMD_PTP`) with `refused_at` saying where; 0 when it was not a refused
        /// path (cleared by the next limb command).
        pub refused_kind: u32,
    }
}

wire_struct! {
    /// CMD SETPOSE: move the end effector to a pose.
    pub struct LimbSetPoseCmd : "limber.v6.LimbSetPoseCmd", size = 72, align = 8 {
        /// Target position, robot coordinates, m.
        pub position: Vec3,
        /// Target approach vector (need not be unit length, must not be zero).
        pub approach: Vec3,
        /// Target orientation vector (need not be unit length, must not be zero).
        pub orientation: Vec3,
    }
}

wire_struct! {
    /// CMD SETPOSITION: move the end effector to a position, orientation left to the driver.
    pub struct LimbSetPositionCmd : "limber.v6.LimbSetPositionCmd", size = 24, align = 8 {
        /// Target position, robot coordinates, m.
        pub position: Vec3,
    }
}

wire_struct! {
    /// CMD VECMOVE: move the end effector `length` m along `direction` in a straight line.
    pub struct LimbVecMoveCmd : "limber.v6.LimbVecMoveCmd", size = 32, align = 8 {
        /// Direction (need not be unit length, must not be zero).
        pub direction: Vec3,
        /// Distance, m.
        pub length: f64,
    }
}

wire_struct! {
    /// The command envelope (channel `cmd`). HOME and STOP have an empty body.
    pub struct LimbCmdMsg : "limber.v6.LimbCmdMsg", size = 120, align = 8 {
        /// Sender, sequence, time, kind, body length.
        pub meta: MsgMeta,
        /// One of the `Limb*Cmd` structs.
        pub body: [u8; 88],
    }
}

wire_struct! {
    /// REQ POWER: power on (1) or off (0).
    pub struct LimbPowerReq : "limber.v6.LimbPowerReq", size = 4, align = 4 {
        /// 0 off, 1 on.
        pub value: u32,
    }
}

wire_struct! {
    /// REQ BRAKES: brakes on (1) or off (0).
    pub struct LimbBrakesReq : "limber.v6.LimbBrakesReq", size = 4, align = 4 {
        /// 0 off, 1 on.
        pub value: u32,
    }
}

wire_struct! {
    /// REQ SPEED: the end-effector speed for later moves, m/s.
    pub struct LimbSpeedReq : "limber.v6.LimbSpeedReq", size = 8, align = 8 {
        /// Speed, m/s.
        pub speed: f64,
    }
}

wire_struct! {
    /// REQ REACH: the pose a SETPOSE would ask for (same fields as [`LimbSetPoseCmd`]).
    pub struct LimbReachReq : "limber.v6.LimbReachReq", size = 72, align = 8 {
        /// Target position, robot coordinates, m.
        pub position: Vec3,
        /// Target approach vector (non-zero).
        pub approach: Vec3,
        /// Target orientation vector (non-zero).
        pub orientation: Vec3,
    }
}

wire_struct! {
    /// The request envelope (channel `req`). GEOM has an empty body.
    pub struct LimbReqMsg : "limber.v6.LimbReqMsg", size = 104, align = 8 {
        /// Sender, sequence, time, kind, body length.
        pub meta: MsgMeta,
        /// One of the `Limb*Req` structs.
        pub body: [u8; 72],
    }
}

wire_struct! {
    /// The limb geometry (the GEOM reply).
    pub struct LimbGeom : "limber.v6.LimbGeom", size = 24, align = 8 {
        /// The limb base in robot coordinates, m.
        pub base_pos: Vec3,
    }
}

wire_struct! {
    /// The REACH reply: where a SETPOSE to the requested pose would end (before the
    /// joints are rounded to the hardware's resolution) and what it would change.
    pub struct LimbReach : "limber.v6.LimbReach", size = 104, align = 8 {
        /// End-effector position it would end at, robot coordinates, m.
        pub position: Vec3,
        /// Approach vector it would end with.
        pub approach: Vec3,
        /// Orientation vector it would end with.
        pub orientation: Vec3,
        /// How much the orientation would be turned to one the joints can hold, rad.
        pub orientation_adjustment: f64,
        /// Distance from the requested position, m.
        pub position_error: f64,
        /// Angle from the requested approach, rad.
        pub approach_error: f64,
        /// 1 when a SETPOSE would answer `ADJUSTED`, 0 when `OK`.
        pub adjusted: u32,
        /// Reserved, zero.
        pub _pad: u32,
    }
}

wire_struct! {
    /// The reply envelope (channel `req`).
    pub struct LimbReplyMsg : "limber.v6.LimbReplyMsg", size = 136, align = 8 {
        /// Client, sequence, time, kind, status.
        pub meta: ReplyMeta,
        /// `LimbGeom` for GEOM, `LimbReach` for REACH, empty otherwise.
        pub body: [u8; 104],
    }
}

envelope!(LimbCmdMsg);
envelope!(LimbReqMsg);
reply_envelope!(LimbReplyMsg);

/// Vectors shorter than this count as zero.
pub const MIN_VECTOR_NORM: f64 = 1e-9;

fn direction(field: &'static str, v: Vec3) -> Result<Vec3, ValueError> {
    if !v.is_finite() {
        return Err(ValueError::NotFinite { field });
    }
    if v.norm() < MIN_VECTOR_NORM {
        return Err(ValueError::ZeroVector { field });
    }
    Ok(v)
}

fn point(field: &'static str, v: Vec3) -> Result<Vec3, ValueError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(ValueError::NotFinite { field })
    }
}

/// A typed limb command.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LimbCommand {
    /// Go to the home pose.
    Home,
    /// Stop every joint now.
    Stop,
    /// Go to a pose.
    SetPose {
        /// Position, robot coordinates, m.
        position: Vec3,
        /// Approach vector (non-zero).
        approach: Vec3,
        /// Orientation vector (non-zero).
        orientation: Vec3,
    },
    /// Go to a position, orientation free.
    SetPosition {
        /// Position, robot coordinates, m.
        position: Vec3,
    },
    /// Move `length` m along `direction`.
    VecMove {
        /// Direction (non-zero).
        direction: Vec3,
        /// Distance, m (finite).
        length: f64,
    },
    /// A straight line of the tool to a goal (limber's LINE).
    Line(LimbPath),
    /// A point-to-point move to a goal, the joints interpolated (limber's PTP).
    Ptp(LimbPath),
}

impl LimbCommand {
    /// SETPOSE, validated (finite, non-zero approach and orientation).
    pub fn set_pose(position: Vec3, approach: Vec3, orientation: Vec3) -> Result<Self, ValueError> {
        Ok(LimbCommand::SetPose {
            position: point("position", position)?,
            approach: direction("approach", approach)?,
            orientation: direction("orientation", orientation)?,
        })
    }
    /// SETPOSITION, validated.
    pub fn set_position(position: Vec3) -> Result<Self, ValueError> {
        Ok(LimbCommand::SetPosition {
            position: point("position", position)?,
        })
    }
    /// LINE, validated ([`LimbPath::new`]): the tool in a straight line to `position`,
    /// its orientation kept (`None`) or turned evenly to (approach, orientation), at most
    /// `speed` m/s (0: the limb's own).
    pub fn line(
        position: Vec3,
        orientation: Option<(Vec3, Vec3)>,
        speed: f64,
    ) -> Result<Self, ValueError> {
        LimbPath::new(position, orientation, speed).map(LimbCommand::Line)
    }
    /// PTP, validated ([`LimbPath::new`]): the joints interpolated to where the tool is at
    /// `position` with its orientation kept (`None`) or the given one, the fastest joint
    /// at most `speed` rad/s (0: the joints' own).
    pub fn ptp(
        position: Vec3,
        orientation: Option<(Vec3, Vec3)>,
        speed: f64,
    ) -> Result<Self, ValueError> {
        LimbPath::new(position, orientation, speed).map(LimbCommand::Ptp)
    }
    /// VECMOVE, validated.
    pub fn vec_move(dir: Vec3, length: f64) -> Result<Self, ValueError> {
        if !length.is_finite() {
            return Err(ValueError::NotFinite { field: "length" });
        }
        Ok(LimbCommand::VecMove {
            direction: direction("direction", dir)?,
            length,
        })
    }
}

impl Message for LimbCommand {
    type Raw = LimbCmdMsg;
    const CHANNEL: &'static str = "limb command";

    fn kind(&self) -> u32 {
        match self {
            LimbCommand::Home => cmd::HOME,
            LimbCommand::Stop => cmd::STOP,
            LimbCommand::SetPose { .. } => cmd::SETPOSE,
            LimbCommand::SetPosition { .. } => cmd::SETPOSITION,
            LimbCommand::VecMove { .. } => cmd::VECMOVE,
            LimbCommand::Line(_) => cmd::LINE,
            LimbCommand::Ptp(_) => cmd::PTP,
        }
    }

    fn write(&self, raw: &mut LimbCmdMsg) {
        let b = &mut raw.body;
        let len = match *self {
            LimbCommand::Home | LimbCommand::Stop => {
                b.fill(0);
                0
            }
            LimbCommand::SetPose {
                position,
                approach,
                orientation,
            } => message::put(
                b,
                &LimbSetPoseCmd {
                    position,
                    approach,
                    orientation,
                },
            ),
            LimbCommand::SetPosition { position } => {
                message::put(b, &LimbSetPositionCmd { position })
            }
            LimbCommand::VecMove { direction, length } => {
                message::put(b, &LimbVecMoveCmd { direction, length })
            }
            LimbCommand::Line(p) | LimbCommand::Ptp(p) => message::put(b, &p.to_wire()),
        };
        raw.meta.kind = self.kind();
        raw.meta.body_len = len;
    }

    fn read(raw: &LimbCmdMsg) -> Result<Self, DecodeError> {
        let (k, b, n) = (raw.meta.kind, &raw.body[..], raw.meta.body_len);
        let ch = Self::CHANNEL;
        Ok(match k {
            cmd::HOME => {
                message::empty(ch, k, n)?;
                LimbCommand::Home
            }
            cmd::STOP => {
                message::empty(ch, k, n)?;
                LimbCommand::Stop
            }
            cmd::SETPOSE => {
                let c: LimbSetPoseCmd = message::get(ch, k, b, n)?;
                LimbCommand::set_pose(c.position, c.approach, c.orientation)?
            }
            cmd::SETPOSITION => {
                let c: LimbSetPositionCmd = message::get(ch, k, b, n)?;
                LimbCommand::set_position(c.position)?
            }
            cmd::VECMOVE => {
                let c: LimbVecMoveCmd = message::get(ch, k, b, n)?;
                LimbCommand::vec_move(c.direction, c.length)?
            }
            cmd::LINE => {
                let c: LimbPathCmd = message::get(ch, k, b, n)?;
                LimbCommand::Line(LimbPath::from_wire(&c)?)
            }
            cmd::PTP => {
                let c: LimbPathCmd = message::get(ch, k, b, n)?;
                LimbCommand::Ptp(LimbPath::from_wire(&c)?)
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

/// A typed limb request.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LimbRequest {
    /// Power on (`true`) or off.
    Power(bool),
    /// Brakes on (`true`) or off.
    Brakes(bool),
    /// Get the geometry.
    Geom,
    /// Set the end-effector speed, m/s (finite).
    Speed(f64),
    /// Where would a SETPOSE to this pose end? Nothing moves.
    Reach {
        /// Position, robot coordinates, m.
        position: Vec3,
        /// Approach vector (non-zero).
        approach: Vec3,
        /// Orientation vector (non-zero).
        orientation: Vec3,
    },
}

impl LimbRequest {
    /// REQ REACH, validated like SETPOSE (finite, non-zero approach and orientation).
    pub fn reach(position: Vec3, approach: Vec3, orientation: Vec3) -> Result<Self, ValueError> {
        Ok(LimbRequest::Reach {
            position: point("position", position)?,
            approach: direction("approach", approach)?,
            orientation: direction("orientation", orientation)?,
        })
    }

    /// REQ SPEED, validated.
    pub fn speed(speed: f64) -> Result<Self, ValueError> {
        if speed.is_finite() {
            Ok(LimbRequest::Speed(speed))
        } else {
            Err(ValueError::NotFinite { field: "speed" })
        }
    }
}

impl Message for LimbRequest {
    type Raw = LimbReqMsg;
    const CHANNEL: &'static str = "limb request";

    fn is_read_only(&self) -> bool {
        matches!(self, LimbRequest::Geom)
    }

    fn kind(&self) -> u32 {
        match self {
            LimbRequest::Power(_) => req::POWER,
            LimbRequest::Brakes(_) => req::BRAKES,
            LimbRequest::Geom => req::GEOM,
            LimbRequest::Speed(_) => req::SPEED,
            LimbRequest::Reach { .. } => req::REACH,
        }
    }

    fn write(&self, raw: &mut LimbReqMsg) {
        let b = &mut raw.body;
        let len = match *self {
            LimbRequest::Power(on) => message::put(b, &LimbPowerReq { value: on as u32 }),
            LimbRequest::Brakes(on) => message::put(b, &LimbBrakesReq { value: on as u32 }),
            LimbRequest::Geom => {
                b.fill(0);
                0
            }
            LimbRequest::Speed(speed) => message::put(b, &LimbSpeedReq { speed }),
            LimbRequest::Reach {
                position,
                approach,
                orientation,
            } => message::put(
                b,
                &LimbReachReq {
                    position,
                    approach,
                    orientation,
                },
            ),
        };
        raw.meta.kind = self.kind();
        raw.meta.body_len = len;
    }

    fn read(raw: &LimbReqMsg) -> Result<Self, DecodeError> {
        let (k, b, n) = (raw.meta.kind, &raw.body[..], raw.meta.body_len);
        let ch = Self::CHANNEL;
        Ok(match k {
            req::POWER => {
                let r: LimbPowerReq = message::get(ch, k, b, n)?;
                LimbRequest::Power(on_off("power value", r.value)?)
            }
            req::BRAKES => {
                let r: LimbBrakesReq = message::get(ch, k, b, n)?;
                LimbRequest::Brakes(on_off("brakes value", r.value)?)
            }
            req::GEOM => {
                message::empty(ch, k, n)?;
                LimbRequest::Geom
            }
            req::SPEED => {
                let r: LimbSpeedReq = message::get(ch, k, b, n)?;
                LimbRequest::speed(r.speed)?
            }
            req::REACH => {
                let r: LimbReachReq = message::get(ch, k, b, n)?;
                LimbRequest::reach(r.position, r.approach, r.orientation)?
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

/// The payload of a limb ACK.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum LimbReply {
    /// A plain ACK (POWER, BRAKES, SPEED).
    Done,
    /// The geometry (GEOM).
    Geom(LimbGeom),
    /// Where a SETPOSE would end (REACH).
    Reach(LimbReach),
}

impl ReplyBody for LimbReply {
    type Raw = LimbReplyMsg;

    fn write(kind: u32, reply: Result<&Self, Status>, raw: &mut LimbReplyMsg) {
        raw.meta.kind = kind;
        match reply {
            Ok(LimbReply::Done) => {
                raw.meta.status = Status::Ok.code();
                raw.body.fill(0);
            }
            Ok(LimbReply::Geom(g)) => {
                raw.meta.status = Status::Ok.code();
                message::put(&mut raw.body, g);
            }
            Ok(LimbReply::Reach(r)) => {
                raw.meta.status = Status::Ok.code();
                message::put(&mut raw.body, r);
            }
            Err(s) => {
                raw.meta.status = s.code();
                raw.body.fill(0);
            }
        }
    }

    fn read(raw: &LimbReplyMsg) -> Result<Result<Self, Status>, DecodeError> {
        let status = message::reply_status(&raw.meta)?;
        if !status.is_ok() {
            return Ok(Err(status));
        }
        match raw.meta.kind {
            req::GEOM => {
                let g: LimbGeom = message::get(
                    "limb reply",
                    req::GEOM,
                    &raw.body,
                    core::mem::size_of::<LimbGeom>() as u32,
                )?;
                finite_vec("base_pos", g.base_pos)?;
                Ok(Ok(LimbReply::Geom(g)))
            }
            req::REACH => {
                let r: LimbReach = message::get(
                    "limb reply",
                    req::REACH,
                    &raw.body,
                    core::mem::size_of::<LimbReach>() as u32,
                )?;
                r.validate()?;
                Ok(Ok(LimbReply::Reach(r)))
            }
            req::POWER | req::BRAKES | req::SPEED => Ok(Ok(LimbReply::Done)),
            k => Err(DecodeError::UnknownKind {
                channel: "limb reply",
                kind: k,
            }),
        }
    }
}

impl LimbReach {
    /// Checks that every number is finite and `adjusted` is 0 or 1.
    pub fn validate(&self) -> Result<(), DecodeError> {
        finite_vec("position", self.position)?;
        finite_vec("approach", self.approach)?;
        finite_vec("orientation", self.orientation)?;
        for (field, v) in [
            ("orientation_adjustment", self.orientation_adjustment),
            ("position_error", self.position_error),
            ("approach_error", self.approach_error),
        ] {
            if !v.is_finite() {
                return Err(DecodeError::Value(ValueError::NotFinite { field }));
            }
        }
        on_off("adjusted", self.adjusted)?;
        Ok(())
    }
}

impl LimbData {
    /// The state, rejecting unknown codes.
    pub fn limb_state(&self) -> Result<LimbState, DecodeError> {
        LimbState::try_from(self.state)
    }

    /// Checks the state code and that every number is finite.
    pub fn validate(&self) -> Result<(), DecodeError> {
        self.limb_state()?;
        finite_vec("position", self.position)?;
        finite_vec("approach", self.approach)?;
        finite_vec("orientation", self.orientation)?;
        if !self.orientation_adjustment.is_finite() {
            return Err(DecodeError::Value(ValueError::NotFinite {
                field: "orientation_adjustment",
            }));
        }
        Ok(())
    }
}

pub(crate) const GROUPS: &[ConstantGroup] = &[
    ConstantGroup {
        name: "LIMB_CMD",
        doc: "limb command kinds (MsgMeta.kind on the cmd channel)",
        constants: &[
            Constant {
                name: "HOME",
                value: 1,
                doc: "empty body",
            },
            Constant {
                name: "STOP",
                value: 2,
                doc: "empty body",
            },
            Constant {
                name: "SETPOSE",
                value: 3,
                doc: "LimbSetPoseCmd",
            },
            Constant {
                name: "SETPOSITION",
                value: 4,
                doc: "LimbSetPositionCmd",
            },
            Constant {
                name: "VECMOVE",
                value: 5,
                doc: "LimbVecMoveCmd",
            },
            Constant {
                name: "LINE",
                value: 6,
                doc: "LimbPathCmd: a straight line of the tool",
            },
            Constant {
                name: "PTP",
                value: 7,
                doc: "LimbPathCmd: a point-to-point move, the joints interpolated",
            },
        ],
    },
    ConstantGroup {
        name: "LIMB_REQ",
        doc: "limb request kinds (MsgMeta.kind on the req channel)",
        constants: &[
            Constant {
                name: "POWER",
                value: 1,
                doc: "LimbPowerReq; reply empty",
            },
            Constant {
                name: "BRAKES",
                value: 2,
                doc: "LimbBrakesReq; reply empty",
            },
            Constant {
                name: "GEOM",
                value: 3,
                doc: "empty; reply LimbGeom",
            },
            Constant {
                name: "SPEED",
                value: 4,
                doc: "LimbSpeedReq; reply empty",
            },
            Constant {
                name: "REACH",
                value: 5,
                doc: "LimbReachReq; reply LimbReach (nothing moves)",
            },
        ],
    },
    ConstantGroup {
        name: "LIMB_STATE",
        doc: "LimbData.state values",
        constants: &[
            Constant {
                name: "IDLE",
                value: 1,
                doc: "at rest",
            },
            Constant {
                name: "BRAKED",
                value: 2,
                doc: "brakes applied",
            },
            Constant {
                name: "MOVING",
                value: 3,
                doc: "moving",
            },
            Constant {
                name: "OOR",
                value: 4,
                doc: "last target out of reach",
            },
            Constant {
                name: "COLL",
                value: 5,
                doc: "blocked",
            },
        ],
    },
    path::PATH_ORIENT_GROUP,
];
