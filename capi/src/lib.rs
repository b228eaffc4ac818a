#![doc = include_str!("../README.md")]
//! ## The library
//!
//! `liblimber.so` / `liblimber.a` and the header `include/limber_client.h` (generated from
//! this crate by cbindgen; `tests/header.rs` fails when it is stale). Every C function is
//! one Rust function here over [`limber_services::client`]: open a device by name, read its
//! latest state (borrowed in place from shared memory, or copied), wait for a newer one,
//! send every command (a ticket), every request (with a timeout), wait for a command's
//! outcome, ask whether the driver lives, list the devices of a domain.
//!
//! The states and geometries are the wire structs of `interfaces/include/limber.h`
//! (`limber_actarray_data`, `limber_limb_geom`, ...), which the generated header includes.
//!
//! Rules at the boundary: every function returns a [`LimberCode`] (0 = ok) and writes its
//! results through pointers; a NULL pointer or a string that is not UTF-8 is an error code,
//! never a crash; no panic crosses the boundary (each body runs under `catch_unwind`); the
//! detail of the last failure is kept per thread ([`limber_last_error`]).
//!
//! Thread-safety: each handle owns its own iceoryx2 node and ports (nothing reference-
//! counted is shared between handles), so different handles can be used by different
//! threads at once, and a handle may be handed from one thread to another between calls;
//! one handle must not be used by two threads at the same time.

use core::ffi::{CStr, c_char};
use core::time::Duration;
use std::cell::{Cell, RefCell};
use std::ffi::CString;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::OnceLock;

use limber_interfaces::InterfaceVisitor;
use limber_interfaces::prelude::*;
use limber_services::client::{
    CommandError, ConnectError, DriverStatus, LeaseError, LeaseHolder, Outcome, RequestError,
    Ticket, WaitError,
};
use limber_services::{Domain, ListError, NameError};

mod actarray;
mod device;
mod discovery;
mod done;
mod gripper;
mod lease;
mod limb;
mod log;
mod ranger;
mod stats;

pub use actarray::*;
pub use device::*;
pub use discovery::*;
pub use done::*;
pub use gripper::*;
pub use lease::*;
pub use limb::*;
pub use log::*;
pub use ranger::*;
pub use stats::*;

/// What a call returned: `LIMBER_CODE_OK` (0), or why it failed. The detail of a failure is
/// in `limber_last_error()`.
#[repr(i32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LimberCode {
    /// Done.
    Ok = 0,
    /// A required pointer argument is NULL.
    NullArgument = 1,
    /// A string argument is not valid UTF-8.
    BadUtf8 = 2,
    /// A device or domain name is invalid (devices are `robot/interface/index`).
    BadName = 3,
    /// No driver offers the device in the domain (or receives commands, or serves
    /// requests).
    NoDriver = 4,
    /// The device is of another interface, or speaks another layout version.
    Incompatible = 5,
    /// Nothing arrived within the timeout (the driver is alive).
    Timeout = 6,
    /// The driver died, or left, while waiting.
    DriverGone = 7,
    /// The driver refused the request; `limber_last_refusal()` says why.
    Refused = 8,
    /// A value is invalid (NaN or infinite, a bad joint index, too many values, a zero
    /// vector); nothing was sent.
    InvalidValue = 9,
    /// The command's outcome was overwritten before it was read: a later command of this
    /// handle has been applied since (so this one was applied too).
    OutcomeMissed = 10,
    /// A state borrowed from this handle is still held: release it first.
    Borrowed = 11,
    /// The reply could not be decoded, or was of an unexpected kind.
    BadReply = 12,
    /// iceoryx2 failed (shared memory, permissions on /dev/shm or /tmp/iceoryx2).
    Transport = 13,
    /// An internal error in limber (a panic was caught at the boundary); please report it.
    Internal = 14,
    /// The control lease of this handle ended (its heartbeat was missed, or the driver
    /// restarted): the driver stopped the device; acquire it again to go on.
    LeaseLost = 15,
}

