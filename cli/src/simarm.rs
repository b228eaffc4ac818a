//! `limber simarm`: the simulated arm as a command.

use std::path::PathBuf;
use std::time::Duration;

use clap::{Args, ValueEnum};
use limber_kinematics::chain::Chain;
use limber_services::event_loop::LoopExit;
use limber_services::{Context, HostError, Role};
use limber_simarm::{SimArm, SimArmError, SimArmOptions, SimObject};

use crate::out::noteln;
use crate::{CliError, exit};

/// A built-in chain.
#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
pub enum Builtin {
    /// The 6-joint UR5-like arm (`drivers/kinematics/chains/arm6.toml`).
    #[value(name = "6dof")]
    Arm6,
    /// The 7-joint Panda-like arm (`drivers/kinematics/chains/arm7.toml`).
    #[value(name = "7dof")]
    Arm7,
}

/// Arguments of `limber simarm`.
#[derive(Debug, Clone, Args)]
pub struct SimArmArgs {
    /// No floor: the arm may reach below its base, as one mounted at a table's edge (the
    /// world's obstacles still stop it). By default the limb and the joints stop at the
    /// floor (z = 0), with the limb state COLLISION.
    #[arg(long)]
    pub no_floor: bool,
    /// Chain file (TOML, see `drivers/kinematics/chains/`); default: the built-in 6-joint arm.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["builtin", "chain_7dof"])]
    pub chain: Option<PathBuf>,
    /// A built-in chain instead of a file.
    #[arg(long, value_enum, conflicts_with = "chain_7dof")]
    pub builtin: Option<Builtin>,
    /// Shorthand for `--builtin 7dof`.
    #[arg(long)]
    pub chain_7dof: bool,
    /// A URDF file: its chain from the root link to the first branch or the end (revolute,
    /// continuous, prismatic and fixed joints, their limits; record/README.md).
    #[arg(long, value_name = "FILE", conflicts_with_all = ["chain", "builtin", "chain_7dof"])]
    pub urdf: Option<PathBuf>,
    /// Robot name in the device names.
    #[arg(long, default_value = "simarm")]
    pub robot: String,
    /// Simulation and publishing period, ms (1 to 1000).
    #[arg(long, default_value_t = 10, value_parser = clap::value_parser!(u64).range(1..=1000))]
    pub tick_ms: u64,
    /// Simulated seconds per real second (2.0 = twice as fast).
    #[arg(long, default_value_t = 1.0)]
    pub time_scale: f64,
    /// An object to grasp: x,y,z of its centre (m, robot frame) and its width (m),
    /// e.g. `--object 0.45,0.1,0.1,0.04`.
    #[arg(long, value_name = "X,Y,Z,WIDTH", value_parser = parse_object)]
    pub object: Option<SimObject>,
    /// How many objects the gripper can store (STORE swallows the object between the
    /// fingers, RETRIEVE gives it back); 0, the default: it cannot, both unsupported.
    #[arg(long, value_name = "N", default_value_t = 0,
          value_parser = clap::value_parser!(u32).range(0..=i64::from(limber_simarm::MAX_STORE_CAPACITY)))]
    pub store_capacity: u32,
    /// The chain's joints have no brakes (BRAKES unsupported, `has_brakes` 0).
    #[arg(long)]
    pub no_brakes: bool,
    /// Clients each device admits at once; a few more slots are kept for priority clients
    /// (LIMBER_PRIORITY=1, --priority).
    #[arg(long, value_name = "N", default_value_t = limber_services::qos::DEFAULT_MAX_CLIENTS,
          value_parser = parse_max_clients)]
    pub max_clients: usize,
    /// The world the laser scans and the gripper picks blocks from.
    #[command(flatten)]
    pub world: crate::world::WorldArgs,
}

/// `--max-clients`: 1 to `qos::MAX_CLIENTS_LIMIT`.
pub(crate) fn parse_max_clients(s: &str) -> Result<usize, String> {
    let n: usize = s.parse().map_err(|e| format!("{s:?}: {e}"))?;
    limber_services::qos::Capacity::new(n)
        .map(|c| c.max_clients())
        .map_err(|e| e.to_string())
}

impl SimArmArgs {
    /// The chain the arguments select.
    pub fn chain(&self) -> Result<Chain, SimArmError> {
        Ok(match (&self.chain, self.builtin, self.chain_7dof) {
            (Some(p), _, _) => Chain::from_file(p)?,
            (None, Some(Builtin::Arm7), _) | (None, None, true) => Chain::default_7dof(),
            _ => Chain::default_6dof(),
        })
    }

