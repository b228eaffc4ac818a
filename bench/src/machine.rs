//! The machine header printed above every report: numbers mean nothing without it.

use serde::Serialize;

/// What the benchmarks ran on.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Machine {
    /// CPU model (`model name` in /proc/cpuinfo).
    pub cpu: String,
    /// Cores this process may run on.
    pub cores: usize,
    /// Kernel (`uname -srm`).
    pub kernel: String,
    /// Load average over 1, 5, 15 minutes when the run started.
    pub load_avg: [f64; 3],
    /// Pinning in effect.
    pub pinning: String,
    /// Build profile of the benchmark binary (`release` or `debug`: debug numbers are
    /// meaningless).
    pub build: String,
    /// Seconds since the Unix epoch when the run started.
    pub started_unix_s: u64,
    /// Sample counts: `default`, `quick`, with the scale factor.
    pub mode: String,
}

impl Machine {
    /// Reads the machine's description; missing files give `unknown`.
    pub fn probe(pinning: String, mode: String) -> Self {
        let cpu = std::fs::read_to_string("/proc/cpuinfo")
            .ok()
            .and_then(|s| {
                s.lines()
                    .find(|l| l.starts_with("model name"))
                    .and_then(|l| l.split_once(':'))
                    .map(|(_, v)| v.trim().to_string())
            })
            .unwrap_or_else(|| "unknown".into());
        let load_avg = std::fs::read_to_string("/proc/loadavg")
            .ok()
            .map(|s| {
                let mut it = s
                    .split_whitespace()
                    .map(|v| v.parse::<f64>().unwrap_or(-1.0));
                [
                    it.next().unwrap_or(-1.0),
                    it.next().unwrap_or(-1.0),
                    it.next().unwrap_or(-1.0),
                ]
            })
            .unwrap_or([-1.0; 3]);
        Machine {
            cpu,
            cores: std::thread::available_parallelism()
                .map(|n| n.get())
                .unwrap_or(1),
            kernel: uname(),
            load_avg,
            pinning,
            build: if cfg!(debug_assertions) {
                "debug".into()
            } else {
                "release".into()
            },
            started_unix_s: std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map(|d| d.as_secs())
                .unwrap_or(0),
            mode,
        }
    }

    /// The header lines.
    pub fn header(&self) -> String {
        format!(
            "machine: {} | {} cores | {} | load {:.2} {:.2} {:.2} | pinning: {} | {} build | {}\n",
            self.cpu,
            self.cores,
            self.kernel,
            self.load_avg[0],
            self.load_avg[1],
            self.load_avg[2],
            self.pinning,
            self.build,
            self.mode
        )
    }
}

fn uname() -> String {
    let u = rustix::system::uname();
    format!(
        "{} {} {}",
        u.sysname().to_string_lossy(),
        u.release().to_string_lossy(),
        u.machine().to_string_lossy()
    )
}
