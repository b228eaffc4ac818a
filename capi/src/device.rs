//! `limber_device_*`: everything an interface does not change, once for every interface:
//! connect, states (copied or borrowed), waits, outcomes, liveness, the control lease,
//! preemption, the geometry. A handle of any interface is a `limber_device`; the typed
//! handles of limber_client.h (`limber_actarray`, `limber_limb`, `limber_gripper`) are the
//! same type, so every call here takes them as they are. Only commands and requests are
//! per interface (`actarray.rs`, `limb.rs`, `gripper.rs`).

use core::ffi::{c_char, c_void};
use std::ffi::CString;

use limber_interfaces::prelude::*;
use limber_services::client::{DeviceClient, Freshness, Ticket, WaitMode, connect_device};
use limber_services::{ConnectError, Context, Role};

use crate::{
    Fail, LimberCode, LimberDriverStatus, LimberInterface, LimberLiveness, LimberTicket, arg,
    domain_of, guard, ms, opt_str, req_str,
};

/// A connection to one device, of any interface (opaque). Use it from one thread at a
/// time; different handles may be used by different threads at once.
pub struct LimberDevice {
    pub(crate) client: Box<dyn DeviceClient>,
    /// A state sample is lent to the caller ([`limber_device_borrow`]).
    borrowed: bool,
    name: CString,
}

/// The outcome of a command, with the other client involved
/// ([`limber_device_outcome`], [`limber_device_preemption`]).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LimberOutcome {
    /// The command's sequence number (its ticket's `seq`).
    pub seq: u64,
    /// The driver's verdict, a `LIMBER_STATUS_*` of limber.h.
    pub status: u32,
    /// Explicit padding (zero).
    pub _pad: u32,
    /// The other client involved: the one whose command preempted this one
    /// (`LIMBER_STATUS_PREEMPTED`) or the holder of the device (`LIMBER_STATUS_LEASED`); 0
    /// if none.
    pub other_client: u64,
    /// When the driver published it (`CLOCK_MONOTONIC` ns).
    pub stamp_ns: u64,
    /// The other client's lease name, NUL-terminated ("" when it has none).
    pub other_name: [c_char; 32],
}

/// The name set by [`limber_set_program_name`], if any.
static PROGRAM_NAME: std::sync::Mutex<Option<String>> = std::sync::Mutex::new(None);

/// The name this process shows in `limber list`: the one set by `limber_set_program_name`,
/// else its executable's.
pub(crate) fn process_name() -> String {
    if let Some(n) = PROGRAM_NAME
        .lock()
        .unwrap_or_else(std::sync::PoisonError::into_inner)
        .clone()
    {
        return n;
    }
    std::env::args()
        .next()
        .and_then(|a| {
            std::path::Path::new(&a)
                .file_name()
                .map(|s| s.to_string_lossy().to_string())
        })
        .filter(|n| n.len() <= 60 && n.bytes().all(|b| b.is_ascii_graphic()))
        .unwrap_or_else(|| "c-client".to_string())
}

/// Copies `s` into `dst` as a NUL-terminated string, cut at a character boundary to fit.
pub(crate) fn copy_str(dst: &mut [c_char], s: &str) {
    let mut n = s.len().min(dst.len() - 1);
    while !s.is_char_boundary(n) {
        n -= 1;
    }
    for (d, b) in dst.iter_mut().zip(&s.as_bytes()[..n]) {
        *d = *b as c_char;
    }
    dst[n] = 0;
}

impl LimberDevice {
    pub(crate) fn not_borrowed(&self) -> Result<(), Fail> {
        if self.borrowed {
            Err(Fail::new(
                LimberCode::Borrowed,
                "a state borrowed from this handle is still held: release it first",
            ))
        } else {
            Ok(())
        }
    }

    /// The typed client of interface `I`, or `LIMBER_CODE_INCOMPATIBLE` naming both.
    pub(crate) fn typed<I: Interface>(&mut self) -> Result<&mut limber_services::Client<I>, Fail> {
        let (kind, name) = (self.client.kind(), self.client.device().to_string());
        (*self.client).typed::<I>().ok_or_else(|| {
            Fail::new(
                LimberCode::Incompatible,
                format!(
                    "{name} is {}, not {}: use the functions of its interface",
                    kind.with_article(),
                    I::KIND.with_article()
                ),
            )
        })
    }
}

