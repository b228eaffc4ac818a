//! The joint trajectory executor that a driver ticks: control_msgs' FollowJointTrajectory
//! semantics (see `spec/motion-reference.md`), written once for every driver.
//!
//! A driver keeps one [`Executor`] per actuator array. It hands it a validated
//! [`JointTrajectory`] with [`Executor::accept`] (which checks it against the device:
//! joints, limits, speeds, start time), and then on every cycle calls [`Executor::tick`]
//! with the joints' actual positions and commands the positions [`Executor::desired`]
//! gives for the joints in [`Executor::driven`]. A STOP calls [`Executor::stop`]
//! (decelerate within each joint's limit), another command of the device
//! [`Executor::release`]. The host's motion tracking asks [`Executor::progress`] for each
//! joint. Nothing here allocates after [`Executor::new`].
//!
//! # Rules (control_msgs' joint_trajectory_controller, as limber applies them)
//!
//! * **Interpolation**: from what the points give: positions only = linear, with
//!   velocities = cubic, with accelerations = quintic. The first segment runs from the
//!   joints' state when the trajectory becomes active (the desired state of the trajectory
//!   it replaces, or the actual positions at rest) to the first point after that moment.
//! * **Start time**: 0 = when accepted; in the future = the trajectory waits (the one
//!   running goes on until then); in the past by up to [`Config::max_start_age`] = points
//!   already past are dropped; further in the past, or every point past = refused
//!   ([`Status::OldTimestamp`]).
//! * **Replacement**: one active trajectory per device; a new one replaces the running one
//!   from its start time, continuing from the old one's desired position and velocity (no
//!   jump). Joints of the old one that the new one does not name hold where they are.
//! * **Tolerances**: per joint, 0 = not enforced. A joint further than its path tolerance
//!   from the desired position ends the trajectory
//!   [`MotionResult::PathToleranceViolated`] and every joint holds where it is. After the
//!   last point's time the joints have the goal time tolerance (0 = [`Config::goal_time`])
//!   to come within their goal tolerance: [`MotionResult::Reached`] when they do,
//!   [`MotionResult::GoalToleranceViolated`] (holding) when they do not.
//! * **Speed scaling**: trajectory time advances at `scale` times real time: 0 pauses, 1
//!   is nominal; the factor stays for later trajectories.
//! * **Cancel**: a STOP decelerates each joint from its desired velocity within its
//!   [`JointLimit::max_deceleration`] (0 = hold at once).

use limber_interfaces::actarray::{Interpolation, JointTrajectory, MAX_TRAJ_POINTS, TrajFeedback};
use limber_interfaces::prelude::*;

mod limits;
mod spline;

pub use limits::{Config, JointLimit, Refusal};

pub use spline::{Knot, sample};

/// How one joint stands with the executor.
#[derive(Debug, Clone, Copy, PartialEq)]
enum JointRun {
    /// Not driven by a trajectory.
    Free,
    /// Driven by the active (or pending) trajectory.
    Running,
    /// Its trajectory ended: how, why.
    Ended(MotionResult, Status),
}

/// What a tick did.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Tick {
    /// No trajectory runs and nothing decelerates: command nothing.
    Idle,
    /// Command [`Executor::desired`] for the joints in [`Executor::driven`].
    Running,
    /// The trajectory ended on this tick, with this result: command the (holding)
    /// [`Executor::desired`] for [`Executor::driven`] this once.
    Ended(MotionResult),
}

/// A trajectory's feedback (control_msgs': desired, actual, error, the current point).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Feedback {
    /// The point the trajectory is heading for (0-based; `points` once past the last).
    pub point: usize,
    /// Its points.
    pub points: usize,
    /// The largest |actual − desired| of its joints at the last tick.
    pub max_error: f64,
    /// Trajectory time at the last tick, s (scaled).
    pub time: f64,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    Idle,
    Running,
    /// Holding after the end (desired fixed), nothing more to report.
    Holding,
    /// Decelerating after a STOP since `since` (ns).
    Decelerating {
        since: u64,
    },
}

