//! A progress line on stderr, updated about 20 times per series (outside the timed
//! region of a sample: the caller ticks after recording).

use std::io::{IsTerminal, Write};

/// Writes one status line on stderr: the one place the bench speaks to its user while it
/// runs (progress, the files it wrote, a scenario that failed; the report goes to stdout).
/// A stderr that cannot be written (closed) loses the line, said at debug level: the run
/// goes on.
pub fn line(args: std::fmt::Arguments<'_>) {
    let mut e = std::io::stderr().lock();
    if let Err(err) = e.write_fmt(args).and_then(|()| e.write_all(b"\n")) {
        tracing::debug!(error = %err, "cannot write a status line on stderr");
    }
}

/// The progress of one series.
#[derive(Debug)]
pub struct Progress {
    label: String,
    total: u64,
    step: u64,
    enabled: bool,
    tty: bool,
}

impl Progress {
    /// Starts a series of `total` samples.
    pub fn new(enabled: bool, label: &str, total: u64) -> Self {
        let tty = std::io::stderr().is_terminal();
        let p = Progress {
            label: label.to_string(),
            total,
            step: (total / 20).max(1),
            enabled,
            tty,
        };
        if enabled && !tty {
            line(format_args!("  {label}: {total} samples"));
        }
        p
    }

    /// Reports that sample `i` (0-based) is done; prints only every 5 %.
    #[inline]
    pub fn tick(&self, i: u64) {
        if self.enabled && self.tty && i.is_multiple_of(self.step) {
            let mut e = std::io::stderr().lock();
            let _ = write!(
                e,
                "\r  {:<40} {:>3}% ",
                self.label,
                (i * 100 / self.total.max(1)).min(100)
            );
            let _ = e.flush();
        }
    }

    /// Ends the series.
    pub fn finish(&self) {
        if self.enabled && self.tty {
            line(format_args!("\r  {:<40} done ", self.label));
        }
    }
}
