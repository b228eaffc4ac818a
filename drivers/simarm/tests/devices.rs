//! simarm end to end: the driver on a thread of the test process (its own domain per
//! test), clients through the services layer. The paper's programs run unchanged on
//! both built-in chains. Time runs 10× faster than real time; nothing asserts speed.

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use limber_examples::pick_block::{self, Devices, PickError, PickParams};
use limber_examples::random_moves::{self, RandomParams};
use limber_kinematics::chain::Chain;
use limber_services::prelude::*;
use limber_services::{Domain, RequestError, Role};
use limber_simarm::{SimArm, SimArmOptions, SimObject};

const TIMEOUT: Duration = Duration::from_secs(10);
const TIME_SCALE: f64 = 10.0;

/// The driver thread; stops and joins when dropped.
struct Driver {
    stop: Arc<AtomicBool>,
    handle: Option<JoinHandle<()>>,
}

impl Drop for Driver {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        if let Some(h) = self.handle.take() {
            let _ = h.join();
        }
    }
}

#[derive(Clone, Copy)]
enum Which {
    Arm6,
    Arm7,
}

fn chain(w: Which) -> Chain {
    match w {
        Which::Arm6 => Chain::default_6dof(),
        Which::Arm7 => Chain::default_7dof(),
    }
}

fn start(domain: &Domain, which: Which, object: Option<SimObject>) -> Driver {
    let stop = Arc::new(AtomicBool::new(false));
    let (ready_tx, ready_rx) = mpsc::channel();
    let name = domain.name().to_string();
    let flag = stop.clone();
    let handle = std::thread::spawn(move || {
        let domain = Domain::new(&name).expect("domain");
        let ctx = Context::new(&domain, Role::Driver, "simarm").expect("context");
        let options = SimArmOptions {
            time_scale: TIME_SCALE,
            object,
            ..SimArmOptions::default()
        };
        let mut arm = SimArm::new(&ctx, chain(which), options).expect("simarm starts");
        ready_tx.send(()).expect("test waits");
        let _ = arm.run(|| flag.load(Ordering::Relaxed));
    });
    ready_rx
        .recv_timeout(TIMEOUT)
        .expect("simarm ready in time");
    Driver {
        stop,
        handle: Some(handle),
    }
}

fn client(d: &Domain) -> Context {
    Context::new(d, Role::Client, "simarm-test").expect("client context")
}

/// Pick parameters that both built-in chains reach with the approach pointing down.
fn pick_params(which: Which) -> PickParams {
    let (block, drop) = match which {
        Which::Arm6 => ([0.45, 0.10], [0.45, -0.10]),
        Which::Arm7 => ([0.50, 0.10], [0.50, -0.10]),
    };
    PickParams {
        block,
        block_radius: 0.02,
        drop,
        grasp_height: 0.15,
        clearance: 0.05,
        across: None,
        motion_timeout: TIMEOUT,
    }
}

fn pick_block_runs(which: Which) {
    let d = Domain::unique_for_test();
    let p = pick_params(which);
    let object = SimObject::block([p.block[0], p.block[1], p.grasp_height], 0.04);
    let _drv = start(&d, which, Some(object));
    let ctx = client(&d);
    let mut dev = Devices::connect(&ctx, "simarm/limb/0", "simarm/gripper/0", TIMEOUT).unwrap();
    let s = pick_block::run(&mut dev, &p, &mut |_| {}).expect("pick_block completes");
    assert_eq!(s.steps, 11);
    assert!(s.block_seen, "the beam saw the block while it was held");
    let r = s.released_at;
    assert!((r[0] - p.drop[0]).abs() < 1e-4, "{r:?}");
    assert!((r[1] - p.drop[1]).abs() < 1e-4, "{r:?}");
    assert!((r[2] - p.grasp_height).abs() < 1e-4, "{r:?}");
    let l = *dev.limb.state().unwrap();
    assert_eq!(l.limb_state(), Ok(LimbState::Idle));
    assert_ne!(
        l.header.flags & limber_interfaces::common::device_flag::SIMULATED,
        0
    );
}

