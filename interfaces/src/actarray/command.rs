//! Typed actarray commands ([`ActArrayCommand`]): validation on construction, encoding
//! into and decoding from the command envelope.

use super::wire::*;
use super::{ALL_JOINTS, cmd};
use crate::common::MAX_ACTUATORS;
use crate::error::{DecodeError, ValueError};
use crate::message::{self, Message};

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
pub(super) fn joint(j: i64) -> Result<u16, ValueError> {
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
    /// A piece of a joint trajectory upload (see [`JointTrajectory::commands`]).
    ///
    /// [`JointTrajectory::commands`]: super::JointTrajectory::commands
    TrajChunk(ActArrayTrajChunkCmd),
    /// Run the uploaded joint trajectory with this header.
    Traj(ActArrayTrajCmd),
    /// The speed scaling of trajectories: 0 pauses, 1 is nominal.
    TrajScale(f64),
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
    /// TRAJ_SCALE, validated (finite; the driver clamps it to 0..1 and says so).
    pub fn traj_scale(scale: f64) -> Result<Self, ValueError> {
        finite_value("scale", scale).map(ActArrayCommand::TrajScale)
    }
    /// MULTI_CURRENT, validated.
    pub fn multi_current(currents: &[f64]) -> Result<Self, ValueError> {
        JointValues::new("currents", currents).map(ActArrayCommand::MultiCurrent)
    }
}

pub(super) fn finite_value(field: &'static str, v: f64) -> Result<f64, ValueError> {
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
            ActArrayCommand::TrajChunk(_) => cmd::TRAJ_CHUNK,
            ActArrayCommand::Traj(_) => cmd::TRAJ,
            ActArrayCommand::TrajScale(_) => cmd::TRAJ_SCALE,
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
            ActArrayCommand::TrajChunk(c) => message::put(b, &c),
            ActArrayCommand::Traj(h) => message::put(b, &h),
            ActArrayCommand::TrajScale(scale) => message::put(b, &ActArrayTrajScaleCmd { scale }),
        };
        raw.meta.kind = self.kind();
        raw.meta.body_len = len;
    }

    fn is_piece(&self) -> bool {
        matches!(self, ActArrayCommand::TrajChunk(_))
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
            cmd::TRAJ_CHUNK => {
                let c: ActArrayTrajChunkCmd = message::get(ch, k, b, n)?;
                super::upload::check_chunk(&c)?;
                ActArrayCommand::TrajChunk(c)
            }
            cmd::TRAJ => {
                let h: ActArrayTrajCmd = message::get(ch, k, b, n)?;
                super::upload::check_header(&h)?;
                ActArrayCommand::Traj(h)
            }
            cmd::TRAJ_SCALE => {
                let c: ActArrayTrajScaleCmd = message::get(ch, k, b, n)?;
                ActArrayCommand::traj_scale(c.scale)?
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
