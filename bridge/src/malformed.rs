//! Malformed messages from the network (a command, request or lease request of the wrong
//! size, or without a valid origin), logged without flooding the log: the first one with
//! its details, then a count. A remote peer that sends thousands of them (a bug, an old
//! client, an attack) costs one line every [`SUMMARY_PERIOD`], not one line each.
//!
//! One count per process: what it limits is this process's log.

use std::sync::Mutex;
use std::time::{Duration, Instant};

/// At most one summary line per this period while malformed messages keep coming.
pub(crate) const SUMMARY_PERIOD: Duration = Duration::from_secs(10);

#[derive(Debug, Default)]
struct Count {
    /// Malformed messages since the bridge started.
    total: u64,
    /// Of which not yet in a log line.
    unreported: u64,
    /// When the last line about them was logged (none yet: the next one is logged).
    last_line: Option<Instant>,
    /// What the latest one was (for the summary).
    latest: String,
}

static COUNT: Mutex<Count> = Mutex::new(Count {
    total: 0,
    unreported: 0,
    last_line: None,
    latest: String::new(),
});

fn count() -> std::sync::MutexGuard<'static, Count> {
    // A panic while holding it leaves only counters behind: still usable.
    COUNT.lock().unwrap_or_else(|e| e.into_inner())
}

/// A malformed message for `device` from `origin` arrived and was dropped or refused:
/// `what` says what was wrong and what was done ("a command of the wrong size (...):
/// dropped"). Logged if it is the first, counted otherwise ([`summarise_if_due`]).
pub(crate) fn note(device: &dyn std::fmt::Display, origin: &str, what: &str) {
    let mut c = count();
    c.total += 1;
    let now = Instant::now();
    match c.last_line {
        None => {
            c.last_line = Some(now);
            tracing::warn!(
                device = %device,
                origin,
                "{what} (further malformed messages are counted, summarised at most every {} s)",
                SUMMARY_PERIOD.as_secs()
            );
        }
        Some(_) => {
            c.unreported += 1;
            c.latest = format!("{what} ({device}, from {origin})");
            summarise(&mut c, now, false);
        }
    }
}

/// Logs the count of malformed messages not yet reported, if the last line about them is
/// [`SUMMARY_PERIOD`] old (called from the bridge's loop).
pub(crate) fn summarise_if_due() {
    summarise(&mut count(), Instant::now(), false);
}

/// Logs the count of malformed messages not yet reported, now (when the bridge ends).
pub(crate) fn summarise_now() {
    summarise(&mut count(), Instant::now(), true);
}

fn summarise(c: &mut Count, now: Instant, force: bool) {
    if c.unreported == 0 {
        return;
    }
    let due = c
        .last_line
        .is_none_or(|t| now.duration_since(t) >= SUMMARY_PERIOD);
    if !(due || force) {
        return;
    }
    tracing::warn!(
        "{} more malformed messages dropped or refused ({} in all); the latest: {}",
        c.unreported,
        c.total,
        c.latest
    );
    c.unreported = 0;
    c.last_line = Some(now);
}
