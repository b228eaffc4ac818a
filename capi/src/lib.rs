//! # limber-c: the limber client API for C and C++
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

use limber_interfaces::prelude::*;
use limber_services::client::{
    Client, CommandError, ConnectError, DriverStatus, Freshness, LeaseError, Outcome, RequestError,
    Ticket, WaitError,
};
use limber_services::{Context, Domain, ListError, NameError, Role};

mod actarray;
mod discovery;
mod gripper;
mod limb;

pub use actarray::*;
pub use discovery::*;
pub use gripper::*;
pub use limb::*;

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
    texts
        .get(status as usize)
        .map_or(c"unknown status".as_ptr(), |t| t.as_ptr())
}

/// Returns the layout version this library speaks (`LIMBER_LAYOUT_VERSION` of limber.h).
#[unsafe(no_mangle)]
pub extern "C" fn limber_layout_version() -> u32 {
    limber_interfaces::LAYOUT_VERSION
}

/// The layout a program was compiled against: the `LIMBER_LAYOUT_VERSION` of its limber.h
/// and the sizes of the state and geometry structs it passes (`limber_*_connect`, the
/// header's inline functions, fill them in).
pub(crate) struct CompiledLayout {
    /// `LIMBER_LAYOUT_VERSION` of the program's limber.h.
    pub version: u32,
    /// `sizeof` the state struct in the program.
    pub data_size: usize,
    /// `sizeof` the geometry struct in the program.
    pub geom_size: usize,
}

impl CompiledLayout {
    /// Refuses (`LIMBER_CODE_INCOMPATIBLE`) a program whose limber.h is not this library's:
    /// another layout version, or a state or geometry struct of another size. A field moved
    /// in a message bumps the layout version (the rule of limber.h), so such a program
    /// cannot connect and misread the states.
    pub(crate) fn check<D, G>(&self, data: &str, geom: &str) -> Result<(), Fail> {
        let ours = (
            limber_interfaces::LAYOUT_VERSION,
            size_of::<D>(),
            size_of::<G>(),
        );
        if (self.version, self.data_size, self.geom_size) == ours {
            return Ok(());
        }
        let detail = format!(
            "this program was compiled against limber.h layout version {} ({data} {} bytes, \
             {geom} {} bytes), but this liblimber speaks layout version {} ({} and {} bytes): \
             rebuild the program against the limber.h installed with this library",
            self.version, self.data_size, self.geom_size, ours.0, ours.1, ours.2
        );
        tracing::warn!("{detail}");
        Err(Fail::new(LimberCode::Incompatible, detail))
    }
}

// ----- failures, recorded per thread ---------------------------------------------------

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
    static LAST_REFUSAL: Cell<u32> = const { Cell::new(0) };
}

/// A failed call: its code and detail.
#[derive(Debug)]
pub(crate) struct Fail {
    code: LimberCode,
    detail: String,
    refusal: u32,
}

impl Fail {
    pub(crate) fn new(code: LimberCode, detail: impl Into<String>) -> Self {
        Fail {
            code,
            detail: detail.into(),
            refusal: Status::Ok as u32,
        }
    }

