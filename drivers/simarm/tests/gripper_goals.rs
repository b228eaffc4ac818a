//! Gripper goals (issue 28, item 4) on simarm: a free goal is reached within the tolerance
//! at the gap asked for; closing on the object stalls on it with "object present" (the
//! beam) in the result; values beyond the gripper's limits are clamped and said so; a
//! malformed goal is refused before anything moves. The driver runs on a thread of the
//! test process, in its own domain per test.

use std::time::Duration;

use limber_kinematics::chain::Chain;
use limber_services::prelude::*;
use limber_services::{CommandError, Domain, Role};
use limber_simarm::model::{SimObject, TOLERANCE};
use limber_simarm::{SimArmOptions, SimArmThread};

const TIMEOUT: Duration = Duration::from_secs(20);
/// Where the object is: where the limb puts the tool below.
const BLOCK: [f64; 3] = [0.45, 0.1, 0.15];
const BLOCK_WIDTH: f64 = 0.04;

/// simarm (6 joints, 10x real time) with a block at [`BLOCK`].
fn start(domain: &Domain) -> SimArmThread {
    let options = SimArmOptions {
        time_scale: 10.0,
        object: Some(SimObject::block(BLOCK, BLOCK_WIDTH)),
        ..SimArmOptions::default()
    };
    SimArmThread::start(domain.name(), Chain::default_6dof(), options, TIMEOUT)
        .expect("simarm starts")
}

#[test]
fn a_free_goal_is_reached_at_its_gap() {
    let d = Domain::unique_for_test();
    let _drv = start(&d);
    let ctx = Context::new(&d, Role::Client, "goals").unwrap();
    let mut grip = GripperClient::connect_timeout(&ctx, "simarm/gripper/0", TIMEOUT).unwrap();
    // The tool at home is far from the block: nothing between the fingers.
    let t = grip.goal(0.03, 5.0, 0.05).unwrap();
    assert_eq!(grip.wait_outcome(t, TIMEOUT).unwrap(), Status::Ok);
    let done = grip.wait_done(t, TIMEOUT).unwrap();
    assert_eq!(
        (done.result(), done.cause()),
        (MotionResult::Reached, Status::Ok),
        "{done}"
    );
    assert!((done.positions()[0] - 0.03).abs() <= TOLERANCE, "{done}");
    assert!(done.errors()[0].abs() <= TOLERANCE, "{done}");
    let s = grip.current(TIMEOUT).unwrap();
    assert_eq!(s.beams & 1, 0, "nothing between the fingers");
}

#[test]
fn closing_on_the_block_stalls_with_the_object_present() {
    let d = Domain::unique_for_test();
    let _drv = start(&d);
    let ctx = Context::new(&d, Role::Client, "goals").unwrap();
    let mut limb = LimbClient::connect_timeout(&ctx, "simarm/limb/0", TIMEOUT).unwrap();
    let mut grip = GripperClient::connect_timeout(&ctx, "simarm/gripper/0", TIMEOUT).unwrap();
    let t = limb
        .set_pose(BLOCK, [0.0, 0.0, -1.0], [1.0, 0.0, 0.0])
        .unwrap();
    assert!(limb.wait_done(t, TIMEOUT).unwrap().reached());
    // A goal narrower than the block: the fingers stop on it.
    let t = grip.goal(0.01, 0.0, 0.0).unwrap();
    let done = grip.wait_done(t, TIMEOUT).unwrap();
    assert_eq!(
        (done.result(), done.cause()),
        (MotionResult::Stalled, Status::ObjectPresent),
        "{done}"
    );
    assert!(
        (done.positions()[0] - BLOCK_WIDTH).abs() <= TOLERANCE,
        "{done}"
    );
    assert!(
        (done.errors()[0] - (BLOCK_WIDTH - 0.01)).abs() <= TOLERANCE,
        "{done}"
    );
    assert!(
        done.to_string()
            .contains("stalled short of the goal (an object is between the fingers)"),
        "{done}"
    );
    // Opening wider than the block, it is still between the fingers: reached, present.
    let t = grip.goal(0.06, 0.0, 0.0).unwrap();
    let done = grip.wait_done(t, TIMEOUT).unwrap();
    assert_eq!(
        (done.result(), done.cause()),
        (MotionResult::Reached, Status::ObjectPresent),
        "{done}"
    );
}

#[test]
fn beyond_the_limits_is_clamped_and_said_so_and_a_bad_goal_is_refused() {
    let d = Domain::unique_for_test();
    let _drv = start(&d);
    let ctx = Context::new(&d, Role::Client, "goals").unwrap();
    let mut grip = GripperClient::connect_timeout(&ctx, "simarm/gripper/0", TIMEOUT).unwrap();
    let stroke = grip.geometry().unwrap().inner_size.width;
    // Wider than the stroke, harder than the fingers can: clamped, then at the stroke.
    let t = grip.goal(stroke + 0.5, 1000.0, 0.0).unwrap();
    assert_eq!(grip.wait_outcome(t, TIMEOUT).unwrap(), Status::Clamped);
    let done = grip.wait_done(t, TIMEOUT).unwrap();
    assert!(done.reached(), "{done}");
    assert!((done.positions()[0] - stroke).abs() <= TOLERANCE, "{done}");
    // Negative and not finite: refused by the client, nothing sent.
    assert!(matches!(
        grip.goal(-0.01, 0.0, 0.0),
        Err(CommandError::Invalid(_))
    ));
    assert!(matches!(
        grip.goal(0.02, f64::NAN, 0.0),
        Err(CommandError::Invalid(_))
    ));
}