pub(crate) fn ticket_of(t: &LimberTicket) -> Ticket {
    Ticket {
        seq: t.seq,
        receivers: usize::try_from(t.receivers).unwrap_or(usize::MAX),
    }
}

/// `LIMBER_CODE_INCOMPATIBLE` unless `size` is `expected` (the caller's struct is this
/// library's).
fn check_size(what: &str, size: usize, expected: usize, kind: InterfaceKind) -> Result<(), Fail> {
    if size == expected {
        return Ok(());
    }
    Err(Fail::new(
        LimberCode::Incompatible,
        format!(
            "the {what} of {} has {expected} bytes in this liblimber, the caller's struct \
             {size}: pass the struct of the device's interface, from the limber.h installed \
             with this library",
            kind.with_article()
        ),
    ))
}

/// Copies `bytes` to `out`, which the caller says has `size` bytes.
///
/// # Safety
/// `out` is NULL or points to `size` writable bytes.
unsafe fn copy_out(
    what: &str,
    bytes: &[u8],
    out: *mut c_void,
    size: usize,
    kind: InterfaceKind,
) -> Result<(), Fail> {
    if out.is_null() {
        return Err(Fail::new(LimberCode::NullArgument, "out is NULL"));
    }
    check_size(what, size, bytes.len(), kind)?;
    // SAFETY: `out` is not NULL and, per the caller, has `size` == bytes.len() writable
    // bytes; the source is a live sample or buffer that does not overlap it.
    unsafe { core::ptr::copy_nonoverlapping(bytes.as_ptr(), out.cast::<u8>(), bytes.len()) };
    Ok(())
}

/// Connects to `device` ("robot/interface/index") in `domain` (NULL: `LIMBER_DOMAIN`, or
/// "limber"), waiting up to `timeout_ms` for a driver to offer it; `*out` is the new
/// handle (free it with `limber_device_disconnect`). Call it through the inline functions
/// of limber_client.h (`limber_device_connect`, `limber_actarray_connect`, ...), which pass
/// the layout the program was compiled against: `layout_version`
/// (`LIMBER_LAYOUT_VERSION`), and, for a typed connect, the interface the program expects
/// (`interface`, a `LIMBER_INTERFACE_*`; -1: any) and the sizes of its state and geometry
/// structs (`data_size`, `geom_size`; 0: not checked). A program compiled against another
/// limber.h, or a device of another interface than the one asked for, is refused with
/// `LIMBER_CODE_INCOMPATIBLE` before it connects, and `limber_last_error()` says what differs.
///
/// # Safety
/// `device` and `domain` are NULL or NUL-terminated strings; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_connect_checked(
    device: *const c_char,
    domain: *const c_char,
    timeout_ms: u64,
    layout_version: u32,
    interface: i32,
    data_size: usize,
    geom_size: usize,
    out: *mut *mut LimberDevice,
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
        let name: limber_services::DeviceName = device.parse()?;
        let kind = name.interface();
        if interface >= 0 && LimberInterface::of(kind) as i32 != interface {
            let asked = LimberInterface::kind_of(interface)
                .map_or("an unknown interface", |k| k.with_article());
            return Err(Fail::new(
                LimberCode::Incompatible,
                format!("{device} is {}, not {asked}", kind.with_article()),
            ));
        }
        let (ds, gs) = kind.visit(crate::Sizes);
        let sizes_differ =
            (data_size != 0 && data_size != ds) || (geom_size != 0 && geom_size != gs);
        if layout_version != limber_interfaces::LAYOUT_VERSION || sizes_differ {
            return Err(crate::incompatible_layout(
                layout_version,
                (data_size != 0).then_some((kind, data_size, geom_size)),
            ));
        }
        let ctx = Context::new(&domain_of(domain)?, Role::Client, &process_name())
            .map_err(|e| Fail::from(ConnectError::from(e)))?;
        let client = connect_device(&ctx, device, ms(timeout_ms))?;
        let name = CString::new(device).unwrap_or_default();
        *out = Box::into_raw(Box::new(LimberDevice {
            client,
            borrowed: false,
            name,
        }));
        Ok(())
    })
}