/// The executor of one device's joint trajectories. About 100 kB (two trajectories):
/// [`Executor::new`] boxes it.
pub struct Executor {
    config: Config,
    active: Box<JointTrajectory>,
    next: Box<JointTrajectory>,
    next_pending: bool,
    next_start_ns: u64,
    phase: Phase,
    scale: f64,
    /// Trajectory time (s, scaled) and the tick it was at.
    tau: f64,
    last_ns: u64,
    /// The first knot (the state the trajectory started from), at `tau0`.
    start: [Knot; MAX_ACTUATORS],
    tau0: f64,
    /// The first point after `tau0`.
    first: usize,
    /// The point being headed for.
    point: usize,
    end_deadline: f64,
    desired: [Knot; MAX_ACTUATORS],
    actual: [f64; MAX_ACTUATORS],
    driven: u64,
    joints: [JointRun; MAX_ACTUATORS],
    error: [f64; MAX_ACTUATORS],
    tolerance: [f64; MAX_ACTUATORS],
    goal: [f64; MAX_ACTUATORS],
    max_error: f64,
    /// Each device joint's desired state when a STOP came.
    stop_from: [Knot; MAX_ACTUATORS],
    /// How the last trajectory ended (`None` while one runs or before the first).
    last_result: Option<MotionResult>,
    /// A trajectory was accepted since the start.
    ever: bool,
}

impl core::fmt::Debug for Executor {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Executor")
            .field("phase", &self.phase)
            .field("active", &self.active)
            .field("next_pending", &self.next_pending)
            .field("scale", &self.scale)
            .field("tau", &self.tau)
            .finish_non_exhaustive()
    }
}

fn bit(j: usize) -> u64 {
    1u64 << j
}

impl Executor {
    /// An idle executor of a device.
    pub fn new(config: Config) -> Box<Self> {
        let empty = || JointTrajectory::new(&[0]).unwrap_or_else(|_| unreachable!());
        Box::new(Executor {
            config,
            active: empty(),
            next: empty(),
            next_pending: false,
            next_start_ns: 0,
            phase: Phase::Idle,
            scale: 1.0,
            tau: 0.0,
            last_ns: 0,
            start: [Knot::default(); MAX_ACTUATORS],
            tau0: 0.0,
            first: 0,
            point: 0,
            end_deadline: 0.0,
            desired: [Knot::default(); MAX_ACTUATORS],
            actual: [0.0; MAX_ACTUATORS],
            driven: 0,
            joints: [JointRun::Free; MAX_ACTUATORS],
            error: [f64::NAN; MAX_ACTUATORS],
            tolerance: [0.0; MAX_ACTUATORS],
            goal: [f64::NAN; MAX_ACTUATORS],
            max_error: 0.0,
            stop_from: [Knot::default(); MAX_ACTUATORS],
            last_result: None,
            ever: false,
        })
    }

    /// The device's configuration.
    pub fn config(&self) -> &Config {
        &self.config
    }

    /// Changes the device's configuration (e.g. limits learnt from the hardware).
    pub fn set_config(&mut self, config: Config) {
        self.config = config;
    }

    /// The device joints a trajectory drives (bit i = joint i), for
    /// `DeviceHandler::motion`.
    pub fn joints_of(traj: &JointTrajectory) -> u64 {
        traj.joints().iter().fold(0, |m, &j| m | bit(j as usize))
    }

    /// The joints whose trajectory (active or pending) is still running.
    pub fn running(&self) -> u64 {
        (0..MAX_ACTUATORS)
            .filter(|&j| self.joints[j] == JointRun::Running)
            .fold(0, |m, j| m | bit(j))
    }

    /// The joints the executor commands now ([`Executor::desired`] holds their positions).
    pub fn driven(&self) -> u64 {
        self.driven
    }

    /// The desired position of device joint `j` (meaningful for the joints in
    /// [`Executor::driven`]).
    pub fn desired(&self, j: usize) -> f64 {
        self.desired[j].p
    }

    /// The desired velocity of device joint `j`.
    pub fn desired_velocity(&self, j: usize) -> f64 {
        self.desired[j].v
    }

    /// The speed scaling factor.
    pub fn scale(&self) -> f64 {
        self.scale
    }

