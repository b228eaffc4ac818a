//! Measurements and their summaries.
//!
//! Every sample is recorded (nanoseconds) into an [`hdrhistogram::Histogram`] with 3
//! significant digits, from 1 ns to 100 s; values above that saturate. The summary gives
//! count, mean, standard deviation, p50, p90, p99, p99.9, max, and the **jitter, defined
//! here as p99 − p50** (the spread a control loop must budget for above the typical
//! latency; the standard deviation is reported too but is dominated by rare outliers).

use hdrhistogram::Histogram;
use serde::Serialize;

use crate::BenchError;

/// Highest value a histogram tracks, ns (100 s).
pub const MAX_TRACKED_NS: u64 = 100_000_000_000;

/// A new, empty latency histogram (no allocation when recording afterwards).
pub fn new_histogram() -> Result<Histogram<u64>, BenchError> {
    Histogram::new_with_bounds(1, MAX_TRACKED_NS, 3)
        .map_err(|e| BenchError::Histogram(e.to_string()))
}

/// How the two sides wait.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Strategy {
    /// Both sides busy-poll (one core each).
    Spin,
    /// Both sides block in the kernel (event, socket read) until woken.
    Blocking,
    /// No exchange: computation time in one process.
    Compute,
}

impl Strategy {
    /// The lowercase name.
    pub fn name(self) -> &'static str {
        match self {
            Strategy::Spin => "spin",
            Strategy::Blocking => "blocking",
            Strategy::Compute => "compute",
        }
    }
}

/// What one sample is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Metric {
    /// Send → the answer is seen by the sender (one clock, one process).
    RoundTrip,
    /// Sender's stamp → receiver's clock (`CLOCK_MONOTONIC`, across processes).
    OneWay,
    /// Time of one computation.
    Solve,
    /// Time of one local read (the latest state from shared memory into the program).
    Read,
    /// Time between two successive events of one periodic loop (or its deviation).
    Period,
}

impl Metric {
    /// A short name.
    pub fn name(self) -> &'static str {
        match self {
            Metric::RoundTrip => "round trip",
            Metric::OneWay => "one-way",
            Metric::Solve => "solve",
            Metric::Read => "read",
            Metric::Period => "period",
        }
    }
}

/// One measured series.
#[derive(Debug, Clone)]
pub struct Measurement {
    /// The scenario that produced it (`floor`, `state`, ...).
    pub scenario: &'static str,
    /// A stable key, e.g. `command.spin.oneway` (used by the ratios and in the JSON).
    pub id: String,
    /// A human label, e.g. `command client→driver`.
    pub label: String,
    /// How the sides waited.
    pub strategy: Strategy,
    /// What a sample is.
    pub metric: Metric,
    /// Payload bytes each way, if any (command bytes, reply bytes).
    pub bytes: Option<(usize, usize)>,
    /// Every sample, ns.
    pub hist: Histogram<u64>,
}

/// The summary of a measurement, ns.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Default)]
pub struct Summary {
    /// Samples.
    pub count: u64,
    /// Mean.
    pub mean_ns: f64,
    /// Standard deviation.
    pub stddev_ns: f64,
    /// Smallest.
    pub min_ns: u64,
    /// Median.
    pub p50_ns: u64,
    /// 90th percentile.
    pub p90_ns: u64,
    /// 99th percentile.
    pub p99_ns: u64,
    /// 99.9th percentile.
    pub p999_ns: u64,
    /// Largest.
    pub max_ns: u64,
    /// p99 − p50.
    pub jitter_ns: u64,
}

impl Summary {
    /// Summarises a histogram.
    pub fn of(h: &Histogram<u64>) -> Self {
        if h.is_empty() {
            return Summary::default();
        }
        let p50 = h.value_at_quantile(0.5);
        let p99 = h.value_at_quantile(0.99);
        Summary {
            count: h.len(),
            mean_ns: h.mean(),
            stddev_ns: h.stdev(),
            min_ns: h.min(),
            p50_ns: p50,
            p90_ns: h.value_at_quantile(0.9),
            p99_ns: p99,
            p999_ns: h.value_at_quantile(0.999),
            max_ns: h.max(),
            jitter_ns: p99.saturating_sub(p50),
        }
    }
}

/// Formats ns for a table: `812ns`, `1.23us`, `45.6us`, `1.20ms`, `2.50s`.
pub fn fmt_ns(ns: u64) -> String {
    let v = ns as f64;
    if ns < 1_000 {
        format!("{ns}ns")
    } else if ns < 1_000_000 {
        if v < 10_000.0 {
            format!("{:.2}us", v / 1e3)
        } else {
            format!("{:.1}us", v / 1e3)
        }
    } else if ns < 1_000_000_000 {
        format!("{:.2}ms", v / 1e6)
    } else {
        format!("{:.2}s", v / 1e9)
    }
}

/// Serialises a histogram (hdrhistogram V2 format) for a child to hand it to the parent.
pub fn serialize(h: &Histogram<u64>) -> Result<Vec<u8>, BenchError> {
    use hdrhistogram::serialization::{Serializer, V2Serializer};
    let mut out = Vec::new();
    V2Serializer::new()
        .serialize(h, &mut out)
        .map_err(|e| BenchError::Histogram(e.to_string()))?;
    Ok(out)
}

/// Reads back a histogram written by [`serialize`].
pub fn deserialize(bytes: &[u8]) -> Result<Histogram<u64>, BenchError> {
    use hdrhistogram::serialization::Deserializer;
    let mut cursor = std::io::Cursor::new(bytes);
    Deserializer::new()
        .deserialize(&mut cursor)
        .map_err(|e| BenchError::Histogram(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn summary_and_roundtrip() {
        let mut h = new_histogram().unwrap();
        for v in 1..=1000u64 {
            h.record(v * 100).unwrap();
        }
        let s = Summary::of(&h);
        assert_eq!(s.count, 1000);
        assert!(s.p50_ns <= s.p90_ns && s.p90_ns <= s.p99_ns && s.p99_ns <= s.max_ns);
        assert_eq!(s.jitter_ns, s.p99_ns - s.p50_ns);
        let back = deserialize(&serialize(&h).unwrap()).unwrap();
        assert_eq!(Summary::of(&back), s);
        assert_eq!(Summary::of(&new_histogram().unwrap()).count, 0);
        assert_eq!(fmt_ns(812), "812ns");
        assert_eq!(fmt_ns(1_234), "1.23us");
        assert_eq!(fmt_ns(1_200_000), "1.20ms");
    }
}