/// Closes the connection and frees the handle (and any state borrowed from it). NULL is
/// ignored.
///
/// # Safety
/// `h` is NULL or a handle of a connect call not yet disconnected.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_disconnect(h: *mut LimberDevice) {
    // SAFETY: the caller's promise: NULL or a handle of a connect call, freed once.
    unsafe { crate::free_handle(h) }
}

/// The device's name ("robot/interface/index"), valid as long as the handle; "" for NULL.
///
/// # Safety
/// `h` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_name(h: *const LimberDevice) -> *const c_char {
    // SAFETY: the caller's promise: NULL or a live handle.
    match unsafe { h.as_ref() } {
        Some(h) => h.name.as_ptr(),
        None => c"".as_ptr(),
    }
}

/// The device's interface.
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_interface(
    h: *mut LimberDevice,
    out: *mut LimberInterface,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "handle")?, arg(out, "out")?) };
        *out = LimberInterface::of(h.client.kind());
        Ok(())
    })
}

/// A state that `take` gives, copied to `out` (`size` bytes): the body of the calls that
/// copy a state out (state, last state, wait state).
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or points to `size` writable bytes.
unsafe fn state_into(
    h: *mut LimberDevice,
    out: *mut c_void,
    size: usize,
    take: impl FnOnce(&mut dyn DeviceClient) -> Result<&[u8], Fail>,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the handle, checked for NULL here.
        let h = unsafe { arg(h, "handle")? };
        h.not_borrowed()?;
        let kind = h.client.kind();
        let bytes = take(&mut *h.client)?;
        // SAFETY: the caller's promise on `out` and `size`.
        unsafe { copy_out("state", bytes, out, size, kind) }
    })
}

/// Copies the latest state into `*out`, a struct of `size` bytes (the device's state
/// struct: `limber_actarray_data`, ...; another size is `LIMBER_CODE_INCOMPATIBLE`),
/// waiting up to `timeout_ms` for a first one (`LIMBER_CODE_TIMEOUT` if none came).
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or points to `size` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_state(
    h: *mut LimberDevice,
    timeout_ms: u64,
    out: *mut c_void,
    size: usize,
) -> LimberCode {
    // SAFETY: forwarded from the caller.
    unsafe { state_into(h, out, size, |c| Ok(c.current_bytes(ms(timeout_ms))?)) }
}

/// Copies the latest state already taken into `*out` (a struct of `size` bytes, as
/// `limber_device_state`), without looking for a newer one; `LIMBER_CODE_TIMEOUT` when no
/// state was taken yet.
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or points to `size` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_last_state(
    h: *mut LimberDevice,
    out: *mut c_void,
    size: usize,
) -> LimberCode {
    // SAFETY: forwarded from the caller.
    unsafe {
        state_into(h, out, size, |c| {
            c.state_bytes()
                .ok_or_else(|| Fail::new(LimberCode::Timeout, "no state was taken yet"))
        })
    }
}

/// Lends the latest state in place, without a copy (waiting up to `timeout_ms` for a
/// first one): `*out` points into shared memory at the device's state struct and stays
/// valid and unchanged until `limber_device_release` (or disconnect). Meanwhile the calls
/// that read states (state, borrow, wait_state, outcome, preemption, liveness) fail with
/// `LIMBER_CODE_BORROWED`; commands and requests work.
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_borrow(
    h: *mut LimberDevice,
    timeout_ms: u64,
    out: *mut *const c_void,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "handle")?, arg(out, "out")?) };
        h.not_borrowed()?;
        *out = h.client.current_bytes(ms(timeout_ms))?.as_ptr().cast();
        h.borrowed = true;
        Ok(())
    })
}

