//! Every motion ends with a result (issue 28), on simarm: reached within the tolerance
//! with its final error, preempted by a newer command, stopped by a STOP, aborted by a
//! power-off, and a refused command has no result. The driver runs on a thread of the
//! test process, in its own domain per test; nothing asserts speed.

use std::time::Duration;

use limber_services::prelude::*;
use limber_services::{Domain, Role};
use limber_simarm::SimArmOptions;
use limber_simarm::model::TOLERANCE;

mod common;
use common::{TIMEOUT, arm};

/// A position of joint `j` a quarter of the way from its centre toward its max.
fn target(geom: &ActArrayGeom, j: usize, fraction: f64) -> f64 {
    let a = &geom.actuators[j];
    a.centre + (a.max - a.centre) * fraction
}

#[test]
fn each_move_is_reached_within_the_tolerance_with_its_final_error() {
    let d = Domain::unique_for_test();
    let _drv = start(&d, 10.0);
    let ctx = Context::new(&d, Role::Client, "results").unwrap();
    let mut a = arm(&ctx);
    let geom = a.geometry().unwrap();
    for (j, f) in [(0, 0.3), (1, 0.2), (2, -0.2), (0, 0.0)] {
        let goal = target(&geom, j, f);
        let t = a.move_to(j, goal).unwrap();
        let done = a.wait_done(t, TIMEOUT).expect("a result");
        assert_eq!(done.result(), MotionResult::Reached, "{done}");
        assert_eq!(done.cause(), Status::Ok);
        assert!(done.max_error() <= done.tolerance(), "{done}");
        assert!(done.tolerance() <= TOLERANCE);
        assert!((done.positions()[j] - goal).abs() <= TOLERANCE);
        // The state taken with the result shows the joint at rest there.
        let s = a.state().unwrap().actuators[j];
        assert!((s.position - goal).abs() <= TOLERANCE);
        assert_eq!(s.flags(), Ok(ActuatorFlags::IDLE));
    }
    let goals = [0.1, -0.1, 0.2];
    let t = a.move_to_multi(&goals).unwrap();
    let done = a.wait_done(t, TIMEOUT).unwrap();
    assert!(done.reached(), "{done}");
    assert_eq!(done.errors().len(), 3);
    let t = a.home(None).unwrap();
    assert!(a.wait_done(t, TIMEOUT).unwrap().reached());
}

#[test]
fn a_newer_command_preempts_a_stop_stops_a_power_off_aborts() {
    let d = Domain::unique_for_test();
    // Real time: a move of a radian takes long enough to be cut short.
    let _drv = start(&d, 1.0);
    let ctx = Context::new(&d, Role::Client, "results").unwrap();
    let mut a = arm(&ctx);
    let geom = a.geometry().unwrap();
    let far = target(&geom, 0, 0.9);
    let near = target(&geom, 0, -0.9);

    // Preempted by this client's own next move of the joint.
    let first = a.move_to(0, far).unwrap();
    assert_eq!(a.wait_outcome(first, TIMEOUT).unwrap(), Status::Ok);
    let second = a.move_to(0, near).unwrap();
    let done = a.wait_done(first, TIMEOUT).unwrap();
    assert_eq!(done.result(), MotionResult::Preempted, "{done}");
    assert!(done.errors()[0].abs() > TOLERANCE, "cut short: {done}");

    // Stopped by a speed of 0 (the actarray's stop) mid-way.
    let stop = a.move_at_speed(0, 0.0).unwrap();
    let done = a.wait_done(second, TIMEOUT).unwrap();
    assert_eq!(done.result(), MotionResult::Stopped, "{done}");
    assert!(a.wait_done(stop, TIMEOUT).unwrap().reached());

    // Aborted by a power-off mid-way, with the cause.
    let third = a.move_to(0, far).unwrap();
    assert_eq!(a.wait_outcome(third, TIMEOUT).unwrap(), Status::Ok);
    a.power(false).unwrap();
    let done = a.wait_done(third, TIMEOUT).unwrap();
    assert_eq!(
        (done.result(), done.cause()),
        (MotionResult::Aborted, Status::PoweredOff),
        "{done}"
    );
    assert!(done.sentence().contains("powered off"), "{done}");

    // A refused command has no motion, so no result.
    let refused = a.move_to(0, far).unwrap();
    assert!(matches!(
        a.wait_done(refused, TIMEOUT),
        Err(DoneError::Refused(Status::PoweredOff))
    ));
}

#[test]
fn limb_and_gripper_motions_end_with_a_result() {
    let d = Domain::unique_for_test();
    let _drv = start(&d, 10.0);
    let ctx = Context::new(&d, Role::Client, "results").unwrap();
    let mut limb = LimbClient::connect_timeout(&ctx, "simarm/limb/0", TIMEOUT).unwrap();
    let mut grip = GripperClient::connect_timeout(&ctx, "simarm/gripper/0", TIMEOUT).unwrap();
    let t = limb.set_position([0.4, 0.1, 0.3]).unwrap();
    let done = limb.wait_done(t, TIMEOUT).unwrap();
    assert!(done.reached(), "{done}");
    let t = limb.home().unwrap();
    assert!(limb.wait_done(t, TIMEOUT).unwrap().reached());
    let t = grip.close().unwrap();
    let done = grip.wait_done(t, TIMEOUT).unwrap();
    assert!(done.reached(), "nothing between the fingers: {done}");
    let t = grip.open().unwrap();
    assert!(grip.wait_done(t, TIMEOUT).unwrap().reached());
}

#[test]
fn the_deadman_stops_a_motion_whose_holder_missed_its_heartbeat() {
    let d = Domain::unique_for_test();
    // Real time: the long move is still running when the lease ends.
    let _drv = start(&d, 1.0);
    let ctx = Context::new(&d, Role::Client, "results").unwrap();
    let mut a = arm(&ctx);
    let far = target(&a.geometry().unwrap(), 0, 0.9);
    let t = a.move_to(0, far).unwrap();
    assert_eq!(a.wait_outcome(t, TIMEOUT).unwrap(), Status::Ok);
    // Mid-way, a lease with the shortest heartbeat, never renewed: the deadman ends it and
    // stops the arm.
    a.acquire("silent", Duration::from_millis(10)).unwrap();
    let done = a.wait_done(t, TIMEOUT).unwrap();
    assert_eq!(
        (done.result(), done.cause()),
        (MotionResult::Stopped, Status::Leased),
        "{done}"
    );
    assert!(done.errors()[0].abs() > TOLERANCE, "stopped short: {done}");
}

/// simarm at `time_scale`.
fn start(domain: &Domain, time_scale: f64) -> common::Driver {
    common::start(
        domain,
        SimArmOptions {
            time_scale,
            ..SimArmOptions::default()
        },
    )
}
