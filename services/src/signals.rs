//! What a long-running limber process does with each signal: every signal whose default
//! action would end the process either stops the hardware first and then ends the process
//! as SIGTERM does, or is ignored. None ends it with the arm still moving.
//!
//! The rule applies to every long-running limber process (the Pioneer driver, simarm, the
//! emulator, both bridges, `limber demo`): each calls [`install`] once, before it starts
//! serving ([`crate::Context::new`] does it for a driver context), and its loop ends when
//! [`termination_requested`] becomes true, stopping what it drives first.
//!
//! # Stop and end: [`TERMINATION_SIGNALS`]
//!
//! - SIGINT (Ctrl-C), SIGTERM (`kill`, systemd, a supervisor), SIGHUP (the terminal or the
//!   ssh session went away), SIGQUIT (Ctrl-\\): somebody asks the process to end.
//! - SIGXCPU: the kernel's warning that the process has used up its CPU time, in
//!   particular RLIMIT_RTTIME for a `--rt` (SCHED_FIFO) driver that has run too long
//!   without blocking. SIGKILL follows at the hard limit, so this is the last chance to
//!   stop the arm: the driver stops it and ends instead of waiting to be killed.
//! - SIGPWR: the power is failing (a UPS daemon, `init`): stop the arm while it can be
//!   commanded.
//!
//! # Ignored, each logged once (warning): [`ignored_signals`]
//!
//! SIGALRM, SIGUSR1, SIGUSR2, SIGIO (SIGPOLL), SIGPROF, SIGVTALRM, SIGSTKFLT, SIGXFSZ,
//! SIGSYS, SIGTRAP and the real-time signals SIGRTMIN..SIGRTMAX. limber sets no timer,
//! no asynchronous I/O owner, no profiler and no file size limit, and gives none of these
//! a meaning; sent by somebody else (a stray `kill -ALRM`, a library's timer, a monitoring
//! tool's SIGUSR1) they are no request to end, and ending on them would leave the arm
//! moving. A file size limit reached makes the write fail with EFBIG instead (the error
//! is reported where it happens). Ignoring is done with a handler, not SIG_IGN, so that
//! the first of each is logged; a signal only interrupts a blocking wait, which resumes.
//!
//! SIGPIPE is ignored by the Rust runtime before `main` (a write to a closed pipe fails
//! with EPIPE, reported as an error where it happens); it is left so. SIGCHLD, SIGCONT,
//! SIGWINCH and SIGURG do not end a process by default; SIGTSTP, SIGTTIN and SIGTTOU
//! would stop it, and iceoryx2 catches SIGTSTP (see below), SIGSTOP cannot be caught.
//!
//! # Faults and SIGKILL: the arm's own watchdog
//!
//! SIGSEGV, SIGBUS, SIGFPE, SIGILL and SIGABRT report a synchronous fault of the process
//! itself (a bad memory access, a failed assertion in C code, `abort`): the process's
//! memory can no longer be trusted, so nothing tries to continue or to talk to the robot
//! after them, and they keep their default action (the process ends, with a core dump
//! where enabled). SIGKILL cannot be caught at all. For these, as for a power cut of the
//! PC, the arm's own autopark watchdog is set by the driver (`autopark_s` in its
//! configuration): the arm parks by itself when the driver falls silent. A SIGSYS or
//! SIGTRAP that the kernel raises for a fault of this process (a seccomp filter, a
//! breakpoint without a debugger) is ignored like one sent with `kill`: limber installs
//! no seccomp filter and has no breakpoints.
//!
//! # iceoryx2's handlers
//!
//! iceoryx2 0.10 (`iceoryx2-bb-posix`'s `SignalHandler`) installs its own handlers (plain
//! sigaction, replacing whatever was there) for SIGINT, SIGTERM, SIGQUIT, SIGCONT,
//! SIGTSTP, SIGTTIN, SIGTTOU, SIGUSR1, SIGUSR2, SIGPROF, SIGURG, SIGVTALRM and SIGABRT the
//! first time anything asks it for a signal, and records only the *last* of them in one
//! slot that each query resets. It does not handle SIGHUP, SIGALRM or most of the others
//! above at all (their default action would end the process). So [`install`] first makes
//! iceoryx2 install its handlers, then installs this module's, which come after them,
//! chain to them (signal-hook runs the handler that was there before) and are never
//! replaced.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, OnceLock};

use iceoryx2_bb_posix::signal::SignalHandler;
use signal_hook::consts::signal as sig;

/// The signals that stop the hardware and end the process: SIGINT, SIGTERM, SIGHUP,
/// SIGQUIT, SIGXCPU, SIGPWR (the module documentation says why).
pub const TERMINATION_SIGNALS: [i32; 6] = [
    sig::SIGINT,
    sig::SIGTERM,
    sig::SIGHUP,
    sig::SIGQUIT,
    sig::SIGXCPU,
    libc::SIGPWR,
];

/// The signals that would end the process by default and are ignored (each logged once):
/// SIGALRM, SIGUSR1, SIGUSR2, SIGIO, SIGPROF, SIGVTALRM, SIGSTKFLT, SIGXFSZ, SIGSYS,
/// SIGTRAP and SIGRTMIN..=SIGRTMAX (the module documentation says why).
pub fn ignored_signals() -> Vec<i32> {
    let mut v = vec![
        sig::SIGALRM,
        sig::SIGUSR1,
        sig::SIGUSR2,
        sig::SIGIO,
        sig::SIGPROF,
        sig::SIGVTALRM,
        libc::SIGSTKFLT,
        sig::SIGXFSZ,
        sig::SIGSYS,
        sig::SIGTRAP,
    ];
    v.extend(libc::SIGRTMIN()..=libc::SIGRTMAX());
    v
}