/// Every code, in order.
const ALL_CODES: [LimberCode; 16] = [
    LimberCode::Ok,
    LimberCode::NullArgument,
    LimberCode::BadUtf8,
    LimberCode::BadName,
    LimberCode::NoDriver,
    LimberCode::Incompatible,
    LimberCode::Timeout,
    LimberCode::DriverGone,
    LimberCode::Refused,
    LimberCode::InvalidValue,
    LimberCode::OutcomeMissed,
    LimberCode::Borrowed,
    LimberCode::BadReply,
    LimberCode::Transport,
    LimberCode::Internal,
    LimberCode::LeaseLost,
];

impl LimberCode {
    /// The code's message, NUL-terminated.
    pub fn message(self) -> &'static CStr {
        match self {
            LimberCode::Ok => c"ok",
            LimberCode::NullArgument => c"a required pointer argument is NULL",
            LimberCode::BadUtf8 => c"a string argument is not valid UTF-8",
            LimberCode::BadName => c"invalid device or domain name",
            LimberCode::NoDriver => c"no driver offers the device",
            LimberCode::Incompatible => c"the device is of another interface or layout version",
            LimberCode::Timeout => c"nothing arrived within the timeout",
            LimberCode::DriverGone => c"the driver is gone",
            LimberCode::Refused => c"the driver refused the request",
            LimberCode::InvalidValue => c"invalid value; nothing was sent",
            LimberCode::OutcomeMissed => c"the outcome was overwritten by a later command's",
            LimberCode::Borrowed => c"a borrowed state is still held on this handle",
            LimberCode::BadReply => c"the reply could not be decoded",
            LimberCode::Transport => c"shared-memory transport failed (iceoryx2)",
            LimberCode::Internal => c"internal error in limber (please report it)",
            LimberCode::LeaseLost => c"the lease was lost (heartbeat missed)",
        }
    }
}

/// A command that was sent: pass it to `limber_*_wait_outcome`.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LimberTicket {
    /// The command's sequence number (per handle, from 1).
    pub seq: u64,
    /// How many driver processes received it (normally 1).
    pub receivers: u64,
}

/// Who holds a device's control lease (`limber_*_holder`).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LimberLeaseHolder {
    /// The holder's client id (as `limber_*_client_id` gives it); 0: nobody holds the
    /// device (then the other fields are zero).
    pub client_id: u64,
    /// The holder's heartbeat: it renews at least this often (ms).
    pub heartbeat_ms: u64,
    /// The holder's name, NUL-terminated (at most `LIMBER_LEASE_NAME_MAX` bytes).
    pub name: [c_char; 32],
}

/// The longest name of a lease holder, in bytes (`limber_*_acquire`).
pub const LIMBER_LEASE_NAME_MAX: usize = 31;
const _: () = assert!(LIMBER_LEASE_NAME_MAX + 1 == 32);

/// How fresh a handle's latest state is (`limber_*_liveness`).
#[repr(i32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LimberLiveness {
    /// The latest state is younger than the limit: the driver is alive and publishing.
    Alive = 0,
    /// The latest state is older than the limit, but the driver's process lives.
    Stale = 1,
    /// The driver's process is gone.
    Gone = 2,
    /// No state received yet.
    NoData = 3,
}

/// Whether a device's driver process lives (`limber_*_driver_status`).
#[repr(i32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LimberDriverStatus {
    /// Its process is alive.
    Alive = 0,
    /// Its process died without cleaning up (its resources are cleaned up now).
    Dead = 1,
    /// No driver is attached.
    Absent = 2,
}

/// Returns the message of `code` (a static string; "unknown limber code" for a value that
/// is not a code). Never NULL.
#[unsafe(no_mangle)]
pub extern "C" fn limber_strerror(code: i32) -> *const c_char {
    ALL_CODES
        .iter()
        .find(|c| **c as i32 == code)
        .map_or(c"unknown limber code".as_ptr(), |c| c.message().as_ptr())
}

/// Returns the detail of the last failure of a limber call on this thread (e.g. "no driver
/// offers pioneer/limb/7 in domain limber (is the driver running? ...)"), or of the last
/// outcome other than `LIMBER_STATUS_OK` that `limber_*_wait_outcome` returned (e.g.
/// "refused: held by another client (alice, client 123)"), or "" if none failed yet. Valid
/// until the next limber call on this thread. Never NULL.
#[unsafe(no_mangle)]
pub extern "C" fn limber_last_error() -> *const c_char {
    LAST_ERROR.with(|e| e.borrow().as_ptr())
}

