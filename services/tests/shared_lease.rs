//! One lease per set of actuators (issue "Nobody moves the arm who may not", item 3): the
//! devices of a [`DeviceSet`] that move the same actuators share one lease. A lease taken on
//! one of them refuses other clients' commands and POWER on the other, naming the holder,
//! admits the holder's, is released from either, and its holder's death stops both.
//!
//! The holder that dies is this test binary run again as a child process
//! (`SHARED_LEASE_CHILD` names the domain), SIGKILLed by the test.

use std::io::{BufRead, BufReader};
use std::process::{Child, Command, Stdio};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use std::time::{Duration, Instant};

use limber_services::prelude::*;
use limber_services::{DeviceSet, DeviceSetHandler, LeaseError, RequestError};

const T: Duration = Duration::from_secs(5);
const ARM: &str = "pair/actarray/0";
const LIMB: &str = "pair/limb/0";
const CHILD_ENV: &str = "SHARED_LEASE_CHILD";

/// Two devices that move the same actuators: every command is carried out, POWER is
/// answered, and each stop is counted.
struct Pair {
    arm_stops: Arc<AtomicU32>,
    limb_stops: Arc<AtomicU32>,
}

impl DeviceSetHandler for Pair {
    fn actarray_command(
        &mut self,
        _: u16,
        _: &ActArrayCommand,
        _: &Origin,
        _: &mut ActArrayData,
    ) -> Status {
        Status::Ok
    }
    fn actarray_stop(&mut self, _: u16, _: &mut ActArrayData) -> Status {
        self.arm_stops.fetch_add(1, Ordering::SeqCst);
        Status::Ok
    }
    fn limb_command(&mut self, _: u16, _: &LimbCommand, _: &Origin, _: &mut LimbData) -> Status {
        Status::Ok
    }
    fn limb_stop(&mut self, _: u16, _: &mut LimbData) -> Status {
        self.limb_stops.fetch_add(1, Ordering::SeqCst);
        Status::Ok
    }
    fn limb_request(
        &mut self,
        _: u16,
        req: &LimbRequest,
        _: &Origin,
        _: &mut LimbData,
    ) -> Result<LimbReply, Status> {
        match req {
            LimbRequest::Power(_) => Ok(LimbReply::Done),
            _ => Err(Status::Unsupported),
        }
    }
}

/// The driver thread: the pair, their lease shared, processed until `stop`.
struct Driver {
    stop: Arc<AtomicBool>,
    arm_stops: Arc<AtomicU32>,
    limb_stops: Arc<AtomicU32>,
    thread: Option<std::thread::JoinHandle<()>>,
}

impl Driver {
    fn start(domain: &Domain) -> Self {
        let stop = Arc::new(AtomicBool::new(false));
        let arm_stops = Arc::new(AtomicU32::new(0));
        let limb_stops = Arc::new(AtomicU32::new(0));
        let mut pair = Pair {
            arm_stops: Arc::clone(&arm_stops),
            limb_stops: Arc::clone(&limb_stops),
        };
        let (s, d) = (Arc::clone(&stop), domain.clone());
        let (ready_tx, ready_rx) = std::sync::mpsc::channel();
        let thread = std::thread::spawn(move || {
            let ctx = Context::new(&d, Role::Driver, "pair").unwrap();
            let devices = [(InterfaceKind::ActArray, 0), (InterfaceKind::Limb, 0)];
            let mut set = DeviceSet::new(&ctx, "pair", "pair", &devices).unwrap();
            set.share_lease(&devices).unwrap();
            set.actarray_mut(0).unwrap().state_mut().actuators_count = 1;
            set.publish_all(monotonic_ns()).unwrap();
            ready_tx.send(()).unwrap();
            while !s.load(Ordering::Relaxed) {
                set.process(&mut pair).unwrap();
                std::thread::yield_now();
            }
        });
        ready_rx.recv_timeout(T).expect("the driver started");
        Driver {
            stop,
            arm_stops,
            limb_stops,
            thread: Some(thread),
        }
    }
}

impl Drop for Driver {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(t) = self.thread.take() {
            t.join().expect("the driver thread ended cleanly");
        }
    }
}

fn arm(ctx: &Context) -> ActArrayClient {
    let mut a = ActArrayClient::connect_timeout(ctx, ARM, T).unwrap();
    a.set_request_timeout(T);
    a
}

fn limb(ctx: &Context) -> LimbClient {
    let mut l = LimbClient::connect_timeout(ctx, LIMB, T).unwrap();
    l.set_request_timeout(T);
    l
}

/// Waits (bounded) until the limb's state shows the `LEASED` flag as `leased`.
fn wait_limb_flag(l: &mut LimbClient, leased: bool) {
    let deadline = Instant::now() + T;
    loop {
        let s = l.wait_state(T).expect("a limb state");
        if (s.header.flags & device_flag::LEASED != 0) == leased {
            return;
        }
        assert!(
            Instant::now() < deadline,
            "the limb's LEASED flag never became {leased}"
        );
    }
}

/// Bob's command on the limb and his POWER are refused naming alice; he cannot take it.
fn bob_is_refused(bob_limb: &mut LimbClient, alice: u64) {
    let t = bob_limb.set_position([0.3, 0.0, 0.2]).unwrap();
    let o = bob_limb.wait_outcome_detail(t, T).unwrap();
    assert_eq!(o.status, Status::Leased, "another client's limb command");
    assert_eq!(o.other_name(), "alice");
    assert_eq!(o.other_client, alice);
    assert!(matches!(
        bob_limb.power(false),
        Err(RequestError::Nack(Status::Leased))
    ));
    match bob_limb.acquire("bob", Duration::from_secs(30)) {
        Err(LeaseError::Held { name, .. }) => assert_eq!(name, "alice"),
        other => panic!("bob acquired the held limb: {other:?}"),
    }
    let h = bob_limb.holder().unwrap().expect("the limb is held");
    assert_eq!(h.name, "alice");
}

