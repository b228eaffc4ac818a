//! A driver loop's timing without allocation: fixed rings of nanosecond samples (the
//! latest [`RING`]), their percentiles computed on a copy that lives on the stack, and the
//! timer cycles of a periodic loop ([`TickStats`]: cycles, overruns, periods, jitter).
//!
//! Every driver's loop keeps its tick timing here (the Pioneer driver and simarm publish it
//! on their `driver` channel, [`crate::diagnostics::put_loop`]), so that the period of one
//! driver's loop means what it means for every other.

use std::time::Instant;

/// Samples a [`Ring`] keeps: the latest 512 (5.12 s of a 10 ms loop).
pub const RING: usize = 512;

/// A fixed ring of nanosecond samples.
#[derive(Debug, Clone)]
pub struct Ring {
    samples: [u64; RING],
    len: usize,
    next: usize,
    max: u64,
}

impl Default for Ring {
    fn default() -> Self {
        Ring {
            samples: [0; RING],
            len: 0,
            next: 0,
            max: 0,
        }
    }
}

impl Ring {
    /// Adds a sample.
    pub fn push(&mut self, ns: u64) {
        self.samples[self.next] = ns;
        self.next = (self.next + 1) % RING;
        self.len = (self.len + 1).min(RING);
        self.max = self.max.max(ns);
    }

    /// The samples in the ring (the latest, at most [`RING`]), in no particular order.
    pub fn samples(&self) -> &[u64] {
        &self.samples[..self.len]
    }

    /// (p50, p99, max since start) of the samples in the ring; zeros when empty.
    pub fn summary(&self) -> (u64, u64, u64) {
        if self.len == 0 {
            return (0, 0, 0);
        }
        let mut copy = [0u64; RING];
        copy[..self.len].copy_from_slice(&self.samples[..self.len]);
        let s = &mut copy[..self.len];
        s.sort_unstable();
        let at = |q: f64| s[((q * (s.len() - 1) as f64).round() as usize).min(s.len() - 1)];
        (at(0.5), at(0.99), self.max)
    }
}

/// The timer cycles of a periodic loop.
#[derive(Debug, Clone, Default)]
pub struct TickStats {
    /// Cycles run.
    pub cycles: u64,
    /// Timer expirations missed (a cycle started more than a period late).
    pub overruns: u64,
    /// Periods between timer cycles, ns.
    pub period: Ring,
    /// |period − nominal|, ns.
    pub jitter: Ring,
    last_tick: Option<Instant>,
}

impl TickStats {
    /// Records a timer cycle at `now` with nominal period `nominal_ns`; `expirations` is
    /// the timer's count (more than 1: overrun).
    pub fn tick(&mut self, now: Instant, nominal_ns: u64, expirations: u64) {
        self.cycles += 1;
        self.overruns += expirations.saturating_sub(1);
        if let Some(prev) = self.last_tick {
            let p = now.duration_since(prev).as_nanos() as u64;
            self.period.push(p);
            self.jitter.push(p.abs_diff(nominal_ns));
        }
        self.last_tick = Some(now);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[test]
    fn ring_percentiles() {
        let mut r = Ring::default();
        assert_eq!(r.summary(), (0, 0, 0));
        for i in 1..=100 {
            r.push(i);
        }
        let (p50, p99, max) = r.summary();
        assert!((50..=51).contains(&p50));
        assert_eq!(p99, 99);
        assert_eq!(max, 100);
        for _ in 0..2000 {
            r.push(7);
        }
        assert_eq!(r.summary().0, 7);
        assert_eq!(r.summary().2, 100);
        assert_eq!(r.samples().len(), RING);
    }

    #[test]
    fn ticks_record_periods_jitter_and_overruns() {
        let mut t = TickStats::default();
        let t0 = Instant::now();
        let nominal = 10_000_000;
        t.tick(t0, nominal, 1);
        assert!(
            t.period.samples().is_empty(),
            "no period before a second tick"
        );
        t.tick(t0 + Duration::from_millis(10), nominal, 1);
        t.tick(t0 + Duration::from_millis(32), nominal, 2);
        assert_eq!(t.cycles, 3);
        assert_eq!(t.overruns, 1);
        let mut periods = t.period.samples().to_vec();
        periods.sort_unstable();
        assert_eq!(periods, vec![10_000_000, 22_000_000]);
        let mut jitter = t.jitter.samples().to_vec();
        jitter.sort_unstable();
        assert_eq!(jitter, vec![0, 12_000_000]);
    }
}
