//! Termination requests of a driver process: SIGINT, SIGTERM and SIGHUP, and nothing else.
//!
//! A driver must end (stopping its hardware first) on every catchable request to end, and
//! must not end on any other signal: SIGCONT after a stop (`Ctrl-Z`, `bg`), SIGWINCH,
//! SIGCHLD... all interrupt a blocking wait (EINTR) without asking for anything.
//!
//! iceoryx2 0.10 (`iceoryx2-bb-posix`'s `SignalHandler`) records only the *last* of a set
//! of signals (SIGINT, SIGTERM, but also SIGCONT, SIGTSTP, SIGUSR1...) in one slot that each
//! query resets, and it does not handle SIGHUP at all (its default action kills the process
//! with status 129, leaving the arm moving). So a driver process keeps its own record: a
//! flag set by handlers for the three termination signals, installed once per process
//! ([`install`], done by [`crate::Context::new`] for a driver context) and read with
//! [`termination_requested`].

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

use iceoryx2_bb_posix::signal::SignalHandler;

/// The signals that ask a driver to end: SIGINT, SIGTERM, SIGHUP.
pub const TERMINATION_SIGNALS: [i32; 3] = [
    signal_hook::consts::SIGINT,
    signal_hook::consts::SIGTERM,
    signal_hook::consts::SIGHUP,
];

fn flag() -> &'static Arc<AtomicBool> {
    static FLAG: OnceLock<Arc<AtomicBool>> = OnceLock::new();
    FLAG.get_or_init(|| Arc::new(AtomicBool::new(false)))
}

/// Installs the handlers of [`TERMINATION_SIGNALS`] for this process (once; later calls
/// return the first call's result). Each handler sets the flag that
/// [`termination_requested`] reads, then runs the handler that was there before.
pub fn install() -> Result<(), rustix::io::Errno> {
    static INSTALLED: OnceLock<Result<(), rustix::io::Errno>> = OnceLock::new();
    *INSTALLED.get_or_init(|| {
        // iceoryx2 installs its own handlers (plain sigaction, replacing whatever was
        // there) the first time anything asks it for a signal. Make that happen now, so
        // ours come after it, chain to it, and are never replaced. The signal it may have
        // recorded so far is of no interest: nothing was waiting yet.
        let _ignored = SignalHandler::last_signal();
        for sig in TERMINATION_SIGNALS {
            signal_hook::flag::register(sig, Arc::clone(flag())).map_err(|e| {
                tracing::error!(signal = sig, error = %e, "cannot install a signal handler");
                rustix::io::Errno::from_io_error(&e).unwrap_or(rustix::io::Errno::INVAL)
            })?;
        }
        Ok(())
    })
}

/// True once SIGINT, SIGTERM or SIGHUP arrived (after [`install`]). Reading it does not
/// reset it: a termination request stays requested.
pub fn termination_requested() -> bool {
    flag().load(Ordering::SeqCst)
}
