//! `limber_limb_*`: Player's `LimbProxy` for C, one function per client call.

use limber_interfaces::prelude::*;

use crate::{Fail, LimberCode, LimberDevice, LimberTicket, arg, guard, sent};

/// A connection to a limb: a `limber_device` of this interface (the same type, so every
/// `limber_device_*` call takes it).
pub type LimberLimb = LimberDevice;

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
        sent(h.typed::<Limb>()?.home(), ticket)
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
        sent(h.typed::<Limb>()?.stop(), ticket)
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
        let r = h.typed::<Limb>()?.set_pose(
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
        sent(h.typed::<Limb>()?.set_position(position.to_array()), ticket)
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
        sent(
            h.typed::<Limb>()?.vec_move(direction.to_array(), length),
            ticket,
        )
    })
}

/// Sends a LINE (`line`) or a PTP: the orientation kept when `approach` or
/// `orientation` is NULL, else the given vectors.
///
/// # Safety
/// `h` is NULL or a live handle; `approach`, `orientation` NULL or readable; `ticket`
/// NULL or writable.
unsafe fn send_path(
    h: *mut LimberLimb,
    line: bool,
    position: Vec3,
    approach: *const Vec3,
    orientation: *const Vec3,
    speed: f64,
    ticket: *mut LimberTicket,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, ticket, a, o) = unsafe {
            (
                arg(h, "handle")?,
                ticket.as_mut(),
                approach.as_ref(),
                orientation.as_ref(),
            )
        };
        let o = a.zip(o).map(|(a, o)| (a.to_array(), o.to_array()));
        let limb = h.typed::<Limb>()?;
        let r = if line {
            limb.line(position.to_array(), o, speed)
        } else {
            limb.ptp(position.to_array(), o, speed)
        };
        sent(r, ticket)
    })
}

/// CMD LINE: moves the tool in a straight line to `position` (m), its orientation kept
/// (`approach` or `orientation` NULL) or turned evenly to the given vectors, at most
/// `speed` m/s (0: the limb's own). A line that leaves the reach or hits the world is
/// refused before anything moves (`LIMBER_STATUS_OUT_OF_REACH`,
/// `LIMBER_STATUS_PATH_COLLIDES`, ...; the limb state's `refused_at` and
/// `refused_fraction` say where). `limber_device_wait_done` gives its result.
///
/// # Safety
/// `h` is NULL or a live handle; `approach`, `orientation` NULL or readable; `ticket`
/// NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_limb_line(
    h: *mut LimberLimb,
    position: Vec3,
    approach: *const Vec3,
    orientation: *const Vec3,
    speed: f64,
    ticket: *mut LimberTicket,
) -> LimberCode {
    // SAFETY: the caller's promise, passed on.
    unsafe { send_path(h, true, position, approach, orientation, speed, ticket) }
}

/// CMD PTP: moves the joints, interpolated, to where the tool is at `position` with its
/// orientation kept (`approach` or `orientation` NULL) or the given one, the fastest joint
/// at most `speed` rad/s (0: the joints' own); checked and refused as `limber_limb_line`.
///
/// # Safety
/// `h` is NULL or a live handle; `approach`, `orientation` NULL or readable; `ticket`
/// NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_limb_ptp(
    h: *mut LimberLimb,
    position: Vec3,
    approach: *const Vec3,
    orientation: *const Vec3,
    speed: f64,
    ticket: *mut LimberTicket,
) -> LimberCode {
    // SAFETY: the caller's promise, passed on.
    unsafe { send_path(h, false, position, approach, orientation, speed, ticket) }
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
        crate::request(h.typed::<Limb>()?, &LimbRequest::Power(on), timeout_ms).map(drop)
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
        crate::request(h.typed::<Limb>()?, &LimbRequest::Brakes(on), timeout_ms).map(drop)
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
        crate::request(h.typed::<Limb>()?, &LimbRequest::speed(speed)?, timeout_ms).map(drop)
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
        match crate::request(h.typed::<Limb>()?, &req, timeout_ms)? {
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
