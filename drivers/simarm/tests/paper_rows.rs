//! The rows of the paper's Tables 1, 2 and 4 that simarm once answered "unsupported",
//! on the model without transport: BRAKES (actarray and limb), ACCEL, CURRENT and
//! MULTI_CURRENT (the motor model), gripper STORE and RETRIEVE.

use limber_interfaces::prelude::*;
use limber_kinematics::chain::Chain;
use limber_simarm::{ArmModel, MotorModel, OptionsError, SimArmOptions, SimObject};

fn model_with(o: SimArmOptions) -> ArmModel {
    ArmModel::new(Chain::default_6dof(), o).unwrap()
}

fn arm(m: &ArmModel) -> ActArrayData {
    let mut s = ActArrayData::default();
    m.arm_state(&mut s);
    s
}

fn limb(m: &ArmModel) -> LimbData {
    let mut s = LimbData::default();
    m.limb_state(&mut s);
    s
}

fn gripper(m: &ArmModel) -> GripperData {
    let mut s = GripperData::default();
    m.gripper_state(&mut s);
    s
}

fn run_for(m: &mut ArmModel, seconds: f64) {
    let steps = (seconds / 0.001).round() as usize;
    for _ in 0..steps {
        m.advance(0.001);
    }
}

#[test]
fn brakes_hold_the_joints_and_refuse_motion_until_released() {
    let mut m = model_with(SimArmOptions::default());
    let g = m.arm_geometry();
    let n = m.gripper_actuator();
    assert!(g.actuators()[..n].iter().all(|a| a.has_brakes == 1));
    assert_eq!(g.actuators()[n].has_brakes, 0, "the gripper has none");
    // A move in progress stops when the brakes go on.
    assert_eq!(
        m.arm_command(&ActArrayCommand::position(0, 1.0).unwrap()),
        Status::Ok
    );
    run_for(&mut m, 0.05);
    assert_eq!(
        m.arm_request(&ActArrayRequest::Brakes(true)),
        Ok(ActArrayReply::Done)
    );
    let held = m.q()[0];
    assert!(held > 0.0 && held < 1.0);
    run_for(&mut m, 0.5);
    assert_eq!(m.q()[0], held);
    let s = arm(&m);
    for a in &s.actuators()[..n] {
        assert_eq!(a.state, ActuatorFlags::BRAKED.bits());
    }
    assert_eq!(s.actuators()[n].state, ActuatorFlags::IDLE.bits());
    assert_eq!(limb(&m).state, LimbState::Braked as u32);
    // Every motion of a chain joint is refused with the reason; the gripper still moves.
    for cmd in [
        ActArrayCommand::position(1, -1.0).unwrap(),
        ActArrayCommand::multi_position(&[0.0, -1.0]).unwrap(),
        ActArrayCommand::speed(2, 0.5).unwrap(),
        ActArrayCommand::home(-1).unwrap(),
        ActArrayCommand::current(0, 1.0).unwrap(),
        ActArrayCommand::multi_current(&[0.5]).unwrap(),
    ] {
        assert_eq!(m.arm_command(&cmd), Status::Braked, "{cmd:?}");
    }
    assert_eq!(Status::Braked.describe(), "brakes on");
    assert_eq!(m.limb_command(&LimbCommand::Home), Status::Braked);
    assert_eq!(
        m.limb_command(&LimbCommand::vec_move(Vec3::new(0.0, 0.0, 1.0), 0.05).unwrap()),
        Status::Braked
    );
    assert_eq!(
        m.limb_command(&LimbCommand::Stop),
        Status::Ok,
        "stopping is not"
    );
    assert_eq!(
        m.arm_command(&ActArrayCommand::speed(1, 0.0).unwrap()),
        Status::Ok
    );
    assert_eq!(
        m.arm_command(&ActArrayCommand::position(n as i64, 0.02).unwrap()),
        Status::Ok
    );
    run_for(&mut m, 0.1);
    assert_eq!(m.q()[0], held);
    // The limb's BRAKES is the same brakes: off there releases them here.
    assert_eq!(
        m.limb_request(&LimbRequest::Brakes(false)),
        Ok(LimbReply::Done)
    );
    assert!(!m.braked());
    assert_eq!(limb(&m).state, LimbState::Idle as u32);
    assert_eq!(
        m.arm_command(&ActArrayCommand::position(0, 0.0).unwrap()),
        Status::Ok
    );
    assert_eq!(
        m.limb_request(&LimbRequest::Brakes(true)),
        Ok(LimbReply::Done)
    );
    assert_eq!(arm(&m).actuators()[0].state, ActuatorFlags::BRAKED.bits());
    // A chain without brakes: unsupported, as the Pioneer says.
    let mut m = model_with(SimArmOptions {
        brakes: false,
        ..Default::default()
    });
    assert_eq!(
        m.arm_request(&ActArrayRequest::Brakes(true)),
        Err(Status::Unsupported)
    );
    assert_eq!(m.arm_geometry().actuators()[0].has_brakes, 0);
}

