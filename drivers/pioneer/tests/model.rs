//! The robot model alone: packets and time in, P2OS commands out (its outbox) and the
//! devices' states. No link, no process, no shared memory.

use std::time::{Duration, Instant};

use limber_interfaces::limb_outcome;
use limber_interfaces::prelude::*;
use limber_p2os::{
    ArmJoint, ArmPacket, ArmStatus, ArmpacLayout, Command, JointSelection, RobotPacket,
};
use limber_pioneer::{INTERNAL, PioneerConfig, Queued, RobotModel};
use limber_services::Origin;

fn client(sent_ns: u64) -> Origin {
    Origin {
        client_id: 7,
        seq: 1,
        sent_ns,
        received_ns: 0,
    }
}

/// A client's command sent now (after the link came up).
fn now_origin() -> Origin {
    client(limber_services::monotonic_ns())
}

fn arm_packet(powered: bool, moving: u8, ticks: [u8; 6]) -> ArmPacket {
    ArmPacket::new(
        ArmStatus {
            moving,
            powered,
            connected: true,
            inited: true,
            homing: false,
        },
        ArmpacLayout::default(),
        ticks,
    )
}

/// The emulator's arm at its home ticks.
fn home_ticks() -> [u8; 6] {
    let info = limber_emulator::default_arm_info();
    core::array::from_fn(|j| info.joints[j].home)
}

/// A model whose link is up, calibrated by the emulator's ARMINFOpac and told by an
/// ARMpac that the arm is powered at home; outbox empty.
fn ready() -> (RobotModel, Instant) {
    let mut m = RobotModel::new(PioneerConfig::default());
    let t0 = Instant::now();
    m.link_up(t0);
    m.set_body_gripper(true);
    let info = limber_emulator::default_arm_info();
    m.on_packet(&RobotPacket::ArmInfo(info), t0);
    m.on_packet(&RobotPacket::Arm(arm_packet(true, 0, home_ticks())), t0);
    assert!(m.calibrated());
    assert!(m.outbox().is_empty());
    (m, t0)
}

fn drain(m: &mut RobotModel) -> Vec<Queued> {
    std::iter::from_fn(|| m.outbox_mut().pop()).collect()
}

/// The P2OS checksum of the reference (section 2): big-endian words of the payload,
/// summed in 16 bits, an odd last byte XORed in.
fn checksum(payload: &[u8]) -> u16 {
    let mut sum: u16 = 0;
    let mut chunks = payload.chunks_exact(2);
    for w in &mut chunks {
        sum = sum.wrapping_add(u16::from(w[0]) << 8 | u16::from(w[1]));
    }
    if let [b] = chunks.remainder() {
        sum ^= u16::from(*b);
    }
    sum
}

#[test]
fn calibration_comes_from_the_arminfopac_and_arm_commands_wait_for_it() {
    let mut m = RobotModel::new(PioneerConfig::default());
    let t0 = Instant::now();
    m.link_up(t0);
    let pos = ActArrayCommand::Position {
        joint: 2,
        position: 0.3,
    };
    // No ARMINFOpac yet: no arm to command.
    assert_eq!(m.arm_command(&pos, &now_origin()), Status::Unsupported);
    assert!(!m.calibrated());
    assert!(m.outbox().is_empty());
    let info = limber_emulator::default_arm_info();
    assert_eq!(
        m.on_packet(&RobotPacket::ArmInfo(info), t0),
        limber_pioneer::PacketEffect::ArmInfo
    );
    assert!(m.calibrated());
    // Calibrated, but no ARMpac has said the arm is powered: motion is refused.
    assert_eq!(m.arm_command(&pos, &now_origin()), Status::PoweredOff);
    assert!(m.outbox().is_empty());
    // The geometry follows the calibration: six joints, each within its limits.
    let g = m.arm_geometry().unwrap();
    assert_eq!(g.actuators_count, 6);
    assert!(g.actuators[..6].iter().all(|a| a.min < a.max));
}

