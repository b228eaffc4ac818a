//! The Pioneer loop's statistics without allocation: its timer cycles (the
//! [`TickStats`] every driver keeps) and the latencies of its commands to the wire.

use std::time::Instant;

pub use limber_services::loop_stats::{Ring, TickStats};

/// Timing of the driver loop.
#[derive(Debug, Clone, Default)]
pub struct LoopStats {
    /// The timer cycles: periods, jitter, overruns.
    pub ticks: TickStats,
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
        self.ticks.tick(now, nominal_ns, expirations);
        let start = *self.second_start.get_or_insert(now);
        let el = now.duration_since(start).as_secs_f64();
        if el >= 1.0 {
            self.sips_per_s = self.sips_this_second as f64 / el;
            self.sips_this_second = 0;
            self.second_start = Some(now);
        }
    }
}
