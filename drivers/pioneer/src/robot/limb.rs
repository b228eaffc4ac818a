//! The limb (`<robot>/limb/0`): end-effector commands through the closed-form IK, VECMOVE streaming, state from the FK.

use std::time::{Duration, Instant};

use limber_interfaces::limb_outcome::adjustment_reported;
use limber_interfaces::prelude::*;
use limber_services::Origin;
use nalgebra::Vector3;

use limber_kinematics::pioneer::{
    ApproachPreference, PIONEER_DOF, PoseSolution, Theta, VecMoveError, VecMoveOptions,
};
use limber_p2os::{ArmJoint, Command, JointSelection};

use super::*;

/// The cause of a VECMOVE that cannot be planned.
fn vecmove_status(e: &VecMoveError) -> Status {
    match e {
        VecMoveError::NonFinite => Status::NotFinite,
        VecMoveError::ZeroDirection | VecMoveError::InvalidOptions => Status::InvalidArgument,
        VecMoveError::Ik(e) | VecMoveError::Unreachable { cause: e, .. } => ik_status(e),
        // The line crosses a singularity or a branch change: it cannot be followed.
        VecMoveError::DeviationExceeded { .. } => Status::OutOfReach,
    }
}

impl RobotModel {
    pub(super) fn send_theta(&mut self, theta: &Theta, from: &Origin) -> Result<(), Status> {
        let q = self.map.driver_from_theta(theta);
        let mut ticks = [0u8; PIONEER_DOF];
        for j in 0..PIONEER_DOF {
            // BEYOND_LIMITS: the solution needs a joint past its limits.
            ticks[j] = self.joint_tick(j, q[j])?;
        }
        self.send_ticks(&ticks, from)
    }

    pub(super) fn send_ticks(
        &mut self,
        ticks: &[u8; PIONEER_DOF],
        from: &Origin,
    ) -> Result<(), Status> {
        for (j, &tick) in ticks.iter().enumerate() {
            let joint = ArmJoint::from_index(j).map_err(|_| Status::UnknownJoint)?;
            if self.arm.target[j] != Some(tick) || self.arm.ticks[j] != tick {
                self.send(&Command::ArmPos { joint, tick }, from)?;
            }
            self.arm.set_target(j, tick);
        }
        Ok(())
    }

    /// A limb command. A SETPOSE whose orientation had to be turned to one the joints
    /// can hold is carried out as `Status::Adjusted`, the amount in the limb state.
    pub fn limb_command(&mut self, cmd: &LimbCommand, from: &Origin) -> Status {
        self.limb.begin();
        let r = self.limb_command_inner(cmd, from);
        let s = self.limb.settle(r);
        if s.is_carried_out() {
            self.end_trajectory(0b1_1111, *cmd == LimbCommand::Stop);
        }
        s
    }

    pub(super) fn limb_command_inner(
        &mut self,
        cmd: &LimbCommand,
        from: &Origin,
    ) -> Result<(), Status> {
        self.calibration()?;
        let current = self.theta().ok_or(Status::NotCalibrated)?;
        if !matches!(cmd, LimbCommand::Stop) {
            self.require_power()?;
        }
        match *cmd {
            // LINE and PTP run on the joint trajectory executor; the Pioneer's streams it
            // (i28-traj), not wired to the limb here yet: unsupported, nothing sent.
            LimbCommand::Line(_) | LimbCommand::Ptp(_) => Err(Status::Unsupported),
            LimbCommand::Home => {
                self.vecmove = None;
                self.home(JointSel::All, from)
            }
            LimbCommand::Stop => {
                self.vecmove = None;
                // Every joint, the wrist pitch included (Player left joint 5 moving).
                self.send(&Command::ArmStop(JointSelection::All), from)?;
                self.arm.target = [None; ARM_JOINTS];
                Ok(())
            }
            LimbCommand::SetPose {
                position,
                approach,
                orientation,
            } => {
                self.vecmove = None;
                let s = self.solve_setpose(position, approach, orientation, &current)?;
                self.send_theta(s.theta(), from)?;
                self.limb.adjusted_by(s.adjustment);
                Ok(())
            }
            LimbCommand::SetPosition { position } => {
                self.vecmove = None;
                let p = Vector3::from(position.to_array()) - self.geom.base_offset;
                let c = self
                    .geom
                    .solve_position(&p, ApproachPreference::Current, &current, &self.ik)
                    .map_err(|e| ik_status(&e))?;
                self.send_theta(&c.theta, from)
            }
            LimbCommand::VecMove { direction, length } => {
                if length < 0.0 {
                    return Err(Status::InvalidArgument);
                }
                let opts = VecMoveOptions {
                    max_deviation: self.cfg.vecmove_deviation,
                    ik: self.ik,
                    ..VecMoveOptions::default()
                };
                let plan = self
                    .geom
                    .vecmove(
                        &current,
                        &Vector3::from(direction.to_array()),
                        length,
                        &opts,
                    )
                    .map_err(|e| vecmove_status(&e))?;
                // Validate the whole line before moving: every waypoint reachable and
                // inside the limits.
                let mut p = Box::new(VecMovePlan {
                    waypoints: [[0; PIONEER_DOF]; MAX_WAYPOINTS],
                    len: 0,
                    next: 0,
                });
                for wp in plan {
                    let theta = wp.map_err(|e| vecmove_status(&e))?.theta;
                    if p.len == MAX_WAYPOINTS {
                        return Err(Status::InvalidArgument);
                    }
                    let q = self.map.driver_from_theta(&theta);
                    #[allow(clippy::needless_range_loop)]
                    for j in 0..PIONEER_DOF {
                        p.waypoints[p.len][j] = self.joint_tick(j, q[j])?;
                    }
                    p.len += 1;
                }
                self.vecmove = Some(p);
                self.stream_vecmove(from)
            }
        }
    }

