//! CPU time of processes over a window: what a latency costs.
//!
//! A process's CPU time is `utime + stime` of `/proc/<pid>/stat` (fields 14 and 15, every
//! thread of the process, living or ended, in clock ticks of `USER_HZ`); its share of one
//! core over a window is the difference between two readings over the wall time between
//! them. A tick is 10 ms, so a window of a few seconds resolves a fraction of a percent.

use std::time::{Duration, Instant};

use serde::Serialize;
use thiserror::Error;

use crate::stats::fmt_ns;

/// Linux's `USER_HZ`, the unit of `/proc/<pid>/stat`'s times (`sysconf(_SC_CLK_TCK)`,
/// fixed at 100 by the kernel's user-space ABI on x86 and arm).
const USER_HZ: u64 = 100;

/// Reading a process's CPU time failed.
#[derive(Debug, Error)]
pub enum CpuError {
    /// `/proc/<pid>/stat` could not be read (the process has ended, or no procfs).
    #[error("cannot read /proc/{pid}/stat: {source}")]
    Read {
        /// The process.
        pid: u32,
        /// Why.
        #[source]
        source: std::io::Error,
    },
    /// Its contents were not as proc(5) describes them.
    #[error("/proc/{pid}/stat is malformed: {what}")]
    Malformed {
        /// The process.
        pid: u32,
        /// What was missing.
        what: &'static str,
    },
}

/// The CPU time (user + system, all threads) `pid` has used so far.
pub fn cpu_time(pid: u32) -> Result<Duration, CpuError> {
    let text = std::fs::read_to_string(format!("/proc/{pid}/stat"))
        .map_err(|source| CpuError::Read { pid, source })?;
    parse_stat(&text).ok_or(CpuError::Malformed {
        pid,
        what: "utime and stime",
    })
}

/// `utime + stime` of a `/proc/<pid>/stat` line. The command name (field 2) is in
/// parentheses and may hold spaces and parentheses itself: fields are counted after its
/// last `)`.
fn parse_stat(text: &str) -> Option<Duration> {
    let rest = &text[text.rfind(')')? + 1..];
    // After the name: state is field 3, utime field 14, stime field 15.
    let mut fields = rest.split_whitespace().skip(11);
    let utime: u64 = fields.next()?.parse().ok()?;
    let stime: u64 = fields.next()?.parse().ok()?;
    let ticks = utime + stime;
    Some(Duration::from_millis(ticks * 1000 / USER_HZ))
}

/// One process watched over a window.
#[derive(Debug, Clone)]
pub struct Watched {
    /// What it is (`driver`, `client`, `bridge expose`, ...).
    pub who: String,
    pid: u32,
    start: Duration,
}

/// CPU readings of several processes from one moment on.
#[derive(Debug)]
pub struct Window {
    started: Instant,
    watched: Vec<Watched>,
}

impl Window {
    /// Starts a window over `processes` (what each is, its pid).
    pub fn start(processes: &[(&str, u32)]) -> Result<Self, CpuError> {
        let watched = processes
            .iter()
            .map(|(who, pid)| {
                Ok(Watched {
                    who: (*who).to_string(),
                    pid: *pid,
                    start: cpu_time(*pid)?,
                })
            })
            .collect::<Result<Vec<_>, CpuError>>()?;
        Ok(Window {
            started: Instant::now(),
            watched,
        })
    }

    /// How long the window has been open.
    pub fn elapsed(&self) -> Duration {
        self.started.elapsed()
    }

    /// Ends the window: each process's share of one core, percent, in the order given.
    pub fn end(self) -> Result<Vec<(String, f64)>, CpuError> {
        let wall = self.started.elapsed().as_secs_f64().max(1e-9);
        self.watched
            .into_iter()
            .map(|w| {
                let used = cpu_time(w.pid)?.saturating_sub(w.start);
                Ok((w.who, used.as_secs_f64() / wall * 100.0))
            })
            .collect()
    }
}

/// CPU readings of several processes over several stretches of time, summed: what they
/// cost while one path ran, when its exchanges alternate with another path's (the
/// bridge's blocks between its floor's).
#[derive(Debug)]
pub struct Stretches {
    processes: Vec<(String, u32)>,
    used: Vec<Duration>,
    wall: Duration,
}

impl Stretches {
    /// Nothing measured yet, over `processes` (what each is, its pid).
    pub fn new(processes: &[(&str, u32)]) -> Self {
        Stretches {
            processes: processes
                .iter()
                .map(|(who, pid)| ((*who).to_string(), *pid))
                .collect(),
            used: vec![Duration::ZERO; processes.len()],
            wall: Duration::ZERO,
        }
    }

    /// Runs `stretch` and adds what each process used meanwhile.
    pub fn measure<T>(&mut self, stretch: impl FnOnce() -> T) -> Result<T, CpuError> {
        let before = self
            .processes
            .iter()
            .map(|(_, pid)| cpu_time(*pid))
            .collect::<Result<Vec<_>, CpuError>>()?;
        let started = Instant::now();
        let out = stretch();
        self.wall += started.elapsed();
        for ((used, (_, pid)), b) in self.used.iter_mut().zip(&self.processes).zip(before) {
            *used += cpu_time(*pid)?.saturating_sub(b);
        }
        Ok(out)
    }

    /// The stretches' wall time, summed.
    pub fn wall(&self) -> Duration {
        self.wall
    }

    /// Each process's share of one core over the stretches, percent, in the order given.
    pub fn shares(&self) -> Vec<(String, f64)> {
        let wall = self.wall.as_secs_f64().max(1e-9);
        self.processes
            .iter()
            .zip(&self.used)
            .map(|((who, _), used)| (who.clone(), used.as_secs_f64() / wall * 100.0))
            .collect()
    }
}

