//! The simulated planar laser: beams ray-cast against the world's blocks (circles) and
//! obstacles (boxes) in the laser's plane, with Gaussian range noise.

use limber_interfaces::prelude::*;
use rand::{Rng, SeedableRng};

use crate::World;

/// How the laser is mounted and what it measures.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LaserConfig {
    /// Position on the robot (x, y, z, m, robot frame).
    pub position: [f64; 3],
    /// Heading of bearing 0 on the robot (rad, counter-clockwise from x).
    pub yaw: f64,
    /// Bearing of the first beam, rad.
    pub min_angle: f64,
    /// Angle between two beams, rad.
    pub angular_res: f64,
    /// Number of beams (at most [`MAX_RANGES`]).
    pub beams: usize,
    /// Shortest range measured, m.
    pub min_range: f64,
    /// Longest range measured, m: a beam that hits nothing reads this.
    pub max_range: f64,
    /// Range resolution, m (each range is rounded to it).
    pub range_res: f64,
    /// Scans per second.
    pub frequency: f64,
    /// Standard deviation of the Gaussian noise added to each range, m (0: none).
    pub noise: f64,
    /// Size of the sensor, m (width, length, height).
    pub size: [f64; 3],
}

impl LaserConfig {
    /// A SICK LMS200 at the front of a Pioneer 3's body, as the paper's robot had: 181
    /// beams over 180° (1° apart, bearing 0 straight ahead), 8 m in millimetre mode (1 mm
    /// resolution), 10 scans a second, mounted at (0.16, 0, 0.20) m facing forward, with
    /// 2 mm of range noise (standard deviation).
    pub fn lms200() -> Self {
        LaserConfig {
            position: [0.16, 0.0, 0.20],
            yaw: 0.0,
            min_angle: -core::f64::consts::FRAC_PI_2,
            angular_res: 1f64.to_radians(),
            beams: 181,
            min_range: 0.0,
            max_range: 8.0,
            range_res: 0.001,
            frequency: 10.0,
            noise: 0.002,
            size: [0.155, 0.156, 0.185],
        }
    }

    /// The same laser at half-degree resolution (361 beams over 180°).
    pub fn lms200_half_degree() -> Self {
        LaserConfig {
            angular_res: 0.5f64.to_radians(),
            beams: 361,
            ..LaserConfig::lms200()
        }
    }

    /// Bearing of the last beam, rad.
    pub fn max_angle(&self) -> f64 {
        self.min_angle + self.angular_res * (self.beams.saturating_sub(1)) as f64
    }

    /// Checks the values.
    pub fn validate(&self) -> Result<(), LaserConfigError> {
        let finite = self
            .position
            .iter()
            .chain(self.size.iter())
            .all(|v| v.is_finite())
            && [self.yaw, self.min_angle, self.angular_res, self.min_range]
                .iter()
                .all(|v| v.is_finite());
        if !finite {
            return Err(LaserConfigError::NotFinite);
        }
        if self.beams == 0 || self.beams > MAX_RANGES {
            return Err(LaserConfigError::Beams(self.beams));
        }
        if !(self.max_range.is_finite() && self.max_range > self.min_range && self.min_range >= 0.0)
        {
            return Err(LaserConfigError::Range);
        }
        if !(self.range_res.is_finite() && self.range_res > 0.0) {
            return Err(LaserConfigError::Range);
        }
        if !(self.frequency.is_finite() && self.frequency > 0.0 && self.frequency <= 100.0) {
            return Err(LaserConfigError::Frequency);
        }
        if !(self.noise.is_finite() && self.noise >= 0.0) {
            return Err(LaserConfigError::Noise);
        }
        Ok(())
    }

    /// The geometry a GET_GEOM answers.
    pub fn geometry(&self) -> RangerGeom {
        let [x, y, z] = self.position;
        RangerGeom {
            pose: Pose3 {
                position: Vec3::new(x, y, z),
                orientation: Orientation3 {
                    roll: 0.0,
                    pitch: 0.0,
                    yaw: self.yaw,
                },
            },
            size: Bbox3 {
                width: self.size[0],
                length: self.size[1],
                height: self.size[2],
            },
            min_angle: self.min_angle,
            max_angle: self.max_angle(),
            angular_res: self.angular_res,
            min_range: self.min_range,
            max_range: self.max_range,
            range_res: self.range_res,
            frequency: self.frequency,
            ranges_count: self.beams as u32,
            _pad: 0,
        }
    }
}

