//! `limber_limb_*`: Player's `LimbProxy` for C, one function per client call.

use core::ffi::c_char;

use limber_interfaces::prelude::*;

use crate::{
    CompiledLayout, Fail, Handle, LimberCode, LimberDriverStatus, LimberLeaseHolder,
    LimberLiveness, LimberTicket, arg, guard, opt_str, req_str, sent,
};

/// A connection to a limb (opaque). Use it from one thread at a time.
pub struct LimberLimb(Handle<Limb>);

/// What `limber_limb_connect` (an inline function of limber_client.h) calls, with the
/// layout the program was compiled against: `layout_version` (`LIMBER_LAYOUT_VERSION`),
/// `data_size` (`sizeof(limber_limb_data)`) and `geom_size` (`sizeof(limber_limb_geom)`). A
/// program compiled against another limber.h than this library's (a field moved, a
/// struct grown: another layout version) is refused with `LIMBER_CODE_INCOMPATIBLE`
/// before it connects, and `limber_last_error()` says which versions and sizes differ.
/// Otherwise as `limber_limb_connect`: call that.
///
/// # Safety
/// `device` and `domain` are NULL or NUL-terminated strings; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_limb_connect_checked(
    device: *const c_char,
    domain: *const c_char,
    timeout_ms: u64,
    layout_version: u32,
    data_size: usize,
    geom_size: usize,
    out: *mut *mut LimberLimb,
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
        .check::<LimbData, LimbGeom>("limber_limb_data", "limber_limb_geom")?;
        let h = Handle::connect(device, domain, timeout_ms)?;
        *out = Box::into_raw(Box::new(LimberLimb(h)));
        Ok(())
    })
}

/// Closes the connection and frees the handle (and any state borrowed from it). NULL is
/// ignored.
///
/// # Safety
/// `h` is NULL or a handle of `limber_limb_connect` not yet disconnected.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_limb_disconnect(h: *mut LimberLimb) {
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
pub unsafe extern "C" fn limber_limb_state(
    h: *mut LimberLimb,
    timeout_ms: u64,
    out: *mut LimbData,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "handle")?, arg(out, "out")?) };
        h.0.state(timeout_ms, out)
    })
}

/// Lends the latest state in place, without a copy (waiting up to `timeout_ms` for a
/// first one): `*out` points into shared memory and stays valid and unchanged until
/// `limber_limb_release` (or disconnect). Meanwhile the calls that read states
/// (state, borrow, wait_state, wait_outcome, preempted, liveness) fail with `LIMBER_CODE_BORROWED`;
/// commands and requests work.
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_limb_borrow(
    h: *mut LimberLimb,
    timeout_ms: u64,
    out: *mut *const LimbData,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "handle")?, arg(out, "out")?) };
        *out = h.0.borrow(timeout_ms)?;
        Ok(())
    })
}

/// Ends the loan of `limber_limb_borrow` (the pointer it gave is invalid from now on).
/// Releasing with nothing borrowed is harmless.
///
/// # Safety
/// `h` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_limb_release(h: *mut LimberLimb) -> LimberCode {
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
pub unsafe extern "C" fn limber_limb_wait_state(
    h: *mut LimberLimb,
    timeout_ms: u64,
    out: *mut LimbData,
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
pub unsafe extern "C" fn limber_limb_wait_outcome(
    h: *mut LimberLimb,
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
pub unsafe extern "C" fn limber_limb_liveness(
    h: *mut LimberLimb,
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
pub unsafe extern "C" fn limber_limb_driver_status(
    h: *mut LimberLimb,
    out: *mut LimberDriverStatus,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "handle")?, arg(out, "out")?) };
        *out = h.0.driver_status();
        Ok(())
    })
}

/// CMD HOME: moves the limb to its home pose. `*ticket` (NULL: not written) is for
/// `limber_limb_wait_outcome`. Returns at once.
///
/// # Safety
/// `h` is NULL or a live handle; `ticket` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_limb_home(
    h: *mut LimberLimb,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, ticket) = unsafe { (arg(h, "handle")?, ticket.as_mut()) };
        sent(h.0.client.home(), ticket)
    })
}

/// CMD STOP: stops every joint now.
///
/// # Safety
/// `h` is NULL or a live handle; `ticket` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_limb_stop(
    h: *mut LimberLimb,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, ticket) = unsafe { (arg(h, "handle")?, ticket.as_mut()) };
        sent(h.0.client.stop(), ticket)
    })
}

/// CMD SETPOSE: the end effector to `position` (robot frame, m), its approach vector
/// along `approach` and its orientation vector along `orientation`. A pose beyond reach
/// is refused with the outcome `LIMBER_STATUS_OUT_OF_REACH` and the limb's state
/// `LIMBER_LIMB_STATE_OOR`.
///
/// # Safety
/// `h` is NULL or a live handle; `ticket` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_limb_set_pose(
    h: *mut LimberLimb,
    position: Vec3,
    approach: Vec3,
    orientation: Vec3,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, ticket) = unsafe { (arg(h, "handle")?, ticket.as_mut()) };
        let r = h.0.client.set_pose(
            position.to_array(),
            approach.to_array(),
            orientation.to_array(),
        );
        sent(r, ticket)
    })
}

/// CMD SETPOSITION: the end effector to `position`, its orientation chosen by the driver.
///
/// # Safety
/// `h` is NULL or a live handle; `ticket` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_limb_set_position(
    h: *mut LimberLimb,
    position: Vec3,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, ticket) = unsafe { (arg(h, "handle")?, ticket.as_mut()) };
        sent(h.0.client.set_position(position.to_array()), ticket)
    })
}

