//! LINE and PTP (issue 28) on the simulated arm: the path is checked whole before anything
//! moves ([`limber_kinematics::path`]: reachable, within the limits, no jump, clear of the
//! floor and the obstacles), its samples become a joint trajectory, and the arm's one
//! trajectory executor runs it as it runs an uploaded one (`trajectory.rs`: the joints
//! take its desired positions exactly, a contact stops them, STOP, power and brakes end
//! it). A refused path leaves the running motion as it was and the limb state names where
//! it failed.

use limber_interfaces::actarray::{JointTrajectory, MAX_TRAJ_POINTS};
use limber_interfaces::limb::{LimbPath, PathOrientation, cmd as limb_cmd};
use limber_interfaces::prelude::*;
use limber_kinematics::Pose;
use limber_kinematics::chain::{IkTarget, JointVec};
use limber_kinematics::path::{self as kpath, BadSample, Orientation, PathFault, PathOptions};
use limber_services::monotonic_ns;
use nalgebra::Vector3;

use super::ArmModel;
use super::preemption::TOLERANCE;

/// How far a joint of a path may be from where its trajectory wants it, rad (or m).
pub const PATH_TOLERANCE: f64 = 0.01;

/// A LINE's tool speed when neither the command nor the limb's SPEED request gives one,
/// m/s.
pub const DEFAULT_LINE_SPEED: f64 = 0.1;

/// The limb's paths: the kind of the last one and its duration (its trajectory runs on the
/// arm's executor), and where the last refused one failed.
#[derive(Debug, Default)]
pub(super) struct PathRun {
    /// The kind of the last path (`LIMB_CMD_LINE`, `LIMB_CMD_PTP`) until another motion
    /// of the joints; 0: none.
    kind: u32,
    /// Its trajectory's duration, s.
    duration: f64,
    /// The last limb command was this path, refused at this sample.
    refused: Option<(u32, BadSample)>,
}

/// The status a path refused at a bad sample answers.
fn fault_status(why: PathFault) -> Status {
    match why {
        PathFault::OutOfReach => Status::OutOfReach,
        PathFault::UnreachableOrientation => Status::UnreachableOrientation,
        PathFault::BeyondLimits => Status::BeyondLimits,
        PathFault::Jump { .. } => Status::PathJumps,
        PathFault::Collision(_) => Status::PathCollides,
        PathFault::Invalid => Status::InvalidArgument,
    }
}

impl ArmModel {
    /// LINE (`line`) or PTP: checked whole, then run on the executor. A refusal records
    /// where (the limb state's `refused_at`) and changes nothing else.
    pub(super) fn start_path(&mut self, line: bool, p: &LimbPath) -> Result<(), Status> {
        let kind = if line { limb_cmd::LINE } else { limb_cmd::PTP };
        let q = self.q();
        let start = self.tool_pose();
        let position = Vector3::from(p.position.to_array());
        let (goal, orientation) = match p.orientation {
            PathOrientation::Keep => (Pose::new(position, start.rotation), Orientation::Keep),
            PathOrientation::Given {
                approach,
                orientation,
            } => (
                Pose::from_approach_orientation(
                    position,
                    Vector3::from(approach.to_array()),
                    Vector3::from(orientation.to_array()),
                    super::limb::PERPENDICULAR_TOLERANCE,
                )
                .map_err(|_| Status::InvalidArgument)?,
                Orientation::Interpolate,
            ),
        };
        let options = PathOptions {
            max_samples: MAX_TRAJ_POINTS,
            ik: self.options.ik,
            ..PathOptions::default()
        };
        let obstacles = &self.options.obstacles;
        let checked = if line {
            kpath::line(&self.chain, obstacles, &q, &goal, orientation, &options)
        } else {
            let target = IkTarget::Pose(goal);
            match self.chain.ik(&target, &q, &options.ik) {
                Ok(sol) => match kpath::nearest_turns(&self.chain, sol.q, &q) {
                    Some(qg) => kpath::ptp(&self.chain, obstacles, &q, &qg, &options),
                    None => Err(BadSample {
                        fraction: 1.0,
                        point: position,
                        why: PathFault::BeyondLimits,
                    }),
                },
                Err(e) => Err(BadSample {
                    fraction: 1.0,
                    point: position,
                    why: match self.ik_status(&e) {
                        Status::UnreachableOrientation => PathFault::UnreachableOrientation,
                        Status::BeyondLimits => PathFault::BeyondLimits,
                        _ => PathFault::OutOfReach,
                    },
                }),
            }
        };
        let samples = checked.map_err(|bad| {
            tracing::info!(kind, %bad, "simarm: path refused before it started");
            self.path.refused = Some((kind, bad));
            fault_status(bad.why)
        })?;
        self.powered()?;
        let (traj, duration) = self.time_samples(&q, &samples.q, samples.spacing, line, p.speed)?;
        let st = self.run_trajectory(&traj, monotonic_ns());
        if !st.is_carried_out() {
            return Err(st);
        }
        self.path.kind = kind;
        self.path.duration = duration;
        Ok(())
    }

