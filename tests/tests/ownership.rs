//! Issue 12, item 12 "Who commands the arm", against `limber pioneer --emulated` (the
//! driver in a process of its own, the holder of the arm in another): per-client outcomes,
//! preemption told, leases that refuse others and name the holder, readers unaffected,
//! and the deadman (the holder SIGKILLed in the middle of a motion, or missing its
//! heartbeat: the joint stops within a bounded wait and the lease is free).

use std::path::PathBuf;
use std::time::{Duration, Instant};

use limber_services::prelude::*;
use limber_services::{Domain, LeaseError, Role};
use limber_tests::Proc;

const PIONEER: &str = env!("CARGO_BIN_EXE_limber-test-pioneer");
const CLIENT: &str = env!("CARGO_BIN_EXE_limber-test-client");
const CLI: &str = env!("CARGO_BIN_EXE_limber-test-cli");
const T: Duration = Duration::from_secs(5);

/// `limber pioneer --emulated` with the tests' short timeouts, ready.
fn start(domain: &Domain, name: &str) -> Proc {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let cfg = limber_tests::pioneer_test_config(&dir, name, "");
    let cfg = cfg.to_str().expect("a UTF-8 path");
    let mut d = Proc::spawn(PIONEER, domain.name(), &["--emulated", "--config", cfg]);
    assert!(
        d.read_until(|l| l.ends_with("ready")).is_some(),
        "driver did not start"
    );
    d
}

fn arm(domain: &Domain, who: &str) -> ActArrayClient {
    let c = Context::new(domain, Role::Client, who).unwrap();
    let mut a = ActArrayClient::connect_timeout(&c, "pioneer/actarray/0", T).unwrap();
    a.power(true).unwrap();
    // Fast joints: every motion of these tests ends within a second or two.
    for j in 0..6 {
        a.set_speed_config(j, 20.0).unwrap();
    }
    a
}

fn joint_flags(a: &mut ActArrayClient, j: usize) -> ActuatorFlags {
    let s = a.wait_state(T).expect("a state");
    ActuatorFlags::from_bits_truncate(s.actuators[j].state)
}

/// Waits (bounded) until joint `j` has the flag `want` (in consecutive samples `n` times).
fn wait_joint(a: &mut ActArrayClient, j: usize, want: ActuatorFlags, what: &str) -> Duration {
    let start = Instant::now();
    let deadline = start + Duration::from_secs(10);
    let mut run = 0;
    while run < 3 {
        // A timeout on the wait, not a speed asserted.
        assert!(Instant::now() < deadline, "joint {j} never {what}");
        if joint_flags(a, j).contains(want) {
            run += 1;
        } else {
            run = 0;
        }
    }
    start.elapsed()
}

