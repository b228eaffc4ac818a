//! One regression test per item of section 6 of the Player reference ("Surprises and
//! pitfalls", the bugs of Player's p2os driver and client libraries), showing that limber
//! does not have it. Each runs the Pioneer driver as a process against the emulator (owned
//! here, to look inside the robot), in a domain of its own.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use limber_emulator::{
    Emulator, EmulatorConfig, EmulatorState, Faults, ModelConfig, ObjectPlacement, default_arm_info,
};
use limber_interfaces::actarray::{self, ActArrayMultiPositionCmd};
use limber_p2os::{ArmCalibration, ArmJoint, Command, GripperCommand as P2Grip};
use limber_services::prelude::*;
use limber_services::{ConnectError, Domain, RequestError, Role};
use limber_tests::Proc;

const PIONEER: &str = env!("CARGO_BIN_EXE_limber-test-pioneer");
const T: Duration = Duration::from_secs(5);

struct Rig {
    emu: Emulator,
    driver: Proc,
    ctx: Context,
    domain: Domain,
}

impl Rig {
    fn new(name: &str) -> Rig {
        Rig::with(name, EmulatorConfig::default(), "")
    }

    fn with(name: &str, cfg: EmulatorConfig, extra_toml: &str) -> Rig {
        let domain = Domain::unique_for_test();
        let emu = Emulator::start_pty(cfg).unwrap();
        let p = limber_tests::pioneer_test_config(
            &PathBuf::from(env!("CARGO_TARGET_TMPDIR")),
            &format!("bug_{name}"),
            extra_toml,
        );
        let port = emu.pty_path().unwrap().display().to_string();
        let driver = limber_tests::start_pioneer(PIONEER, domain.name(), &port, &p);
        let ctx = Context::new(&domain, Role::Client, "bugs").unwrap();
        Rig {
            emu,
            driver,
            ctx,
            domain,
        }
    }

    fn arm(&self) -> ActArrayClient {
        let mut a = ActArrayClient::connect_timeout(&self.ctx, "pioneer/actarray/0", T).unwrap();
        a.power(true).unwrap();
        for j in 0..6 {
            a.set_speed_config(j, 20.0).unwrap();
        }
        a
    }

    fn until(&self, what: &str, pred: impl FnMut(&EmulatorState) -> bool) -> EmulatorState {
        let (ok, s) = self.emu.wait_for(T, pred);
        assert!(ok, "{what}: {:?}", s.robot);
        s
    }
}

fn cal() -> ArmCalibration {
    ArmCalibration::from(default_arm_info())
}

fn tick(j: usize, rad: f64) -> u8 {
    cal()
        .radians_to_ticks(ArmJoint::from_index(j).unwrap(), rad)
        .unwrap()
        .tick
}

/// Sends a command and asserts that it was carried out.
macro_rules! ok {
    ($c:expr, $e:expr) => {{
        let t = $e;
        assert_eq!($c.wait_outcome(t, T).unwrap(), Status::Ok);
    }};
}

/// Waits until every actuator of the arm is idle.
fn settle(a: &mut ActArrayClient) -> ActArrayData {
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let s = *a.wait_state(T).unwrap();
        if s.actuators()
            .iter()
            .all(|x| x.flags().unwrap() == ActuatorFlags::IDLE)
        {
            return s;
        }
        assert!(Instant::now() < deadline, "arm did not settle: {s:?}");
    }
}

/// Section 6, item 1: XDR doubles array counts and widens every byte: our messages are fixed layouts with
/// a single count in front of a fixed array.
#[test]
fn bug01_no_xdr_doubled_counts() {
    let m = limber_interfaces::manifest();
    let s = m.find("ActArrayMultiPositionCmd").unwrap();
    assert_eq!((s.fields[0].name, s.fields[0].offset), ("count", 0));
    assert_eq!(
        (s.fields[2].name, s.fields[2].offset, s.fields[2].array_len),
        ("positions", 8, 32)
    );
    assert_eq!(core::mem::size_of::<ActArrayMultiPositionCmd>(), 264);
}

