//! `gripper`: a gripper with optional break beams and storage, Player interface 3.
//!
//! State: [`GripperData`]. Commands ([`GripperCommand`], envelope [`GripperCmdMsg`]):
//! OPEN, CLOSE, STOP, STORE, RETRIEVE (all without body), and limber's GOAL
//! ([`GripperGoalCmd`]: a gap with a maximum effort and speed, whose result says
//! REACHED or STALLED, with `OBJECT_PRESENT` when the break beams see an object).
//! Request ([`GripperRequest`]):
//! GET_GEOM, answered with [`GripperGeom`] in [`GripperReplyMsg`].

use crate::common::{Bbox3, MsgMeta, Pose3, ReplyMeta, StateHeader, Status};
use crate::error::{DecodeError, ValueError};
use crate::manifest::{Constant, ConstantGroup};
use crate::message::{self, Message, ReplyBody, envelope, reply_envelope};
#[allow(unused_imports)]
use crate::wire::{ZeroCopySend, wire_struct};

/// Command kinds (Player's `PLAYER_GRIPPER_CMD_*`).
pub mod cmd {
    /// Open the fingers / paddles.
    pub const OPEN: u32 = 1;
    /// Close them.
    pub const CLOSE: u32 = 2;
    /// Stop them.
    pub const STOP: u32 = 3;
    /// Store the held object.
    pub const STORE: u32 = 4;
    /// Retrieve a stored object.
    pub const RETRIEVE: u32 = 5;
    /// Move the fingers to a gap (limber's; [`GripperGoalCmd`](super::GripperGoalCmd)).
    pub const GOAL: u32 = 6;
}

/// Request kinds (Player's `PLAYER_GRIPPER_REQ_*`).
pub mod req {
    /// Get the geometry.
    pub const GET_GEOM: u32 = 1;
}

/// The gripper's state (Player's `PLAYER_GRIPPER_STATE_*`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum GripperState {
    /// Open.
    Open = 1,
    /// Closed (possibly on an object).
    Closed = 2,
    /// Moving.
    Moving = 3,
    /// In error.
    Error = 4,
}

impl TryFrom<u32> for GripperState {
    type Error = DecodeError;
    fn try_from(v: u32) -> Result<Self, DecodeError> {
        Ok(match v {
            1 => GripperState::Open,
            2 => GripperState::Closed,
            3 => GripperState::Moving,
            4 => GripperState::Error,
            _ => {
                return Err(DecodeError::UnknownCode {
                    field: "gripper state",
                    value: v as i64,
                });
            }
        })
    }
}

wire_struct! {
    /// The gripper's state (channel `data`).
    pub struct GripperData : "limber.v6.GripperData", size = 64, align = 8 {
        /// Common header.
        pub header: StateHeader,
        /// `GRIPPER_STATE` value.
        pub state: u32,
        /// Break-beam bit mask: bit i set = beam i broken (beam 0 the outermost).
        pub beams: u32,
        /// Number of objects stored.
        pub stored: u32,
        /// Reserved, zero.
        pub _pad: u32,
    }
}

wire_struct! {
    /// CMD GOAL: move the fingers to a gap, with at most an effort and a speed.
    pub struct GripperGoalCmd : "limber.v6.GripperGoalCmd", size = 24, align = 8 {
        /// The goal gap between the fingers, m (0: closed).
        pub gap: f64,
        /// The largest grip effort, N; 0: the gripper's own.
        pub effort: f64,
        /// The fingers' speed, m/s; 0: the gripper's configured speed.
        pub speed: f64,
    }
}

wire_struct! {
    /// The command envelope (channel `cmd`). GOAL's body is a [`GripperGoalCmd`]; every
    /// other gripper command has an empty body.
    pub struct GripperCmdMsg : "limber.v6.GripperCmdMsg", size = 56, align = 8 {
        /// Sender, sequence, time, kind, body length.
        pub meta: MsgMeta,
        /// The body (GOAL's `GripperGoalCmd`), zero-padded.
        pub body: [u8; 24],
    }
}

wire_struct! {
    /// The request envelope (channel `req`). GET_GEOM has an empty body.
    pub struct GripperReqMsg : "limber.v6.GripperReqMsg", size = 40, align = 8 {
        /// Sender, sequence, time, kind, body length (0).
        pub meta: MsgMeta,
        /// Reserved, zero.
        pub body: [u8; 8],
    }
}

