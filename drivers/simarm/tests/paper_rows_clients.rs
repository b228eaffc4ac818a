//! The rows of the paper's Tables 1, 2 and 4 that simarm once answered "unsupported",
//! end to end through Rust clients: the driver on a thread of the test process (its own
//! domain per test), BRAKES, ACCEL, CURRENT, MULTI_CURRENT, STORE and RETRIEVE.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use limber_kinematics::chain::Chain;
use limber_services::prelude::*;
use limber_services::{Domain, RequestError, Role};
use limber_simarm::{SimArm, SimArmOptions, SimObject};

const TIMEOUT: Duration = Duration::from_secs(10);

/// The driver thread; stops and joins when dropped.
struct Driver {
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

/// simarm (6 joints, 10× time) with a block between the fingers at home and a store of 1.
fn start(domain: &Domain) -> Driver {
    let chain = Chain::default_6dof();
    let p = chain.fk(&chain.home()).unwrap().position;
    let stop = Arc::new(AtomicBool::new(false));
    let (ready_tx, ready_rx) = mpsc::channel();
    let name = domain.name().to_string();
    let flag = stop.clone();
    let handle = std::thread::spawn(move || {
        let domain = Domain::new(&name).expect("domain");
        let ctx = Context::new(&domain, Role::Driver, "simarm").expect("context");
        let options = SimArmOptions {
            time_scale: 10.0,
            object: Some(SimObject::block([p.x, p.y, p.z], 0.03)),
            store_capacity: 1,
            ..SimArmOptions::default()
        };
        let mut arm = SimArm::new(&ctx, chain, options).expect("simarm starts");
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

/// The state once `pred` holds, within [`TIMEOUT`].
fn until<I: Interface>(c: &mut Client<I>, pred: impl Fn(&I::Data) -> bool) -> I::Data
where
    I::Data: Copy + core::fmt::Debug,
{
    let deadline = Instant::now() + TIMEOUT;
    loop {
        if let Some(s) = c.state()
            && pred(s)
        {
            return *s;
        }
        let left = deadline.saturating_duration_since(Instant::now());
        assert!(!left.is_zero(), "never got there: {:?}", c.state());
        let _ = c.wait_state(left);
    }
}

fn connect<I: Interface>(d: &Domain, device: &str) -> Client<I> {
    let ctx = Context::new(d, Role::Client, "paper-rows").expect("client context");
    Client::<I>::connect_timeout(&ctx, device, TIMEOUT).expect("connects")
}

#[test]
fn brakes_accel_and_current_through_clients() {
    let d = Domain::unique_for_test();
    let _drv = start(&d);
    let mut arm: ActArrayClient = connect(&d, "simarm/actarray/0");
    let mut limb: LimbClient = connect(&d, "simarm/limb/0");
    let g = arm.geometry().unwrap();
    assert!(g.actuators()[..6].iter().all(|a| a.has_brakes == 1));
    // Brakes on through the limb, refused motion on both devices, off through the arm.
    assert_eq!(limb.brakes(true), Ok(()));
    let t = arm.move_to(0, 0.5).unwrap();
    assert_eq!(arm.wait_outcome(t, TIMEOUT), Ok(Status::Braked));
    let t = limb.home().unwrap();
    assert_eq!(limb.wait_outcome(t, TIMEOUT), Ok(Status::Braked));
    until(&mut arm, |s| {
        s.actuators()[..6]
            .iter()
            .all(|a| a.state == ActuatorFlags::BRAKED.bits())
    });
    until(&mut limb, |s| s.limb_state() == Ok(LimbState::Braked));
    assert_eq!(arm.brakes(false), Ok(()));
    until(&mut limb, |s| s.limb_state() == Ok(LimbState::Idle));
    // MULTI_CURRENT closing the gripper on the block (the joints at home with 0 A: no
    // gravity about their axes there): stalls on it.
    let t = arm
        .set_current_multi(&[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0])
        .unwrap();
    assert_eq!(arm.wait_outcome(t, TIMEOUT), Ok(Status::Ok));
    let s = until(&mut arm, |s| {
        s.actuators()[6].state == ActuatorFlags::STALLED.bits()
    });
    assert!((s.actuators()[6].position - 0.03).abs() < 1e-9, "{s:?}");
    // ACCEL: the limited move reports its acceleration while it ramps.
    assert_eq!(arm.set_accel_config(0, 0.5), Ok(()));
    assert_eq!(
        arm.set_accel_config(0, 0.0),
        Err(RequestError::Nack(Status::InvalidArgument))
    );
    let t = arm.move_to(0, 1.0).unwrap();
    assert_eq!(arm.wait_outcome(t, TIMEOUT), Ok(Status::Ok));
    let s = until(&mut arm, |s| s.actuators()[0].acceleration > 0.0);
    assert!(s.actuators()[0].acceleration <= 0.5 + 1e-9, "{s:?}");
    until(&mut arm, |s| {
        s.actuators()[0].position == 1.0 && s.actuators()[0].state == ActuatorFlags::IDLE.bits()
    });
    // CURRENT on joint 0 (no gravity about the vertical): moves, the model's current.
    let t = arm.set_current(Some(0), 0.5).unwrap();
    assert_eq!(arm.wait_outcome(t, TIMEOUT), Ok(Status::Ok));
    let s = until(&mut arm, |s| {
        s.actuators()[0].state == ActuatorFlags::MOVING.bits()
    });
    assert_eq!(s.actuators()[0].current, 0.5);
}

#[test]
fn store_and_retrieve_through_clients() {
    let d = Domain::unique_for_test();
    let _drv = start(&d);
    let mut grip: GripperClient = connect(&d, "simarm/gripper/0");
    assert_eq!(grip.geometry().unwrap().capacity, 1);
    let t = grip.retrieve().unwrap();
    assert_eq!(grip.wait_outcome(t, TIMEOUT), Ok(Status::NothingStored));
    let t = grip.close().unwrap();
    assert_eq!(grip.wait_outcome(t, TIMEOUT), Ok(Status::Ok));
    until(&mut grip, |s| {
        s.gripper_state() == Ok(GripperState::Closed) && s.beams == 1
    });
    let t = grip.store().unwrap();
    assert_eq!(grip.wait_outcome(t, TIMEOUT), Ok(Status::Ok));
    until(&mut grip, |s| s.stored == 1 && s.beams == 0);
    let t = grip.store().unwrap();
    assert_eq!(grip.wait_outcome(t, TIMEOUT), Ok(Status::StoreFull));
    let t = grip.retrieve().unwrap();
    assert_eq!(grip.wait_outcome(t, TIMEOUT), Ok(Status::Ok));
    until(&mut grip, |s| s.stored == 0 && s.beams == 1);
}