#[test]
fn pick_block_on_6dof() {
    pick_block_runs(Which::Arm6);
}

#[test]
fn pick_block_on_7dof() {
    pick_block_runs(Which::Arm7);
}

#[test]
fn pick_block_far_block_is_out_of_reach() {
    let d = Domain::unique_for_test();
    let _drv = start(&d, Which::Arm6, None);
    let ctx = client(&d);
    let mut dev = Devices::connect(&ctx, "simarm/limb/0", "simarm/gripper/0", TIMEOUT).unwrap();
    let p = PickParams {
        block: [2.0, 0.0],
        ..pick_params(Which::Arm6)
    };
    let e = pick_block::run(&mut dev, &p, &mut |_| {}).unwrap_err();
    assert!(matches!(e, PickError::OutOfReach { .. }), "{e:?}");
}

fn random_moves_run(which: Which) {
    let d = Domain::unique_for_test();
    let _drv = start(&d, which, None);
    let ctx = client(&d);
    let mut arm = ActArrayClient::connect_timeout(&ctx, "simarm/actarray/0", TIMEOUT).unwrap();
    let p = RandomParams {
        rounds: 2,
        round_timeout: TIMEOUT,
        ..RandomParams::default()
    };
    let q = random_moves::run(&mut arm, &p, &mut |_, _| {}).expect("random moves complete");
    let geom = arm.geometry().unwrap();
    let c = chain(which);
    assert_eq!(q.len(), c.dof() + 1);
    assert_eq!(geom.actuators().len(), c.dof() + 1);
    for (v, g) in q.iter().zip(geom.actuators()) {
        assert!(
            *v >= g.min && *v <= g.max,
            "{v} outside [{}, {}]",
            g.min,
            g.max
        );
    }
    assert!(c.within_limits(&q[..c.dof()]));
    let s = arm.state().unwrap();
    assert!(
        s.actuators()
            .iter()
            .all(|a| a.state == ActuatorFlags::IDLE.bits())
    );
}

#[test]
fn random_moves_on_6dof() {
    random_moves_run(Which::Arm6);
}

#[test]
fn random_moves_on_7dof() {
    random_moves_run(Which::Arm7);
}

/// Waits until the limb is no longer moving.
fn wait_limb_idle(limb: &mut LimbClient) -> LimbData {
    let deadline = Instant::now() + TIMEOUT;
    loop {
        let l = *limb.state().expect("limb state");
        if l.limb_state() != Ok(LimbState::Moving) {
            return l;
        }
        let left = deadline.saturating_duration_since(Instant::now());
        assert!(!left.is_zero(), "limb still moving");
        let _ = limb.wait_state(left);
    }
}

#[test]
fn out_of_reach_until_the_next_valid_command() {
    let d = Domain::unique_for_test();
    let _drv = start(&d, Which::Arm7, None);
    let ctx = client(&d);
    let mut limb = LimbClient::connect_timeout(&ctx, "simarm/limb/0", TIMEOUT).unwrap();
    let t = limb.set_position([3.0, 0.0, 0.5]).unwrap();
    assert_eq!(limb.wait_outcome(t, TIMEOUT), Ok(Status::OutOfReach));
    assert_eq!(
        limb.state().unwrap().limb_state(),
        Ok(LimbState::OutOfReach)
    );
    // Still out of reach a few ticks later.
    let _ = limb.wait_state(TIMEOUT);
    assert_eq!(
        limb.state().unwrap().limb_state(),
        Ok(LimbState::OutOfReach)
    );
    let t = limb
        .set_pose([0.5, 0.0, 0.3], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0])
        .unwrap();
    assert_eq!(limb.wait_outcome(t, TIMEOUT), Ok(Status::Ok));
    let l = wait_limb_idle(&mut limb);
    assert_eq!(l.limb_state(), Ok(LimbState::Idle));
    let p = l.position.to_array();
    assert!((p[0] - 0.5).abs() < 1e-4 && p[1].abs() < 1e-4 && (p[2] - 0.3).abs() < 1e-4);
    let a = l.approach.to_array();
    assert!((a[2] + 1.0).abs() < 1e-4, "{a:?}");
}

