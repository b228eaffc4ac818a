//! The report of a run: the terminal table, ratios against the floor and the peers with
//! the goals, and the JSON file.

use std::fmt::Write as _;
use std::path::Path;

use serde::Serialize;

use crate::cpu::CpuCost;
pub use crate::goals::{RATIOS, TIME_GOALS};
use crate::machine::Machine;
use crate::scenario::ScenarioOutcome;
use crate::stats::{Measurement, Metric, Strategy, Summary, fmt_ns};
use crate::{BenchArgs, BenchError};

/// The jitter definition, stated in every report.
pub const JITTER: &str = "jitter = p99 - p50";

/// Which percentile a ratio compares.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Pct {
    /// Median.
    P50,
    /// 99th percentile.
    P99,
}

impl Pct {
    fn of(self, s: &Summary) -> u64 {
        match self {
            Pct::P50 => s.p50_ns,
            Pct::P99 => s.p99_ns,
        }
    }
    fn name(self) -> &'static str {
        match self {
            Pct::P50 => "p50",
            Pct::P99 => "p99",
        }
    }
}

/// A goal on a ratio.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Goal {
    /// The ratio must be at most this.
    AtMost(f64),
    /// The ratio must be at least this.
    AtLeast(f64),
}

/// A ratio of two measurements of the same run.
#[derive(Debug, Clone, Copy)]
pub struct RatioDef {
    /// What it says.
    pub label: &'static str,
    /// Numerator measurement id.
    pub num: &'static str,
    /// Denominator measurement id.
    pub den: &'static str,
    /// The percentile compared.
    pub pct: Pct,
    /// The goal, if any.
    pub goal: Option<Goal>,
    /// The same ratio between the floors of the two series, where it is measured: a goal
    /// tighter than the floors' own ratio is below its floor, and the report says so.
    pub floor: Option<RatioFloor>,
}

/// The floors' own ratio beside a ratio (see [`RatioDef::floor`]).
#[derive(Debug, Clone, Copy)]
pub struct RatioFloor {
    /// Numerator measurement id.
    pub num: &'static str,
    /// Further series added to the numerator, each so many times, each at its median: a
    /// floor made of several hops, each measured alone. At p50, a sum of medians is at most
    /// the median of the sum for these right-skewed latencies; at p99, one hop's p99 plus
    /// the others' medians is at most the sum's p99. Either way the floor is not overstated.
    pub plus: &'static [(&'static str, u32)],
    /// Denominator measurement id.
    pub den: &'static str,
    /// What the floors' ratio is, in words.
    pub what: &'static str,
}

/// A goal in time on one series of a run (issue 16's absolute goals): unlike the ratios they
/// depend on the machine, and on this VM its compute speed varies (up to 1.8x between runs).
#[derive(Debug, Clone, Copy)]
pub struct TimeGoalDef {
    /// What it says.
    pub label: &'static str,
    /// The measurement id.
    pub id: &'static str,
    /// The percentile.
    pub pct: Pct,
    /// The most it may be, ns.
    pub at_most_ns: u64,
    /// The series that is this one's floor in the same run (what the kernel alone takes
    /// for the same work), and what it is: reported beside the goal, so that a goal below
    /// the floor shows as such.
    pub floor: Option<(&'static str, &'static str)>,
}

/// A goal in time, as measured.
#[derive(Debug, Clone, Serialize)]
pub struct TimeGoal {
    /// What it says, with the percentile.
    pub label: String,
    /// The measurement id.
    pub id: &'static str,
    /// The percentile.
    pub pct: Pct,
    /// The value measured, ns.
    pub ns: u64,
    /// The most it may be, ns.
    pub at_most_ns: u64,
    /// Whether the goal was met.
    pub met: bool,
    /// The floor's id and value (same percentile, same run), where the goal has one.
    pub floor: Option<TimeGoalFloor>,
}

/// A goal's floor as measured in the same run.
#[derive(Debug, Clone, Serialize)]
pub struct TimeGoalFloor {
    /// The floor's measurement id.
    pub id: &'static str,
    /// What it is.
    pub what: &'static str,
    /// Its value at the goal's percentile, ns.
    pub ns: u64,
}

/// One point of a percentile curve.
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct CurvePoint {
    /// Percentile, 0 to 100.
    pub percentile: f64,
    /// Latency at it, ns.
    pub ns: u64,
}