/// Waits (bounded) until nobody holds the device.
fn wait_free(a: &mut ActArrayClient) -> Duration {
    let start = Instant::now();
    let deadline = start + Duration::from_secs(10);
    loop {
        match a.holder() {
            Ok(None) => return start.elapsed(),
            Ok(Some(_)) => {}
            Err(e) => panic!("cannot ask who holds the arm: {e}"),
        }
        assert!(Instant::now() < deadline, "the lease never ended");
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// A holder process: takes the arm as `name` and moves joint 0 slowly.
fn holder(domain: &Domain, name: &str, extra: &[&str]) -> Proc {
    let mut args = vec!["--robot", "pioneer", "own", "--name", name];
    args.extend_from_slice(extra);
    let mut h = Proc::spawn(CLIENT, domain.name(), &args);
    assert!(
        h.read_until(|l| l.starts_with("owning")).is_some(),
        "the holder did not take the arm"
    );
    h
}

#[test]
fn a_held_arm_refuses_others_with_the_holders_name_and_serves_readers() {
    let domain = Domain::unique_for_test();
    let _d = start(&domain, "own-refuse");
    let mut me = arm(&domain, "other");
    let _h = holder(&domain, "alice", &["--heartbeat-ms", "5000"]);

    let h = me.holder().unwrap().expect("held");
    assert_eq!(h.name, "alice");
    // A command: refused, naming the holder.
    let t = me.move_to(0, 0.0).unwrap();
    let o = me.wait_outcome_detail(t, T).unwrap();
    assert_eq!(o.status, Status::Leased);
    assert_eq!(o.other_name(), "alice");
    assert_eq!(o.other_client, h.client_id);
    // A request that changes the device: refused too.
    assert_eq!(
        me.power(false),
        Err(limber_services::RequestError::Nack(Status::Leased))
    );
    // Taking it: refused, naming the holder.
    match me.acquire("bob", Duration::from_secs(1)) {
        Err(LeaseError::Held { name, .. }) => assert_eq!(name, "alice"),
        other => panic!("acquired a held arm: {other:?}"),
    }
    // Readers are unaffected: geometry, state (with the LEASED flag), still moving.
    assert_eq!(me.geometry().unwrap().actuators_count, 6);
    let s = me.wait_state(T).unwrap();
    assert!(s.header.flags & device_flag::LEASED != 0);
    wait_joint(&mut me, 0, ActuatorFlags::MOVING, "moving");
}

#[test]
fn the_deadman_stops_the_joint_when_the_holder_is_killed_mid_motion() {
    let domain = Domain::unique_for_test();
    let _d = start(&domain, "own-kill");
    let mut me = arm(&domain, "watcher");
    // A long heartbeat: only the death of the process can end the lease this quickly.
    let h = holder(&domain, "doomed", &["--heartbeat-ms", "60000"]);
    wait_joint(&mut me, 0, ActuatorFlags::MOVING, "moving");

    h.signal(libc::SIGKILL);
    // Reading states only (nothing that wakes the driver): its own ticks find the death.
    let stopped = wait_joint(&mut me, 0, ActuatorFlags::IDLE, "stopped");
    let freed = wait_free(&mut me);
    eprintln!("joint idle {stopped:?}, then the lease free within {freed:?} after the SIGKILL");
    // The joint stays where it stopped (it is not still driven toward its limit).
    let p0 = me.wait_state(T).unwrap().actuators[0].position;
    let p1 = me.wait_state(T).unwrap().actuators[0].position;
    assert!((p1 - p0).abs() < 1e-6, "joint 0 still moving: {p0} -> {p1}");
    // Another client can command now.
    let t = me.move_to(0, 0.0).unwrap();
    assert!(me.wait_outcome(t, T).unwrap().is_carried_out());
}

#[test]
fn the_deadman_stops_the_joint_when_the_holder_misses_its_heartbeat() {
    let domain = Domain::unique_for_test();
    let _d = start(&domain, "own-heartbeat");
    let mut me = arm(&domain, "watcher");
    let mut h = holder(&domain, "sleepy", &["--heartbeat-ms", "400", "--no-renew"]);
    // Reading states only (nothing that wakes the driver): its own ticks find it.
    wait_joint(&mut me, 0, ActuatorFlags::IDLE, "stopped");
    wait_free(&mut me);
    // The holder is alive: its heartbeat, not its death, ended the lease.
    assert!(h.child.try_wait().unwrap().is_none(), "the holder died");
    let t = me.move_to(0, 0.0).unwrap();
    assert!(me.wait_outcome(t, T).unwrap().is_carried_out());
    h.write_line("bye");
}

#[test]
fn a_client_whose_motion_is_cut_short_by_another_is_told_preempted() {
    let domain = Domain::unique_for_test();
    let _d = start(&domain, "own-preempt");
    let mut a = arm(&domain, "a");
    let mut b = arm(&domain, "b");
    a.set_speed_config(0, 0.2).unwrap();
    let ta = a.move_at_speed(0, 0.1).unwrap();
    assert!(a.wait_outcome(ta, T).unwrap().is_carried_out());
    wait_joint(&mut a, 0, ActuatorFlags::MOVING, "moving");
    assert_eq!(a.preempted(ta).unwrap(), None);

    // B moves another joint: A's motion runs on, nothing to tell.
    let tb = b.move_to(2, 0.1).unwrap();
    assert!(b.wait_outcome(tb, T).unwrap().is_carried_out());
    // B stops joint 0 (a speed of 0): A's motion was cut short, and A is told by whom.
    let tb = b.move_at_speed(0, 0.0).unwrap();
    assert!(b.wait_outcome(tb, T).unwrap().is_carried_out());
    let deadline = Instant::now() + T;
    let p = loop {
        if let Some(p) = a.preempted(ta).unwrap() {
            break p;
        }
        assert!(
            Instant::now() < deadline,
            "A was never told it was preempted"
        );
        // A timeout only means: look again.
        let _ = a.wait_state(Duration::from_millis(50));
    };
    assert_eq!(p.status, Status::Preempted);
    assert_eq!(p.other_client, b.client_id());
    // B's own outcome is its own: ok, never A's preemption.
    assert_eq!(b.preempted(tb).unwrap(), None);
}

/// The reproduction: another client's STOP cancels a running VECMOVE. Its sender
/// was told "ok"; now it is told its VECMOVE was preempted, and by whom.
#[test]
fn a_vecmove_stopped_by_another_client_is_told_preempted() {
    let domain = Domain::unique_for_test();
    let _d = start(&domain, "own-vecmove");
    let c = Context::new(&domain, Role::Client, "limbs").unwrap();
    let mut a = LimbClient::connect_timeout(&c, "pioneer/limb/0", T).unwrap();
    let mut b = LimbClient::connect_timeout(&c, "pioneer/limb/0", T).unwrap();
    a.power(true).unwrap();
    let t = a.vec_move([1.0, 1.0, 0.0], 0.05).unwrap();
    assert_eq!(a.wait_outcome(t, T).unwrap(), Status::Ok);
    let deadline = Instant::now() + T;
    while a.wait_state(T).unwrap().state != LimbState::Moving as u32 {
        assert!(Instant::now() < deadline, "the VECMOVE never ran");
    }
    let tb = b.stop().unwrap();
    assert_eq!(b.wait_outcome(tb, T).unwrap(), Status::Ok);
    let deadline = Instant::now() + T;
    let p = loop {
        if let Some(p) = a.preempted(t).unwrap() {
            break p;
        }
        assert!(
            Instant::now() < deadline,
            "A was never told its VECMOVE was preempted"
        );
        // A timeout only means: look again.
        match a.wait_state(Duration::from_millis(50)) {
            Ok(_) | Err(WaitError::Timeout(_)) => {}
            Err(e) => panic!("waiting for A's state: {e}"),
        }
    };
    assert_eq!(
        (p.status, p.other_client),
        (Status::Preempted, b.client_id())
    );
}

/// Issue "Nobody moves the arm who may not", item 3: a lease on the arm's joints covers the
/// arm. While alice holds `pioneer/actarray/0`, another client's limb SETPOSE and arm
/// gripper CLOSE, and `limber limb ... setpose` from the shell, are refused naming her;
/// her own process commands the limb; the body gripper (other actuators) stays free.
#[test]
fn a_lease_on_the_arms_joints_holds_its_limb_and_its_gripper() {
    let domain = Domain::unique_for_test();
    let _d = start(&domain, "own-arm-set");
    let alice = Context::new(&domain, Role::Client, "alice").unwrap();
    let mut a = ActArrayClient::connect_timeout(&alice, "pioneer/actarray/0", T).unwrap();
    a.set_request_timeout(T);
    a.acquire("alice", Duration::from_secs(30)).unwrap();

    let bob = Context::new(&domain, Role::Client, "bob").unwrap();
    let mut limb = LimbClient::connect_timeout(&bob, "pioneer/limb/0", T).unwrap();
    let mut hand = GripperClient::connect_timeout(&bob, "pioneer/gripper/1", T).unwrap();
    let t = limb
        .set_pose([0.38, 0.1, 0.22], [0.0, 0.0, -1.0], [0.94, 0.34, 0.0])
        .unwrap();
    let o = limb.wait_outcome_detail(t, T).unwrap();
    assert_eq!(o.status, Status::Leased, "another client's SETPOSE");
    assert_eq!(o.other_name(), "alice");
    assert_eq!(o.other_client, a.client_id());
    let t = hand.close().unwrap();
    let o = hand.wait_outcome_detail(t, T).unwrap();
    assert_eq!(
        o.status,
        Status::Leased,
        "another client's arm gripper CLOSE"
    );
    assert_eq!(o.other_name(), "alice");
    assert_eq!(limb.holder().unwrap().map(|h| h.name), Some("alice".into()));

    // From the shell: refused, exit 5, naming the holder.
    let o = limber_bounded_run::output_within(
        std::process::Command::new(CLI)
            .args([
                "limb",
                "pioneer/limb/0",
                "setpose",
                "0.38",
                "0.1",
                "0.22",
                "--approach",
                "0",
                "0",
                "-1",
                "--orient",
                "0.94",
                "0.34",
                "0",
            ])
            .env("LIMBER_DOMAIN", domain.name()),
        Duration::from_secs(30),
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(5), "{err}");
    assert!(
        err.contains("held by another client (alice)"),
        "the refusal names the holder: {err}"
    );

    // The body gripper moves other actuators: not held.
    let mut body = GripperClient::connect_timeout(&bob, "pioneer/gripper/0", T).unwrap();
    assert_eq!(body.holder().unwrap(), None);
    // The holder's process commands the arm's gripper through a client of its own.
    let mut own_hand = GripperClient::connect_timeout(&alice, "pioneer/gripper/1", T).unwrap();
    let t = own_hand.close().unwrap();
    assert!(own_hand.wait_outcome(t, T).unwrap().is_carried_out());
}