/// Section 6, item 2: Subtypes and state bits are Player 3's, and points are doubles.
#[test]
fn bug02_player3_numbering() {
    assert_eq!((actarray::cmd::SPEED, actarray::cmd::HOME), (3, 5));
    assert_eq!(
        (ActuatorFlags::BRAKED.bits(), ActuatorFlags::STALLED.bits()),
        (4, 8)
    );
    assert_eq!(core::mem::size_of::<Vec3>(), 24);
}

/// Section 6, item 3: Checksum big-endian, arguments little-endian, negatives sign-magnitude (ARGNINT).
#[test]
fn bug03_checksum_and_argument_encoding() {
    let f = Command::ArmPos {
        joint: ArmJoint::new(1).unwrap(),
        tick: 128,
    }
    .encode()
    .unwrap();
    assert_eq!(
        f.as_bytes(),
        &[0xFA, 0xFB, 0x06, 0x4D, 0x3B, 0x80, 0x01, 0xCD, 0x3C]
    );
    let f = Command::GripperValue(-100).encode().unwrap();
    assert_eq!(&f.as_bytes()[3..7], &[36, 0x1B, 100, 0]);
}

/// Section 6, item 4: Joints are 1-based on the wire; "all" is 0xFF (the manuals accept any value
/// above 6 for HOME, 255 for STOP; Player sends 7, which the emulator also takes): HOME all homes
/// every joint, HOME of joint 2 only joint 2.
#[test]
fn bug04_joint_numbering_and_home_all() {
    let r = Rig::new("b04");
    let mut a = r.arm();
    ok!(a, a.move_to_multi(&[0.3, -0.3, 0.3, 0.3, 0.3]).unwrap());
    let home = default_arm_info();
    // The robot's joints 1 and 2 away from home first: a state published before the
    // controller's next cycle still says idle at home (a race seen once in CI).
    r.until("joints 1 and 2 moved", |s| {
        (1..=2).all(|j| s.robot.servo_ticks[j] != home.joints[j].home)
    });
    settle(&mut a);
    ok!(a, a.home(Some(2)).unwrap());
    let s = r.until("joint 2 homed", |s| {
        s.robot.servo_ticks[2] == home.joints[2].home
    });
    assert_ne!(
        s.robot.servo_ticks[1], home.joints[1].home,
        "joint 1 homed too"
    );
    ok!(a, a.home(None).unwrap());
    r.until("all homed", |s| {
        (0..6).all(|j| s.robot.servo_ticks[j] == home.joints[j].home)
    });
}

/// Section 6, item 5: Two sign layers (ARIA's tick signs, KineCalc's θ signs) are consistent: a SETPOSE
/// ends where it was asked, measured through the ticks the robot reports.
#[test]
fn bug05_sign_layers_consistent() {
    let r = Rig::new("b05");
    let _a = r.arm();
    let mut limb = LimbClient::connect(&r.ctx, "pioneer/limb/0").unwrap();
    for target in [[0.38, 0.12, 0.22], [0.36, -0.15, 0.25]] {
        let base = limb.geometry().unwrap().base_pos;
        let o = limber_examples::pick_block::radial(base.to_array(), [target[0], target[1]]);
        let t = limb.set_pose(target, [0.0, 0.0, -1.0], o).unwrap();
        assert_eq!(limb.wait_outcome(t, T).unwrap(), Status::Ok);
        let deadline = Instant::now() + Duration::from_secs(10);
        loop {
            let s = *limb.wait_state(T).unwrap();
            if s.limb_state().unwrap() == LimbState::Idle {
                let p = s.position;
                let err = ((p.x - target[0]).powi(2)
                    + (p.y - target[1]).powi(2)
                    + (p.z - target[2]).powi(2))
                .sqrt();
                assert!(err < 0.01, "at {p:?} for {target:?}");
                assert!(s.approach.z < -0.99, "approach {:?}", s.approach);
                break;
            }
            assert!(Instant::now() < deadline);
        }
    }
}

/// Section 6, item 6: Nothing is commanded before the calibration: a robot that never answers ARM_INFO
/// gets no arm devices, so no servo can be driven to tick 0.
#[test]
fn bug06_nothing_before_calibration() {
    let cfg = EmulatorConfig {
        model: ModelConfig {
            arm: None,
            ..ModelConfig::default()
        },
        ..EmulatorConfig::default()
    };
    let r = Rig::with("b06", cfg, "");
    assert!(matches!(
        ActArrayClient::connect(&r.ctx, "pioneer/actarray/0"),
        Err(ConnectError::NoDriver { .. })
    ));
    assert!(matches!(
        LimbClient::connect(&r.ctx, "pioneer/limb/0"),
        Err(ConnectError::NoDriver { .. })
    ));
    assert!(
        r.emu.state().robot.servo_ticks.iter().all(|&t| t != 0),
        "a servo was driven to tick 0"
    );
}

