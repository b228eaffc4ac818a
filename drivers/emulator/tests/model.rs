//! The emulated controller's behaviour on simulated time (no I/O, no sleeps).

use limber_emulator::{ModelConfig, ObjectPlacement, Robot, SyncStage, Timing, default_arm_info};
use limber_p2os::*;
use std::time::{Duration, Instant};

fn ms(n: u64) -> Duration {
    Duration::from_millis(n)
}

struct Sim {
    robot: Robot,
    t0: Instant,
    out: Vec<Frame>,
}

impl Sim {
    /// A robot in fast mode (replies at once): most tests here are about
    /// behaviour, not timing.
    fn new(cfg: ModelConfig) -> Sim {
        Sim::with_timing(cfg, Timing::Fast)
    }

    fn with_timing(cfg: ModelConfig, timing: Timing) -> Sim {
        let t0 = Instant::now();
        let mut robot = Robot::new(cfg, t0);
        robot.set_timing(timing);
        Sim {
            robot,
            t0,
            out: Vec::new(),
        }
    }

    /// Sends a command at `at` after the start; returns the replies' payloads.
    fn cmd(&mut self, at: u64, c: Command) -> Vec<Vec<u8>> {
        self.out.clear();
        let f = c.encode().unwrap();
        self.robot
            .handle(f.payload(), self.t0 + ms(at), &mut self.out);
        self.out.iter().map(|f| f.payload().to_vec()).collect()
    }

    fn advance(&mut self, at: u64) -> Vec<Vec<u8>> {
        self.out.clear();
        self.robot.advance(self.t0 + ms(at), &mut self.out);
        self.out.iter().map(|f| f.payload().to_vec()).collect()
    }

    fn cycle(&mut self, at: u64) -> Vec<Vec<u8>> {
        self.out.clear();
        self.robot.cycle(self.t0 + ms(at), &mut self.out);
        self.out.iter().map(|f| f.payload().to_vec()).collect()
    }

    fn open(&mut self) {
        assert_eq!(self.cmd(0, Command::Sync0), vec![vec![0]]);
        assert_eq!(
            self.cmd(0, Command::Sync0),
            vec![vec![0]],
            "duplicate SYNC0"
        );
        assert_eq!(self.cmd(0, Command::Sync1), vec![vec![1]]);
        let r = self.cmd(0, Command::Sync2);
        assert_eq!(r.len(), 1);
        assert_eq!(
            RobotIdentity::parse(&r[0][1..]),
            ModelConfig::default().identity
        );
        assert_eq!(self.robot.stage(), SyncStage::Synced);
        assert!(self.cmd(0, Command::Open).is_empty());
        assert_eq!(self.robot.stage(), SyncStage::Open);
    }
}

fn j(n: u8) -> ArmJoint {
    ArmJoint::new(n).unwrap()
}

#[test]
fn handshake_and_nothing_before_open() {
    let mut s = Sim::new(ModelConfig::default());
    assert!(s.cmd(0, Command::ArmInfo).is_empty());
    assert!(s.cycle(100).is_empty(), "no SIP before OPEN");
    assert!(s.cmd(0, Command::Sync2).is_empty(), "SYNC2 out of order");
    s.open();
    let c = s.cycle(100);
    assert_eq!(c.len(), 1);
    assert!(matches!(RobotPacket::parse(&c[0]), Ok(RobotPacket::Sip(_))));
    // CLOSE: back to NO_SYNC, silent.
    s.cmd(150, Command::Close);
    assert_eq!(s.robot.stage(), SyncStage::NoSync);
    assert!(s.cycle(200).is_empty());
}

