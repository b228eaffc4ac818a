//! The Pioneer gripper's state byte as the vendor's manual writes it (the Pioneer Gripper
//! manual, Table 4 "Gripper State Byte", active high: bit 0 paddles open, 1 closed, 2
//! moving, 3 gripper error, 4 lift up, 5 lift down, 6 lift moving, 7 lift error; both
//! bits of a pair equal = position unknown; the breakbeams in DIGIN): the emulated SIP
//! and GRIPPERpac carry the manual's bits for each state, and limber's driver and
//! Player's p2os (its decoding as the reference, section 3.7, records it) read them as
//! the manual says. ARIA's active-low reading stays available on both sides.

use std::time::{Duration, Instant};

use limber_emulator::{GripperByteLayout, ModelConfig, ObjectPlacement, Robot, Timing};
use limber_interfaces::prelude::*;
use limber_p2os::{Command, Frame, GripperCommand as P2, RobotPacket, Sip};
use limber_pioneer::{PioneerConfig, RobotModel};

// The manual's Table 4, bit by bit.
const PADDLES_OPEN: u8 = 1 << 0;
const PADDLES_CLOSED: u8 = 1 << 1;
const PADDLES_MOVING: u8 = 1 << 2;
const LIFT_UP: u8 = 1 << 4;
const LIFT_DOWN: u8 = 1 << 5;
const LIFT_MOVING: u8 = 1 << 6;
/// DIGIN: the outer and inner breakbeams, 1 = obstructed.
const DIGIN_BEAMS: u8 = 0x04 | 0x08;

/// Player 3's p2os reading of the byte g (reference 3.7): the gripper state.
fn player_gripper(g: u8) -> GripperState {
    if g & 0x01 != 0 && g & 0x02 != 0 && g & 0x04 == 0 {
        GripperState::Error
    } else if g & 0x01 != 0 {
        GripperState::Open
    } else if g & 0x02 != 0 {
        GripperState::Closed
    } else if g & 0x04 != 0 {
        GripperState::Moving
    } else {
        GripperState::Error
    }
}

/// Player 3's p2os reading of the lift (reference 3.7): state and position (0 down, 1
/// up, `None` = the last commanded one).
fn player_lift(g: u8) -> (ActuatorFlags, Option<f64>) {
    if g & 0x10 != 0 && g & 0x20 != 0 && g & 0x40 == 0 {
        (ActuatorFlags::IDLE, None)
    } else if g & 0x10 != 0 {
        (ActuatorFlags::IDLE, Some(1.0))
    } else if g & 0x20 != 0 {
        (ActuatorFlags::IDLE, Some(0.0))
    } else if g & 0x40 != 0 {
        (ActuatorFlags::MOVING, None)
    } else {
        (ActuatorFlags::STALLED, None)
    }
}

/// The emulated controller (immediate replies) with the gripper byte in `layout`.
struct Emu {
    robot: Robot,
    t0: Instant,
    at: u64,
    out: Vec<Frame>,
}

impl Emu {
    fn new(layout: GripperByteLayout) -> Emu {
        let t0 = Instant::now();
        let cfg = ModelConfig {
            gripper_byte: layout,
            ..ModelConfig::default()
        };
        let mut robot = Robot::new(cfg, t0);
        robot.set_timing(Timing::Fast);
        let mut e = Emu {
            robot,
            t0,
            at: 0,
            out: Vec::new(),
        };
        for c in [
            Command::Sync0,
            Command::Sync1,
            Command::Sync2,
            Command::Open,
        ] {
            e.cmd(c);
        }
        e
    }

    fn now(&self) -> Instant {
        self.t0 + Duration::from_millis(self.at)
    }

    fn cmd(&mut self, c: Command) {
        let f = c.encode().unwrap();
        let now = self.now();
        self.out.clear();
        self.robot.handle(f.payload(), now, &mut self.out);
    }

    fn grip(&mut self, c: P2) {
        self.cmd(Command::Gripper(c));
    }

    /// `ms` later.
    fn wait(&mut self, ms: u64) {
        self.at += ms;
        let now = self.now();
        self.out.clear();
        self.robot.advance(now, &mut self.out);
    }

    fn sip(&self) -> Sip {
        self.robot.sip()
    }

    /// The GRIPPERpac the controller answers GRIPREQUEST 1 with.
    fn gripper_packet(&mut self) -> limber_p2os::GripperPacket {
        self.cmd(Command::GripperPacketRequest(1));
        let f = self
            .out
            .first()
            .expect("a GRIPPERpac at once (fast timing)");
        match RobotPacket::parse(f.payload()).unwrap() {
            RobotPacket::Gripper(g) => g,
            other => panic!("{other:?}"),
        }
    }
}

/// limber's driver (the robot model) fed the emulated SIP: its gripper and lift states.
fn driver_reads(
    m: &mut RobotModel,
    sip: &Sip,
    at: Instant,
) -> (GripperState, u32, ActuatorFlags, f64) {
    m.on_packet(&RobotPacket::Sip(*sip), at);
    // As the driver does with every SIP.
    m.lift_from_sip(at);
    let mut g = GripperData::default();
    m.gripper_state(&mut g);
    let mut l = ActArrayData::default();
    m.lift_state(&mut l);
    let lift = l.actuators[0];
    (
        g.gripper_state().unwrap(),
        g.beams,
        ActuatorFlags::from_bits_truncate(lift.state),
        lift.position,
    )
}

fn driver(layout: GripperByteLayout, t0: Instant) -> RobotModel {
    let mut m = RobotModel::new(PioneerConfig {
        gripper_byte: layout,
        ..PioneerConfig::default()
    });
    m.link_up(t0);
    m.set_body_gripper(true);
    m
}

