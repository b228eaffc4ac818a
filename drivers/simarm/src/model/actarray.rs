//! The actuator-array interface of the model: one actuator per chain joint plus the
//! gripper opening, moved to a position or at a speed, with its geometry and state.

use limber_interfaces::prelude::*;

use limber_kinematics::chain::JointKind;

use super::ArmModel;
use super::gripper::GripperCmd;

impl ArmModel {
    /// Carries out or refuses an actuator-array command. A SPEED above the actuator's
    /// maximum speed runs at the maximum and is answered CLAMPED.
    /// Trajectory commands need their sender and the time: [`ArmModel::trajectory_command`]
    /// (here they are `UNSUPPORTED`). A motion carried out ends a running trajectory: a
    /// stop decelerates it, anything else preempts it.
    pub fn arm_command(&mut self, cmd: &ActArrayCommand) -> Status {
        let motion = self.arm_motion(cmd);
        let s = self.arm_command_inner(cmd).unwrap_or_else(|e| e);
        if s.is_carried_out() {
            if motion.stop {
                self.stop_trajectory();
            } else {
                self.preempt_trajectory(motion.drives);
            }
        }
        s
    }

    fn arm_command_inner(&mut self, cmd: &ActArrayCommand) -> Result<Status, Status> {
        self.arm_unbraked(cmd)?;
        match *cmd {
            ActArrayCommand::Position { joint, position } => {
                let j = joint as usize;
                self.check(j, position)?;
                self.powered()?;
                if j < self.n {
                    self.vecmove.active = false;
                }
                self.move_actuator(j, position, None);
                Ok(Status::Ok)
            }
            ActArrayCommand::MultiPosition(v) => {
                let v = v.as_slice();
                if v.len() > self.actuators() {
                    return Err(Status::UnknownJoint);
                }
                for (j, p) in v.iter().enumerate() {
                    self.check(j, *p)?;
                }
                self.powered()?;
                self.vecmove.active = false;
                for (j, p) in v.iter().enumerate() {
                    self.move_actuator(j, *p, None);
                }
                Ok(Status::Ok)
            }
            ActArrayCommand::Speed { joint, speed } => {
                let j = joint as usize;
                self.check_speed_target(j, speed)?;
                if speed != 0.0 {
                    self.powered()?;
                }
                if j < self.n {
                    self.vecmove.active = false;
                }
                Ok(self.move_at_speed(j, speed))
            }
            ActArrayCommand::MultiSpeed(v) => {
                let v = v.as_slice();
                if v.len() > self.actuators() {
                    return Err(Status::UnknownJoint);
                }
                for (j, s) in v.iter().enumerate() {
                    self.check_speed_target(j, *s)?;
                }
                if v.iter().any(|s| *s != 0.0) {
                    self.powered()?;
                }
                self.vecmove.active = false;
                let mut status = Status::Ok;
                for (j, s) in v.iter().enumerate() {
                    if self.move_at_speed(j, *s) == Status::Clamped {
                        status = Status::Clamped;
                    }
                }
                Ok(status)
            }
            ActArrayCommand::Home(JointSel::All) => {
                self.powered()?;
                self.vecmove.active = false;
                for j in 0..self.n {
                    let h = self.chain.joints()[j].home;
                    self.move_actuator(j, h, None);
                }
                let open = self.gripper_stroke;
                self.move_actuator(self.n, open, None);
                self.gripper_cmd = GripperCmd::Open;
                Ok(Status::Ok)
            }
            ActArrayCommand::Home(JointSel::One(j)) => {
                let j = j as usize;
                if j > self.n {
                    return Err(Status::UnknownJoint);
                }
                self.powered()?;
                if j < self.n {
                    self.vecmove.active = false;
                    let h = self.chain.joints()[j].home;
                    self.move_actuator(j, h, None);
                } else {
                    let open = self.gripper_stroke;
                    self.move_actuator(j, open, None);
                    self.gripper_cmd = GripperCmd::Open;
                }
                Ok(Status::Ok)
            }
            ActArrayCommand::Current { .. } | ActArrayCommand::MultiCurrent(_) => {
                self.current_command(cmd)
            }
            ActArrayCommand::TrajChunk(_)
            | ActArrayCommand::Traj(_)
            | ActArrayCommand::TrajScale(_) => Err(Status::Unsupported),
        }
    }

    fn check_speed_target(&self, j: usize, speed: f64) -> Result<(), Status> {
        self.joint_limits(j).ok_or(Status::UnknownJoint)?;
        if !speed.is_finite() {
            return Err(Status::NotFinite);
        }
        Ok(())
    }

    /// Moves actuator `j` toward its limit in the direction of `speed`'s sign at
    /// |speed|, capped at the actuator's maximum speed (then `Status::Clamped`); 0 stops
    /// it.
    fn move_at_speed(&mut self, j: usize, speed: f64) -> Status {
        if speed == 0.0 {
            if j < self.n {
                self.joints[j].stop();
            } else {
                self.gripper.stop();
            }
            return Status::Ok;
        }
        let Some((lo, hi)) = self.joint_limits(j) else {
            return Status::UnknownJoint;
        };
        let end = if speed > 0.0 { hi } else { lo };
        let max = if j < self.n {
            self.chain.joints()[j].max_speed
        } else {
            self.gripper_max_speed
        };
        self.move_actuator(j, end, Some(speed.abs().min(max)));
        if speed.abs() > max {
            tracing::debug!(joint = j, speed, max, "speed clamped");
            Status::Clamped
        } else {
            Status::Ok
        }
    }