/// Section 6, item 7, and issue 13 item 8: Player reads the ARMpac status bytes in the vendor's
/// manuals' order (byte A power and connection, byte B the moving bits), as limber now does by
/// default, but it only ever sets its moving flags: once a joint has moved it is MOVING forever.
/// limber clears them when the joint arrives, reading the emulator's default (manual) layout.
#[test]
fn bug07_moving_flags_cleared() {
    let r = Rig::new("b07");
    assert!(r.emu.state().robot.has_arm, "the emulator has an arm");
    let mut a = r.arm();
    // Slowly (about a second), so the motion is seen even on a loaded machine: at full
    // speed it could end between two samples this test reads.
    a.set_speed_config(0, 0.5).unwrap();
    ok!(a, a.move_to(0, 0.6).unwrap());
    let mut saw_moving = false;
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let s = *a.wait_state(T).unwrap();
        let f = s.actuators[0].flags().unwrap();
        saw_moving |= f.contains(ActuatorFlags::MOVING);
        if f == ActuatorFlags::IDLE && saw_moving {
            break;
        }
        assert!(Instant::now() < deadline, "joint 0 never idle again: {f:?}");
    }
    assert_eq!(
        a.state().unwrap().motor_state,
        1,
        "power state from the manuals' status byte"
    );
}

/// Issue 13 item 8: Player's arm GET_GEOM first sends ARM_INFO and then reads the robot's packets
/// (3.10; every command is followed by a read, and an ARMINFOpac by another, 3.4 and 3.6), so
/// the reply waits for the robot's cycles. limber answers from the calibration it holds: with
/// the robot silent (no cycle at all) the geometry still comes back within 0.5 s.
#[test]
fn player_get_geom_waits_for_robot_cycles_ours_needs_none() {
    let r = Rig::with(
        "b_geom",
        EmulatorConfig::default(),
        "link_timeout_ms = 60000\n",
    );
    let mut a = ActArrayClient::connect_timeout(&r.ctx, "pioneer/actarray/0", T).unwrap();
    assert_eq!(a.geometry().unwrap().actuators_count, 6);
    r.emu.set_faults(Faults {
        silent: true,
        ..Faults::default()
    });
    a.set_request_timeout(Duration::from_millis(500));
    for _ in 0..3 {
        assert_eq!(a.geometry().unwrap().actuators_count, 6);
    }
}

/// Section 6, item 8: REQ SPEED uses the joint's own calibration; speed 0 is refused, not infinite.
#[test]
fn bug08_speed_request_uses_its_own_joint() {
    let r = Rig::new("b08");
    let mut a = ActArrayClient::connect_timeout(&r.ctx, "pioneer/actarray/0", T).unwrap();
    let before = r.emu.state().robot.ms_per_step;
    let speed = 0.2;
    a.set_speed_config(2, speed).unwrap();
    let want = cal()
        .speed_to_ms_per_step(ArmJoint::from_index(2).unwrap(), speed)
        .unwrap();
    let s = r.until("joint 2 speed set", |s| s.robot.ms_per_step[2] == want);
    assert_eq!(s.robot.ms_per_step[3], before[3], "joint 3 changed");
    assert_eq!(
        a.set_speed_config(2, 0.0),
        Err(RequestError::Nack(Status::InvalidArgument))
    );
}

/// Section 6, item 9: No broken de-duplication: a repeated POS, and (joint 0, 0.0), are carried out;
/// MULTI_POS reports success.
#[test]
fn bug09_no_broken_dedup() {
    let r = Rig::new("b09");
    let mut a = r.arm();
    ok!(a, a.move_to(0, 0.4).unwrap());
    ok!(a, a.move_to(0, 0.4).unwrap());
    ok!(a, a.move_to(0, 0.0).unwrap());
    r.until("joint 0 at 0.0", |s| s.robot.servo_ticks[0] == tick(0, 0.0));
    ok!(a, a.move_to_multi(&[0.1, 0.1]).unwrap());
}