#[test]
fn accel_ramps_the_speed_up_and_down() {
    let mut m = model_with(SimArmOptions::default());
    // Joint 0: 1 rad at 1 rad/s with 2 rad/s² takes 0.5 s to reach the speed.
    assert_eq!(
        m.arm_request(&ActArrayRequest::speed(0, 1.0).unwrap()),
        Ok(ActArrayReply::Done)
    );
    assert_eq!(
        m.arm_request(&ActArrayRequest::accel(0, 2.0).unwrap()),
        Ok(ActArrayReply::Done)
    );
    assert_eq!(
        arm(&m).actuators()[1].acceleration,
        -1.0,
        "unknown without a limit"
    );
    assert_eq!(
        m.arm_command(&ActArrayCommand::position(0, 1.0).unwrap()),
        Status::Ok
    );
    run_for(&mut m, 0.25);
    // s = a t² / 2, v = a t: 0.0625 rad at 0.5 rad/s.
    let s = arm(&m);
    let a = &s.actuators()[0];
    assert!((a.position - 0.0625).abs() < 2e-3, "{}", a.position);
    assert!((a.speed - 0.5).abs() < 2e-3, "{}", a.speed);
    assert!((a.acceleration - 2.0).abs() < 1e-6, "{}", a.acceleration);
    assert_eq!(a.state, ActuatorFlags::MOVING.bits());
    // Cruising at the speed, no acceleration.
    run_for(&mut m, 0.5);
    let a = arm(&m).actuators()[0];
    assert!(
        (a.speed - 1.0).abs() < 1e-9 && a.acceleration < 1e-9,
        "{a:?}"
    );
    // Still on its way when a constant-speed move would have arrived (1 s), there
    // after 1.5 s: 0.5 s up, 0.5 s at speed, 0.5 s down.
    run_for(&mut m, 0.27);
    let a = arm(&m).actuators()[0];
    assert!(a.position < 1.0 && a.speed < 1.0, "braking: {a:?}");
    run_for(&mut m, 0.5);
    let a = arm(&m).actuators()[0];
    assert_eq!(a.position, 1.0);
    assert_eq!(a.state, ActuatorFlags::IDLE.bits());
    // Refusals.
    assert_eq!(
        m.arm_request(&ActArrayRequest::accel(0, 0.0).unwrap()),
        Err(Status::InvalidArgument)
    );
    assert_eq!(
        m.arm_request(&ActArrayRequest::accel(7, 1.0).unwrap()),
        Err(Status::UnknownJoint)
    );
}

