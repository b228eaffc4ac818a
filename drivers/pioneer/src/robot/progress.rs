//! How each part of a motion is doing, for its result (issue 28): a joint has reached its
//! goal when the ARMpac shows it at its target tick (within one tick of the goal a client
//! asked in radians: the servo's resolution), stalled when the driver's stall rule says
//! so, aborted when the arm stops reporting (link lost) or loses power; and the speed,
//! estimated from successive ARMpacs.

use std::time::{Duration, Instant};

use limber_interfaces::prelude::*;
use limber_p2os::{ArmJoint, PaddleState};
use limber_services::Progress;

use super::*;

/// What a joint's move may take beyond its servo's stepping ([`RobotModel::travel_bound`]).
pub const TRAVEL_MARGIN: Duration = Duration::from_secs(2);

impl RobotModel {
    /// One tick of joint `j`, in radians (the servo's resolution: the tolerance).
    fn tick_rad(&self, j: usize) -> Option<f64> {
        let cal = self.cal.as_ref()?;
        let joint = ArmJoint::from_index(j).ok()?;
        let c = cal.joint(joint).ok()?;
        (c.ticks_per_90 > 0).then(|| core::f64::consts::FRAC_PI_2 / f64::from(c.ticks_per_90))
    }

    /// Joint `j`'s angle for `tick`.
    fn tick_angle(&self, j: usize, tick: u8) -> Option<f64> {
        let cal = self.cal.as_ref()?;
        cal.ticks_to_radians(ArmJoint::from_index(j).ok()?, tick)
            .ok()
    }

    /// Why the arm cannot go on moving now, if it cannot.
    fn arm_abort_cause(&self, now: Instant) -> Option<Status> {
        if !self.arm_reporting(now) {
            Some(Status::LinkDown)
        } else if !self.arm.powered_or_pending() {
            Some(Status::PoweredOff)
        } else {
            None
        }
    }

    /// How arm joint `j` (5: the arm gripper) is doing in a motion; `streaming`: a VECMOVE
    /// is still being streamed to it. A joint still moving past its
    /// [`RobotModel::travel_bound`] ends TIMED_OUT (cause TIMEOUT).
    pub fn joint_progress(&self, j: usize, streaming: bool, now: Instant) -> Progress {
        if j >= ARM_JOINTS {
            return Progress::UNKNOWN;
        }
        let position = self.tick_angle(j, self.arm.ticks[j]).unwrap_or(f64::NAN);
        let goal =
            self.arm.goal[j].or_else(|| self.arm.target[j].and_then(|t| self.tick_angle(j, t)));
        let error = goal.map_or(f64::NAN, |g| position - g);
        let tolerance = self.tick_rad(j).unwrap_or(0.0);
        if let Some(cause) = self.arm_abort_cause(now) {
            return Progress::ended(MotionResult::Aborted, cause, position, error, tolerance);
        }
        let stall = Duration::from_millis(self.cfg.stall_timeout_ms);
        let flags = self.arm.flags(j, now, stall);
        if !streaming
            && flags.contains(ActuatorFlags::MOVING)
            && let Some(bound) = self.travel_bound(j)
            && let Some((since, _)) = self.arm.target_set[j]
            && now.saturating_duration_since(since) > bound
        {
            return Progress::ended(
                MotionResult::TimedOut,
                Status::Timeout,
                position,
                error,
                tolerance,
            );
        }
        if streaming || flags.contains(ActuatorFlags::MOVING) {
            return Progress::moving(position, error, tolerance);
        }
        let result = if flags.contains(ActuatorFlags::STALLED) {
            MotionResult::Stalled
        } else if error.is_nan() || error.abs() <= tolerance {
            MotionResult::Reached
        } else {
            MotionResult::Stalled
        };
        Progress::ended(result, Status::Ok, position, error, tolerance)
    }

