//! A client that has its command's outcome (or its request's reply) sees the command's
//! effect in the latest state at once: the host sends that state before the outcome (or
//! the reply), and the client takes the outcome from that state when it comes first. With the outcome sent first, a client spinning
//! for it sees it before the state that shows the command, and its latest state is the
//! one from before (the pick-a-block program then took an arm that had not started its
//! motion for one that had finished it).

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use limber_services::WaitMode;
use limber_services::prelude::*;
use limber_services::testing::TestArm;

const T: Duration = Duration::from_secs(5);
const DEVICE: &str = "order/actarray/0";
const COMMANDS: u64 = 3000;
const REQUESTS: u64 = 200;

#[test]
fn after_an_outcome_or_a_reply_the_latest_state_shows_it() {
    let domain = Domain::unique_for_test();
    let stop = Arc::new(AtomicBool::new(false));
    let driver_stop = Arc::clone(&stop);
    let driver_domain = domain.clone();
    // The driver busy-polls in a thread of its own, as `--spin` does.
    let driver = std::thread::spawn(move || {
        let ctx = Context::new(&driver_domain, Role::Driver, "order").unwrap();
        let mut host = DeviceHost::<ActArray>::new(&ctx, &DEVICE.parse().unwrap(), "t").unwrap();
        host.state_mut().actuators_count = 2;
        host.publish().unwrap();
        let mut arm = TestArm::new(2);
        while !driver_stop.load(Ordering::Relaxed) {
            host.process_spin(&mut arm).unwrap();
            std::hint::spin_loop();
        }
    });
    let cctx = Context::new(&domain, Role::Client, "order-client").unwrap();
    let mut arm = ActArrayClient::connect_timeout(&cctx, DEVICE, T).unwrap();
    arm.set_wait_mode(WaitMode::Spin);
    arm.set_request_timeout(T);
    let mut stale = Vec::new();
    for i in 0..COMMANDS {
        let target = if i % 2 == 0 { 0.25 } else { -0.25 };
        let ticket = arm.move_to(0, target).unwrap();
        assert_eq!(arm.wait_outcome(ticket, T), Ok(Status::Ok), "command {i}");
        // Without taking anything more: what the wait took.
        let s = arm.last_state().expect("a state");
        if s.header.last_cmd.cmd_seq != ticket.seq || s.actuators[0].position != target {
            stale.push((i, s.header.last_cmd.cmd_seq, ticket.seq));
        }
    }
    for i in 0..REQUESTS {
        let on = i % 2 == 0;
        arm.power(on).unwrap();
        // A reply is not waited for through the states: `state` takes what arrived.
        let s = arm.state().expect("a state");
        if s.motor_state != on as u32 {
            stale.push((COMMANDS + i, u64::from(s.motor_state), on as u64));
        }
    }
    stop.store(true, Ordering::Relaxed);
    driver.join().unwrap();
    assert!(
        stale.is_empty(),
        "{} of {} answers came with an older state (index, state's, expected): {:?}",
        stale.len(),
        COMMANDS + REQUESTS,
        &stale[..stale.len().min(10)]
    );
}