    fn from_error(code: LimberCode, e: &dyn std::error::Error) -> Self {
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
            ConnectError::Transport { .. } | ConnectError::Permission { .. } => {
                LimberCode::Transport
            }
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

// ----- one handle, any interface --------------------------------------------------------

/// The state of one C handle: its client (with its own iceoryx2 node) and whether a state
/// sample is lent to the caller.
///
/// A lent sample is the client's latest one, which only [`Client::refresh`] replaces (and
/// with it releases the old one to the driver, who may overwrite it). Every call that
/// refreshes (state, current, wait_state, wait_outcome, preempted, freshness) is refused while a
/// sample is lent; commands, requests and `driver_status` do not refresh and stay allowed.
pub(crate) struct Handle<I: Interface> {
    pub(crate) client: Client<I>,
    borrowed: bool,
}

/// The name this process shows in `limber list`: its executable's.
fn process_name() -> String {
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

impl<I: Interface> Handle<I> {
    /// Connects to `device` in `domain` (NULL: `LIMBER_DOMAIN`), waiting up to
    /// `timeout_ms` for a driver to offer it. Each handle joins the domain with a node of
    /// its own.
    pub(crate) fn connect(
        device: &str,
        domain: Option<&str>,
        timeout_ms: u64,
    ) -> Result<Self, Fail> {
        let domain = domain_of(domain)?;
        let ctx = Context::new(&domain, Role::Client, &process_name())
            .map_err(|e| Fail::from(ConnectError::from(e)))?;
        let client = Client::<I>::connect_timeout(&ctx, device, ms(timeout_ms))?;
        Ok(Handle {
            client,
            borrowed: false,
        })
    }

    fn not_borrowed(&self) -> Result<(), Fail> {
        if self.borrowed {
            Err(Fail::new(
                LimberCode::Borrowed,
                "a state borrowed from this handle is still held: release it first",
            ))
        } else {
            Ok(())
        }
    }

    /// Copies the latest state into `out`, waiting up to `timeout_ms` for a first one.
    pub(crate) fn state(&mut self, timeout_ms: u64, out: &mut I::Data) -> Result<(), Fail> {
        self.not_borrowed()?;
        *out = *self.client.current(ms(timeout_ms))?;
        Ok(())
    }

    /// Lends the latest state in place (waiting up to `timeout_ms` for a first one) until
    /// [`Handle::release`].
    pub(crate) fn borrow(&mut self, timeout_ms: u64) -> Result<*const I::Data, Fail> {
        self.not_borrowed()?;
        let p: *const I::Data = self.client.current(ms(timeout_ms))?;
        self.borrowed = true;
        Ok(p)
    }

    /// Ends the loan of [`Handle::borrow`].
    pub(crate) fn release(&mut self) {
        self.borrowed = false;
    }

    /// Waits up to `timeout_ms` for a state newer than the latest taken; copies it into
    /// `out` if given.
    pub(crate) fn wait_state(
        &mut self,
        timeout_ms: u64,
        out: Option<&mut I::Data>,
    ) -> Result<(), Fail> {
        self.not_borrowed()?;
        let d = *self.client.wait_state(ms(timeout_ms))?;
        if let Some(out) = out {
            *out = d;
        }
        Ok(())
    }

    /// Waits up to `timeout_ms` for the outcome of `ticket` (a `LIMBER_STATUS_*`). An
    /// outcome other than `LIMBER_STATUS_OK` is kept for `limber_last_error` and
    /// `limber_last_refusal` too (for `LIMBER_STATUS_LEASED`, with the holder's name).
    pub(crate) fn wait_outcome(
        &mut self,
        ticket: &LimberTicket,
        timeout_ms: u64,
    ) -> Result<u32, Fail> {
        self.not_borrowed()?;
        let o = self
            .client
            .wait_outcome_detail(ticket_of(ticket), ms(timeout_ms))?;
        if o.status != Status::Ok {
            let mut f = Fail::new(LimberCode::Refused, outcome_text(&o));
            f.refusal = o.status as u32;
            f.record();
        }
        Ok(o.status as u32)
    }

    /// Takes the device's control lease as `name` (`None`: this process's name),
    /// renewed at least every `heartbeat_ms`.
    pub(crate) fn acquire(&mut self, name: Option<&str>, heartbeat_ms: u64) -> Result<(), Fail> {
        let name = match name {
            Some(n) => n.to_string(),
            None => {
                let mut n = process_name();
                n.truncate(LIMBER_LEASE_NAME_MAX);
                n
            }
        };
        if name.is_empty() || name.len() > LIMBER_LEASE_NAME_MAX {
            return Err(Fail::new(
                LimberCode::InvalidValue,
                format!(
                    "a lease name has 1 to {LIMBER_LEASE_NAME_MAX} bytes, not {} ({name:?})",
                    name.len()
                ),
            ));
        }
        self.client.acquire(&name, ms(heartbeat_ms))?;
        Ok(())
    }

    /// The heartbeat of the lease.
    pub(crate) fn renew(&mut self) -> Result<(), Fail> {
        Ok(self.client.renew()?)
    }

    /// Renews the lease when a third of its heartbeat has passed; whether it did.
    pub(crate) fn keep_lease(&mut self) -> Result<bool, Fail> {
        Ok(self.client.keep_lease()?)
    }

    /// Gives the lease back (nothing to do when none is held).
    pub(crate) fn release_lease(&mut self) -> Result<(), Fail> {
        Ok(self.client.release()?)
    }

    /// Who holds the device (client id 0: nobody).
    pub(crate) fn holder(&mut self) -> Result<LimberLeaseHolder, Fail> {
        let mut out = LimberLeaseHolder::default();
        if let Some(h) = self.client.holder()? {
            out.client_id = h.client_id;
            out.heartbeat_ms = u64::try_from(h.timeout.as_millis()).unwrap_or(u64::MAX);
            let mut n = h.name.len().min(LIMBER_LEASE_NAME_MAX);
            while !h.name.is_char_boundary(n) {
                n -= 1;
            }
            for (d, b) in out.name.iter_mut().zip(&h.name.as_bytes()[..n]) {
                *d = *b as c_char;
            }
        }
        Ok(out)
    }

    /// Whether another client's command cut short the motion of `ticket`'s command (as
    /// far as the outcomes that arrived tell): the preempting client's id if so.
    pub(crate) fn preempted(&mut self, ticket: &LimberTicket) -> Result<Option<u64>, Fail> {
        self.not_borrowed()?;
        Ok(self
            .client
            .preempted(ticket_of(ticket))?
            .map(|o| o.other_client))
    }

    /// Alive (a state younger than `max_age_ms`), stale, gone, or no data yet.
    pub(crate) fn liveness(&mut self, max_age_ms: u64) -> Result<LimberLiveness, Fail> {
        self.not_borrowed()?;
        Ok(match self.client.freshness(ms(max_age_ms)) {
            Freshness::Fresh => LimberLiveness::Alive,
            Freshness::Stale => LimberLiveness::Stale,
            Freshness::Gone => LimberLiveness::Gone,
            Freshness::NoData => LimberLiveness::NoData,
        })
    }

    /// Whether the driver's process lives.
    pub(crate) fn driver_status(&self) -> LimberDriverStatus {
        match self.client.driver_status() {
            DriverStatus::Alive => LimberDriverStatus::Alive,
            DriverStatus::Dead => LimberDriverStatus::Dead,
            DriverStatus::Absent => LimberDriverStatus::Absent,
        }
    }

    /// A request with its timeout.
    pub(crate) fn request(&mut self, req: &I::Request, timeout_ms: u64) -> Result<I::Reply, Fail> {
        Ok(self.client.request_with_timeout(req, ms(timeout_ms))?)
    }
}

fn ticket_of(t: &LimberTicket) -> Ticket {
    Ticket {
        seq: t.seq,
        receivers: usize::try_from(t.receivers).unwrap_or(usize::MAX),
    }
}

/// The detail of an outcome that is not OK: its status, and the other client involved.
fn outcome_text(o: &Outcome) -> String {
    let mut t = format!("refused: {}", o.status.describe());
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
    } else if o.other_client != 0 {
        t.push_str(&format!(" (by client {})", o.other_client));
    }
    t
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
