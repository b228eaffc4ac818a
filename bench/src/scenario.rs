//! The scenarios: the [`Scenario`] trait, the registry, and what a run shares
//! ([`RunCtx`]).
//!
//! Adding a scenario means implementing [`Scenario`] — run it, push [`Measurement`]s with
//! [`RunCtx::push`] — and listing it in [`registry`]; if it needs child processes, add a
//! role to [`crate::roles::run_role`] (`request` and `loop`, in [`pty_loop`], are worked
//! examples with a driver child). Ratios against the floor and
//! the peers are defined in [`crate::report::RATIOS`].

pub mod bridge;
pub mod command;
pub mod floor;
pub mod gateway;
pub mod ik;
pub mod lang;
pub mod peers;
pub mod physical;
pub mod pty_loop;
pub mod request;
pub mod state;
pub mod traj;

use std::path::PathBuf;
use std::time::{Duration, Instant};

use limber_services::Domain;
use serde::Serialize;

use crate::machine::Machine;
use crate::stats::Measurement;
use crate::{BenchArgs, BenchError, StrategyArg};

/// How long a child may take to set up and print `ready`.
pub const READY_TIMEOUT: Duration = Duration::from_secs(15);
/// How long one exchange may take before the run is declared hung.
pub const SAMPLE_TIMEOUT: Duration = Duration::from_secs(2);

/// One benchmark scenario.
pub trait Scenario {
    /// The name used by `--only` and in the report.
    fn name(&self) -> &'static str;
    /// One line: what it measures.
    fn description(&self) -> &'static str;
    /// `Err(why)` when it cannot run yet (reported as "not yet available").
    fn availability(&self) -> Result<(), String> {
        Ok(())
    }
    /// Runs it, pushing its measurements into `ctx`.
    fn run(&self, ctx: &mut RunCtx) -> Result<(), BenchError>;
}

/// Every scenario, in the order of a run.
pub fn registry() -> Vec<Box<dyn Scenario>> {
    vec![
        Box::new(floor::Floor),
        Box::new(state::StateFanout),
        Box::new(command::Command),
        Box::new(peers::Peers),
        Box::new(ik::Ik),
        Box::new(traj::Traj),
        Box::new(request::Request),
        Box::new(pty_loop::Loop),
        Box::new(lang::Lang),
        Box::new(bridge::Bridge),
        Box::new(gateway::Gateway),
    ]
}

/// The scenarios named by `--only` (all when empty), in registry order.
pub fn select(only: &[String]) -> Result<Vec<Box<dyn Scenario>>, BenchError> {
    let all = registry();
    let known: Vec<&str> = all.iter().map(|s| s.name()).collect();
    for name in only {
        if !known.contains(&name.as_str()) {
            return Err(BenchError::UnknownScenario {
                name: name.clone(),
                known: known.join(", "),
            });
        }
    }
    Ok(all
        .into_iter()
        .filter(|s| only.is_empty() || only.iter().any(|n| n == s.name()))
        .collect())
}

/// How a scenario ended.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct ScenarioOutcome {
    /// The scenario.
    pub name: &'static str,
    /// `ok`, `not_available`, `skipped` or `failed`.
    pub status: &'static str,
    /// Why, for anything but `ok` (or notes).
    pub detail: String,
    /// Wall time, s.
    pub seconds: f64,
}

/// Runs one scenario, turning errors into a `failed` outcome (the run goes on).
pub fn run_one(s: &dyn Scenario, ctx: &mut RunCtx) -> ScenarioOutcome {
    let start = Instant::now();
    let (status, detail) = match s.availability() {
        Err(why) => ("not_available", why),
        Ok(()) => {
            if ctx.progress {
                eprintln!("{}: {}", s.name(), s.description());
            }
            match s.run(ctx) {
                Ok(()) => ("ok", std::mem::take(&mut ctx.notes).join("; ")),
                Err(e) => {
                    eprintln!("{}: FAILED: {e}", s.name());
                    ("failed", e.to_string())
                }
            }
        }
    };
    ctx.notes.clear();
    ScenarioOutcome {
        name: s.name(),
        status,
        detail,
        seconds: start.elapsed().as_secs_f64(),
    }
}

