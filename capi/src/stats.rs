//! `limber_stats_*`: a driver's loop, link and robot facts (`limber_driver_stats` of
//! limber.h), as `limber echo <robot>/driver` prints them.

use core::ffi::c_char;

use limber_interfaces::diagnostics::DriverStats;
use limber_services::diagnostics::{DiagnosticsError, StatsReader};
use limber_services::{Context, Role};

use crate::device::process_name;
use crate::{Fail, LimberCode, arg, domain_of, guard, ms, opt_str, req_str};

/// A reader of one driver's statistics (opaque).
pub struct LimberStats {
    reader: StatsReader,
    /// The reader's node lives as long as the reader.
    _ctx: Context,
}

impl From<DiagnosticsError> for Fail {
    fn from(e: DiagnosticsError) -> Self {
        let code = match &e {
            DiagnosticsError::Name(_) => LimberCode::BadName,
            DiagnosticsError::NoDriver(_) => LimberCode::NoDriver,
            DiagnosticsError::Timeout(_) => LimberCode::Timeout,
            _ => LimberCode::Transport,
        };
        Fail::from_error(code, &e)
    }
}

/// Opens the statistics of the driver of `robot` (e.g. "pioneer") in `domain` (NULL:
/// `LIMBER_DOMAIN`, or "limber"); `LIMBER_CODE_NO_DRIVER` if no driver publishes them.
/// Free the reader with `limber_stats_close`.
///
/// # Safety
/// `robot` and `domain` are NULL or NUL-terminated strings; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_stats_open(
    robot: *const c_char,
    domain: *const c_char,
    out: *mut *mut LimberStats,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the arguments, checked for NULL here.
        let (robot, domain, out) = unsafe {
            (
                req_str(robot, "robot")?,
                opt_str(domain, "domain")?,
                arg(out, "out")?,
            )
        };
        let ctx = Context::new(&domain_of(domain)?, Role::Client, &process_name())
            .map_err(|e| Fail::from_error(LimberCode::Transport, &e))?;
        let reader = StatsReader::open(&ctx, robot)?;
        *out = Box::into_raw(Box::new(LimberStats { reader, _ctx: ctx }));
        Ok(())
    })
}

/// Closes the reader. NULL is ignored.
///
/// # Safety
/// `h` is NULL or a reader of `limber_stats_open` not yet closed.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_stats_close(h: *mut LimberStats) {
    // SAFETY: the caller's promise: NULL or a reader of the open call, freed once.
    unsafe { crate::free_handle(h) }
}

/// Copies the latest statistics into `*out` (taking what arrived first);
/// `LIMBER_CODE_TIMEOUT` when none arrived yet. Never waits.
///
/// # Safety
/// `h` is NULL or a live reader; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_stats_latest(
    h: *mut LimberStats,
    out: *mut DriverStats,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "reader")?, arg(out, "out")?) };
        h.reader.refresh()?;
        *out = *h
            .reader
            .latest()
            .ok_or_else(|| Fail::new(LimberCode::Timeout, "no statistics arrived yet"))?;
        Ok(())
    })
}

/// Waits up to `timeout_ms` for statistics newer than the latest taken and copies them
/// into `*out`.
///
/// # Safety
/// `h` is NULL or a live reader; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_stats_wait(
    h: *mut LimberStats,
    timeout_ms: u64,
    out: *mut DriverStats,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "reader")?, arg(out, "out")?) };
        *out = *h.reader.wait(ms(timeout_ms))?;
        Ok(())
    })
}
