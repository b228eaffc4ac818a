//! The simulation without transport: timing, coordination, refusals, VECMOVE, gripper.

use limber_interfaces::prelude::*;
use limber_kinematics::chain::Chain;
use limber_simarm::{ArmModel, OptionsError, SimArmOptions, SimObject};
use nalgebra::Vector3;

fn model(chain: Chain) -> ArmModel {
    ArmModel::new(chain, SimArmOptions::default()).unwrap()
}

fn moving(m: &ArmModel) -> bool {
    let mut s = ActArrayData::default();
    m.arm_state(&mut s);
    s.actuators()
        .iter()
        .any(|a| a.state == ActuatorFlags::MOVING.bits())
        || m.limb_moving()
}

fn run_until_idle(m: &mut ArmModel) {
    for _ in 0..100_000 {
        if !moving(m) {
            return;
        }
        m.advance(0.01);
    }
    panic!("still moving");
}

#[test]
fn options_are_validated() {
    let bad = |o: SimArmOptions| ArmModel::new(Chain::default_6dof(), o).unwrap_err();
    assert_eq!(
        bad(SimArmOptions {
            time_scale: 0.0,
            ..Default::default()
        }),
        OptionsError::TimeScale
    );
    assert_eq!(
        bad(SimArmOptions {
            tick: std::time::Duration::ZERO,
            ..Default::default()
        }),
        OptionsError::Tick
    );
    assert_eq!(
        bad(SimArmOptions {
            object: Some(SimObject::block([f64::NAN, 0.0, 0.0], 0.04)),
            ..Default::default()
        }),
        OptionsError::Object
    );
}

#[test]
fn joints_move_at_their_speed_in_simulated_time() {
    let mut m = ArmModel::new(
        Chain::default_6dof(),
        SimArmOptions {
            time_scale: 2.0,
            ..Default::default()
        },
    )
    .unwrap();
    let q0 = m.q()[0];
    assert_eq!(
        m.arm_command(&ActArrayCommand::position(0, q0 + 1.0).unwrap()),
        Status::Ok
    );
    m.advance(0.05); // 0.1 s simulated
    let v = m.chain().joints()[0].max_speed;
    assert!((m.q()[0] - (q0 + 0.1 * v)).abs() < 1e-9);
    let mut s = ActArrayData::default();
    m.arm_state(&mut s);
    assert_eq!(s.actuators()[0].state, ActuatorFlags::MOVING.bits());
    assert!((s.actuators()[0].speed - v).abs() < 1e-9);
    run_until_idle(&mut m);
    assert!((m.q()[0] - (q0 + 1.0)).abs() < 1e-12);
    assert!((m.time() - 1.0 / v).abs() < 0.03);
}

#[test]
fn refusals_and_out_of_reach() {
    let mut m = model(Chain::default_7dof());
    let n = m.actuators() as i64;
    assert_eq!(n, 8);
    assert_eq!(
        m.arm_command(&ActArrayCommand::position(n, 0.0).unwrap()),
        Status::UnknownJoint
    );
    assert_eq!(
        m.arm_command(&ActArrayCommand::position(3, 0.5).unwrap()),
        Status::BeyondLimits
    );
    assert_eq!(
        m.arm_command(&ActArrayCommand::current(9, 1.0).unwrap()),
        Status::UnknownJoint
    );
    assert_eq!(
        m.arm_command(&ActArrayCommand::home(9).unwrap()),
        Status::UnknownJoint
    );
    assert!(!moving(&m));
    assert_eq!(
        m.limb_command(&LimbCommand::set_position(Vec3::new(5.0, 0.0, 0.0)).unwrap()),
        Status::OutOfReach
    );
    let mut s = LimbData::default();
    m.limb_state(&mut s);
    assert_eq!(s.state, LimbState::OutOfReach as u32);
    // Another kind of refusal does not clear it; a valid command does.
    assert_eq!(
        m.limb_command(&LimbCommand::vec_move(Vec3::new(0.0, 0.0, 1.0), -1.0).unwrap()),
        Status::InvalidArgument
    );
    m.limb_state(&mut s);
    assert_eq!(s.state, LimbState::OutOfReach as u32);
    assert_eq!(m.limb_command(&LimbCommand::Home), Status::Ok);
    m.limb_state(&mut s);
    assert_ne!(s.state, LimbState::OutOfReach as u32);
}

