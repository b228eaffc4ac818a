//! The test driver as a process: `<robot>/actarray/0`, `<robot>/limb/0`, `<robot>/gripper/0`
//! in the domain of `LIMBER_DOMAIN`. Prints `ready` when serving; on SIGINT/SIGTERM prints
//! every command it received (`cmd <client> <seq> <kind>`) and the host counters, then exits 0.
//! With `--hold-first-request`, the first request to the arm is announced (`request <client>
//! <seq>`) and held until a line arrives on stdin (or stdin closes), then answered.

use std::io::{BufRead, Write};
use std::time::Duration;

use clap::Parser;
use limber_interfaces::prelude::*;
use limber_services::host::{DeviceHandler, Motion, Origin};
use limber_services::testing::{TestArm, TestDriver};
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
    /// Announce the first request to the arm and hold it until a line arrives on stdin.
    #[arg(long)]
    hold_first_request: bool,
}

/// The test arm, announcing each request on stdout and holding it until a line arrives on
/// stdin: the evidence a test needs that a request is being handled.
struct Holding<'a>(&'a mut TestArm);

impl DeviceHandler<ActArray> for Holding<'_> {
    fn command(
        &mut self,
        cmd: &ActArrayCommand,
        from: &Origin,
        state: &mut ActArrayData,
    ) -> Status {
        self.0.command(cmd, from, state)
    }

    fn motion(&mut self, cmd: &ActArrayCommand, state: &ActArrayData) -> Motion {
        self.0.motion(cmd, state)
    }

    fn stop(&mut self, state: &mut ActArrayData) -> Status {
        self.0.stop(state)
    }

    fn request(
        &mut self,
        req: &ActArrayRequest,
        from: &Origin,
        state: &mut ActArrayData,
    ) -> Result<ActArrayReply, Status> {
        println!("request {} {}", from.client_id, from.seq);
        std::io::stdout().flush().expect("stdout");
        let mut go = String::new();
        // EOF (the test gone) releases the request too.
        std::io::stdin().lock().read_line(&mut go).expect("stdin");
        self.0.request(req, from, state)
    }
}

fn main() {
    let a = Args::parse();
    let domain = Domain::from_env().expect("valid LIMBER_DOMAIN");
    let ctx = Context::new(&domain, Role::Driver, "testdriver").expect("join domain");
    let mut d = TestDriver::new(&ctx, &a.robot, a.joints).expect("offer devices");
    d.arm.reply_delay = Duration::from_millis(a.reply_delay_ms);
    println!("ready");
    if a.hold_first_request {
        // Until the first request has been held and answered; the loop below serves the rest.
        loop {
            let host = d
                .hosts
                .actarray_mut(0)
                .expect("the test driver serves actarray/0");
            match host.process(&mut Holding(&mut d.arm)) {
                Ok(n) if n.requests > 0 => break,
                Ok(_) => std::thread::sleep(Duration::from_millis(2)),
                Err(e) => {
                    println!("exit error {e}");
                    std::process::exit(1);
                }
            }
        }
    }
    let exit = d.run(Duration::from_millis(a.period_ms), || false);
    for (c, s, k) in &d.arm.log {
        println!("cmd {c} {s} {k}");
    }
    let st = d.arm_host().stats();
    println!(
        "stats commands={} refused={} overflows={} requests={} undelivered={}",
        st.commands, st.refused, st.overflows, st.requests, st.undelivered_replies
    );
    match exit {
        Ok(e) => println!("exit {e:?}"),
        Err(e) => {
            println!("exit error {e}");
            std::process::exit(1);
        }
    }
}