    /// Sets the speed scaling: 0 pauses, 1 is nominal. Returns `Clamped` for a factor
    /// above 1 (1 is used) and refuses a negative or non-finite one.
    pub fn set_scale(&mut self, scale: f64) -> Status {
        if !scale.is_finite() {
            return Status::NotFinite;
        }
        if scale < 0.0 {
            return Status::BeyondLimits;
        }
        self.scale = scale.min(1.0);
        if scale > 1.0 {
            Status::Clamped
        } else {
            Status::Ok
        }
    }

    /// The feedback of the active trajectory.
    pub fn feedback(&self) -> Feedback {
        Feedback {
            point: self.point,
            points: self.active.len(),
            max_error: self.max_error,
            time: self.tau,
        }
    }

    /// The feedback as the actuator array's state carries it ([`TrajFeedback`]).
    pub fn state_feedback(&self) -> TrajFeedback {
        let running = self.running() != 0;
        TrajFeedback {
            active: match (self.ever, running) {
                (false, _) => 0,
                (true, true) => 1,
                (true, false) => 2,
            },
            point: self.point as u32,
            points: self.active.len() as u32,
            result: if running {
                0
            } else {
                self.last_result.map_or(0, MotionResult::code)
            },
            max_error: self.max_error,
            time: self.tau,
            scale: self.scale,
        }
    }

    /// Checks `traj` against the device and takes it: it replaces the running trajectory
    /// from its start time. `now_ns` is `CLOCK_MONOTONIC`; `actual` the device's joint
    /// positions (one per device joint). Nothing changes when it is refused.
    pub fn accept(
        &mut self,
        traj: &JointTrajectory,
        now_ns: u64,
        actual: &[f64],
    ) -> Result<(), Refusal> {
        traj.validate()?;
        let last = self.config.joints.saturating_sub(1);
        if let Some(&joint) = traj
            .joints()
            .iter()
            .find(|&&j| j as usize >= self.config.joints)
        {
            return Err(Refusal::UnknownJoint { joint, last });
        }
        let start_ns = if traj.start_ns() == 0 {
            now_ns
        } else {
            traj.start_ns()
        };
        let age = now_ns.saturating_sub(start_ns) as f64 * 1e-9;
        if age > self.config.max_start_age || age >= traj.duration() {
            return Err(Refusal::OldTimestamp {
                age,
                max: self.config.max_start_age,
            });
        }
        // The state it starts from: where the joints will be when it becomes active. For a
        // start now (or past), the desired state of what runs, else the actual position;
        // a start ahead is checked from the same state (the hand-off is re-planned then).
        let mut from = [Knot::default(); MAX_ACTUATORS];
        for (c, &j) in traj.joints().iter().enumerate() {
            let j = j as usize;
            from[c] = self.state_of(j, actual);
        }
        self.check_goal(traj, &from, age)?;
        *self.next = traj.clone();
        self.next_pending = true;
        self.ever = true;
        self.last_result = None;
        self.next_start_ns = start_ns;
        for &j in traj.joints() {
            self.joints[j as usize] = JointRun::Running;
        }
        if start_ns <= now_ns {
            self.activate(now_ns, actual);
        }
        Ok(())
    }

    /// Where joint `j` is now for a trajectory starting from it.
    fn state_of(&self, j: usize, actual: &[f64]) -> Knot {
        if self.driven & bit(j) != 0 {
            let d = self.desired[j];
            match self.phase {
                Phase::Running | Phase::Decelerating { .. } => d,
                _ => Knot {
                    p: d.p,
                    ..Knot::default()
                },
            }
        } else {
            Knot {
                p: actual.get(j).copied().unwrap_or(0.0),
                ..Knot::default()
            }
        }
    }

