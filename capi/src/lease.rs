//! `limber_device_*` for the control lease: who commands a device (acquire, heartbeat,
//! release, who holds it), the same for every interface.

use core::ffi::c_char;

use crate::device::process_name;
use crate::{Fail, LimberCode, LimberDevice, LimberLeaseHolder, arg, guard, ms, opt_str};

/// This handle's client id: how the driver, outcomes and `limber_device_holder` name it.
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_client_id(
    h: *mut LimberDevice,
    out: *mut u64,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "handle")?, arg(out, "out")?) };
        *out = h.client.client_id();
        Ok(())
    })
}

/// Takes the device's control lease as `name` (NULL: this program's name; 1 to 31 bytes,
/// else `LIMBER_CODE_INVALID_VALUE`). Until `limber_device_release_lease` (or disconnect),
/// other clients' commands, and their requests that change the device, are refused as
/// `LIMBER_STATUS_LEASED` naming `name`; readers are unaffected. Renew it at least every
/// `heartbeat_ms` (`limber_device_renew`, or `limber_device_keep_lease` in a loop): when the
/// heartbeat is missed, or this process dies, the driver stops the device and frees it.
/// Acquiring again sets a new heartbeat. Held by another client: `LIMBER_CODE_REFUSED`,
/// `limber_last_refusal()` is `LIMBER_STATUS_LEASED`, `limber_last_error()` and
/// `limber_last_holder()` name the holder. Waits for the driver's answer up to 2 s.
///
/// # Safety
/// `h` is NULL or a live handle; `name` is NULL or a NUL-terminated string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_acquire(
    h: *mut LimberDevice,
    name: *const c_char,
    heartbeat_ms: u64,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, name) = unsafe { (arg(h, "handle")?, opt_str(name, "name")?) };
        let name = match name {
            Some(n) => n.to_string(),
            None => {
                let mut n = process_name();
                n.truncate(crate::LIMBER_LEASE_NAME_MAX);
                n
            }
        };
        if name.is_empty() || name.len() > crate::LIMBER_LEASE_NAME_MAX {
            return Err(Fail::new(
                LimberCode::InvalidValue,
                format!(
                    "a lease name has 1 to {} bytes, not {} ({name:?})",
                    crate::LIMBER_LEASE_NAME_MAX,
                    name.len()
                ),
            ));
        }
        Ok(h.client.acquire(&name, ms(heartbeat_ms))?)
    })
}

/// The lease's heartbeat: tells the driver this holder lives. A lease that ended
/// meanwhile: `LIMBER_CODE_LEASE_LOST` (nobody holds it now) or `LIMBER_CODE_REFUSED` with
/// `LIMBER_STATUS_LEASED` (another client took it).
///
/// # Safety
/// `h` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_renew(h: *mut LimberDevice) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointer, checked for NULL here.
        Ok(unsafe { arg(h, "handle")? }.client.renew()?)
    })
}

/// For a control loop: renews the lease when a third of its heartbeat has passed since the
/// last renewal (`*renewed`, if not NULL, says whether it did); does nothing when no lease
/// is held. Fails as `limber_device_renew`.
///
/// # Safety
/// `h` is NULL or a live handle; `renewed` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_keep_lease(
    h: *mut LimberDevice,
    renewed: *mut bool,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, renewed) = unsafe { (arg(h, "handle")?, renewed.as_mut()) };
        let r = h.client.keep_lease()?;
        if let Some(out) = renewed {
            *out = r;
        }
        Ok(())
    })
}

/// Gives the control lease back (the motion in progress goes on). Without a lease it does
/// nothing. (`limber_device_release` ends the loan of a borrowed state.)
///
/// # Safety
/// `h` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_release_lease(h: *mut LimberDevice) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointer, checked for NULL here.
        Ok(unsafe { arg(h, "handle")? }.client.release()?)
    })
}

/// Whether this handle holds the device's control lease (as far as it knows: a lease lost
/// to a missed heartbeat shows at the next renewal).
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_holds_lease(
    h: *mut LimberDevice,
    out: *mut bool,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "handle")?, arg(out, "out")?) };
        *out = h.client.holds_lease();
        Ok(())
    })
}

/// Who holds the device's control lease: `out->client_id` is 0 when nobody does. Asks the
/// driver (waits for its answer up to 2 s).
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_holder(
    h: *mut LimberDevice,
    out: *mut LimberLeaseHolder,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "handle")?, arg(out, "out")?) };
        *out = h
            .client
            .holder()?
            .as_ref()
            .map(LimberLeaseHolder::of)
            .unwrap_or_default();
        Ok(())
    })
}
