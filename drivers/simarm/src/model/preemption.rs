//! Which motions are still running (so that a client whose motion another client's command
//! cuts short is told `Preempted`), how each part of a motion is doing (its result when it
//! ends), and the deadman's stop.

use limber_interfaces::prelude::*;

use limber_services::{Motion, Progress};

use super::ArmModel;

/// The simulation is exact: a part reached its goal when within this (rad or m).
pub const TOLERANCE: f64 = 1e-9;

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
            ActArrayCommand::Traj(h) => {
                let drives = h.joints[..(h.joint_count as usize).min(MAX_ACTUATORS)]
                    .iter()
                    .fold(0u64, |m, &j| m | 1u64.checked_shl(j.into()).unwrap_or(0));
                return Motion::of(drives, self.running());
            }
            ActArrayCommand::TrajChunk(_) | ActArrayCommand::TrajScale(_) => {
                return Motion::NONE;
            }
        };
        let drives = (first..(first + count).min(64)).fold(0u64, |m, j| m | 1 << j);
        let stop = match *cmd {
            ActArrayCommand::Speed { speed, .. } => speed == 0.0,
            ActArrayCommand::MultiSpeed(v) => v.as_slice().iter().all(|s| *s == 0.0),
            _ => false,
        };
        let m = Motion::of(drives, self.running());
        if stop { m.stopping() } else { m }
    }

    /// What a limb command (a new target or a stop) drives: every joint; and which still
    /// move.
    pub fn limb_motion(&self, cmd: &LimbCommand) -> Motion {
        let joints = (1u64 << self.n) - 1;
        let m = Motion::of(joints, self.running() & joints);
        if *cmd == LimbCommand::Stop {
            m.stopping()
        } else {
            m
        }
    }

    /// A gripper command drives the gripper (bit 0); still moving or not.
    pub fn gripper_motion(&self, cmd: &GripperCommand) -> Motion {
        let m = Motion::of(1, self.gripper.moving as u64);
        if *cmd == GripperCommand::Stop {
            m.stopping()
        } else {
            m
        }
    }

    /// How actuator `j` (the gripper at `dof`) is doing in a motion: moving, or ended
    /// (reached within [`TOLERANCE`], stalled short of its goal, aborted by a power-off or
    /// the brakes), with its error against the goal.
    fn actuator_progress(&self, j: usize) -> Progress {
        if let Some(p) = self.trajectory_progress(j) {
            return p;
        }
        let Some(m) = self.actuator(j) else {
            return Progress::UNKNOWN;
        };
        let error = m.pos - m.goal;
        if m.moving || (j < self.n && self.vecmove.active) {
            return Progress::moving(m.pos, error, TOLERANCE);
        }
        let (result, cause) = if !self.powered {
            (MotionResult::Aborted, Status::PoweredOff)
        } else if self.brakes && j < self.n {
            (MotionResult::Aborted, Status::Braked)
        } else if !m.stalled && error.abs() <= TOLERANCE {
            (MotionResult::Reached, Status::Ok)
        } else {
            (MotionResult::Stalled, Status::Ok)
        };
        Progress::ended(result, cause, m.pos, error, TOLERANCE)
    }

    /// How actuator `part` of the actuator array is doing.
    pub fn arm_progress(&self, part: u32) -> Progress {
        self.actuator_progress(part as usize)
    }

    /// How limb joint `part` is doing (a VECMOVE runs until its last waypoint is reached).
    pub fn limb_progress(&self, part: u32) -> Progress {
        if (part as usize) < self.n {
            self.actuator_progress(part as usize)
        } else {
            Progress::UNKNOWN
        }
    }

    /// How the gripper is doing (stalled: closed on an object).
    pub fn gripper_progress(&self) -> Progress {
        let mut p = self.actuator_progress(self.n);
        // The beam's "object present" in the result: the cause of a reached or stalled
        // end with the object between the fingers.
        if let Some((r @ (MotionResult::Reached | MotionResult::Stalled), Status::Ok)) = p.end
            && self.object_between_fingers()
        {
            p.end = Some((r, Status::ObjectPresent));
        }
        p
    }

    /// The deadman's stop of the actarray: every joint and the gripper stop where they are.
    pub fn stop_arm(&mut self) -> Status {
        self.stop_all_joints();
        self.stop_trajectory();
        self.gripper.stop();
        Status::Ok
    }

    /// The deadman's stop of the limb: every joint stops where it is.
    pub fn stop_limb(&mut self) -> Status {
        self.stop_all_joints();
        self.stop_trajectory();
        Status::Ok
    }

    /// The deadman's stop of the gripper.
    pub fn stop_gripper(&mut self) -> Status {
        self.gripper.stop();
        Status::Ok
    }
}
