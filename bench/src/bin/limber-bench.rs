//! `limber-bench`: the latency benchmarks (the same as `limber bench`).

use std::process::ExitCode;

use clap::Parser;
use limber_bench::{BenchArgs, run_cli};

/// Latency benchmarks of the control loop, beside their floor and their peers.
#[derive(Debug, Parser)]
#[command(name = "limber-bench", version)]
struct Cli {
    #[command(flatten)]
    args: BenchArgs,
}

fn main() -> ExitCode {
    // Warnings (pinning not permitted, ...) on stderr; RUST_LOG overrides the level.
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("warn"));
    tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .init();
    match run_cli(Cli::parse().args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("limber-bench: {e}");
            // 2: usage, as clap's own errors and the `limber` verbs.
            if e.is_usage() {
                ExitCode::from(2)
            } else {
                ExitCode::FAILURE
            }
        }
    }
}