wire_struct! {
    /// The gripper geometry (the GET_GEOM reply).
    pub struct GripperGeom : "limber.v6.GripperGeom", size = 104, align = 8 {
        /// Pose of the gripper in the robot frame.
        pub pose: Pose3,
        /// Outer size, m.
        pub outer_size: Bbox3,
        /// Space between the fully opened fingers, m.
        pub inner_size: Bbox3,
        /// Number of break beams.
        pub num_beams: u32,
        /// How many objects it can store (0 = cannot store).
        pub capacity: u32,
    }
}

wire_struct! {
    /// The reply envelope (channel `req`).
    pub struct GripperReplyMsg : "limber.v6.GripperReplyMsg", size = 136, align = 8 {
        /// Client, sequence, time, kind, status.
        pub meta: ReplyMeta,
        /// `GripperGeom` for GET_GEOM.
        pub body: [u8; 104],
    }
}

envelope!(GripperCmdMsg);
envelope!(GripperReqMsg);
reply_envelope!(GripperReplyMsg);

/// A typed gripper command.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GripperCommand {
    /// Open.
    Open,
    /// Close.
    Close,
    /// Stop.
    Stop,
    /// Store the held object.
    Store,
    /// Retrieve a stored object.
    Retrieve,
    /// Move the fingers to a gap (validated by [`GripperCommand::goal`]).
    Goal {
        /// The goal gap, m (finite, not negative).
        gap: f64,
        /// The largest effort, N (finite, not negative; 0: the gripper's own).
        effort: f64,
        /// The speed, m/s (finite, not negative; 0: the configured speed).
        speed: f64,
    },
}

impl GripperCommand {
    /// GOAL, validated: every value finite and not negative (0 effort or speed: the
    /// gripper's own). What the gripper can do with them is the driver's to say.
    pub fn goal(gap: f64, effort: f64, speed: f64) -> Result<Self, ValueError> {
        for (field, v) in [("gap", gap), ("effort", effort), ("speed", speed)] {
            if !v.is_finite() {
                return Err(ValueError::NotFinite { field });
            }
            if v < 0.0 {
                return Err(ValueError::Negative { field });
            }
        }
        Ok(GripperCommand::Goal { gap, effort, speed })
    }
}

impl Message for GripperCommand {
    type Raw = GripperCmdMsg;
    const CHANNEL: &'static str = "gripper command";

    fn kind(&self) -> u32 {
        match self {
            GripperCommand::Open => cmd::OPEN,
            GripperCommand::Close => cmd::CLOSE,
            GripperCommand::Stop => cmd::STOP,
            GripperCommand::Store => cmd::STORE,
            GripperCommand::Retrieve => cmd::RETRIEVE,
            GripperCommand::Goal { .. } => cmd::GOAL,
        }
    }

    fn write(&self, raw: &mut GripperCmdMsg) {
        raw.body.fill(0);
        raw.meta.kind = self.kind();
        raw.meta.body_len = match *self {
            GripperCommand::Goal { gap, effort, speed } => {
                message::put(&mut raw.body, &GripperGoalCmd { gap, effort, speed })
            }
            _ => 0,
        };
    }

    fn read(raw: &GripperCmdMsg) -> Result<Self, DecodeError> {
        let k = raw.meta.kind;
        let c = match k {
            cmd::OPEN => GripperCommand::Open,
            cmd::CLOSE => GripperCommand::Close,
            cmd::STOP => GripperCommand::Stop,
            cmd::STORE => GripperCommand::Store,
            cmd::RETRIEVE => GripperCommand::Retrieve,
            cmd::GOAL => {
                let g: GripperGoalCmd =
                    message::get(Self::CHANNEL, k, &raw.body, raw.meta.body_len)?;
                return Ok(GripperCommand::goal(g.gap, g.effort, g.speed)?);
            }
            _ => {
                return Err(DecodeError::UnknownKind {
                    channel: Self::CHANNEL,
                    kind: k,
                });
            }
        };
        message::empty(Self::CHANNEL, k, raw.meta.body_len)?;
        Ok(c)
    }
}

/// A typed gripper request.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum GripperRequest {
    /// Get the geometry.
    GetGeom,
}

impl Message for GripperRequest {
    type Raw = GripperReqMsg;
    const CHANNEL: &'static str = "gripper request";

    fn is_read_only(&self) -> bool {
        matches!(self, GripperRequest::GetGeom)
    }

