//! Log output of the `limber` command: `tracing` events on stderr.
//!
//! The level comes from `-v` (warn by default, `-v` info, `-vv` debug, `-vvv` trace);
//! `RUST_LOG` (an `EnvFilter` directive such as `limber_pioneer=debug`) overrides it.

use tracing_subscriber::EnvFilter;

/// Installs the stderr subscriber once; later calls do nothing.
pub(crate) fn init(verbose: u8) {
    let level = match verbose {
        0 => "warn",
        1 => "info",
        2 => "debug",
        _ => "trace",
    };
    let filter = EnvFilter::try_from_default_env().unwrap_or_else(|_| EnvFilter::new(level));
    // A second initialisation in the same process (tests calling `run_from` twice) is
    // not an error worth reporting: the first subscriber stays.
    if tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .with_target(true)
        .try_init()
        .is_err()
    {
        tracing::trace!("a tracing subscriber was already installed");
    }
}
