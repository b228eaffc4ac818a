//! Joint trajectories on the Pioneer arm: the executor (`limber_trajectory`) samples the
//! trajectory at every driver tick and its positions are streamed as servo targets
//! (ARM_POS) within what the servo protocol can do:
//!
//! * **Speed, refused up front**: a servo steps one tick per its `SPEED` (ms per step;
//!   the calibration's default is the fastest this driver commands), and the servo link
//!   carries one step of one joint per ~2 ms at 9600 baud, so with k joints moving each
//!   steps at most every max(SPEED, 2k) ms. A trajectory that needs a joint faster than
//!   that is refused before anything moves (`TOO_FAST`, the driver's log naming the
//!   joint, the point and the speeds needed and possible).
//! * **Rate**: a joint's target is sent when its tick changes, at most once per
//!   [`STREAM_PERIOD_MS`] (six joints then cost ~540 bytes/s of the link), and the last
//!   point's target as soon as it is due.
//! * **Ends**: reached when the ARMpac positions are within the goal tolerance (at least
//!   one tick) of the last point; a STOP, another command of the arm, a path or goal
//!   violation end it and nothing more is streamed (on a violation the joints are
//!   stopped where they are).

use limber_interfaces::prelude::*;
use limber_p2os::{ArmJoint, Command, JointSelection};
use limber_services::{Origin, Progress, monotonic_ns};
use limber_trajectory::{Config, Executor, JointLimit, Tick};

use super::*;

/// The shortest time between two targets of one joint, ms.
pub const STREAM_PERIOD_MS: u64 = 100;

/// The goal time tolerance of a trajectory that gives none, s: the servos' lag behind the
/// last target plus two ARMpac cycles.
const GOAL_TIME: f64 = 2.0;

/// The trajectory side of the robot model.
#[derive(Debug)]
pub(crate) struct Trajectories {
    pub(super) exec: Box<Executor>,
    /// Taken out while its trajectory starts (so the model can be borrowed meanwhile).
    upload: Option<TrajectoryUpload>,
    /// Joints whose motion the host follows is a trajectory's.
    joints: u64,
    /// When each joint's last target went out (`CLOCK_MONOTONIC` ns).
    sent_ns: [u64; ARM_JOINTS],
}

impl Default for Trajectories {
    fn default() -> Self {
        Trajectories {
            exec: Executor::new(Config::new(ARM_JOINTS)),
            upload: Some(TrajectoryUpload::new()),
            joints: 0,
            sent_ns: [0; ARM_JOINTS],
        }
    }
}

impl RobotModel {
    /// The executor's view of the arm for a trajectory of `k` joints: limits and the
    /// fastest each servo can follow.
    fn traj_config(&self, k: usize) -> Result<Config, Status> {
        let cal = self.calibration()?;
        let n = cal.num_joints().min(ARM_JOINTS);
        let mut c = Config::new(n);
        c.goal_time = GOAL_TIME;
        for (j, l) in c.limits.iter_mut().enumerate().take(n) {
            let joint = ArmJoint::from_index(j).map_err(|_| Status::UnknownJoint)?;
            let [a, _, b, _] = cal
                .limits_radians(joint)
                .map_err(|_| Status::NotCalibrated)?;
            let jc = cal.joint(joint).map_err(|_| Status::NotCalibrated)?;
            let rad_per_tick = core::f64::consts::FRAC_PI_2 / f64::from(jc.ticks_per_90.max(1));
            let ms_per_step = f64::from(jc.speed.max(1)).max(2.0 * k as f64);
            *l = JointLimit {
                min: a.min(b),
                max: a.max(b),
                max_velocity: rad_per_tick * 1000.0 / ms_per_step,
                max_deceleration: 0.0,
            };
        }
        Ok(c)
    }

    /// A trajectory command (`None` for any other).
    pub(super) fn trajectory_command(
        &mut self,
        cmd: &ActArrayCommand,
        from: &Origin,
    ) -> Option<Result<Status, Status>> {
        Some(match cmd {
            ActArrayCommand::TrajChunk(c) => {
                if let Some(u) = self.traj.upload.as_mut() {
                    u.chunk(from.client_id, c);
                }
                Ok(Status::Ok)
            }
            ActArrayCommand::TrajScale(s) => Ok(self.traj.exec.set_scale(*s)),
            ActArrayCommand::Traj(h) => self.start_trajectory(h, from).map(|()| Status::Ok),
            _ => return None,
        })
    }

    fn start_trajectory(&mut self, h: &ActArrayTrajCmd, from: &Origin) -> Result<(), Status> {
        let Some(mut upload) = self.traj.upload.take() else {
            return Err(Status::Busy);
        };
        let r = match upload.finish(from.client_id, h) {
            Ok(traj) => self.run_trajectory(traj, from),
            Err(e) => {
                tracing::info!(reason = %e, "trajectory refused");
                Err(e.status())
            }
        };
        self.traj.upload = Some(upload);
        r
    }

