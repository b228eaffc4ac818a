//! VECMOVE: a straight line of the end effector, planned as joint waypoints whose
//! linear interpolation stays within a bound of the line. The planner is an iterator
//! ([`VecMove`]), so nothing is allocated and a whole move can be validated by running
//! a clone of it before executing it.

use nalgebra::Vector3;

use super::{PioneerGeometry, PioneerIkError, PioneerIkOptions, Theta};
use crate::pose::{all_finite, unit_direction};

impl PioneerGeometry {
    /// VECMOVE: plans a straight line from the current end-effector position along
    /// `direction` (arm-base frame, any non-zero length) for `length` metres, holding the
    /// current approach vector. The 5-DOF arm cannot hold a full orientation along an
    /// arbitrary line (the normal must stay perpendicular to the forearm, which turns
    /// with θ1), so the wrist roll follows the arm, continuously. The returned iterator
    /// yields joint waypoints such that linear joint interpolation between consecutive
    /// waypoints stays within [`VecMoveOptions::max_deviation`] of the line (checked at
    /// [`VecMoveOptions::samples`] interior points per segment). Validate a whole move
    /// before executing it by running a clone of the iterator.
    pub fn vecmove(
        &self,
        current: &Theta,
        direction: &Vector3<f64>,
        length: f64,
        options: &VecMoveOptions,
    ) -> Result<VecMove<'_>, VecMoveError> {
        self.validate().map_err(PioneerIkError::from)?;
        options.ik.check()?;
        if !(current.iter().all(|t| t.is_finite()) && all_finite(direction) && length.is_finite()) {
            return Err(VecMoveError::NonFinite);
        }
        let ok = |v: f64| v.is_finite() && v > 0.0;
        if !(ok(options.max_deviation)
            && ok(options.min_step)
            && ok(options.max_step)
            && options.min_step <= options.max_step
            && options.samples >= 1
            && options.samples <= 64)
            || length < 0.0
        {
            return Err(VecMoveError::InvalidOptions);
        }
        // Scaled by the largest component first: (1e308, 1e308, 0) is a direction too
        // (its norm overflows).
        let direction = unit_direction(direction).ok_or(VecMoveError::ZeroDirection)?;
        let start = self.fk_raw(current);
        Ok(VecMove {
            geometry: self,
            start: start.position,
            direction,
            approach: start.approach(),
            length,
            travelled: 0.0,
            theta: *current,
            options: *options,
            finished: length == 0.0,
        })
    }
}

/// Options of [`PioneerGeometry::vecmove`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VecMoveOptions {
    /// Largest accepted distance of the interpolated end effector from the line, m
    /// (default 1 mm).
    pub max_deviation: f64,
    /// Shortest segment the planner will subdivide to, m (default 0.1 mm); if the
    /// deviation cannot be met with it, the move fails.
    pub min_step: f64,
    /// Longest segment, m (default 2 cm): keeps the sampled deviation check meaningful.
    pub max_step: f64,
    /// Interior points per segment at which the deviation is checked (1..=64, default 4).
    pub samples: usize,
    /// IK options for every waypoint.
    pub ik: PioneerIkOptions,
}

impl Default for VecMoveOptions {
    fn default() -> Self {
        Self {
            max_deviation: 1e-3,
            min_step: 1e-4,
            max_step: 0.02,
            samples: 4,
            ik: PioneerIkOptions::default(),
        }
    }
}

/// Why a VECMOVE could not be planned or continued.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum VecMoveError {
    /// NaN or infinite input.
    #[error("input contains NaN or an infinite value")]
    NonFinite,
    /// The direction vector has zero length.
    #[error("direction has zero length")]
    ZeroDirection,
    /// Negative length, or invalid deviation/step/sample options.
    #[error("invalid VECMOVE options or length")]
    InvalidOptions,
    /// Geometry or IK options invalid.
    #[error(transparent)]
    Ik(#[from] PioneerIkError),
    /// The line leaves the reachable set at `distance` m from the start.
    #[error("line unreachable at {distance} m: {cause}")]
    Unreachable {
        /// Distance along the line, m.
        distance: f64,
        /// The IK failure there.
        cause: PioneerIkError,
    },
    /// Even the shortest segment deviates more than allowed (a singularity or a branch
    /// change) at `distance` m from the start.
    #[error("deviation {deviation} m exceeds the bound at {distance} m")]
    DeviationExceeded {
        /// Distance along the line, m.
        distance: f64,
        /// Deviation of the shortest segment tried, m.
        deviation: f64,
    },
}

/// One VECMOVE waypoint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Waypoint {
    /// Joint angles θ1..θ5 to command.
    pub theta: Theta,
    /// Distance along the line from the start, m.
    pub distance: f64,
    /// Largest sampled deviation from the line of the segment ending here, m.
    pub deviation: f64,
}

/// The VECMOVE planner: an iterator of waypoints (see [`PioneerGeometry::vecmove`]).
/// It ends after the waypoint at the full length, or after the first error.
#[derive(Clone, Debug)]
pub struct VecMove<'a> {
    geometry: &'a PioneerGeometry,
    start: Vector3<f64>,
    direction: Vector3<f64>,
    approach: Vector3<f64>,
    length: f64,
    travelled: f64,
    theta: Theta,
    options: VecMoveOptions,
    finished: bool,
}

impl VecMove<'_> {
    /// The line's start point (arm-base frame).
    pub fn start(&self) -> Vector3<f64> {
        self.start
    }

    /// The approach vector held along the line.
    pub fn approach(&self) -> Vector3<f64> {
        self.approach
    }

    fn deviation(&self, from: &Theta, to: &Theta) -> f64 {
        let m = self.options.samples;
        let mut worst: f64 = 0.0;
        for k in 1..=m {
            let t = k as f64 / (m + 1) as f64;
            let q: Theta = std::array::from_fn(|i| from[i] + (to[i] - from[i]) * t);
            let p = self.geometry.fk_raw(&q).position;
            let s = (p - self.start)
                .dot(&self.direction)
                .clamp(0.0, self.length);
            let d = (p - (self.start + self.direction * s)).norm();
            worst = worst.max(if d.is_finite() { d } else { f64::INFINITY });
        }
        worst
    }
}

impl Iterator for VecMove<'_> {
    type Item = Result<Waypoint, VecMoveError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.finished {
            return None;
        }
        let remaining = self.length - self.travelled;
        let mut step = remaining.min(self.options.max_step);
        loop {
            let last = step >= remaining;
            let s = if last {
                self.length
            } else {
                self.travelled + step
            };
            let p = self.start + self.direction * s;
            let can_halve = step * 0.5 >= self.options.min_step;
            match self.geometry.solve_position_approach(
                &p,
                &self.approach,
                &self.theta,
                &self.options.ik,
            ) {
                Err(cause) => {
                    if can_halve {
                        step *= 0.5;
                        continue;
                    }
                    self.finished = true;
                    return Some(Err(VecMoveError::Unreachable { distance: s, cause }));
                }
                Ok(c) => {
                    let deviation = self.deviation(&self.theta, &c.theta);
                    if deviation <= self.options.max_deviation {
                        self.theta = c.theta;
                        self.travelled = s;
                        self.finished = last;
                        return Some(Ok(Waypoint {
                            theta: c.theta,
                            distance: s,
                            deviation,
                        }));
                    }
                    if can_halve {
                        step *= 0.5;
                        continue;
                    }
                    self.finished = true;
                    return Some(Err(VecMoveError::DeviationExceeded {
                        distance: s,
                        deviation,
                    }));
                }
            }
        }
    }
}
