#![doc = include_str!("../README.md")]
//! ## The library
//!
//! `limber bench` (or the `limber-bench` binary) runs latency scenarios in separate
//! processes and reports every one with percentiles from an [`hdrhistogram`], beside
//! the floor (raw iceoryx2 with the same payloads and process setup) and the peers (the
//! same exchange over a Unix domain socket and over TCP loopback, Player's transport),
//! all measured in the same run.
//!
//! * [`BenchArgs`] / [`run_cli`]: the command line (wired by the `limber` CLI as
//!   `limber bench`).
//! * [`scenario`]: the [`scenario::Scenario`] trait and the registry; `loop` goes through
//!   the emulator and is split by stage with the stamps on the way (client send, the
//!   driver's read of the robot's reply, client receipt).
//! * [`stats`]: what a measurement is and how it is summarised (jitter = p99 − p50).
//! * [`report`]: the terminal table, the ratios and goals, the JSON file; [`plot`]: the SVG.
//! * [`results`]: `--results DIR`, the run as a Markdown page with the machine and the
//!   command.
//! * [`cpu`]: the CPU time of the processes of a scenario over a window (what a latency
//!   costs, idle and under load).
//!
//! Child processes are this crate's own binary re-executed with the hidden `--role`
//! argument (see [`child`]); every child has a deadline after which it is killed.

#![warn(missing_docs)]

pub mod child;
pub mod cpu;
pub mod goals;
pub mod machine;
pub mod plot;
pub mod progress;
pub mod report;
pub mod results;
pub mod roles;
pub mod scenario;
pub mod stats;

use std::path::PathBuf;
use std::time::Duration;

use thiserror::Error;

pub use report::Report;
pub use scenario::{RunCtx, Scenario, ScenarioOutcome, registry};
pub use stats::{Measurement, Metric, Strategy, Summary};