/// A measurement as reported.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    /// The scenario.
    pub scenario: &'static str,
    /// The stable id.
    pub id: String,
    /// The label.
    pub label: String,
    /// `spin`, `blocking` or `compute`.
    pub strategy: Strategy,
    /// `round_trip`, `one_way` or `solve`.
    pub metric: Metric,
    /// Bytes out, if an exchange.
    pub bytes_out: Option<usize>,
    /// Bytes back, if an exchange.
    pub bytes_back: Option<usize>,
    /// Percentiles etc., ns.
    pub summary: Summary,
    /// The floor this row is compared with in the table (same strategy and metric).
    pub floor_id: Option<String>,
    /// p50 of this row / p50 of its floor.
    pub x_floor_p50: Option<f64>,
    /// The physical floor this row is compared with (futex for blocking, cache line for
    /// spinning; same metric).
    pub phys_id: Option<String>,
    /// p50 of this row / p50 of its physical floor.
    pub x_phys_p50: Option<f64>,
    /// The percentile curve (for plots).
    pub curve: Vec<CurvePoint>,
}

/// A computed ratio.
#[derive(Debug, Clone, Serialize)]
pub struct Ratio {
    /// What it says.
    pub label: String,
    /// Numerator id.
    pub num: &'static str,
    /// Denominator id.
    pub den: &'static str,
    /// The percentile compared.
    pub pct: Pct,
    /// The strategy of the numerator and denominator.
    pub strategy: String,
    /// The value.
    pub value: f64,
    /// The goal.
    pub goal: Option<Goal>,
    /// Whether the goal was met (None without a goal).
    pub met: Option<bool>,
    /// The floors' own ratio at the same percentile, and what it is (see
    /// [`RatioDef::floor`]), when both floors were measured.
    pub floor: Option<(f64, &'static str)>,
}

impl Ratio {
    /// Whether the goal is tighter than the floors' own ratio: not reachable over them.
    pub fn below_floor(&self) -> bool {
        match (self.goal, self.floor) {
            (Some(Goal::AtMost(x)), Some((f, _))) => f > x,
            (Some(Goal::AtLeast(x)), Some((f, _))) => f < x,
            _ => false,
        }
    }

    /// What the report adds after the goal: the floors' ratio, and whether the goal is
    /// out of its reach (empty without a floor).
    pub fn floor_note(&self) -> String {
        match self.floor {
            // A ratio that must stay under its goal cannot go below the floors' ratio; one
            // that must reach its goal cannot go above it.
            // Met although the floors' ratio says it could not be: the floor, composed of
            // series measured at other moments, overstated this run's.
            Some((f, what)) if self.below_floor() && self.met == Some(true) => {
                format!(
                    " ({what} = {f:.2}: met past that floor, whose series ran at other moments)"
                )
            }
            Some((f, what)) if self.below_floor() => match self.goal {
                Some(Goal::AtLeast(_)) => {
                    format!(" (the goal is above its floor: {what} = {f:.2})")
                }
                _ => format!(" (the goal is below its floor: {what} = {f:.2})"),
            },
            Some((f, what)) => format!(" ({what} = {f:.2})"),
            None => String::new(),
        }
    }
}

/// A whole report.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// The machine.
    pub machine: Machine,
    /// How jitter is defined.
    pub jitter_definition: &'static str,
    /// How every scenario ended.
    pub scenarios: Vec<ScenarioOutcome>,
    /// Every measurement.
    pub measurements: Vec<Row>,
    /// Ratios against the floor and the peers, with goals.
    pub ratios: Vec<Ratio>,
    /// Goals in time on single series.
    pub time_goals: Vec<TimeGoal>,
    /// What the processes cost (share of one core), idle and under load, with goals.
    pub cpu: Vec<CpuCost>,
}