#[test]
fn servos_step_one_tick_per_ms_per_step() {
    let mut s = Sim::new(ModelConfig::default());
    s.open();
    let r = s.cmd(0, Command::ArmInfo);
    match RobotPacket::parse(&r[0]) {
        Ok(RobotPacket::ArmInfo(i)) => assert_eq!(i, default_arm_info()),
        other => panic!("{other:?}"),
    }
    // Unpowered: position commands are ignored.
    s.cmd(
        0,
        Command::ArmPos {
            joint: j(1),
            tick: 138,
        },
    );
    s.advance(500);
    assert_eq!(s.robot.state().servo_ticks[0], 128);
    s.cmd(1000, Command::ArmPower(true));
    s.cmd(
        1000,
        Command::ArmSpeed {
            joint: j(1),
            ms_per_step: 10,
        },
    );
    s.cmd(
        1000,
        Command::ArmPos {
            joint: j(1),
            tick: 138,
        },
    );
    s.advance(1055);
    assert_eq!(s.robot.state().servo_ticks[0], 133);
    assert_eq!(
        s.robot
            .arm_packet()
            .status(ArmpacLayout::Manual)
            .moving_mask(),
        1
    );
    s.advance(1099);
    assert_eq!(s.robot.state().servo_ticks[0], 137);
    // Reaching the target sends no ARMpac unless the stream is on.
    assert!(s.advance(1100).is_empty());
    assert_eq!(s.robot.state().servo_ticks[0], 138);
    assert_eq!(
        s.robot
            .arm_packet()
            .status(ArmpacLayout::Manual)
            .moving_mask(),
        0
    );

    // With the stream on, commands and arrivals produce an ARMpac at once.
    assert_eq!(
        s.cmd(1200, Command::ArmStatus(ArmStatusMode::Continuous))
            .len(),
        1
    );
    let r = s.cmd(
        1200,
        Command::ArmPos {
            joint: j(1),
            tick: 136,
        },
    );
    assert_eq!(r.len(), 1);
    assert!(s.advance(1205).is_empty());
    let r = s.advance(1220);
    match RobotPacket::parse(&r[0]) {
        Ok(RobotPacket::Arm(a)) => {
            assert_eq!(a.tick(j(1)), 136);
            let st = a.status(ArmpacLayout::Manual);
            assert_eq!(st.moving_mask(), 0);
            assert!(st.powered && st.connected);
        }
        other => panic!("{other:?}"),
    }
    // Every cycle: SIP and ARMpac.
    assert_eq!(s.cycle(1300).len(), 2);
    // Targets are clamped to the calibrated range; bad joints are ignored.
    s.cmd(
        1300,
        Command::ArmPos {
            joint: j(1),
            tick: 255,
        },
    );
    assert_eq!(s.robot.state().servo_targets[0], 228);
    s.cmd(
        1300,
        Command::Custom {
            number: num::ARM_POS,
            arg: Some(0x0905),
        },
    );
    s.cmd(
        1300,
        Command::Custom {
            number: num::ARM_POS,
            arg: Some(-5),
        },
    );
    s.cmd(
        1300,
        Command::Custom {
            number: num::ARM_POS,
            arg: None,
        },
    );
    assert_eq!(s.robot.state().servo_targets[1], 200);
}

#[test]
fn park_homes_then_powers_off() {
    let mut s = Sim::new(ModelConfig::default());
    s.open();
    s.cmd(0, Command::ArmPower(true));
    for joint in ArmJoint::all() {
        s.cmd(
            0,
            Command::ArmSpeed {
                joint,
                ms_per_step: 1,
            },
        );
    }
    s.cmd(
        0,
        Command::ArmPos {
            joint: j(2),
            tick: 100,
        },
    );
    s.cmd(
        0,
        Command::ArmPos {
            joint: j(6),
            tick: 110,
        },
    );
    s.advance(1000);
    assert_eq!(s.robot.state().servo_ticks[1], 100);
    s.cmd(1000, Command::ArmPark);
    assert!(s.robot.state().homing);
    s.advance(1050);
    s.advance(2000);
    let st = s.robot.state();
    let homes: Vec<u8> = default_arm_info()
        .calibrations()
        .iter()
        .map(|c| c.home)
        .collect();
    assert_eq!(st.servo_ticks.to_vec(), homes);
    assert!(!st.arm_powered && !st.homing);
}

#[test]
fn lift_takes_three_and_a_half_seconds_per_stroke() {
    let mut s = Sim::new(ModelConfig::default());
    s.open();
    s.cmd(0, Command::Gripper(GripperCommand::LiftUp));
    s.advance(1750);
    let st = s.robot.state();
    assert!((st.lift - 0.5).abs() < 1e-9 && st.lift_moving);
    assert_eq!(st.gripper.lift, LiftState::Moving);
    s.advance(3500);
    let st = s.robot.state();
    assert_eq!(st.lift, 1.0);
    assert!(!st.lift_moving && st.gripper.lift == LiftState::Up);
    // Stop half way down: not at a limit.
    s.cmd(3500, Command::Gripper(GripperCommand::LiftDown));
    s.cmd(4375, Command::Gripper(GripperCommand::LiftStop));
    let st = s.robot.state();
    assert!((st.lift - 0.75).abs() < 1e-9);
    assert_eq!(st.gripper.lift, LiftState::Between);
}

