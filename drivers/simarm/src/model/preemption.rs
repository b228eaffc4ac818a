//! Which motions are still running (so that a client whose motion another client's command
//! cuts short is told `Preempted`), and the deadman's stop.

use limber_interfaces::prelude::*;

use limber_services::Motion;

use super::ArmModel;

impl ArmModel {
    /// The actuators still moving (bit j: joint j, bit `dof`: the gripper); every joint
    /// while a VECMOVE is in progress.
    fn running(&self) -> u64 {
        let mut bits = 0u64;
        for j in 0..self.n {
            if self.vecmove.active || self.joints[j].moving {
                bits |= 1 << j;
            }
        }
        if self.gripper.moving {
            bits |= 1 << self.n;
        }
        bits
    }

    /// What an actarray command drives, and which of its actuators still move.
    pub fn arm_motion(&self, cmd: &ActArrayCommand) -> Motion {
        let (first, count) = match *cmd {
            ActArrayCommand::Position { joint, .. }
            | ActArrayCommand::Speed { joint, .. }
            | ActArrayCommand::Current {
                joint: JointSel::One(joint),
                ..
            }
            | ActArrayCommand::Home(JointSel::One(joint)) => (joint as usize, 1),
            ActArrayCommand::Current {
                joint: JointSel::All,
                ..
            } => (0, self.n + 1),
            ActArrayCommand::MultiPosition(v)
            | ActArrayCommand::MultiSpeed(v)
            | ActArrayCommand::MultiCurrent(v) => (0, v.len()),
            ActArrayCommand::Home(JointSel::All) => (0, self.n + 1),
        };
        let drives = (first..(first + count).min(64)).fold(0u64, |m, j| m | 1 << j);
        Motion::of(drives, self.running())
    }

    /// What a limb command (a new target or a stop) drives: every joint; and which still
    /// move.
    pub fn limb_motion(&self) -> Motion {
        let joints = (1u64 << self.n) - 1;
        Motion::of(joints, self.running() & joints)
    }

    /// A gripper command drives the gripper (bit 0); still moving or not.
    pub fn gripper_motion(&self) -> Motion {
        Motion::of(1, self.gripper.moving as u64)
    }

    /// The deadman's stop of the actarray: every joint and the gripper stop where they are.
    pub fn stop_arm(&mut self) -> Status {
        self.stop_all_joints();
        self.gripper.stop();
        Status::Ok
    }

    /// The deadman's stop of the limb: every joint stops where it is.
    pub fn stop_limb(&mut self) -> Status {
        self.stop_all_joints();
        Status::Ok
    }

    /// The deadman's stop of the gripper.
    pub fn stop_gripper(&mut self) -> Status {
        self.gripper.stop();
        Status::Ok
    }
}