/// Ends the loan of `limber_device_borrow` (the pointer it gave is invalid from now on).
/// Releasing with nothing borrowed is harmless.
///
/// # Safety
/// `h` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_release(h: *mut LimberDevice) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the handle, checked for NULL here.
        unsafe { arg(h, "handle")? }.borrowed = false;
        Ok(())
    })
}

/// Takes every state and outcome that arrived, without waiting; `*fresh` (NULL: not
/// written) says whether a new state came. What a program that polls
/// `limber_device_fd` calls when the descriptor is readable.
///
/// # Safety
/// `h` is NULL or a live handle; `fresh` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_refresh(
    h: *mut LimberDevice,
    fresh: *mut bool,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, fresh) = unsafe { (arg(h, "handle")?, fresh.as_mut()) };
        h.not_borrowed()?;
        h.client.take_notifications()?;
        let f = h.client.refresh()?;
        if let Some(out) = fresh {
            *out = f;
        }
        Ok(())
    })
}

/// A file descriptor that becomes readable when the driver notifies this handle (a new
/// state, an outcome, a reply), for `poll(2)`, `select(2)` or `epoll(7)` over several
/// devices (or sockets, timers...) at once. When it is readable, call
/// `limber_device_refresh`, then read the state. The descriptor is the handle's: do not
/// close it; it is valid until `limber_device_disconnect`.
///
/// # Safety
/// `h` is NULL or a live handle; `fd` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_fd(h: *mut LimberDevice, fd: *mut i32) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, fd) = unsafe { (arg(h, "handle")?, arg(fd, "fd")?) };
        *fd = h.client.notification_fd()?;
        Ok(())
    })
}

/// Waits up to `timeout_ms` for a state newer than the latest one taken and copies it into
/// `*out` (NULL: not copied; else a struct of `size` bytes, as `limber_device_state`).
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or points to `size` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_wait_state(
    h: *mut LimberDevice,
    timeout_ms: u64,
    out: *mut c_void,
    size: usize,
) -> LimberCode {
    if out.is_null() {
        // Waited for, not copied.
        return guard(|| {
            // SAFETY: the caller's promise on the handle, checked for NULL here.
            let h = unsafe { arg(h, "handle")? };
            h.not_borrowed()?;
            h.client.wait_state_bytes(ms(timeout_ms))?;
            Ok(())
        });
    }
    // SAFETY: forwarded from the caller.
    unsafe { state_into(h, out, size, |c| Ok(c.wait_state_bytes(ms(timeout_ms))?)) }
}

/// Waits up to `timeout_ms` for the outcome of the command of `ticket` and writes it to
/// `*out`: the driver's `LIMBER_STATUS_*`, and the other client involved (the holder of the
/// device for `LIMBER_STATUS_LEASED`, with its name). When it returns, the latest state
/// shows the command. A status other than OK is also kept for `limber_last_refusal()` and
/// `limber_last_error()`; the call still returns `LIMBER_CODE_OK`. On
/// `LIMBER_CODE_OUTCOME_MISSED`, `out->seq` is the later command of this handle whose
/// outcome was seen (the rest is zero).
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_outcome(
    h: *mut LimberDevice,
    ticket: LimberTicket,
    timeout_ms: u64,
    out: *mut LimberOutcome,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "handle")?, arg(out, "out")?) };
        outcome_into(h, &ticket, timeout_ms, out)
    })
}

fn outcome_into(
    h: &mut LimberDevice,
    ticket: &LimberTicket,
    timeout_ms: u64,
    out: &mut LimberOutcome,
) -> Result<(), Fail> {
    {
        h.not_borrowed()?;
        let o = match h
            .client
            .wait_outcome_detail(ticket_of(ticket), ms(timeout_ms))
        {
            Ok(o) => o,
            Err(e) => {
                if let limber_services::client::WaitError::Missed { newer_seq } = e {
                    *out = LimberOutcome {
                        seq: newer_seq,
                        ..LimberOutcome::default()
                    };
                }
                return Err(e.into());
            }
        };
        if o.status != Status::Ok {
            Fail::refused_outcome(&o).record();
        }
        *out = outcome_of(&o);
        Ok(())
    }
}

