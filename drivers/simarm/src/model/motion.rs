//! One actuator's motion: toward a target at a speed, one time step at a time; with an
//! acceleration limit the speed ramps up and down (a trapezoidal profile).

/// A target is reached when within this distance (rad or m).
const REACHED: f64 = 1e-12;

/// One actuator's motion.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Motion {
    /// Current position, rad or m.
    pub(super) pos: f64,
    /// Where it is going (equal to `pos` when idle).
    pub(super) target: f64,
    /// Speed of the current move (> 0 while moving), rad/s or m/s.
    pub(super) speed: f64,
    /// Signed velocity during the last step, for the state.
    pub(super) velocity: f64,
    /// Moving toward `target`.
    pub(super) moving: bool,
    /// Blocked (the gripper squeezing an object).
    pub(super) stalled: bool,
    /// Acceleration limit of the current move, rad/s² or m/s² (infinite: none, the
    /// speed is reached at once).
    pub(super) accel: f64,
    /// Magnitude of the acceleration during the last step (0 without a limit).
    pub(super) accel_now: f64,
    /// Current mode: the commanded current, A (`None`: position or speed mode).
    pub(super) current: Option<f64>,
    /// The goal of the last motion commanded (kept by a stop: the error of a motion cut
    /// short is against it).
    pub(super) goal: f64,
}

impl Motion {
    /// At rest at `pos`.
    pub(super) fn at(pos: f64) -> Self {
        Motion {
            pos,
            target: pos,
            speed: 0.0,
            velocity: 0.0,
            moving: false,
            stalled: false,
            accel: f64::INFINITY,
            accel_now: 0.0,
            current: None,
            goal: pos,
        }
    }

    /// Starts toward `target` at `speed` (at once there when `speed` is 0 or it is
    /// already there), without an acceleration limit; ends a current mode.
    pub(super) fn go(&mut self, target: f64, speed: f64) {
        self.go_accel(target, speed, f64::INFINITY);
    }

    /// Starts toward `target` at `speed`, the speed changing by at most `accel` per
    /// second (infinite: at once); ends a current mode.
    pub(super) fn go_accel(&mut self, target: f64, speed: f64, accel: f64) {
        self.current = None;
        self.drive(target, speed, accel);
    }

    /// As [`go_accel`](Self::go_accel), keeping the current mode (the motor model
    /// re-aims a current-driven joint every step).
    pub(super) fn drive(&mut self, target: f64, speed: f64, accel: f64) {
        self.target = target;
        self.goal = target;
        self.speed = speed;
        self.accel = if accel > 0.0 { accel } else { f64::INFINITY };
        self.stalled = false;
        self.moving = (target - self.pos).abs() > REACHED && speed > 0.0;
        if !self.moving {
            self.pos = target;
            self.velocity = 0.0;
            self.accel_now = 0.0;
        }
    }

    /// Stops where it is (an acceleration limit does not apply to a stop); ends a
    /// current mode.
    pub(super) fn stop(&mut self) {
        self.target = self.pos;
        self.moving = false;
        self.velocity = 0.0;
        self.accel_now = 0.0;
        self.current = None;
    }

    /// Advances by `dt` seconds.
    pub(super) fn step(&mut self, dt: f64) {
        if !self.moving {
            self.velocity = 0.0;
            self.accel_now = 0.0;
            return;
        }
        if self.accel.is_finite() {
            self.step_limited(dt);
            return;
        }
        let d = self.target - self.pos;
        let max = self.speed * dt;
        if d.abs() <= max + 1e-12 {
            self.pos = self.target;
            self.moving = false;
            self.velocity = if dt > 0.0 { d / dt } else { 0.0 };
        } else {
            self.pos += max.copysign(d);
            self.velocity = self.speed.copysign(d);
        }
    }

