//! Which motions are still running (so that a client whose motion another client's command
//! cuts short is told `Preempted`), and the deadman's stop of each device.

use std::time::{Duration, Instant};

use limber_interfaces::prelude::*;
use limber_p2os::{ArmJoint, PaddleState};
use limber_services::Origin;

use super::*;

/// The driver itself, as the origin of a deadman stop (never refused as stale).
const DEADMAN: Origin = Origin {
    client_id: 0,
    seq: 0,
    sent_ns: 0,
};

/// Bits of the five arm joints (the limb's), without the gripper (joint 5).
const LIMB_JOINTS: u8 = 0b1_1111;

impl RobotModel {
    /// True when one of the arm joints in `mask` (bit j = joint j) is still moving toward
    /// a commanded target, or a VECMOVE (which drives the limb joints) is being streamed.
    fn joints_running(&self, mask: u8) -> bool {
        if self.vecmove.is_some() && mask & LIMB_JOINTS != 0 {
            return true;
        }
        let now = Instant::now();
        let stall = Duration::from_millis(self.cfg.stall_timeout_ms);
        (0..ARM_JOINTS)
            .filter(|j| mask & (1 << j) != 0)
            .any(|j| self.arm.flags(j, now, stall).contains(ActuatorFlags::MOVING))
    }

    /// Whether an arm actarray command cuts short a motion still running on its joints.
    pub fn arm_preempts(&self, cmd: &ActArrayCommand) -> bool {
        let all = (1u8 << ARM_JOINTS) - 1;
        let first = |n: usize| ((1u16 << n.min(ARM_JOINTS)) - 1) as u8;
        let one = |j: u16| if (j as usize) < ARM_JOINTS { 1u8 << j } else { 0 };
        let mask = match *cmd {
            ActArrayCommand::Position { joint, .. } | ActArrayCommand::Speed { joint, .. } => {
                one(joint)
            }
            ActArrayCommand::MultiPosition(v) | ActArrayCommand::MultiSpeed(v) => first(v.len()),
            ActArrayCommand::Home(JointSel::All) => all,
            ActArrayCommand::Home(JointSel::One(j)) => one(j),
            ActArrayCommand::Current { .. } | ActArrayCommand::MultiCurrent(_) => 0,
        };
        self.joints_running(mask)
    }

    /// Whether a limb command (any: a new target or a stop) cuts short a running limb
    /// motion (SETPOSE, SETPOSITION, VECMOVE, HOME, or joints of the arm moving).
    pub fn limb_preempts(&self, _cmd: &LimbCommand) -> bool {
        self.joints_running(LIMB_JOINTS)
    }

    /// Whether a command of the arm gripper cuts short its running motion.
    pub fn armgrip_preempts(&self) -> bool {
        self.joints_running(1 << ArmJoint::GRIPPER.index())
    }

    /// Whether a command of the body gripper cuts short its running motion (the paddles
    /// are between their end switches, moving).
    pub fn gripper_preempts(&self) -> bool {
        self.sip
            .as_ref()
            .is_some_and(|s| s.gripper_switches().paddles() == PaddleState::Moving)
    }

    /// Whether a command of the lift cuts short its running motion.
    pub fn lift_preempts(&self) -> bool {
        self.lift.moving.is_some()
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
