//! The limb interface of the model: SETPOSE and SETPOSITION through the chain's numeric
//! inverse kinematics, and VECMOVE planned completely (every waypoint solved) before it
//! is streamed one waypoint at a time.

use limber_interfaces::limb_outcome::adjustment_reported;
use limber_interfaces::prelude::*;
use nalgebra::Vector3;

use limber_kinematics::chain::{ChainIkError, IkTarget, JointVec, NearestSolution};
use limber_kinematics::{Pose, unit_direction};

use super::{ArmModel, MAX_WAYPOINTS};

/// Largest joint jump (rad or m) accepted between two consecutive VECMOVE waypoints; a
/// bigger jump means the inverse switched branches, which would leave the line.
const MAX_WAYPOINT_JUMP: f64 = 0.5;

/// Tolerance (rad) on the perpendicularity of SETPOSE's approach and orientation.
pub(super) const PERPENDICULAR_TOLERANCE: f64 = 0.05;

/// The VECMOVE being streamed.
#[derive(Debug)]
pub(super) struct VecMovePlan {
    pub(super) waypoints: Vec<JointVec>,
    /// Where a new line is solved, swapped with `waypoints` once every waypoint is
    /// known, so a refused line leaves the running one untouched.
    pub(super) scratch: Vec<JointVec>,
    pub(super) next: usize,
    /// Tool distance between waypoints, m.
    pub(super) step: f64,
    pub(super) active: bool,
}

impl ArmModel {
    /// Carries out or refuses a limb command. OUT_OF_REACH sets the limb state to
    /// out-of-reach until the next valid limb command.
    pub fn limb_command(&mut self, cmd: &LimbCommand) -> Status {
        self.limb.begin();
        // A new command ends the COLLISION state, and may move away from the contact.
        self.collision = None;
        self.leaving_contact = self.contact().is_some();
        self.clear_refused_path();
        let r = self.limb_command_inner(cmd);
        let s = self.limb.settle(r);
        if s.is_carried_out() {
            match cmd {
                LimbCommand::Stop => self.stop_trajectory(),
                // A path's trajectory replaces the running one in the executor.
                LimbCommand::Line(_) | LimbCommand::Ptp(_) => {}
                _ => {
                    self.end_path();
                    self.preempt_trajectory((1u64 << self.n) - 1);
                }
            }
        }
        s
    }

    fn ik_to(&self, target: &IkTarget, seed: &[f64]) -> Result<JointVec, Status> {
        let sol = self
            .chain
            .ik(target, seed, &self.options.ik)
            .map_err(|e| self.ik_status(&e))?;
        self.nearest_turns(sol.q, seed)
    }

    /// SETPOSE (and REACH): position and approach within the tolerances, the orientation
    /// the nearest one the joints can hold.
    fn solve_setpose(
        &self,
        position: Vec3,
        approach: Vec3,
        orientation: Vec3,
        seed: &[f64],
    ) -> Result<NearestSolution, Status> {
        let pose = Pose::from_approach_orientation(
            Vector3::from(position.to_array()),
            Vector3::from(approach.to_array()),
            Vector3::from(orientation.to_array()),
            PERPENDICULAR_TOLERANCE,
        )
        .map_err(|e| match e {
            limber_kinematics::FrameError::NonFinite => Status::NotFinite,
            _ => Status::InvalidArgument,
        })?;
        let mut s = self
            .chain
            .ik_nearest_orientation(&pose, seed, &self.options.ik, &self.options.setpose)
            .map_err(|e| match e {
                // Position or approach not met within the tolerances.
                ChainIkError::NotConverged { .. } => Status::OutOfReach,
                e => self.ik_status(&e),
            })?;
        s.q = self.nearest_turns(s.q, seed)?;
        Ok(s)
    }

    fn nearest_turns(&self, q: JointVec, seed: &[f64]) -> Result<JointVec, Status> {
        // Take the turn of each revolute joint nearest to the seed (less travel).
        limber_kinematics::path::nearest_turns(&self.chain, q, seed).ok_or(Status::BeyondLimits)
    }