    /// Limits and speeds of every segment from `from` (the columns' start state) at
    /// trajectory time `tau0`.
    fn check_goal(&self, traj: &JointTrajectory, from: &[Knot], tau0: f64) -> Result<(), Refusal> {
        let kind = traj.interpolation();
        let first = (0..traj.len())
            .find(|&i| traj.time(i) > tau0)
            .unwrap_or(traj.len());
        for (c, &j) in traj.joints().iter().enumerate() {
            let lim = self.config.limits[j as usize];
            let mut k0 = from[c];
            let mut t0 = tau0;
            for i in first..traj.len() {
                let k1 = point_knot(traj, kind, i, c);
                let span = traj.time(i) - t0;
                let (vmax, lo, hi) = spline::extremes(kind, k0, k1, span);
                for value in [lo, hi] {
                    if value < lim.min - 1e-9 || value > lim.max + 1e-9 {
                        return Err(Refusal::BeyondLimits {
                            joint: j,
                            point: i,
                            value,
                            min: lim.min,
                            max: lim.max,
                        });
                    }
                }
                if lim.max_velocity > 0.0 && vmax > lim.max_velocity * (1.0 + 1e-9) {
                    return Err(Refusal::TooFast {
                        joint: j,
                        point: i,
                        needed: vmax,
                        possible: lim.max_velocity,
                    });
                }
                k0 = k1;
                t0 = traj.time(i);
            }
        }
        Ok(())
    }

    /// Makes the pending trajectory the active one at `now_ns`.
    fn activate(&mut self, now_ns: u64, actual: &[f64]) {
        let tau0 = now_ns.saturating_sub(self.next_start_ns) as f64 * 1e-9;
        let mut from = [Knot::default(); MAX_ACTUATORS];
        for (c, &j) in self.next.joints().iter().enumerate() {
            from[c] = self.state_of(j as usize, actual);
        }
        // Joints of the old trajectory that the new one does not drive hold where they are.
        let new_mask = Self::joints_of(&self.next);
        for j in 0..MAX_ACTUATORS {
            if self.driven & bit(j) != 0 && new_mask & bit(j) == 0 {
                self.desired[j].v = 0.0;
                self.desired[j].a = 0.0;
                if self.joints[j] == JointRun::Running {
                    self.joints[j] = JointRun::Ended(MotionResult::Preempted, Status::Ok);
                }
            }
        }
        core::mem::swap(&mut self.active, &mut self.next);
        self.next_pending = false;
        self.start = from;
        self.tau0 = tau0;
        self.tau = tau0;
        self.last_ns = now_ns;
        self.first = (0..self.active.len())
            .find(|&i| self.active.time(i) > tau0)
            .unwrap_or(self.active.len());
        self.point = self.first;
        let goal_time = match self.active.goal_time_tolerance() {
            0.0 => self.config.goal_time,
            t => t,
        };
        self.end_deadline = self.active.duration() + goal_time;
        self.max_error = 0.0;
        let last = self.active.len() - 1;
        for (c, &j) in self.active.joints().iter().enumerate() {
            let j = j as usize;
            self.driven |= bit(j);
            self.joints[j] = JointRun::Running;
            self.goal[j] = self.active.positions(last)[c];
            self.tolerance[j] = self.active.goal_tolerance()[c];
            self.desired[j] = from[c];
        }
        self.phase = Phase::Running;
    }

    /// Advances to `now_ns` with the joints' actual positions (one per device joint):
    /// computes the desired positions, checks the tolerances, ends the trajectory when it
    /// is done. Allocation-free.
    pub fn tick(&mut self, now_ns: u64, actual: &[f64]) -> Tick {
        match self.sample(now_ns, actual) {
            Tick::Running if self.phase == Phase::Running => self.check(actual),
            t => t,
        }
    }

    /// The first half of [`Executor::tick`], for a simulator that puts its joints where
    /// they are wanted before it measures them: advances to `now_ns` and computes the
    /// desired positions (`actual`: where the joints are, for a trajectory that becomes
    /// active now). Follow it with [`Executor::check`]. Allocation-free.
    pub fn sample(&mut self, now_ns: u64, actual: &[f64]) -> Tick {
        let n = actual.len().min(MAX_ACTUATORS);
        self.actual[..n].copy_from_slice(&actual[..n]);
        if self.next_pending && now_ns >= self.next_start_ns {
            self.activate(now_ns, actual);
        }
        match self.phase {
            Phase::Idle => Tick::Idle,
            Phase::Holding => Tick::Running,
            Phase::Decelerating { since } => self.decelerate(now_ns, since),
            Phase::Running => {
                self.desire(now_ns);
                Tick::Running
            }
        }
    }

