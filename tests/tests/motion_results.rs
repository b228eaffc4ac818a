//! Every motion ends with a result (issue 28), against the emulated Pioneer: a driver
//! process on the emulator's pty, commanded from this process. A joint shows MOVING from
//! its command's outcome on, with a speed estimated from successive ARMpacs (and flagged
//! so); its motion ends reached within one servo tick of the goal, preempted by a newer
//! command, stopped by a speed of 0, or aborted when the link is killed.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use limber_emulator::{Emulator, EmulatorConfig};
use limber_services::prelude::*;
use limber_services::{Domain, Role};
use limber_tests::Proc;

const PIONEER: &str = env!("CARGO_BIN_EXE_limber-test-pioneer");
const T: Duration = Duration::from_secs(5);
/// A whole move of the emulated arm (its servos step every few ms).
const MOVE: Duration = Duration::from_secs(30);

fn start(domain: &Domain, emu: &Emulator, name: &str) -> Proc {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let cfg = limber_tests::pioneer_test_config(&dir, name, "");
    let port = emu.pty_path().unwrap().display().to_string();
    limber_tests::start_pioneer(PIONEER, domain.name(), &port, &cfg)
}

fn arm(domain: &Domain) -> ActArrayClient {
    let c = Context::new(domain, Role::Client, "results-test").unwrap();
    ActArrayClient::connect_timeout(&c, "pioneer/actarray/0", T).unwrap()
}

/// A position of joint `j`, `fraction` of the way from its centre to its max (or min).
fn target(geom: &ActArrayGeom, j: usize, fraction: f64) -> f64 {
    let a = &geom.actuators[j];
    let end = if fraction >= 0.0 { a.max } else { a.min };
    a.centre + (end - a.centre) * fraction.abs()
}

#[test]
fn a_move_shows_moving_at_once_reports_its_speed_and_ends_reached_within_a_tick() {
    let domain = Domain::unique_for_test();
    let emu = Emulator::start_pty(EmulatorConfig::default()).unwrap();
    let _driver = start(&domain, &emu, "results-reached");
    let mut a = arm(&domain);
    let geom = a.geometry().unwrap();
    for (j, f) in [(2, 0.5), (1, -0.3), (2, 0.0)] {
        let goal = target(&geom, j, f);
        let t = a.move_to(j, goal).unwrap();
        assert_eq!(a.wait_outcome(t, T).unwrap(), Status::Ok);
        // The state that came with the outcome shows the joint moving already.
        let s = a.last_state().unwrap().actuators[j];
        let moved = (s.position - goal).abs() > 1e-9;
        if moved {
            assert!(s.flags().unwrap().contains(ActuatorFlags::MOVING), "{s:?}");
        }
        // While it moves, its speed is estimated (and flagged so).
        let mut saw_speed = !moved;
        let deadline = Instant::now() + MOVE;
        while !saw_speed && Instant::now() < deadline {
            let s = a.wait_state(T).unwrap().actuators[j];
            let f = s.flags().unwrap();
            if !f.contains(ActuatorFlags::MOVING) {
                break;
            }
            saw_speed = f.contains(ActuatorFlags::SPEED_ESTIMATED) && s.speed != 0.0;
        }
        assert!(saw_speed, "joint {j} never reported a speed while moving");
        let done = a.wait_done(t, MOVE).unwrap();
        assert_eq!(done.result(), MotionResult::Reached, "{done}");
        assert!(done.max_error() <= done.tolerance(), "{done}");
        assert!(done.tolerance() > 0.0 && done.tolerance() < 0.05, "{done}");
        assert!(
            (done.positions()[j] - goal).abs() <= done.tolerance(),
            "{done}"
        );
        let s = a.state().unwrap().actuators[j];
        assert_eq!(s.flags().unwrap(), ActuatorFlags::IDLE);
        assert_eq!(s.speed, 0.0);
    }
}

#[test]
fn a_newer_move_preempts_a_zero_speed_stops_and_a_killed_link_aborts() {
    let domain = Domain::unique_for_test();
    let emu = Emulator::start_pty(EmulatorConfig::default()).unwrap();
    let _driver = start(&domain, &emu, "results-cut");
    let mut a = arm(&domain);
    let geom = a.geometry().unwrap();
    let (far, near) = (target(&geom, 0, 0.9), target(&geom, 0, -0.9));

    let first = a.move_to(0, far).unwrap();
    assert_eq!(a.wait_outcome(first, T).unwrap(), Status::Ok);
    let second = a.move_to(0, near).unwrap();
    let done = a.wait_done(first, T).unwrap();
    assert_eq!(done.result(), MotionResult::Preempted, "{done}");

    let stop = a.move_at_speed(0, 0.0).unwrap();
    let done = a.wait_done(second, T).unwrap();
    assert_eq!(done.result(), MotionResult::Stopped, "{done}");
    assert!(a.wait_done(stop, T).unwrap().reached());

    let third = a.move_to(0, far).unwrap();
    assert_eq!(a.wait_outcome(third, T).unwrap(), Status::Ok);
    emu.disconnect();
    let done = a.wait_done(third, MOVE).unwrap();
    assert_eq!(
        (done.result(), done.cause()),
        (MotionResult::Aborted, Status::LinkDown),
        "{done}"
    );
}