/// Section 6, item 10: The lift: metres, LIFTup written properly, negative carry as ARGNINT, HOME
/// updates the position, the geometry has every field.
#[test]
fn bug10_lift() {
    let r = Rig::new("b10");
    let mut lift = ActArrayClient::connect_timeout(&r.ctx, "pioneer/actarray/1", T).unwrap();
    let g = lift.geometry().unwrap();
    let a = g.actuators[0];
    assert_eq!(a.actuator_kind().unwrap(), ActuatorKind::Linear);
    assert_eq!((a.min, a.max, a.home, a.length), (0.0, 0.07, 0.07, 0.0));
    assert_eq!(a.axis, Vec3::new(0.0, 0.0, 1.0));
    assert!((a.config_speed - 0.02).abs() < 1e-12);
    ok!(lift, lift.move_to(0, 0.0).unwrap());
    r.until("lift down", |s| s.robot.lift < 0.01 && !s.robot.lift_moving);
    ok!(lift, lift.move_to(0, 0.07).unwrap());
    r.until("lift up", |s| s.robot.lift > 0.99 && !s.robot.lift_moving);
    // The reported position follows, in metres.
    let deadline = Instant::now() + T;
    while (lift.wait_state(T).unwrap().actuators[0].position - 0.07).abs() > 1e-6 {
        assert!(Instant::now() < deadline);
    }
    // A carry downwards (negative value) moves it down.
    ok!(lift, lift.move_to(0, 0.035).unwrap());
    r.until("lift moved down", |s| s.robot.lift < 0.9);
    ok!(lift, lift.home(None).unwrap());
    r.until("lift homed up", |s| {
        s.robot.lift > 0.99 && !s.robot.lift_moving
    });
    let t = lift.move_to(0, 0.2).unwrap();
    assert_eq!(lift.wait_outcome(t, T).unwrap(), Status::BeyondLimits);
    let _ = P2Grip::LiftUp;
}

/// Section 6, item 11: Break beams are reported from the switch byte (Player's were always 0).
#[test]
fn bug11_beams_reported() {
    let r = Rig::new("b11");
    let mut g = GripperClient::connect_timeout(&r.ctx, "pioneer/gripper/0", T).unwrap();
    ok!(g, g.open().unwrap());
    r.emu.set_object(Some(ObjectPlacement::Inner));
    let deadline = Instant::now() + T;
    loop {
        let s = *g.wait_state(T).unwrap();
        if s.beams == 0b11 {
            break;
        }
        assert!(Instant::now() < deadline, "beams {:#b}", s.beams);
    }
    ok!(g, g.close().unwrap());
    let deadline = Instant::now() + T;
    while g.wait_state(T).unwrap().gripper_state().unwrap() != GripperState::Closed {
        assert!(Instant::now() < deadline);
    }
}

/// Section 6, item 12: Limb quirks: POWER answered on the limb itself, BRAKES refused at once,
/// SETPOSITION and VECMOVE dispatched, STOP stops every joint (wrist pitch included).
#[test]
fn bug12_limb_quirks() {
    let r = Rig::new("b12");
    let _a = r.arm();
    let mut limb = LimbClient::connect(&r.ctx, "pioneer/limb/0").unwrap();
    limb.set_request_timeout(Duration::from_secs(1));
    limb.power(true).unwrap();
    assert_eq!(
        limb.brakes(true),
        Err(RequestError::Nack(Status::Unsupported))
    );
    let t = limb.set_position([0.35, 0.05, 0.25]).unwrap();
    assert_eq!(limb.wait_outcome(t, T).unwrap(), Status::Ok);
    let start = settle_limb(&mut limb);
    let t = limb.vec_move([0.0, 1.0, 0.0], 0.03).unwrap();
    assert_eq!(limb.wait_outcome(t, T).unwrap(), Status::Ok);
    let end = settle_limb(&mut limb);
    assert!(
        (end.y - start.y - 0.03).abs() < 0.006,
        "{start:?} -> {end:?}"
    );
    assert!(
        (end.x - start.x).abs() < 0.006 && (end.z - start.z).abs() < 0.006,
        "{start:?} -> {end:?}"
    );
    // STOP during a wrist-pitch move stops joint 5 (index 4) too.
    let mut a = ActArrayClient::connect(&r.ctx, "pioneer/actarray/0").unwrap();
    settle(&mut a);
    let slow = 0.05;
    a.set_speed_config(4, slow).unwrap();
    ok!(a, a.move_to(4, 1.5).unwrap());
    r.until("wrist pitch moving", |s| {
        s.robot.servo_ticks[4] != s.robot.servo_targets[4]
    });
    let t = limb.stop().unwrap();
    assert_eq!(limb.wait_outcome(t, T).unwrap(), Status::Ok);
    r.until("wrist pitch stopped", |s| {
        s.robot.servo_ticks[4] == s.robot.servo_targets[4]
    });
}

