//! `limber_actarray_*`: Player's `ActArrayProxy` for C, one function per client call.

use core::ffi::c_char;

use limber_interfaces::prelude::*;

use crate::{
    CompiledLayout, Fail, Handle, LimberCode, LimberDriverStatus, LimberLeaseHolder,
    LimberLiveness, LimberTicket, arg, guard, opt_str, req_str, sent,
};

/// A connection to an actuator array (opaque). Use it from one thread at a time.
pub struct LimberActArray(Handle<ActArray>);

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

/// What `limber_actarray_connect` (an inline function of limber_client.h) calls, with the
/// layout the program was compiled against: `layout_version` (`LIMBER_LAYOUT_VERSION`),
/// `data_size` (`sizeof(limber_actarray_data)`) and `geom_size` (`sizeof(limber_actarray_geom)`). A
/// program compiled against another limber.h than this library's (a field moved, a
/// struct grown: another layout version) is refused with `LIMBER_CODE_INCOMPATIBLE`
/// before it connects, and `limber_last_error()` says which versions and sizes differ.
/// Otherwise as `limber_actarray_connect`: call that.
///
/// # Safety
/// `device` and `domain` are NULL or NUL-terminated strings; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_connect_checked(
    device: *const c_char,
    domain: *const c_char,
    timeout_ms: u64,
    layout_version: u32,
    data_size: usize,
    geom_size: usize,
    out: *mut *mut LimberActArray,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the arguments, checked for NULL here.
        let (device, domain, out) = unsafe {
            (
                req_str(device, "device")?,
                opt_str(domain, "domain")?,
                arg(out, "out")?,
            )
        };
        CompiledLayout {
            version: layout_version,
            data_size,
            geom_size,
        }
        .check::<ActArrayData, ActArrayGeom>("limber_actarray_data", "limber_actarray_geom")?;
        let h = Handle::connect(device, domain, timeout_ms)?;
        *out = Box::into_raw(Box::new(LimberActArray(h)));
        Ok(())
    })
}

/// Closes the connection and frees the handle (and any state borrowed from it). NULL is
/// ignored.
///
/// # Safety
/// `h` is NULL or a handle of `limber_actarray_connect` not yet disconnected.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_disconnect(h: *mut LimberActArray) {
    // SAFETY: the caller's promise (see above): NULL or a handle of the connect call,
    // freed once.
    unsafe { crate::free_handle(h) }
}

/// Copies the latest state into `*out`, waiting up to `timeout_ms` for a first one
/// (`LIMBER_CODE_TIMEOUT` if none came).
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_state(
    h: *mut LimberActArray,
    timeout_ms: u64,
    out: *mut ActArrayData,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "handle")?, arg(out, "out")?) };
        h.0.state(timeout_ms, out)
    })
}

/// Lends the latest state in place, without a copy (waiting up to `timeout_ms` for a
/// first one): `*out` points into shared memory and stays valid and unchanged until
/// `limber_actarray_release` (or disconnect). Meanwhile the calls that read states
/// (state, borrow, wait_state, wait_outcome, preempted, liveness) fail with `LIMBER_CODE_BORROWED`;
/// commands and requests work.
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_borrow(
    h: *mut LimberActArray,
    timeout_ms: u64,
    out: *mut *const ActArrayData,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "handle")?, arg(out, "out")?) };
        *out = h.0.borrow(timeout_ms)?;
        Ok(())
    })
}

/// Ends the loan of `limber_actarray_borrow` (the pointer it gave is invalid from now on).
/// Releasing with nothing borrowed is harmless.
///
/// # Safety
/// `h` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_release(h: *mut LimberActArray) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the handle, checked for NULL here.
        let h = unsafe { arg(h, "handle")? };
        h.0.release();
        Ok(())
    })
}

/// Waits up to `timeout_ms` for a state newer than the latest one taken and copies it into
/// `*out` (NULL: not copied).
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_wait_state(
    h: *mut LimberActArray,
    timeout_ms: u64,
    out: *mut ActArrayData,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "handle")?, out.as_mut()) };
        h.0.wait_state(timeout_ms, out)
    })
}

/// Waits up to `timeout_ms` for the outcome of the command of `ticket`; `*status` is the
/// driver's `LIMBER_STATUS_*` (`LIMBER_STATUS_OK`: carried out). A status other than OK is
/// also kept for `limber_last_refusal()` and `limber_last_error()`, which for
/// `LIMBER_STATUS_LEASED` names the client holding the device ("refused: held by another
/// client (alice, client 123)"); the call still returns `LIMBER_CODE_OK`.
///
/// # Safety
/// `h` is NULL or a live handle; `status` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_wait_outcome(
    h: *mut LimberActArray,
    ticket: LimberTicket,
    timeout_ms: u64,
    status: *mut u32,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, status) = unsafe { (arg(h, "handle")?, arg(status, "status")?) };
        *status = h.0.wait_outcome(&ticket, timeout_ms)?;
        Ok(())
    })
}

/// Whether the driver publishes: `LIMBER_LIVENESS_ALIVE` if the latest state is younger
/// than `max_age_ms`, `STALE` if older but the driver lives, `GONE`, or `NO_DATA`.
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_liveness(
    h: *mut LimberActArray,
    max_age_ms: u64,
    out: *mut LimberLiveness,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "handle")?, arg(out, "out")?) };
        *out = h.0.liveness(max_age_ms)?;
        Ok(())
    })
}

