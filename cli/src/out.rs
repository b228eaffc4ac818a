//! Writing to stdout as Unix tools do: a closed pipe (`limber echo ... | head -1`) ends
//! the verb quietly with exit 0 instead of a panic; any other write error is a failure.

use std::io::{ErrorKind, Write};

use crate::{CliError, exit};

/// Writes the formatted arguments to stdout; on a closed pipe the error is
/// [`CliError::stdout_closed`] (exit 0, nothing printed).
pub(crate) fn write(args: std::fmt::Arguments<'_>) -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    out.write_fmt(args).map_err(stdout_error)
}

/// The error of a failed write to stdout.
pub(crate) fn stdout_error(e: std::io::Error) -> CliError {
    if e.kind() == ErrorKind::BrokenPipe {
        CliError::stdout_closed()
    } else {
        CliError::new(exit::FAILURE, format!("cannot write to stdout: {e}"))
    }
}

/// A driver's informational line ("serving ...; ready"): a driver does not end because
/// nobody reads its stdout, so a failed write is logged and the driver serves on.
pub(crate) fn note(args: std::fmt::Arguments<'_>) {
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_fmt(args).and_then(|()| out.flush()) {
        tracing::warn!("cannot write to stdout ({e}); serving on");
    }
}

/// [`write`] and a newline.
pub(crate) fn write_line(args: std::fmt::Arguments<'_>) -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    out.write_fmt(args)
        .and_then(|()| out.write_all(b"\n"))
        .map_err(stdout_error)
}

/// `print!` that returns `Result<(), CliError>` (see [`write`]).
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::out::write(format_args!($($arg)*))
    };
}

/// `println!` that returns `Result<(), CliError>` (see [`write`]).
macro_rules! outln {
    ($($arg:tt)*) => {
        $crate::out::write_line(format_args!($($arg)*))
    };
}

/// `println!` for a driver's informational lines (see [`note`]).
macro_rules! noteln {
    ($($arg:tt)*) => {
        $crate::out::note(format_args!("{}\n", format_args!($($arg)*)))
    };
}

pub(crate) use {noteln, out, outln};
