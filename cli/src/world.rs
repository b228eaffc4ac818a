//! The simulated world of `limber simarm`, `limber pioneer --emulated` and `limber demo`:
//! its flags, and [`RunningWorld`], the world's driver (the laser as `<robot>/ranger/0`)
//! on a thread of the robot's process.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError, mpsc};
use std::thread::JoinHandle;
use std::time::Duration;

use clap::Args;
use limber_services::Domain;
use limber_world::{Block, LaserConfig, World, WorldDriver, WorldOptions};

use crate::{CliError, exit};

/// Where a block is placed when no flag says: in front of the robot, within the reach of
/// the Pioneer's arm and simarm's (the paper's Listing 2 finds it with the laser).
pub const DEFAULT_BLOCK: [f64; 2] = [0.38, 0.10];

/// The rectangle `--seed` places a block in (x, then y; m, robot frame): within the reach
/// of both arms, clear of the drop point (0.38, -0.10).
pub const RANDOM_REGION: [[f64; 2]; 2] = [[0.37, 0.42], [0.04, 0.12]];

/// The height of a block's grasp point in the robot frame (m): the paper's
/// `HandleHeight`, where Listing 2 grips it.
pub const HANDLE_HEIGHT: f64 = 0.17;

/// The floor's height in simarm's robot frame (m): its base stands on it.
pub const SIMARM_FLOOR: f64 = 0.0;

/// What simarm's limb stops at (the COLLISION state): the floor, and the world's obstacles
/// (boxes as tall as can be).
pub fn simarm_obstacles(world: &World) -> limber_simarm::Obstacles {
    limber_simarm::Obstacles {
        floor: Some(SIMARM_FLOOR),
        boxes: world
            .obstacles
            .iter()
            .map(|o| limber_simarm::SimObstacle {
                min: [o.x - o.length / 2.0, o.y - o.width / 2.0, f64::NEG_INFINITY],
                max: [o.x + o.length / 2.0, o.y + o.width / 2.0, f64::INFINITY],
            })
            .collect(),
    }
}

/// The world's flags.
#[derive(Debug, Clone, Default, Args)]
pub struct WorldArgs {
    /// The world: a TOML file of blocks and obstacles (format: `drivers/world/README.md`).
    #[arg(long, value_name = "FILE")]
    pub world: Option<PathBuf>,
    /// A block at X Y (m, robot frame; repeat for more). Default, without --world or
    /// --seed: one block at 0.38 0.10.
    #[arg(long, num_args = 2, value_names = ["X", "Y"], allow_negative_numbers = true,
          action = clap::ArgAction::Append)]
    pub block: Vec<f64>,
    /// A block at a random place within reach, drawn from seed N (the same N, the same
    /// place).
    #[arg(long, value_name = "N")]
    pub seed: Option<u64>,
    /// The laser's range noise, standard deviation in m (0 switches it off).
    #[arg(long, value_name = "M", default_value_t = LaserConfig::lms200().noise)]
    pub laser_noise: f64,
}

impl WorldArgs {
    /// The world the flags describe.
    pub fn world(&self) -> Result<World, CliError> {
        let usage = |e: limber_world::WorldError| CliError::new(exit::USAGE, e.to_string());
        let mut w = match &self.world {
            Some(p) => World::load(p).map_err(usage)?,
            None => World::default(),
        };
        w.blocks
            .extend(self.block.chunks(2).map(|c| Block::at(c[0], c[1])));
        if let Some(seed) = self.seed {
            w.blocks.push(World::random_block(
                seed,
                RANDOM_REGION[0],
                RANDOM_REGION[1],
            ));
        }
        if self.world.is_none() && w.blocks.is_empty() {
            w.blocks.push(Block::at(DEFAULT_BLOCK[0], DEFAULT_BLOCK[1]));
        }
        w.validate().map_err(usage)?;
        Ok(w)
    }

    /// The laser the flags describe (a negative or non-finite noise is a usage error).
    pub fn laser(&self) -> Result<LaserConfig, CliError> {
        let c = LaserConfig {
            noise: self.laser_noise,
            ..LaserConfig::lms200()
        };
        c.validate()
            .map_err(|e| CliError::new(exit::USAGE, format!("--laser-noise: {e}")))?;
        Ok(c)
    }

    /// True when a flag describes a world (`--world`, `--block`, `--seed`).
    pub fn given(&self) -> bool {
        self.world.is_some() || !self.block.is_empty() || self.seed.is_some()
    }
}

/// The world's driver on a thread of this process, stopped when dropped.
pub struct RunningWorld {
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
    world: Arc<Mutex<World>>,
}

impl RunningWorld {
    /// Starts `world` for `robot` (the laser as `<robot>/ranger/0`; the blocks carried by
    /// `limb` and `gripper`), and waits until its first scan is published.
    pub fn start(
        domain: &Domain,
        robot: &str,
        limb: &str,
        gripper: &str,
        world: World,
        laser: LaserConfig,
    ) -> Result<Self, CliError> {
        let options = WorldOptions {
            laser,
            ..WorldOptions::new(robot, limb, gripper)
        };
        let stop = Arc::new(AtomicBool::new(false));
        let (tx, rx) = mpsc::channel();
        let (d, s) = (domain.clone(), Arc::clone(&stop));
        let thread = std::thread::Builder::new()
            .name("world".into())
            .spawn(move || {
                let mut driver = match WorldDriver::new(&d, world, options) {
                    Ok(w) => w,
                    Err(e) => {
                        if tx.send(Err(e.to_string())).is_err() {
                            tracing::debug!("nobody waits for the world any more");
                        }
                        return;
                    }
                };
                if tx.send(Ok(driver.world())).is_err() {
                    return;
                }
                if let Err(e) = driver.run(|| s.load(Ordering::Relaxed)) {
                    tracing::error!("the world stopped: {e}");
                }
            })
            .map_err(|e| CliError::new(exit::FAILURE, e.to_string()))?;
        let world = match rx.recv_timeout(Duration::from_secs(30)) {
            Ok(Ok(w)) => w,
            Ok(Err(e)) => {
                return Err(CliError::new(
                    exit::FAILURE,
                    format!("the world did not start: {e}"),
                ));
            }
            Err(_) => {
                return Err(CliError::new(
                    exit::TIMEOUT,
                    "the world did not start within 30 s",
                ));
            }
        };
        Ok(RunningWorld {
            stop,
            thread: Some(thread),
            world,
        })
    }

    /// The blocks where they are now.
    pub fn blocks(&self) -> Vec<Block> {
        self.world
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .blocks
            .clone()
    }
}

impl Drop for RunningWorld {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take()
            && t.join().is_err()
        {
            tracing::error!("the world's thread panicked");
        }
    }
}

/// How the world's blocks read in a "serving" line: `2 blocks at (0.38, 0.10), (0.40, 0.05)`.
pub fn describe(blocks: &[Block]) -> String {
    let at: Vec<String> = blocks
        .iter()
        .map(|b| format!("({:.3}, {:.3})", b.x, b.y))
        .collect();
    match blocks.len() {
        0 => "no block".to_string(),
        1 => format!("1 block at {}", at[0]),
        n => format!("{n} blocks at {}", at.join(", ")),
    }
}
