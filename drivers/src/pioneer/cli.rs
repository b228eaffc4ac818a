//! `limber pioneer`: the driver as a command.

use std::path::PathBuf;

use clap::Args;
use limber_services::{Context, Domain, Role};

use crate::emulator::{Emulator, EmulatorConfig};
use crate::p2os::LinkTarget;

use super::config::PioneerConfig;
use super::driver::{DriverError, LoopMode, PioneerDriver, RunOptions};

/// Arguments of `limber pioneer`.
#[derive(Debug, Clone, Args)]
pub struct PioneerArgs {
    /// Configuration file (TOML); see `--print-config` for every key and its default.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    /// The link: a serial device (/dev/ttyS0), a pty, or tcp://host:port (simulator: 8101).
    #[arg(long)]
    pub port: Option<String>,
    /// Serial baud rate (default: try 9600, 38400, 19200, 115200, 57600).
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
    /// Pin the driver thread to this CPU core.
    #[arg(long, value_name = "N")]
    pub cpu: Option<usize>,
    /// Real-time: SCHED_FIFO priority 80 and locked memory (needs CAP_SYS_NICE /
    /// CAP_IPC_LOCK; a warning says so when not permitted).
    #[arg(long)]
    pub rt: bool,
    /// Print the configuration (defaults merged with --config) as TOML and exit.
    #[arg(long)]
    pub print_config: bool,
}

/// `limber pioneer` failed.
#[derive(Debug, thiserror::Error)]
pub enum PioneerCliError {
    /// The configuration is invalid.
    #[error(transparent)]
    Config(#[from] super::config::ConfigError),
    /// The domain or context could not be set up.
    #[error("{0}")]
    Setup(String),
    /// The emulator could not start.
    #[error("cannot start the emulator: {0}")]
    Emulator(#[from] crate::emulator::EmulatorError),
    /// The driver failed.
    #[error(transparent)]
    Driver(#[from] DriverError),
}

/// Applies `--cpu` and `--rt`; returns warnings for what was not permitted.
pub fn apply_realtime(cpu: Option<usize>, rt: bool) -> Vec<String> {
    let mut warnings = Vec::new();
    if let Some(n) = cpu {
        let ok = core_affinity::get_core_ids()
            .and_then(|ids| ids.into_iter().find(|c| c.id == n))
            .map(core_affinity::set_for_current)
            .unwrap_or(false);
        if !ok {
            warnings.push(format!(
                "cannot pin to CPU {n} (no such core, or not permitted)"
            ));
        }
    }
    if rt {
        use thread_priority::{
            RealtimeThreadSchedulePolicy, ThreadPriority, ThreadSchedulePolicy,
            set_thread_priority_and_policy, thread_native_id,
        };
        let prio = ThreadPriority::Crossplatform(80u8.try_into().expect("80 is a valid priority"));
        if let Err(e) = set_thread_priority_and_policy(
            thread_native_id(),
            prio,
            ThreadSchedulePolicy::Realtime(RealtimeThreadSchedulePolicy::Fifo),
        ) {
            warnings.push(format!(
                "SCHED_FIFO not permitted ({e:?}): running with normal priority (grant CAP_SYS_NICE or run as root)"
            ));
        }
        if let Err(e) = rustix::mm::mlockall(
            rustix::mm::MlockAllFlags::CURRENT | rustix::mm::MlockAllFlags::FUTURE,
        ) {
            warnings.push(format!(
                "mlockall not permitted ({e}): memory may be paged (grant CAP_IPC_LOCK or raise RLIMIT_MEMLOCK)"
            ));
        }
    }
    warnings
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
    cfg.validate()?;
    Ok(cfg)
}

/// Runs `limber pioneer` until SIGINT/SIGTERM.
pub fn run_cli(args: PioneerArgs) -> Result<(), PioneerCliError> {
    let cfg = config_from(&args)?;
    if args.print_config {
        print!("{}", cfg.to_toml());
        return Ok(());
    }
    let domain = Domain::from_env().map_err(|e| PioneerCliError::Setup(e.to_string()))?;
    let ctx = Context::new(&domain, Role::Driver, "pioneer")
        .map_err(|e| PioneerCliError::Setup(e.to_string()))?;
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
    for w in apply_realtime(args.cpu, args.rt) {
        eprintln!("limber pioneer: warning: {w}");
    }
    let mut driver = PioneerDriver::start(&ctx, cfg.clone(), target)?;
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
        println!("serving {r}/actarray/0 (arm), {r}/limb/0, {r}/gripper/1 (arm gripper)");
    } else {
        println!(
            "no arm: the robot did not answer ARM_INFO; not serving {r}/actarray/0, {r}/limb/0, {r}/gripper/1"
        );
    }
    if hw.gripper {
        println!("serving {r}/gripper/0 (body gripper), {r}/actarray/1 (lift)");
    }
    println!("serving {r}/driver/0 (statistics); ready");
    let mode = if args.spin {
        LoopMode::Spin
    } else {
        LoopMode::Event
    };
    driver.run(RunOptions { mode })?;
    eprintln!("limber pioneer: stopped the arm and closed the link");
    drop(driver);
    if let Some(e) = emulator {
        let _ = e.stop();
    }
    Ok(())
}