#[test]
fn a_current_moves_a_joint_against_gravity_and_stalls_when_it_cannot() {
    let motor = MotorModel::default();
    // Joint 0 turns about the vertical: no gravity, speed = k I / damping.
    let mut m = model_with(SimArmOptions::default());
    assert_eq!(
        m.arm_command(&ActArrayCommand::current(0, 0.5).unwrap()),
        Status::Ok
    );
    run_for(&mut m, 0.1);
    let a = arm(&m).actuators()[0];
    let v = motor.torque_constant * 0.5 / motor.damping;
    assert!((a.speed - v).abs() < 1e-9, "{}", a.speed);
    assert!((a.position - v * 0.1).abs() < 1e-6);
    assert_eq!(a.current, 0.5, "the model's current");
    assert_eq!(a.state, ActuatorFlags::MOVING.bits());
    // Beyond the largest current: driven at the largest, CLAMPED.
    assert_eq!(
        m.arm_command(&ActArrayCommand::current(0, 99.0).unwrap()),
        Status::Clamped
    );
    assert_eq!(arm(&m).actuators()[0].current, motor.max_current);

    // Joint 1 (shoulder lift) leaning 0.8 rad from upright holds the load against
    // gravity: the state says with which current.
    let leaning = |m: &mut ArmModel| {
        let q = m.q()[1] + 0.8;
        assert_eq!(
            m.arm_command(&ActArrayCommand::position(1, q).unwrap()),
            Status::Ok
        );
        run_for(m, 1.0);
        q
    };
    let mut m = model_with(SimArmOptions::default());
    let start = leaning(&mut m);
    let hold = arm(&m).actuators()[1].current;
    assert!(hold > 0.1, "{hold}");
    // No current: gravity pulls it down one way.
    assert_eq!(
        m.arm_command(&ActArrayCommand::current(1, 0.0).unwrap()),
        Status::Ok
    );
    run_for(&mut m, 0.01);
    let sag = (m.q()[1] - start).signum();
    assert!(sag != 0.0);
    // Exactly the holding current against it: it neither rises nor falls, pushed and
    // still: STALLED.
    let mut m = model_with(SimArmOptions::default());
    leaning(&mut m);
    assert_eq!(
        m.arm_command(&ActArrayCommand::current(1, -sag * hold).unwrap()),
        Status::Ok
    );
    run_for(&mut m, 0.1);
    assert!((m.q()[1] - start).abs() < 1e-9);
    assert_eq!(arm(&m).actuators()[1].state, ActuatorFlags::STALLED.bits());
    // Half as much again lifts it against gravity.
    assert_eq!(
        m.arm_command(&ActArrayCommand::current(1, -sag * 1.5 * hold).unwrap()),
        Status::Ok
    );
    run_for(&mut m, 0.05);
    assert!((m.q()[1] - start) * sag < 0.0, "lifted");
    assert_eq!(arm(&m).actuators()[1].state, ActuatorFlags::MOVING.bits());
    // A position command ends the current mode.
    assert_eq!(
        m.arm_command(&ActArrayCommand::position(1, start).unwrap()),
        Status::Ok
    );
    run_for(&mut m, 1.0);
    assert_eq!(m.q()[1], start);
    assert_eq!(arm(&m).actuators()[1].state, ActuatorFlags::IDLE.bits());
}

#[test]
fn a_current_stalls_at_a_limit_and_on_the_object_between_the_fingers() {
    let n = 6;
    // MULTI_CURRENT opening the already open gripper: at its limit, STALLED.
    let mut m = model_with(SimArmOptions::default());
    let mut currents = [0.0; 7];
    currents[n] = 1.0;
    // The joints are driven too (0 A: joint 0 has no gravity and stays).
    assert_eq!(
        m.arm_command(&ActArrayCommand::multi_current(&currents).unwrap()),
        Status::Ok
    );
    run_for(&mut m, 0.05);
    let s = arm(&m);
    assert_eq!(s.actuators()[n].state, ActuatorFlags::STALLED.bits());
    assert_eq!(s.actuators()[n].current, 1.0);
    assert_eq!(s.actuators()[0].state, ActuatorFlags::IDLE.bits());

    // Closing with a current on an object between the fingers: stops at its width.
    let m = model_with(SimArmOptions::default());
    let p = m.tool_pose().position;
    let width = 0.03;
    let mut m = model_with(SimArmOptions {
        object: Some(SimObject::block([p.x, p.y, p.z], width)),
        ..Default::default()
    });
    assert_eq!(
        m.arm_command(&ActArrayCommand::current(n as i64, -2.0).unwrap()),
        Status::Ok
    );
    run_for(&mut m, 2.0);
    let a = arm(&m).actuators()[n];
    assert!((a.position - width).abs() < 1e-9, "{}", a.position);
    assert_eq!(a.state, ActuatorFlags::STALLED.bits());
    assert!(m.holding());
    // Power off ends the current mode: IDLE.
    assert_eq!(
        m.arm_request(&ActArrayRequest::Power(false)),
        Ok(ActArrayReply::Done)
    );
    assert_eq!(
        m.arm_command(&ActArrayCommand::current(0, 1.0).unwrap()),
        Status::PoweredOff
    );
}

