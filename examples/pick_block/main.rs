//! Find a block with the laser, pick it up and put it down elsewhere (the paper's Listing 2).
//!
//! `cargo run -p limber-examples --bin pick_block -- --limb pioneer/limb/0 --gripper pioneer/gripper/1 --laser pioneer/ranger/0`

use std::process::ExitCode;
use std::time::Duration;

use clap::Parser;
use limber_examples::pick_block::{self, Devices, Event, PickParams};
use limber_services::Context;

/// Pick up a block with a limb and its gripper, carry it and put it down.
#[derive(Parser)]
struct Args {
    /// The limb device.
    #[arg(long, default_value = "pioneer/limb/0")]
    limb: String,
    /// The gripper at the end of the limb.
    #[arg(long, default_value = "pioneer/gripper/1")]
    gripper: String,
    /// The laser that finds the block.
    #[arg(long, default_value = "pioneer/ranger/0")]
    laser: String,
    /// Block centre x y (m, robot frame): given instead of found with the laser.
    #[arg(long, num_args = 2, allow_negative_numbers = true)]
    block: Option<Vec<f64>>,
    /// Drop point x y (m, robot frame).
    #[arg(long, num_args = 2, default_values_t = [0.38, -0.10], allow_negative_numbers = true)]
    drop: Vec<f64>,
    /// Grasp height above the floor (m).
    #[arg(long, default_value_t = 0.17)]
    height: f64,
}

fn main() -> ExitCode {
    let a = Args::parse();
    let params = PickParams {
        block: a.block.as_ref().map_or([0.0; 2], |b| [b[0], b[1]]),
        drop: [a.drop[0], a.drop[1]],
        grasp_height: a.height,
        ..PickParams::default()
    };
    let ctx = match Context::client_from_env() {
        Ok(c) => c,
        Err(e) => {
            eprintln!("pick_block: {e}");
            return ExitCode::from(3);
        }
    };
    let t = Duration::from_secs(2);
    let connected = match a.block {
        Some(_) => Devices::connect(&ctx, &a.limb, &a.gripper, t),
        None => Devices::connect_with_laser(&ctx, &a.limb, &a.gripper, &a.laser, t),
    };
    let mut dev = match connected {
        Ok(d) => d,
        Err(e) => {
            eprintln!("pick_block: {e}");
            return ExitCode::from(3);
        }
    };
    let result = pick_block::run(&mut dev, &params, &mut |ev| match ev {
        Event::Found(f) => println!(
            "found the block with the laser: closest point ({:.3}, {:.3}), centre ({:.3}, {:.3})",
            f.closest[0], f.closest[1], f.centre[0], f.centre[1]
        ),
        Event::Start(step) => println!("{step:?} ..."),
        Event::Done(_, l, g) => println!(
            "   done: end effector ({:+.3}, {:+.3}, {:+.3}), gripper state {} beams {:#b}",
            l.position.x, l.position.y, l.position.z, g.state, g.beams
        ),
        Event::Progress(..) => {}
    });
    match result {
        Ok(s) => {
            println!(
                "picked and placed in {} steps, {:.1} s; block seen by the beams: {}",
                s.steps,
                s.elapsed.as_secs_f64(),
                s.block_seen
            );
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("pick_block: {e}");
            ExitCode::from(1)
        }
    }
}
