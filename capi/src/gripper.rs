//! `limber_gripper_*`: Player's `GripperProxy` for C, one function per client call.

use limber_interfaces::prelude::*;

use crate::{LimberCode, LimberDevice, LimberTicket, arg, guard, sent};

/// A connection to a gripper: a `limber_device` of this interface (the same type, so every
/// `limber_device_*` call takes it).
pub type LimberGripper = LimberDevice;

/// CMD OPEN: opens the gripper. `*ticket` (NULL: not written) is for
/// `limber_gripper_wait_outcome`. Returns at once.
///
/// # Safety
/// `h` is NULL or a live handle; `ticket` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_gripper_open(
    h: *mut LimberGripper,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, ticket) = unsafe { (arg(h, "handle")?, ticket.as_mut()) };
        sent(h.typed::<Gripper>()?.open(), ticket)
    })
}

/// CMD CLOSE: closes the gripper (on an object: the state becomes closed, the beams see it).
///
/// # Safety
/// `h` is NULL or a live handle; `ticket` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_gripper_close(
    h: *mut LimberGripper,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, ticket) = unsafe { (arg(h, "handle")?, ticket.as_mut()) };
        sent(h.typed::<Gripper>()?.close(), ticket)
    })
}

/// CMD GOAL: moves the fingers to `gap` m with at most `effort` N at `speed` m/s (0: the
/// gripper's own effort, its configured speed). `limber_device_wait_done` gives the
/// result: REACHED, or STALLED on an object, with status `LIMBER_STATUS_OBJECT_PRESENT`
/// when the break beams see one. A gripper that cannot set one of them refuses the goal
/// (`LIMBER_STATUS_GAP_NOT_SETTABLE`, `..._EFFORT_...`, `..._SPEED_...`).
///
/// # Safety
/// `h` is NULL or a live handle; `ticket` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_gripper_goal(
    h: *mut LimberGripper,
    gap: f64,
    effort: f64,
    speed: f64,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, ticket) = unsafe { (arg(h, "handle")?, ticket.as_mut()) };
        sent(h.typed::<Gripper>()?.goal(gap, effort, speed), ticket)
    })
}

/// CMD STOP: stops the gripper where it is.
///
/// # Safety
/// `h` is NULL or a live handle; `ticket` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_gripper_stop(
    h: *mut LimberGripper,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, ticket) = unsafe { (arg(h, "handle")?, ticket.as_mut()) };
        sent(h.typed::<Gripper>()?.stop(), ticket)
    })
}

/// CMD STORE: stores the held object.
///
/// # Safety
/// `h` is NULL or a live handle; `ticket` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_gripper_store(
    h: *mut LimberGripper,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, ticket) = unsafe { (arg(h, "handle")?, ticket.as_mut()) };
        sent(h.typed::<Gripper>()?.store(), ticket)
    })
}

/// CMD RETRIEVE: retrieves a stored object.
///
/// # Safety
/// `h` is NULL or a live handle; `ticket` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_gripper_retrieve(
    h: *mut LimberGripper,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, ticket) = unsafe { (arg(h, "handle")?, ticket.as_mut()) };
        sent(h.typed::<Gripper>()?.retrieve(), ticket)
    })
}

// ----- control: who commands the device ------------------------------------------------
