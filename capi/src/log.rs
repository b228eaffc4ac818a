//! `limber_set_logger`: the library's log (its `tracing` events: a driver found dead, a
//! lease lost, a program of another layout refused...) handed to a C callback, so a C or
//! C++ program logs them with its own logger instead of losing them.

use core::ffi::{c_char, c_void};
use std::ffi::CString;
use std::sync::{Mutex, OnceLock};

use tracing::field::{Field, Visit};
use tracing::{Event, Level, Subscriber};
use tracing_subscriber::layer::{Context, Layer, SubscriberExt};

use crate::{Fail, LimberCode, guard};

/// How severe a log message is.
#[repr(i32)]
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum LimberLogLevel {
    /// Details for tracing a problem down.
    Trace = 0,
    /// Details for debugging.
    Debug = 1,
    /// Normal operation worth knowing (a device found, a reconnect).
    Info = 2,
    /// Something went wrong and was handled (a driver gone, a lease lost).
    Warn = 3,
    /// Something failed.
    Error = 4,
    /// Nothing is logged.
    Off = 5,
}

impl LimberLogLevel {
    fn of(l: &Level) -> Self {
        match *l {
            Level::TRACE => LimberLogLevel::Trace,
            Level::DEBUG => LimberLogLevel::Debug,
            Level::INFO => LimberLogLevel::Info,
            Level::WARN => LimberLogLevel::Warn,
            Level::ERROR => LimberLogLevel::Error,
        }
    }
}

/// A log callback: called on the thread that logs, with the level, the module that logs
/// (e.g. "limber_services::client") and the message with its fields (e.g. "cannot receive
/// the state device=pioneer/limb/0"), both NUL-terminated and valid during the call only,
/// and the `user` pointer given to `limber_set_logger`. It must not call limber.
pub type LimberLogFn = Option<
    unsafe extern "C" fn(
        level: LimberLogLevel,
        target: *const c_char,
        message: *const c_char,
        user: *mut c_void,
    ),
>;

struct Sink {
    callback: unsafe extern "C" fn(LimberLogLevel, *const c_char, *const c_char, *mut c_void),
    user: usize,
    min: LimberLogLevel,
}

fn sink() -> &'static Mutex<Option<Sink>> {
    static SINK: Mutex<Option<Sink>> = Mutex::new(None);
    &SINK
}

/// The message and fields of an event, as one line.
#[derive(Default)]
struct Line(String);

impl Visit for Line {
    fn record_debug(&mut self, field: &Field, value: &dyn core::fmt::Debug) {
        if field.name() == "message" {
            let rest = core::mem::take(&mut self.0);
            self.0.push_str(&format!("{value:?}{rest}"));
        } else {
            self.0.push_str(&format!(" {}={value:?}", field.name()));
        }
    }
    fn record_str(&mut self, field: &Field, value: &str) {
        if field.name() == "message" {
            self.0.insert_str(0, value);
        } else {
            self.0.push_str(&format!(" {}={value}", field.name()));
        }
    }
}

struct CallbackLayer;

impl<S: Subscriber> Layer<S> for CallbackLayer {
    fn on_event(&self, event: &Event<'_>, _: Context<'_, S>) {
        let level = LimberLogLevel::of(event.metadata().level());
        let Ok(guard) = sink().lock() else {
            return;
        };
        let Some(s) = guard.as_ref() else {
            return;
        };
        if level < s.min {
            return;
        }
        let mut line = Line::default();
        event.record(&mut line);
        let text = CString::new(line.0.replace('\0', "?")).unwrap_or_default();
        let target = CString::new(event.metadata().target()).unwrap_or_default();
        // SAFETY: the callback the program gave, with NUL-terminated strings that live
        // during the call and the program's own `user` pointer.
        unsafe { (s.callback)(level, target.as_ptr(), text.as_ptr(), s.user as *mut c_void) };
    }
}

/// Hands the library's log messages of level `min_level` and above to `callback` (with
/// `user`), from now on; NULL stops it (nothing is logged then, the default). Installs
/// the library's log collector the first time: `LIMBER_CODE_TRANSPORT` if the process
/// already has another `tracing` collector (a Rust program that set its own).
///
/// # Safety
/// `callback` is NULL or a function that is safe to call from any thread while it is
/// set; `user` is what it expects.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn limber_set_logger(
    callback: LimberLogFn,
    user: *mut c_void,
    min_level: LimberLogLevel,
) -> LimberCode {
    guard(|| {
        static INSTALLED: OnceLock<bool> = OnceLock::new();
        let installed = *INSTALLED.get_or_init(|| {
            let collector = tracing_subscriber::registry().with(CallbackLayer);
            match tracing::subscriber::set_global_default(collector) {
                Ok(()) => true,
                Err(e) => {
                    // Nowhere else to say it: the program's own collector has it.
                    tracing::warn!(error = %e, "liblimber: another tracing collector is set");
                    false
                }
            }
        });
        if !installed {
            return Err(Fail::new(
                LimberCode::Transport,
                "this process already has a tracing collector: limber logs there",
            ));
        }
        let mut s = sink()
            .lock()
            .map_err(|_| Fail::new(LimberCode::Internal, "the log sink is poisoned"))?;
        *s = callback.map(|callback| Sink {
            callback,
            user: user as usize,
            min: min_level,
        });
        Ok(())
    })
}
