//! Issue 12, "ok must mean it" (items 7 to 10), against the emulated Pioneer: a driver
//! process on the emulator's pty, commanded from this process. "ok" means the arm will do
//! it; a refusal names its cause.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use limber_emulator::{Emulator, EmulatorConfig, EmulatorState};
use limber_p2os::{ArmCalibration, ArmJoint};
use limber_services::prelude::*;
use limber_services::{Domain, Role};
use limber_tests::Proc;

const PIONEER: &str = env!("CARGO_BIN_EXE_limber-test-pioneer");
const T: Duration = Duration::from_secs(5);

fn start(domain: &Domain, emu: &Emulator, name: &str) -> Proc {
    let dir = PathBuf::from(env!("CARGO_TARGET_TMPDIR"));
    let cfg = limber_tests::pioneer_test_config(&dir, name, "");
    let port = emu.pty_path().unwrap().display().to_string();
    limber_tests::start_pioneer(PIONEER, domain.name(), &port, &cfg)
}

fn ctx(domain: &Domain) -> Context {
    Context::new(domain, Role::Client, "ok-test").unwrap()
}

fn cal() -> ArmCalibration {
    ArmCalibration::from(limber_emulator::default_arm_info())
}

/// A barrier: a joint-0 speed setting that the robot has taken. The link keeps the order,
/// so everything the driver wrote before it has arrived.
fn barrier(arm: &mut ActArrayClient, emu: &Emulator, speed: f64) -> EmulatorState {
    arm.set_speed_config(0, speed).unwrap();
    let ms = cal()
        .speed_to_ms_per_step(ArmJoint::from_index(0).unwrap(), speed)
        .unwrap();
    let (arrived, st) = emu.wait_for(T, |s| s.robot.ms_per_step[0] == ms);
    assert!(
        arrived,
        "the barrier (speed {speed}) never reached the robot"
    );
    st
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

fn dist(a: Vec3, b: Vec3) -> f64 {
    ((a.x - b.x).powi(2) + (a.y - b.y).powi(2) + (a.z - b.z).powi(2)).sqrt()
}

/// Item 7: `power off` then `pos 2 0.3` answered "ok" and the joint never moved (STALLED
/// after 2 s). Now every motion command is refused as POWERED_OFF and nothing reaches the
/// robot; stopping is still carried out; after `power on` the same command moves.
#[test]
fn an_unpowered_arm_refuses_motion_with_the_reason() {
    let domain = Domain::unique_for_test();
    let emu = Emulator::start_pty(EmulatorConfig::default()).unwrap();
    let _driver = start(&domain, &emu, "ok-power");
    let c = ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&c, "pioneer/actarray/0", T).unwrap();
    let mut limb = LimbClient::connect_timeout(&c, "pioneer/limb/0", T).unwrap();
    let mut grip = GripperClient::connect_timeout(&c, "pioneer/gripper/1", T).unwrap();
    arm.power(false).unwrap();
    let (off, _) = emu.wait_for(T, |s| !s.robot.arm_powered);
    assert!(off, "the arm never powered off");
    let st0 = barrier(&mut arm, &emu, 0.3);

    let refused = [
        arm.move_to(2, 0.3).unwrap(),
        arm.move_to_multi(&[0.0, 0.1, 0.2]).unwrap(),
        arm.move_at_speed(2, 0.5).unwrap(),
        arm.move_at_speed_multi(&[0.0, 0.5]).unwrap(),
        arm.home(None).unwrap(),
        arm.home(Some(1)).unwrap(),
    ];
    for t in refused {
        assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::PoweredOff);
    }
    let t = limb.set_position([0.35, 0.0, 0.25]).unwrap();
    assert_eq!(limb.wait_outcome(t, T).unwrap(), Status::PoweredOff);
    let t = limb.vec_move([1.0, 0.0, 0.0], 0.02).unwrap();
    assert_eq!(limb.wait_outcome(t, T).unwrap(), Status::PoweredOff);
    let t = limb.home().unwrap();
    assert_eq!(limb.wait_outcome(t, T).unwrap(), Status::PoweredOff);
    let t = grip.open().unwrap();
    assert_eq!(grip.wait_outcome(t, T).unwrap(), Status::PoweredOff);
    assert_eq!(Status::PoweredOff.to_string(), "powered off");
    // Stopping needs no power.
    let t = arm.move_at_speed(2, 0.0).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);
    let t = limb.stop().unwrap();
    assert_eq!(limb.wait_outcome(t, T).unwrap(), Status::Ok);
    let st1 = barrier(&mut arm, &emu, 1.0);
    assert_eq!(
        st1.robot.servo_targets, st0.robot.servo_targets,
        "a refused command reached the robot"
    );

    // Powered again, the same command is carried out at once (no wait for the robot's
    // confirmation: the power command reaches it first) and the joint gets there.
    arm.power(true).unwrap();
    let t = arm.move_to(2, 0.3).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);
    let joint = ArmJoint::from_index(2).unwrap();
    let tick = cal().radians_to_ticks(joint, 0.3).unwrap().tick;
    let (there, st) = emu.wait_for(Duration::from_secs(20), |s| s.robot.servo_ticks[2] == tick);
    assert!(there, "joint 2 never reached its target: {:?}", st.robot);
}