/// Everything that can go wrong in a benchmark run.
#[derive(Debug, Error)]
pub enum BenchError {
    /// A command-line value is invalid (e.g. a scenario named twice, a zero count).
    #[error("invalid argument: {0}")]
    Args(String),
    /// `--only` named a scenario that does not exist.
    #[error("--only: unknown scenario {name:?}; the scenarios are {known} (see --list)")]
    UnknownScenario {
        /// The name given.
        name: String,
        /// The names that exist.
        known: String,
    },
    /// iceoryx2 or limber-services failed (creating a node, a service, a port; sending).
    #[error("{context}: {reason}")]
    Transport {
        /// What was being done.
        context: String,
        /// The underlying error.
        reason: String,
    },
    /// A child process could not be started.
    #[error("cannot start the child process {role}: {source}")]
    Spawn {
        /// The child's role.
        role: String,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
    /// A child did not become ready or finish before its deadline; it was killed.
    #[error("child {role} timed out ({what}) and was killed")]
    ChildTimeout {
        /// The child's role.
        role: String,
        /// What it was expected to do.
        what: String,
    },
    /// A child reported an error or exited unsuccessfully.
    #[error("child {role} failed: {reason}")]
    ChildFailed {
        /// The child's role.
        role: String,
        /// Its message or exit status.
        reason: String,
    },
    /// No answer to one exchange within the per-sample timeout.
    #[error("{what}: no answer within {timeout:?}")]
    Timeout {
        /// The exchange.
        what: String,
        /// The timeout.
        timeout: Duration,
    },
    /// An I/O operation failed (sockets, files, pipes to a child).
    #[error("{context}: {source}")]
    Io {
        /// What was being done.
        context: String,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
    /// A histogram could not be created, serialised or read back.
    #[error("histogram: {0}")]
    Histogram(String),
    /// The plot could not be drawn.
    #[error("cannot draw the plot {path}: {reason}")]
    Plot {
        /// The SVG file.
        path: PathBuf,
        /// Why.
        reason: String,
    },
    /// One or more scenarios failed; the report (table, JSON, plot) was still written.
    #[error("{0} scenario(s) failed (see the report)")]
    ScenariosFailed(usize),
}

impl BenchError {
    /// Whether the command line was wrong (an unknown scenario, a bad value): a usage
    /// error (exit 2), not a failed run.
    pub fn is_usage(&self) -> bool {
        matches!(
            self,
            BenchError::Args(_) | BenchError::UnknownScenario { .. }
        )
    }
}

impl BenchError {
    /// An [`BenchError::Io`] with context.
    pub fn io(context: impl Into<String>, source: std::io::Error) -> Self {
        BenchError::Io {
            context: context.into(),
            source,
        }
    }

    /// A [`BenchError::Transport`] from any debuggable error.
    pub fn transport(context: impl Into<String>, reason: impl core::fmt::Debug) -> Self {
        BenchError::Transport {
            context: context.into(),
            reason: format!("{reason:?}"),
        }
    }
}

/// Which waiting strategies the iceoryx2 and socket scenarios run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, Default)]
pub enum StrategyArg {
    /// Both: spinning (busy-poll) and blocking (event-driven) variants.
    #[default]
    Both,
    /// Only the spinning variants (the driver's `--spin`: driver busy-polls, client spins).
    Spin,
    /// Only the blocking (event-driven) variants.
    Blocking,
}

/// The options of `limber bench`.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct BenchArgs {
    /// Run only these scenarios (comma separated): floor, state, command, ik, traj,
    /// peers, request, loop, lang, bridge, gateway, cpu, many. Default: all.
    #[arg(long, value_delimiter = ',', value_name = "NAME[,NAME]")]
    pub only: Vec<String>,
    /// Small sample counts (a run takes under 20 s).
    #[arg(long)]
    pub quick: bool,
    /// Which waiting strategies to run.
    #[arg(long, value_enum, default_value_t = StrategyArg::Both)]
    pub strategy: StrategyArg,
    /// Shorthand for `--strategy spin`.
    #[arg(long, conflicts_with = "strategy")]
    pub spin: bool,
    /// Pin this process (the client) to the first core and each driver/echo child to the
    /// second (core_affinity).
    #[arg(long)]
    pub pin: bool,
    /// Multiply the sample counts by this factor (e.g. 0.1 for a smoke run).
    #[arg(long, default_value_t = 1.0, value_name = "FACTOR")]
    pub scale: f64,
    /// Write the results (machine header, every measurement with its percentiles in ns,
    /// ratios and goals) as JSON to this file.
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Draw the latency percentile curves of every measurement into this SVG file.
    #[arg(long, value_name = "FILE.svg")]
    pub plot: Option<PathBuf>,
    /// Write the run to this directory as `latest.md` (the machine, the exact command, the
    /// table, the goals missed) and `latest.json` (e.g. `--results bench/results`).
    #[arg(long, value_name = "DIR")]
    pub results: Option<PathBuf>,
    /// List the scenarios and exit.
    #[arg(long)]
    pub list: bool,
    /// No progress line on stderr.
    #[arg(long)]
    pub no_progress: bool,

    /// Internal: run as a child process of a scenario (driver, echo, subscriber).
    #[arg(long, hide = true)]
    pub role: Option<String>,
    /// Internal: the child's domain (its own flag: `limber`'s global `--domain` is the
    /// parent's).
    #[arg(id = "child_domain", long = "child-domain", hide = true)]
    pub domain: Option<String>,
    /// Internal: where the child writes its histogram.
    #[arg(long, hide = true)]
    pub out: Option<PathBuf>,
    /// Internal: the socket address a child connects to.
    #[arg(long, hide = true)]
    pub addr: Option<String>,
    /// Internal: the file a physical-floor child maps shared.
    #[arg(long, hide = true)]
    pub shm: Option<PathBuf>,
    /// Internal: the device a driver child offers (default `bench/actarray/0`).
    #[arg(long, hide = true)]
    pub device: Option<String>,
    /// Internal: how long an event-driven driver child keeps polling after activity, µs.
    #[arg(long, hide = true, default_value_t = 0)]
    pub linger_us: u64,
    /// Internal: the core a child pins itself to.
    #[arg(long, hide = true)]
    pub cpu: Option<usize>,
    /// Internal: the core a Pioneer driver child pins its emulator thread to.
    #[arg(long, hide = true)]
    pub emulator_cpu: Option<usize>,
    /// Internal: samples a child discards before recording.
    #[arg(long, hide = true, default_value_t = 0)]
    pub warmup: u64,
    /// Internal: samples a child produces (state publisher).
    #[arg(long, hide = true, default_value_t = 0)]
    pub count: u64,
    /// Internal: the child's own deadline, ms; it exits when it passes.
    #[arg(long, hide = true, default_value_t = 60_000)]
    pub deadline_ms: u64,
}

impl BenchArgs {
    /// The strategies to run.
    pub fn strategy(&self) -> StrategyArg {
        if self.spin {
            StrategyArg::Spin
        } else {
            self.strategy
        }
    }
}

/// Fails when `path` (the file of `flag`) cannot be written: its directory is missing or
/// not writable, or it is a directory. An existing file is left as it is until the report
/// replaces it; a new one is created empty.
fn check_writable(flag: &str, path: &std::path::Path) -> Result<(), BenchError> {
    std::fs::OpenOptions::new()
        .write(true)
        .create(true)
        .truncate(false)
        .open(path)
        .map(drop)
        .map_err(|e| BenchError::io(format!("{flag} {}: cannot write it", path.display()), e))
}

/// Runs `limber bench` with parsed arguments: the selected scenarios, then the table,
/// the JSON file and the plot. With the hidden `--role`, runs as a child process instead.
///
/// Returns [`BenchError::ScenariosFailed`] after writing the report if a scenario failed.
pub fn run_cli(args: BenchArgs) -> Result<(), BenchError> {
    if let Some(role) = args.role.clone() {
        return roles::run_role(&role, &args);
    }
    let scenarios = scenario::select(&args.only)?;
    if args.list {
        for s in registry() {
            let avail = match s.availability() {
                Ok(()) => String::new(),
                Err(why) => format!(" (not yet available: {why})"),
            };
            println!("{:<8} {}{}", s.name(), s.description(), avail);
        }
        return Ok(());
    }
    if !(args.scale.is_finite() && args.scale > 0.0) {
        return Err(BenchError::Args(format!(
            "--scale must be a positive number, got {}",
            args.scale
        )));
    }
    // A run takes seconds to minutes: an output that cannot be written is said before it,
    // not after.
    for (flag, path) in [("--json", &args.json), ("--plot", &args.plot)] {
        if let Some(path) = path {
            check_writable(flag, path)?;
        }
    }
    if let Some(dir) = &args.results {
        let (md, json) = results::paths(dir);
        check_writable("--results", &md)?;
        check_writable("--results", &json)?;
    }
    let mut ctx = RunCtx::new(&args)?;
    let mut outcomes = Vec::new();
    for s in &scenarios {
        outcomes.push(scenario::run_one(s.as_ref(), &mut ctx));
    }
    let cpu = ctx.take_cpu();
    let report = Report::new(
        ctx.machine.clone(),
        &args,
        outcomes,
        ctx.take_measurements(),
    )
    .with_cpu(cpu);
    print!("{}", report.table());
    if let Some(path) = &args.json {
        report.write_json(path)?;
        progress::line(format_args!("wrote {}", path.display()));
    }
    if let Some(path) = &args.plot {
        plot::draw(path, &report)?;
        progress::line(format_args!("wrote {}", path.display()));
    }
    if let Some(dir) = &args.results {
        results::write(dir, &report, &results::invocation())?;
        progress::line(format_args!("wrote {}", results::paths(dir).0.display()));
    }
    match report.failed() {
        0 => Ok(()),
        n => Err(BenchError::ScenariosFailed(n)),
    }
}
