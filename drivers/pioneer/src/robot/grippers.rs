//! The arm gripper (`<robot>/gripper/1`, joint 6) and the body gripper (`<robot>/gripper/0`).

use std::time::{Duration, Instant};

use limber_interfaces::prelude::*;
use limber_services::Origin;

use limber_p2os::{ArmJoint, Command, GripperCommand as P2Gripper, JointSelection, PaddleState};

use super::*;

impl RobotModel {
    /// An arm-gripper command.
    pub fn armgrip_command(&mut self, cmd: &GripperCommand, from: &Origin) -> Status {
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
                GripperCommand::Store | GripperCommand::Retrieve => {
                    return Err(Status::Unsupported);
                }
            }
            self.armgrip_cmd = Some(*cmd);
            Ok(())
        })();
        r.err().unwrap_or(Status::Ok)
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

    /// A body-gripper command.
    pub fn gripper_command(&mut self, cmd: &GripperCommand, from: &Origin) -> Status {
        if !self.body_gripper {
            return Status::Unsupported;
        }
        let p2 = match cmd {
            GripperCommand::Open => P2Gripper::Open,
            GripperCommand::Close => P2Gripper::Close,
            GripperCommand::Stop => P2Gripper::Stop,
            GripperCommand::Store | GripperCommand::Retrieve => return Status::Unsupported,
        };
        match self.send(&Command::Gripper(p2), from) {
            Ok(()) => {
                self.gripper_cmd = Some(*cmd);
                Status::Ok
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
