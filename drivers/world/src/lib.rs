#![doc = include_str!("../README.md")]
//! ## The library
//!
//! limber-world: a small world for the simulated robots (simarm, the emulated Pioneer), as
//! Stage was for Player: the floor, blocks the gripper can carry, obstacles, and a
//! simulated planar laser that scans them.
//!
//! * [`World`]: blocks (a centre on the floor and a size) and obstacles (boxes), in the
//!   robot frame (x forward, y left, m), loaded from a small TOML file
//!   ([`World::from_toml`], format below), built from flags, or placed at random from a
//!   seed ([`World::random_block`]).
//! * [`Laser`]: a SICK LMS200-like planar laser ([`LaserConfig::lms200`]: 181 beams over
//!   180°, 8 m, 10 scans a second) at a pose on the robot; [`Laser::scan`] ray-casts the
//!   world into a [`RangerData`](limber_interfaces::ranger::RangerData), with Gaussian noise that can be switched off.
//! * [`Carrier`]: blocks move with the gripper: a block whose centre is within the capture
//!   radius of the tool point when the gripper closes is carried (it follows the tool)
//!   until the gripper opens, where it is put down.
//! * [`WorldDriver`]: serves the laser as `<robot>/ranger/0` and watches the robot's limb
//!   and gripper (as any client does) to carry the blocks.
//!
//! ## The world file
//!
//! ```toml
//! # A block: its centre on the floor (x, y, m, robot frame) and its size (m; default
//! # 0.04). The laser sees it as a circle of radius size / 2 (the paper's "block radius").
//! [[block]]
//! x = 0.38
//! y = 0.10
//! size = 0.04
//!
//! # An obstacle: a box of length (along x) by width (along y), centred at x, y.
//! [[obstacle]]
//! x = 1.2
//! y = 0.0
//! length = 0.2
//! width = 1.0
//! ```
//!
//! Every object is taller than the laser's plane: the laser sees every block and obstacle
//! (a carried block too).

mod carry;
mod driver;
mod laser;

pub use carry::Carrier;
pub use driver::{WorldDriver, WorldDriverError, WorldOptions};
pub use laser::{Laser, LaserConfig, LaserConfigError};

use serde::Deserialize;

/// The default size of a block, m (4 cm: the gripper's stroke is larger).
pub const DEFAULT_BLOCK_SIZE: f64 = 0.04;

/// A block the gripper can carry.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Block {
    /// Centre, x (m, robot frame).
    pub x: f64,
    /// Centre, y (m, robot frame).
    pub y: f64,
    /// Size across (m): the width the fingers close on; the laser sees a circle of
    /// radius `size / 2`.
    #[serde(default = "default_size")]
    pub size: f64,
    /// How high it is lifted above where it rested (m; 0 on the floor).
    #[serde(skip)]
    pub lifted: f64,
}

fn default_size() -> f64 {
    DEFAULT_BLOCK_SIZE
}

impl Block {
    /// A block of the default size resting at `x`, `y`.
    pub fn at(x: f64, y: f64) -> Self {
        Block {
            x,
            y,
            size: DEFAULT_BLOCK_SIZE,
            lifted: 0.0,
        }
    }

    /// Its radius as the laser sees it, m.
    pub fn radius(&self) -> f64 {
        self.size / 2.0
    }
}

/// An obstacle: a box, axis-aligned in the robot frame.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Obstacle {
    /// Centre, x (m).
    pub x: f64,
    /// Centre, y (m).
    pub y: f64,
    /// Extent along x (m).
    pub length: f64,
    /// Extent along y (m).
    pub width: f64,
}

/// The world: blocks and obstacles on the floor.
#[derive(Debug, Clone, Default, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct World {
    /// The blocks.
    #[serde(default, rename = "block")]
    pub blocks: Vec<Block>,
    /// The obstacles.
    #[serde(default, rename = "obstacle")]
    pub obstacles: Vec<Obstacle>,
}

/// A world file or its values cannot be used.
#[derive(Debug, thiserror::Error)]
pub enum WorldError {
    /// The file could not be read.
    #[error("cannot read the world file {path}: {source}")]
    Read {
        /// The file.
        path: String,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// The text is not a world (TOML syntax, an unknown key, a missing coordinate).
    #[error("not a world file: {0}")]
    Parse(#[from] toml::de::Error),
    /// A number is not finite, or a size not positive.
    #[error("{what} {index}: coordinates must be finite and sizes > 0")]
    Value {
        /// "block" or "obstacle".
        what: &'static str,
        /// Which one (from 0).
        index: usize,
    },
}

impl World {
    /// Parses a world file's text (format: the crate's documentation).
    pub fn from_toml(text: &str) -> Result<Self, WorldError> {
        let w: World = toml::from_str(text)?;
        w.validate()?;
        Ok(w)
    }

    /// Reads and parses a world file.
    pub fn load(path: &std::path::Path) -> Result<Self, WorldError> {
        let text = std::fs::read_to_string(path).map_err(|source| WorldError::Read {
            path: path.display().to_string(),
            source,
        })?;
        World::from_toml(&text)
    }

    /// Checks every coordinate and size.
    pub fn validate(&self) -> Result<(), WorldError> {
        let ok = |v: &[f64], sizes: &[f64]| {
            v.iter().all(|x| x.is_finite()) && sizes.iter().all(|s| s.is_finite() && *s > 0.0)
        };
        for (index, b) in self.blocks.iter().enumerate() {
            if !ok(&[b.x, b.y, b.lifted], &[b.size]) {
                return Err(WorldError::Value {
                    what: "block",
                    index,
                });
            }
        }
        for (index, o) in self.obstacles.iter().enumerate() {
            if !ok(&[o.x, o.y], &[o.length, o.width]) {
                return Err(WorldError::Value {
                    what: "obstacle",
                    index,
                });
            }
        }
        Ok(())
    }

    /// A block of the default size at a random place of the rectangle `x` by `y` (m),
    /// drawn from `seed` (the same seed, the same place).
    pub fn random_block(seed: u64, x: [f64; 2], y: [f64; 2]) -> Block {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::SmallRng::seed_from_u64(seed);
        let mut draw = |r: [f64; 2]| {
            if r[1] > r[0] {
                rng.random_range(r[0]..r[1])
            } else {
                r[0]
            }
        };
        Block::at(draw(x), draw(y))
    }
}
