//! Issue 13 item 6, "the limb takes what people write", against the emulated Pioneer: a
//! 5-DOF SETPOSE meets the position and the approach within the configured tolerances,
//! turns the orientation to the nearest one the joints can hold and says so (ADJUSTED,
//! the limb state's `orientation_adjustment`); what truly cannot be reached is refused
//! with its cause; REACH answers without moving.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use limber_emulator::{Emulator, EmulatorConfig};
use limber_services::prelude::*;
use limber_services::{Domain, RequestError, Role};
use limber_tests::Proc;

const PIONEER: &str = env!("CARGO_BIN_EXE_limber-test-pioneer");
const T: Duration = Duration::from_secs(5);

/// The README's example pose: 38 cm ahead, 10 cm left, 22 cm up, pointing down.
const README_P: [f64; 3] = [0.38, 0.1, 0.22];
const DOWN: [f64; 3] = [0.0, 0.0, -1.0];

fn start(domain: &Domain, emu: &Emulator, name: &str, extra: &str) -> Proc {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let cfg = limber_tests::pioneer_test_config(&dir, name, extra);
    let port = emu.pty_path().unwrap().display().to_string();
    limber_tests::start_pioneer(PIONEER, domain.name(), &port, &cfg)
}

struct Rig {
    _emu: Emulator,
    _driver: Proc,
    limb: LimbClient,
}

fn rig(name: &str, extra: &str) -> Rig {
    let domain = Domain::unique_for_test();
    let emu = Emulator::start_pty(EmulatorConfig::default()).unwrap();
    let driver = start(&domain, &emu, name, extra);
    let c = Context::new(&domain, Role::Client, "limb-setpose-test").unwrap();
    let mut arm = ActArrayClient::connect_timeout(&c, "pioneer/actarray/0", T).unwrap();
    let limb = LimbClient::connect_timeout(&c, "pioneer/limb/0", T).unwrap();
    arm.power(true).unwrap();
    for j in 0..6 {
        arm.set_speed_config(j, 20.0).unwrap();
    }
    Rig {
        _emu: emu,
        _driver: driver,
        limb,
    }
}

/// Waits (bounded) for a limb state satisfying `pred`.
fn wait_limb(limb: &mut LimbClient, what: &str, pred: impl Fn(&LimbData) -> bool) -> LimbData {
    let deadline = Instant::now() + Duration::from_secs(20);
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        assert!(!left.is_zero(), "the limb never got {what}");
        if let Ok(s) = limb.wait_state(left.min(T))
            && pred(s)
        {
            return *s;
        }
    }
}

fn dist(a: Vec3, b: [f64; 3]) -> f64 {
    ((a.x - b[0]).powi(2) + (a.y - b[1]).powi(2) + (a.z - b[2]).powi(2)).sqrt()
}

fn setpose(limb: &mut LimbClient, p: [f64; 3], a: [f64; 3], o: [f64; 3]) -> Status {
    let t = limb.set_pose(p, a, o).unwrap();
    limb.wait_outcome(t, T).unwrap()
}

#[test]
fn the_readme_pose_is_carried_out_with_its_orientation_adjusted_and_said_so() {
    let mut r = rig("setpose-readme", "");
    let limb = &mut r.limb;
    // Two decimals: about 0.1° from a frame five joints can hold.
    assert_eq!(
        setpose(limb, README_P, DOWN, [0.94, 0.34, 0.0]),
        Status::Adjusted
    );
    let s = wait_limb(limb, "idle at the README pose", |s| {
        s.limb_state() == Ok(LimbState::Idle) && dist(s.position, README_P) < 0.01
    });
    assert!(
        s.orientation_adjustment > 1e-3 && s.orientation_adjustment < 3e-3,
        "{s:?}"
    );
    assert!(s.approach.z < -0.99, "approach {:?}", s.approach);
    // Four decimals: still adjusted, by less.
    assert_eq!(
        setpose(limb, README_P, DOWN, [0.9398, 0.3417, 0.0]),
        Status::Adjusted
    );
    let s = wait_limb(limb, "the smaller adjustment", |s| {
        s.orientation_adjustment > 0.0 && s.orientation_adjustment < 1e-4
    });
    assert!(s.orientation_adjustment > 1e-5, "{s:?}");
    // Six decimals: the frame the arm holds, carried out as asked.
    assert_eq!(
        setpose(limb, README_P, DOWN, [0.939793, 0.341743, 0.0]),
        Status::Ok
    );
    wait_limb(limb, "no adjustment", |s| s.orientation_adjustment == 0.0);
    // The `limber limb --help` example.
    assert_eq!(
        setpose(limb, [0.4, 0.0, 0.2], DOWN, [1.0, 0.0, 0.0]),
        Status::Ok
    );
}