/// The floor of `m` of one kind: `(spin, blocking)` name the floor's series for each
/// strategy (e.g. `("spin", "event")` for iceoryx2, `("cacheline", "futex")` for the
/// physical floors). None for a floor of that kind itself and for computations.
fn floor_of(m: &Measurement, (spin, blocking): (&str, &str)) -> Option<String> {
    let k = match m.strategy {
        Strategy::Spin => spin,
        Strategy::Blocking => blocking,
        Strategy::Compute => return None,
    };
    if m.id.starts_with(&format!("floor.{k}.")) {
        return None;
    }
    let what = match m.metric {
        Metric::RoundTrip => "rtt",
        Metric::OneWay if m.id.ends_with(".back") => "back",
        Metric::OneWay => "oneway",
        Metric::Solve | Metric::Read | Metric::Period => return None,
    };
    Some(format!("floor.{k}.{what}"))
}

/// The iceoryx2 floors.
const IOX2_FLOOR: (&str, &str) = ("spin", "event");
/// The physical floors.
const PHYS_FLOOR: (&str, &str) = ("cacheline", "futex");

/// A ratio in the table, or `-`.
fn ratio_cell(x: Option<f64>) -> String {
    x.map(|x| format!("{x:.2}")).unwrap_or_else(|| "-".into())
}

/// The percentiles of a curve: 0 to 99.999 on a "nines" scale.
pub const CURVE_NINES: &[f64] = &[
    0.0, 0.1, 0.2, 0.3, 0.5, 0.7, 1.0, 1.3, 1.5, 1.7, 2.0, 2.3, 2.5, 2.7, 3.0, 3.3, 3.5, 3.7, 4.0,
    4.5, 5.0,
];

fn curve(m: &Measurement) -> Vec<CurvePoint> {
    let n = m.hist.len();
    if n == 0 {
        return Vec::new();
    }
    let max_nines = (n as f64).log10();
    CURVE_NINES
        .iter()
        .filter(|x| **x <= max_nines)
        .map(|x| {
            let q = 1.0 - 10f64.powf(-x);
            CurvePoint {
                percentile: q * 100.0,
                ns: m.hist.value_at_quantile(q),
            }
        })
        .chain(std::iter::once(CurvePoint {
            percentile: 100.0,
            ns: m.hist.max(),
        }))
        .collect()
}

impl Report {
    /// Builds the report of a run.
    pub fn new(
        machine: Machine,
        _args: &BenchArgs,
        scenarios: Vec<ScenarioOutcome>,
        measurements: Vec<Measurement>,
    ) -> Self {
        let find = |id: &str| measurements.iter().find(|m| m.id == id);
        let rows: Vec<Row> = measurements
            .iter()
            .map(|m| {
                let s = Summary::of(&m.hist);
                let x_p50 = |id: Option<&str>| {
                    id.and_then(find).and_then(|f| {
                        let fp = Summary::of(&f.hist).p50_ns;
                        (fp > 0).then(|| s.p50_ns as f64 / fp as f64)
                    })
                };
                // The physical floors are not compared with iceoryx2's.
                let physical =
                    m.id.starts_with("floor.cacheline.") || m.id.starts_with("floor.futex.");
                let floor_id = floor_of(m, IOX2_FLOOR).filter(|f| !physical && find(f).is_some());
                let x_floor_p50 = x_p50(floor_id.as_deref());
                let phys_id = floor_of(m, PHYS_FLOOR).filter(|f| find(f).is_some());
                let x_phys_p50 = x_p50(phys_id.as_deref());
                Row {
                    scenario: m.scenario,
                    id: m.id.clone(),
                    label: m.label.clone(),
                    strategy: m.strategy,
                    metric: m.metric,
                    bytes_out: m.bytes.map(|b| b.0),
                    bytes_back: m.bytes.map(|b| b.1),
                    summary: s,
                    floor_id,
                    x_floor_p50,
                    phys_id,
                    x_phys_p50,
                    curve: curve(m),
                }
            })
            .collect();
        let value_of = |num: &str, den: &str, pct: Pct| {
            let (a, b) = (find(num)?, find(den)?);
            let (sa, sb) = (Summary::of(&a.hist), Summary::of(&b.hist));
            let d = pct.of(&sb);
            if d == 0 || sa.count == 0 {
                return None;
            }
            Some((pct.of(&sa) as f64 / d as f64, a, b))
        };
        let ratios = RATIOS
            .iter()
            .filter_map(|r| {
                let (value, a, b) = value_of(r.num, r.den, r.pct)?;
                let floor = r.floor.and_then(|f| {
                    let (v, _, b) = value_of(f.num, f.den, r.pct)?;
                    let d = r.pct.of(&Summary::of(&b.hist)) as f64;
                    let mut extra = 0.0;
                    for (id, times) in f.plus {
                        extra +=
                            f64::from(*times) * Pct::P50.of(&Summary::of(&find(id)?.hist)) as f64;
                    }
                    Some((v + extra / d, f.what))
                });
                let met = r.goal.map(|g| match g {
                    Goal::AtMost(x) => value <= x,
                    Goal::AtLeast(x) => value >= x,
                });
                let strategy = if a.strategy == b.strategy {
                    a.strategy.name().to_string()
                } else {
                    format!("{} / {}", a.strategy.name(), b.strategy.name())
                };
                Some(Ratio {
                    label: format!("{} ({})", r.label, r.pct.name()),
                    num: r.num,
                    den: r.den,
                    pct: r.pct,
                    strategy,
                    value,
                    goal: r.goal,
                    met,
                    floor,
                })
            })
            .collect();
        let time_goals = TIME_GOALS
            .iter()
            .filter_map(|g| {
                let m = find(g.id)?;
                let sm = Summary::of(&m.hist);
                if sm.count == 0 {
                    return None;
                }
                let ns = g.pct.of(&sm);
                let floor = g.floor.and_then(|(id, what)| {
                    let fm = Summary::of(&find(id)?.hist);
                    (fm.count > 0).then(|| TimeGoalFloor {
                        id,
                        what,
                        ns: g.pct.of(&fm),
                    })
                });
                Some(TimeGoal {
                    label: format!("{} ({})", g.label, g.pct.name()),
                    id: g.id,
                    pct: g.pct,
                    ns,
                    at_most_ns: g.at_most_ns,
                    met: ns <= g.at_most_ns,
                    floor,
                })
            })
            .collect();
        Report {
            machine,
            jitter_definition: JITTER,
            scenarios,
            measurements: rows,
            ratios,
            time_goals,
            cpu: Vec::new(),
        }
    }

