//! simarm on a thread of the test process, in the test's own domain: what the tests of
//! motions and trajectories share.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::thread::JoinHandle;
use std::time::Duration;

use limber_kinematics::chain::Chain;
use limber_services::prelude::*;
use limber_services::{Domain, Role};
use limber_simarm::{SimArm, SimArmOptions};

/// How long any wait of these tests may take.
pub const TIMEOUT: Duration = Duration::from_secs(20);

/// The driver thread; stops and joins when dropped.
pub struct Driver {
    stop: Arc<AtomicBool>,
    handle: Option<JoinHandle<()>>,
}

impl Drop for Driver {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}

/// simarm (the built-in 6 joints and the gripper) with `options`, ready.
pub fn start(domain: &Domain, options: SimArmOptions) -> Driver {
    let stop = Arc::new(AtomicBool::new(false));
    let (ready_tx, ready_rx) = mpsc::channel();
    let name = domain.name().to_string();
    let flag = stop.clone();
    let handle = std::thread::spawn(move || {
        let domain = Domain::new(&name).expect("domain");
        let ctx = Context::new(&domain, Role::Driver, "simarm").expect("context");
        let mut arm = SimArm::new(&ctx, Chain::default_6dof(), options).expect("simarm starts");
        ready_tx.send(()).expect("test waits");
        let _ = arm.run(|| flag.load(Ordering::Relaxed));
    });
    ready_rx
        .recv_timeout(TIMEOUT)
        .expect("simarm ready in time");
    Driver {
        stop,
        handle: Some(handle),
    }
}

/// A client of simarm's actuator array.
pub fn arm(ctx: &Context) -> ActArrayClient {
    ActArrayClient::connect_timeout(ctx, "simarm/actarray/0", TIMEOUT).expect("arm")
}