/// What a process cost in one state of a scenario, as reported.
#[derive(Debug, Clone, Serialize)]
pub struct CpuCost {
    /// A stable key, e.g. `cpu.event.idle.driver`.
    pub id: String,
    /// The scenario.
    pub scenario: &'static str,
    /// The mode or setup (`event-driven`, `linger`, `spin`, `bridge`).
    pub mode: String,
    /// `idle` or the load (`1 kHz commands`).
    pub load: String,
    /// The process (`driver`, `client`, `bridge expose`, `bridge mirror`).
    pub process: String,
    /// Share of one core, percent.
    pub percent: f64,
    /// The window's length, seconds.
    pub window_s: f64,
    /// The latency measured under this load, if any (a measurement id of the same run).
    pub latency_id: Option<String>,
    /// The most it may be, percent (a goal), if any.
    pub at_most_percent: Option<f64>,
}

impl CpuCost {
    /// Whether its goal is met (None without a goal).
    pub fn met(&self) -> Option<bool> {
        self.at_most_percent.map(|g| self.percent <= g)
    }
}

/// The CPU block of the terminal report: each process's share of one core per mode and
/// load, beside the latency of that load (`latency(id)`: p50 and p99, ns, of the same
/// run) and its goal; empty without costs.
pub fn table(costs: &[CpuCost], latency: impl Fn(&str) -> Option<(u64, u64)>) -> String {
    use std::fmt::Write as _;
    if costs.is_empty() {
        return String::new();
    }
    let mut t = String::from("\nCPU cost (share of one core, /proc/<pid>/stat over the window):\n");
    for c in costs {
        let latency = c
            .latency_id
            .as_deref()
            .and_then(&latency)
            .map(|(p50, p99)| format!("  latency p50 {} p99 {}", fmt_ns(p50), fmt_ns(p99)))
            .unwrap_or_default();
        let goal = match (c.at_most_percent, c.met()) {
            (Some(g), Some(m)) => format!("  goal <= {g} %: {}", if m { "met" } else { "NOT met" }),
            _ => String::new(),
        };
        writeln!(
            t,
            "  {:<14} {:<16} {:<14} {:>7.2} % ({:.1} s){latency}{goal}",
            c.mode, c.load, c.process, c.percent, c.window_s
        )
        .expect("writing to a String cannot fail");
    }
    t
}

/// Watches `processes` for `window`, sleeping meanwhile (the idle cost).
pub fn idle(processes: &[(&str, u32)], window: Duration) -> Result<Vec<(String, f64)>, CpuError> {
    let w = Window::start(processes)?;
    std::thread::sleep(window);
    w.end()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn utime_and_stime_are_read_after_the_command_name() {
        // A name with a space and a parenthesis; utime 250, stime 50 ticks = 3 s.
        let line = "4242 (a (b) c) S 1 4242 4242 0 -1 4194560 100 0 0 0 250 50 0 0 20 0 3 0 \
                    100 1000 10 18446744073709551615";
        assert_eq!(parse_stat(line), Some(Duration::from_secs(3)));
        assert_eq!(parse_stat("4242 (x) S 1"), None);
        assert_eq!(parse_stat("no name here"), None);
    }

    /// Only the stretches count: time between them (burning or not) is neither wall time
    /// nor use.
    #[test]
    fn stretches_count_only_what_ran_inside_them() {
        let me = std::process::id();
        let mut s = Stretches::new(&[("me", me)]);
        assert_eq!(s.shares(), vec![("me".to_string(), 0.0)]);
        let deadline = Instant::now() + Duration::from_secs(20);
        let mut x = 0u64;
        // Burning, in several stretches, until the kernel has charged a tick in one.
        while s.used[0].is_zero() && Instant::now() < deadline {
            s.measure(|| {
                let before = cpu_time(me).expect("cpu time");
                while cpu_time(me).expect("cpu time") == before && Instant::now() < deadline {
                    for _ in 0..100_000 {
                        x = x.wrapping_mul(6364136223846793005).wrapping_add(1);
                    }
                    std::hint::black_box(x);
                }
            })
            .expect("a stretch");
        }
        let wall = s.wall();
        assert!(!wall.is_zero());
        // Between stretches: not counted.
        let between = Instant::now();
        while between.elapsed() < Duration::from_millis(30) {
            std::hint::black_box(x.wrapping_add(1));
        }
        assert_eq!(s.wall(), wall, "time between stretches was counted");
        let got = s.shares();
        assert_eq!(got[0].0, "me");
        assert!(got[0].1 > 0.0, "{got:?}");
        let mut gone = Stretches::new(&[("none", u32::MAX)]);
        assert!(matches!(gone.measure(|| ()), Err(CpuError::Read { .. })));
    }

    #[test]
    fn this_process_burning_cpu_shows_in_its_window() {
        let me = std::process::id();
        let w = Window::start(&[("me", me)]).expect("window");
        let before = cpu_time(me).expect("cpu time");
        let deadline = Instant::now() + Duration::from_secs(20);
        let mut x = 0u64;
        // Busy until the kernel has charged this process a tick (or the deadline).
        while cpu_time(me).expect("cpu time") == before && Instant::now() < deadline {
            for _ in 0..100_000 {
                x = x.wrapping_mul(6364136223846793005).wrapping_add(1);
            }
            std::hint::black_box(x);
        }
        let got = w.end().expect("end");
        assert_eq!(got[0].0, "me");
        assert!(got[0].1 > 0.0, "{got:?}");
        assert!(matches!(cpu_time(u32::MAX), Err(CpuError::Read { .. })));
    }
}
