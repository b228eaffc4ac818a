//! Whether a domain may have changed since `expose` last listed it, so that an idle bridge
//! lists the domain only when something came or went.
//!
//! Listing a domain ([`limber_services::list_devices`]) reads and parses the static file of
//! every service under iceoryx2's root (those of every domain of the user) and probes the
//! nodes of every device: when idle, the exposing bridge's main cost if done once a second.
//! A device appears through new files: its services' static files in iceoryx2's service
//! directory and its driver's node in the node directory. A file created or removed in a
//! directory changes the directory's modification time, so the listing is needed only when
//! either time changed since the last listing, with two margins:
//!
//! * **settling**: a service being made may be listed half-made (skipped); a listing that
//!   saw a change younger than [`SETTLE`] is repeated at the next look even without a new
//!   change;
//! * **a full listing at least every [`FULL_EVERY`]**, whatever the times say (a driver
//!   that comes back into service files that stayed, a file system without fine times).
//!
//! [`DirWatch::force`] asks for a listing at the next look (a device was withdrawn: its
//! driver may come back into the same files).

use std::path::PathBuf;
use std::time::{Duration, Instant, SystemTime};

use limber_services::Domain;

/// How old a directory's change must be for a listing to have seen its result whole.
pub const SETTLE: Duration = Duration::from_secs(1);
/// The longest time without a full listing.
pub const FULL_EVERY: Duration = Duration::from_secs(10);

/// The directories watched, and what the last listing saw.
#[derive(Debug)]
pub struct DirWatch {
    dirs: Vec<PathBuf>,
    /// The directories' times at the last listing (None: unknown, list).
    seen: Option<Vec<SystemTime>>,
    /// The last listing saw a change younger than [`SETTLE`]: list again.
    unsettled: bool,
    /// When the last listing was.
    listed: Option<Instant>,
}

impl DirWatch {
    /// Watches the service and node directories of `domain`'s iceoryx2 files. A domain
    /// whose configuration cannot be read is listed every time (the listing reports why).
    pub fn new(domain: &Domain) -> Self {
        let dirs = match domain.config() {
            Ok(c) => vec![
                PathBuf::from(c.global.service_dir().as_str()),
                PathBuf::from(c.global.node_dir().as_str()),
            ],
            Err(e) => {
                tracing::debug!(error = %e, "no domain configuration: listing every time");
                Vec::new()
            }
        };
        Self::of(dirs)
    }

    /// Watches `dirs`.
    pub fn of(dirs: Vec<PathBuf>) -> Self {
        DirWatch {
            dirs,
            seen: None,
            unsettled: false,
            listed: None,
        }
    }

    /// Asks for a listing at the next look.
    pub fn force(&mut self) {
        self.seen = None;
    }

    /// Whether to list now; when it says yes, the caller lists (this counts as a listing).
    pub fn should_list(&mut self, now: Instant) -> bool {
        let times = self.times();
        let due = match (&times, &self.seen, self.listed) {
            (Some(t), Some(s), Some(at)) => {
                t != s || self.unsettled || now.duration_since(at) >= FULL_EVERY
            }
            _ => true,
        };
        if due {
            let wall = SystemTime::now();
            self.unsettled = times.as_ref().is_none_or(|t| {
                t.iter()
                    .any(|m| wall.duration_since(*m).map_or(true, |age| age < SETTLE))
            });
            self.seen = times;
            self.listed = Some(now);
        }
        due
    }

    /// The directories' modification times, or None when one cannot be read.
    fn times(&self) -> Option<Vec<SystemTime>> {
        if self.dirs.is_empty() {
            return None;
        }
        self.dirs
            .iter()
            .map(|d| match std::fs::metadata(d).and_then(|m| m.modified()) {
                Ok(t) => Some(t),
                Err(e) => {
                    tracing::debug!(dir = %d.display(), error = %e, "cannot read the time of a domain directory");
                    None
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dir(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!(
            "limber-dirwatch-{}-{tag}-{}",
            std::process::id(),
            limber_services::monotonic_ns()
        ));
        std::fs::create_dir_all(&d).expect("make the directory");
        d
    }

    /// Sets the directory's time `age` into the past, as if its last change were that old.
    fn age(d: &std::path::Path, age: Duration) {
        let t = SystemTime::now() - age;
        std::fs::File::open(d)
            .and_then(|f| f.set_modified(t))
            .expect("set the directory's time");
    }

    #[test]
    fn lists_first_then_only_after_a_change_or_when_unsettled() {
        let d = dir("a");
        age(&d, Duration::from_secs(60));
        let mut w = DirWatch::of(vec![d.clone()]);
        let t0 = Instant::now();
        assert!(w.should_list(t0), "the first look lists");
        assert!(!w.should_list(t0), "nothing changed, settled");
        // A file comes: the directory's time changes, and the change is young.
        std::fs::write(d.join("svc"), b"x").expect("write");
        assert!(w.should_list(t0), "a file came");
        assert!(
            w.should_list(t0),
            "the change was younger than SETTLE: again"
        );
        age(&d, Duration::from_secs(60));
        assert!(w.should_list(t0), "the time changed (set back)");
        assert!(!w.should_list(t0), "settled now");
        // A file goes.
        std::fs::remove_file(d.join("svc")).expect("remove");
        assert!(w.should_list(t0), "a file went");
        age(&d, Duration::from_secs(60));
        assert!(w.should_list(t0));
        assert!(!w.should_list(t0));
        w.force();
        assert!(w.should_list(t0), "forced");
        assert!(!w.should_list(t0));
        assert!(
            w.should_list(t0 + FULL_EVERY),
            "a full listing every FULL_EVERY"
        );
        assert!(!w.should_list(t0 + FULL_EVERY));
        std::fs::remove_dir_all(&d).expect("remove the test's directory");
    }

    #[test]
    fn an_unreadable_directory_lists_every_time() {
        let d = dir("b");
        std::fs::remove_dir_all(&d).expect("remove");
        let mut w = DirWatch::of(vec![d]);
        let t0 = Instant::now();
        assert!(w.should_list(t0));
        assert!(w.should_list(t0));
        let mut none = DirWatch::of(Vec::new());
        assert!(none.should_list(t0));
        assert!(none.should_list(t0));
    }
}