    /// Answers an actuator-array request.
    pub fn arm_request(&mut self, req: &ActArrayRequest) -> Result<ActArrayReply, Status> {
        match *req {
            ActArrayRequest::Power(on) => {
                self.set_power(on);
                Ok(ActArrayReply::Done)
            }
            ActArrayRequest::GetGeom => Ok(ActArrayReply::Geom(self.arm_geometry())),
            ActArrayRequest::Speed { joint, speed } => {
                let j = joint as usize;
                if j > self.n {
                    return Err(Status::UnknownJoint);
                }
                if !speed.is_finite() {
                    return Err(Status::NotFinite);
                }
                if speed <= 0.0 {
                    return Err(Status::InvalidArgument);
                }
                if j < self.n {
                    self.config_speed[j] = speed.min(self.chain.joints()[j].max_speed);
                } else {
                    self.gripper_config_speed = speed.min(self.gripper_max_speed);
                }
                Ok(ActArrayReply::Done)
            }
            ActArrayRequest::Brakes(on) => {
                self.set_brakes(on)?;
                Ok(ActArrayReply::Done)
            }
            ActArrayRequest::Accel { joint, accel } => {
                let j = joint as usize;
                if j > self.n {
                    return Err(Status::UnknownJoint);
                }
                if !accel.is_finite() {
                    return Err(Status::NotFinite);
                }
                if accel <= 0.0 {
                    return Err(Status::InvalidArgument);
                }
                self.config_accel[j] = accel;
                Ok(ActArrayReply::Done)
            }
        }
    }

    /// Switches the power; off stops every actuator.
    pub(super) fn set_power(&mut self, on: bool) {
        self.powered = on;
        if !on {
            self.stop_all_joints();
            self.gripper.stop();
            self.abort_trajectory(Status::PoweredOff);
        }
    }

    /// The actuator-array geometry: per joint its kind, axis, rest orientation (roll,
    /// pitch, yaw), link length (the joint's origin offset), limits, centre, home and
    /// configured speed; the gripper last (linear, 0 to the stroke, home open); the
    /// chain base.
    pub fn arm_geometry(&self) -> ActArrayGeom {
        let mut g = ActArrayGeom {
            actuators_count: self.actuators() as u32,
            ..Default::default()
        };
        for (i, j) in self.chain.joints().iter().enumerate() {
            let (roll, pitch, yaw) = j.rest.euler_angles();
            let axis = j.axis.into_inner();
            g.actuators[i] = ActuatorGeom {
                kind: match j.kind {
                    JointKind::Rotary => ActuatorKind::Rotary,
                    JointKind::Linear => ActuatorKind::Linear,
                } as u32,
                has_brakes: u32::from(self.options.brakes),
                length: j.origin.norm(),
                orientation: Orientation3 { roll, pitch, yaw },
                axis: Vec3::new(axis.x, axis.y, axis.z),
                min: j.min,
                centre: 0.5 * (j.min + j.max),
                max: j.max,
                home: j.home,
                config_speed: self.config_speed[i],
            };
        }
        g.actuators[self.n] = ActuatorGeom {
            kind: ActuatorKind::Linear as u32,
            has_brakes: 0,
            length: 0.0,
            orientation: Orientation3::default(),
            axis: Vec3::new(0.0, 1.0, 0.0),
            min: 0.0,
            centre: 0.5 * self.gripper_stroke,
            max: self.gripper_stroke,
            home: self.gripper_stroke,
            config_speed: self.gripper_config_speed,
        };
        let base = self.chain.base();
        let (roll, pitch, yaw) = base.rotation.euler_angles();
        g.base_pos = Vec3::new(base.position.x, base.position.y, base.position.z);
        g.base_orientation = Orientation3 { roll, pitch, yaw };
        g
    }

    /// Fills the actuator-array state: positions, velocities, the acceleration (of the
    /// last step, for an actuator with an ACCEL limit; -1 otherwise), the motor model's
    /// current, and BRAKED (chain joints while the brakes are on) / STALLED (blocked, or
    /// pushed by a current and not moving) / MOVING / IDLE.
    pub fn arm_state(&self, s: &mut ActArrayData) {
        s.trajectory = self.trajectory_state();
        s.actuators_count = self.actuators() as u32;
        s.motor_state = self.powered as u32;
        let currents = self.model_currents();
        let all = self.joints[..self.n].iter().chain(Some(&self.gripper));
        for (j, (a, m)) in s.actuators.iter_mut().zip(all).enumerate() {
            let braked = self.brakes && j < self.n;
            a.position = m.pos;
            a.speed = m.velocity;
            a.acceleration = if self.config_accel[j].is_finite() {
                m.accel_now
            } else {
                -1.0
            };
            a.current = if braked { 0.0 } else { currents[j] };
            let pushed = m.current.is_some_and(|i| i != 0.0) && !m.moving;
            a.state = if braked {
                ActuatorFlags::BRAKED
            } else if m.stalled || pushed {
                ActuatorFlags::STALLED
            } else if m.moving {
                ActuatorFlags::MOVING
            } else {
                ActuatorFlags::IDLE
            }
            .bits();
        }
    }
}
