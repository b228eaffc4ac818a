//! The arm actarray (`<robot>/actarray/0`): joint commands, requests, geometry, state.

use std::time::{Duration, Instant};

use limber_interfaces::prelude::*;
use limber_services::Origin;

use limber_p2os::{ArmJoint, Command, JointSelection};

use super::*;

/// The servo step (ms per tick) for `speed` rad/s, never faster than the joint's
/// configured speed (its calibration; the geometry's `config_speed`): `Status::Clamped`
/// when `speed` was beyond it.
pub(super) fn ms_per_step_within_limit(
    cal: &ArmCalibration,
    joint: ArmJoint,
    speed: f64,
) -> Result<(u8, Status), Status> {
    let ms = cal
        .speed_to_ms_per_step(joint, speed)
        .map_err(|_| Status::InvalidArgument)?;
    // Fewer ms per step is faster.
    let limit = cal.joint(joint).map_err(|_| Status::NotCalibrated)?.speed;
    Ok(if limit > 0 && ms < limit {
        tracing::debug!(
            joint = joint.index(),
            speed,
            limit_ms_per_step = limit,
            "speed clamped"
        );
        (limit, Status::Clamped)
    } else {
        (ms, Status::Ok)
    })
}

impl RobotModel {
    /// An arm actarray command.
    /// A SPEED faster than the joint's configured speed (the geometry's `config_speed`,
    /// from the calibration) runs at that speed and is answered CLAMPED.
    pub fn arm_command(&mut self, cmd: &ActArrayCommand, from: &Origin) -> Status {
        if let Some(r) = self.trajectory_command(cmd, from) {
            return r.unwrap_or_else(|e| e);
        }
        let motion = self.arm_motion(cmd);
        let r = match *cmd {
            ActArrayCommand::Position { joint, position } => {
                self.vecmove = None;
                self.move_joint(joint as usize, position, from)
                    .map(|()| Status::Ok)
            }
            ActArrayCommand::MultiPosition(v) => {
                self.vecmove = None;
                // Validate every joint before sending any.
                let mut ticks = [0u8; ARM_JOINTS];
                let r = v.as_slice().iter().enumerate().try_for_each(|(j, p)| {
                    ticks[j] = self.joint_tick(j, *p)?;
                    Ok(())
                });
                r.and_then(|()| self.require_power()).and_then(|()| {
                    for (j, &tick) in ticks.iter().enumerate().take(v.len()) {
                        let joint = ArmJoint::from_index(j).map_err(|_| Status::UnknownJoint)?;
                        self.send(&Command::ArmPos { joint, tick }, from)?;
                        self.arm.set_target(j, tick);
                        self.arm.goal[j] = Some(v.as_slice()[j]);
                    }
                    Ok(Status::Ok)
                })
            }
            ActArrayCommand::Speed { joint, speed } => {
                self.move_at_speed(joint as usize, speed, from)
            }
            ActArrayCommand::MultiSpeed(v) => {
                let r = v.as_slice().iter().enumerate().try_for_each(|(j, _)| {
                    self.joint_tick(j, 0.0).map(|_| ()).or_else(|e| {
                        if e == Status::BeyondLimits {
                            Ok(())
                        } else {
                            Err(e)
                        }
                    })
                });
                let r = r.and_then(|()| {
                    if v.as_slice().iter().any(|s| *s != 0.0) {
                        self.require_power()
                    } else {
                        Ok(())
                    }
                });
                r.and_then(|()| {
                    let mut status = Status::Ok;
                    for (j, s) in v.as_slice().iter().enumerate() {
                        if self.move_at_speed(j, *s, from)? == Status::Clamped {
                            status = Status::Clamped;
                        }
                    }
                    Ok(status)
                })
            }
            ActArrayCommand::Home(sel) => self.home(sel, from).map(|()| Status::Ok),
            ActArrayCommand::Current { .. } | ActArrayCommand::MultiCurrent(_) => {
                Err(Status::Unsupported)
            }
            ActArrayCommand::TrajChunk(_)
            | ActArrayCommand::Traj(_)
            | ActArrayCommand::TrajScale(_) => Err(Status::Unsupported),
        };
        if r.is_ok_and(|s| s.is_carried_out()) {
            self.end_trajectory(motion.drives, motion.stop);
        }
        r.unwrap_or_else(|e| e)
    }

    /// Moves joint `j` toward its limit in the direction of `speed`'s sign (0 stops it):
    /// `Ok(Status::Clamped)` when |speed| exceeded the joint's configured speed and the
    /// joint runs at that instead.
    pub(super) fn move_at_speed(
        &mut self,
        j: usize,
        speed: f64,
        from: &Origin,
    ) -> Result<Status, Status> {
        let cal = self.calibration()?;
        if j >= cal.num_joints().min(ARM_JOINTS) {
            return Err(Status::UnknownJoint);
        }
        let joint = ArmJoint::from_index(j).map_err(|_| Status::UnknownJoint)?;
        if !speed.is_finite() {
            return Err(Status::NotFinite);
        }
        if speed == 0.0 {
            self.send(&Command::ArmStop(JointSelection::One(joint)), from)?;
            self.arm.target[j] = None;
            return Ok(Status::Ok);
        }
        self.require_power()?;
        let (ms, status) = ms_per_step_within_limit(cal, joint, speed.abs())?;
        let [a, _, b, _] = cal
            .limits_radians(joint)
            .map_err(|_| Status::NotCalibrated)?;
        let end = if speed > 0.0 { a.max(b) } else { a.min(b) };
        let tick = self.joint_tick(j, end)?;
        self.send(
            &Command::ArmSpeed {
                joint,
                ms_per_step: ms,
            },
            from,
        )?;
        self.send(&Command::ArmPos { joint, tick }, from)?;
        self.arm.set_target(j, tick);
        Ok(status)
    }