#[test]
fn limb_moves_are_synchronised() {
    let mut m = model(Chain::default_6dof());
    let st = m.limb_command(
        &LimbCommand::set_pose(
            Vec3::new(0.4, 0.1, 0.3),
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, 0.0),
        )
        .unwrap(),
    );
    assert_eq!(st, Status::Ok);
    let dof = m.chain().dof();
    let mut finished = vec![None; dof];
    let mut s = ActArrayData::default();
    for k in 0..100_000 {
        m.advance(0.001);
        m.arm_state(&mut s);
        for (i, f) in finished.iter_mut().enumerate() {
            if f.is_none() && s.actuators()[i].state != ActuatorFlags::MOVING.bits() {
                *f = Some(k);
            }
        }
        if !m.limb_moving() {
            break;
        }
    }
    let ks: Vec<usize> = finished.iter().flatten().copied().collect();
    assert_eq!(ks.len(), dof);
    assert!(
        ks.iter().max().unwrap() - ks.iter().min().unwrap() <= 1,
        "{ks:?}"
    );
    let p = m.tool_pose().position;
    assert!((p - Vector3::new(0.4, 0.1, 0.3)).norm() < 1e-5);
}

#[test]
fn vecmove_follows_the_line_and_honours_the_limb_speed() {
    let mut m = model(Chain::default_7dof());
    let st = m.limb_command(
        &LimbCommand::set_pose(
            Vec3::new(0.5, 0.0, 0.3),
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, 0.0),
        )
        .unwrap(),
    );
    assert_eq!(st, Status::Ok);
    run_until_idle(&mut m);
    assert!(m.limb_request(&LimbRequest::Speed(0.1)).is_ok());
    let t0 = m.time();
    let st = m.limb_command(&LimbCommand::vec_move(Vec3::new(0.0, 1.0, 0.0), 0.1).unwrap());
    assert_eq!(st, Status::Ok);
    let mut worst = 0.0_f64;
    while m.limb_moving() {
        m.advance(0.002);
        let p = m.tool_pose().position;
        worst = worst.max((p.x - 0.5).hypot(p.z - 0.3));
    }
    let p = m.tool_pose().position;
    assert!((p - Vector3::new(0.5, 0.1, 0.3)).norm() < 1e-5, "{p:?}");
    assert!(worst < 2e-3, "left the line by {worst}");
    // 0.1 m at 0.1 m/s: at least a second of simulated time.
    assert!(m.time() - t0 >= 1.0 - 1e-6);
}

#[test]
fn gripper_closes_on_the_object_and_carries_it() {
    let p = Vector3::new(0.45, 0.1, 0.15);
    let mut m = ArmModel::new(
        Chain::default_6dof(),
        SimArmOptions {
            object: Some(SimObject::block([p.x, p.y, p.z], 0.04)),
            ..SimArmOptions::default()
        },
    )
    .unwrap();
    assert!(!m.object_between_fingers());
    let st = m.limb_command(
        &LimbCommand::set_pose(
            Vec3::new(p.x, p.y, p.z),
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, 0.0),
        )
        .unwrap(),
    );
    assert_eq!(st, Status::Ok);
    run_until_idle(&mut m);
    assert!(m.object_between_fingers());
    assert_eq!(m.gripper_command(&GripperCommand::Close), Status::Ok);
    let mut g = GripperData::default();
    m.gripper_state(&mut g);
    assert_eq!(g.state, GripperState::Moving as u32);
    run_until_idle(&mut m);
    assert!(m.holding());
    assert!((m.gripper_opening() - 0.04).abs() < 1e-9);
    m.gripper_state(&mut g);
    assert_eq!(g.state, GripperState::Closed as u32);
    assert_eq!(g.beams, 1);
    // Carried along a line.
    assert_eq!(
        m.limb_command(&LimbCommand::vec_move(Vec3::new(0.0, 0.0, 1.0), 0.05).unwrap()),
        Status::Ok
    );
    run_until_idle(&mut m);
    let o = m.object().unwrap().position;
    assert!((o[2] - (p.z + 0.05)).abs() < 1e-5);
    assert_eq!(m.gripper_command(&GripperCommand::Open), Status::Ok);
    run_until_idle(&mut m);
    assert!(!m.holding());
    m.gripper_state(&mut g);
    assert_eq!(g.state, GripperState::Open as u32);
    assert_eq!(
        m.gripper_command(&GripperCommand::Store),
        Status::Unsupported
    );
}