#[test]
fn a_pos_command_becomes_the_arm_pos_bytes_of_the_reference() {
    let (mut m, _) = ready();
    let st = m.arm_command(
        &ActArrayCommand::Position {
            joint: 2,
            position: 0.3,
        },
        &now_origin(),
    );
    assert_eq!(st, Status::Ok);
    let out = drain(&mut m);
    assert_eq!(out.len(), 1, "{out:?}");
    // Joint index 2 is joint 3: centre 128, 90 ticks per 90°, sign -1 (the reference's
    // conventions): 0.3 rad = 17.19° = 17 ticks below the centre.
    assert_eq!(
        out[0].cmd,
        Command::ArmPos {
            joint: ArmJoint::from_index(2).unwrap(),
            tick: 111
        }
    );
    let payload = [77u8, 0x3B, 111, 3];
    let ck = checksum(&payload);
    let mut want = vec![0xFA, 0xFB, payload.len() as u8 + 2];
    want.extend_from_slice(&payload);
    want.extend_from_slice(&ck.to_be_bytes());
    assert_eq!(out[0].cmd.encode().unwrap().as_bytes(), &want[..]);
    assert_eq!(want, [0xFA, 0xFB, 6, 0x4D, 0x3B, 0x6F, 0x03, 0xBC, 0x3E]);
    // The joint is moving toward its target until an ARMpac shows it there (its speed
    // estimated from the ARMpacs).
    let mut s = ActArrayData::default();
    m.arm_state(&mut s, Instant::now());
    assert_eq!(
        s.actuators[2].state,
        (ActuatorFlags::MOVING | ActuatorFlags::SPEED_ESTIMATED).bits()
    );
    let mut ticks = home_ticks();
    ticks[2] = 111;
    m.on_packet(
        &RobotPacket::Arm(arm_packet(true, 0, ticks)),
        Instant::now(),
    );
    m.arm_state(&mut s, Instant::now());
    assert_eq!(s.actuators[2].state, ActuatorFlags::IDLE.bits());
    assert!(
        (s.actuators[2].position - 0.3).abs() < 0.01,
        "{}",
        s.actuators[2].position
    );
}

#[test]
fn refusals_queue_nothing() {
    let (mut m, _) = ready();
    for (cmd, want) in [
        (
            ActArrayCommand::Position {
                joint: 2,
                position: f64::NAN,
            },
            Status::NotFinite,
        ),
        (
            ActArrayCommand::Position {
                joint: 2,
                position: 3.0,
            },
            Status::BeyondLimits,
        ),
        (
            ActArrayCommand::Position {
                joint: 9,
                position: 0.0,
            },
            Status::UnknownJoint,
        ),
    ] {
        assert_eq!(m.arm_command(&cmd, &now_origin()), want, "{cmd:?}");
        assert!(m.outbox().is_empty(), "{cmd:?}");
    }
}

#[test]
fn link_down_refuses_and_drops_what_was_queued() {
    let (mut m, t0) = ready();
    let pos = ActArrayCommand::Position {
        joint: 1,
        position: 0.2,
    };
    assert_eq!(m.arm_command(&pos, &now_origin()), Status::Ok);
    assert_eq!(m.outbox().len(), 1);
    // Nothing queued before a link loss is sent after it.
    assert_eq!(m.link_down(), 1);
    assert!(m.outbox().is_empty());
    assert_eq!(m.arm_command(&pos, &now_origin()), Status::LinkDown);
    assert_eq!(
        m.gripper_command(&GripperCommand::Open, &now_origin()),
        Status::LinkDown
    );
    assert_eq!(
        m.limb_command(&LimbCommand::Home, &now_origin()),
        Status::LinkDown
    );
    assert!(m.outbox().is_empty());
    // A command sent before the link came up again is never carried out on the new link.
    let before = client(1);
    m.link_up(t0 + Duration::from_secs(1));
    assert_eq!(m.arm_command(&pos, &before), Status::LinkDown);
    assert!(m.outbox().is_empty());
    // The driver's own commands and those sent since are.
    assert_eq!(m.arm_command(&pos, &now_origin()), Status::Ok);
    assert_eq!(m.arm_command(&pos, &INTERNAL), Status::Ok);
    assert_eq!(m.outbox().len(), 2);
}