/// Returns the driver's reason (a `LIMBER_STATUS_*` of limber.h) of the last
/// `LIMBER_CODE_REFUSED` on this thread, or of the last outcome other than OK that
/// `limber_*_wait_outcome` returned; `LIMBER_STATUS_OK` if there was none.
#[unsafe(no_mangle)]
pub extern "C" fn limber_last_refusal() -> u32 {
    LAST_REFUSAL.with(Cell::get)
}

/// Returns the text of a driver's `LIMBER_STATUS_*` (e.g. "the position lies beyond the
/// limb's reach"), or "unknown status" for a value that is none. Never NULL.
#[unsafe(no_mangle)]
pub extern "C" fn limber_status_text(status: u32) -> *const c_char {
    static TEXTS: OnceLock<Vec<CString>> = OnceLock::new();
    let texts = TEXTS.get_or_init(|| {
        Status::ALL
            .iter()
            .map(|s| CString::new(s.describe()).unwrap_or_default())
            .collect()
    });
    // By code, not by index: the codes have gaps (blocks given out per issue).
    Status::try_from(status)
        .ok()
        .and_then(|s| texts.get(Status::ALL.iter().position(|x| *x == s)?))
        .map_or(c"unknown status".as_ptr(), |t| t.as_ptr())
}

/// Returns the name of a driver's `LIMBER_STATUS_*` as limber.h spells it without its
/// prefix ("OK", "CLAMPED", "OUT_OF_REACH", ...), or "UNKNOWN" for a value that is none.
/// Never NULL.
#[unsafe(no_mangle)]
pub extern "C" fn limber_status_name(status: u32) -> *const c_char {
    static NAMES: OnceLock<Vec<CString>> = OnceLock::new();
    let names = NAMES.get_or_init(|| {
        Status::ALL
            .iter()
            .map(|s| CString::new(s.name()).unwrap_or_default())
            .collect()
    });
    Status::try_from(status)
        .ok()
        .and_then(|s| names.get(Status::ALL.iter().position(|x| *x == s)?))
        .map_or(c"UNKNOWN".as_ptr(), |t| t.as_ptr())
}

/// Whether a command with outcome `status` was carried out: `LIMBER_STATUS_OK`, and the
/// statuses that say how (`CLAMPED`: a value clamped to a limit; `ADJUSTED`: a limb pose's
/// orientation turned to one the joints can hold). False for every refusal and for a
/// value that is no status.
#[unsafe(no_mangle)]
pub extern "C" fn limber_status_is_carried_out(status: u32) -> bool {
    Status::try_from(status).is_ok_and(Status::is_carried_out)
}

/// Copies the holder of the device named by the last refusal on this thread because
/// another client holds it (`LIMBER_STATUS_LEASED`: a command's outcome, an acquire, a
/// request) into `*out`; `out->client_id` is 0 when the last failure was of another kind.
/// Does nothing for NULL.
///
/// # Safety
/// `out` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_last_holder(out: *mut LimberLeaseHolder) {
    // SAFETY: the caller's promise: NULL or writable.
    if let Some(out) = unsafe { out.as_mut() } {
        *out = LAST_HOLDER.with(Cell::get);
    }
}

/// Returns the layout version this library speaks (`LIMBER_LAYOUT_VERSION` of limber.h).
#[unsafe(no_mangle)]
pub extern "C" fn limber_layout_version() -> u32 {
    limber_interfaces::LAYOUT_VERSION
}

// ----- failures, recorded per thread ---------------------------------------------------

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
    static LAST_REFUSAL: Cell<u32> = const { Cell::new(0) };
    static LAST_HOLDER: Cell<LimberLeaseHolder> = Cell::new(LimberLeaseHolder::default());
}

/// A failed call: its code and detail.
#[derive(Debug)]
pub(crate) struct Fail {
    code: LimberCode,
    detail: String,
    refusal: u32,
    /// The holder of the device, for a refusal because another client holds it.
    holder: Option<LeaseHolder>,
}

impl Fail {
    pub(crate) fn new(code: LimberCode, detail: impl Into<String>) -> Self {
        Fail {
            code,
            detail: detail.into(),
            refusal: Status::Ok as u32,
            holder: None,
        }
    }