    pub(super) fn home(&mut self, sel: JointSel, from: &Origin) -> Result<(), Status> {
        let cal = *self.calibration()?;
        self.require_power()?;
        self.vecmove = None;
        match sel {
            JointSel::All => {
                self.send(&Command::ArmHome(JointSelection::All), from)?;
                for j in 0..cal.num_joints().min(ARM_JOINTS) {
                    if let Ok(c) =
                        cal.joint(ArmJoint::from_index(j).map_err(|_| Status::UnknownJoint)?)
                    {
                        self.arm.set_target(j, c.home);
                    }
                }
            }
            JointSel::One(j) => {
                let j = j as usize;
                if j >= cal.num_joints().min(ARM_JOINTS) {
                    return Err(Status::UnknownJoint);
                }
                let joint = ArmJoint::from_index(j).map_err(|_| Status::UnknownJoint)?;
                self.send(&Command::ArmHome(JointSelection::One(joint)), from)?;
                if let Ok(c) = cal.joint(joint) {
                    self.arm.set_target(j, c.home);
                }
            }
        }
        Ok(())
    }

    /// An arm actarray request.
    pub fn arm_request(
        &mut self,
        req: &ActArrayRequest,
        from: &Origin,
    ) -> Result<ActArrayReply, Status> {
        match *req {
            ActArrayRequest::Power(on) => {
                self.calibration()?;
                self.send(&Command::ArmPower(on), from)?;
                Ok(ActArrayReply::Done)
            }
            ActArrayRequest::GetGeom => Ok(ActArrayReply::Geom(self.arm_geometry()?)),
            ActArrayRequest::Speed { joint, speed } => {
                let cal = self.calibration()?;
                let j = joint as usize;
                if j >= cal.num_joints().min(ARM_JOINTS) {
                    return Err(Status::UnknownJoint);
                }
                if !(speed.is_finite() && speed > 0.0) {
                    return Err(if speed.is_finite() {
                        Status::InvalidArgument
                    } else {
                        Status::NotFinite
                    });
                }
                // This joint's own calibration (Player used joint j+1's); never faster
                // than the joint's limit (a reply has no room for CLAMPED: the geometry's
                // config_speed says what the limit is).
                let aj = ArmJoint::from_index(j).map_err(|_| Status::UnknownJoint)?;
                let (ms, _) = ms_per_step_within_limit(cal, aj, speed)?;
                self.send(
                    &Command::ArmSpeed {
                        joint: aj,
                        ms_per_step: ms,
                    },
                    from,
                )?;
                Ok(ActArrayReply::Done)
            }
            ActArrayRequest::Brakes(_) | ActArrayRequest::Accel { .. } => Err(Status::Unsupported),
        }
    }

    /// The arm geometry from the calibration.
    pub fn arm_geometry(&self) -> Result<ActArrayGeom, Status> {
        let cal = self.cal.as_ref().ok_or(if self.has_arm || !self.link.up {
            Status::NotCalibrated
        } else {
            Status::Unsupported
        })?;
        let mut g = ActArrayGeom {
            actuators_count: cal.num_joints().min(ARM_JOINTS) as u32,
            base_pos: Vec3::from(self.cfg.arm_base),
            ..Default::default()
        };
        #[allow(clippy::needless_range_loop)]
        for j in 0..g.actuators_count as usize {
            let joint = ArmJoint::from_index(j).map_err(|_| Status::UnknownJoint)?;
            let [a, c, b, h] = cal
                .limits_radians(joint)
                .map_err(|_| Status::NotCalibrated)?;
            let jc = cal.joint(joint).map_err(|_| Status::NotCalibrated)?;
            let speed = cal.ms_per_step_to_speed(joint, jc.speed).unwrap_or(0.0);
            g.actuators[j] = ActuatorGeom {
                kind: ActuatorKind::Rotary as u32,
                has_brakes: 0,
                length: self.cfg.arm_geometry_lengths[j],
                orientation: Orientation3::default(),
                axis: Vec3::from(AXES[j]),
                min: a.min(b),
                centre: c,
                max: a.max(b),
                home: h,
                config_speed: speed,
            };
        }
        Ok(g)
    }

    /// Fills the arm actarray state.
    pub fn arm_state(&self, s: &mut ActArrayData, now: Instant) {
        s.trajectory = self.traj.exec.state_feedback();
        let n = self
            .cal
            .as_ref()
            .map(|c| c.num_joints().min(ARM_JOINTS))
            .unwrap_or(ARM_JOINTS);
        s.actuators_count = n as u32;
        // What was last asked at once (the state sent before a POWER request's reply shows
        // it); the ARMpacs confirm it, or correct it once the grace of a power-on is over.
        s.motor_state = self.arm.powered_or_pending() as u32;
        let q = self.joint_angles();
        let speeds = self.estimated_speeds();
        for j in 0..n {
            let a = &mut s.actuators[j];
            a.position = q.map(|q| q[j]).unwrap_or(0.0);
            a.acceleration = -1.0;
            a.current = -1.0;
            let flags = self
                .arm
                .flags(j, now, Duration::from_millis(self.cfg.stall_timeout_ms));
            // While it moves, its speed is the one estimated from the last two ARMpacs
            // (and says so); at rest, 0.
            (a.speed, a.state) = if flags.contains(ActuatorFlags::MOVING) {
                (speeds[j], (flags | ActuatorFlags::SPEED_ESTIMATED).bits())
            } else {
                (0.0, flags.bits())
            };
        }
        s.header.stamp_ns = self.arm.stamp_ns;
    }
}
