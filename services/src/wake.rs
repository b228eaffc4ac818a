//! The state's wake word: one futex in shared memory per device, bumped by the driver
//! each time it publishes a state, on which the clients that wait for a state
//! ([`crate::Client::wait_state`]) sleep.
//!
//! Why not the device's iceoryx2 event alone: iceoryx2 0.10 notifies each listener with a
//! datagram of its own, one system call and one wake-up per listener, in turn; a futex
//! wakes every sleeper with one call, and a sleeper wakes sooner (`limber bench --only
//! state`: the futex and iceoryx2 event wakes paced at 1 kHz, side by side). A driver
//! bumps the word and notifies the event as before: clients that wait on the event (for
//! an outcome, a reply, or through `limber_device_fd`) are woken as they were.
//!
//! The word is a file in `/dev/shm` named with the domain's prefix
//! (`<prefix><robot>.<interface>.<index>.wake`, one page, mode 0600; in group mode the
//! domain's files are opened to the group as they appear, see [`crate::domain::group`]):
//! the prefix holds the domain's secret token, so nobody outside the domain can guess the
//! name, and `limber clean` removes it with the domain's other files. A file found there
//! that is not ours (or, in group mode, the group's) is refused, as every file of a domain
//! is ([`crate::domain::dir`]); the driver then works without a word and its clients wait
//! on the event. A driver that starts again opens the same file, so a client that waits
//! on it keeps waiting on the word the new driver bumps.
//!
//! Everything in the page is an atomic integer that any process of the domain may write;
//! a wrong value there costs a spurious wake-up or a missed one, and a client's wait is
//! bounded by its liveness check ([`crate::client::LIVENESS_PERIOD`]) either way.

use core::ptr::NonNull;
use core::sync::atomic::{AtomicU32, Ordering};
use core::time::Duration;
use std::fs::{File, OpenOptions};
use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
use std::path::{Path, PathBuf};

use rustix::thread::futex;
use thiserror::Error;

use crate::domain::Domain;
use crate::domain::dir::{self, DomainError, IoError};
use crate::naming::DeviceName;

/// The size of the word's file: one page.
const PAGE: u64 = 4096;

/// The layout at the start of the page.
#[repr(C)]
struct Word {
    /// Bumped by every state the driver publishes; the futex.
    seq: AtomicU32,
    /// How many clients sleep on `seq` (or are about to): the driver makes the wake-up
    /// system call only when it is not zero.
    sleepers: AtomicU32,
}

/// Opening a device's wake word failed.
#[derive(Debug, Error)]
pub enum WakeError {
    /// The domain's files could not be prepared, or the file is not the domain's (another
    /// user's: refused, as every file of a domain that is not ours).
    #[error(transparent)]
    Domain(#[from] DomainError),
    /// The file could not be opened, sized or mapped.
    #[error("cannot {what} {}: {source}", path.display())]
    Io {
        /// What was done.
        what: &'static str,
        /// The file.
        path: PathBuf,
        /// The system's error.
        #[source]
        source: IoError,
    },
    /// There is no word for the device (yet): its driver has not made one.
    #[error("{} does not exist (yet)", path.display())]
    Absent {
        /// The file.
        path: PathBuf,
    },
}

/// A device's wake word, mapped.
pub(crate) struct WakeWord {
    word: NonNull<Word>,
    path: PathBuf,
}

impl core::fmt::Debug for WakeWord {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("WakeWord")
            .field("path", &self.path)
            .finish()
    }
}

impl Domain {
    /// The file of `device`'s wake word in this domain, a futex its driver bumps with
    /// every state and on which [`crate::Client::wait_state`] sleeps:
    /// `/dev/shm/<prefix><robot>.<interface>.<index>.wake`.
    pub fn wake_word_path(&self, device: &DeviceName) -> Result<PathBuf, DomainError> {
        let name = format!(
            "{}{}.wake",
            self.prefix()?,
            device.to_string().replace('/', ".")
        );
        Ok(Path::new(dir::SHM_DIR).join(name))
    }
}