#[test]
fn the_emulated_sip_and_both_readers_agree_with_the_manuals_table() {
    let mut e = Emu::new(GripperByteLayout::Manual);
    let mut m = driver(GripperByteLayout::Manual, e.t0);
    let stroke = PioneerConfig::default().lift_stroke;
    // Each state the manual's table names: what the emulator must write, and what
    // Player and limber then read.
    let mut check = |e: &mut Emu,
                     what: &str,
                     byte: u8,
                     grip: GripperState,
                     lift: (ActuatorFlags, Option<f64>)| {
        let sip = e.sip();
        let g = sip.gripper_switches().0;
        assert_eq!(
            g, byte,
            "{what}: the SIP's byte {g:#010b}, the manual's {byte:#010b}"
        );
        assert_eq!(player_gripper(g), grip, "{what}: Player's gripper reading");
        assert_eq!(player_lift(g), lift, "{what}: Player's lift reading");
        assert_eq!(sip.digin & DIGIN_BEAMS, 0, "{what}: no beam broken");
        // The GRIPPERpac carries the same byte.
        assert_eq!(e.gripper_packet().switches.0, byte, "{what}: GRIPPERpac");
        let now = e.now();
        let (dg, _, dl, pos) = driver_reads(&mut m, &sip, now);
        assert_eq!(dg, grip, "{what}: limber's gripper state");
        assert_eq!(dl, lift.0, "{what}: limber's lift state");
        if let Some(p) = lift.1 {
            assert!((pos - p * stroke).abs() < 1e-9, "{what}: lift at {pos}");
        }
    };
    // At rest: paddles closed, lift down.
    check(
        &mut e,
        "closed, lift down",
        PADDLES_CLOSED | LIFT_DOWN,
        GripperState::Closed,
        (ActuatorFlags::IDLE, Some(0.0)),
    );
    e.grip(P2::Open);
    e.wait(100);
    check(
        &mut e,
        "opening",
        PADDLES_MOVING | LIFT_DOWN,
        GripperState::Moving,
        (ActuatorFlags::IDLE, Some(0.0)),
    );
    e.wait(2000);
    check(
        &mut e,
        "open",
        PADDLES_OPEN | LIFT_DOWN,
        GripperState::Open,
        (ActuatorFlags::IDLE, Some(0.0)),
    );
    e.grip(P2::LiftUp);
    e.wait(1000);
    check(
        &mut e,
        "lift moving",
        PADDLES_OPEN | LIFT_MOVING,
        GripperState::Open,
        (ActuatorFlags::MOVING, None),
    );
    e.wait(3000);
    check(
        &mut e,
        "lift up",
        PADDLES_OPEN | LIFT_UP,
        GripperState::Open,
        (ActuatorFlags::IDLE, Some(1.0)),
    );
    // Stopped half way: both positions unknown (the paddles' bits both clear, the
    // lift's both set: what Player reads as in between).
    e.grip(P2::LiftDown);
    e.grip(P2::Close);
    e.wait(700);
    e.grip(P2::LiftStop);
    e.grip(P2::Stop);
    let sip = e.sip();
    let g = sip.gripper_switches().0;
    assert_eq!(g, LIFT_UP | LIFT_DOWN, "unknown: {g:#010b}");
    assert_eq!(player_lift(g), (ActuatorFlags::IDLE, None));
    let r = sip.gripper_reading(GripperByteLayout::Manual);
    assert_eq!(r.paddles, limber_p2os::PaddleState::Between);
    assert_eq!(r.lift, limber_p2os::LiftState::Between);
    // Closed on an object between the paddles (on the floor: the lift down): closed,
    // and both beams in DIGIN.
    e.grip(P2::Open);
    e.grip(P2::LiftDown);
    e.wait(4000);
    e.robot.set_object(Some(ObjectPlacement::Inner));
    e.grip(P2::Close);
    e.wait(3000);
    let sip = e.sip();
    let g = sip.gripper_switches().0;
    assert_eq!(
        g & (PADDLES_OPEN | PADDLES_CLOSED | PADDLES_MOVING),
        PADDLES_CLOSED
    );
    assert_eq!(sip.digin & DIGIN_BEAMS, DIGIN_BEAMS);
    assert_eq!(player_gripper(g), GripperState::Closed);
    let now = e.now();
    let (dg, beams, _, _) = driver_reads(&mut m, &sip, now);
    assert_eq!((dg, beams), (GripperState::Closed, 0b11));
}

#[test]
fn arias_reading_stays_an_option_on_both_sides() {
    let mut e = Emu::new(GripperByteLayout::Aria);
    let mut m = driver(GripperByteLayout::Aria, e.t0);
    // Closed, lift down, as ARIA's General-I/O switches say it: active low, the lift at
    // a limit (bit 1 clear), both paddle contacts (bits 4, 5 clear), not open (bit 0 set).
    let closed = e.sip();
    assert_eq!(closed.gripper_switches().0, 0x01);
    let now = e.now();
    assert_eq!(driver_reads(&mut m, &closed, now).0, GripperState::Closed);
    e.grip(P2::Open);
    e.wait(3000);
    let sip = e.sip();
    assert_eq!(sip.gripper_switches().0, 0x30);
    let now = e.now();
    assert_eq!(driver_reads(&mut m, &sip, now).0, GripperState::Open);
    // ARIA's closed byte read the manual's way says OPEN (as Player's p2os says): why
    // the two sides' layouts must match.
    let mut manual = driver(GripperByteLayout::Manual, e.t0);
    assert_eq!(
        driver_reads(&mut manual, &closed, now).0,
        GripperState::Open
    );
    assert_eq!(player_gripper(0x01), GripperState::Open);
}
