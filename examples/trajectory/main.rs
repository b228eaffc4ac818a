//! Follow a joint trajectory and say how it ended: joint `--joint` swings `--amplitude`
//! rad out and back from where it is, through four points (cubic: positions and
//! velocities), in `--seconds` s; then the result and each joint's final error.
//!
//! `cargo run -p limber-examples --bin trajectory -- --arm simarm/actarray/0`

use std::process::ExitCode;
use std::time::Duration;

use clap::Parser;
use limber_interfaces::actarray::JointTrajectory;
use limber_services::prelude::*;

/// A joint trajectory out and back, with its result.
#[derive(Parser)]
struct Args {
    /// The actuator array.
    #[arg(long, default_value = "simarm/actarray/0")]
    arm: String,
    /// The joint to swing.
    #[arg(long, default_value_t = 0)]
    joint: u16,
    /// How far out, rad (or m).
    #[arg(long, default_value_t = 0.2, allow_negative_numbers = true)]
    amplitude: f64,
    /// How long the whole swing takes, s.
    #[arg(long, default_value_t = 4.0)]
    seconds: f64,
    /// The goal tolerance (0: not enforced).
    #[arg(long, default_value_t = 0.05)]
    goal_tolerance: f64,
}

fn main() -> ExitCode {
    let a = Args::parse();
    let run = || -> Result<Done, Box<dyn std::error::Error>> {
        let ctx = Context::client_from_env()?;
        let mut arm = ActArrayClient::connect_timeout(&ctx, &a.arm, Duration::from_secs(2))?;
        let j = usize::from(a.joint);
        let q = arm.wait_state(Duration::from_secs(2))?.actuators[j].position;
        let (t, amp) = (a.seconds, a.amplitude);
        // Out to q + amp at half time (at rest there), back to q at the end; the halfway
        // points of each leg at the leg's top speed (1.5 times its mean for a cubic).
        let v = 1.5 * amp / (t / 2.0);
        let mut traj = JointTrajectory::new(&[a.joint])?;
        traj.push(t / 4.0, &[q + amp / 2.0], Some(&[v]), None)?;
        traj.push(t / 2.0, &[q + amp], Some(&[0.0]), None)?;
        traj.push(3.0 * t / 4.0, &[q + amp / 2.0], Some(&[-v]), None)?;
        traj.push(t, &[q], Some(&[0.0]), None)?;
        traj.set_goal_tolerance(&[a.goal_tolerance])?;
        traj.set_goal_time_tolerance(10.0)?;
        let ticket = arm.follow_trajectory(&traj)?;
        let status = arm.wait_outcome(ticket, Duration::from_secs(2))?;
        if !status.is_carried_out() {
            return Err(format!("refused: {status}").into());
        }
        Ok(arm.wait_done(ticket, Duration::from_secs_f64(t + 30.0))?)
    };
    match run() {
        Ok(done) => {
            println!("{}", done.sentence());
            for (j, e) in done.errors().iter().enumerate() {
                if !e.is_nan() {
                    println!("joint {j}: final error {e:+.4}");
                }
            }
            if done.reached() {
                ExitCode::SUCCESS
            } else {
                ExitCode::FAILURE
            }
        }
        Err(e) => {
            eprintln!("trajectory: {e}");
            ExitCode::FAILURE
        }
    }
}