/// Waits until the limb is idle; returns its position.
fn settle_limb(limb: &mut LimbClient) -> Vec3 {
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let s = *limb.wait_state(T).unwrap();
        if s.limb_state().unwrap() == LimbState::Idle {
            return s.position;
        }
        assert!(Instant::now() < deadline, "limb did not settle: {s:?}");
    }
}

/// Section 6, item 13: Geometry lengths go to their own joint (Player shifted them by one).
#[test]
fn bug13_geometry_lengths_per_joint() {
    let r = Rig::with(
        "b13",
        EmulatorConfig::default(),
        "arm_geometry_lengths = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6]\n",
    );
    let mut a = ActArrayClient::connect_timeout(&r.ctx, "pioneer/actarray/0", T).unwrap();
    let g = a.geometry().unwrap();
    let lens: Vec<f64> = g.actuators().iter().map(|x| x.length).collect();
    assert_eq!(lens, [0.1, 0.2, 0.3, 0.4, 0.5, 0.6]);
}

/// Section 6, item 14: The published end-effector frame is orthonormal for any joints (Player's FK had a
/// sign error whenever θ4, θ5 and θ1 were all non-zero).
#[test]
fn bug14_fk_frame_orthonormal() {
    let r = Rig::new("b14");
    let mut a = r.arm();
    ok!(a, a.move_to_multi(&[0.5, -0.4, 0.6, 0.7, -0.5]).unwrap());
    settle(&mut a);
    let mut limb = LimbClient::connect(&r.ctx, "pioneer/limb/0").unwrap();
    let s = *limb.wait_state(T).unwrap();
    let (av, ov) = (s.approach, s.orientation);
    assert!((av.norm() - 1.0).abs() < 1e-9 && (ov.norm() - 1.0).abs() < 1e-9);
    assert!((av.x * ov.x + av.y * ov.y + av.z * ov.z).abs() < 1e-9);
}

/// Section 6, item 15: IK checks reach and limits in one convention and chooses deterministically.
#[test]
fn bug15_ik_reach_limits_deterministic() {
    let r = Rig::new("b15");
    let mut a = r.arm();
    let mut limb = LimbClient::connect(&r.ctx, "pioneer/limb/0").unwrap();
    let t = limb.set_position([0.9, 0.0, 0.3]).unwrap();
    assert_eq!(limb.wait_outcome(t, T).unwrap(), Status::OutOfReach);
    let mut targets = Vec::new();
    for _ in 0..2 {
        let t = limb.set_position([0.33, 0.08, 0.24]).unwrap();
        assert_eq!(limb.wait_outcome(t, T).unwrap(), Status::Ok);
        // The barrier: a later command (the gripper joint) that the robot has carried out;
        // the link keeps the order, so the joint targets of the pose arrived before it.
        let grip = if r.emu.state().robot.servo_targets[5] == tick(5, 0.2) {
            0.0
        } else {
            0.2
        };
        ok!(a, a.move_to(5, grip).unwrap());
        let s = r.until("the gripper joint's target", |s| {
            s.robot.servo_targets[5] == tick(5, grip)
        });
        targets.push(s.robot.servo_targets);
    }
    // The same target from (almost) the same configuration gives the same joints, to the
    // servo tick that the achieved configuration may differ by.
    for j in 0..5 {
        assert!(targets[0][j].abs_diff(targets[1][j]) <= 1, "{targets:?}");
    }
}