    fn kind(&self) -> u32 {
        req::GET_GEOM
    }

    fn write(&self, raw: &mut GripperReqMsg) {
        raw.body.fill(0);
        raw.meta.kind = self.kind();
        raw.meta.body_len = 0;
    }

    fn read(raw: &GripperReqMsg) -> Result<Self, DecodeError> {
        match raw.meta.kind {
            req::GET_GEOM => {
                message::empty(Self::CHANNEL, req::GET_GEOM, raw.meta.body_len)?;
                Ok(GripperRequest::GetGeom)
            }
            k => Err(DecodeError::UnknownKind {
                channel: Self::CHANNEL,
                kind: k,
            }),
        }
    }
}

/// The payload of a gripper ACK.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum GripperReply {
    /// The geometry (GET_GEOM).
    Geom(GripperGeom),
}

impl ReplyBody for GripperReply {
    type Raw = GripperReplyMsg;

    fn write(kind: u32, reply: Result<&Self, Status>, raw: &mut GripperReplyMsg) {
        raw.meta.kind = kind;
        match reply {
            Ok(GripperReply::Geom(g)) => {
                raw.meta.status = Status::Ok.code();
                message::put(&mut raw.body, g);
            }
            Err(s) => {
                raw.meta.status = s.code();
                raw.body.fill(0);
            }
        }
    }

    fn read(raw: &GripperReplyMsg) -> Result<Result<Self, Status>, DecodeError> {
        let status = message::reply_status(&raw.meta)?;
        if !status.is_ok() {
            return Ok(Err(status));
        }
        match raw.meta.kind {
            req::GET_GEOM => {
                let g: GripperGeom = message::get(
                    "gripper reply",
                    req::GET_GEOM,
                    &raw.body,
                    core::mem::size_of::<GripperGeom>() as u32,
                )?;
                if !(g.pose.is_finite() && g.outer_size.is_finite() && g.inner_size.is_finite()) {
                    return Err(DecodeError::not_finite("gripper geometry"));
                }
                Ok(Ok(GripperReply::Geom(g)))
            }
            k => Err(DecodeError::UnknownKind {
                channel: "gripper reply",
                kind: k,
            }),
        }
    }
}

impl GripperData {
    /// The state, rejecting unknown codes.
    pub fn gripper_state(&self) -> Result<GripperState, DecodeError> {
        GripperState::try_from(self.state)
    }

    /// True when break beam `i` is broken.
    pub fn beam(&self, i: u32) -> bool {
        i < 32 && self.beams & (1 << i) != 0
    }

    /// Checks the state code.
    pub fn validate(&self) -> Result<(), DecodeError> {
        self.gripper_state().map(|_| ())
    }
}

pub(crate) const GROUPS: &[ConstantGroup] = &[
    ConstantGroup {
        name: "GRIPPER_CMD",
        doc: "gripper command kinds (MsgMeta.kind on the cmd channel); all but GOAL have an empty body",
        constants: &[
            Constant {
                name: "OPEN",
                value: 1,
                doc: "open",
            },
            Constant {
                name: "CLOSE",
                value: 2,
                doc: "close",
            },
            Constant {
                name: "STOP",
                value: 3,
                doc: "stop",
            },
            Constant {
                name: "STORE",
                value: 4,
                doc: "store the held object",
            },
            Constant {
                name: "RETRIEVE",
                value: 5,
                doc: "retrieve a stored object",
            },
            Constant {
                name: "GOAL",
                value: 6,
                doc: "GripperGoalCmd: move the fingers to a gap, with at most an effort and a speed",
            },
        ],
    },
    ConstantGroup {
        name: "GRIPPER_REQ",
        doc: "gripper request kinds (MsgMeta.kind on the req channel)",
        constants: &[Constant {
            name: "GET_GEOM",
            value: 1,
            doc: "empty; reply GripperGeom",
        }],
    },
    ConstantGroup {
        name: "GRIPPER_STATE",
        doc: "GripperData.state values",
        constants: &[
            Constant {
                name: "OPEN",
                value: 1,
                doc: "open",
            },
            Constant {
                name: "CLOSED",
                value: 2,
                doc: "closed",
            },
            Constant {
                name: "MOVING",
                value: 3,
                doc: "moving",
            },
            Constant {
                name: "ERROR",
                value: 4,
                doc: "error",
            },
        ],
    },
];