#[test]
fn a_lease_on_one_device_holds_every_device_that_moves_the_same_actuators() {
    if std::env::var_os(CHILD_ENV).is_some() {
        return;
    }
    let domain = Domain::unique_for_test();
    let driver = Driver::start(&domain);
    let alice = Context::new(&domain, Role::Client, "alice").unwrap();
    let (mut alice_arm, mut alice_limb) = (arm(&alice), limb(&alice));
    let bob = Context::new(&domain, Role::Client, "bob").unwrap();
    let (mut bob_arm, mut bob_limb) = (arm(&bob), limb(&bob));

    alice_arm.acquire("alice", Duration::from_secs(30)).unwrap();
    wait_limb_flag(&mut bob_limb, true);
    bob_is_refused(&mut bob_limb, alice_arm.client_id());

    // The holder's process commands the limb (through a client of its own) and the arm.
    let t = alice_limb.set_position([0.3, 0.0, 0.2]).unwrap();
    assert_eq!(alice_limb.wait_outcome(t, T).unwrap(), Status::Ok);
    assert_eq!(alice_limb.power(true), Ok(()));
    let t = alice_arm.move_to(0, 0.5).unwrap();
    assert_eq!(alice_arm.wait_outcome(t, T).unwrap(), Status::Ok);

    // The holder renews and releases on the limb: the one lease, so both are free.
    alice_limb
        .acquire("alice", Duration::from_secs(30))
        .unwrap();
    assert_eq!(
        bob_arm.holder().unwrap().map(|h| h.name),
        Some("alice".to_string()),
        "still one lease, on the arm too"
    );
    alice_limb.release().unwrap();
    wait_limb_flag(&mut bob_limb, false);
    assert!(bob_limb.holder().unwrap().is_none());
    assert!(bob_arm.holder().unwrap().is_none(), "the arm is free too");
    let t = bob_arm.move_to(0, 0.2).unwrap();
    assert_eq!(bob_arm.wait_outcome(t, T).unwrap(), Status::Ok);
    let t = bob_limb.set_position([0.3, 0.0, 0.2]).unwrap();
    assert_eq!(bob_limb.wait_outcome(t, T).unwrap(), Status::Ok);
    drop(driver);
}

/// A child process (this test binary again) holding the arm, killed when dropped.
struct Holder(Child);

impl Drop for Holder {
    fn drop(&mut self) {
        // Already gone when the test killed it: nothing to do then.
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

#[test]
fn the_holders_death_stops_every_device_of_the_lease() {
    if std::env::var_os(CHILD_ENV).is_some() {
        return;
    }
    let domain = Domain::unique_for_test();
    let driver = Driver::start(&domain);
    let mut child = Holder(
        Command::new(std::env::current_exe().unwrap())
            .args(["--exact", "holder_process", "--nocapture"])
            .env(CHILD_ENV, domain.name())
            .stdin(Stdio::piped())
            .stdout(Stdio::piped())
            .spawn()
            .unwrap(),
    );
    let mut lines = BufReader::new(child.0.stdout.take().unwrap()).lines();
    // Bounded: the child exits (EOF) if it fails, and nextest's timeout bounds the rest.
    assert!(
        lines.any(|l| l.is_ok_and(|l| l == "held")),
        "the child never took the lease"
    );
    let bob = Context::new(&domain, Role::Client, "bob").unwrap();
    let mut bob_limb = limb(&bob);
    wait_limb_flag(&mut bob_limb, true);
    assert_eq!(
        bob_limb.holder().unwrap().map(|h| h.name),
        Some("alice".to_string())
    );
    let (arm0, limb0) = (
        driver.arm_stops.load(Ordering::SeqCst),
        driver.limb_stops.load(Ordering::SeqCst),
    );
    child.0.kill().unwrap();
    child.0.wait().unwrap();
    // The deadman: the lease ends, and both devices stop.
    wait_limb_flag(&mut bob_limb, false);
    let deadline = Instant::now() + T;
    while driver.arm_stops.load(Ordering::SeqCst) == arm0
        || driver.limb_stops.load(Ordering::SeqCst) == limb0
    {
        assert!(
            Instant::now() < deadline,
            "not both devices were stopped: arm {} limb {}",
            driver.arm_stops.load(Ordering::SeqCst) - arm0,
            driver.limb_stops.load(Ordering::SeqCst) - limb0
        );
        std::thread::yield_now();
    }
    assert!(bob_limb.holder().unwrap().is_none());
    drop(driver);
}

/// The child of `the_holders_death_stops_every_device_of_the_lease`: takes the arm as
/// "alice", says "held", and waits on its standard input until it is killed (or its parent
/// is gone). Does nothing when run as a test.
#[test]
fn holder_process() {
    let Some(name) = std::env::var_os(CHILD_ENV) else {
        return;
    };
    let domain = Domain::new(name.to_str().unwrap()).unwrap();
    let ctx = Context::new(&domain, Role::Client, "alice").unwrap();
    let mut a = arm(&ctx);
    a.acquire("alice", Duration::from_secs(30)).unwrap();
    println!("held");
    let mut line = String::new();
    let _ = std::io::stdin().read_line(&mut line);
}