#[test]
fn a_failed_write_forgets_what_it_would_have_started() {
    let (mut m, _) = ready();
    let st = m.arm_command(
        &ActArrayCommand::MultiPosition(JointValues::new("positions", &[0.1, 0.1, 0.1]).unwrap()),
        &now_origin(),
    );
    assert_eq!(st, Status::Ok);
    assert_eq!(m.outbox().len(), 3);
    let first = m.outbox_mut().pop().unwrap();
    m.write_failed(&first);
    assert!(m.outbox().is_empty());
    let mut s = ActArrayData::default();
    m.arm_state(&mut s, Instant::now());
    assert!(
        s.actuators[..3]
            .iter()
            .all(|a| a.state == ActuatorFlags::IDLE.bits()),
        "the joints hold where they are"
    );
}

#[test]
fn home_and_stop_are_the_reference_commands_and_stop_needs_no_power() {
    let (mut m, t0) = ready();
    assert_eq!(
        m.limb_command(&LimbCommand::Home, &now_origin()),
        Status::Ok
    );
    assert_eq!(
        drain(&mut m).iter().map(|q| q.cmd).collect::<Vec<_>>(),
        [Command::ArmHome(JointSelection::All)]
    );
    // The arm reports itself unpowered: motion refused, STOP carried out.
    for _ in 0..4 {
        m.on_packet(&RobotPacket::Arm(arm_packet(false, 0, home_ticks())), t0);
    }
    assert_eq!(
        m.limb_command(&LimbCommand::Home, &now_origin()),
        Status::PoweredOff
    );
    assert_eq!(
        m.limb_command(&LimbCommand::Stop, &now_origin()),
        Status::Ok
    );
    assert_eq!(
        drain(&mut m).iter().map(|q| q.cmd).collect::<Vec<_>>(),
        [Command::ArmStop(JointSelection::All)]
    );
}

#[test]
fn a_speed_above_the_joint_limit_is_clamped_and_said_so() {
    let (mut m, _) = ready();
    let st = m.arm_command(
        &ActArrayCommand::Speed {
            joint: 1,
            speed: 100.0,
        },
        &now_origin(),
    );
    assert_eq!(st, Status::Clamped);
    let out = drain(&mut m);
    let info = limber_emulator::default_arm_info();
    assert_eq!(
        out[0].cmd,
        Command::ArmSpeed {
            joint: ArmJoint::from_index(1).unwrap(),
            ms_per_step: info.joints[1].speed
        }
    );
    assert!(matches!(out[1].cmd, Command::ArmPos { .. }));
}

#[test]
fn setpose_out_of_reach_sets_the_limb_state_until_a_command_is_carried_out() {
    let (mut m, _) = ready();
    let far = LimbCommand::SetPose {
        position: Vec3::new(5.0, 0.0, 0.0),
        approach: Vec3::new(1.0, 0.0, 0.0),
        orientation: Vec3::new(0.0, 0.0, 1.0),
    };
    assert_eq!(m.limb_command(&far, &now_origin()), Status::OutOfReach);
    assert!(m.outbox().is_empty());
    let mut s = LimbData::default();
    m.limb_state(&mut s, Instant::now());
    assert_eq!(s.state, LimbState::OutOfReach as u32);
    assert_eq!(
        m.limb_command(&LimbCommand::Home, &now_origin()),
        Status::Ok
    );
    m.limb_state(&mut s, Instant::now());
    assert_ne!(s.state, LimbState::OutOfReach as u32);
}

#[test]
fn the_shared_adjustment_threshold_is_the_kinematics_one() {
    assert_eq!(
        limb_outcome::ADJUSTMENT_REPORTED,
        limber_kinematics::pioneer::ADJUSTMENT_REPORTED
    );
}

#[test]
fn sips_are_taken_and_the_silence_clock_follows_the_packets() {
    let (mut m, t0) = ready();
    let later = t0 + Duration::from_millis(700);
    m.on_packet(&RobotPacket::Arm(arm_packet(true, 0, home_ticks())), later);
    assert_eq!(m.last_rx(), later);
}

