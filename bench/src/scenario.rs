//! The scenarios: the [`Scenario`] trait, the registry, and what a run shares
//! ([`RunCtx`]).
//!
//! Adding a scenario means implementing [`Scenario`] — run it, push [`Measurement`]s with
//! [`RunCtx::push`] — and listing it in [`registry`]; if it needs child processes, add a
//! role to [`crate::roles::run_role`] (`request` and `loop`, in [`pty_loop`], are worked
//! examples with a driver child). Ratios against the floor and
//! the peers are defined in [`crate::goals::RATIOS`].

pub mod bridge;
pub mod command;
pub mod cpu;
pub mod fanout_floor;
pub mod floor;
pub mod gateway;
pub mod ik;
pub mod lang;
pub mod many;
pub mod many_drivers;
pub mod peers;
pub mod physical;
pub mod pty_loop;
pub mod request;
pub mod state;
pub mod traj;
pub mod zenoh_floor;

use std::path::PathBuf;
use std::time::{Duration, Instant};

use limber_services::Domain;
use serde::Serialize;

use crate::cpu::CpuCost;
use crate::machine::Machine;
use crate::stats::Measurement;
use crate::{BenchArgs, BenchError, StrategyArg};

/// How long a child may take to set up and print `ready`.
pub const READY_TIMEOUT: Duration = Duration::from_secs(15);
/// How long one exchange may take before the run is declared hung.
pub const SAMPLE_TIMEOUT: Duration = Duration::from_secs(2);

/// One command round trip as the bench's client scenarios time it: joint 0 of `client`'s
/// device to +0.25 rad for an even `i`, -0.25 for an odd one, then a blocking wait for the
/// outcome; the time from the send to the outcome, ns. A refusal, or no outcome within
/// [`SAMPLE_TIMEOUT`], is an error naming command `i` (of `what`).
pub(crate) fn timed_command(
    client: &mut limber_services::ActArrayClient,
    i: u64,
    what: &str,
) -> Result<u64, BenchError> {
    use limber_interfaces::prelude::Status;
    let target = if i.is_multiple_of(2) { 0.25 } else { -0.25 };
    let t0 = limber_services::monotonic_ns();
    let ticket = client
        .move_to(0, target)
        .map_err(|e| BenchError::transport(format!("move_to ({what})"), e))?;
    let status = client
        .wait_outcome(ticket, SAMPLE_TIMEOUT)
        .map_err(|e| BenchError::transport(format!("outcome of command {i} ({what})"), e))?;
    let t1 = limber_services::monotonic_ns();
    if status != Status::Ok {
        return Err(BenchError::Transport {
            context: format!("command {i} ({what})"),
            reason: format!("refused: {status}"),
        });
    }
    Ok(t1.saturating_sub(t0))
}

/// How a floor's exchanges are spaced: back to back (the floor scenario), or at the rate
/// of the path it is the floor of, so that each exchange starts with a wake-up after the
/// same idle time as the path's (on a VM a wake-up after an idle millisecond costs more
/// than one after a few microseconds).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pace {
    /// Back to back: `floor.<key>.*`.
    BackToBack,
    /// One exchange per period, from a sleeping sender, as the `state` publisher does:
    /// `<scenario>.paced.<key>.*`.
    Paced {
        /// The period.
        period: Duration,
        /// The scenario the floor belongs to (and the ids' first part).
        scenario: &'static str,
        /// What runs beside the exchanges, for a floor measured under a scenario's load:
        /// the ids' second part and the label's words (`("16", "16 drivers")`:
        /// `many.16.paced.*`, "..., beside 16 drivers").
        beside: Option<(&'static str, &'static str)>,
        /// In how many turns the series is measured, each with its own warm-up and a
        /// share of the samples, merged into one series (a measurement pushed again with
        /// the same id, label, strategy and metric adds to it: [`RunCtx::push`]): a path
        /// and its floor measured in alternate turns meet the same phases of a VM whose
        /// speed changes over seconds. 1: one turn.
        turns: u32,
    },
}