impl WakeWord {
    /// The driver's side: opens `device`'s word in `domain`, creating it if missing.
    pub(crate) fn create(domain: &Domain, device: &DeviceName) -> Result<Self, WakeError> {
        Self::open_at(domain.wake_word_path(device)?, true, domain)
    }

    /// A client's side: opens `device`'s word, which its driver made.
    pub(crate) fn open(domain: &Domain, device: &DeviceName) -> Result<Self, WakeError> {
        Self::open_at(domain.wake_word_path(device)?, false, domain)
    }

    fn open_at(path: PathBuf, create: bool, domain: &Domain) -> Result<Self, WakeError> {
        let io = |what: &'static str, path: &Path| {
            let path = path.to_path_buf();
            move |e: std::io::Error| WakeError::Io {
                what,
                path,
                source: e.into(),
            }
        };
        let file = match OpenOptions::new()
            .read(true)
            .write(true)
            .create(create)
            .mode(0o600)
            .custom_flags(libc::O_NOFOLLOW)
            .open(&path)
        {
            Ok(f) => f,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                return Err(WakeError::Absent { path });
            }
            Err(e) => return Err(io("open", &path)(e)),
        };
        let md = file.metadata().map_err(io("inspect", &path))?;
        dir::check_trusted(&path, &md, domain.group()?)?;
        if !md.is_file() {
            return Err(io("use", &path)(std::io::Error::new(
                std::io::ErrorKind::InvalidInput,
                "not a regular file",
            )));
        }
        if md.size() < PAGE {
            if !create {
                // Being made by its driver: not there yet.
                return Err(WakeError::Absent { path });
            }
            file.set_len(PAGE).map_err(io("size", &path))?;
        }
        if create {
            // The page itself, now: a page of tmpfs that cannot be had when it is first
            // written kills the writer (SIGBUS); here it is an error (`/dev/shm` full).
            rustix::fs::fallocate(&file, rustix::fs::FallocateFlags::empty(), 0, PAGE)
                .map_err(|e| io("allocate", &path)(e.into()))?;
        }
        let word = map(&file).map_err(io("map", &path))?;
        Ok(Self { word, path })
    }

    fn word(&self) -> &Word {
        // SAFETY: `word` points at the start of a live shared mapping of PAGE bytes (made
        // in `map`, unmapped only in `drop`), page-aligned, which holds only atomics: other
        // processes writing it concurrently is what atomics allow.
        unsafe { self.word.as_ref() }
    }

    /// The driver published a state: bumps the word and wakes every client that sleeps on
    /// it (one system call, made only when a client sleeps).
    pub(crate) fn bump(&self) {
        let w = self.word();
        // SeqCst on both sides (here and in `wait`): either the client sees the new value
        // before it sleeps, or this sees the client's sleeper count and wakes it.
        w.seq.fetch_add(1, Ordering::SeqCst);
        if w.sleepers.load(Ordering::SeqCst) != 0
            && let Err(e) = futex::wake(&w.seq, futex::Flags::empty(), i32::MAX as u32)
        {
            tracing::debug!(path = %self.path.display(), error = %e, "cannot wake the clients");
        }
    }

    /// The word's value now: read it before looking for a state, then [`WakeWord::wait`]
    /// with it.
    pub(crate) fn seen(&self) -> u32 {
        self.word().seq.load(Ordering::SeqCst)
    }

    /// Sleeps until the word is no longer `seen` (a state was published since it was
    /// read), `timeout` passed, or a signal came; returns at once if it changed already.
    pub(crate) fn wait(&self, seen: u32, timeout: Duration) {
        let w = self.word();
        w.sleepers.fetch_add(1, Ordering::SeqCst);
        if w.seq.load(Ordering::SeqCst) == seen {
            let ts = rustix::time::Timespec {
                tv_sec: i64::try_from(timeout.as_secs()).unwrap_or(i64::MAX),
                tv_nsec: i64::from(timeout.subsec_nanos()),
            };
            // EAGAIN (it changed), ETIMEDOUT and EINTR all mean: look again.
            if let Err(e) = futex::wait(&w.seq, futex::Flags::empty(), seen, Some(&ts))
                && !matches!(
                    e,
                    rustix::io::Errno::AGAIN
                        | rustix::io::Errno::TIMEDOUT
                        | rustix::io::Errno::INTR
                )
            {
                tracing::debug!(path = %self.path.display(), error = %e, "cannot sleep on the wake word");
            }
        }
        w.sleepers.fetch_sub(1, Ordering::SeqCst);
    }
}