/// Item 9: `speed 2 1e308` answered "ok" and the joint ran at about 17 rad/s while the
/// geometry says 0.87 rad/s. Now the speed is clamped to the joint's configured speed and
/// the outcome says so (CLAMPED, carried out); a speed within the limit is plain OK.
#[test]
fn a_speed_beyond_the_joint_limit_is_clamped_and_says_so() {
    let domain = Domain::unique_for_test();
    let emu = Emulator::start_pty(EmulatorConfig::default()).unwrap();
    let _driver = start(&domain, &emu, "ok-speed");
    let c = ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&c, "pioneer/actarray/0", T).unwrap();
    arm.power(true).unwrap();
    let geom = arm.geometry().unwrap();
    let limit = geom.actuators()[2].config_speed;
    let joint = ArmJoint::from_index(2).unwrap();
    let limit_ms = cal().joint(joint).unwrap().speed;
    assert!(limit > 0.0 && limit < 2.0, "{limit}");

    let t = arm.move_at_speed(2, 1e308).unwrap();
    let s = arm.wait_outcome(t, T).unwrap();
    assert_eq!(s, Status::Clamped);
    assert!(s.is_carried_out() && s.to_string() == "ok, clamped to the limit");
    let (clamped, st) = emu.wait_for(T, |s| s.robot.ms_per_step[2] == limit_ms);
    assert!(
        clamped,
        "joint 2 runs at {} ms/step, its limit is {limit_ms}",
        st.robot.ms_per_step[2]
    );
    // And it moves (it was told to go to its limit).
    let start_tick = st.robot.servo_ticks[2];
    let (moved, _) = emu.wait_for(Duration::from_secs(20), |s| {
        s.robot.servo_ticks[2] != start_tick
    });
    assert!(moved, "the clamped joint never moved");
    let t = arm.move_at_speed(2, 0.0).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);

    // Within the limit: exactly as asked.
    let slow = limit / 2.0;
    let t = arm.move_at_speed(2, -slow).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);
    let slow_ms = cal().speed_to_ms_per_step(joint, slow).unwrap();
    assert!(slow_ms > limit_ms);
    let (slowed, _) = emu.wait_for(T, |s| s.robot.ms_per_step[2] == slow_ms);
    assert!(slowed);
    // One joint of several beyond its limit: the whole command says CLAMPED.
    let t = arm.move_at_speed_multi(&[0.0, 0.0, 1e9]).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Clamped);
    let t = arm.move_at_speed_multi(&[0.0, 0.0, 0.0]).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);
}

/// Items 8 and 10: `vecmove 1e308 1e308 0 0.02` answered "ok" and nothing moved; it now
/// moves 2 cm like `1 1 0`; a zero direction and parallel approach and orientation are
/// invalid arguments; beyond the reach is OUT_OF_REACH; an orientation the five joints
/// cannot hold is UNREACHABLE_ORIENTATION.
#[test]
fn limb_refusals_name_their_cause_and_a_huge_direction_moves() {
    let domain = Domain::unique_for_test();
    let emu = Emulator::start_pty(EmulatorConfig::default()).unwrap();
    let _driver = start(&domain, &emu, "ok-limb");
    let c = ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&c, "pioneer/actarray/0", T).unwrap();
    let mut limb = LimbClient::connect_timeout(&c, "pioneer/limb/0", T).unwrap();
    arm.power(true).unwrap();
    for j in 0..6 {
        arm.set_speed_config(j, 20.0).unwrap();
    }
    let t = limb.set_position([0.35, 0.0, 0.25]).unwrap();
    assert_eq!(limb.wait_outcome(t, T).unwrap(), Status::Ok);
    let idle = |s: &LimbData| s.limb_state() == Ok(LimbState::Idle);
    let before = wait_limb(&mut limb, "idle at the start", idle);

    let t = limb.vec_move([1e308, 1e308, 0.0], 0.02).unwrap();
    assert_eq!(limb.wait_outcome(t, T).unwrap(), Status::Ok);
    let after = wait_limb(&mut limb, "2 cm along (1, 1, 0)", |s| {
        idle(s) && dist(s.position, before.position) > 0.01
    });
    let moved = dist(after.position, before.position);
    assert!((moved - 0.02).abs() < 0.01, "moved {moved} m");
    let d = Vec3::new(
        after.position.x - before.position.x,
        after.position.y - before.position.y,
        after.position.z - before.position.z,
    );
    assert!(
        (d.x - d.y).abs() < 0.01 && d.z.abs() < 0.01,
        "not along (1, 1, 0): {d:?}"
    );

    // A zero direction never leaves the client (the driver refuses one that does, with
    // INVALID_ARGUMENT: see the decoding tests of limber-interfaces).
    assert!(matches!(
        limb.vec_move([0.0, 0.0, 0.0], 0.02),
        Err(CommandError::Invalid(_))
    ));
    // Parallel approach and orientation make no frame, reachable position or not.
    for p in [[0.35, 0.0, 0.25], [1.5, 0.0, 0.3]] {
        let t = limb.set_pose(p, [1.0, 0.0, 0.0], [1.0, 0.0, 0.0]).unwrap();
        assert_eq!(limb.wait_outcome(t, T).unwrap(), Status::InvalidArgument);
    }
    let t = limb
        .set_pose([1.5, 0.0, 0.3], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0])
        .unwrap();
    assert_eq!(limb.wait_outcome(t, T).unwrap(), Status::OutOfReach);
    assert_eq!(
        limb.state().unwrap().limb_state().unwrap(),
        LimbState::OutOfReach
    );
    // Where the arm is, with its own approach, but the frame rolled about the approach:
    let s = wait_limb(&mut limb, "a state", |_| true);
    let (a, o) = (s.approach, s.orientation);
    let axo = Vec3::new(
        a.y * o.z - a.z * o.y,
        a.z * o.x - a.x * o.z,
        a.x * o.y - a.y * o.x,
    );
    let (c5, s5) = (0.5f64.cos(), 0.5f64.sin());
    let rolled = [
        o.x * c5 + axo.x * s5,
        o.y * c5 + axo.y * s5,
        o.z * c5 + axo.z * s5,
    ];
    // the 5-DOF wrist cannot follow: it stays where it is (the nearest frame it can
    // hold) and says by how much the orientation was adjusted (issue 13 item 6).
    let t = limb
        .set_pose(s.position.to_array(), a.to_array(), rolled)
        .unwrap();
    assert_eq!(limb.wait_outcome(t, T).unwrap(), Status::Adjusted);
    let s = wait_limb(&mut limb, "the adjustment", |s| {
        s.orientation_adjustment > 0.0
    });
    assert!(
        (s.orientation_adjustment - 0.5).abs() < 0.05,
        "adjusted by {}",
        s.orientation_adjustment
    );
}

