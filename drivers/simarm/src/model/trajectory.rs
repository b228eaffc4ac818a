//! Joint trajectories on the simulated arm, executed exactly: every tick the joints a
//! trajectory drives are where [`limber_trajectory::Executor`] wants them, unless something
//! stops them (a contact with the world: they stay at the contact, and the executor's path
//! tolerance ends the trajectory). Trajectory time is real time (`CLOCK_MONOTONIC`, as its
//! start time), whatever the simulation's time scale.

use limber_interfaces::prelude::*;
use limber_services::Progress;
use limber_trajectory::{Config, Executor, JointLimit, Tick};

use super::ArmModel;

/// Deceleration on a STOP of a joint without an ACCEL limit: its highest speed lost in
/// this many seconds.
const STOP_TIME: f64 = 0.1;

/// The trajectory side of the model: the executor, the upload being received, and which
/// actuators' last motion was a trajectory.
#[derive(Debug)]
pub(super) struct Trajectories {
    exec: Box<Executor>,
    /// Taken out while its trajectory starts (so the model can be borrowed meanwhile).
    upload: Option<TrajectoryUpload>,
    /// Actuators whose motion the host follows is a trajectory's.
    joints: u64,
    /// The last tick's time, ns.
    last_ns: u64,
}

impl Trajectories {
    pub(super) fn new(actuators: usize) -> Self {
        Trajectories {
            exec: Executor::new(Config::new(actuators)),
            upload: Some(TrajectoryUpload::new()),
            joints: 0,
            last_ns: 0,
        }
    }
}

impl ArmModel {
    /// The executor's view of the arm: every actuator's limits, highest speed and STOP
    /// deceleration (its ACCEL, else its highest speed lost in 0.1 s).
    fn traj_config(&self) -> Config {
        let mut c = Config::new(self.actuators());
        for (j, l) in c.limits.iter_mut().enumerate().take(self.actuators()) {
            let Some((min, max)) = self.joint_limits(j) else {
                continue;
            };
            let max_velocity = if j < self.n {
                self.chain.joints()[j].max_speed
            } else {
                self.gripper_max_speed
            };
            let accel = self.config_accel[j];
            *l = JointLimit {
                min,
                max,
                max_velocity,
                max_deceleration: if accel.is_finite() {
                    accel
                } else {
                    max_velocity / STOP_TIME
                },
            };
        }
        c
    }

    fn actual(&self) -> [f64; MAX_ACTUATORS] {
        let mut a = [0.0; MAX_ACTUATORS];
        for (j, v) in a.iter_mut().enumerate().take(self.actuators()) {
            *v = self.actuator(j).map_or(0.0, |m| m.pos);
        }
        a
    }

    /// Carries out a trajectory command of client `client` at `now_ns`
    /// (`CLOCK_MONOTONIC`): `None` for any other command.
    pub fn trajectory_command(
        &mut self,
        cmd: &ActArrayCommand,
        client: u64,
        now_ns: u64,
    ) -> Option<Status> {
        Some(match cmd {
            ActArrayCommand::TrajChunk(c) => {
                if let Some(u) = self.traj.upload.as_mut() {
                    u.chunk(client, c);
                }
                Status::Ok
            }
            ActArrayCommand::TrajScale(s) => self.traj.exec.set_scale(*s),
            ActArrayCommand::Traj(h) => self.start_trajectory(h, client, now_ns),
            _ => return None,
        })
    }

    fn start_trajectory(&mut self, h: &ActArrayTrajCmd, client: u64, now_ns: u64) -> Status {
        let Some(mut upload) = self.traj.upload.take() else {
            return Status::Busy;
        };
        let status = match upload.finish(client, h) {
            Ok(traj) => self.run_trajectory(traj, now_ns),
            Err(e) => {
                tracing::info!(reason = %e, "trajectory refused");
                e.status()
            }
        };
        self.traj.upload = Some(upload);
        status
    }