/// Maps the first page of `file`, shared.
fn map(file: &File) -> std::io::Result<NonNull<Word>> {
    // SAFETY: a new mapping (the kernel picks the address) of PAGE bytes of a file that has
    // at least that many (checked or set by the caller); `file` may be closed afterwards,
    // the mapping stays until `WakeWord::drop` unmaps it.
    let p = unsafe {
        rustix::mm::mmap(
            core::ptr::null_mut(),
            PAGE as usize,
            rustix::mm::ProtFlags::READ | rustix::mm::ProtFlags::WRITE,
            rustix::mm::MapFlags::SHARED,
            file,
            0,
        )
    }?;
    NonNull::new(p.cast::<Word>()).ok_or_else(|| std::io::Error::other("mmap returned null"))
}

impl Drop for WakeWord {
    fn drop(&mut self) {
        // SAFETY: the mapping made in `map`, of PAGE bytes; nothing refers to it after this
        // (`word()` borrows `self`).
        if let Err(e) = unsafe { rustix::mm::munmap(self.word.as_ptr().cast(), PAGE as usize) } {
            tracing::warn!(path = %self.path.display(), error = %e, "cannot unmap the wake word");
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;
    use std::sync::atomic::AtomicBool;
    use std::time::Instant;

    fn device() -> DeviceName {
        "waketest/actarray/0".parse().expect("a valid name")
    }

    #[test]
    fn a_client_cannot_open_a_word_its_driver_did_not_make() {
        let domain = Domain::unique_for_test();
        assert!(matches!(
            WakeWord::open(&domain, &device()),
            Err(WakeError::Absent { .. })
        ));
        let _driver = WakeWord::create(&domain, &device()).expect("created");
        WakeWord::open(&domain, &device()).expect("opened once made");
    }

    #[test]
    fn a_bump_wakes_a_sleeper_and_a_changed_word_does_not_sleep() {
        let domain = Domain::unique_for_test();
        let driver = WakeWord::create(&domain, &device()).expect("created");
        let client = WakeWord::open(&domain, &device()).expect("opened");
        let seen = client.seen();
        driver.bump();
        // Changed since `seen`: returns at once (a 60 s timeout would fail the test).
        let t = Instant::now();
        client.wait(seen, Duration::from_secs(60));
        assert!(
            t.elapsed() < Duration::from_secs(30),
            "slept on a changed word"
        );
        assert_eq!(client.seen(), seen.wrapping_add(1));

        // A sleeper in another thread (its own mapping, as another process has), woken by
        // bumps until it saw one.
        let done = Arc::new(AtomicBool::new(false));
        let d2 = Arc::clone(&done);
        let dom2 = domain.clone();
        let sleeper = std::thread::spawn(move || {
            let w = WakeWord::open(&dom2, &device()).expect("opened");
            let seen = w.seen();
            while w.seen() == seen {
                w.wait(seen, Duration::from_secs(60));
            }
            d2.store(true, Ordering::SeqCst);
        });
        let deadline = Instant::now() + Duration::from_secs(20);
        while !done.load(Ordering::SeqCst) {
            assert!(Instant::now() < deadline, "the sleeper was never woken");
            driver.bump();
            std::thread::yield_now();
        }
        sleeper.join().expect("the sleeper ended");
        assert_eq!(driver.word().sleepers.load(Ordering::SeqCst), 0);
    }
}