    /// The report with the CPU costs measured in the run.
    pub fn with_cpu(mut self, cpu: Vec<CpuCost>) -> Self {
        self.cpu = cpu;
        self
    }

    /// Scenarios that failed.
    pub fn failed(&self) -> usize {
        self.scenarios
            .iter()
            .filter(|s| s.status == "failed")
            .count()
    }

    /// The terminal table.
    pub fn table(&self) -> String {
        let mut t = String::new();
        let _ = writeln!(t);
        t.push_str(&self.machine.header());
        let _ = writeln!(
            t,
            "{JITTER}; x iox2 = p50 / p50 of the raw iceoryx2 floor, x phys = p50 / p50 of the \
             physical floor (futex if blocking, cache line if spinning), same strategy and metric\n"
        );
        let _ = writeln!(
            t,
            "{:<8} {:<34} {:<8} {:<10} {:>7} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>7} {:>7}",
            "scenario",
            "series",
            "strategy",
            "metric",
            "count",
            "p50",
            "p90",
            "p99",
            "p99.9",
            "max",
            "jitter",
            "x iox2",
            "x phys"
        );
        for r in &self.measurements {
            let s = &r.summary;
            let _ = writeln!(
                t,
                "{:<8} {:<34} {:<8} {:<10} {:>7} {:>8} {:>8} {:>8} {:>8} {:>8} {:>8} {:>7} {:>7}",
                r.scenario,
                r.label,
                r.strategy.name(),
                r.metric.name(),
                s.count,
                fmt_ns(s.p50_ns),
                fmt_ns(s.p90_ns),
                fmt_ns(s.p99_ns),
                fmt_ns(s.p999_ns),
                fmt_ns(s.max_ns),
                fmt_ns(s.jitter_ns),
                ratio_cell(r.x_floor_p50),
                ratio_cell(r.x_phys_p50),
            );
        }
        let others: Vec<&ScenarioOutcome> =
            self.scenarios.iter().filter(|s| s.status != "ok").collect();
        let notes: Vec<&ScenarioOutcome> = self
            .scenarios
            .iter()
            .filter(|s| s.status == "ok" && !s.detail.is_empty())
            .collect();
        if !others.is_empty() || !notes.is_empty() {
            let _ = writeln!(t);
        }
        for s in others {
            let status = match s.status {
                "not_available" => "not yet available",
                other => other,
            };
            let _ = writeln!(t, "{:<8} {status}: {}", s.name, s.detail);
        }
        for s in notes {
            let _ = writeln!(t, "{:<8} note: {}", s.name, s.detail);
        }
        if !self.ratios.is_empty() {
            let _ = writeln!(t, "\nratios (same run):");
            for r in &self.ratios {
                let goal = match (r.goal, r.met) {
                    (Some(Goal::AtMost(x)), Some(m)) => {
                        format!("goal <= {x}: {}", if m { "met" } else { "NOT met" })
                    }
                    (Some(Goal::AtLeast(x)), Some(m)) => {
                        format!("goal >= {x}: {}", if m { "met" } else { "NOT met" })
                    }
                    _ => String::new(),
                };
                let value = if r.value < 0.1 {
                    format!("{:.4}", r.value)
                } else {
                    format!("{:.2}", r.value)
                };
                t.push_str(&format!(
                    "  {:<72} {:<15} {value:>8}  {goal}{}\n",
                    r.label,
                    r.strategy,
                    r.floor_note()
                ));
            }
        }
        if !self.time_goals.is_empty() {
            t.push_str("\ngoals in time (this machine, this run):\n");
            for g in &self.time_goals {
                let met = if g.met { "met" } else { "NOT met" };
                let x = |f: &TimeGoalFloor| g.ns as f64 / f.ns.max(1) as f64;
                let floor = match &g.floor {
                    Some(f) if f.ns > g.at_most_ns => {
                        format!(
                            " (the goal is below its floor: {} takes {}; {:.2}x it)",
                            f.what,
                            fmt_ns(f.ns),
                            x(f)
                        )
                    }
                    Some(f) => format!(" ({} takes {}; {:.2}x it)", f.what, fmt_ns(f.ns), x(f)),
                    None => " (no floor)".to_string(),
                };
                t.push_str(&format!(
                    "  {:<72} {:>24}  goal <= {}: {met}{floor}\n",
                    g.label,
                    fmt_ns(g.ns),
                    fmt_ns(g.at_most_ns)
                ));
            }
        }
        t.push_str(&crate::cpu::table(&self.cpu, |id| {
            let r = self.measurements.iter().find(|r| r.id == id)?;
            Some((r.summary.p50_ns, r.summary.p99_ns))
        }));
        t
    }

