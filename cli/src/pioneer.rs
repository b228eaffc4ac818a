//! `limber pioneer`: the driver as a command.

use std::path::PathBuf;

use clap::Args;
use limber_emulator::{Emulator, EmulatorConfig};
use limber_p2os::LinkTarget;
use limber_pioneer::{
    ConfigError, DriverError, LoopMode, PioneerConfig, PioneerDriver, RunOptions, StartOptions,
    apply_realtime, check_cpu,
};
use limber_services::{Context, Role};

use crate::out::{noteln, out};
use crate::{CliError, exit};

/// Arguments of `limber pioneer`.
#[derive(Debug, Clone, Args)]
pub struct PioneerArgs {
    /// Configuration file (TOML); see `--print-config` for every key and its default.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// The link: a serial device (/dev/ttyS0), a pty, or tcp://host:port (simulator: 8101).
    #[arg(long)]
    pub port: Option<String>,
    /// Serial baud rate: 9600, 19200, 38400, 57600 or 115200 (default: try 9600, 38400,
    /// 19200, 115200, 57600).
    #[arg(long)]
    pub baud: Option<u32>,
    /// Robot name in the device names (default "pioneer").
    #[arg(long)]
    pub robot: Option<String>,
    /// Start the built-in Pioneer emulator on a pty and drive it.
    #[arg(long)]
    pub emulated: bool,
    /// Busy-poll instead of waiting on events (lowest latency; takes a whole core).
    #[arg(long)]
    pub spin: bool,
    /// Pin the driver thread to this CPU core (one this process may use: refused
    /// otherwise).
    #[arg(long, value_name = "N")]
    pub cpu: Option<usize>,
    /// Real-time: SCHED_FIFO priority 80 and locked memory (needs CAP_SYS_NICE /
    /// CAP_IPC_LOCK; a warning says so when not permitted).
    #[arg(long)]
    pub rt: bool,
    /// Clients each device admits at once (default 64, or max_clients of --config); a few
    /// more slots are kept for priority clients (LIMBER_PRIORITY=1, --priority).
    #[arg(long, value_name = "N")]
    pub max_clients: Option<usize>,
    /// Print the configuration (defaults merged with --config) as TOML and exit.
    #[arg(long)]
    pub print_config: bool,
    /// With --emulated: the world its laser scans and its arm picks blocks from.
    #[command(flatten)]
    pub world: crate::world::WorldArgs,
}