    /// SETPOSE's solution (see `limber_kinematics::pioneer::PoseSolution`), its joints
    /// checked against the limits in ticks.
    fn solve_setpose(
        &self,
        position: Vec3,
        approach: Vec3,
        orientation: Vec3,
        current: &Theta,
    ) -> Result<PoseSolution, Status> {
        let s = self
            .geom
            .solve_setpose_nearest(
                &Vector3::from(position.to_array()),
                &Vector3::from(approach.to_array()),
                &Vector3::from(orientation.to_array()),
                current,
                &self.setpose_options(),
            )
            .map_err(|e| ik_status(&e))?;
        let q = self.map.driver_from_theta(s.theta());
        for (j, rad) in q.iter().enumerate() {
            // BEYOND_LIMITS: the solution needs a joint past its limits.
            self.joint_tick(j, *rad)?;
        }
        Ok(s)
    }

    /// REQ REACH: where a SETPOSE to this pose would end; nothing moves.
    fn reach(
        &self,
        position: Vec3,
        approach: Vec3,
        orientation: Vec3,
    ) -> Result<LimbReach, Status> {
        self.calibration()?;
        let current = self.theta().ok_or(Status::NotCalibrated)?;
        let s = self.solve_setpose(position, approach, orientation, &current)?;
        let (p, a, o) = (
            s.achieved.position,
            s.achieved.approach(),
            s.achieved.orientation(),
        );
        Ok(LimbReach {
            position: Vec3::new(p.x, p.y, p.z),
            approach: Vec3::new(a.x, a.y, a.z),
            orientation: Vec3::new(o.x, o.y, o.z),
            orientation_adjustment: s.adjustment,
            position_error: s.position_error,
            approach_error: s.approach_error,
            adjusted: u32::from(adjustment_reported(s.adjustment)),
            _pad: 0,
        })
    }

    /// Sends the next VECMOVE waypoint once the arm has reached the current one.
    pub fn stream_vecmove(&mut self, from: &Origin) -> Result<(), Status> {
        let Some(plan) = self.vecmove.as_mut() else {
            return Ok(());
        };
        let reached =
            (0..PIONEER_DOF).all(|j| self.arm.target[j].is_none_or(|t| t == self.arm.ticks[j]));
        if plan.next > 0 && !reached {
            return Ok(());
        }
        // Skip waypoints that quantise to the ticks already commanded.
        while plan.next < plan.len
            && (0..PIONEER_DOF).all(|j| Some(plan.waypoints[plan.next][j]) == self.arm.target[j])
        {
            plan.next += 1;
        }
        if plan.next >= plan.len {
            self.vecmove = None;
            return Ok(());
        }
        let wp = plan.waypoints[plan.next];
        plan.next += 1;
        self.send_ticks(&wp, from)
    }

    /// A limb request.
    pub fn limb_request(&mut self, req: &LimbRequest, from: &Origin) -> Result<LimbReply, Status> {
        match *req {
            LimbRequest::Power(on) => {
                self.calibration()?;
                self.send(&Command::ArmPower(on), from)?;
                Ok(LimbReply::Done)
            }
            LimbRequest::Geom => Ok(LimbReply::Geom(LimbGeom {
                base_pos: Vec3::from(self.cfg.arm_base),
            })),
            LimbRequest::Speed(v) => {
                if v.is_nan() || v <= 0.0 {
                    return Err(Status::InvalidArgument);
                }
                let cal = *self.calibration()?;
                // The end effector moves at about v when each joint turns at v / r, with r
                // the arm's reach from the shoulder (≈ 0.4 m).
                let reach = self.geom.l2 + self.geom.l4 + self.geom.l5;
                for j in 0..PIONEER_DOF {
                    let joint = ArmJoint::from_index(j).map_err(|_| Status::UnknownJoint)?;
                    let (ms, _) = super::arm::ms_per_step_within_limit(&cal, joint, v / reach)?;
                    self.send(
                        &Command::ArmSpeed {
                            joint,
                            ms_per_step: ms,
                        },
                        from,
                    )?;
                }
                self.limb_speed = v;
                Ok(LimbReply::Done)
            }
            LimbRequest::Brakes(_) => Err(Status::Unsupported),
            LimbRequest::Reach {
                position,
                approach,
                orientation,
            } => self
                .reach(position, approach, orientation)
                .map(LimbReply::Reach),
        }
    }

    /// Fills the limb state: FK of the current joints, and the state.
    pub fn limb_state(&self, s: &mut LimbData, now: Instant) {
        if let Some(theta) = self.theta()
            && let Ok(pose) = self.geom.fk_robot(&theta)
        {
            let (p, a, o) = (pose.position, pose.approach(), pose.orientation());
            s.position = Vec3::new(p.x, p.y, p.z);
            s.approach = Vec3::new(a.x, a.y, a.z);
            s.orientation = Vec3::new(o.x, o.y, o.z);
        }
        let stall = Duration::from_millis(self.cfg.stall_timeout_ms);
        let flags: [ActuatorFlags; PIONEER_DOF] =
            core::array::from_fn(|j| self.arm.flags(j, now, stall));
        s.state = if self.limb.out_of_reach {
            LimbState::OutOfReach
        } else if flags.iter().any(|f| f.contains(ActuatorFlags::STALLED)) {
            LimbState::Collision
        } else if self.vecmove.is_some() || flags.iter().any(|f| f.contains(ActuatorFlags::MOVING))
        {
            LimbState::Moving
        } else {
            LimbState::Idle
        } as u32;
        s.orientation_adjustment = self.limb.adjustment;
        s.header.stamp_ns = self.arm.stamp_ns;
    }
}