    /// Writes the JSON file.
    pub fn write_json(&self, path: &Path) -> Result<(), BenchError> {
        let text = serde_json::to_string_pretty(self)
            .map_err(|e| BenchError::io(path.display().to_string(), std::io::Error::other(e)))?;
        std::fs::write(path, text).map_err(|e| BenchError::io(path.display().to_string(), e))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::{Metric, Strategy, new_histogram};

    fn constant(id: &str, ns: u64) -> Measurement {
        let mut hist = new_histogram().expect("a histogram");
        for _ in 0..100 {
            hist.record(ns).expect("in range");
        }
        Measurement {
            scenario: "test",
            id: id.to_string(),
            label: id.to_string(),
            strategy: Strategy::Blocking,
            metric: Metric::RoundTrip,
            bytes: None,
            hist,
        }
    }

    /// The report of a run of `measurements`, and its bridge p50 goal.
    fn bridge_goal(measurements: Vec<Measurement>) -> Ratio {
        bridge_goal_at(measurements, Pct::P50)
    }

    /// The bridge's goal at `pct` in a run of `measurements`.
    fn bridge_goal_at(measurements: Vec<Measurement>, pct: Pct) -> Ratio {
        let report = Report::new(
            Machine::probe("off".into(), "test".into()),
            &BenchArgs::default(),
            Vec::new(),
            measurements,
        );
        report
            .ratios
            .into_iter()
            .find(|r| r.num == "bridge.zenoh.rtt" && r.den == "bridge.raw.put.rtt" && r.pct == pct)
            .expect("the bridge's goal")
    }

    /// The bridge's goal carries a floor made of its hops: raw Zenoh's round trip plus two
    /// raw iceoryx2 event round trips, over raw Zenoh's.
    #[test]
    fn a_floor_of_several_hops_adds_them_at_the_percentile() {
        let r = bridge_goal(vec![
            constant("bridge.zenoh.rtt", 300_000),
            constant("bridge.raw.put.rtt", 100_000),
            constant("state.paced.event.rtt", 25_000),
        ]);
        let (floor, what) = r.floor.expect("its floor");
        assert!((floor - 1.5).abs() < 0.01, "{floor}");
        assert!(what.contains("two raw iceoryx2 event round trips"));
        assert!(r.below_floor());
        assert!(
            r.floor_note().contains("the goal is below its floor"),
            "{}",
            r.floor_note()
        );
        // Without the iceoryx2 series in the run, no floor is claimed.
        let r = bridge_goal(vec![
            constant("bridge.zenoh.rtt", 300_000),
            constant("bridge.raw.put.rtt", 100_000),
        ]);
        assert!(r.floor.is_none());
    }

    /// A series of 100 samples: 98 of `p50`, 2 of `p99` (its 99th percentile).
    fn two_valued(id: &str, p50: u64, p99: u64) -> Measurement {
        let mut m = constant(id, p50);
        m.hist.reset();
        for i in 0..100 {
            m.hist
                .record(if i < 98 { p50 } else { p99 })
                .expect("in range");
        }
        m
    }

    /// A goal met past its floor (the floor composed of series measured at other moments,
    /// the bridge's) says so, not that the goal is below its floor.
    #[test]
    fn a_goal_met_past_its_floor_does_not_say_it_is_below_it() {
        let r = bridge_goal(vec![
            constant("bridge.zenoh.rtt", 125_000),
            constant("bridge.raw.put.rtt", 100_000),
            constant("state.paced.event.rtt", 25_000),
        ]);
        assert_eq!(r.met, Some(true));
        assert!(r.below_floor());
        let note = r.floor_note();
        assert!(!note.contains("the goal is below its floor"), "{note}");
        assert!(
            note.contains("met past that floor") && note.contains("1.50"),
            "{note}"
        );
    }

    /// At p99 the bridge's floor is raw Zenoh's p99 plus the two iceoryx2 round trips'
    /// medians (not their p99s, which would overstate it).
    #[test]
    fn the_bridges_p99_floor_adds_the_hops_at_their_median() {
        let r = bridge_goal_at(
            vec![
                two_valued("bridge.zenoh.rtt", 150_000, 280_000),
                two_valued("bridge.raw.put.rtt", 100_000, 200_000),
                two_valued("state.paced.event.rtt", 25_000, 100_000),
            ],
            Pct::P99,
        );
        assert!((r.value - 1.4).abs() < 0.01, "{}", r.value);
        let (floor, _) = r.floor.expect("its floor");
        assert!((floor - 1.25).abs() < 0.01, "{floor}");
        assert_eq!(r.met, Some(false));
        // Its floor is under the goal: not met, and not excused.
        assert!(!r.below_floor());
        assert!(
            !r.floor_note().contains("the goal is"),
            "{}",
            r.floor_note()
        );
    }

    /// A goal that a ratio must reach (TCP spin over limber's spin) is out of reach when
    /// the floors' own ratio (TCP spin over raw iceoryx2's) stays under it, and the report
    /// says so; one within reach only shows the floor.
    #[test]
    fn an_at_least_goal_over_its_floor_says_the_goal_is_above_it() {
        let ratio = |tcp: u64| {
            Report::new(
                Machine::probe("off".into(), "test".into()),
                &BenchArgs::default(),
                Vec::new(),
                vec![
                    constant("peers.tcp.spin.rtt", tcp),
                    constant("command.spin.rtt", 1_000),
                    constant("floor.spin2.rtt", 800),
                ],
            )
            .ratios
            .into_iter()
            .find(|r| r.num == "peers.tcp.spin.rtt" && r.den == "command.spin.rtt")
            .expect("the TCP spin goal")
        };
        let r = ratio(6_000);
        assert_eq!(r.met, Some(false));
        assert!(r.below_floor());
        assert!(
            r.floor_note().contains("the goal is above its floor")
                && r.floor_note().contains("7.50"),
            "{}",
            r.floor_note()
        );
        let r = ratio(12_000);
        assert_eq!(r.met, Some(true));
        assert!(!r.below_floor());
        assert!(
            !r.floor_note().contains("the goal is"),
            "{}",
            r.floor_note()
        );
    }
}