/// The name of signal `sig`: `SIGALRM`, `SIGRTMIN+3`, or its number.
pub fn signal_name(sig: i32) -> String {
    if let Some(n) = signal_hook::low_level::signal_name(sig) {
        return n.to_string();
    }
    match sig {
        libc::SIGPWR => "SIGPWR".into(),
        libc::SIGSTKFLT => "SIGSTKFLT".into(),
        s if s == libc::SIGRTMIN() => "SIGRTMIN".into(),
        s if s == libc::SIGRTMAX() => "SIGRTMAX".into(),
        s if s > libc::SIGRTMIN() && s < libc::SIGRTMAX() => {
            format!("SIGRTMIN+{}", s - libc::SIGRTMIN())
        }
        s => format!("signal {s}"),
    }
}

fn flag() -> &'static Arc<AtomicBool> {
    static FLAG: OnceLock<Arc<AtomicBool>> = OnceLock::new();
    FLAG.get_or_init(|| Arc::new(AtomicBool::new(false)))
}

fn errno(sig: i32, e: &std::io::Error) -> rustix::io::Errno {
    tracing::error!(signal = %signal_name(sig), error = %e, "cannot install a signal handler");
    rustix::io::Errno::from_io_error(e).unwrap_or(rustix::io::Errno::INVAL)
}

/// Installs this process's signal handling (once; later calls return the first call's
/// result): the handlers of [`TERMINATION_SIGNALS`], each of which sets the flag that
/// [`termination_requested`] reads and then runs the handler that was there before, and
/// those of [`ignored_signals`], whose first arrival of each is logged (a thread named
/// `limber-signals` logs it; the handler itself only writes to a pipe).
pub fn install() -> Result<(), rustix::io::Errno> {
    static INSTALLED: OnceLock<Result<(), rustix::io::Errno>> = OnceLock::new();
    *INSTALLED.get_or_init(|| {
        // iceoryx2 installs its own handlers the first time anything asks it for a signal.
        // Make that happen now, so ours come after it, chain to it, and are never
        // replaced. The signal it may have recorded so far is of no interest: nothing
        // was waiting yet.
        let _ignored = SignalHandler::last_signal();
        for s in TERMINATION_SIGNALS {
            signal_hook::flag::register(s, Arc::clone(flag())).map_err(|e| errno(s, &e))?;
        }
        let ignored = ignored_signals();
        let mut signals =
            signal_hook::iterator::Signals::new(&ignored).map_err(|e| errno(ignored[0], &e))?;
        std::thread::Builder::new()
            .name("limber-signals".into())
            .spawn(move || {
                let mut logged = [false; 128];
                for s in signals.forever() {
                    let seen = usize::try_from(s)
                        .ok()
                        .and_then(|i| logged.get_mut(i))
                        .map(|l| std::mem::replace(l, true));
                    if seen != Some(true) {
                        tracing::warn!(
                            "{} ignored: not a request to end (logged once)",
                            signal_name(s)
                        );
                    }
                }
            })
            .map_err(|e| errno(ignored[0], &e))?;
        Ok(())
    })
}

/// True once one of [`TERMINATION_SIGNALS`] arrived (after [`install`]). Reading it does
/// not reset it: a termination request stays requested.
pub fn termination_requested() -> bool {
    flag().load(Ordering::SeqCst)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_signal_that_ends_a_process_by_default_is_handled_or_a_fault() {
        let handled: Vec<i32> = TERMINATION_SIGNALS
            .iter()
            .copied()
            .chain(ignored_signals())
            .collect();
        // Faults (default action: end with a core dump) and the uncatchable SIGKILL are
        // left to the arm's watchdog; SIGPIPE is ignored by the Rust runtime.
        let left = [
            sig::SIGSEGV,
            sig::SIGBUS,
            sig::SIGFPE,
            sig::SIGILL,
            sig::SIGABRT,
            sig::SIGKILL,
            sig::SIGPIPE,
        ];
        // The other signals do not end a process by default.
        let harmless = [
            sig::SIGCHLD,
            sig::SIGCONT,
            sig::SIGWINCH,
            sig::SIGURG,
            sig::SIGSTOP,
            sig::SIGTSTP,
            sig::SIGTTIN,
            sig::SIGTTOU,
        ];
        for s in 1..=libc::SIGRTMAX() {
            // glibc keeps 32 and 33 for its threads.
            if (32..libc::SIGRTMIN()).contains(&s) {
                continue;
            }
            let n = [&handled[..], &left, &harmless]
                .iter()
                .filter(|set| set.contains(&s))
                .count();
            assert_eq!(n, 1, "{} is in {n} sets", signal_name(s));
        }
    }

    #[test]
    fn real_time_signals_have_names() {
        assert_eq!(signal_name(libc::SIGRTMIN()), "SIGRTMIN");
        assert_eq!(signal_name(libc::SIGRTMIN() + 2), "SIGRTMIN+2");
        assert_eq!(signal_name(libc::SIGRTMAX()), "SIGRTMAX");
        assert_eq!(signal_name(libc::SIGPWR), "SIGPWR");
        assert_eq!(signal_name(sig::SIGALRM), "SIGALRM");
    }
}