#[test]
fn refusals_reach_the_sender() {
    let d = Domain::unique_for_test();
    let _drv = start(&d, Which::Arm7, None);
    let ctx = client(&d);
    let mut arm = ActArrayClient::connect_timeout(&ctx, "simarm/actarray/0", TIMEOUT).unwrap();
    let mut limb = LimbClient::connect_timeout(&ctx, "simarm/limb/0", TIMEOUT).unwrap();
    let mut grip = GripperClient::connect_timeout(&ctx, "simarm/gripper/0", TIMEOUT).unwrap();
    let before = arm.wait_state(TIMEOUT).unwrap().actuators()[3].position;

    // Unknown joint: 7 joints + the gripper = actuators 0..=7.
    let t = arm.move_to(8, 0.0).unwrap();
    assert_eq!(arm.wait_outcome(t, TIMEOUT), Ok(Status::UnknownJoint));
    // Joint 4 of the Panda-like chain (index 3) lives in [-3.07, -0.07].
    let t = arm.move_to(3, 0.5).unwrap();
    assert_eq!(arm.wait_outcome(t, TIMEOUT), Ok(Status::BeyondLimits));
    // A MULTI_POS with one bad value moves nothing.
    let t = arm
        .move_to_multi(&[0.1, 0.1, 0.1, 0.5, 0.0, 1.0, 0.0])
        .unwrap();
    assert_eq!(arm.wait_outcome(t, TIMEOUT), Ok(Status::BeyondLimits));
    let t = arm.move_to_multi(&[0.0; 9]).unwrap();
    assert_eq!(arm.wait_outcome(t, TIMEOUT), Ok(Status::UnknownJoint));
    // The gripper actuator: 0 to the stroke (0.08 m).
    let t = arm.move_to(7, 0.2).unwrap();
    assert_eq!(arm.wait_outcome(t, TIMEOUT), Ok(Status::BeyondLimits));
    let t = arm.set_current(Some(8), 1.0).unwrap();
    assert_eq!(arm.wait_outcome(t, TIMEOUT), Ok(Status::UnknownJoint));
    // NaN never reaches the driver.
    assert!(arm.move_to(0, f64::NAN).is_err());
    assert!(limb.set_position([f64::NAN, 0.0, 0.0]).is_err());
    assert!(limb.vec_move([0.0, 0.0, 0.0], 0.1).is_err());
    // Requests.
    assert_eq!(
        arm.set_accel_config(8, 1.0),
        Err(RequestError::Nack(Status::UnknownJoint))
    );
    assert_eq!(
        arm.set_accel_config(0, -1.0),
        Err(RequestError::Nack(Status::InvalidArgument))
    );
    assert_eq!(
        arm.set_speed_config(9, 1.0),
        Err(RequestError::Nack(Status::UnknownJoint))
    );
    assert_eq!(
        arm.set_speed_config(0, -1.0),
        Err(RequestError::Nack(Status::InvalidArgument))
    );
    assert_eq!(
        limb.set_speed(0.0),
        Err(RequestError::Nack(Status::InvalidArgument))
    );
    assert_eq!(
        limb.set_pose([0.5, 0.0, 0.3], [0.0, 0.0, -1.0], [0.0, 0.0, 1.0])
            .map(|t| limb.wait_outcome(t, TIMEOUT)),
        Ok(Ok(Status::InvalidArgument))
    );
    let t = grip.store().unwrap();
    assert_eq!(grip.wait_outcome(t, TIMEOUT), Ok(Status::Unsupported));
    // Nothing moved.
    let s = arm.wait_state(TIMEOUT).unwrap();
    assert_eq!(s.actuators()[3].position, before);
    assert!(
        s.actuators()
            .iter()
            .all(|a| a.state == ActuatorFlags::IDLE.bits())
    );
}