/// `limber pioneer` failed.
#[derive(Debug, thiserror::Error)]
pub enum PioneerCliError {
    /// The configuration is invalid.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// The domain or context could not be set up.
    #[error("{0}")]
    Setup(String),
    /// The emulator could not start.
    #[error("cannot start the emulator: {0}")]
    Emulator(#[from] limber_emulator::EmulatorError),
    /// The driver failed.
    #[error(transparent)]
    Driver(#[from] DriverError),
    /// `--cpu` names a core this process may not use.
    #[error(transparent)]
    Cpu(#[from] limber_pioneer::CpuError),
}

/// The configuration from `--config` and the flags.
pub fn config_from(args: &PioneerArgs) -> Result<PioneerConfig, PioneerCliError> {
    let mut cfg = match &args.config {
        Some(p) => PioneerConfig::from_file(p)?,
        None => PioneerConfig::default(),
    };
    if let Some(p) = &args.port {
        cfg.port = p.clone();
    }
    if let Some(b) = args.baud {
        cfg.baud = Some(b);
    }
    if let Some(r) = &args.robot {
        cfg.robot = r.clone();
    }
    if let Some(n) = args.max_clients {
        cfg.max_clients = n;
    }
    cfg.validate()?;
    Ok(cfg)
}

/// Runs `limber pioneer` until a termination signal ([`limber_services::signals`]: SIGINT,
/// SIGTERM, SIGHUP, SIGQUIT, SIGXCPU, SIGPWR), which stops the arm first.
pub fn run(args: PioneerArgs) -> Result<(), CliError> {
    if !args.emulated && args.world.given() {
        return Err(CliError::new(
            exit::USAGE,
            "--world, --block and --seed describe the emulated robot's world: use them with --emulated",
        ));
    }
    let to_cli = |e: PioneerCliError| {
        let code = match e {
            PioneerCliError::Config(_) | PioneerCliError::Cpu(_) => exit::USAGE,
            _ => exit::FAILURE,
        };
        CliError::new(code, e.to_string())
    };
    if args.print_config {
        let cfg = config_from(&args).map_err(to_cli)?;
        return out!("{}", cfg.to_toml());
    }
    // The emulated robot's world, checked before anything starts (a bad file is a usage
    // error).
    let world = if args.emulated {
        Some((args.world.world()?, args.world.laser()?))
    } else {
        None
    };
    let domain = crate::domain()?;
    serve(args, &domain, world).map_err(to_cli)
}

/// The emulated robot's world and its laser.
type EmulatedWorld = (limber_world::World, limber_world::LaserConfig);

fn serve(
    args: PioneerArgs,
    domain: &limber_services::Domain,
    world: Option<EmulatedWorld>,
) -> Result<(), PioneerCliError> {
    let cfg = config_from(&args)?;
    if let Some(n) = args.cpu {
        check_cpu(n)?;
    }
    let ctx = Context::new(domain, Role::Driver, "pioneer").map_err(|e| {
        PioneerCliError::Setup(format!("cannot join domain {}: {e}", domain.name()))
    })?;
    let emulator = if args.emulated {
        let emu = Emulator::start_pty(EmulatorConfig::default())?;
        eprintln!(
            "limber pioneer: emulator on {}",
            emu.pty_path()
                .map(|p| p.display().to_string())
                .unwrap_or_default()
        );
        Some(emu)
    } else {
        None
    };
    let target = match &emulator {
        Some(e) => e.link_target(),
        None => LinkTarget::parse(&cfg.port),
    };
    // Each warning is logged where it arises.
    let _warnings = apply_realtime(args.cpu, args.rt);
    // The built-in emulator's devices say SIMULATED; a driver on a port never does.
    let start = StartOptions {
        simulated: emulator.is_some(),
    };
    let mut driver = PioneerDriver::start_with(&ctx, cfg.clone(), target, start)?;
    let hw = driver.hardware().clone();
    eprintln!(
        "limber pioneer: connected to {:?} class {:?} subclass {:?}; domain {}",
        hw.identity.name,
        hw.identity.class,
        hw.identity.subclass,
        domain.name()
    );
    let r = &cfg.robot;
    if hw.arm {
        noteln!("serving {r}/actarray/0 (arm), {r}/limb/0, {r}/gripper/1 (arm gripper)");
    } else {
        noteln!(
            "no arm: the robot did not answer ARM_INFO; not serving {r}/actarray/0, {r}/limb/0, {r}/gripper/1 (asking again: served if it answers)"
        );
    }
    // Served or not, and why (the robot's CONFIGpac, or `body_gripper`).
    noteln!("{}", hw.gripper_note);
    // The emulated robot's world in this process: its laser and the blocks its arm moves.
    let _world = match world {
        Some((w, laser)) => {
            let blocks = crate::world::describe(&w.blocks);
            let running = crate::world::RunningWorld::start(
                domain,
                r,
                &format!("{r}/limb/0"),
                &format!("{r}/gripper/1"),
                w,
                laser,
            )
            .map_err(|e| PioneerCliError::Setup(e.to_string()))?;
            noteln!("serving {r}/ranger/0 (simulated laser; {blocks})");
            Some(running)
        }
        None => None,
    };
    noteln!("serving {r}/driver/0 (statistics); ready");
    let mode = if args.spin {
        LoopMode::Spin
    } else {
        LoopMode::Event
    };
    let ran = driver.run_until(RunOptions { mode }, || false);
    // What the shutdown could do: a robot that does not listen is not said stopped.
    let report = driver.shutdown();
    eprintln!("limber pioneer: {report}");
    ran?;
    drop(driver);
    if let Some(e) = emulator
        && let Err(err) = e.stop()
    {
        tracing::warn!("stopping the emulator: {err}");
    }
    Ok(())
}