    pub(crate) fn from_error(code: LimberCode, e: &dyn std::error::Error) -> Self {
        let mut detail = e.to_string();
        let mut source = e.source();
        while let Some(s) = source {
            let text = s.to_string();
            if !detail.contains(&text) {
                detail.push_str(": ");
                detail.push_str(&text);
            }
            source = s.source();
        }
        Fail::new(code, detail)
    }

    /// Keeps the detail for `limber_last_error` and returns the code.
    fn record(self) -> LimberCode {
        let text = CString::new(self.detail.replace('\0', "?")).unwrap_or_default();
        LAST_ERROR.with(|e| *e.borrow_mut() = text);
        LAST_REFUSAL.with(|r| r.set(self.refusal));
        let holder = self
            .holder
            .as_ref()
            .map(LimberLeaseHolder::of)
            .unwrap_or_default();
        LAST_HOLDER.with(|h| h.set(holder));
        self.code
    }
}

impl From<ConnectError> for Fail {
    fn from(e: ConnectError) -> Self {
        let code = match &e {
            ConnectError::Name(_) => LimberCode::BadName,
            ConnectError::Context(_) => LimberCode::Transport,
            ConnectError::NoDriver { .. } => LimberCode::NoDriver,
            ConnectError::Incompatible { .. } => LimberCode::Incompatible,
            ConnectError::Transport { .. }
            | ConnectError::Permission { .. }
            | ConnectError::Full { .. } => LimberCode::Transport,
        };
        Fail::from_error(code, &e)
    }
}

impl From<CommandError> for Fail {
    fn from(e: CommandError) -> Self {
        let code = match &e {
            CommandError::Invalid(_) => LimberCode::InvalidValue,
            CommandError::NoDriver => LimberCode::NoDriver,
            CommandError::Transport(_) => LimberCode::Transport,
        };
        Fail::from_error(code, &e)
    }
}

impl From<RequestError> for Fail {
    fn from(e: RequestError) -> Self {
        let code = match &e {
            RequestError::Nack(_) => LimberCode::Refused,
            RequestError::Timeout(_) => LimberCode::Timeout,
            RequestError::NoDriver => LimberCode::NoDriver,
            RequestError::DriverGone => LimberCode::DriverGone,
            RequestError::Invalid(_) => LimberCode::InvalidValue,
            RequestError::Decode(_) | RequestError::Unexpected => LimberCode::BadReply,
            RequestError::Transport(_) => LimberCode::Transport,
        };
        let mut f = Fail::from_error(code, &e);
        if let RequestError::Nack(status) = e {
            f.refusal = status as u32;
        }
        f
    }
}

impl From<WaitError> for Fail {
    fn from(e: WaitError) -> Self {
        let code = match &e {
            WaitError::Timeout(_) => LimberCode::Timeout,
            WaitError::DriverGone => LimberCode::DriverGone,
            WaitError::Missed { .. } => LimberCode::OutcomeMissed,
            WaitError::Transport(_) => LimberCode::Transport,
        };
        Fail::from_error(code, &e)
    }
}

impl From<LeaseError> for Fail {
    fn from(e: LeaseError) -> Self {
        let (code, refusal) = match &e {
            LeaseError::Held { .. } => (LimberCode::Refused, Status::Leased),
            LeaseError::Refused(s) => (LimberCode::Refused, *s),
            LeaseError::Lost => (LimberCode::LeaseLost, Status::Ok),
            LeaseError::Timeout(_) => (LimberCode::Timeout, Status::Ok),
            LeaseError::NoDriver => (LimberCode::NoDriver, Status::Ok),
            LeaseError::DriverGone => (LimberCode::DriverGone, Status::Ok),
            LeaseError::Decode(_) => (LimberCode::BadReply, Status::Ok),
            LeaseError::Transport(_) => (LimberCode::Transport, Status::Ok),
        };
        let mut f = Fail::from_error(code, &e);
        f.refusal = refusal as u32;
        if let LeaseError::Held { client_id, name } = &e {
            f.holder = Some(LeaseHolder {
                client_id: *client_id,
                name: name.clone(),
                timeout: Duration::ZERO,
            });
        }
        f
    }
}

