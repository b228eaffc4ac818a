//! `limber pioneer` as a test binary (the CLI crate's binary is not visible to this
//! package's tests): the same arguments, the same behaviour.

use clap::Parser;

#[derive(Parser)]
struct Args {
    #[command(flatten)]
    inner: limber_drivers::pioneer::PioneerArgs,
}

fn main() -> std::process::ExitCode {
    match limber_drivers::pioneer::run_cli(Args::parse().inner) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("limber pioneer: {e}");
            std::process::ExitCode::FAILURE
        }
    }
}
