//! A progress line on stderr, updated about 20 times per series (outside the timed
//! region of a sample: the caller ticks after recording).

use std::io::{IsTerminal, Write};

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
            eprintln!("  {label}: {total} samples");
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
            eprintln!("\r  {:<40} done ", self.label);
        }
    }
}