impl From<ValueError> for Fail {
    fn from(e: ValueError) -> Self {
        Fail::from_error(LimberCode::InvalidValue, &e)
    }
}

impl From<NameError> for Fail {
    fn from(e: NameError) -> Self {
        Fail::from_error(LimberCode::BadName, &e)
    }
}

impl From<ListError> for Fail {
    fn from(e: ListError) -> Self {
        Fail::from_error(LimberCode::Transport, &e)
    }
}

/// Runs the body of a C function: its failure is recorded for `limber_last_error`, and a
/// panic is caught here (it never unwinds into C) and reported as `LIMBER_CODE_INTERNAL`.
pub(crate) fn guard(body: impl FnOnce() -> Result<(), Fail>) -> LimberCode {
    match catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(())) => LimberCode::Ok,
        Ok(Err(fail)) => fail.record(),
        Err(_) => Fail::new(LimberCode::Internal, "internal error: a panic was caught").record(),
    }
}

/// Frees a handle made by `Box::into_raw` in a `*_connect` (NULL is ignored). Dropping it
/// closes the client's ports; a panic there is caught, recorded as the thread's last error
/// (a `void` function has no code to return) and logged.
///
/// # Safety
/// `h` is NULL or came from `Box::into_raw` of a `*_connect` and is freed once.
pub(crate) unsafe fn free_handle<T>(h: *mut T) {
    if h.is_null() {
        return;
    }
    // SAFETY: the caller's promise: a handle of `*_connect`, freed once.
    let h = unsafe { Box::from_raw(h) };
    let code = guard(move || {
        drop(h);
        Ok(())
    });
    if code != LimberCode::Ok {
        tracing::warn!(?code, "closing a handle failed");
    }
}

// ----- pointers from C ------------------------------------------------------------------

/// `p` as a reference, or `LIMBER_CODE_NULL_ARGUMENT` naming `what`.
///
/// # Safety
/// `p` is NULL or points to a valid, writable `T` not used elsewhere during the call.
pub(crate) unsafe fn arg<'a, T>(p: *mut T, what: &str) -> Result<&'a mut T, Fail> {
    // SAFETY: the caller promises `p` is NULL or valid and exclusive for the call.
    unsafe { p.as_mut() }
        .ok_or_else(|| Fail::new(LimberCode::NullArgument, format!("{what} is NULL")))
}

/// A NUL-terminated UTF-8 string argument; `None` for NULL.
///
/// # Safety
/// `p` is NULL or points to a NUL-terminated string valid during the call.
pub(crate) unsafe fn opt_str<'a>(p: *const c_char, what: &str) -> Result<Option<&'a str>, Fail> {
    if p.is_null() {
        return Ok(None);
    }
    // SAFETY: not NULL, and NUL-terminated per the caller's promise.
    let s = unsafe { CStr::from_ptr(p) };
    s.to_str().map(Some).map_err(|e| {
        Fail::new(
            LimberCode::BadUtf8,
            format!("{what} is not valid UTF-8: {e}"),
        )
    })
}

/// A required NUL-terminated UTF-8 string argument.
///
/// # Safety
/// As [`opt_str`].
pub(crate) unsafe fn req_str<'a>(p: *const c_char, what: &str) -> Result<&'a str, Fail> {
    // SAFETY: forwarded from the caller.
    unsafe { opt_str(p, what) }?
        .ok_or_else(|| Fail::new(LimberCode::NullArgument, format!("{what} is NULL")))
}

/// The domain named `domain`, or `LIMBER_DOMAIN`'s (default `limber`) for NULL.
pub(crate) fn domain_of(domain: Option<&str>) -> Result<Domain, Fail> {
    Ok(match domain {
        Some(d) => Domain::new(d)?,
        None => Domain::from_env()?,
    })
}

pub(crate) fn ms(timeout_ms: u64) -> Duration {
    Duration::from_millis(timeout_ms)
}

// ----- conversions at the boundary -----------------------------------------------------

impl LimberInterface {
    /// The C code of an interface.
    pub fn of(kind: InterfaceKind) -> Self {
        match kind {
            InterfaceKind::ActArray => LimberInterface::Actarray,
            InterfaceKind::Limb => LimberInterface::Limb,
            InterfaceKind::Gripper => LimberInterface::Gripper,
            InterfaceKind::Ranger => LimberInterface::Ranger,
        }
    }

