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
    match run_cli(Cli::parse().args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("limber-bench: {e}");
            ExitCode::FAILURE
        }
    }
}