    fn desire(&mut self, now_ns: u64) {
        let dt = now_ns.saturating_sub(self.last_ns) as f64 * 1e-9;
        self.last_ns = now_ns;
        self.tau += dt * self.scale;
        let traj = &*self.active;
        let kind = traj.interpolation();
        while self.point < traj.len() && traj.time(self.point) <= self.tau {
            self.point += 1;
        }
        let (t0, t1) = if self.point == self.first {
            (self.tau0, traj.time(self.first.min(traj.len() - 1)))
        } else {
            let i = self.point.min(traj.len() - 1);
            (traj.time(i.saturating_sub(1)), traj.time(i))
        };
        for (c, &j) in traj.joints().iter().enumerate() {
            self.desired[j as usize] = if self.point >= traj.len() {
                point_knot(traj, kind, traj.len() - 1, c)
            } else {
                let k1 = point_knot(traj, kind, self.point, c);
                let k0 = if self.point == self.first {
                    self.start[c]
                } else {
                    point_knot(traj, kind, self.point - 1, c)
                };
                spline::sample(kind, k0, k1, t1 - t0, self.tau - t0)
            };
        }
    }

    /// The second half of [`Executor::tick`]: the joints' actual positions now against the
    /// desired ones: the path tolerance, and after the last point the goal tolerance and
    /// the goal time. Allocation-free.
    pub fn check(&mut self, actual: &[f64]) -> Tick {
        if self.phase != Phase::Running {
            return Tick::Running;
        }
        let n = actual.len().min(MAX_ACTUATORS);
        self.actual[..n].copy_from_slice(&actual[..n]);
        let traj = &*self.active;
        let mut max_error: f64 = 0.0;
        let mut violated = false;
        for (c, &j) in traj.joints().iter().enumerate() {
            let j = j as usize;
            let e = self.actual[j] - self.desired[j].p;
            max_error = max_error.max(e.abs());
            let tol = traj.path_tolerance()[c];
            if tol > 0.0 && e.abs() > tol && self.point < traj.len() {
                violated = true;
            }
            self.error[j] = self.actual[j] - self.goal[j];
        }
        self.max_error = max_error;
        if violated {
            return self.finish(MotionResult::PathToleranceViolated, true);
        }
        if self.tau >= traj.duration() {
            let within = traj.joints().iter().enumerate().all(|(c, &j)| {
                let tol = traj.goal_tolerance()[c];
                tol == 0.0 || (self.actual[j as usize] - self.goal[j as usize]).abs() <= tol
            });
            if within {
                return self.finish(MotionResult::Reached, false);
            }
            if self.tau >= self.end_deadline {
                return self.finish(MotionResult::GoalToleranceViolated, true);
            }
        }
        Tick::Running
    }

    /// Ends the active trajectory: every joint holds (where it is when `at_actual`, at the
    /// last point otherwise).
    fn finish(&mut self, result: MotionResult, at_actual: bool) -> Tick {
        for &j in self.active.joints() {
            let j = j as usize;
            if at_actual {
                self.desired[j].p = self.actual[j];
            }
            self.desired[j].v = 0.0;
            self.desired[j].a = 0.0;
            if self.joints[j] == JointRun::Running && !self.next_pending_drives(j) {
                self.joints[j] = JointRun::Ended(result, Status::Ok);
            }
            self.error[j] = self.actual[j] - self.goal[j];
        }
        self.phase = Phase::Holding;
        self.last_result = Some(result);
        Tick::Ended(result)
    }

    fn next_pending_drives(&self, j: usize) -> bool {
        self.next_pending && self.next.joints().contains(&(j as u8))
    }

    fn decelerate(&mut self, now_ns: u64, since: u64) -> Tick {
        let t = now_ns.saturating_sub(since) as f64 * 1e-9;
        let mut moving = false;
        for j in 0..MAX_ACTUATORS {
            if self.driven & bit(j) == 0 {
                continue;
            }
            let k = self.stop_from[j];
            let a = self.config.limits[j].max_deceleration;
            if a <= 0.0 || k.v == 0.0 {
                self.desired[j] = Knot {
                    p: k.p,
                    ..Knot::default()
                };
                continue;
            }
            let stop = k.v.abs() / a;
            let tt = t.min(stop);
            self.desired[j] = Knot {
                p: k.p + k.v * tt - k.v.signum() * a * tt * tt / 2.0,
                v: k.v - k.v.signum() * a * tt,
                a: 0.0,
            };
            moving |= t < stop;
        }
        if moving {
            Tick::Running
        } else {
            self.phase = Phase::Holding;
            Tick::Running
        }
    }