    /// The options the arguments select.
    pub fn options(&self) -> SimArmOptions {
        SimArmOptions {
            robot: self.robot.clone(),
            tick: Duration::from_millis(self.tick_ms),
            time_scale: self.time_scale,
            object: self.object,
            store_capacity: self.store_capacity,
            brakes: !self.no_brakes,
            ..SimArmOptions::default()
        }
    }
}

/// Parses `x,y,z,width` (metres) into a block captured within 2 cm.
fn parse_object(s: &str) -> Result<SimObject, String> {
    let mut v = [0.0; 4];
    let mut n = 0;
    for part in s.split(',') {
        if n == 4 {
            return Err("expected 4 numbers: x,y,z,width".into());
        }
        v[n] = part
            .trim()
            .parse::<f64>()
            .map_err(|e| format!("{part:?}: {e}"))?;
        n += 1;
    }
    if n != 4 {
        return Err("expected 4 numbers: x,y,z,width".into());
    }
    if !(v.iter().all(|x| x.is_finite()) && v[3] > 0.0) {
        return Err("values must be finite and the width > 0".into());
    }
    Ok(SimObject::block([v[0], v[1], v[2]], v[3]))
}

/// Runs `limber simarm` until a termination signal ([`limber_services::signals`]): joins
/// the domain of `LIMBER_DOMAIN`, prints `serving <robot>/actarray/0, <robot>/limb/0,
/// <robot>/gripper/0, <robot>/ranger/0 (laser; ...); ready` and serves, with the world
/// (the laser, the blocks) on a thread.
pub fn run(args: SimArmArgs) -> Result<(), CliError> {
    let fail = |e: SimArmError| CliError::new(exit::FAILURE, e.to_string());
    let chain = match &args.urdf {
        Some(p) => limber_record::urdf_in::chain_from_urdf_file(p)
            .map_err(|e| CliError::new(exit::USAGE, format!("{}: {e}", p.display())))?,
        None => args
            .chain()
            .map_err(|e| CliError::new(exit::USAGE, e.to_string()))?,
    };
    let mut options = args.options();
    let world = args.world.world()?;
    args.world.laser()?;
    // The first block is the object the simulated fingers close on (and the beams see),
    // its grasp point at the paper's HandleHeight, unless --object names another.
    if options.object.is_none()
        && let Some(b) = world.blocks.first()
    {
        options.object = Some(SimObject::block(
            [b.x, b.y, crate::world::HANDLE_HEIGHT],
            b.size,
        ));
    }
    options.obstacles = crate::world::simarm_obstacles(&world);
    if args.no_floor {
        options.obstacles.floor = None;
    }
    let domain = crate::domain()?;
    let ctx = Context::new(&domain, Role::Driver, "simarm").map_err(|e| {
        CliError::new(
            exit::FAILURE,
            format!("cannot join domain {}: {e}", domain.name()),
        )
    })?;
    match limber_services::qos::Capacity::new(args.max_clients) {
        Ok(c) => ctx.set_capacity(c),
        Err(e) => return Err(CliError::new(exit::USAGE, e.to_string())),
    }
    let robot = options.robot.clone();
    let mut arm = SimArm::new(&ctx, chain, options).map_err(|e| match e {
        // Bad option values (time scale, object, robot name) are usage errors.
        SimArmError::Options(_) | SimArmError::Chain(_) | SimArmError::Host(HostError::Name(_)) => {
            CliError::new(exit::USAGE, e.to_string())
        }
        // Another driver holds the robot name (a second simarm, or another driver).
        SimArmError::Host(HostError::AlreadyServed { .. } | HostError::Incompatible { .. }) => {
            CliError::new(
                exit::FAILURE,
                format!(
                    "robot {robot} is already served in domain {} by another driver ({e}); \
                     stop it or choose another name with --robot",
                    domain.name()
                ),
            )
        }
        e => fail(e),
    })?;
    eprintln!(
        "limber simarm: chain {:?}, {} joints + gripper, time scale {}; domain {}",
        arm.model().chain().name(),
        arm.model().chain().dof(),
        args.time_scale,
        domain.name()
    );
    let blocks = crate::world::describe(&world.blocks);
    let _world = crate::world::RunningWorld::start(
        &domain,
        &robot,
        &format!("{robot}/limb/0"),
        &format!("{robot}/gripper/0"),
        world,
        args.world.laser()?,
    )?;
    noteln!(
        "serving {robot}/actarray/0, {robot}/limb/0, {robot}/gripper/0, {robot}/ranger/0 (laser; {blocks}); ready"
    );
    let ended = arm.run(|| false).map_err(fail)?;
    if ended == LoopExit::Signal {
        eprintln!("limber simarm: stopped");
    }
    Ok(())
}
