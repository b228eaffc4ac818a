//! LINE and PTP (issue 28) on the simulated arm: the path is checked whole before anything
//! moves ([`limber_kinematics::path`]: reachable, within the limits, no jump, clear of the
//! floor and the obstacles), its samples become a joint trajectory, and the trajectory
//! executor ([`limber_trajectory::Executor`], the one every driver ticks) runs it: each
//! step of the simulation the joints take its desired positions exactly. A refused path
//! leaves the running motion as it was and the limb state names where it failed.

use limber_interfaces::actarray::{JointTrajectory, MAX_TRAJ_POINTS};
use limber_interfaces::limb::{LimbPath, PathOrientation, cmd as limb_cmd};
use limber_interfaces::prelude::*;
use limber_kinematics::Pose;
use limber_kinematics::chain::{Chain, IkTarget, JointVec};
use limber_kinematics::path::{self as kpath, BadSample, Orientation, PathFault, PathOptions};
use limber_services::Progress;
use limber_trajectory::{Config, Executor, JointLimit, Tick};
use nalgebra::Vector3;

use super::ArmModel;
use super::preemption::TOLERANCE;

/// A LINE's tool speed when neither the command nor the limb's SPEED request gives one,
/// m/s.
pub const DEFAULT_LINE_SPEED: f64 = 0.1;

/// The paths of the limb: the executor, the trajectory being built, what runs.
#[derive(Debug)]
pub(super) struct PathRun {
    exec: Box<Executor>,
    /// The executor drives the joints (the path has not ended).
    pub(super) active: bool,
    /// The kind of the last path (`LIMB_CMD_LINE`, `LIMB_CMD_PTP`) until another motion
    /// of the joints: its results come from the executor. 0: none.
    kind: u32,
    /// The running path's duration, s.
    duration: f64,
    /// The last limb command was this path, refused at this sample.
    refused: Option<(u32, BadSample)>,
}

impl PathRun {
    /// Idle, for `chain`'s joints at their limits and maximum speeds (a STOP holds at
    /// once: the simulated joints stop where they are).
    pub(super) fn new(chain: &Chain) -> Self {
        let mut config = Config::new(chain.dof());
        for (l, j) in config.limits.iter_mut().zip(chain.joints()) {
            *l = JointLimit {
                min: j.min,
                max: j.max,
                max_velocity: j.max_speed,
                max_deceleration: 0.0,
            };
        }
        PathRun {
            exec: Executor::new(config),
            active: false,
            kind: 0,
            duration: 0.0,
            refused: None,
        }
    }
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
    /// Simulated time, ns (the executor's clock).
    fn now_ns(&self) -> u64 {
        (self.time * 1e9) as u64
    }

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
        let now = self.now_ns();
        self.path.exec.accept(&traj, now, &q).map_err(|r| {
            tracing::info!(kind, refusal = %r, "simarm: path refused by the executor");
            r.status()
        })?;
        // The executor drives the joints from here on.
        self.vecmove.active = false;
        for m in &mut self.joints[..self.n] {
            m.stop();
        }
        if let Some(last) = samples.q.last() {
            for (m, g) in self.joints.iter_mut().zip(last.iter()) {
                m.goal = *g;
            }
        }
        self.path.active = true;
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

    /// One step of the running path: the executor's desired positions become the joints'.
    pub(super) fn step_path(&mut self) {
        if !self.path.active {
            return;
        }
        let now = self.now_ns();
        let q = self.q();
        let tick = self.path.exec.tick(now, &q);
        let driven = self.path.exec.driven();
        for j in 0..self.n {
            if driven & (1 << j) != 0 {
                self.joints[j].pos = self.path.exec.desired(j);
            }
        }
        if matches!(tick, Tick::Ended(_) | Tick::Idle) {
            self.path.active = false;
        }
    }

    /// The joints stop where they are (STOP, power off, brakes): the path ends STOPPED.
    pub(super) fn halt_path(&mut self) {
        if self.path.active {
            let now = self.now_ns();
            self.path.exec.stop(now);
            self.path.active = false;
        }
    }

    /// The limb touched something: the path ends STALLED where it is.
    pub(super) fn stall_path(&mut self) {
        if self.path.active {
            self.path.exec.abort(MotionResult::Stalled, Status::Ok);
            self.path.active = false;
        }
    }

    /// Another motion of the joints takes them: the path (if any) is done with.
    pub(super) fn release_path(&mut self) {
        if self.path.kind != 0 {
            self.path.exec.release();
            self.path.active = false;
            self.path.kind = 0;
        }
    }

    /// A new limb command: no path refused yet.
    pub(super) fn clear_refused_path(&mut self) {
        self.path.refused = None;
    }

    /// How joint `j` of the last path is doing (`None`: no path drives it).
    pub(super) fn path_progress(&self, j: usize) -> Option<Progress> {
        if self.path.kind == 0 || j >= self.n {
            return None;
        }
        let p = self.path.exec.progress(j);
        let pos = self.joints[j].pos;
        Some(match p.end {
            None => Progress::moving(pos, p.error, TOLERANCE),
            Some((r, s)) => Progress::ended(r, s, pos, pos - self.joints[j].goal, TOLERANCE),
        })
    }

    /// The limb state's path fields: the running path and how far it got, the last
    /// refused one and where.
    pub(super) fn path_state(&self, s: &mut LimbData) {
        if self.path.active {
            let f = self.path.exec.feedback();
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