    /// The interface of a C code, if it is one.
    pub fn kind_of(code: i32) -> Option<InterfaceKind> {
        InterfaceKind::ALL
            .into_iter()
            .find(|k| LimberInterface::of(*k) as i32 == code)
    }
}

impl LimberDriverStatus {
    pub(crate) fn of(s: DriverStatus) -> Self {
        match s {
            DriverStatus::Alive => LimberDriverStatus::Alive,
            DriverStatus::Dead => LimberDriverStatus::Dead,
            DriverStatus::Absent => LimberDriverStatus::Absent,
        }
    }
}

impl LimberLeaseHolder {
    pub(crate) fn of(h: &LeaseHolder) -> Self {
        let mut out = LimberLeaseHolder {
            client_id: h.client_id,
            heartbeat_ms: u64::try_from(h.timeout.as_millis()).unwrap_or(u64::MAX),
            name: [0; 32],
        };
        device::copy_str(&mut out.name, &h.name);
        out
    }
}

/// The sizes of an interface's state and geometry structs.
pub(crate) struct Sizes;

impl InterfaceVisitor for Sizes {
    type Output = (usize, usize);
    fn visit<I: Interface>(self) -> (usize, usize) {
        (size_of::<I::Data>(), size_of::<I::Geom>())
    }
}

/// A program compiled against another limber.h: another layout version, or (for a typed
/// connect, with the interface and the sizes of its state and geometry structs) structs of
/// other sizes.
pub(crate) fn incompatible_layout(
    version: u32,
    sizes: Option<(InterfaceKind, usize, usize)>,
) -> Fail {
    let ours = limber_interfaces::LAYOUT_VERSION;
    let detail = match sizes {
        Some((kind, data, geom)) => {
            let (d, g) = kind.visit(Sizes);
            format!(
                "this program was compiled against limber.h layout version {version} \
                 (limber_{k}_data {data} bytes, limber_{k}_geom {geom} bytes), but this \
                 liblimber speaks layout version {ours} ({d} and {g} bytes): rebuild the \
                 program against the limber.h installed with this library",
                k = kind.name()
            )
        }
        None => format!(
            "this program was compiled against limber.h layout version {version}, but this \
             liblimber speaks layout version {ours}: rebuild the program against the \
             limber.h installed with this library"
        ),
    };
    tracing::warn!("{detail}");
    Fail::new(LimberCode::Incompatible, detail)
}

impl Fail {
    /// The detail of an outcome that is not OK: its status, and the other client involved
    /// (for `LIMBER_STATUS_LEASED`, the holder, also kept for `limber_last_holder`).
    pub(crate) fn refused_outcome(o: &Outcome) -> Fail {
        let mut t = format!("refused: {}", o.status.describe());
        let mut holder = None;
        if o.status == Status::Leased {
            let name = if o.other_name().is_empty() {
                "unnamed"
            } else {
                o.other_name()
            };
            t = format!(
                "refused: held by another client ({name}, client {})",
                o.other_client
            );
            holder = Some(LeaseHolder {
                client_id: o.other_client,
                name: o.other_name().to_string(),
                timeout: Duration::ZERO,
            });
        } else if o.other_client != 0 {
            t.push_str(&format!(" (by client {})", o.other_client));
        }
        let mut f = Fail::new(LimberCode::Refused, t);
        f.refusal = o.status as u32;
        f.holder = holder;
        f
    }
}

/// Writes a sent command's ticket (if `out` is given).
pub(crate) fn sent(
    r: Result<Ticket, CommandError>,
    out: Option<&mut LimberTicket>,
) -> Result<(), Fail> {
    let t = r?;
    if let Some(out) = out {
        *out = LimberTicket {
            seq: t.seq,
            receivers: t.receivers as u64,
        };
    }
    Ok(())
}

/// A request of interface `I` with its timeout.
pub(crate) fn request<I: Interface>(
    c: &mut limber_services::Client<I>,
    req: &I::Request,
    timeout_ms: u64,
) -> Result<I::Reply, Fail> {
    Ok(c.request_with_timeout(req, ms(timeout_ms))?)
}