    /// The cause of an IK failure: beyond the reach; a position reached but not the
    /// orientation (the joints cannot hold it); or neither within the joint limits.
    pub(super) fn ik_status(&self, e: &ChainIkError) -> Status {
        let ik = &self.options.ik;
        match *e {
            ChainIkError::NonFinite => Status::NotFinite,
            ChainIkError::WrongJointCount { .. } | ChainIkError::InvalidOptions => {
                Status::InvalidArgument
            }
            ChainIkError::OutOfReach { .. } => Status::OutOfReach,
            ChainIkError::NotConverged {
                position_error,
                orientation_error,
                ..
            } => {
                if position_error <= ik.position_tolerance
                    && orientation_error > ik.orientation_tolerance
                {
                    Status::UnreachableOrientation
                } else {
                    Status::OutOfReach
                }
            }
        }
    }

    fn limb_command_inner(&mut self, cmd: &LimbCommand) -> Result<(), Status> {
        self.limb_unbraked(cmd)?;
        let current = self.q();
        match *cmd {
            LimbCommand::Home => {
                self.powered()?;
                self.vecmove.active = false;
                let home = self.chain.home();
                self.move_joints_together(&home, 0.0);
                Ok(())
            }
            LimbCommand::Stop => {
                self.stop_all_joints();
                Ok(())
            }
            LimbCommand::SetPose {
                position,
                approach,
                orientation,
            } => {
                if !(position.is_finite() && approach.is_finite() && orientation.is_finite()) {
                    return Err(Status::NotFinite);
                }
                let s = self.solve_setpose(position, approach, orientation, &current)?;
                self.powered()?;
                self.vecmove.active = false;
                self.move_joints_together(&s.q, 0.0);
                self.limb.adjusted_by(s.adjustment);
                Ok(())
            }
            LimbCommand::SetPosition { position } => {
                if !position.is_finite() {
                    return Err(Status::NotFinite);
                }
                self.powered()?;
                let p = Vector3::from(position.to_array());
                let q = self.ik_to(&IkTarget::Position(p), &current)?;
                self.vecmove.active = false;
                self.move_joints_together(&q, 0.0);
                Ok(())
            }
            LimbCommand::VecMove { direction, length } => {
                if !(direction.is_finite() && length.is_finite()) {
                    return Err(Status::NotFinite);
                }
                // Normalised without overflow: (1e308, 1e308, 0) is a direction too.
                let dir = unit_direction(&Vector3::from(direction.to_array()));
                let Some(dir) = dir.filter(|_| length >= 0.0) else {
                    return Err(Status::InvalidArgument);
                };
                self.powered()?;
                self.plan_vecmove(&dir, length)
            }
            LimbCommand::Line(ref p) => self.start_path(true, p),
            LimbCommand::Ptp(ref p) => self.start_path(false, p),
        }
    }

    /// Plans the straight line from the current tool pose (orientation kept) and starts
    /// streaming it; every waypoint is solved before anything moves.
    fn plan_vecmove(&mut self, dir: &Vector3<f64>, length: f64) -> Result<(), Status> {
        let start = self.tool_pose();
        let step = self.options.vecmove_step;
        let count = (length / step).ceil() as usize;
        if count > MAX_WAYPOINTS {
            return Err(Status::InvalidArgument);
        }
        // Solve into the scratch buffer so a refusal leaves the running line intact.
        let mut seed = self.q();
        let mut plan = core::mem::take(&mut self.vecmove.scratch);
        plan.clear();
        let mut result = Ok(());
        for k in 1..=count {
            let d = (k as f64 * step).min(length);
            let target = start.translated(&(dir * d));
            match self.ik_to(&IkTarget::Pose(target), &seed) {
                Ok(q) => {
                    let jump = q
                        .iter()
                        .zip(seed.iter())
                        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
                    if jump > MAX_WAYPOINT_JUMP {
                        result = Err(Status::OutOfReach);
                        break;
                    }
                    plan.push(q);
                    seed = q;
                }
                Err(e) => {
                    result = Err(e);
                    break;
                }
            }
        }
        if let Err(e) = result {
            self.vecmove.scratch = plan;
            return Err(e);
        }
        self.vecmove.scratch = core::mem::replace(&mut self.vecmove.waypoints, plan);
        self.vecmove.step = if count > 0 {
            length / count as f64
        } else {
            0.0
        };
        self.vecmove.next = 0;
        self.vecmove.active = true;
        for m in &mut self.joints[..self.n] {
            m.stop();
        }
        self.next_waypoint();
        Ok(())
    }

