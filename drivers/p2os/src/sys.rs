//! Small OS helpers shared by the link and the emulator: waiting for readability or
//! writability with `poll(2)` (through rustix) and saturating deadlines.

use std::io;
use std::os::fd::{BorrowedFd, RawFd};
use std::time::{Duration, Instant};

use rustix::event::{PollFd, PollFlags, Timespec};

/// Waits until one of `fds` is readable (or hung up / in error), at most `timeout`.
/// Returns a bit mask of the ready entries (bit `i` = `fds[i]`); 0 on timeout or on an
/// interrupted wait. At most 8 descriptors; a negative descriptor is skipped (never
/// ready).
///
/// Every non-negative descriptor must stay open for the duration of the call (the
/// callers pass descriptors of objects they hold borrowed).
pub fn wait_readable(fds: &[RawFd], timeout: Duration) -> io::Result<u8> {
    wait(fds, PollFlags::IN, timeout)
}

/// Waits until `fd` can take bytes (or is hung up / in error, which the next write
/// reports), at most `timeout`. Returns whether it is ready; false on timeout or on an
/// interrupted wait. `fd` must stay open for the duration of the call.
pub fn wait_writable(fd: RawFd, timeout: Duration) -> io::Result<bool> {
    Ok(wait(&[fd], PollFlags::OUT, timeout)? != 0)
}

/// [`wait_readable`] for `events`.
fn wait(fds: &[RawFd], events: PollFlags, timeout: Duration) -> io::Result<u8> {
    // The positions in `fds` of the descriptors that are polled.
    let mut index = [0usize; 8];
    let mut n = 0;
    for (i, &fd) in fds.iter().enumerate().take(8) {
        if fd >= 0 {
            index[n] = i;
            n += 1;
        }
    }
    let mut polled: [PollFd<'_>; 8] = std::array::from_fn(|k| {
        // Slots past `n` are never passed to poll(2); they hold descriptor 0 as a
        // placeholder value only.
        let (fd, events) = if k < n {
            (fds[index[k]], events)
        } else {
            (0, PollFlags::empty())
        };
        // SAFETY: `fd` is non-negative and, per the public functions' contract, open for
        // the whole call (placeholders are never used); the borrow does not outlive it.
        PollFd::from_borrowed_fd(unsafe { BorrowedFd::borrow_raw(fd) }, events)
    });
    // Round up so a sub-millisecond timeout does not become a busy loop.
    let ms = timeout.as_micros().div_ceil(1000).min(i32::MAX as u128) as i64;
    let ts = Timespec {
        tv_sec: ms / 1000,
        tv_nsec: (ms % 1000) * 1_000_000,
    };
    match rustix::event::poll(&mut polled[..n], Some(&ts)) {
        Ok(_) => {}
        Err(rustix::io::Errno::INTR) => return Ok(0),
        Err(e) => return Err(e.into()),
    }
    let mut mask = 0u8;
    for (k, p) in polled.iter().take(n).enumerate() {
        if !p.revents().is_empty() {
            mask |= 1 << index[k];
        }
    }
    Ok(mask)
}

/// `now + timeout`, saturating far in the future instead of overflowing (a caller may
/// pass `Duration::MAX` for "no limit").
pub fn deadline(timeout: Duration) -> Instant {
    let now = Instant::now();
    now.checked_add(timeout)
        .or_else(|| now.checked_add(Duration::from_secs(100 * 365 * 86_400)))
        .unwrap_or(now)
}