#[test]
fn breakbeams_follow_the_object() {
    let mut s = Sim::new(ModelConfig::default());
    s.open();
    s.cmd(0, Command::Gripper(GripperCommand::Open));
    s.advance(2000);
    assert_eq!(s.robot.state().gripper.paddles, PaddleState::Open);
    s.robot.set_object(Some(ObjectPlacement::Outer));
    let sw = s.robot.sip().gripper_reading(GripperByteLayout::Manual);
    assert!(sw.outer_beam && !sw.inner_beam);
    s.robot.set_object(Some(ObjectPlacement::Inner));
    let sw = s.robot.sip().gripper_reading(GripperByteLayout::Manual);
    assert!(sw.outer_beam && sw.inner_beam);
    s.cmd(2000, Command::Gripper(GripperCommand::Close));
    s.advance(2500);
    assert_eq!(s.robot.state().gripper.paddles, PaddleState::Moving);
    s.advance(4000);
    let st = s.robot.state();
    assert!(st.object_in_gripper);
    assert_eq!(st.gripper.paddles, PaddleState::Closed);
    assert!((st.paddles - 0.35).abs() < 1e-9, "stopped on the object");
    // Lifted with the paddles open, the object stays on the floor.
    s.cmd(4000, Command::Gripper(GripperCommand::Open));
    s.cmd(4000, Command::Gripper(GripperCommand::LiftUp));
    s.advance(8000);
    let st = s.robot.state();
    assert!(!st.object_in_gripper);
    assert!(!st.gripper.outer_beam && !st.gripper.inner_beam);
}

#[test]
fn a_robot_without_arm_or_gripper_ignores_their_commands() {
    let cfg = ModelConfig {
        arm: None,
        gripper: false,
        ..ModelConfig::default()
    };
    let mut s = Sim::new(cfg);
    s.open();
    assert!(s.cmd(0, Command::ArmInfo).is_empty());
    assert!(s.cmd(0, Command::ArmStatus(ArmStatusMode::Once)).is_empty());
    s.cmd(0, Command::Gripper(GripperCommand::LiftUp));
    s.cmd(0, Command::Gripper(GripperCommand::LiftCarry));
    s.cmd(0, Command::GripperValue(-10));
    s.advance(5000);
    assert_eq!(s.robot.state().lift, 0.0);
    assert_eq!(s.cycle(5000).len(), 1);
    assert!(!s.robot.state().has_arm);
    // Logged and counted as unsupported, like a controller without a gripper.
    let st = s.robot.state();
    assert_eq!(st.unsupported_gripper_commands, 2);
    assert_eq!(st.unsupported_gripperval_commands, 1);
    // GRIPREQUEST is answered: HAS GRIPPER 0.
    let r = s.cmd(5000, Command::GripperPacketRequest(1));
    assert!(
        matches!(RobotPacket::parse(&r[0]), Ok(RobotPacket::Gripper(g)) if g.gripper_type == 0),
        "{r:?}"
    );
}

/// CONFIG (18) is answered with a CONFIGpac built from the model: GRIPPER says whether
/// the body gripper is fitted; like every reply, at the next cycle in controller timing.
#[test]
fn config_is_answered_with_what_the_robot_has() {
    for gripper in [true, false] {
        let cfg = ModelConfig {
            gripper,
            ..ModelConfig::default()
        };
        let mut s = Sim::new(cfg.clone());
        s.open();
        let r = s.cmd(0, Command::Config);
        assert_eq!(r.len(), 1, "{r:?}");
        let c = ConfigPacket::parse(&r[0]).unwrap();
        assert_eq!(c.has_gripper(), gripper);
        assert_eq!(c.robot_type, cfg.identity.class);
        assert_eq!(c.subtype, cfg.identity.subclass);
        assert_eq!(c.name, cfg.identity.name);
        assert_eq!(c.sip_cycle_ms, 100);
        assert_eq!(s.robot.state().config_requests, 1);
        if gripper {
            s.cmd(0, Command::Gripper(GripperCommand::Open));
            assert_eq!(s.robot.state().unsupported_gripper_commands, 0);
        }

        let mut s = Sim::with_timing(cfg, Timing::Controller);
        s.cmd(0, Command::Sync0);
        s.cycle(100);
        s.cmd(100, Command::Sync1);
        s.cycle(200);
        s.cmd(200, Command::Sync2);
        s.cycle(300);
        s.cmd(300, Command::Open);
        assert!(s.cmd(310, Command::Config).is_empty(), "answered at once");
        let c = s.cycle(400);
        let configs: Vec<_> = c
            .iter()
            .filter_map(|p| ConfigPacket::parse(p).ok())
            .collect();
        assert_eq!(configs.len(), 1, "{c:?}");
        assert_eq!(configs[0].has_gripper(), gripper);
    }
}

