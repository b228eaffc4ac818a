#![doc = include_str!("../README.md")]

use std::process::ExitCode;
use std::sync::OnceLock;

use clap::{Parser, Subcommand};
use limber_services::{Context, Domain, Role};

#[cfg(feature = "bridge")]
mod bridge;
mod clean;
mod demo;
mod device;
mod echo;
pub mod emulator;
mod lacks;
mod layout;
mod list;
mod logging;
mod monitor;
mod out;
mod path;
pub mod pioneer;
mod player_gateway;
mod record;
pub mod simarm;
mod traj;
pub mod world;

/// limber: Player's generic limb interfaces (actarray, limb, gripper) over zero-copy
/// shared memory, with a real-time driver for the Pioneer arm.
#[derive(Debug, Parser)]
#[command(name = "limber", version, about, long_about = None, propagate_version = true)]
struct Cli {
    /// The domain to work in (default: $LIMBER_DOMAIN, or "limber"). Robots and tests in
    /// different domains never see each other; a domain is its user's alone, or with
    /// $LIMBER_GROUP set the domain of a Unix group's members (its files are in
    /// $LIMBER_RUNTIME_DIR, default /tmp/limber-<uid>, in group mode /tmp/limber-g-<gid>:
    /// docs/guide/security.md).
    #[arg(long, global = true, value_name = "NAME", env = limber_services::naming::DOMAIN_ENV,
          hide_env_values = true, value_parser = parse_domain)]
    domain: Option<Domain>,

    /// More log output on stderr (-v info, -vv debug, -vvv trace); RUST_LOG overrides.
    #[arg(short, long, global = true, action = clap::ArgAction::Count)]
    verbose: u8,

    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// The main job: start the Pioneer emulator and driver in this process and run the
    /// paper's pick-a-block program on it, step by step with the live joint and gripper
    /// state, then a summary. `--on simarm` runs the very same program on the simulated arm.
    Demo(demo::DemoArgs),
    /// Print the wire contract: every message struct with its type name, size and fields.
    ///
    /// Without a flag, a readable catalogue. `--json` prints the layout manifest that the
    /// C header and the Python classes are generated from.
    Layout(layout::LayoutArgs),
    /// List every device of the domain by its name robot/interface/index, with its driver
    /// and whether the driver is alive; then what each running driver found its robot
    /// lacks ("robot pioneer has no arm").
    List(list::ListArgs),
    /// Print the live state of a device (one line per sample; --json for scripts).
    Echo(echo::EchoArgs),
    /// Remove every file of the domain (its /dev/shm segments, its iceoryx2 files, its
    /// token) once no live process uses it: what a SIGKILLed driver or client left. Refused
    /// (exit 5, naming them) while a driver or client runs in it; `--all` for every domain
    /// of this user.
    ///
    /// Example: limber clean --domain scratch
    Clean(clean::CleanArgs),
    /// A live terminal view of every device of the domain, like Player's playerv: joints
    /// against their limits, states, limb pose, grippers, lift, drivers' link statistics.
    ///
    /// Keys: up/down (j/k) select a device, h home, s stop, o open, c close, q quit.
    /// `--once` (or a stdout that is not a terminal) prints one frame as text.
    Monitor(monitor::MonitorArgs),
    /// Command an actuator array: pos, multipos, speed, multispeed, home, current,
    /// multicurrent; requests power, brakes, geom, speedcfg, accel.
    ///
    /// Example: limber actarray pioneer/actarray/0 pos 2 0.5
    Actarray(device::ActArrayArgs),
    /// Command a limb: home, stop, setpose, setposition, vecmove; requests power, brakes,
    /// geom, speed, reach (where would a setpose end, without moving).
    ///
    /// On a 5-joint arm, setpose meets the position and the approach (within the driver's
    /// tolerances) and turns the orientation to the nearest one the joints can hold: it
    /// answers "ok, orientation adjusted" and the limb state says by how much.
    ///
    /// Example: limber limb pioneer/limb/0 setpose 0.4 0 0.2 --approach 0 0 -1 --orient 1 0 0
    Limb(device::LimbArgs),
    /// Command a gripper: open, close, stop, store, retrieve; request geom.
    ///
    /// Example: limber gripper pioneer/gripper/0 open
    Gripper(device::GripperArgs),
    /// Read a ranger (a laser scanner): scan (the latest ranges with their bearings),
    /// geom (its pose on the robot and configuration).
    ///
    /// Example: limber ranger simarm/ranger/0 geom
    Ranger(device::RangerArgs),
    /// Run the Pioneer driver: the arm, limb, grippers and lift over P2OS (serial, pty or
    /// tcp://host:port). `--emulated` drives the built-in emulator.
    Pioneer(pioneer::PioneerArgs),
    /// Run a Pioneer controller emulator on a pty (prints its path) or on TCP.
    Emulator(emulator::EmulatorArgs),
    /// Run the simulated arm: actarray, limb and gripper for any serial chain (default the
    /// built-in 6-joint arm; --builtin 7dof, or --chain FILE), robot name "simarm".
    Simarm(simarm::SimArmArgs),
    /// Measure latency: the command and state paths, requests, the loop through the
    /// emulator and IK, beside raw iceoryx2 (the floor) and Unix/TCP sockets (the peers).
    Bench(limber_bench::BenchArgs),
    /// Carry devices between hosts over Zenoh: `expose` on the robot's PC puts this
    /// domain's devices on the network, `mirror` on another host hosts them in its domain
    /// under the same names.
    ///
    /// The walkthrough is in docs/guide/bridge.md, the keys and payloads in
    /// bridge/README.md.
    #[cfg(feature = "bridge")]
    Bridge(bridge::BridgeArgs),
    /// Serve Player's TCP protocol (Player 3) for every device of the domain, so that
    /// Player's own programs (libplayerc, libplayerc++, playerv, playerprint, playerjoy)
    /// use limber devices unchanged: point them at this address. Loopback by default.
    ///
    /// Runs until SIGINT, SIGTERM, SIGHUP (or SIGQUIT); prints "session N from ADDR" and
    /// "session N ended" as clients come and go (a session's leases end with it).
    PlayerGateway(player_gateway::PlayerGatewayArgs),
    /// Record every state, outcome and driver statistics of the domain (or of the devices
    /// named) into an MCAP file, with a progress line on stderr; `--info FILE` summarises a
    /// recorded file. Foxglove and the `mcap` tools open the files (record/README.md).
    ///
    /// Example: limber record pioneer/actarray/0 -o /tmp/limber-help.mcap --duration 2
    Record(record::RecordArgs),
    /// Republish a recorded file into the domain as if its devices were live: `limber
    /// echo`, `limber monitor` and clients work on it; commands are refused.
    ///
    /// Example: limber replay /tmp/limber-help.mcap --rate 4
    Replay(record::ReplayArgs),
    /// Show the domain's devices live in Foxglove: a read-only foxglove.websocket.v1
    /// server (loopback by default) with every state as JSON, the actuator arrays as
    /// foxglove.JointStates and a URDF of each arm whose chain limber knows. Foxglove
    /// connects to ws://127.0.0.1:8765 (record/README.md).
    View(record::ViewArgs),
}