#[test]
fn a_refused_line_leaves_the_running_one_alone() {
    let mut m = model(Chain::default_6dof());
    let st = m.limb_command(
        &LimbCommand::set_pose(
            Vec3::new(0.4, 0.0, 0.2),
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, 0.0),
        )
        .unwrap(),
    );
    assert_eq!(st, Status::Ok);
    run_until_idle(&mut m);
    let st = m.limb_command(&LimbCommand::vec_move(Vec3::new(0.0, 1.0, 0.0), 0.1).unwrap());
    assert_eq!(st, Status::Ok);
    m.advance(0.02);
    assert!(m.limb_moving());
    let st = m.limb_command(&LimbCommand::vec_move(Vec3::new(1.0, 0.0, 0.0), 2.0).unwrap());
    assert_eq!(st, Status::OutOfReach);
    run_until_idle(&mut m);
    let p = m.tool_pose().position;
    assert!((p - Vector3::new(0.4, 0.1, 0.2)).norm() < 1e-5, "{p:?}");
    // Limb STOP stops a line at once.
    let st = m.limb_command(&LimbCommand::vec_move(Vec3::new(0.0, -1.0, 0.0), 0.1).unwrap());
    assert_eq!(st, Status::Ok);
    m.advance(0.02);
    assert_eq!(m.limb_command(&LimbCommand::Stop), Status::Ok);
    assert!(!moving(&m));
    let mut s = LimbData::default();
    m.limb_state(&mut s);
    assert_eq!(s.state, LimbState::Idle as u32);
}

/// Issue 12, items 7 to 10 on the simulated arm: the same refusals, with the same causes,
/// as the Pioneer's.
#[test]
fn refusals_name_their_cause_like_the_pioneer() {
    let mut m = model(Chain::default_6dof());
    // Item 7: an unpowered arm refuses motion (POWERED_OFF); stopping is fine.
    assert!(m.arm_request(&ActArrayRequest::Power(false)).is_ok());
    let refused = [
        m.arm_command(&ActArrayCommand::position(0, 0.1).unwrap()),
        m.arm_command(&ActArrayCommand::speed(0, 0.1).unwrap()),
        m.arm_command(&ActArrayCommand::multi_speed(&[0.0, 0.1]).unwrap()),
        m.arm_command(&ActArrayCommand::home(-1).unwrap()),
        m.limb_command(&LimbCommand::Home),
        m.limb_command(&LimbCommand::vec_move(Vec3::new(1.0, 0.0, 0.0), 0.01).unwrap()),
    ];
    assert!(
        refused.iter().all(|s| *s == Status::PoweredOff),
        "{refused:?}"
    );
    assert_eq!(
        m.arm_command(&ActArrayCommand::speed(0, 0.0).unwrap()),
        Status::Ok
    );
    assert_eq!(m.limb_command(&LimbCommand::Stop), Status::Ok);
    assert!(!moving(&m));
    assert!(m.arm_request(&ActArrayRequest::Power(true)).is_ok());

    // Item 9: beyond the joint's maximum speed: clamped, and said so.
    let max = m.chain().joints()[2].max_speed;
    assert_eq!(
        m.arm_command(&ActArrayCommand::speed(2, 1e308).unwrap()),
        Status::Clamped
    );
    m.advance(0.01);
    let mut s = ActArrayData::default();
    m.arm_state(&mut s);
    assert!(
        (s.actuators()[2].speed - max).abs() < 1e-9,
        "{}",
        s.actuators()[2].speed
    );
    assert_eq!(
        m.arm_command(&ActArrayCommand::speed(2, -max / 2.0).unwrap()),
        Status::Ok
    );
    assert_eq!(
        m.arm_command(&ActArrayCommand::multi_speed(&[0.0, 0.0, -1e9]).unwrap()),
        Status::Clamped
    );
    assert_eq!(
        m.arm_command(&ActArrayCommand::speed(2, 0.0).unwrap()),
        Status::Ok
    );

    // Item 8: a direction whose norm overflows still is one; it moves like (1, 1, 0).
    let st = m.limb_command(
        &LimbCommand::set_pose(
            Vec3::new(0.4, 0.1, 0.3),
            Vec3::new(0.0, 0.0, -1.0),
            Vec3::new(1.0, 0.0, 0.0),
        )
        .unwrap(),
    );
    assert_eq!(st, Status::Ok);
    run_until_idle(&mut m);
    let p0 = m.tool_pose().position;
    assert_eq!(
        m.limb_command(&LimbCommand::vec_move(Vec3::new(1e308, 1e308, 0.0), 0.02).unwrap()),
        Status::Ok
    );
    run_until_idle(&mut m);
    let d = m.tool_pose().position - p0;
    assert!((d.norm() - 0.02).abs() < 1e-3, "{d:?}");
    assert!((d.x - d.y).abs() < 1e-3 && d.z.abs() < 1e-3, "{d:?}");

    // Item 10: parallel approach and orientation are an invalid argument, reachable or
    // not; beyond the reach is OUT_OF_REACH.
    for p in [Vec3::new(0.4, 0.1, 0.3), Vec3::new(5.0, 0.0, 0.0)] {
        let parallel =
            LimbCommand::set_pose(p, Vec3::new(1.0, 0.0, 0.0), Vec3::new(2.0, 0.0, 0.0)).unwrap();
        assert_eq!(m.limb_command(&parallel), Status::InvalidArgument);
    }
    let far = LimbCommand::set_pose(
        Vec3::new(5.0, 0.0, 0.0),
        Vec3::new(0.0, 0.0, -1.0),
        Vec3::new(1.0, 0.0, 0.0),
    )
    .unwrap();
    assert_eq!(m.limb_command(&far), Status::OutOfReach);
}

