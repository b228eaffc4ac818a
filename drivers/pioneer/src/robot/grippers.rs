//! The arm gripper (`<robot>/gripper/1`, joint 6) and the body gripper (`<robot>/gripper/0`).

use std::time::{Duration, Instant};

use limber_interfaces::prelude::*;
use limber_services::Origin;

use limber_p2os::{ArmJoint, Command, GripperCommand as P2Gripper, JointSelection, PaddleState};

use super::*;

/// What a Pioneer gripper (the P2OS paddles, the arm's gripper servo as Player drives it)
/// does with a GOAL: it only opens fully or closes fully, at its one speed, with no effort
/// setting (P2OS's GRIPpress sets a grip time in 20 ms steps, not a force). A gap of 0 is
/// CLOSE, a gap of at least `open_gap` (the fingers' inner width) is OPEN ([`Status::Clamped`]
/// above it); a gap in between, an effort or a speed is refused with the reason. Any other
/// command is itself.
fn open_or_close(cmd: &GripperCommand, open_gap: f64) -> Result<(GripperCommand, Status), Status> {
    let GripperCommand::Goal { gap, effort, speed } = *cmd else {
        return Ok((*cmd, Status::Ok));
    };
    if effort != 0.0 {
        return Err(Status::EffortNotSettable);
    }
    if speed != 0.0 {
        return Err(Status::SpeedNotSettable);
    }
    if gap == 0.0 {
        Ok((GripperCommand::Close, Status::Ok))
    } else if gap == open_gap {
        Ok((GripperCommand::Open, Status::Ok))
    } else if gap > open_gap {
        Ok((GripperCommand::Open, Status::Clamped))
    } else {
        Err(Status::GapNotSettable)
    }
}

impl RobotModel {
    /// An arm-gripper command (a GOAL as `open_or_close` says).
    pub fn armgrip_command(&mut self, cmd: &GripperCommand, from: &Origin) -> Status {
        let (cmd, carried) = match open_or_close(cmd, self.cfg.arm_gripper.inner[0]) {
            Ok(c) => c,
            Err(e) => {
                tracing::info!(?cmd, status = %e, "arm gripper goal refused");
                return e;
            }
        };
        let cmd = &cmd;
        let r = (|| {
            let cal = *self.calibration()?;
            let joint = ArmJoint::GRIPPER;
            let c = *cal.joint(joint).map_err(|_| Status::Unsupported)?;
            match cmd {
                GripperCommand::Open | GripperCommand::Close => {
                    self.require_power()?;
                    let tick = if *cmd == GripperCommand::Open {
                        c.max.max(c.min)
                    } else {
                        c.max.min(c.min)
                    };
                    self.send(&Command::ArmPos { joint, tick }, from)?;
                    self.arm.set_target(joint.index(), tick);
                }
                GripperCommand::Stop => {
                    self.send(&Command::ArmStop(JointSelection::One(joint)), from)?;
                    self.arm.target[joint.index()] = None;
                }
                GripperCommand::Store | GripperCommand::Retrieve | GripperCommand::Goal { .. } => {
                    return Err(Status::Unsupported);
                }
            }
            self.armgrip_cmd = Some(*cmd);
            Ok(())
        })();
        r.err().unwrap_or(carried)
    }

    /// Fills the arm-gripper state.
    pub fn armgrip_state(&self, s: &mut GripperData, now: Instant) {
        let j = ArmJoint::GRIPPER.index();
        let stall = Duration::from_millis(self.cfg.stall_timeout_ms);
        let f = self.arm.flags(j, now, stall);
        s.state = if f.contains(ActuatorFlags::MOVING) {
            GripperState::Moving
        } else {
            match self.armgrip_cmd {
                Some(GripperCommand::Close) => GripperState::Closed, // stopped at the target or on an object
                Some(GripperCommand::Open) if f.contains(ActuatorFlags::STALLED) => {
                    GripperState::Error
                }
                Some(GripperCommand::Open) => GripperState::Open,
                _ => match self
                    .cal
                    .as_ref()
                    .and_then(|c| c.joint(ArmJoint::GRIPPER).ok())
                {
                    Some(c) if self.arm.ticks[j] > c.centre => GripperState::Open,
                    Some(_) => GripperState::Closed,
                    None => GripperState::Error,
                },
            }
        } as u32;
        s.beams = 0;
        s.stored = 0;
        s.header.stamp_ns = self.arm.stamp_ns;
    }

    // ----- body gripper and lift ---------------------------------------------------------

    /// A body-gripper command (a GOAL as `open_or_close` says).
    pub fn gripper_command(&mut self, cmd: &GripperCommand, from: &Origin) -> Status {
        if !self.body_gripper {
            return Status::Unsupported;
        }
        let (cmd, carried) = match open_or_close(cmd, self.cfg.gripper.inner[0]) {
            Ok(c) => c,
            Err(e) => {
                tracing::info!(?cmd, status = %e, "gripper goal refused");
                return e;
            }
        };
        let p2 = match cmd {
            GripperCommand::Open => P2Gripper::Open,
            GripperCommand::Close => P2Gripper::Close,
            GripperCommand::Stop => P2Gripper::Stop,
            GripperCommand::Store | GripperCommand::Retrieve | GripperCommand::Goal { .. } => {
                return Status::Unsupported;
            }
        };
        match self.send(&Command::Gripper(p2), from) {
            Ok(()) => {
                self.gripper_cmd = Some(cmd);
                carried
            }
            Err(e) => e,
        }
    }

    /// Fills the body-gripper state from the SIP's gripper state byte, read in the
    /// configured layout (`gripper_byte`: the manual's by default), and the breakbeams.
    pub fn gripper_state(&self, s: &mut GripperData) {
        let Some(sip) = self.sip.as_ref() else {
            s.state = GripperState::Error as u32;
            return;
        };
        let r = sip.gripper_reading(self.cfg.gripper_byte);
        s.state = match r.paddles {
            PaddleState::Open => GripperState::Open,
            PaddleState::Closed => GripperState::Closed,
            PaddleState::Moving => GripperState::Moving,
            PaddleState::Error => GripperState::Error,
            PaddleState::Between => {
                if self.gripper_cmd == Some(GripperCommand::Close) {
                    GripperState::Closed
                } else {
                    GripperState::Open
                }
            }
        } as u32;
        // Beam 0 = outer, beam 1 = inner.
        s.beams = r.outer_beam as u32 | (r.inner_beam as u32) << 1;
        s.stored = 0;
    }
}