#[test]
fn gripper_packet_on_request_and_sonar() {
    let mut s = Sim::new(ModelConfig::default());
    s.open();
    let r = s.cmd(0, Command::GripperPacketRequest(1));
    assert!(
        matches!(RobotPacket::parse(&r[0]), Ok(RobotPacket::Gripper(g)) if g.gripper_type == 1)
    );
    s.cmd(0, Command::Sonar(true));
    let c = s.cycle(100);
    match RobotPacket::parse(&c[0]) {
        Ok(RobotPacket::Sip(sip)) => assert_eq!(sip.sonars().len(), 8),
        other => panic!("{other:?}"),
    }
}

#[test]
fn garbage_commands_do_not_panic() {
    let mut s = Sim::new(ModelConfig::default());
    s.open();
    let mut out = Vec::new();
    for n in 0..=255u8 {
        for payload in [
            vec![n],
            vec![n, 0x3B],
            vec![n, 0x1B, 0xFF, 0xFF],
            vec![n, 0x3B, 0xFF, 0xFF],
            vec![n, 0x2B, 3, b'a'],
        ] {
            s.robot.handle(&payload, s.t0 + ms(10), &mut out);
        }
    }
    s.robot.handle(&[], s.t0, &mut out);
    s.robot.advance(s.t0 + ms(10_000), &mut out);
}

fn home_of_all() -> Vec<u8> {
    default_arm_info()
        .calibrations()
        .iter()
        .map(|c| c.home)
        .collect()
}

/// Moves every joint off its home, 1 ms per step.
fn powered_away_from_home(s: &mut Sim) {
    s.open();
    s.cmd(0, Command::ArmPower(true));
    for joint in ArmJoint::all() {
        s.cmd(
            0,
            Command::ArmSpeed {
                joint,
                ms_per_step: 1,
            },
        );
        let home = home_of_all()[joint.index()];
        s.cmd(
            0,
            Command::ArmPos {
                joint,
                tick: home - 10,
            },
        );
    }
    s.advance(1000);
    assert!(
        s.robot
            .state()
            .servo_ticks
            .iter()
            .zip(home_of_all())
            .all(|(t, h)| *t == h - 10)
    );
}

fn raw(number: u8, arg: i32) -> Command {
    Command::Custom {
        number,
        arg: Some(arg),
    }
}

/// Issue 13 item 2: HOME takes 1..6, or any value above 6 for all joints
/// (Player sends 7, ARIA 255); 0 is ignored and raises no homing bit.
#[test]
fn home_7_and_255_home_every_joint_and_home_0_does_nothing() {
    for all in [7, 255, 100] {
        let mut s = Sim::new(ModelConfig::default());
        powered_away_from_home(&mut s);
        s.cmd(1000, raw(num::ARM_HOME, all));
        assert!(s.robot.state().homing, "HOME {all}");
        s.advance(2000);
        let st = s.robot.state();
        assert_eq!(st.servo_ticks.to_vec(), home_of_all(), "HOME {all}");
        assert!(!st.homing);
    }
    let mut s = Sim::new(ModelConfig::default());
    powered_away_from_home(&mut s);
    let before = s.robot.state().servo_targets;
    for bad in [0, -1] {
        assert!(s.cmd(1000, raw(num::ARM_HOME, bad)).is_empty());
        let st = s.robot.state();
        assert!(!st.homing, "HOME {bad} raised the homing bit");
        assert_eq!(st.servo_targets, before, "HOME {bad} moved a joint");
    }
    // One joint.
    s.cmd(1000, raw(num::ARM_HOME, 3));
    s.advance(2000);
    let st = s.robot.state();
    assert_eq!(st.servo_ticks[2], home_of_all()[2]);
    assert_eq!(st.servo_ticks[1], home_of_all()[1] - 10);
}

/// Issue 13 item 2: STOP takes 1..6 or 255 (all); other values are ignored.
#[test]
fn stop_takes_one_joint_or_255() {
    let mut s = Sim::new(ModelConfig::default());
    powered_away_from_home(&mut s);
    s.cmd(1000, raw(num::ARM_HOME, 7));
    s.advance(1003);
    for ignored in [0, 7, 254] {
        s.cmd(1003, raw(num::ARM_STOP, ignored));
        assert!(
            s.robot
                .state()
                .servo_targets
                .iter()
                .zip(home_of_all())
                .all(|(t, h)| *t == h)
        );
    }
    s.cmd(1003, raw(num::ARM_STOP, 2));
    let st = s.robot.state();
    assert_eq!(st.servo_targets[1], st.servo_ticks[1]);
    assert_eq!(st.servo_targets[0], home_of_all()[0]);
    s.cmd(1003, raw(num::ARM_STOP, 255));
    let st = s.robot.state();
    assert_eq!(st.servo_targets, st.servo_ticks);
    // POWER takes 0 or 1 only.
    s.cmd(1003, raw(num::ARM_POWER, 2));
    assert!(s.robot.state().arm_powered);
    s.cmd(1003, raw(num::ARM_POWER, 0));
    assert!(!s.robot.state().arm_powered);
}