/// Issue 13 item 6 on a 5-joint chain (the Pioneer arm, relative to its base): the
/// numeric IK follows the closed form's rules. Position and approach met, the
/// orientation the nearest one the joints can hold, the adjustment in the outcome and
/// the state; REACH answers without moving.
#[test]
fn a_five_joint_chain_adjusts_the_orientation_and_says_so() {
    let mut m = model(Chain::pioneer5());
    // The README's pose (0.38, 0.1, 0.22) in the robot frame, relative to the arm base.
    let p = Vec3::new(0.38 - 0.105, 0.1, 0.22 - 0.3185);
    let down = Vec3::new(0.0, 0.0, -1.0);
    let pose = |o: Vec3| LimbCommand::set_pose(p, down, o).unwrap();
    let started = std::time::Instant::now();
    let st = m.limb_command(&pose(Vec3::new(0.94, 0.34, 0.0)));
    eprintln!("5-joint SETPOSE, adjusted: {:?}", started.elapsed());
    assert_eq!(st, Status::Adjusted);
    run_until_idle(&mut m);
    let mut s = LimbData::default();
    m.limb_state(&mut s);
    assert!(
        s.orientation_adjustment > 1e-3 && s.orientation_adjustment < 3e-3,
        "{s:?}"
    );
    let tool = m.tool_pose();
    assert!((tool.position - Vector3::new(p.x, p.y, p.z)).norm() < 1e-6);
    assert!((tool.approach() - Vector3::new(0.0, 0.0, -1.0)).norm() < 1e-6);
    // Four decimals: adjusted, by less; six: as asked.
    assert_eq!(
        m.limb_command(&pose(Vec3::new(0.9398, 0.3417, 0.0))),
        Status::Adjusted
    );
    run_until_idle(&mut m);
    let started = std::time::Instant::now();
    let st = m.limb_command(&pose(Vec3::new(0.939793, 0.341743, 0.0)));
    eprintln!("5-joint SETPOSE, exact: {:?}", started.elapsed());
    assert_eq!(st, Status::Ok);
    m.limb_state(&mut s);
    assert_eq!(s.orientation_adjustment, 0.0);
    run_until_idle(&mut m);
    // REACH: where it would end; nothing moves.
    let q = m.q();
    let reach = |m: &mut ArmModel, p: Vec3| {
        m.limb_request(&LimbRequest::reach(p, down, Vec3::new(0.94, 0.34, 0.0)).unwrap())
    };
    let Ok(LimbReply::Reach(r)) = reach(&mut m, p) else {
        panic!("no reach reply");
    };
    assert_eq!(r.adjusted, 1);
    assert!(r.position_error < 1e-6 && r.approach_error < 1e-6, "{r:?}");
    assert!(!moving(&m));
    assert_eq!(m.q(), q);
    // Beyond the reach, and beyond the joint limits (the elbow folded about 130°).
    assert_eq!(
        reach(&mut m, Vec3::new(2.0, 0.0, 0.0)),
        Err(Status::OutOfReach)
    );
    let folded = LimbCommand::set_pose(
        Vec3::new(0.3 - 0.105, 0.0, 0.2 - 0.3185),
        down,
        Vec3::new(1.0, 0.0, 0.0),
    )
    .unwrap();
    let st = m.limb_command(&folded);
    assert!(
        matches!(st, Status::BeyondLimits | Status::OutOfReach),
        "{st:?}"
    );
}

/// The 6-joint arm holds the README's and the `--help` poses exactly.
#[test]
fn the_six_joint_arm_holds_the_documented_poses() {
    let mut m = model(Chain::default_6dof());
    let down = Vec3::new(0.0, 0.0, -1.0);
    for (p, o) in [
        (Vec3::new(0.38, 0.1, 0.22), Vec3::new(0.94, 0.34, 0.0)),
        (Vec3::new(0.4, 0.0, 0.2), Vec3::new(1.0, 0.0, 0.0)),
    ] {
        assert_eq!(
            m.limb_command(&LimbCommand::set_pose(p, down, o).unwrap()),
            Status::Ok
        );
        run_until_idle(&mut m);
    }
}
