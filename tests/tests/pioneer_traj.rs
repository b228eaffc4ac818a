//! Joint trajectories on the emulated Pioneer (issue 28): a driver process on the
//! emulator's pty streams a trajectory's positions as servo targets and it ends reached
//! within its goal tolerance; one faster than the servos move is refused up front as
//! TOO_FAST, nothing moving.

use std::path::PathBuf;
use std::time::Duration;

use limber_emulator::{Emulator, EmulatorConfig};
use limber_interfaces::actarray::JointTrajectory;
use limber_services::prelude::*;
use limber_services::{Domain, Role};
use limber_tests::Proc;

const PIONEER: &str = env!("CARGO_BIN_EXE_limber-test-pioneer");
const T: Duration = Duration::from_secs(5);
/// A whole trajectory of the emulated arm, with its servos' lag.
const MOVE: Duration = Duration::from_secs(60);

fn start(domain: &Domain, emu: &Emulator, name: &str) -> Proc {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let cfg = limber_tests::pioneer_test_config(&dir, name, "");
    let port = emu.pty_path().unwrap().display().to_string();
    limber_tests::start_pioneer(PIONEER, domain.name(), &port, &cfg)
}

#[test]
fn a_trajectory_is_streamed_to_its_goal_and_one_too_fast_is_refused() {
    let domain = Domain::unique_for_test();
    let emu = Emulator::start_pty(EmulatorConfig::default()).unwrap();
    let _driver = start(&domain, &emu, "traj");
    let c = Context::new(&domain, Role::Client, "traj-test").unwrap();
    let mut a = ActArrayClient::connect_timeout(&c, "pioneer/actarray/0", T).unwrap();
    let geom = a.geometry().unwrap();
    let j = 2;
    let g = geom.actuators[j];
    let from = a.wait_state(T).unwrap().actuators[j].position;
    let goal = g.centre + 0.3 * (g.max - g.centre);
    // Five points over 2.5 s, positions only (linear).
    let mut t = JointTrajectory::new(&[j as u16]).unwrap();
    for i in 1..=5 {
        let f = i as f64 / 5.0;
        t.push(0.5 * i as f64, &[from + f * (goal - from)], None, None)
            .unwrap();
    }
    t.set_goal_tolerance(&[0.05]).unwrap();
    t.set_goal_time_tolerance(20.0).unwrap();
    let ticket = a.follow_trajectory(&t).unwrap();
    assert_eq!(a.wait_outcome(ticket, T).unwrap(), Status::Ok);
    let done = a.wait_done(ticket, MOVE).unwrap();
    assert_eq!(done.result(), MotionResult::Reached, "{done}");
    assert!((done.positions()[j] - goal).abs() <= 0.05, "{done}");

    // The whole range of joint 1 in 50 ms: no servo steps that fast.
    let g1 = geom.actuators[1];
    let mut fast = JointTrajectory::new(&[1]).unwrap();
    fast.push(
        0.05,
        &[if from > g1.centre { g1.min } else { g1.max }],
        None,
        None,
    )
    .unwrap();
    let before = a.wait_state(T).unwrap().actuators[1].position;
    let ticket = a.follow_trajectory(&fast).unwrap();
    assert_eq!(a.wait_outcome(ticket, T).unwrap(), Status::TooFast);
    assert!(a.done(ticket).unwrap().is_none());
    for _ in 0..3 {
        assert_eq!(a.wait_state(T).unwrap().actuators[1].position, before);
    }
}
