//! Move every joint of an arm to random positions within its limits (the paper's Listing 1).
//!
//! `cargo run -p limber-examples --bin random_moves -- --arm pioneer/actarray/0 --rounds 3`

use std::process::ExitCode;
use std::time::Duration;

use clap::Parser;
use limber_examples::random_moves::{self, RandomParams};
use limber_services::prelude::*;

/// Random joint moves within the limits read from the geometry.
#[derive(Parser)]
struct Args {
    /// The actuator array.
    #[arg(long, default_value = "pioneer/actarray/0")]
    arm: String,
    /// Rounds of moves.
    #[arg(long, default_value_t = 3)]
    rounds: usize,
    /// Random seed.
    #[arg(long, default_value_t = 2006)]
    seed: u64,
}

fn main() -> ExitCode {
    let a = Args::parse();
    let run = || -> Result<Vec<f64>, Box<dyn std::error::Error>> {
        let ctx = Context::client_from_env()?;
        let mut arm = ActArrayClient::connect_timeout(&ctx, &a.arm, Duration::from_secs(2))?;
        let p = RandomParams {
            rounds: a.rounds,
            seed: a.seed,
            ..RandomParams::default()
        };
        Ok(random_moves::run(&mut arm, &p, &mut |m, _s| {
            if let Some(m) = m {
                println!(
                    "round {} joint {} -> {:+.4} (limits {:+.4} .. {:+.4})",
                    m.round, m.joint, m.target, m.limits.0, m.limits.1
                );
            }
        })?)
    };
    match run() {
        Ok(q) => {
            println!("final joints: {q:.4?}");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("random_moves: {e}");
            ExitCode::from(1)
        }
    }
}