/// Runs the `limber` command line with the process's arguments.
pub fn run() -> ExitCode {
    run_from(std::env::args_os())
}

/// Runs the `limber` command line with `args` (the first is the program name).
pub fn run_from<I, T>(args: I) -> ExitCode
where
    I: IntoIterator<Item = T>,
    T: Into<std::ffi::OsString> + Clone,
{
    let cli = Cli::parse_from(args);
    logging::init(cli.verbose);
    let domain = match cli.domain {
        Some(d) => d,
        None => match Domain::new(limber_services::naming::DEFAULT_DOMAIN) {
            Ok(d) => d,
            Err(e) => {
                eprintln!("limber: {e}");
                return ExitCode::from(exit::USAGE);
            }
        },
    };
    if DOMAIN.set(domain).is_err() {
        tracing::debug!("the domain was already chosen in this process");
    }
    let result = match cli.command {
        Command::Demo(args) => demo::run(args),
        Command::Layout(args) => layout::run(args),
        Command::List(args) => list::run(args),
        Command::Echo(args) => echo::run(args),
        Command::Clean(args) => clean::run(args),
        Command::Monitor(args) => monitor::run(args),
        Command::Actarray(args) => device::actarray(args),
        Command::Limb(args) => device::limb(args),
        Command::Gripper(args) => device::gripper(args),
        Command::Ranger(args) => device::ranger(args),
        Command::Pioneer(args) => pioneer::run(args),
        Command::Emulator(args) => emulator::run(args),
        Command::Simarm(args) => simarm::run(args),
        #[cfg(feature = "bridge")]
        Command::Bridge(args) => bridge::run(args),
        Command::PlayerGateway(args) => player_gateway::run(args),
        Command::Record(args) => record::record(args),
        Command::Replay(args) => record::replay(args),
        Command::View(args) => record::view(args),
        Command::Bench(args) => limber_bench::run_cli(args).map_err(|e| {
            let code = if e.is_usage() {
                exit::USAGE
            } else {
                exit::FAILURE
            };
            CliError::new(code, e.to_string())
        }),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        // A closed stdout (`| head -1`): done, quietly, as Unix tools do.
        Err(e) if e.quiet => ExitCode::from(e.exit_code()),
        Err(e) => {
            eprintln!("limber: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}

static DOMAIN: OnceLock<Domain> = OnceLock::new();

/// `--domain` / `LIMBER_DOMAIN`: a valid domain name; an empty one is an error, not the
/// default.
fn parse_domain(s: &str) -> Result<Domain, String> {
    if s.is_empty() {
        return Err("the domain name is empty (unset LIMBER_DOMAIN or name a domain)".into());
    }
    Domain::new(s).map_err(|e| e.to_string())
}

/// A number of seconds for a flag: finite and not negative (at most an hour).
pub(crate) fn parse_seconds(s: &str) -> Result<f64, String> {
    let v: f64 = s
        .parse()
        .map_err(|e| format!("{s:?} is not a number of seconds: {e}"))?;
    if !v.is_finite() || !(0.0..=3600.0).contains(&v) {
        return Err(format!("{s:?}: seconds must be between 0 and 3600"));
    }
    Ok(v)
}

/// The domain selected by `--domain` or `LIMBER_DOMAIN` (default `limber`).
pub fn domain() -> Result<Domain, CliError> {
    match DOMAIN.get() {
        Some(d) => Ok(d.clone()),
        None => Domain::new(limber_services::naming::DEFAULT_DOMAIN)
            .map_err(|e| CliError::new(exit::USAGE, e.to_string())),
    }
}

/// A client context in the selected domain, named after the verb's program.
pub(crate) fn client_context() -> Result<Context, CliError> {
    let domain = domain()?;
    Context::new(&domain, Role::Client, "limber").map_err(|e| {
        CliError::new(
            exit::FAILURE,
            format!("cannot join domain {}: {e}", domain.name()),
        )
    })
}

/// Exit codes of the `limber` command.
pub mod exit {
    /// Bad arguments (as clap uses).
    pub const USAGE: u8 = 2;
    /// No driver offers the device.
    pub const NO_DRIVER: u8 = 3;
    /// The driver died.
    pub const DRIVER_GONE: u8 = 4;
    /// The driver refused the command or request (the reason is printed).
    pub const REFUSED: u8 = 5;
    /// No answer in time.
    pub const TIMEOUT: u8 = 6;
    /// Anything else (I/O, shared memory).
    pub const FAILURE: u8 = 1;
}

/// An error of a verb, with the exit code it maps to.
#[derive(Debug)]
pub struct CliError {
    message: String,
    code: u8,
    /// Nothing to say (the reader of stdout went away).
    quiet: bool,
}

impl CliError {
    /// An error with exit code `code`.
    pub fn new(code: u8, message: impl Into<String>) -> Self {
        CliError {
            message: message.into(),
            code,
            quiet: false,
        }
    }

    /// Stdout is a closed pipe: the verb ends with exit 0 and prints nothing.
    pub fn stdout_closed() -> Self {
        CliError {
            message: "stdout is closed".into(),
            code: 0,
            quiet: true,
        }
    }

    pub(crate) fn exit_code(&self) -> u8 {
        self.code
    }
}

impl std::fmt::Display for CliError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}