#[test]
fn store_swallows_the_held_object_and_retrieve_gives_it_back() {
    let p = model_with(SimArmOptions::default()).tool_pose().position;
    let width = 0.03;
    let mut m = model_with(SimArmOptions {
        object: Some(SimObject::block([p.x, p.y, p.z], width)),
        store_capacity: 1,
        ..Default::default()
    });
    assert_eq!(
        m.gripper_request(&GripperRequest::GetGeom)
            .map(|r| match r {
                GripperReply::Geom(g) => g.capacity,
            }),
        Ok(1)
    );
    assert_eq!(
        m.gripper_command(&GripperCommand::Retrieve),
        Status::NothingStored
    );
    // Grip it, store it: it leaves the world and the count rises.
    assert_eq!(m.gripper_command(&GripperCommand::Close), Status::Ok);
    run_for(&mut m, 1.0);
    assert!(m.holding());
    assert_eq!(m.gripper_command(&GripperCommand::Store), Status::Ok);
    assert_eq!(m.object(), None);
    assert!(!m.holding());
    let g = gripper(&m);
    assert_eq!((g.stored, g.beams), (1, 0));
    // Full now, and nothing between the fingers anyway: full is the reason.
    assert_eq!(m.gripper_command(&GripperCommand::Store), Status::StoreFull);
    // Elsewhere, RETRIEVE puts it back between the fingers, held.
    assert_eq!(
        m.arm_command(&ActArrayCommand::position(2, 0.5).unwrap()),
        Status::Ok
    );
    run_for(&mut m, 1.0);
    assert_eq!(m.gripper_command(&GripperCommand::Retrieve), Status::Ok);
    let o = m.object().unwrap();
    let t = m.tool_pose().position;
    assert_eq!(o.position, [t.x, t.y, t.z]);
    assert!((t - p).norm() > 0.1, "moved elsewhere");
    assert!(m.holding());
    let g = gripper(&m);
    assert_eq!(g.stored, 0);
    assert_eq!(g.beams, 1);
    assert_eq!(g.state, GripperState::Closed as u32);
    assert_eq!(m.gripper_opening(), width);
    // Open: it is let go (here, in the air), nothing to store any more.
    assert_eq!(m.gripper_command(&GripperCommand::Open), Status::Ok);
    run_for(&mut m, 1.0);
    assert_eq!(
        m.arm_command(&ActArrayCommand::position(2, 0.0).unwrap()),
        Status::Ok
    );
    run_for(&mut m, 1.0);
    assert!(!m.holding());
    assert_eq!(
        m.gripper_command(&GripperCommand::Store),
        Status::NothingToStore
    );
    // Without a store (the default): both unsupported, as on the Pioneer.
    let mut m = model_with(SimArmOptions::default());
    assert_eq!(
        m.gripper_command(&GripperCommand::Retrieve),
        Status::Unsupported
    );
    assert_eq!(
        ArmModel::new(
            Chain::default_6dof(),
            SimArmOptions {
                store_capacity: 5000,
                ..Default::default()
            }
        )
        .unwrap_err(),
        OptionsError::StoreCapacity
    );
}
