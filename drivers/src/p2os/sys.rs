//! Small OS helpers: waiting for readability with `poll(2)`.

use std::io;
use std::os::fd::RawFd;
use std::time::Duration;

/// Waits until one of `fds` is readable (or hung up / in error), at most
/// `timeout`. Returns a bit mask of the ready entries (bit `i` = `fds[i]`);
/// 0 on timeout or on an interrupted wait. At most 8 descriptors.
pub(crate) fn wait_readable(fds: &[RawFd], timeout: Duration) -> io::Result<u8> {
    let mut pfds = [libc::pollfd {
        fd: -1,
        events: 0,
        revents: 0,
    }; 8];
    let n = fds.len().min(8);
    for (p, &fd) in pfds.iter_mut().zip(fds.iter()) {
        p.fd = fd;
        p.events = libc::POLLIN;
    }
    // Round up so a sub-millisecond timeout does not become a busy loop.
    let ms = timeout.as_micros().div_ceil(1000).min(i32::MAX as u128) as libc::c_int;
    // SAFETY: `pfds` is a valid, initialised array of at least `n` pollfd
    // structures that lives for the whole call; poll only writes `revents`.
    let rc = unsafe { libc::poll(pfds.as_mut_ptr(), n as libc::nfds_t, ms) };
    if rc < 0 {
        let e = io::Error::last_os_error();
        if e.kind() == io::ErrorKind::Interrupted {
            return Ok(0);
        }
        return Err(e);
    }
    let mut mask = 0u8;
    for (i, p) in pfds.iter().take(n).enumerate() {
        if p.revents != 0 {
            mask |= 1 << i;
        }
    }
    Ok(mask)
}

/// `now + timeout`, saturating far in the future instead of overflowing
/// (a caller may pass `Duration::MAX` for "no limit").
pub(crate) fn deadline(timeout: Duration) -> std::time::Instant {
    let now = std::time::Instant::now();
    now.checked_add(timeout)
        .or_else(|| now.checked_add(Duration::from_secs(100 * 365 * 86_400)))
        .unwrap_or(now)
}
