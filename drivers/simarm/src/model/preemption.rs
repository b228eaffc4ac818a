//! Which motions are still running (so that a client whose motion another client's command
//! cuts short is told `Preempted`), and the deadman's stop.

use limber_interfaces::prelude::*;

use super::ArmModel;

impl ArmModel {
    /// True when actuator `j` (a joint, or `dof` = the gripper) is moving; a VECMOVE in
    /// progress counts for every joint.
    fn actuator_running(&self, j: usize) -> bool {
        if j < self.n {
            self.vecmove.active || self.joints[j].moving
        } else if j == self.n {
            self.gripper.moving
        } else {
            false
        }
    }

    /// Whether an actarray command cuts short a motion still running on its actuators.
    pub fn arm_preempts(&self, cmd: &ActArrayCommand) -> bool {
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
        (first..first + count).any(|j| self.actuator_running(j))
    }

    /// Whether a limb command (a new target or a stop) cuts short a running limb motion.
    pub fn limb_preempts(&self) -> bool {
        self.limb_moving()
    }

    /// Whether a gripper command cuts short the gripper's running motion.
    pub fn gripper_preempts(&self) -> bool {
        self.gripper.moving
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