/// A laser configuration that cannot be used.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum LaserConfigError {
    /// A pose, angle or size is not finite.
    #[error("the laser's pose, angles and size must be finite")]
    NotFinite,
    /// The number of beams is 0 or above the ranger's capacity.
    #[error("{0} beams: a scan holds 1 to 361")]
    Beams(usize),
    /// The range limits or resolution are not positive and ordered.
    #[error("the laser's ranges must be 0 <= min < max (finite) with a resolution > 0")]
    Range,
    /// The frequency is not in (0, 100] Hz.
    #[error("the laser's frequency must be in (0, 100] Hz")]
    Frequency,
    /// The noise is negative or not finite.
    #[error("the laser's noise must be finite and >= 0")]
    Noise,
}

/// The simulated laser: its configuration and the random source of its noise.
#[derive(Debug)]
pub struct Laser {
    config: LaserConfig,
    rng: rand::rngs::SmallRng,
}

impl Laser {
    /// A laser with `config`, its noise drawn from `seed`.
    pub fn new(config: LaserConfig, seed: u64) -> Result<Self, LaserConfigError> {
        config.validate()?;
        Ok(Laser {
            config,
            rng: rand::rngs::SmallRng::seed_from_u64(seed),
        })
    }

    /// Its configuration.
    pub fn config(&self) -> &LaserConfig {
        &self.config
    }

    /// Scans `world` into `out` (the header is left to the publisher): every beam's
    /// range to the nearest block or obstacle (or the maximum range), plus noise,
    /// rounded to the range resolution and kept within the sensor's limits.
    pub fn scan(&mut self, world: &World, out: &mut RangerData) {
        let c = self.config;
        out.min_angle = c.min_angle;
        out.max_angle = c.max_angle();
        out.angular_res = c.angular_res;
        out.min_range = c.min_range;
        out.max_range = c.max_range;
        out.range_res = c.range_res;
        out.frequency = c.frequency;
        out.ranges_count = c.beams as u32;
        out.intensities_count = 0;
        let origin = [c.position[0], c.position[1]];
        for i in 0..c.beams {
            let heading = c.yaw + c.min_angle + c.angular_res * i as f64;
            let dir = [heading.cos(), heading.sin()];
            let hit = cast(world, origin, dir).unwrap_or(c.max_range);
            let mut r = hit;
            if c.noise > 0.0 && hit < c.max_range {
                r += c.noise * gaussian(&mut self.rng);
            }
            r = (r / c.range_res).round() * c.range_res;
            out.ranges[i] = r.clamp(c.min_range, c.max_range);
        }
        out.ranges[c.beams..].fill(0.0);
        out.intensities.fill(0.0);
    }
}

/// The distance along the unit vector `dir` from `origin` to the nearest block or
/// obstacle in front, if any.
pub(crate) fn cast(world: &World, origin: [f64; 2], dir: [f64; 2]) -> Option<f64> {
    let blocks = world
        .blocks
        .iter()
        .filter_map(|b| circle(origin, dir, [b.x, b.y], b.radius()));
    let boxes = world.obstacles.iter().filter_map(|o| {
        slab(
            origin,
            dir,
            [o.x - o.length / 2.0, o.y - o.width / 2.0],
            [o.x + o.length / 2.0, o.y + o.width / 2.0],
        )
    });
    blocks.chain(boxes).min_by(f64::total_cmp)
}

/// Where a ray first meets a circle (`None`: it misses, or starts inside).
fn circle(o: [f64; 2], d: [f64; 2], c: [f64; 2], r: f64) -> Option<f64> {
    let (fx, fy) = (o[0] - c[0], o[1] - c[1]);
    let b = fx * d[0] + fy * d[1];
    let cc = fx * fx + fy * fy - r * r;
    if cc <= 0.0 {
        return None;
    }
    let disc = b * b - cc;
    if disc < 0.0 {
        return None;
    }
    let t = -b - disc.sqrt();
    (t >= 0.0).then_some(t)
}

/// Where a ray first meets an axis-aligned box (`None`: it misses, or starts inside).
fn slab(o: [f64; 2], d: [f64; 2], lo: [f64; 2], hi: [f64; 2]) -> Option<f64> {
    let (mut t0, mut t1) = (f64::NEG_INFINITY, f64::INFINITY);
    for k in 0..2 {
        if d[k].abs() < 1e-12 {
            if o[k] < lo[k] || o[k] > hi[k] {
                return None;
            }
        } else {
            let (a, b) = ((lo[k] - o[k]) / d[k], (hi[k] - o[k]) / d[k]);
            t0 = t0.max(a.min(b));
            t1 = t1.min(a.max(b));
        }
    }
    (t0 <= t1 && t0 > 0.0).then_some(t0)
}

/// A standard normal sample (Box-Muller).
fn gaussian(rng: &mut rand::rngs::SmallRng) -> f64 {
    let u1: f64 = rng.random_range(f64::EPSILON..1.0);
    let u2: f64 = rng.random_range(0.0..1.0);
    (-2.0 * u1.ln()).sqrt() * (core::f64::consts::TAU * u2).cos()
}