    /// How long joint `j`'s move to its target may take: its ticks to go at the servo's
    /// speed (the last commanded, else the calibration's), twice, plus
    /// `TRAVEL_MARGIN` (two ARMpac cycles and the link's latency, generously).
    pub fn travel_bound(&self, j: usize) -> Option<Duration> {
        let (_, ticks) = self.arm.target_set.get(j).copied().flatten()?;
        let cal = self.cal.as_ref()?;
        let default = cal.joint(ArmJoint::from_index(j).ok()?).ok()?.speed;
        let ms = match self.arm.servo_ms[j] {
            0 => default,
            ms => ms,
        };
        Some(Duration::from_millis(2 * u64::from(ticks) * u64::from(ms.max(1))) + TRAVEL_MARGIN)
    }

    /// How part `part` of an arm actarray motion is doing (joint `part`).
    pub fn arm_progress(&self, part: u32) -> Progress {
        if let Some(p) = self.trajectory_progress(part as usize) {
            return p;
        }
        self.joint_progress(part as usize, false, Instant::now())
    }

    /// How limb joint `part` is doing (every joint moves while a VECMOVE is streamed).
    pub fn limb_progress(&self, part: u32) -> Progress {
        let streaming = self.vecmove.is_some();
        self.joint_progress(part as usize, streaming, Instant::now())
    }

    /// How the arm gripper (joint 5) is doing.
    pub fn armgrip_progress(&self) -> Progress {
        self.joint_progress(ArmJoint::GRIPPER.index(), false, Instant::now())
    }

    /// How the body gripper is doing: moving while its paddles are between their end
    /// switches; reached at either (its position is not measured), except a CLOSE that
    /// stopped with an object between the paddles (the break beams): stalled on it. With
    /// the beams broken the result's cause is [`Status::ObjectPresent`].
    pub fn gripper_progress(&self) -> Progress {
        if !self.link.up {
            return Progress::ended(
                MotionResult::Aborted,
                Status::LinkDown,
                f64::NAN,
                f64::NAN,
                0.0,
            );
        }
        let Some(r) = self
            .sip
            .as_ref()
            .map(|s| s.gripper_reading(self.cfg.gripper_byte))
        else {
            return Progress::UNKNOWN;
        };
        if r.paddles == PaddleState::Moving {
            return Progress::UNKNOWN;
        }
        let object = r.outer_beam || r.inner_beam;
        let end = match (object, self.gripper_cmd) {
            (true, Some(GripperCommand::Close)) => (MotionResult::Stalled, Status::ObjectPresent),
            (true, _) => (MotionResult::Reached, Status::ObjectPresent),
            (false, _) => (MotionResult::Reached, Status::Ok),
        };
        Progress::ended(end.0, end.1, f64::NAN, f64::NAN, 0.0)
    }

    /// How the lift is doing: moving until it reaches its end or its goal.
    pub fn lift_progress(&self) -> Progress {
        if !self.link.up {
            return Progress::ended(
                MotionResult::Aborted,
                Status::LinkDown,
                f64::NAN,
                f64::NAN,
                0.0,
            );
        }
        if self.lift.moving.is_some() {
            Progress::UNKNOWN
        } else {
            Progress::ended(MotionResult::Reached, Status::Ok, f64::NAN, f64::NAN, 0.0)
        }
    }

    /// Each arm joint's speed (rad/s), estimated from the last two ARMpacs (0 for a joint
    /// at rest, and before two have arrived).
    pub fn estimated_speeds(&self) -> [f64; ARM_JOINTS] {
        let mut out = [0.0; ARM_JOINTS];
        let (Some(prev), Some(last)) = (self.arm.prev_packet, self.arm.last_packet) else {
            return out;
        };
        let dt = last.saturating_duration_since(prev).as_secs_f64();
        if dt <= 0.0 {
            return out;
        }
        for (j, o) in out.iter_mut().enumerate() {
            if let (Some(a), Some(b)) = (
                self.tick_angle(j, self.arm.prev_ticks[j]),
                self.tick_angle(j, self.arm.ticks[j]),
            ) {
                *o = (b - a) / dt;
            }
        }
        out
    }
}