/// Issue "Nobody moves the arm who may not", item 8: `speedcfg 2 1e308` answered a plain
/// "ok" and set the servo to the controller's fastest step, so the next `pos 2 -1.5` moved
/// 17 times faster than the geometry's `config_speed`. A speed request beyond the joint's
/// limit now sets the limit (the joint's calibrated speed), like the SPEED command.
#[test]
fn a_speed_request_beyond_the_joint_limit_is_clamped_to_it() {
    let domain = Domain::unique_for_test();
    let emu = Emulator::start_pty(EmulatorConfig::default()).unwrap();
    let _driver = start(&domain, &emu, "ok-speedcfg");
    let c = ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&c, "pioneer/actarray/0", T).unwrap();
    let j2 = ArmJoint::from_index(2).unwrap();
    let limit_ms = cal().joint(j2).unwrap().speed;
    let limit = arm.geometry().unwrap().actuators()[2].config_speed;
    for speed in [1e308, 17.0 * limit] {
        arm.set_speed_config(2, speed).unwrap();
        let st = barrier(&mut arm, &emu, 0.3);
        assert_eq!(
            st.robot.ms_per_step[2], limit_ms,
            "speedcfg 2 {speed}: the servo runs faster than its limit ({limit} rad/s)"
        );
    }
    // Below the limit: as asked.
    arm.set_speed_config(2, limit / 2.0).unwrap();
    let st = barrier(&mut arm, &emu, 1.0);
    assert_eq!(
        st.robot.ms_per_step[2],
        cal().speed_to_ms_per_step(j2, limit / 2.0).unwrap()
    );
}

/// Issue "Nobody moves the arm who may not", item 15: `power off` answered "ok" while the
/// latest state still said powered (the driver changed `motor_state` only when the robot's
/// next ARMpac said so). The state sent before a POWER reply shows what was asked; the
/// robot's ARMpacs then confirm it, and the state keeps saying so.
#[test]
fn after_a_power_reply_the_latest_state_already_shows_it() {
    let domain = Domain::unique_for_test();
    let emu = Emulator::start_pty(EmulatorConfig::default()).unwrap();
    let _driver = start(&domain, &emu, "ok-power-state");
    let c = ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&c, "pioneer/actarray/0", T).unwrap();
    arm.set_request_timeout(T);
    arm.current(T).unwrap();
    for (on, speed) in [(false, 0.3), (true, 0.25), (false, 0.2), (true, 0.35)] {
        arm.power(on).unwrap();
        // Nothing waited for: what arrived with the reply.
        let s = arm.state().expect("a state");
        assert_eq!(
            s.motor_state, on as u32,
            "power {on} answered ok, but the latest state says motor_state {}",
            s.motor_state
        );
        let (done, _) = emu.wait_for(T, |s| s.robot.arm_powered == on);
        assert!(done, "the robot never took power {on}");
        // A barrier the robot took after the power command: the robot's reports since
        // then confirm the state.
        barrier(&mut arm, &emu, speed);
        let s = arm.state().expect("a state");
        assert_eq!(
            s.motor_state, on as u32,
            "power {on}: after the robot took it"
        );
    }
}
