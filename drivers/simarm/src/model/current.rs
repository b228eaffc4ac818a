//! The current mode (CURRENT, MULTI_CURRENT) and its motor model
//! ([`MotorModel`](super::MotorModel)): a driven actuator moves at the speed where the
//! motor's torque, gravity on the load at the tool and viscous friction balance, toward
//! the limit it is pushed to; at a limit, on the object between the fingers, or held by
//! gravity it does not move and is STALLED. The state's `current` is the model's: the
//! commanded current in the current mode, the current that holds or moves the joint
//! otherwise (magnitudes, A).

use limber_interfaces::prelude::*;
use nalgebra::Vector3;

use limber_kinematics::Pose;
use limber_kinematics::chain::{JointKind, MAX_JOINTS};

use super::ArmModel;
use super::gripper::GripperCmd;

/// Below this speed a driven actuator does not move (rad/s or m/s).
const STILL: f64 = 1e-9;

impl ArmModel {
    /// Carries out CURRENT or MULTI_CURRENT (validated, powered and unbraked first): the
    /// actuators enter the current mode. A current beyond the motor's largest runs at the
    /// largest and is answered CLAMPED.
    pub(super) fn current_command(&mut self, cmd: &ActArrayCommand) -> Result<Status, Status> {
        let mut values = [0.0; MAX_JOINTS + 1];
        let (first, count) = match *cmd {
            ActArrayCommand::Current {
                joint: JointSel::All,
                current,
            } => {
                values.fill(current);
                (0, self.actuators())
            }
            ActArrayCommand::Current {
                joint: JointSel::One(j),
                current,
            } => {
                let j = j as usize;
                self.actuator(j).ok_or(Status::UnknownJoint)?;
                values[j] = current;
                (j, 1)
            }
            ActArrayCommand::MultiCurrent(v) => {
                let v = v.as_slice();
                if v.len() > self.actuators() {
                    return Err(Status::UnknownJoint);
                }
                values[..v.len()].copy_from_slice(v);
                (0, v.len())
            }
            _ => return Err(Status::InvalidArgument),
        };
        if values.iter().any(|v| !v.is_finite()) {
            return Err(Status::NotFinite);
        }
        self.powered()?;
        let max = self.options.motor.max_current;
        let mut status = Status::Ok;
        for (j, v) in values.iter().enumerate().skip(first).take(count) {
            if v.abs() > max {
                tracing::debug!(joint = j, current = v, max, "current clamped");
                status = Status::Clamped;
            }
            let c = v.clamp(-max, max);
            if j < self.n {
                self.vecmove.active = false;
            } else {
                self.gripper_cmd = GripperCmd::None;
            }
            if let Some(m) = self.actuator_mut(j) {
                m.stop();
                m.current = Some(c);
            }
        }
        self.drive_currents();
        Ok(status)
    }

    /// Aims every current-driven actuator from where it is now: toward the limit the net
    /// torque pushes it to, at the speed friction allows (at most its maximum).
    pub(super) fn drive_currents(&mut self) {
        if !self.joints[..self.n]
            .iter()
            .chain(Some(&self.gripper))
            .any(|m| m.current.is_some())
        {
            return;
        }
        let gravity = self.gravity_torques();
        let motor = self.options.motor;
        for (j, g) in gravity.iter().enumerate().take(self.n + 1) {
            let (lo, hi) = self.joint_limits(j).unwrap_or((0.0, 0.0));
            let max = if j < self.n {
                self.chain.joints()[j].max_speed
            } else {
                self.gripper_max_speed
            };
            let Some(m) = self.actuator_mut(j) else {
                continue;
            };
            let Some(i) = m.current else { continue };
            let net = motor.torque_constant * i + g;
            let speed = (net / motor.damping).abs().min(max);
            if speed < STILL {
                m.drive(m.pos, 0.0, f64::INFINITY);
            } else {
                let end = if net > 0.0 { hi } else { lo };
                m.drive(end, speed, f64::INFINITY);
            }
        }
    }

    /// The torque (N·m) or force (N) gravity on the load at the tool exerts on each
    /// actuator, in the sense of its axis (the gripper's: 0).
    fn gravity_torques(&self) -> [f64; MAX_JOINTS + 1] {
        let mut out = [0.0; MAX_JOINTS + 1];
        let motor = &self.options.motor;
        let weight = Vector3::new(0.0, 0.0, -motor.load_mass * motor.gravity);
        if weight.z == 0.0 {
            return out;
        }
        let mut frames = [Pose::identity(); MAX_JOINTS];
        let q = self.q();
        let Ok(tool) = self.chain.fk_frames(&q, &mut frames) else {
            return out;
        };
        for ((o, f), spec) in out.iter_mut().zip(&frames).zip(self.chain.joints()) {
            let axis = f.rotation * spec.axis.into_inner();
            *o = match spec.kind {
                JointKind::Rotary => axis.dot(&(tool.position - f.position).cross(&weight)),
                JointKind::Linear => axis.dot(&weight),
            };
        }
        out
    }

    /// The model's current of each actuator, A (magnitudes): the commanded one in the
    /// current mode; otherwise the one whose torque holds the joint against gravity and
    /// friction at its present velocity.
    pub(super) fn model_currents(&self) -> [f64; MAX_JOINTS + 1] {
        let gravity = self.gravity_torques();
        let motor = &self.options.motor;
        let mut out = [0.0; MAX_JOINTS + 1];
        for (j, o) in out.iter_mut().enumerate().take(self.n + 1) {
            let Some(m) = self.actuator(j) else { continue };
            *o = match m.current {
                Some(i) => i.abs(),
                None => ((motor.damping * m.velocity - gravity[j]) / motor.torque_constant).abs(),
            };
        }
        out
    }
}
