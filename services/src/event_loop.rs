//! The driver loop's waiting: a WaitSet over the wake listeners of a driver's devices, a
//! precise periodic timer (`timerfd`, not the WaitSet's 1 ms-rounded interval) and any
//! other file descriptor (a serial port), returning on a termination request (SIGINT,
//! SIGTERM, SIGHUP, SIGQUIT, SIGXCPU, SIGPWR: [`crate::signals`]) and on nothing else: a
//! signal that merely interrupts the wait (SIGCONT, SIGALRM, SIGUSR1...) is waited through.

use core::ops::ControlFlow;
use core::time::Duration;
use std::os::fd::{AsFd, AsRawFd, OwnedFd};

use iceoryx2::port::listener::Listener;
use iceoryx2::prelude::*;
use iceoryx2::waitset::{WaitSetRunError, WaitSetRunResult};
use rustix::time::{Itimerspec, TimerfdClockId, TimerfdFlags, TimerfdTimerFlags, Timespec};
use thiserror::Error;

use crate::error::Iox2Error;

/// The event loop failed ([`run`], [`TimerFd::periodic`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Error)]
pub enum LoopError {
    /// The timer period is zero.
    #[error("cannot create the loop timer: period is zero")]
    ZeroPeriod,
    /// The timer could not be created or armed (too many fds?).
    #[error("cannot create the loop timer: {0}")]
    Timer(#[source] rustix::io::Errno),
    /// The timer's file descriptor cannot be waited on.
    #[error("cannot create the loop timer: invalid fd")]
    TimerFd,
    /// The WaitSet could not be created or an attachment failed (too many fds?).
    #[error("cannot set up the wait set: {0}")]
    WaitSet(#[source] Iox2Error),
    /// Waiting failed.
    #[error("the wait set failed: {0}")]
    Wait(#[source] WaitSetRunError),
}

/// Why the loop returned.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LoopExit {
    /// A termination request arrived ([`crate::signals::TERMINATION_SIGNALS`]).
    Signal,
    /// The callback asked to stop.
    Stopped,
}

/// What woke the loop.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Wake {
    /// A client sent a command or request (the wake events are already consumed).
    Clients,
    /// The periodic timer expired (`n` times since the last tick: more than 1 = overrun).
    Tick(u64),
    /// The extra file descriptor is readable.
    Fd,
}

/// A periodic `CLOCK_MONOTONIC` timer as a file descriptor, with nanosecond resolution.
#[derive(Debug)]
pub struct TimerFd {
    fd: OwnedFd,
    handle: FileDescriptor,
}

impl TimerFd {
    /// A timer that expires every `period`, first after one period.
    pub fn periodic(period: Duration) -> Result<Self, LoopError> {
        if period.is_zero() {
            return Err(LoopError::ZeroPeriod);
        }
        let fd = rustix::time::timerfd_create(
            TimerfdClockId::Monotonic,
            TimerfdFlags::NONBLOCK | TimerfdFlags::CLOEXEC,
        )
        .map_err(LoopError::Timer)?;
        let ts = Timespec {
            tv_sec: period.as_secs() as _,
            tv_nsec: period.subsec_nanos() as _,
        };
        rustix::time::timerfd_settime(
            &fd,
            TimerfdTimerFlags::empty(),
            &Itimerspec {
                it_interval: ts,
                it_value: ts,
            },
        )
        .map_err(LoopError::Timer)?;
        let handle = FileDescriptor::non_owning_new(fd.as_raw_fd()).ok_or(LoopError::TimerFd)?;
        Ok(TimerFd { fd, handle })
    }