/// Whether the driver's process lives (costs tens of microseconds).
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_driver_status(
    h: *mut LimberActArray,
    out: *mut LimberDriverStatus,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "handle")?, arg(out, "out")?) };
        *out = h.0.driver_status();
        Ok(())
    })
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
        sent(h.0.client.move_to(joint as usize, position), ticket)
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
        sent(h.0.client.move_to_multi(v), ticket)
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
        sent(h.0.client.move_at_speed(joint as usize, speed), ticket)
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
        sent(h.0.client.move_at_speed_multi(v), ticket)
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
        sent(h.0.client.home(usize::try_from(joint).ok()), ticket)
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
            h.0.client.set_current(usize::try_from(joint).ok(), current),
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
        sent(h.0.client.set_current_multi(v), ticket)
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
        h.0.request(&ActArrayRequest::Power(on), timeout_ms)
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
        h.0.request(&ActArrayRequest::Brakes(on), timeout_ms)
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
        h.0.request(&req, timeout_ms).map(drop)
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
        h.0.request(&req, timeout_ms).map(drop)
    })
}

/// REQ GET_GEOM: copies the geometry (kinds, limits, home positions of every actuator)
/// into `*out`; waits up to `timeout_ms` for the reply.
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_geometry(
    h: *mut LimberActArray,
    timeout_ms: u64,
    out: *mut ActArrayGeom,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "handle")?, arg(out, "out")?) };
        match h.0.request(&ActArrayRequest::GetGeom, timeout_ms)? {
            ActArrayReply::Geom(g) => {
                *out = g;
                Ok(())
            }
            ActArrayReply::Done => Err(Fail::new(
                LimberCode::BadReply,
                "the driver answered GET_GEOM without a geometry",
            )),
        }
    })
}

// ----- control: who commands the device ------------------------------------------------

/// This handle's client id: how the driver, outcomes (`limber_actarray_preempted`) and
/// `limber_actarray_holder` name it.
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_client_id(
    h: *mut LimberActArray,
    out: *mut u64,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "handle")?, arg(out, "out")?) };
        *out = h.0.client.client_id();
        Ok(())
    })
}

/// Takes the device's control lease as `name` (NULL: this program's name; 1 to 31 bytes,
/// else `LIMBER_CODE_INVALID_VALUE`). Until `limber_actarray_release_lease` (or disconnect),
/// other clients' commands, and their requests that change the device, are refused as
/// `LIMBER_STATUS_LEASED` naming `name`; readers are unaffected. Renew it at least every
/// `heartbeat_ms` (`limber_actarray_renew`, or `limber_actarray_keep_lease` in a loop): when the
/// heartbeat is missed, or this process dies, the driver stops the device and frees it.
/// Acquiring again sets a new heartbeat. Held by another client: `LIMBER_CODE_REFUSED`,
/// `limber_last_refusal()` is `LIMBER_STATUS_LEASED` and `limber_last_error()` names the
/// holder. Waits for the driver's answer up to 2 s.
///
/// # Safety
/// `h` is NULL or a live handle; `name` is NULL or a NUL-terminated string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_acquire(
    h: *mut LimberActArray,
    name: *const c_char,
    heartbeat_ms: u64,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, name) = unsafe { (arg(h, "handle")?, opt_str(name, "name")?) };
        h.0.acquire(name, heartbeat_ms)
    })
}

/// The lease's heartbeat: tells the driver this holder lives. A lease that ended
/// meanwhile: `LIMBER_CODE_LEASE_LOST` (nobody holds it now) or `LIMBER_CODE_REFUSED` with
/// `LIMBER_STATUS_LEASED` (another client took it).
///
/// # Safety
/// `h` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_renew(h: *mut LimberActArray) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointer, checked for NULL here.
        unsafe { arg(h, "handle")? }.0.renew()
    })
}

/// For a control loop: renews the lease when a third of its heartbeat has passed since the
/// last renewal (`*renewed`, if not NULL, says whether it did); does nothing when no lease
/// is held. Fails as `limber_actarray_renew`.
///
/// # Safety
/// `h` is NULL or a live handle; `renewed` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_keep_lease(
    h: *mut LimberActArray,
    renewed: *mut bool,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, renewed) = unsafe { (arg(h, "handle")?, renewed.as_mut()) };
        let r = h.0.keep_lease()?;
        if let Some(out) = renewed {
            *out = r;
        }
        Ok(())
    })
}

/// Gives the control lease back (the motion in progress goes on). Without a lease it does
/// nothing. (`limber_actarray_release` ends the loan of a borrowed state.)
///
/// # Safety
/// `h` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_release_lease(h: *mut LimberActArray) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointer, checked for NULL here.
        unsafe { arg(h, "handle")? }.0.release_lease()
    })
}

/// Who holds the device's control lease: `out->client_id` is 0 when nobody does. Asks the
/// driver (waits for its answer up to 2 s).
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_holder(
    h: *mut LimberActArray,
    out: *mut LimberLeaseHolder,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "handle")?, arg(out, "out")?) };
        *out = h.0.holder()?;
        Ok(())
    })
}

/// Whether another client's command cut short the motion that the command of `ticket`
/// started (the driver's second outcome, `LIMBER_STATUS_PREEMPTED`): `*preempted`, and
/// `*by_client` (NULL: not written; 0 if not preempted) the preempting client's id. Looks
/// at the outcomes that arrived, without waiting; remembers this handle's last 256
/// commands.
///
/// # Safety
/// `h` is NULL or a live handle; `preempted` is NULL or writable; `by_client` is NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_actarray_preempted(
    h: *mut LimberActArray,
    ticket: LimberTicket,
    preempted: *mut bool,
    by_client: *mut u64,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, preempted, by_client) = unsafe {
            (
                arg(h, "handle")?,
                arg(preempted, "preempted")?,
                by_client.as_mut(),
            )
        };
        let p = h.0.preempted(&ticket)?;
        *preempted = p.is_some();
        if let Some(out) = by_client {
            *out = p.unwrap_or(0);
        }
        Ok(())
    })
}