    /// Starts the next VECMOVE waypoint, or ends the VECMOVE after the last one.
    pub(super) fn next_waypoint(&mut self) {
        let i = self.vecmove.next;
        let Some(q) = self.vecmove.waypoints.get(i).copied() else {
            self.vecmove.active = false;
            return;
        };
        self.vecmove.next += 1;
        let min_time = match self.limb_speed {
            Some(v) if v > 0.0 => self.vecmove.step / v,
            _ => 0.0,
        };
        self.move_joints_together(&q, min_time);
    }

    /// Answers a limb request.
    pub fn limb_request(&mut self, req: &LimbRequest) -> Result<LimbReply, Status> {
        match *req {
            LimbRequest::Power(on) => {
                self.set_power(on);
                Ok(LimbReply::Done)
            }
            LimbRequest::Geom => {
                let b = self.chain.base().position;
                Ok(LimbReply::Geom(LimbGeom {
                    base_pos: Vec3::new(b.x, b.y, b.z),
                }))
            }
            LimbRequest::Speed(v) => {
                if !v.is_finite() {
                    return Err(Status::NotFinite);
                }
                if v <= 0.0 {
                    return Err(Status::InvalidArgument);
                }
                self.limb_speed = Some(v);
                Ok(LimbReply::Done)
            }
            LimbRequest::Brakes(on) => {
                self.set_brakes(on)?;
                Ok(LimbReply::Done)
            }
            LimbRequest::Reach {
                position,
                approach,
                orientation,
            } => {
                let s = self.solve_setpose(position, approach, orientation, &self.q())?;
                let (p, a, o) = (
                    s.achieved.position,
                    s.achieved.approach(),
                    s.achieved.orientation(),
                );
                Ok(LimbReply::Reach(LimbReach {
                    position: Vec3::new(p.x, p.y, p.z),
                    approach: Vec3::new(a.x, a.y, a.z),
                    orientation: Vec3::new(o.x, o.y, o.z),
                    orientation_adjustment: s.adjustment,
                    position_error: s.position_error,
                    approach_error: s.approach_error,
                    adjusted: u32::from(adjustment_reported(s.adjustment)),
                    _pad: 0,
                }))
            }
        }
    }

    /// Fills the limb state: the tool pose (FK of the current joints) and
    /// OUT_OF_REACH / MOVING / IDLE.
    pub fn limb_state(&self, s: &mut LimbData) {
        let pose = self.tool_pose();
        let (p, a, o) = (pose.position, pose.approach(), pose.orientation());
        s.position = Vec3::new(p.x, p.y, p.z);
        s.approach = Vec3::new(a.x, a.y, a.z);
        s.orientation = Vec3::new(o.x, o.y, o.z);
        s.orientation_adjustment = self.limb.adjustment;
        self.path_state(s);
        s.state = if self.brakes {
            LimbState::Braked
        } else if self.limb.out_of_reach {
            LimbState::OutOfReach
        } else if self.collision.is_some() {
            LimbState::Collision
        } else if self.limb_moving() {
            LimbState::Moving
        } else {
            LimbState::Idle
        } as u32;
    }
}