    /// Reads and resets the expiry count (0 if it has not expired).
    pub fn consume(&self) -> u64 {
        let mut buf = [0u8; 8];
        match rustix::io::read(self.fd.as_fd(), &mut buf) {
            Ok(8) => u64::from_ne_bytes(buf),
            // Not expired since the last read.
            Err(rustix::io::Errno::AGAIN) => 0,
            // A timerfd read is 8 bytes or an error; anything else is reported.
            Ok(n) => {
                tracing::warn!(bytes = n, "short read of the loop timer");
                0
            }
            Err(e) => {
                tracing::warn!(error = %e, "cannot read the loop timer");
                0
            }
        }
    }
}

impl FileDescriptorBased for TimerFd {
    fn file_descriptor(&self) -> &FileDescriptor {
        &self.handle
    }
}
impl SynchronousMultiplexing for TimerFd {}

/// Any readable file descriptor (a serial port, a socket) for a WaitSet. Does not own it.
#[derive(Debug)]
pub struct FdSource {
    handle: FileDescriptor,
}

impl FdSource {
    /// Wraps `fd`, which must stay open while the source is attached.
    pub fn new(fd: &impl AsRawFd) -> Option<Self> {
        FileDescriptor::non_owning_new(fd.as_raw_fd()).map(|handle| FdSource { handle })
    }
}

impl FileDescriptorBased for FdSource {
    fn file_descriptor(&self) -> &FileDescriptor {
        &self.handle
    }
}
impl SynchronousMultiplexing for FdSource {}

/// Runs the loop of a driver: waits on the wake `listeners` of its devices, a timer of
/// `period`, and `extra` (e.g. the serial port), and calls `on` for each wake-up until it
/// returns `Break` or a termination request ([`crate::signals`]) arrives; any other
/// signal that interrupts the wait is waited through. Listener events are consumed before
/// `on` runs.
pub fn run<F>(
    listeners: &[Listener<ipc::Service>],
    period: Duration,
    extra: Option<&FdSource>,
    mut on: F,
) -> Result<LoopExit, LoopError>
where
    F: FnMut(Wake) -> ControlFlow<()>,
{
    let ws = WaitSetBuilder::new()
        .create::<ipc::Service>()
        .map_err(|e| LoopError::WaitSet(e.into()))?;
    let timer = TimerFd::periodic(period)?;
    let mut guards = Vec::with_capacity(listeners.len());
    for l in listeners {
        guards.push(
            ws.attach_notification(l)
                .map_err(|e| LoopError::WaitSet(e.into()))?,
        );
    }
    let timer_guard = ws
        .attach_notification(&timer)
        .map_err(|e| LoopError::WaitSet(e.into()))?;
    let extra_guard = match extra {
        Some(fd) => Some(
            ws.attach_notification(fd)
                .map_err(|e| LoopError::WaitSet(e.into()))?,
        ),
        None => None,
    };
    let mut terminate = false;
    loop {
        let result = ws
            .wait_and_process(|id| {
                // A request that arrived between two waits (not interrupting either).
                if crate::signals::termination_requested() {
                    terminate = true;
                    return CallbackProgression::Stop;
                }
                let wake = if id.has_event_from(&timer_guard) {
                    Wake::Tick(timer.consume())
                } else if extra_guard.as_ref().is_some_and(|g| id.has_event_from(g)) {
                    Wake::Fd
                } else {
                    for (l, g) in listeners.iter().zip(&guards) {
                        // Unconsumed events wake the loop again at once: logged.
                        if id.has_event_from(g)
                            && let Err(e) = l.try_wait(|_| {})
                        {
                            tracing::warn!(error = %e, "cannot consume wake-up events");
                        }
                    }
                    Wake::Clients
                };
                if on(wake).is_break() {
                    CallbackProgression::Stop
                } else {
                    CallbackProgression::Continue
                }
            })
            .map_err(LoopError::Wait)?;
        match result {
            // iceoryx2's own record of SIGINT/SIGTERM.
            WaitSetRunResult::TerminationRequest => return Ok(LoopExit::Signal),
            // EINTR: any caught signal, or a stop and continue. Only a termination
            // request ends the loop.
            WaitSetRunResult::Interrupt => {
                if crate::signals::termination_requested() {
                    return Ok(LoopExit::Signal);
                }
                tracing::debug!("the wait was interrupted by a signal that does not end the loop");
            }
            _ if terminate => return Ok(LoopExit::Signal),
            _ => return Ok(LoopExit::Stopped),
        }
    }
}

/// After activity, keeps polling for more instead of going back to sleep at once: calls
/// `poll` (which returns whether it found work) until it has found nothing for `budget`.
/// A driver calls it after it processed its clients, so that a client's next command,
/// sent within `budget`, is picked up without a wake-up; zero returns at once. Never
/// longer than `budget` or 1 ms in all, whichever is longer, so that a flood of commands
/// does not keep the loop from its timer and signals. Returns how many polls found work.
pub fn linger(budget: Duration, mut poll: impl FnMut() -> bool) -> u64 {
    if budget.is_zero() {
        return 0;
    }
    let start = std::time::Instant::now();
    let cap = budget.max(Duration::from_millis(1));
    let mut found = 0;
    let mut idle_since = start;
    loop {
        if poll() {
            found += 1;
            idle_since = std::time::Instant::now();
        } else if idle_since.elapsed() >= budget {
            return found;
        } else {
            // Yield rather than spin: a client sharing this core runs now.
            std::thread::yield_now();
        }
        if start.elapsed() >= cap {
            return found;
        }
    }
}

#[cfg(test)]
mod linger_tests {
    use super::linger;
    use core::time::Duration;

    #[test]
    fn zero_budget_does_not_poll() {
        let mut polls = 0;
        assert_eq!(
            linger(Duration::ZERO, || {
                polls += 1;
                true
            }),
            0
        );
        assert_eq!(polls, 0);
    }

    #[test]
    fn counts_the_polls_that_found_work_and_stops_when_idle() {
        let mut left = 5;
        let found = linger(Duration::from_micros(200), || {
            if left > 0 {
                left -= 1;
                true
            } else {
                false
            }
        });
        assert_eq!(found, 5);
    }

    /// A flood (work on every poll) does not keep the loop from its timer and signals.
    #[test]
    fn a_flood_ends_the_linger() {
        let found = linger(Duration::from_micros(50), || true);
        assert!(found > 0);
    }
}
