//! Draws a square with a limb's tool: each edge a straight line, waiting for each result.
//!
//! `cargo run -p limber-examples --bin square -- --limb simarm/limb/0 --side 0.1`

use std::process::ExitCode;
use std::time::Duration;

use clap::Parser;
use limber_examples::square::{self, SquareParams};
use limber_services::prelude::*;

/// A square in the horizontal plane, drawn with LINE moves.
#[derive(Parser)]
struct Args {
    /// The limb.
    #[arg(long, default_value = "simarm/limb/0")]
    limb: String,
    /// The square's centre x y z, m.
    #[arg(long, num_args = 3, allow_negative_numbers = true, default_values_t = [0.4, 0.0, 0.25])]
    centre: Vec<f64>,
    /// Its side, m.
    #[arg(long, default_value_t = 0.1)]
    side: f64,
    /// The tool's speed along the edges, m/s.
    #[arg(long, default_value_t = 0.05)]
    speed: f64,
}

fn main() -> ExitCode {
    let a = Args::parse();
    let run = || -> Result<(), Box<dyn std::error::Error>> {
        let ctx = Context::client_from_env()?;
        let mut limb = LimbClient::connect_timeout(&ctx, &a.limb, Duration::from_secs(2))?;
        let p = SquareParams {
            centre: [a.centre[0], a.centre[1], a.centre[2]],
            side: a.side,
            speed: a.speed,
            ..SquareParams::default()
        };
        square::run(&mut limb, &p, &mut |s| {
            let [x, y, z] = s.corner;
            let how = if s.motion == 0 { "ptp" } else { "line" };
            println!(
                "{how} {} to ({x:.3}, {y:.3}, {z:.3}): {} error {:.6} tolerance {:.6}",
                s.motion,
                s.done.result().name(),
                s.done.max_error(),
                s.done.tolerance()
            );
        })?;
        Ok(())
    };
    match run() {
        Ok(()) => {
            println!("square drawn");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("square: {e}");
            ExitCode::from(1)
        }
    }
}