    /// Runs a validated joint trajectory from `now_ns` (`CLOCK_MONOTONIC`), wherever it
    /// came from (an upload, a limb path sampled into joints): it replaces the running one
    /// from its start time. The status is the command's outcome (`OK`, or why it was
    /// refused, nothing moving); its result comes through
    /// [`ArmModel::arm_progress`] like any motion's.
    pub fn run_trajectory(&mut self, traj: &JointTrajectory, now_ns: u64) -> Status {
        if !self.powered {
            return Status::PoweredOff;
        }
        let mask = Executor::joints_of(traj);
        if self.brakes && mask & ((1u64 << self.n) - 1) != 0 {
            return Status::Braked;
        }
        let config = self.traj_config();
        let actual = self.actual();
        self.traj.exec.set_config(config);
        if let Err(e) = self
            .traj
            .exec
            .accept(traj, now_ns, &actual[..self.actuators()])
        {
            tracing::info!(reason = %e, "trajectory refused");
            return e.status();
        }
        // A new motion ends the COLLISION state, and may move away from the contact.
        self.collision = None;
        self.leaving_contact = self.contact().is_some();
        if mask & ((1u64 << self.n) - 1) != 0 {
            self.vecmove.active = false;
        }
        self.traj.joints |= mask;
        self.traj.last_ns = now_ns;
        for j in 0..self.actuators() {
            if mask & (1 << j) != 0
                && let Some(m) = self.actuator_mut(j)
            {
                m.stop();
                m.moving = true;
            }
        }
        Status::Ok
    }

    /// Advances the trajectory to `now_ns`: the joints it drives go where it wants them
    /// (unless in contact with the world), then a contact stops them.
    pub fn step_trajectory(&mut self, now_ns: u64) {
        let actual = self.actual();
        let tick = self.traj.exec.sample(now_ns, &actual[..self.actuators()]);
        self.traj.last_ns = now_ns;
        if tick == Tick::Idle {
            return;
        }
        let driven = self.traj.exec.driven();
        let blocked = self.collision.is_some();
        for j in 0..self.actuators() {
            if driven & (1 << j) == 0 || (blocked && j < self.n) {
                continue;
            }
            let (p, v) = (
                self.traj.exec.desired(j),
                self.traj.exec.desired_velocity(j),
            );
            if let Some(m) = self.actuator_mut(j) {
                m.pos = p;
                m.target = p;
                m.velocity = v;
                m.moving = true;
                m.stalled = false;
            }
        }
        self.stop_at_contact();
        // Measured where they are now: exact unless something stopped them.
        let actual = self.actual();
        self.traj.exec.check(&actual[..self.actuators()]);
        let running = self.traj.exec.running();
        for j in 0..self.actuators() {
            if driven & (1 << j) != 0
                && let Some(m) = self.actuator_mut(j)
            {
                m.moving = running & (1 << j) != 0;
                if !m.moving {
                    m.velocity = 0.0;
                }
            }
        }
    }

    /// A STOP (or the deadman): the trajectory decelerates and ends stopped.
    pub(crate) fn stop_trajectory(&mut self) {
        self.traj.exec.stop(self.traj.last_ns);
    }

    /// Another command takes actuators `drives`: the trajectory ends preempted.
    pub(crate) fn preempt_trajectory(&mut self, drives: u64) {
        if self.traj.exec.driven() & drives != 0 {
            self.traj.exec.release();
        }
        self.traj.joints &= !drives;
    }

    /// The power went off or the brakes on: the trajectory ends aborted.
    pub(super) fn abort_trajectory(&mut self, cause: Status) {
        self.traj.exec.abort(MotionResult::Aborted, cause);
    }

    /// How actuator `j`'s trajectory is doing, when its last motion was a trajectory's.
    pub(super) fn trajectory_progress(&self, j: usize) -> Option<Progress> {
        if j >= 64 || self.traj.joints & (1 << j) == 0 {
            return None;
        }
        let p = self.traj.exec.progress(j);
        Some(match p.end {
            None => Progress::moving(p.position, p.error, p.tolerance),
            Some((r, cause)) => Progress::ended(r, cause, p.position, p.error, p.tolerance),
        })
    }

    /// The actuators a trajectory still drives toward its goal.
    pub(super) fn trajectory_running(&self) -> u64 {
        self.traj.exec.running()
    }

    /// The feedback of the trajectory running (or last run), if any.
    pub(super) fn trajectory_feedback(&self) -> Option<limber_trajectory::Feedback> {
        (self.traj.joints != 0).then(|| self.traj.exec.feedback())
    }

    /// The trajectory's feedback as the actuator array's state carries it.
    pub fn trajectory_state(&self) -> TrajFeedback {
        self.traj.exec.state_feedback()
    }
}