    /// A STOP at `now_ns`: the trajectory (and a pending one) ends
    /// [`MotionResult::Stopped`]; each joint decelerates from its desired velocity within
    /// its limit and holds.
    pub fn stop(&mut self, now_ns: u64) {
        if self.running() != 0 {
            self.last_result = Some(MotionResult::Stopped);
        }
        self.next_pending = false;
        for j in 0..MAX_ACTUATORS {
            if self.joints[j] == JointRun::Running {
                self.joints[j] = JointRun::Ended(MotionResult::Stopped, Status::Ok);
            }
            // The deceleration starts from the desired state now.
            self.stop_from[j] = self.desired[j];
        }
        if matches!(self.phase, Phase::Running) {
            self.phase = Phase::Decelerating { since: now_ns };
        }
    }

    /// Another command takes the device's joints (a POS, a HOME, ...): the trajectory (and
    /// a pending one) ends [`MotionResult::Preempted`], and the executor commands nothing
    /// more until the next trajectory.
    pub fn release(&mut self) {
        if self.running() != 0 {
            self.last_result = Some(MotionResult::Preempted);
        }
        self.next_pending = false;
        for j in 0..MAX_ACTUATORS {
            if self.joints[j] == JointRun::Running {
                self.joints[j] = JointRun::Ended(MotionResult::Preempted, Status::Ok);
            }
        }
        self.driven = 0;
        self.phase = Phase::Idle;
    }

    /// Ends what runs with `result` because of `cause` (the link went down, the power went
    /// off, a collision): every joint holds where it is.
    pub fn abort(&mut self, result: MotionResult, cause: Status) {
        if self.running() != 0 {
            self.last_result = Some(result);
        }
        self.next_pending = false;
        for j in 0..MAX_ACTUATORS {
            if self.joints[j] == JointRun::Running {
                self.joints[j] = JointRun::Ended(result, cause);
                self.desired[j] = Knot {
                    p: self.actual[j],
                    ..Knot::default()
                };
                self.error[j] = self.actual[j] - self.goal[j];
            }
        }
        if self.phase != Phase::Idle {
            self.phase = Phase::Holding;
        }
    }

    /// How device joint `j`'s trajectory is doing, for the host's motion tracking
    /// (`DeviceHandler::progress`). A joint no trajectory drives reads as preempted.
    pub fn progress(&self, j: usize) -> JointProgress {
        let Some(run) = self.joints.get(j) else {
            return JointProgress {
                end: Some((MotionResult::Preempted, Status::Ok)),
                position: f64::NAN,
                error: f64::NAN,
                tolerance: 0.0,
            };
        };
        JointProgress {
            end: match *run {
                JointRun::Running => None,
                JointRun::Ended(r, s) => Some((r, s)),
                JointRun::Free => Some((MotionResult::Preempted, Status::Ok)),
            },
            position: self.actual[j],
            error: self.error[j],
            tolerance: self.tolerance[j],
        }
    }
}

/// How one joint's trajectory is doing ([`Executor::progress`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointProgress {
    /// `None` while it runs; how it ended and why.
    pub end: Option<(MotionResult, Status)>,
    /// Its position at the last tick.
    pub position: f64,
    /// Its position minus the trajectory's last point.
    pub error: f64,
    /// Its goal tolerance (0: not enforced).
    pub tolerance: f64,
}

/// The knot of point `i`, column `c`, with the fields the interpolation uses.
fn point_knot(traj: &JointTrajectory, kind: Interpolation, i: usize, c: usize) -> Knot {
    let i = i.min(MAX_TRAJ_POINTS - 1);
    Knot {
        p: traj.positions(i)[c],
        v: if kind == Interpolation::Linear {
            0.0
        } else {
            traj.velocities(i)[c]
        },
        a: if kind == Interpolation::Quintic {
            traj.accelerations(i)[c]
        } else {
            0.0
        },
    }
}
