//! A client that connects to a driver while the driver is still opening its channels is
//! either told there is no driver yet (and `connect_timeout` tries again) or connected to
//! a driver that answers: its first request and lease are never refused with "no driver".
//!
//! A driver opens its channels one after the other; a client found the device as soon as
//! the channels it opens existed, before the driver's request and lease servers did, and
//! its first request or lease went to nobody.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use limber_services::prelude::*;
use limber_services::testing::TestArm;

const T: Duration = Duration::from_secs(10);
const ROUNDS: usize = 50;

#[test]
fn the_first_request_and_lease_of_a_client_of_a_starting_driver_reach_it() {
    for round in 0..ROUNDS {
        let domain = Domain::unique_for_test();
        let device = format!("starting{round}/actarray/0");
        let stop = Arc::new(AtomicBool::new(false));
        let (d, dev, st) = (domain.clone(), device.clone(), Arc::clone(&stop));
        let driver = std::thread::spawn(move || {
            let ctx = Context::new(&d, Role::Driver, "starting").unwrap();
            let mut host = DeviceHost::<ActArray>::new(&ctx, &dev.parse().unwrap(), "t").unwrap();
            host.state_mut().actuators_count = 2;
            host.publish().unwrap();
            let mut arm = TestArm::new(2);
            while !st.load(Ordering::Relaxed) {
                host.process_spin(&mut arm).unwrap();
                std::hint::spin_loop();
            }
        });
        let ctx = Context::new(&domain, Role::Client, "early").unwrap();
        // As soon as the device can be connected to: `connect` in a tight loop (what
        // `connect_timeout` does, without its pause) meets the driver mid-start.
        let deadline = std::time::Instant::now() + T;
        let mut arm = loop {
            match ActArrayClient::connect(&ctx, &device) {
                Ok(c) => break c,
                Err(ConnectError::NoDriver { .. }) if std::time::Instant::now() < deadline => {}
                Err(e) => panic!("round {round}: {e}"),
            }
        };
        arm.set_request_timeout(T);
        let first = arm.power(true);
        let lease = arm.acquire("early", Duration::from_secs(5));
        stop.store(true, Ordering::Relaxed);
        driver.join().unwrap();
        assert_eq!(first, Ok(()), "round {round}: the first request");
        assert_eq!(lease, Ok(()), "round {round}: the first lease");
    }
}