/// Section 6, item 16: IDLE vs STALLED is honest (idle at start, not stalled before any command) and
/// motor_state is the real power state.
#[test]
fn bug16_idle_not_stalled_and_motor_state() {
    let r = Rig::new("b16");
    let mut a = ActArrayClient::connect_timeout(&r.ctx, "pioneer/actarray/0", T).unwrap();
    let s = *a.wait_state(T).unwrap();
    assert!(
        s.actuators()
            .iter()
            .all(|x| x.flags().unwrap() == ActuatorFlags::IDLE),
        "{s:?}"
    );
    assert_eq!(s.actuators_count, 6, "the gripper is the sixth actuator");
    for (on, want) in [(false, 0), (true, 1)] {
        a.power(on).unwrap();
        let deadline = Instant::now() + T;
        while a.wait_state(T).unwrap().motor_state != want {
            assert!(Instant::now() < deadline, "motor_state never {want}");
        }
    }
}

/// Section 6, item 17: Keep-alive PULSEs go out whether or not commands do (the robot would stop sending
/// SIPs otherwise).
#[test]
fn bug17_keep_alive_without_commands() {
    let r = Rig::new("b17");
    let before = r.emu.state().stats.bytes_in;
    // No command is sent: whatever arrives is the driver's own keep-alive.
    r.until("a PULSE without commands", |s| {
        s.stats.bytes_in >= before + 6
    });
}

/// Section 6, item 18: A silent robot is an error, not a hang (and TCP never tries baud changes).
#[test]
fn bug18_silent_robot_is_an_error() {
    let domain = Domain::unique_for_test();
    let cfg = EmulatorConfig {
        faults: Faults {
            silent: true,
            ..Faults::default()
        },
        ..EmulatorConfig::default()
    };
    let emu = Emulator::start_tcp(cfg, "127.0.0.1:0".parse().unwrap()).unwrap();
    let port = format!("tcp://{}", emu.tcp_addr().unwrap());
    let mut d = Proc::spawn(PIONEER, domain.name(), &["--port", &port]);
    let code = d.wait_timeout(Duration::from_secs(30));
    assert!(matches!(code, Some(c) if c != 0), "exit {code:?}");
}

/// Section 6, item 19: Requests are answered as they arrive, not after the next robot packet: with a
/// robot cycle of 2 s, geometry requests still come back within a 0.5 s timeout.
#[test]
fn bug19_requests_answered_without_waiting_for_the_robot() {
    // Fast mode: with the controller's timing a 2 s cycle would also delay the sync replies
    // past the handshake's timeouts; here only the SIP cycle is slow.
    let cfg = EmulatorConfig {
        cycle: Duration::from_secs(2),
        ..EmulatorConfig::fast()
    };
    let r = Rig::with("b19", cfg, "link_timeout_ms = 5000\n");
    let mut a = ActArrayClient::connect_timeout(&r.ctx, "pioneer/actarray/0", T).unwrap();
    a.set_request_timeout(Duration::from_millis(500));
    for _ in 0..5 {
        assert_eq!(a.geometry().unwrap().actuators_count, 6);
    }
}

/// Section 6, item 20: Geometry types are right (rotary arm, linear lift) and limits are inclusive.
#[test]
fn bug20_types_and_inclusive_limits() {
    let r = Rig::new("b20");
    let mut a = r.arm();
    let g = a.geometry().unwrap();
    assert!(
        g.actuators()
            .iter()
            .all(|x| x.actuator_kind().unwrap() == ActuatorKind::Rotary)
    );
    let max = g.actuators[1].max;
    ok!(a, a.move_to(1, max).unwrap());
    let t = a.move_to(1, max + 0.05).unwrap();
    assert_eq!(a.wait_outcome(t, T).unwrap(), Status::BeyondLimits);
}

/// Section 6, item 21: A failed geometry request is an error, never an uninitialised reply.
#[test]
fn bug21_geometry_errors_propagate() {
    let mut r = Rig::new("b21");
    let mut a = ActArrayClient::connect_timeout(&r.ctx, "pioneer/actarray/0", T).unwrap();
    a.geometry().unwrap();
    r.driver.signal(libc::SIGKILL);
    let _ = r.driver.wait_timeout(T);
    a.set_request_timeout(Duration::from_secs(2));
    assert!(matches!(
        a.geometry(),
        Err(RequestError::DriverGone | RequestError::NoDriver)
    ));
    let _ = r.domain.name();
}