/// Issue 13 item 1: the emulator sends the manuals' layout by default and
/// ARIA's when configured.
#[test]
fn armpac_layout_manual_by_default_aria_on_request() {
    for (layout, idle) in [
        (ArmpacLayout::Manual, [0b11, 0]),
        (ArmpacLayout::Aria, [0, 0b0111]),
    ] {
        let cfg = ModelConfig {
            armpac_layout: layout,
            ..ModelConfig::default()
        };
        if layout == ArmpacLayout::Manual {
            assert_eq!(cfg.armpac_layout, ModelConfig::default().armpac_layout);
        }
        let mut s = Sim::new(cfg);
        s.open();
        s.cmd(0, Command::ArmPower(true));
        assert_eq!(s.robot.arm_packet().status_bytes, idle, "{layout}");
        s.cmd(
            0,
            Command::ArmPos {
                joint: j(1),
                tick: 100,
            },
        );
        s.advance(1);
        let st = s.robot.arm_packet().status(layout);
        assert!(st.powered && st.joint_moving(j(1)) && !st.joint_moving(j(2)));
    }
}

/// Issue 13 item 3: with the controller's timing, replies wait for the next
/// cycle boundary and no ARMpac leaves outside the cycle.
#[test]
fn controller_timing_replies_at_the_cycle_boundary() {
    let mut s = Sim::with_timing(ModelConfig::default(), Timing::Controller);
    assert_eq!(s.robot.timing(), Timing::Controller);
    assert!(
        s.cmd(0, Command::Sync0).is_empty(),
        "SYNC0 answered at once"
    );
    assert_eq!(s.cycle(100), vec![vec![0]]);
    assert!(s.cmd(110, Command::Sync1).is_empty());
    assert_eq!(s.cycle(200), vec![vec![1]]);
    assert!(s.cmd(210, Command::Sync2).is_empty());
    let c = s.cycle(300);
    assert_eq!(c.len(), 1);
    assert_eq!(
        RobotIdentity::parse(&c[0][1..]),
        ModelConfig::default().identity
    );
    assert!(s.cmd(310, Command::Open).is_empty());
    assert_eq!(s.robot.stage(), SyncStage::Open);
    // ARM_INFO and ARM_STATUS 1: answered with the next cycle's packets.
    assert!(s.cmd(320, Command::ArmInfo).is_empty());
    assert!(
        s.cmd(320, Command::ArmStatus(ArmStatusMode::Once))
            .is_empty()
    );
    let c = s.cycle(400);
    let kinds: Vec<u8> = c.iter().map(|p| p[0]).collect();
    assert_eq!(kinds, vec![ptype::ARM_INFO, ptype::SIP_STOPPED, ptype::ARM]);
    // Once means once.
    assert_eq!(s.cycle(500).len(), 1);
    // The stream: one ARMpac per cycle, none on commands or motion changes.
    assert!(
        s.cmd(510, Command::ArmStatus(ArmStatusMode::Continuous))
            .is_empty()
    );
    assert!(s.cmd(510, Command::ArmPower(true)).is_empty());
    assert!(
        s.cmd(
            510,
            Command::ArmPos {
                joint: j(1),
                tick: 130,
            },
        )
        .is_empty()
    );
    assert!(s.advance(550).is_empty());
    assert!(
        s.advance(599).is_empty(),
        "joint 1 stopped: no extra ARMpac"
    );
    assert_eq!(s.robot.state().servo_ticks[0], 130);
    let c = s.cycle(600);
    let kinds: Vec<u8> = c.iter().map(|p| p[0]).collect();
    assert_eq!(kinds, vec![ptype::SIP_STOPPED, ptype::ARM]);
    // The gripper packet requested once also waits for the cycle.
    assert!(s.cmd(610, Command::GripperPacketRequest(1)).is_empty());
    assert_eq!(s.cycle(700).len(), 3);
    assert_eq!(s.cycle(800).len(), 2);
}
