//! IK solve-time measurement, for `limber bench ik` and the `ik_bench` example.
//!
//! Targets are the FK of deterministic random configurations inside the limits
//! (reachable by construction); each solve is timed alone with [`Instant`]. Target
//! generation and the result vectors allocate, outside the timed region. Numbers are
//! only meaningful in a release build.

use std::fmt;
use std::hint::black_box;
use std::time::Instant;

use super::chain::{Chain, DeterministicRng, IkTarget, NumericIkOptions};
use super::pioneer::{PioneerGeometry, PioneerIkOptions, Theta};

/// Solve-time percentiles of one solver, nanoseconds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Percentiles {
    /// Solves timed.
    pub samples: usize,
    /// Solves that succeeded.
    pub successes: usize,
    /// Median, ns.
    pub p50_ns: u64,
    /// 90th percentile, ns.
    pub p90_ns: u64,
    /// 99th percentile, ns.
    pub p99_ns: u64,
    /// 99.9th percentile, ns.
    pub p999_ns: u64,
    /// Slowest, ns.
    pub max_ns: u64,
}

impl Percentiles {
    /// Percentiles (nearest rank) of `times` (sorted in place).
    pub fn from_times(times: &mut [u64], successes: usize) -> Self {
        times.sort_unstable();
        let at = |q: f64| -> u64 {
            if times.is_empty() {
                return 0;
            }
            let rank = ((q * times.len() as f64).ceil() as usize).clamp(1, times.len());
            times[rank - 1]
        };
        Self {
            samples: times.len(),
            successes,
            p50_ns: at(0.50),
            p90_ns: at(0.90),
            p99_ns: at(0.99),
            p999_ns: at(0.999),
            max_ns: times.last().copied().unwrap_or(0),
        }
    }
}

impl fmt::Display for Percentiles {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "n={} ok={} p50={:.3}us p90={:.3}us p99={:.3}us p99.9={:.3}us max={:.3}us",
            self.samples,
            self.successes,
            self.p50_ns as f64 / 1e3,
            self.p90_ns as f64 / 1e3,
            self.p99_ns as f64 / 1e3,
            self.p999_ns as f64 / 1e3,
            self.max_ns as f64 / 1e3,
        )
    }
}

/// Timings of every solver.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct IkBenchReport {
    /// Pioneer closed form, SETPOSE (full pose), current joints = 0.
    pub pioneer_pose: Percentiles,
    /// Pioneer closed form, SETPOSITION keeping the current approach (often a search).
    pub pioneer_position: Percentiles,
    /// Numeric IK on the 6-joint chain, full pose, seeded at home.
    pub chain6_pose: Percentiles,
    /// Numeric IK on the 6-joint chain, position only, seeded at home.
    pub chain6_position: Percentiles,
    /// Numeric IK on the 7-joint chain, full pose, seeded at home.
    pub chain7_pose: Percentiles,
}

impl fmt::Display for IkBenchReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "pioneer closed form, pose     : {}", self.pioneer_pose)?;
        writeln!(
            f,
            "pioneer closed form, position : {}",
            self.pioneer_position
        )?;
        writeln!(f, "numeric 6-joint, pose         : {}", self.chain6_pose)?;
        writeln!(
            f,
            "numeric 6-joint, position     : {}",
            self.chain6_position
        )?;
        write!(f, "numeric 7-joint, pose         : {}", self.chain7_pose)
    }
}

fn time_all<T>(targets: &[T], mut solve: impl FnMut(&T) -> bool) -> Percentiles {
    let mut times = Vec::with_capacity(targets.len());
    let mut ok = 0;
    for t in targets {
        let start = Instant::now();
        let good = black_box(solve(black_box(t)));
        times.push(start.elapsed().as_nanos().min(u64::MAX as u128) as u64);
        ok += usize::from(good);
    }
    Percentiles::from_times(&mut times, ok)
}

/// Times `n` solves of each solver on reachable random targets (deterministic).
pub fn ik_solve_times(n: usize) -> IkBenchReport {
    let mut rng = DeterministicRng::new(0xB0A7_5EED);
    let geometry = PioneerGeometry::default();
    let popts = PioneerIkOptions::default();
    let zero: Theta = [0.0; 5];
    let pioneer_targets: Vec<_> = (0..n)
        .map(|_| {
            let theta: Theta = std::array::from_fn(|i| {
                rng.uniform(geometry.limits[i].min, geometry.limits[i].max)
            });
            geometry
                .fk(&theta)
                .unwrap_or_else(|_| super::Pose::identity())
        })
        .collect();
    let pioneer_pose = time_all(&pioneer_targets, |t| {
        geometry.solve_pose(t, &zero, &popts).is_ok()
    });
    let pioneer_position = time_all(&pioneer_targets, |t| {
        geometry
            .solve_position(
                &t.position,
                super::pioneer::ApproachPreference::Current,
                &zero,
                &popts,
            )
            .is_ok()
    });

    let copts = NumericIkOptions::default();
    let mut chain_targets = |chain: &Chain| -> Vec<super::Pose> {
        (0..n)
            .map(|_| {
                let q = chain.random_configuration(&mut rng);
                chain.fk(&q).unwrap_or_else(|_| super::Pose::identity())
            })
            .collect()
    };
    let c6 = Chain::default_6dof();
    let c7 = Chain::default_7dof();
    let t6 = chain_targets(&c6);
    let t7 = chain_targets(&c7);
    let h6 = c6.home();
    let h7 = c7.home();
    let chain6_pose = time_all(&t6, |t| c6.ik(&IkTarget::Pose(*t), &h6, &copts).is_ok());
    let chain6_position = time_all(&t6, |t| {
        c6.ik(&IkTarget::Position(t.position), &h6, &copts).is_ok()
    });
    let chain7_pose = time_all(&t7, |t| c7.ik(&IkTarget::Pose(*t), &h7, &copts).is_ok());
    IkBenchReport {
        pioneer_pose,
        pioneer_position,
        chain6_pose,
        chain6_position,
        chain7_pose,
    }
}
