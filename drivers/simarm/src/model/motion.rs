//! One actuator's motion: toward a target at a speed, one time step at a time.

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
        }
    }

    /// Starts toward `target` at `speed` (at once there when `speed` is 0 or it is
    /// already there).
    pub(super) fn go(&mut self, target: f64, speed: f64) {
        self.target = target;
        self.speed = speed;
        self.stalled = false;
        self.moving = (target - self.pos).abs() > REACHED && speed > 0.0;
        if !self.moving {
            self.pos = target;
            self.velocity = 0.0;
        }
    }

    /// Stops where it is.
    pub(super) fn stop(&mut self) {
        self.target = self.pos;
        self.moving = false;
        self.velocity = 0.0;
    }

    /// Advances by `dt` seconds.
    pub(super) fn step(&mut self, dt: f64) {
        if !self.moving {
            self.velocity = 0.0;
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
}