    /// Fills the path's trajectory with `samples` at their times: each segment as long as
    /// its slowest joint needs at its speed (`speed` for a PTP's fastest joint), and for a
    /// LINE at least its length at the tool's speed. The trajectory, and its duration.
    fn time_samples(
        &self,
        start: &[f64],
        samples: &[JointVec],
        spacing: f64,
        line: bool,
        speed: f64,
    ) -> Result<(Box<JointTrajectory>, f64), Status> {
        let tool_speed = if speed > 0.0 {
            speed
        } else {
            self.limb_speed.unwrap_or(DEFAULT_LINE_SPEED)
        };
        let n = self.n;
        let joints: Vec<u16> = (0..n as u16).collect();
        let mut traj = JointTrajectory::new(&joints).map_err(|e| e.status())?;
        traj.set_goal_tolerance(&[TOLERANCE; super::MAX_JOINTS][..n])
            .map_err(|e| e.status())?;
        // The joints follow exactly; one held off its path (a contact) ends the path
        // PATH_TOLERANCE_VIOLATED where it is rather than waiting out the goal time.
        traj.set_path_tolerance(&[PATH_TOLERANCE; super::MAX_JOINTS][..n])
            .map_err(|e| e.status())?;
        let mut t = 0.0;
        let mut prev = start;
        for q in samples {
            let mut seg: f64 = if line { spacing / tool_speed } else { 0.0 };
            for j in 0..n {
                let mut v = self.config_speed[j];
                if !line && speed > 0.0 {
                    v = v.min(speed);
                }
                if v > 0.0 {
                    seg = seg.max((q[j] - prev[j]).abs() / v);
                }
            }
            t += seg.max(1e-3);
            traj.push(t, q, None, None).map_err(|e| e.status())?;
            prev = q;
        }
        Ok((traj, t))
    }

    /// Another motion takes the joints: no path runs.
    pub(super) fn end_path(&mut self) {
        self.path.kind = 0;
    }

    /// A new limb command: no path refused yet.
    pub(super) fn clear_refused_path(&mut self) {
        self.path.refused = None;
    }

    /// The limb state's path fields: the running path and how far it got, the last
    /// refused one and where.
    pub(super) fn path_state(&self, s: &mut LimbData) {
        let joints = (1u64 << self.n) - 1;
        let running = self.path.kind != 0 && self.trajectory_running() & joints != 0;
        if let (true, Some(f)) = (running, self.trajectory_feedback()) {
            s.path_kind = self.path.kind;
            s.path_progress = if self.path.duration > 0.0 {
                (f.time / self.path.duration).clamp(0.0, 1.0)
            } else {
                1.0
            };
        } else {
            s.path_kind = 0;
            s.path_progress = 0.0;
        }
        match self.path.refused {
            Some((kind, bad)) => {
                s.refused_kind = kind;
                s.refused_at = Vec3::new(bad.point.x, bad.point.y, bad.point.z);
                s.refused_fraction = bad.fraction;
            }
            None => {
                s.refused_kind = 0;
                s.refused_at = Vec3::default();
                s.refused_fraction = 0.0;
            }
        }
    }
}
