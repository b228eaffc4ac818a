//! `limber_device_wait_done`: how the motion a command started ended (issue 28), for every
//! interface. The result, its cause, each part's final position and error, and the
//! sentence are the Rust core's ([`limber_services::Done`]): C, C++ and Python read them.

use core::ffi::c_char;

use limber_services::client::DoneError;

use crate::device::{LimberDevice, copy_str, ticket_of};
use crate::{Fail, LimberCode, LimberTicket, arg, guard, ms};

/// How a motion ended ([`limber_device_wait_done`]).
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LimberDone {
    /// The command's sequence number (its ticket's `seq`).
    pub seq: u64,
    /// A `LIMBER_RESULT_*` of limber.h: reached, stalled, stopped, preempted, aborted,
    /// timed out.
    pub result: u32,
    /// Why, a `LIMBER_STATUS_*`: OK when reached; the cause of an abort (LINK_DOWN,
    /// POWERED_OFF, BRAKED); PREEMPTED; LEASED for the deadman's stop.
    pub cause: u32,
    /// The client whose command preempted or stopped it (0: none or the driver).
    pub other_client: u64,
    /// When the driver published it (`CLOCK_MONOTONIC` ns).
    pub stamp_ns: u64,
    /// The valid entries of `position` and `error` (part i: joint i).
    pub parts: u32,
    /// Explicit padding (zero).
    pub _pad: u32,
    /// The largest |final error| against the goal (rad or m); NaN if not known.
    pub max_error: f64,
    /// The device's tolerance for "reached".
    pub tolerance: f64,
    /// Each part's final position; NaN where not known.
    pub position: [f64; 32],
    /// Each part's final error against the goal (position − goal); NaN where not known.
    pub error: [f64; 32],
    /// The result in one sentence, NUL-terminated.
    pub sentence: [c_char; 160],
}

impl Default for LimberDone {
    fn default() -> Self {
        LimberDone {
            seq: 0,
            result: 0,
            cause: 0,
            other_client: 0,
            stamp_ns: 0,
            parts: 0,
            _pad: 0,
            max_error: 0.0,
            tolerance: 0.0,
            position: [0.0; 32],
            error: [0.0; 32],
            sentence: [0; 160],
        }
    }
}

impl From<DoneError> for Fail {
    fn from(e: DoneError) -> Self {
        match e {
            DoneError::Refused(status) => {
                let mut f = Fail::from_error(LimberCode::Refused, &e);
                f.refusal = status as u32;
                f
            }
            DoneError::Wait(w) => w.into(),
        }
    }
}

/// Waits up to `timeout_ms` until the motion that the command of `ticket` started has
/// ended, and writes how to `*out`: reached within the device's tolerance, stalled,
/// stopped, preempted, aborted or timed out, with each part's final position and error
/// against the goal and a sentence. A command that starts nothing that runs on is reached
/// when carried out. A refused command is `LIMBER_CODE_REFUSED` (its status in
/// `limber_last_refusal()`); `LIMBER_CODE_TIMEOUT` when the motion has not ended in time.
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_wait_done(
    h: *mut LimberDevice,
    ticket: LimberTicket,
    timeout_ms: u64,
    out: *mut LimberDone,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "handle")?, arg(out, "out")?) };
        h.not_borrowed()?;
        let d = h.client.wait_done(ticket_of(&ticket), ms(timeout_ms))?;
        let m = d.message();
        *out = LimberDone {
            seq: m.cmd_seq,
            result: m.result,
            cause: m.status,
            other_client: m.other_client,
            stamp_ns: m.stamp_ns,
            parts: m.parts,
            _pad: 0,
            max_error: m.max_error,
            tolerance: m.tolerance,
            position: m.position,
            error: m.error,
            sentence: [0; 160],
        };
        copy_str(&mut out.sentence, &d.sentence());
        Ok(())
    })
}