/// Waits up to `timeout_ms` for the outcome of the command of `ticket`; `*status` is the
/// driver's `LIMBER_STATUS_*` (`LIMBER_STATUS_OK`: carried out as asked;
/// `limber_status_is_carried_out` tells the other "ok" statuses apart). As
/// `limber_device_outcome`, with the status alone.
///
/// # Safety
/// `h` is NULL or a live handle; `status` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_wait_outcome(
    h: *mut LimberDevice,
    ticket: LimberTicket,
    timeout_ms: u64,
    status: *mut u32,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, status) = unsafe { (arg(h, "handle")?, arg(status, "status")?) };
        let mut o = LimberOutcome::default();
        outcome_into(h, &ticket, timeout_ms, &mut o)?;
        *status = o.status;
        Ok(())
    })
}

fn outcome_of(o: &limber_services::Outcome) -> LimberOutcome {
    let mut out = LimberOutcome {
        seq: o.seq,
        status: o.status as u32,
        _pad: 0,
        other_client: o.other_client,
        stamp_ns: o.stamp_ns,
        other_name: [0; 32],
    };
    copy_str(&mut out.other_name, o.other_name());
    out
}

/// Whether another client's command cut short the motion that the command of `ticket`
/// started (`LIMBER_STATUS_PREEMPTED`): `*preempted`, and `*out` (NULL: not written; zero
/// if not preempted) the preempting client with its name. Looks at the outcomes that
/// arrived, without waiting; remembers this handle's last 16 commands.
///
/// # Safety
/// `h` is NULL or a live handle; `preempted` is NULL or writable; `out` is NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_preemption(
    h: *mut LimberDevice,
    ticket: LimberTicket,
    preempted: *mut bool,
    out: *mut LimberOutcome,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, preempted, out) = unsafe {
            (
                arg(h, "handle")?,
                arg(preempted, "preempted")?,
                out.as_mut(),
            )
        };
        h.not_borrowed()?;
        let p = h.client.preempted(ticket_of(&ticket))?;
        *preempted = p.is_some();
        if let Some(out) = out {
            *out = p.as_ref().map(outcome_of).unwrap_or_default();
        }
        Ok(())
    })
}

/// As `limber_device_preemption`, with the preempting client's id alone (`*by_client`,
/// NULL: not written; 0 if not preempted).
///
/// # Safety
/// `h` is NULL or a live handle; `preempted` is NULL or writable; `by_client` is NULL or
/// writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_preempted(
    h: *mut LimberDevice,
    ticket: LimberTicket,
    preempted: *mut bool,
    by_client: *mut u64,
) -> LimberCode {
    let mut o = LimberOutcome::default();
    // SAFETY: forwarded from the caller; `o` is a local.
    let code = unsafe { limber_device_preemption(h, ticket, preempted, &mut o) };
    if code == LimberCode::Ok {
        // SAFETY: the caller's promise: NULL or writable.
        if let Some(b) = unsafe { by_client.as_mut() } {
            *b = o.other_client;
        }
    }
    code
}

/// Whether the driver publishes: `LIMBER_LIVENESS_ALIVE` if the latest state is younger
/// than `max_age_ms`, `STALE` if older but the driver lives, `GONE`, or `NO_DATA`.
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_liveness(
    h: *mut LimberDevice,
    max_age_ms: u64,
    out: *mut LimberLiveness,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "handle")?, arg(out, "out")?) };
        h.not_borrowed()?;
        *out = match h.client.freshness(ms(max_age_ms)) {
            Freshness::Fresh => LimberLiveness::Alive,
            Freshness::Stale => LimberLiveness::Stale,
            Freshness::Gone => LimberLiveness::Gone,
            Freshness::NoData => LimberLiveness::NoData,
        };
        Ok(())
    })
}

/// The age of the latest state taken, in nanoseconds (`CLOCK_MONOTONIC` now minus its
/// acquisition stamp); `LIMBER_CODE_TIMEOUT` when no state was taken yet.
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_state_age(
    h: *mut LimberDevice,
    out: *mut u64,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "handle")?, arg(out, "out")?) };
        let age = h
            .client
            .state_age()
            .ok_or_else(|| Fail::new(LimberCode::Timeout, "no state was taken yet"))?;
        *out = u64::try_from(age.as_nanos()).unwrap_or(u64::MAX);
        Ok(())
    })
}