#[test]
fn a_client_command_is_refused_when_the_robot_has_been_silent_too_long() {
    let (mut m, _) = ready();
    let pos = ActArrayCommand::Position {
        joint: 1,
        position: 0.2,
    };
    let bound = m.config().command_silence();
    // The last packet came longer ago than the bound: refused, nothing queued.
    let then = Instant::now() - bound - Duration::from_millis(50);
    m.on_packet(&RobotPacket::Arm(arm_packet(true, 0, home_ticks())), then);
    assert_eq!(m.arm_command(&pos, &now_origin()), Status::LinkDown);
    assert!(m.outbox().is_empty());
    // The driver's own commands (a deadman's stop) still go out.
    assert_eq!(m.limb_command(&LimbCommand::Stop, &INTERNAL), Status::Ok);
    drain(&mut m);
    // The robot speaks again: accepted.
    m.on_packet(
        &RobotPacket::Arm(arm_packet(true, 0, home_ticks())),
        Instant::now(),
    );
    assert_eq!(m.arm_command(&pos, &now_origin()), Status::Ok);
}

/// Issue "Nobody moves the arm who may not", item 9: an ARMINFOpac that cannot be a
/// calibration (no joint; a joint with 0 ticks per 90°) is not taken: the arm is not
/// calibrated (its state says so), and HOME is refused instead of answered "ok".
#[test]
fn an_arminfopac_that_cannot_be_a_calibration_is_not_taken() {
    let good = limber_emulator::default_arm_info();
    let mut zero_tp90 = good.joints;
    zero_tp90[2].ticks_per_90 = 0;
    for (what, info) in [
        ("no joint", limber_p2os::ArmInfo::new("x", &[])),
        (
            "0 ticks per 90° on joint 3",
            limber_p2os::ArmInfo::new("x", &zero_tp90),
        ),
    ] {
        let mut m = RobotModel::new(PioneerConfig::default());
        let t0 = Instant::now();
        m.link_up(t0);
        m.on_packet(&RobotPacket::ArmInfo(info), t0);
        m.on_packet(&RobotPacket::Arm(arm_packet(true, 0, home_ticks())), t0);
        assert!(!m.calibrated(), "{what}: taken as a calibration");
        assert_eq!(m.malformed(), 1, "{what}: not counted");
        assert_eq!(
            m.arm_command(&ActArrayCommand::Home(JointSel::All), &now_origin()),
            Status::NotCalibrated,
            "{what}"
        );
        assert_eq!(
            m.limb_command(&LimbCommand::Home, &now_origin()),
            Status::NotCalibrated,
            "{what}"
        );
        assert!(m.outbox().is_empty(), "{what}");
        // A good one afterwards is taken.
        m.on_packet(&RobotPacket::ArmInfo(good), t0);
        assert!(m.calibrated(), "{what}");
    }
}

#[test]
fn a_robot_without_its_body_gripper_has_gripper_and_lift_commands_refused() {
    let (mut m, _) = ready();
    assert_eq!(
        m.gripper_command(&GripperCommand::Open, &now_origin()),
        Status::Ok
    );
    assert_eq!(drain(&mut m).len(), 1);
    m.set_body_gripper(false);
    assert_eq!(
        m.gripper_command(&GripperCommand::Open, &now_origin()),
        Status::Unsupported
    );
    assert_eq!(
        m.lift_command(&ActArrayCommand::Home(JointSel::All), &now_origin()),
        Status::Unsupported
    );
    assert!(m.outbox().is_empty());
}

#[test]
fn an_armpac_in_flight_when_the_power_off_left_does_not_power_the_arm_again() {
    let (mut m, _) = ready();
    assert!(matches!(
        m.arm_request(&ActArrayRequest::Power(false), &now_origin()),
        Ok(ActArrayReply::Done)
    ));
    drain(&mut m);
    // An ARMpac the controller sent before it read the power-off.
    m.on_packet(
        &RobotPacket::Arm(arm_packet(true, 0, home_ticks())),
        Instant::now(),
    );
    assert_eq!(
        m.arm_command(
            &ActArrayCommand::Position {
                joint: 2,
                position: 0.3
            },
            &now_origin()
        ),
        Status::PoweredOff
    );
    assert!(m.outbox().is_empty());
}

