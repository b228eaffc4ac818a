//! Which motions are still running (so that a client whose motion another client's command
//! cuts short is told `Preempted`), and the deadman's stop of each device.

use std::time::{Duration, Instant};

use limber_interfaces::prelude::*;
use limber_p2os::{ArmJoint, PaddleState};
use limber_services::{Motion, Origin};

use super::*;

/// The driver itself, as the origin of a deadman stop (never refused as stale).
const DEADMAN: Origin = INTERNAL;

/// Bits of the five arm joints (the limb's), without the gripper (joint 5).
const LIMB_JOINTS: u8 = 0b1_1111;

impl RobotModel {
    /// The arm joints still moving toward a commanded target (bit j = joint j); every
    /// limb joint while a VECMOVE is being streamed.
    fn joints_running(&self) -> u64 {
        let now = Instant::now();
        let stall = Duration::from_millis(self.cfg.stall_timeout_ms);
        let mut bits = if self.vecmove.is_some() {
            LIMB_JOINTS as u64
        } else {
            0
        } | self.traj.exec.running();
        for j in 0..ARM_JOINTS {
            if self
                .arm
                .flags(j, now, stall)
                .contains(ActuatorFlags::MOVING)
            {
                bits |= 1 << j;
            }
        }
        bits
    }

    /// What an arm actarray command drives, and which of its joints still move.
    pub fn arm_motion(&self, cmd: &ActArrayCommand) -> Motion {
        let all = (1u8 << ARM_JOINTS) - 1;
        let first = |n: usize| ((1u16 << n.min(ARM_JOINTS)) - 1) as u8;
        let one = |j: u16| {
            if (j as usize) < ARM_JOINTS {
                1u8 << j
            } else {
                0
            }
        };
        let stop = match *cmd {
            ActArrayCommand::Speed { speed, .. } => speed == 0.0,
            ActArrayCommand::MultiSpeed(v) => v.as_slice().iter().all(|s| *s == 0.0),
            _ => false,
        };
        let mask = match *cmd {
            ActArrayCommand::Position { joint, .. } | ActArrayCommand::Speed { joint, .. } => {
                one(joint)
            }
            ActArrayCommand::MultiPosition(v) | ActArrayCommand::MultiSpeed(v) => first(v.len()),
            ActArrayCommand::Home(JointSel::All) => all,
            ActArrayCommand::Home(JointSel::One(j)) => one(j),
            ActArrayCommand::Current { .. } | ActArrayCommand::MultiCurrent(_) => 0,
            ActArrayCommand::Traj(h) => h.joints[..(h.joint_count as usize).min(MAX_ACTUATORS)]
                .iter()
                .fold(0, |m, &j| m | one(j.into())),
            ActArrayCommand::TrajChunk(_) | ActArrayCommand::TrajScale(_) => 0,
        };
        let m = Motion::of(mask as u64, self.joints_running());
        if stop { m.stopping() } else { m }
    }

    /// What a limb command drives (any: a new target or a stop drives every limb joint),
    /// and which limb joints still move (SETPOSE, SETPOSITION, VECMOVE, HOME).
    pub fn limb_motion(&self, cmd: &LimbCommand) -> Motion {
        let m = Motion::of(LIMB_JOINTS as u64, self.joints_running());
        if *cmd == LimbCommand::Stop {
            m.stopping()
        } else {
            m
        }
    }

    /// A command of the arm gripper drives it (bit 0); still moving or not.
    pub fn armgrip_motion(&self) -> Motion {
        let moving = self.joints_running() >> ArmJoint::GRIPPER.index() & 1;
        Motion::of(1, moving)
    }

    /// A command of the body gripper drives it (bit 0); moving while the paddles are
    /// between their end switches.
    pub fn gripper_motion(&self) -> Motion {
        let moving = self.sip.as_ref().is_some_and(|s| {
            s.gripper_reading(self.cfg.gripper_byte).paddles == PaddleState::Moving
        });
        Motion::of(1, moving as u64)
    }

    /// A command of the lift drives it (bit 0); still moving or not.
    pub fn lift_motion(&self) -> Motion {
        Motion::of(1, self.lift.moving.is_some() as u64)
    }

    /// The deadman's stop of the arm actarray and the limb: every arm joint stops.
    pub fn arm_stop(&mut self) -> Status {
        self.limb_command(&LimbCommand::Stop, &DEADMAN)
    }

    /// The deadman's stop of the arm gripper.
    pub fn armgrip_stop(&mut self) -> Status {
        self.armgrip_command(&GripperCommand::Stop, &DEADMAN)
    }

    /// The deadman's stop of the body gripper.
    pub fn gripper_stop(&mut self) -> Status {
        self.gripper_command(&GripperCommand::Stop, &DEADMAN)
    }

    /// The deadman's stop of the lift.
    pub fn lift_stop(&mut self) -> Status {
        self.lift_command(
            &ActArrayCommand::Speed {
                joint: 0,
                speed: 0.0,
            },
            &DEADMAN,
        )
    }
}