/// What the scenarios of one run share: settings, the machine, a scratch directory and
/// the measurements so far.
#[derive(Debug)]
pub struct RunCtx {
    /// The machine header.
    pub machine: Machine,
    /// Quick mode.
    pub quick: bool,
    /// Sample count factor.
    pub scale: f64,
    /// Strategies to run.
    pub strategy: StrategyArg,
    /// Pinning requested and possible.
    pub pin: bool,
    /// When pinned: the client's core and the driver/echo child's, probed before this
    /// process pinned itself (afterwards its affinity names one core only).
    pinned: Option<[usize; 2]>,
    /// Progress output on stderr.
    pub progress: bool,
    /// Scratch directory (histograms of children, socket files), removed at the end.
    pub tmp: PathBuf,
    /// Notes of the running scenario (e.g. a skipped variant).
    pub notes: Vec<String>,
    measurements: Vec<Measurement>,
}

impl RunCtx {
    /// Prepares a run: probes the machine, pins this process when asked, makes the
    /// scratch directory.
    pub fn new(args: &BenchArgs) -> Result<Self, BenchError> {
        // Probe before pinning: the core count is read from this process's affinity.
        let mut machine = Machine::probe(String::new(), String::new());
        let mut pin = false;
        let mut pinned = None;
        let pinning = if args.pin {
            match core_affinity::get_core_ids() {
                Some(ids) if ids.len() >= 2 && core_affinity::set_for_current(ids[0]) => {
                    pin = true;
                    pinned = Some([ids[0].id, ids[1].id]);
                    format!(
                        "client/publisher side on core {}, driver/echo child on core {}, \
                         the loop's emulator thread on core {}, state subscribers unpinned",
                        ids[0].id, ids[1].id, ids[0].id
                    )
                }
                _ => "requested but not possible (fewer than 2 cores or refused)".into(),
            }
        } else {
            "off".into()
        };
        let mode = format!(
            "{} counts x{}",
            if args.quick { "quick" } else { "default" },
            args.scale
        );
        let tmp = std::env::temp_dir().join(format!(
            "limber-bench-{}-{}",
            std::process::id(),
            limber_services::monotonic_ns()
        ));
        std::fs::create_dir_all(&tmp).map_err(|e| BenchError::io(tmp.display().to_string(), e))?;
        machine.pinning = pinning;
        machine.mode = mode;
        Ok(RunCtx {
            machine,
            quick: args.quick,
            scale: args.scale,
            strategy: args.strategy(),
            pin,
            pinned,
            progress: !args.no_progress,
            tmp,
            notes: Vec::new(),
            measurements: Vec::new(),
        })
    }

    /// A sample count: `default` or `quick`, scaled, at least 10.
    pub fn count(&self, default: u64, quick: u64) -> u64 {
        let base = if self.quick { quick } else { default };
        ((base as f64 * self.scale) as u64).max(10)
    }

    /// A fresh domain, so that runs (and scenarios) never collide.
    pub fn domain(&self) -> Domain {
        Domain::unique_for_test()
    }

    /// The core a driver/echo child pins itself to (when pinning).
    pub fn child_cpu(&self) -> Option<usize> {
        self.pinned.map(|[_, child]| child)
    }

    /// The core this process (the client side) is pinned to (when pinning).
    pub fn client_cpu(&self) -> Option<usize> {
        self.pinned.map(|[client, _]| client)
    }

    /// Whether spinning variants run: asked for, and at least 2 cores (never more
    /// spinning processes than cores).
    pub fn spin_enabled(&mut self) -> bool {
        if self.strategy == StrategyArg::Blocking {
            return false;
        }
        if self.machine.cores < 2 {
            self.notes
                .push("spin variants skipped: fewer than 2 cores".into());
            return false;
        }
        true
    }

    /// Whether blocking variants run.
    pub fn blocking_enabled(&self) -> bool {
        self.strategy != StrategyArg::Spin
    }

    /// A path in the scratch directory.
    pub fn tmp_file(&self, name: &str) -> PathBuf {
        self.tmp.join(name)
    }

    /// A deadline for a child that handles `n` exchanges of about `each`.
    pub fn deadline_for(&self, n: u64, each: Duration) -> Duration {
        Duration::from_secs(30) + each * (n.min(u32::MAX as u64) as u32) * 20
    }

    /// Adds a measurement.
    pub fn push(&mut self, m: Measurement) {
        self.measurements.push(m);
    }

    /// The measurements so far.
    pub fn measurements(&self) -> &[Measurement] {
        &self.measurements
    }

    /// Takes the measurements.
    pub fn take_measurements(&mut self) -> Vec<Measurement> {
        std::mem::take(&mut self.measurements)
    }
}

impl Drop for RunCtx {
    fn drop(&mut self) {
        if let Err(e) = std::fs::remove_dir_all(&self.tmp) {
            tracing::debug!("cannot remove {}: {e}", self.tmp.display());
        }
    }
}
