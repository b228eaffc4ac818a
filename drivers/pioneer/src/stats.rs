//! Loop statistics without allocation: fixed rings of samples, percentiles computed once a
//! second on a copy that lives on the stack.

use std::time::Instant;

const RING: usize = 512;

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

    /// The samples in the ring (the latest, at most 512), in no particular order.
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

/// Timing of the driver loop.
#[derive(Debug, Clone, Default)]
pub struct LoopStats {
    /// Cycles run.
    pub cycles: u64,
    /// Timer expirations missed (a cycle started more than a period late).
    pub overruns: u64,
    /// Periods between timer cycles.
    pub period: Ring,
    /// |period − nominal|.
    pub jitter: Ring,
    /// Client send → bytes on the wire.
    pub cmd_to_wire: Ring,
    /// Command taken from the channel → bytes on the wire: the driver's own cost
    /// (validation, IK, encoding, the write), without the way from the client.
    pub arrival_to_wire: Ring,
    /// Inside `arrival_to_wire`, the link's send alone (encoding and `write(2)`): what
    /// the kernel takes. On a busy core it includes what the kernel runs as the write
    /// returns (a pty's write wakes the tty's buffer worker, which may take the core
    /// before the driver reads its clock).
    pub link_write: Ring,
    /// Inside `arrival_to_wire`, what comes before the link's send: the driver's own work
    /// (taking the command, validation, IK, the handler), without encoding and `write(2)`.
    pub arrival_to_send: Ring,
    last_tick: Option<Instant>,
    /// SIPs counted in the current second.
    pub sips_this_second: u64,
    /// SIPs in the last full second.
    pub sips_per_s: f64,
    second_start: Option<Instant>,
}

impl LoopStats {
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
        let start = *self.second_start.get_or_insert(now);
        let el = now.duration_since(start).as_secs_f64();
        if el >= 1.0 {
            self.sips_per_s = self.sips_this_second as f64 / el;
            self.sips_this_second = 0;
            self.second_start = Some(now);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
    }
}