    /// One step of the trapezoidal profile. The speed toward the target changes by at
    /// most `a dt` per step, toward the move's speed but never above the largest speed
    /// from which the joint still stops at the target at `a`, counted from where this
    /// step ends (`v² <= 2 a d'`): it ramps up, cruises, and brakes at `a` to rest on the
    /// target, the acceleration never above the limit. The position follows the mean
    /// velocity of the step.
    fn step_limited(&mut self, dt: f64) {
        let a = self.accel;
        let d = self.target - self.pos;
        let dir = d.signum();
        let left = d.abs();
        // Speed toward the target (negative: moving away from it).
        let v = self.velocity * dir;
        // v_new² <= 2a (left - (v + v_new) dt / 2), solved for v_new.
        let room = (left - 0.5 * v * dt).max(0.0);
        let stoppable = 0.5 * (-a * dt + (a * a * dt * dt + 8.0 * a * room).sqrt());
        let wanted = self.speed.min(stoppable.max(0.0));
        let dv = (wanted - v).clamp(-a * dt, a * dt);
        let v_new = v + dv;
        self.accel_now = if dt > 0.0 { dv.abs() / dt } else { 0.0 };
        let ds = 0.5 * (v + v_new) * dt;
        if (v >= 0.0 && v_new <= 0.0) || ds >= left {
            // At rest on the target within this step.
            self.pos = self.target;
            self.moving = false;
            self.velocity = 0.0;
            return;
        }
        self.pos += ds * dir;
        self.velocity = v_new * dir;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_limited_move_ramps_up_cruises_and_ramps_down() {
        // 1 rad at 1 rad/s with 2 rad/s²: 0.5 s up (0.25 rad), 0.5 rad cruising
        // (0.5 s), 0.5 s down.
        let mut m = Motion::at(0.0);
        m.go_accel(1.0, 1.0, 2.0);
        let dt = 0.001;
        let mut t = 0.0;
        let mut peak: f64 = 0.0;
        while m.moving && t < 5.0 {
            m.step(dt);
            t += dt;
            peak = peak.max(m.velocity.abs());
            if (t - 0.25).abs() < dt / 2.0 {
                // Ramping up: s = a t² / 2.
                assert!((m.pos - 0.0625).abs() < 2e-3, "{}", m.pos);
                assert!((m.velocity - 0.5).abs() < 2e-3, "{}", m.velocity);
                assert!((m.accel_now - 2.0).abs() < 1e-9);
            }
            if (t - 0.75).abs() < dt / 2.0 {
                assert!((m.velocity - 1.0).abs() < 1e-9, "cruising: {}", m.velocity);
            }
        }
        assert_eq!(m.pos, 1.0);
        assert!((peak - 1.0).abs() < 1e-9);
        assert!((t - 1.5).abs() < 0.005, "arrived after {t} s");
    }

    #[test]
    fn coarse_steps_never_exceed_the_limit_and_arrive() {
        // 1 rad at 0.5 rad/s² in 0.1 s steps (a 10 ms tick at 10x time): a triangle of
        // 2 * sqrt(2) s, the speed never above the limit's.
        for (dt, dist) in [(0.1, 1.0), (0.1, -0.3), (0.05, 0.01), (0.001, 2.0)] {
            let mut m = Motion::at(0.0);
            m.go_accel(dist, 3.15, 0.5);
            let mut t = 0.0;
            let mut prev = 0.0f64;
            while m.moving && t < 100.0 {
                m.step(dt);
                t += dt;
                assert!(m.accel_now <= 0.5 + 1e-9, "{dt} {dist}: {}", m.accel_now);
                assert!((m.velocity - prev).abs() <= 0.5 * dt + 1e-9);
                prev = m.velocity;
            }
            assert_eq!(m.pos, dist);
            let ideal = 2.0 * (dist.abs() / 0.5f64).sqrt();
            assert!(
                t >= ideal - 1e-9 && t <= ideal + 2.0 * dt + 1e-9,
                "{dt} {dist}: {t} s"
            );
        }
    }

    #[test]
    fn go_and_stop_end_a_current_mode() {
        let mut m = Motion::at(0.0);
        m.current = Some(1.0);
        m.drive(1.0, 0.5, f64::INFINITY);
        assert_eq!(m.current, Some(1.0));
        m.go(0.5, 0.5);
        assert_eq!(m.current, None);
        m.current = Some(1.0);
        m.stop();
        assert_eq!(m.current, None);
    }
}