#[test]
fn geometry_comes_from_the_chain() {
    let d = Domain::unique_for_test();
    let _drv = start(&d, Which::Arm6, None);
    let ctx = client(&d);
    let mut arm = ActArrayClient::connect_timeout(&ctx, "simarm/actarray/0", TIMEOUT).unwrap();
    let mut limb = LimbClient::connect_timeout(&ctx, "simarm/limb/0", TIMEOUT).unwrap();
    let c = Chain::default_6dof();
    let g = arm.geometry().unwrap();
    assert_eq!(g.actuators().len(), 7);
    for (a, j) in g.actuators().iter().zip(c.joints()) {
        assert_eq!(a.actuator_kind(), Ok(ActuatorKind::Rotary));
        assert_eq!((a.min, a.max, a.home), (j.min, j.max, j.home));
        assert_eq!(a.config_speed, j.max_speed);
        let ax = j.axis.into_inner();
        assert_eq!(a.axis.to_array(), [ax.x, ax.y, ax.z]);
    }
    let gr = &g.actuators()[6];
    assert_eq!(gr.actuator_kind(), Ok(ActuatorKind::Linear));
    assert_eq!((gr.min, gr.max), (0.0, 0.085));
    arm.set_speed_config(0, 1.0).unwrap();
    assert_eq!(arm.geometry().unwrap().actuators()[0].config_speed, 1.0);
    assert_eq!(limb.geometry().unwrap().base_pos.to_array(), [0.0; 3]);
    // Joint state starts at home.
    let s = arm.wait_state(TIMEOUT).unwrap();
    assert_eq!(s.actuators()[1].position, c.joints()[1].home);
}

#[test]
fn move_at_speed_and_stop() {
    let d = Domain::unique_for_test();
    let _drv = start(&d, Which::Arm6, None);
    let ctx = client(&d);
    let mut arm = ActArrayClient::connect_timeout(&ctx, "simarm/actarray/0", TIMEOUT).unwrap();
    let t = arm.move_at_speed(2, 0.5).unwrap();
    assert_eq!(arm.wait_outcome(t, TIMEOUT), Ok(Status::Ok));
    let s = *arm.state().unwrap();
    assert_eq!(s.actuators()[2].state, ActuatorFlags::MOVING.bits());
    let p0 = s.actuators()[2].position;
    // It moves in the positive direction.
    let deadline = Instant::now() + TIMEOUT;
    while arm.wait_state(TIMEOUT).unwrap().actuators()[2].position <= p0 + 0.01 {
        assert!(Instant::now() < deadline);
    }
    let t = arm.move_at_speed(2, 0.0).unwrap();
    assert_eq!(arm.wait_outcome(t, TIMEOUT), Ok(Status::Ok));
    let s = *arm.state().unwrap();
    assert_eq!(s.actuators()[2].state, ActuatorFlags::IDLE.bits());
    let stopped = s.actuators()[2].position;
    let s = arm.wait_state(TIMEOUT).unwrap();
    assert_eq!(s.actuators()[2].position, stopped);
    // Power off: motion refused until power is on.
    arm.power(false).unwrap();
    let t = arm.move_to(0, 0.5).unwrap();
    assert_eq!(arm.wait_outcome(t, TIMEOUT), Ok(Status::PoweredOff));
    arm.power(true).unwrap();
    let t = arm.home(None).unwrap();
    assert_eq!(arm.wait_outcome(t, TIMEOUT), Ok(Status::Ok));
}