/// Issue "Nobody moves the arm who may not", item 9: ARMpacs that stop arriving (lost, or
/// truncated and dropped) while SIPs keep the link up leave the arm's state stale: it is
/// not reported as reporting, and its commands are refused LINK_DOWN, never carried out
/// from a made-up position.
#[test]
fn an_arm_whose_armpacs_stop_is_stale_and_refuses_commands() {
    let (mut m, _) = ready();
    let timeout = Duration::from_millis(m.config().link_timeout_ms);
    let long_ago = Instant::now() - timeout - Duration::from_millis(500);
    m.link_up(long_ago);
    m.on_packet(
        &RobotPacket::Arm(arm_packet(true, 0, home_ticks())),
        long_ago,
    );
    // SIPs keep coming.
    m.on_packet(
        &RobotPacket::Sip(limber_p2os::Sip::default()),
        Instant::now(),
    );
    assert!(!m.arm_reporting(Instant::now()));
    let pos = ActArrayCommand::Position {
        joint: 2,
        position: 0.3,
    };
    assert_eq!(m.arm_command(&pos, &now_origin()), Status::LinkDown);
    assert_eq!(
        m.limb_command(&LimbCommand::Home, &now_origin()),
        Status::LinkDown
    );
    assert!(m.outbox().is_empty());
    m.on_packet(
        &RobotPacket::Arm(arm_packet(true, 0, home_ticks())),
        Instant::now(),
    );
    assert!(m.arm_reporting(Instant::now()));
    assert_eq!(m.arm_command(&pos, &now_origin()), Status::Ok);
}

/// Issue "Nobody moves the arm who may not", item 15: the arm's state shows a power
/// request at once; the robot's ARMpacs confirm it, or (a power-on the robot never takes)
/// correct it once the grace is over.
#[test]
fn motor_state_shows_the_power_asked_until_the_robot_corrects_it() {
    let (mut m, _) = ready();
    let motor = |m: &RobotModel| {
        let mut s = ActArrayData::default();
        m.arm_state(&mut s, Instant::now());
        s.motor_state
    };
    assert_eq!(motor(&m), 1);
    m.arm_request(&ActArrayRequest::Power(false), &now_origin())
        .unwrap();
    drain(&mut m);
    assert_eq!(motor(&m), 0, "off at once");
    m.arm_request(&ActArrayRequest::Power(true), &now_origin())
        .unwrap();
    drain(&mut m);
    assert_eq!(motor(&m), 1, "on at once");
    // The robot keeps saying "unpowered", well after the power-on: corrected.
    let later = Instant::now() + Duration::from_secs(1);
    for _ in 0..3 {
        m.on_packet(&RobotPacket::Arm(arm_packet(false, 0, home_ticks())), later);
    }
    assert_eq!(motor(&m), 0, "the robot's reports correct it");
    // Confirmed by the robot.
    m.arm_request(&ActArrayRequest::Power(true), &now_origin())
        .unwrap();
    drain(&mut m);
    m.on_packet(&RobotPacket::Arm(arm_packet(true, 0, home_ticks())), later);
    assert_eq!(motor(&m), 1);
}

#[test]
fn a_move_still_going_past_its_travel_bound_ends_timed_out() {
    let (mut m, _) = ready();
    let home = home_ticks();
    let target = m.arm().ticks[2];
    let geom_goal = {
        let mut s = ActArrayData::default();
        m.arm_state(&mut s, Instant::now());
        s.actuators[2].position - 0.3
    };
    let o = m.arm_command(
        &ActArrayCommand::position(2, geom_goal).unwrap(),
        &now_origin(),
    );
    assert_eq!(o, Status::Ok);
    drain(&mut m);
    let bound = m.travel_bound(2).expect("a bound");
    assert!(bound > Duration::from_secs(2), "{bound:?}");
    // The controller says the joint moves, but it never gets anywhere.
    let start = Instant::now();
    let mut t = start;
    while t < start + bound + Duration::from_millis(500) {
        t += Duration::from_millis(100);
        m.on_packet(&RobotPacket::Arm(arm_packet(true, 1 << 2, home)), t);
        let p = m.joint_progress(2, false, t);
        if t < start + bound {
            assert_eq!(p.end, None, "{:?} after {:?}", p, t - start);
        }
    }
    let p = m.joint_progress(2, false, t);
    assert_eq!(p.end, Some((MotionResult::TimedOut, Status::Timeout)));
    assert_eq!(m.arm().ticks[2], target);
}