impl Pace {
    /// The scenario a measurement belongs to.
    pub fn scenario(self) -> &'static str {
        match self {
            Pace::BackToBack => "floor",
            Pace::Paced { scenario, .. } => scenario,
        }
    }
    /// The measurement id `<prefix>.<key>.<suffix>`.
    pub fn id(self, key: &str, suffix: &str) -> String {
        match self {
            Pace::BackToBack => format!("floor.{key}.{suffix}"),
            Pace::Paced {
                scenario,
                beside: Some((tag, _)),
                ..
            } => format!("{scenario}.{tag}.paced.{key}.{suffix}"),
            Pace::Paced { scenario, .. } => format!("{scenario}.paced.{key}.{suffix}"),
        }
    }
    /// What a label says about the pace (empty back to back).
    pub fn label(self) -> String {
        match self {
            Pace::BackToBack => String::new(),
            Pace::Paced { period, beside, .. } => {
                let hz = 1_000_000_000 / period.as_nanos().max(1);
                let rate = if hz >= 1_000 && hz % 1_000 == 0 {
                    format!(", {} kHz", hz / 1_000)
                } else {
                    format!(", {hz} Hz")
                };
                match beside {
                    Some((_, what)) => format!("{rate}, beside {what}"),
                    None => rate,
                }
            }
        }
    }
    /// Warm-up and sample counts: `back_to_back` (default, quick) when back to back,
    /// the state scenario's counts when paced (a few seconds at 1 kHz).
    pub fn counts(self, ctx: &RunCtx, back_to_back: ((u64, u64), (u64, u64))) -> (u64, u64) {
        let ((warm, warm_quick), (n, n_quick)) = match self {
            Pace::BackToBack => back_to_back,
            Pace::Paced { turns, .. } => {
                let t = u64::from(turns.max(1));
                ((200, 50), (3_000 / t, 300 / t))
            }
        };
        (ctx.count(warm, warm_quick), ctx.count(n, n_quick))
    }
    /// A child's deadline for `n` exchanges of about `each` (back to back).
    pub fn deadline(self, ctx: &RunCtx, n: u64, each: Duration) -> Duration {
        match self {
            Pace::BackToBack => ctx.deadline_for(n, each),
            Pace::Paced { period, .. } => {
                Duration::from_secs(30) + period * (n.min(u32::MAX as u64) as u32) * 3
            }
        }
    }
    /// Before exchange `i` (1-based) of a run that started at `start`: sleeps until its
    /// time when paced.
    pub fn wait_turn(self, start: Instant, i: u64) {
        if let Pace::Paced { period, .. } = self {
            let next = start + period * (i.min(u32::MAX as u64) as u32);
            let now = Instant::now();
            if next > now {
                std::thread::sleep(next - now);
            }
        }
    }
}

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
        Box::new(cpu::Cpu),
        Box::new(many::Many),
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
                crate::progress::line(format_args!("{}: {}", s.name(), s.description()));
            }
            match s.run(ctx) {
                Ok(()) => ("ok", std::mem::take(&mut ctx.notes).join("; ")),
                Err(e) => {
                    crate::progress::line(format_args!("{}: FAILED: {e}", s.name()));
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
    /// Whether `pinned` is one scenario's ([`RunCtx::pin_scenario`]), not the run's.
    scenario_pin: bool,
    /// Progress output on stderr.
    pub progress: bool,
    /// Scratch directory (histograms of children, socket files), removed at the end.
    pub tmp: PathBuf,
    /// Notes of the running scenario (e.g. a skipped variant).
    pub notes: Vec<String>,
    measurements: Vec<Measurement>,
    cpu: Vec<CpuCost>,
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
            scenario_pin: false,
            progress: !args.no_progress,
            tmp,
            notes: Vec::new(),
            measurements: Vec::new(),
            cpu: Vec::new(),
        })
    }

    /// A sample count: `default` or `quick`, scaled, at least 10.
    pub fn count(&self, default: u64, quick: u64) -> u64 {
        let base = if self.quick { quick } else { default };
        ((base as f64 * self.scale) as u64).max(10)
    }

    /// A progress line on stderr, unless progress is off (`--no-progress`).
    pub fn say(&self, args: std::fmt::Arguments<'_>) {
        if self.progress {
            crate::progress::line(args);
        }
    }

    /// A fresh domain, so that runs (and scenarios) never collide: each call another.
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

    /// Pins for one scenario whose series compare clients run one after the other against
    /// one driver (`lang`): this process's thread (and so the client processes it starts,
    /// which inherit its affinity) on one core, the driver child on another, as `--pin`
    /// does for the whole run. Unpinned, each client lands on the driver's core or not as
    /// the scheduler has it, and a read of what the driver just wrote costs some 3x more
    /// from the other core (on the project's VM, 0.25 against 0.76 us for a Rust state
    /// read): the ratio between languages then measures the placement. Returns the note
    /// for the report; `None` when the run is pinned already or cannot be (fewer than two
    /// cores, refused). [`RunCtx::end_scenario_pin`] undoes it.
    pub fn pin_scenario(&mut self, scenario: &str) -> Option<String> {
        if self.pinned.is_some() {
            return None;
        }
        let ids = core_affinity::get_core_ids()?;
        if ids.len() < 2 || !core_affinity::set_for_current(ids[0]) {
            return None;
        }
        self.pinned = Some([ids[0].id, ids[1].id]);
        self.scenario_pin = true;
        Some(format!(
            "{scenario} pinned whatever --pin says (one placement for every client): the \
             clients on core {}, the driver child on core {}",
            ids[0].id, ids[1].id
        ))
    }

    /// Undoes [`RunCtx::pin_scenario`] (nothing when it did not pin).
    pub fn end_scenario_pin(&mut self) {
        if std::mem::take(&mut self.scenario_pin) {
            self.pinned = None;
            crate::roles::unpin();
        }
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
    /// A series measured in several turns ([`Pace::Paced::turns`]) is one: a measurement
    /// whose id, label, strategy and metric are there already adds its samples to it. Two
    /// different series under one id (a scenario's mistake) stay two, and it is logged.
    pub fn push(&mut self, m: Measurement) {
        let same = |o: &Measurement| {
            o.id == m.id && o.label == m.label && o.strategy == m.strategy && o.metric == m.metric
        };
        match self.measurements.iter_mut().find(|o| same(o)) {
            Some(o) => {
                if let Err(e) = o.hist.add(&m.hist) {
                    tracing::warn!(id = %m.id, error = %e, "cannot merge a turn's samples: the turn is left out");
                }
            }
            None => {
                if self.measurements.iter().any(|o| o.id == m.id) {
                    tracing::warn!(id = %m.id, label = %m.label, "two different series under one id");
                }
                self.measurements.push(m);
            }
        }
    }

    /// The measurements so far.
    pub fn measurements(&self) -> &[Measurement] {
        &self.measurements
    }

    /// Takes the measurements.
    pub fn take_measurements(&mut self) -> Vec<Measurement> {
        std::mem::take(&mut self.measurements)
    }

    /// Adds what a process cost.
    pub fn push_cpu(&mut self, c: CpuCost) {
        self.cpu.push(c);
    }

    /// Takes the CPU costs.
    pub fn take_cpu(&mut self) -> Vec<CpuCost> {
        std::mem::take(&mut self.cpu)
    }

    /// The length of a CPU window: `default`, or `quick` in quick mode, scaled (at least
    /// 100 ms).
    pub fn window(&self, default: Duration, quick: Duration) -> Duration {
        let base = if self.quick { quick } else { default };
        base.mul_f64(self.scale).max(Duration::from_millis(100))
    }
}

impl Drop for RunCtx {
    fn drop(&mut self) {
        if let Err(e) = std::fs::remove_dir_all(&self.tmp) {
            tracing::debug!("cannot remove {}: {e}", self.tmp.display());
        }
    }
}