#[test]
fn vecmove_ends_on_the_line() {
    let d = Domain::unique_for_test();
    let _drv = start(&d, Which::Arm6, None);
    let ctx = client(&d);
    let mut limb = LimbClient::connect_timeout(&ctx, "simarm/limb/0", TIMEOUT).unwrap();
    let start_p = [0.40, 0.10, 0.20];
    let t = limb
        .set_pose(start_p, [0.0, 0.0, -1.0], [1.0, 0.0, 0.0])
        .unwrap();
    assert_eq!(limb.wait_outcome(t, TIMEOUT), Ok(Status::Ok));
    let l0 = wait_limb_idle(&mut limb);
    let dir = [0.0, 0.6, 0.8];
    let t = limb.vec_move(dir, 0.15).unwrap();
    assert_eq!(limb.wait_outcome(t, TIMEOUT), Ok(Status::Ok));
    let off_line = |p: [f64; 3]| {
        let v = [p[0] - start_p[0], p[1] - start_p[1], p[2] - start_p[2]];
        let along = v[0] * dir[0] + v[1] * dir[1] + v[2] * dir[2];
        let perp = [
            v[0] - along * dir[0],
            v[1] - along * dir[1],
            v[2] - along * dir[2],
        ];
        (perp[0].hypot(perp[1]).hypot(perp[2]), along)
    };
    let deadline = Instant::now() + TIMEOUT;
    let mut worst: f64 = 0.0;
    let l = loop {
        let l = *limb.state().unwrap();
        worst = worst.max(off_line(l.position.to_array()).0);
        if l.limb_state() != Ok(LimbState::Moving) {
            break l;
        }
        assert!(Instant::now() < deadline, "still moving");
        let _ = limb.wait_state(TIMEOUT);
    };
    assert_eq!(l.limb_state(), Ok(LimbState::Idle));
    let (perp, along) = off_line(l.position.to_array());
    assert!(perp < 1e-4, "ended {perp} m off the line");
    assert!((along - 0.15).abs() < 1e-4, "travelled {along} m");
    assert!(worst < 2e-3, "left the line by {worst} m");
    // The orientation is kept.
    let (a0, a1) = (l0.approach.to_array(), l.approach.to_array());
    assert!((0..3).all(|i| (a0[i] - a1[i]).abs() < 1e-4));
    // A line leaving the workspace is refused before anything moves.
    let t = limb.vec_move([1.0, 0.0, 0.0], 1.5).unwrap();
    assert_eq!(limb.wait_outcome(t, TIMEOUT), Ok(Status::OutOfReach));
    assert_eq!(
        limb.state().unwrap().limb_state(),
        Ok(LimbState::OutOfReach)
    );
    assert!(off_line(limb.state().unwrap().position.to_array()).0 < 1e-4);
}

#[test]
fn gripper_closes_on_the_object_and_opens() {
    let d = Domain::unique_for_test();
    let c = Chain::default_7dof();
    let home = c.fk(&c.home()).unwrap().position;
    let _drv = start(
        &d,
        Which::Arm7,
        Some(SimObject::block([home.x, home.y, home.z], 0.03)),
    );
    let ctx = client(&d);
    let mut grip = GripperClient::connect_timeout(&ctx, "simarm/gripper/0", TIMEOUT).unwrap();
    let mut arm = ActArrayClient::connect_timeout(&ctx, "simarm/actarray/0", TIMEOUT).unwrap();
    let g = grip.wait_state(TIMEOUT).unwrap();
    assert_eq!(g.gripper_state(), Ok(GripperState::Open));
    assert_eq!(g.beams & 1, 1, "the object is between the fingers");
    let t = grip.close().unwrap();
    assert_eq!(grip.wait_outcome(t, TIMEOUT), Ok(Status::Ok));
    let deadline = Instant::now() + TIMEOUT;
    while grip.state().unwrap().gripper_state() != Ok(GripperState::Closed) {
        assert!(Instant::now() < deadline);
        let _ = grip.wait_state(TIMEOUT);
    }
    let s = arm.wait_state(TIMEOUT).unwrap();
    let finger = s.actuators()[7];
    assert!((finger.position - 0.03).abs() < 1e-9, "{}", finger.position);
    assert_eq!(finger.state, ActuatorFlags::STALLED.bits());
    let t = grip.open().unwrap();
    assert_eq!(grip.wait_outcome(t, TIMEOUT), Ok(Status::Ok));
    while grip.state().unwrap().gripper_state() != Ok(GripperState::Open) {
        assert!(Instant::now() < deadline);
        let _ = grip.wait_state(TIMEOUT);
    }
    let geom = grip.geometry().unwrap();
    assert_eq!(geom.num_beams, 1);
}