    /// Runs a validated joint trajectory, wherever it came from (an upload, a limb path
    /// sampled into joints): checked against the servos (limits, speed), then streamed
    /// from now; it replaces the running one from its start time. `Err` is why it was
    /// refused (nothing moving); its result comes through [`RobotModel::arm_progress`].
    pub fn run_trajectory(&mut self, traj: &JointTrajectory, from: &Origin) -> Result<(), Status> {
        let now = monotonic_ns();
        let config = self.traj_config(traj.joints().len())?;
        let actual = self.joint_angles().ok_or(Status::NotCalibrated)?;
        self.require_power()?;
        self.traj.exec.set_config(config);
        self.traj.exec.accept(traj, now, &actual).map_err(|e| {
            tracing::info!(reason = %e, "trajectory refused");
            e.status()
        })?;
        let mask = Executor::joints_of(traj);
        self.traj.joints |= mask;
        let last = traj.len() - 1;
        let goals: [f64; ARM_JOINTS] = core::array::from_fn(|j| {
            traj.joints()
                .iter()
                .position(|&c| c as usize == j)
                .map_or(f64::NAN, |c| traj.positions(last)[c])
        });
        self.vecmove = None;
        // Every servo of the trajectory at the speed the check assumed.
        let cal = *self.calibration()?;
        for (j, &goal) in goals.iter().enumerate() {
            if mask & (1 << j) == 0 {
                continue;
            }
            let joint = ArmJoint::from_index(j).map_err(|_| Status::UnknownJoint)?;
            let ms = cal.joint(joint).map_err(|_| Status::NotCalibrated)?.speed;
            self.send(
                &Command::ArmSpeed {
                    joint,
                    ms_per_step: ms.max(1),
                },
                from,
            )?;
            self.arm.goal[j] = Some(goal);
            self.traj.sent_ns[j] = 0;
        }
        self.stream_trajectory(now, from)
    }

    /// At every driver tick: samples the trajectory and streams the joints' targets (see
    /// the module's documentation). A failure to queue ends the trajectory aborted.
    pub fn step_trajectory(&mut self) {
        if self.traj.exec.running() == 0 {
            return;
        }
        if !self.arm.powered_or_pending() {
            self.traj
                .exec
                .abort(MotionResult::Aborted, Status::PoweredOff);
            return;
        }
        let now = monotonic_ns();
        if let Err(status) = self.stream_trajectory(now, &INTERNAL) {
            tracing::warn!("trajectory abandoned: {status}");
            self.traj.exec.abort(MotionResult::Aborted, status);
        }
    }

    fn stream_trajectory(&mut self, now: u64, from: &Origin) -> Result<(), Status> {
        let Some(actual) = self.joint_angles() else {
            return Err(Status::NotCalibrated);
        };
        let tick = self.traj.exec.tick(now, &actual);
        let driven = self.traj.exec.driven();
        if let Tick::Ended(r) = tick {
            if r != MotionResult::Reached {
                // Hold where they are: the servos stop stepping.
                for j in 0..ARM_JOINTS {
                    if driven & (1 << j) != 0 {
                        let joint = ArmJoint::from_index(j).map_err(|_| Status::UnknownJoint)?;
                        self.send(&Command::ArmStop(JointSelection::One(joint)), from)?;
                        self.arm.target[j] = None;
                    }
                }
            }
            return Ok(());
        }
        if tick != Tick::Running {
            return Ok(());
        }
        let last_due = self.traj.exec.feedback().point >= self.traj.exec.feedback().points;
        for j in 0..ARM_JOINTS {
            if driven & (1 << j) == 0 {
                continue;
            }
            let t = self.joint_tick(j, self.traj.exec.desired(j))?;
            let due = now.saturating_sub(self.traj.sent_ns[j]) >= STREAM_PERIOD_MS * 1_000_000;
            if self.arm.target[j] == Some(t) || !(due || last_due) {
                continue;
            }
            let joint = ArmJoint::from_index(j).map_err(|_| Status::UnknownJoint)?;
            self.send(&Command::ArmPos { joint, tick: t }, from)?;
            self.arm.set_target(j, t);
            self.traj.sent_ns[j] = now;
        }
        Ok(())
    }

    /// Another command of the arm carried out: a stop ends the trajectory stopped, any
    /// other motion of its joints preempted; nothing more is streamed.
    pub(super) fn end_trajectory(&mut self, drives: u64, stop: bool) {
        if self.traj.exec.running() & drives == 0 && !(stop && self.traj.exec.running() != 0) {
            self.traj.joints &= !drives;
            return;
        }
        if stop {
            self.traj.exec.stop(monotonic_ns());
        } else {
            self.traj.exec.release();
            self.traj.joints &= !drives;
        }
    }

    /// The link went down or the power off: the trajectory ends aborted.
    pub(super) fn abort_trajectory(&mut self, cause: Status) {
        if self.traj.exec.running() != 0 {
            self.traj.exec.abort(MotionResult::Aborted, cause);
        }
    }

    /// How joint `j`'s trajectory is doing, when its last motion was a trajectory's: its
    /// end from the executor, its position and error from the ARMpac.
    pub(super) fn trajectory_progress(&self, j: usize) -> Option<Progress> {
        if j >= ARM_JOINTS || self.traj.joints & (1 << j) == 0 {
            return None;
        }
        let own = self.joint_progress(j, true, std::time::Instant::now());
        let p = self.traj.exec.progress(j);
        let tolerance = p.tolerance.max(own.tolerance);
        Some(match (own.end, p.end) {
            // The link or the power failed: the ARMpac's cause.
            (Some(end @ (MotionResult::Aborted, _)), _) => {
                Progress::ended(end.0, end.1, own.position, own.error, tolerance)
            }
            (_, None) => Progress::moving(own.position, own.error, tolerance),
            (_, Some((r, cause))) => Progress::ended(r, cause, own.position, own.error, tolerance),
        })
    }
}