/// Whether the driver's process lives (costs tens of microseconds).
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_driver_status(
    h: *mut LimberDevice,
    out: *mut LimberDriverStatus,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointers, checked for NULL here.
        let (h, out) = unsafe { (arg(h, "handle")?, arg(out, "out")?) };
        *out = LimberDriverStatus::of(h.client.driver_status());
        Ok(())
    })
}

/// REQ GET_GEOM (the limb's GEOM): copies the geometry into `*out`, a struct of `size`
/// bytes (the device's geometry struct: `limber_actarray_geom`, `limber_limb_geom`,
/// `limber_gripper_geom`); waits up to `timeout_ms` for the reply.
///
/// # Safety
/// `h` is NULL or a live handle; `out` is NULL or points to `size` writable bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_geometry(
    h: *mut LimberDevice,
    timeout_ms: u64,
    out: *mut c_void,
    size: usize,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the handle, checked for NULL here.
        let h = unsafe { arg(h, "handle")? };
        let kind = h.client.kind();
        let g = h.client.geometry_within(ms(timeout_ms))?;
        // SAFETY: the caller's promise on `out` and `size`.
        unsafe { copy_out("geometry", g.bytes(), out, size, kind) }
    })
}

/// How this handle waits for states, outcomes and replies: `spin` false (the default)
/// blocks on the driver's notification after busy-polling for `spin_budget_us`
/// microseconds after each send (0: blocks at once; the default comes from
/// `LIMBER_SPIN_US`); `spin` true busy-polls shared memory (lowest latency; takes a core).
///
/// # Safety
/// `h` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_set_wait(
    h: *mut LimberDevice,
    spin: bool,
    spin_budget_us: u64,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the handle, checked for NULL here.
        let h = unsafe { arg(h, "handle")? };
        h.client.set_wait_mode(if spin {
            WaitMode::Spin
        } else {
            WaitMode::Event
        });
        h.client
            .set_spin_budget(core::time::Duration::from_micros(spin_budget_us));
        Ok(())
    })
}

/// How long this handle's requests that take no timeout of their own wait for the
/// driver's answer (the lease calls: acquire, renew, release, holder); 2000 ms by default.
///
/// # Safety
/// `h` is NULL or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_device_set_request_timeout(
    h: *mut LimberDevice,
    timeout_ms: u64,
) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the handle, checked for NULL here.
        unsafe { arg(h, "handle")? }
            .client
            .set_request_timeout(ms(timeout_ms));
        Ok(())
    })
}

/// The spin budget a new handle starts with, in microseconds: `LIMBER_SPIN_US` if set (at
/// most 1 s), else 30 on a machine with two or more cores and 0 on one (read once per
/// process).
#[unsafe(no_mangle)]
pub extern "C" fn limber_default_spin_budget_us() -> u64 {
    u64::try_from(limber_services::qos::default_spin_budget().as_micros()).unwrap_or(u64::MAX)
}

/// Names this process in `limber list` (and in leases taken with a NULL name) for the
/// handles and readers opened from now on: 1 to 60 printable ASCII characters, else
/// `LIMBER_CODE_INVALID_VALUE`; NULL goes back to the executable's name (the default).
///
/// # Safety
/// `name` is NULL or a NUL-terminated string.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_set_program_name(name: *const c_char) -> LimberCode {
    guard(|| {
        // SAFETY: the caller's promise on the pointer.
        let name = unsafe { opt_str(name, "name")? };
        if let Some(n) = name
            && (n.is_empty() || n.len() > 60 || !n.bytes().all(|b| b.is_ascii_graphic()))
        {
            return Err(Fail::new(
                LimberCode::InvalidValue,
                format!("a program name has 1 to 60 printable ASCII characters, not {n:?}"),
            ));
        }
        *PROGRAM_NAME
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner) = name.map(str::to_string);
        Ok(())
    })
}