#[test]
fn poses_that_cannot_be_reached_are_refused_with_their_cause() {
    let mut r = rig("setpose-refused", "");
    let limb = &mut r.limb;
    assert_eq!(
        setpose(limb, [1.5, 0.0, 0.3], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
        Status::OutOfReach
    );
    let s = wait_limb(limb, "out of reach", |s| {
        s.limb_state() == Ok(LimbState::OutOfReach)
    });
    assert_eq!(s.orientation_adjustment, 0.0);
    // Straight down at 0.3 0 0.2 needs the elbow folded about 130°.
    assert_eq!(
        setpose(limb, [0.3, 0.0, 0.2], DOWN, [1.0, 0.0, 0.0]),
        Status::BeyondLimits
    );
    for (p, cause) in [
        ([1.5, 0.0, 0.3], Status::OutOfReach),
        ([0.3, 0.0, 0.2], Status::BeyondLimits),
    ] {
        match limb.reach(p, DOWN, [1.0, 0.0, 0.0]) {
            Err(RequestError::Nack(s)) => assert_eq!(s, cause, "{p:?}"),
            other => panic!("{p:?}: {other:?}"),
        }
    }
}

#[test]
fn reach_answers_where_the_arm_would_end_without_moving() {
    let mut r = rig("setpose-reach", "");
    let limb = &mut r.limb;
    assert_eq!(
        setpose(limb, [0.4, 0.0, 0.2], DOWN, [1.0, 0.0, 0.0]),
        Status::Ok
    );
    let before = wait_limb(limb, "idle", |s| {
        s.limb_state() == Ok(LimbState::Idle) && dist(s.position, [0.4, 0.0, 0.2]) < 0.01
    });
    let reach = limb.reach(README_P, DOWN, [0.94, 0.34, 0.0]).unwrap();
    assert_eq!(reach.adjusted, 1);
    assert!(dist(reach.position, README_P) < 1e-6, "{reach:?}");
    assert!(reach.approach.z < -0.999_999, "{reach:?}");
    assert!(
        (reach.orientation.x - 0.939793).abs() < 1e-5
            && (reach.orientation.y - 0.341743).abs() < 1e-5,
        "{reach:?}"
    );
    assert!(reach.orientation_adjustment > 1e-3 && reach.orientation_adjustment < 3e-3);
    let exact = limb
        .reach(README_P, DOWN, [0.939793, 0.341743, 0.0])
        .unwrap();
    assert_eq!(exact.adjusted, 0, "{exact:?}");
    // Nothing moved: the arm is idle where it was, the last command's outcome unchanged.
    for _ in 0..5 {
        let s = *limb.wait_state(T).unwrap();
        assert_eq!(s.limb_state(), Ok(LimbState::Idle));
        assert!(dist(s.position, before.position.to_array()) < 1e-9, "{s:?}");
    }
}

#[test]
fn the_setpose_tolerances_come_from_the_configuration() {
    // Pointing straight ahead, 0.5 mm beyond the stretched arm: within the default 1 mm.
    let cfg = limber_pioneer::PioneerConfig::default();
    let ([bx, _, bz], [l1, l2, l4, l5]) = (cfg.arm_base, cfg.arm_links);
    let far = [bx + l1 + l2 + l4 + l5 + 0.0005, 0.0, bz];
    let (ahead, up) = ([1.0, 0.0, 0.0], [0.0, 0.0, 1.0]);
    // The orientation 1.15° from perpendicular to the approach.
    let tilted = [1.0, 0.0, 0.02];
    let mut r = rig("setpose-tol-default", "");
    let reach = r.limb.reach(far, ahead, up).unwrap();
    assert!(
        reach.position_error > 4e-4 && reach.position_error <= 1e-3,
        "{reach:?}"
    );
    assert!(matches!(
        r.limb.reach(README_P, DOWN, tilted),
        Err(RequestError::Nack(Status::InvalidArgument))
    ));
    drop(r);
    let mut r = rig(
        "setpose-tol-tight",
        "setpose_position_tolerance = 0.0001\nsetpose_approach_tolerance_deg = 2.0",
    );
    assert!(matches!(
        r.limb.reach(far, ahead, up),
        Err(RequestError::Nack(Status::OutOfReach))
    ));
    r.limb.reach(README_P, [0.0, 0.0, -1.0], tilted).unwrap();
}
