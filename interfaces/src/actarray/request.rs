//! Typed actarray requests ([`ActArrayRequest`]) and replies ([`ActArrayReply`]).

use super::command::{finite_value, joint};
use super::req;
use super::wire::*;
use crate::common::Status;
use crate::error::{DecodeError, ValueError};
use crate::message::{self, Message, ReplyBody};

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

    fn is_read_only(&self) -> bool {
        matches!(self, ActArrayRequest::GetGeom)
    }

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
