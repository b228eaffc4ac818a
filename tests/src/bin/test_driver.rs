//! The test driver as a process: `<robot>/actarray/0`, `<robot>/limb/0`, `<robot>/gripper/0`
//! in the domain of `LIMBER_DOMAIN`. Prints `ready` when serving; on SIGINT/SIGTERM prints
//! every command it received (`cmd <client> <seq> <kind>`) and the host counters, then exits 0.

use std::time::Duration;

use clap::Parser;
use limber_services::testing::TestDriver;
use limber_services::{Context, Domain, Role};

#[derive(Parser)]
struct Args {
    /// Robot name.
    #[arg(long, default_value = "test")]
    robot: String,
    /// Joints of the arm.
    #[arg(long, default_value_t = 6)]
    joints: usize,
    /// Sleep this many ms in each request.
    #[arg(long, default_value_t = 0)]
    reply_delay_ms: u64,
    /// State publication period, ms.
    #[arg(long, default_value_t = 20)]
    period_ms: u64,
}

fn main() {
    let a = Args::parse();
    let domain = Domain::from_env().expect("valid LIMBER_DOMAIN");
    let ctx = Context::new(&domain, Role::Driver, "testdriver").expect("join domain");
    let mut d = TestDriver::new(&ctx, &a.robot, a.joints).expect("offer devices");
    d.arm.reply_delay = Duration::from_millis(a.reply_delay_ms);
    println!("ready");
    let exit = d.run(Duration::from_millis(a.period_ms), || false);
    for (c, s, k) in &d.arm.log {
        println!("cmd {c} {s} {k}");
    }
    let st = d.arm_host().stats();
    println!(
        "stats commands={} overflows={} requests={} undelivered={}",
        st.commands, st.overflows, st.requests, st.undelivered_replies
    );
    match exit {
        Ok(e) => println!("exit {e:?}"),
        Err(e) => {
            println!("exit error {e}");
            std::process::exit(1);
        }
    }
}
