//! `limber_actarray_*`: Player's `ActArrayProxy` for C, one function per client call.

use limber_interfaces::prelude::*;

use crate::{Fail, LimberCode, LimberDevice, LimberTicket, arg, guard, sent};

/// A connection to an actuator array: a `limber_device` of this interface (the same type, so every
/// `limber_device_*` call takes it).
pub type LimberActArray = LimberDevice;

/// The values of a `*_multi` call.
///
/// # Safety
/// `p` is NULL (then `count` must be 0) or points to `count` readable doubles.
unsafe fn values<'a>(p: *const f64, count: usize) -> Result<&'a [f64], Fail> {
    if count == 0 {
        return Ok(&[]);
    }
    if p.is_null() {
        return Err(Fail::new(LimberCode::NullArgument, "the values are NULL"));
    }
    // SAFETY: not NULL, and the caller promises `count` readable doubles.
    Ok(unsafe { core::slice::from_raw_parts(p, count) })
}

/// CMD POS: moves `joint` to `position` (rad or m). `*ticket` (NULL: not written) is for
/// `limber_actarray_wait_outcome`. Returns at once.
///
/// # Safety
/// `h` is NULL or a live handle; `ticket` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_move_to(
    h: *mut LimberActArray,
    joint: u32,
    position: f64,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, ticket) = unsafe { (arg(h, "handle")?, ticket.as_mut()) };
        sent(
            h.typed::<ActArray>()?.move_to(joint as usize, position),
            ticket,
        )
    })
}

/// CMD MULTI_POS: moves joints 0..count to `positions[0..count]`.
///
/// # Safety
/// `h` is NULL or a live handle; `positions` points to `count` doubles (or is NULL with
/// `count` 0); `ticket` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_move_to_multi(
    h: *mut LimberActArray,
    positions: *const f64,
    count: usize,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, v, ticket) = unsafe {
            (
                arg(h, "handle")?,
                values(positions, count)?,
                ticket.as_mut(),
            )
        };
        sent(h.typed::<ActArray>()?.move_to_multi(v), ticket)
    })
}

/// CMD SPEED: moves `joint` at `speed` (rad/s or m/s).
///
/// # Safety
/// `h` is NULL or a live handle; `ticket` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_move_at_speed(
    h: *mut LimberActArray,
    joint: u32,
    speed: f64,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, ticket) = unsafe { (arg(h, "handle")?, ticket.as_mut()) };
        sent(
            h.typed::<ActArray>()?.move_at_speed(joint as usize, speed),
            ticket,
        )
    })
}

/// CMD MULTI_SPEED: moves joints 0..count at `speeds[0..count]`.
///
/// # Safety
/// As `limber_actarray_move_to_multi`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_move_at_speed_multi(
    h: *mut LimberActArray,
    speeds: *const f64,
    count: usize,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, v, ticket) =
            unsafe { (arg(h, "handle")?, values(speeds, count)?, ticket.as_mut()) };
        sent(h.typed::<ActArray>()?.move_at_speed_multi(v), ticket)
    })
}

/// CMD HOME: homes `joint`, or every joint if `joint` is negative.
///
/// # Safety
/// `h` is NULL or a live handle; `ticket` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_home(
    h: *mut LimberActArray,
    joint: i32,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, ticket) = unsafe { (arg(h, "handle")?, ticket.as_mut()) };
        sent(
            h.typed::<ActArray>()?.home(usize::try_from(joint).ok()),
            ticket,
        )
    })
}

/// CMD CURRENT: drives `joint` (every joint if negative) with `current` A.
///
/// # Safety
/// `h` is NULL or a live handle; `ticket` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_set_current(
    h: *mut LimberActArray,
    joint: i32,
    current: f64,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, ticket) = unsafe { (arg(h, "handle")?, ticket.as_mut()) };
        sent(
            h.typed::<ActArray>()?
                .set_current(usize::try_from(joint).ok(), current),
            ticket,
        )
    })
}

/// CMD MULTI_CURRENT: drives joints 0..count with `currents[0..count]` A.
///
/// # Safety
/// As `limber_actarray_move_to_multi`.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_set_current_multi(
    h: *mut LimberActArray,
    currents: *const f64,
    count: usize,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, v, ticket) =
            unsafe { (arg(h, "handle")?, values(currents, count)?, ticket.as_mut()) };
        sent(h.typed::<ActArray>()?.set_current_multi(v), ticket)
    })
}

/// REQ POWER: power on (`on` true) or off; waits up to `timeout_ms` for the reply.
///
/// # Safety
/// `h` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_power(
    h: *mut LimberActArray,
    on: bool,
    timeout_ms: u64,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the handle, checked for NULL here.
        let h = unsafe { arg(h, "handle")? };
        crate::request(
            h.typed::<ActArray>()?,
            &ActArrayRequest::Power(on),
            timeout_ms,
        )
        .map(drop)
    })
}

/// REQ BRAKES: brakes on or off; waits up to `timeout_ms` for the reply.
///
/// # Safety
/// `h` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_brakes(
    h: *mut LimberActArray,
    on: bool,
    timeout_ms: u64,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the handle, checked for NULL here.
        let h = unsafe { arg(h, "handle")? };
        crate::request(
            h.typed::<ActArray>()?,
            &ActArrayRequest::Brakes(on),
            timeout_ms,
        )
        .map(drop)
    })
}

/// REQ SPEED: the speed of `joint` for later position moves.
///
/// # Safety
/// `h` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_set_speed_config(
    h: *mut LimberActArray,
    joint: u32,
    speed: f64,
    timeout_ms: u64,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the handle, checked for NULL here.
        let h = unsafe { arg(h, "handle")? };
        let req = ActArrayRequest::speed(i64::from(joint), speed)?;
        crate::request(h.typed::<ActArray>()?, &req, timeout_ms).map(drop)
    })
}

/// REQ ACCEL: the acceleration of `joint` for later position moves.
///
/// # Safety
/// `h` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_set_accel_config(
    h: *mut LimberActArray,
    joint: u32,
    accel: f64,
    timeout_ms: u64,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the handle, checked for NULL here.
        let h = unsafe { arg(h, "handle")? };
        let req = ActArrayRequest::accel(i64::from(joint), accel)?;
        crate::request(h.typed::<ActArray>()?, &req, timeout_ms).map(drop)
    })
}

// ----- control: who commands the device ------------------------------------------------