/// CMD VECMOVE: moves the end effector `length` m along `direction` in a straight line.
///
/// # Safety
/// `h` is NULL or a live handle; `ticket` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_limb_vec_move(
    h: *mut LimberLimb,
    direction: Vec3,
    length: f64,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, ticket) = unsafe { (arg(h, "handle")?, ticket.as_mut()) };
        sent(h.0.client.vec_move(direction.to_array(), length), ticket)
    })
}

/// REQ POWER: power on (`on` true) or off; waits up to `timeout_ms` for the reply.
///
/// # Safety
/// `h` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_limb_power(
    h: *mut LimberLimb,
    on: bool,
    timeout_ms: u64,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the handle, checked for NULL here.
        let h = unsafe { arg(h, "handle")? };
        h.0.request(&LimbRequest::Power(on), timeout_ms).map(drop)
    })
}

/// REQ BRAKES: brakes on or off; waits up to `timeout_ms` for the reply.
///
/// # Safety
/// `h` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_limb_brakes(
    h: *mut LimberLimb,
    on: bool,
    timeout_ms: u64,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the handle, checked for NULL here.
        let h = unsafe { arg(h, "handle")? };
        h.0.request(&LimbRequest::Brakes(on), timeout_ms).map(drop)
    })
}

/// REQ SPEED: the end effector's speed (m/s) for later moves.
///
/// # Safety
/// `h` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_limb_set_speed(
    h: *mut LimberLimb,
    speed: f64,
    timeout_ms: u64,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the handle, checked for NULL here.
        let h = unsafe { arg(h, "handle")? };
        h.0.request(&LimbRequest::speed(speed)?, timeout_ms)
            .map(drop)
    })
}

/// REQ GEOM: copies the limb's geometry (its base position) into `*out`; waits up to
/// `timeout_ms` for the reply.
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_limb_geometry(
    h: *mut LimberLimb,
    timeout_ms: u64,
    out: *mut LimbGeom,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "handle")?, arg(out, "out")?) };
        match h.0.request(&LimbRequest::Geom, timeout_ms)? {
            LimbReply::Geom(g) => {
                *out = g;
                Ok(())
            }
            LimbReply::Done | LimbReply::Reach(_) => Err(Fail::new(
                LimberCode::BadReply,
                "the driver answered GEOM without a geometry",
            )),
        }
    })
}

/// REQ REACH: where the end effector would end for this pose (as
/// [`limber_limb_set_pose`] takes it), without moving: copies the answer into `*out`
/// (the pose it would reach, how far its position and approach would be off, and by how
/// much the orientation would be adjusted); waits up to `timeout_ms` for the reply. A pose
/// it cannot reach is refused with `LIMBER_CODE_REFUSED` and its cause
/// (`limber_last_refusal`).
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_limb_can_reach(
    h: *mut LimberLimb,
    position: Vec3,
    approach: Vec3,
    orientation: Vec3,
    timeout_ms: u64,
    out: *mut LimbReach,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "handle")?, arg(out, "out")?) };
        let req = LimbRequest::reach(position, approach, orientation)?;
        match h.0.request(&req, timeout_ms)? {
            LimbReply::Reach(r) => {
                *out = r;
                Ok(())
            }
            LimbReply::Done | LimbReply::Geom(_) => Err(Fail::new(
                LimberCode::BadReply,
                "the driver answered REACH without a pose",
            )),
        }
    })
}

// ----- control: who commands the device ------------------------------------------------

/// This handle's client id: how the driver, outcomes (`limber_limb_preempted`) and
/// `limber_limb_holder` name it.
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_limb_client_id(h: *mut LimberLimb, out: *mut u64) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "handle")?, arg(out, "out")?) };
        *out = h.0.client.client_id();
        Ok(())
    })
}

/// Takes the device's control lease as `name` (NULL: this program's name; 1 to 31 bytes,
/// else `LIMBER_CODE_INVALID_VALUE`). Until `limber_limb_release_lease` (or disconnect),
/// other clients' commands, and their requests that change the device, are refused as
/// `LIMBER_STATUS_LEASED` naming `name`; readers are unaffected. Renew it at least every
/// `heartbeat_ms` (`limber_limb_renew`, or `limber_limb_keep_lease` in a loop): when the
/// heartbeat is missed, or this process dies, the driver stops the device and frees it.
/// Acquiring again sets a new heartbeat. Held by another client: `LIMBER_CODE_REFUSED`,
/// `limber_last_refusal()` is `LIMBER_STATUS_LEASED` and `limber_last_error()` names the
/// holder. Waits for the driver's answer up to 2 s.
///
/// # Safety
/// `h` is NULL or a live handle; `name` is NULL or a NUL-terminated string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_limb_acquire(
    h: *mut LimberLimb,
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
pub unsafe extern "C" fn limber_limb_renew(h: *mut LimberLimb) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointer, checked for NULL here.
        unsafe { arg(h, "handle")? }.0.renew()
    })
}

/// For a control loop: renews the lease when a third of its heartbeat has passed since the
/// last renewal (`*renewed`, if not NULL, says whether it did); does nothing when no lease
/// is held. Fails as `limber_limb_renew`.
///
/// # Safety
/// `h` is NULL or a live handle; `renewed` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_limb_keep_lease(
    h: *mut LimberLimb,
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
/// nothing. (`limber_limb_release` ends the loan of a borrowed state.)
///
/// # Safety
/// `h` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_limb_release_lease(h: *mut LimberLimb) -> LimberCode {
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
pub unsafe extern "C" fn limber_limb_holder(
    h: *mut LimberLimb,
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
pub unsafe extern "C" fn limber_limb_preempted(
    h: *mut LimberLimb,
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
