//! Joint trajectories on simarm (issue 28): reached within the goal tolerance, pushed off
//! the path by an obstacle (path tolerance violated, holding), stopped by a STOP (holding),
//! replaced mid-way (the rule: the new one from its start time), paused by a speed scaling
//! of 0 and resumed by 1, and invalid goals refused with their cause. The driver runs on a
//! thread of the test process, in its own domain per test; nothing asserts speed.

use limber_interfaces::actarray::{JointTrajectory, cmd, traj_field};
use limber_services::prelude::*;
use limber_services::{Domain, Role, TrajectorySendError};
use limber_simarm::{Obstacles, SimArmOptions};

mod common;
use common::{TIMEOUT, arm};

fn position(a: &mut ActArrayClient, j: usize) -> f64 {
    a.wait_state(TIMEOUT).expect("a state").actuators[j].position
}

/// Joint `j` from where it is to `goal` in `seconds`, through the midpoint, cubic (zero
/// velocity at the ends), with these tolerances.
fn move_joint(
    a: &mut ActArrayClient,
    j: u16,
    goal: f64,
    seconds: f64,
    path_tol: f64,
    goal_tol: f64,
) -> Box<JointTrajectory> {
    let from = position(a, j as usize);
    let mid = 0.5 * (from + goal);
    let v = (goal - from) / seconds * 1.5;
    let mut t = JointTrajectory::new(&[j]).unwrap();
    t.push(seconds / 2.0, &[mid], Some(&[v]), None).unwrap();
    t.push(seconds, &[goal], Some(&[0.0]), None).unwrap();
    t.set_path_tolerance(&[path_tol]).unwrap();
    t.set_goal_tolerance(&[goal_tol]).unwrap();
    t
}

/// Waits for states until joint `j` has moved more than `by` from `from`.
fn wait_moved(a: &mut ActArrayClient, j: usize, from: f64, by: f64) {
    for _ in 0..10_000 {
        if (position(a, j) - from).abs() > by {
            return;
        }
    }
    panic!("joint {j} did not move");
}

/// Joint `j`'s position over `n` new states is one value (it holds).
fn holds(a: &mut ActArrayClient, j: usize, n: usize) -> f64 {
    let p = position(a, j);
    for _ in 0..n {
        assert_eq!(position(a, j), p, "joint {j} moves");
    }
    p
}

#[test]
fn a_trajectory_of_three_joints_is_reached_within_its_goal_tolerance() {
    let d = Domain::unique_for_test();
    let _drv = start(&d, Obstacles::default());
    let ctx = Context::new(&d, Role::Client, "traj").unwrap();
    let mut a = arm(&ctx);
    let s = *a.wait_state(TIMEOUT).unwrap();
    let q: Vec<f64> = (0..3).map(|j| s.actuators[j].position).collect();
    let mut t = JointTrajectory::new(&[0, 1, 2]).unwrap();
    for (i, f) in [0.25, 0.5, 0.75, 1.0].iter().enumerate() {
        let p: Vec<f64> = q.iter().map(|x| x + 0.4 * f).collect();
        let v = if i == 3 { 0.0 } else { 0.4 };
        t.push(0.3 * (i + 1) as f64, &p, Some(&[v; 3]), Some(&[0.0; 3]))
            .unwrap();
    }
    t.set_goal_tolerance(&[0.001; 3]).unwrap();
    t.set_path_tolerance(&[0.05; 3]).unwrap();
    let ticket = a.follow_trajectory(&t).unwrap();
    assert_eq!(a.wait_outcome(ticket, TIMEOUT).unwrap(), Status::Ok);
    // MOVING from the moment it was accepted.
    let flags = a.state().unwrap().actuators[1].flags().unwrap();
    assert_eq!(flags, ActuatorFlags::MOVING);
    let done = a.wait_done(ticket, TIMEOUT).unwrap();
    assert_eq!(done.result(), MotionResult::Reached, "{done}");
    assert_eq!(done.errors().len(), 3);
    assert!(
        done.max_error() <= 0.001 && done.tolerance() == 0.001,
        "{done}"
    );
    for (j, x) in q.iter().enumerate() {
        assert!((done.positions()[j] - (x + 0.4)).abs() <= 0.001, "{done}");
    }
    // The state's feedback: the last trajectory ended reached, past its last point.
    let fb = a.wait_state(TIMEOUT).unwrap().trajectory;
    assert_eq!((fb.active, fb.result), (2, MotionResult::Reached.code()));
    assert_eq!((fb.point, fb.points), (4, 4));
    // It holds at the goal.
    let p = holds(&mut a, 1, 3);
    assert!((p - (q[1] + 0.4)).abs() <= 0.001);
}

#[test]
fn an_obstacle_ends_it_with_the_path_tolerance_result_and_it_holds() {
    let d = Domain::unique_for_test();
    // A floor just below the base: swinging the shoulder half a turn takes the arm into it.
    let _drv = start(
        &d,
        Obstacles {
            floor: Some(-0.05),
            boxes: vec![],
        },
    );
    let ctx = Context::new(&d, Role::Client, "traj").unwrap();
    let mut a = arm(&ctx);
    let from = position(&mut a, 1);
    let t = move_joint(&mut a, 1, from + core::f64::consts::PI, 3.0, 0.05, 0.01);
    let ticket = a.follow_trajectory(&t).unwrap();
    let done = a.wait_done(ticket, TIMEOUT).unwrap();
    assert_eq!(done.result(), MotionResult::PathToleranceViolated, "{done}");
    assert!(
        done.sentence().contains("path tolerance"),
        "{}",
        done.sentence()
    );
    let stopped = done.positions()[1];
    assert!(stopped > from + 0.1 && stopped < from + 3.0, "{done}");
    // Held where the contact stopped it.
    let p = holds(&mut a, 1, 5);
    assert!((p - stopped).abs() < 0.06, "{p} {stopped}");
}

#[test]
fn a_stop_mid_way_ends_it_stopped_and_it_holds() {
    let d = Domain::unique_for_test();
    let _drv = start(&d, Obstacles::default());
    let ctx = Context::new(&d, Role::Client, "traj").unwrap();
    let mut a = arm(&ctx);
    let from = position(&mut a, 0);
    let t = move_joint(&mut a, 0, from + 2.0, 20.0, 0.1, 0.01);
    let ticket = a.follow_trajectory(&t).unwrap();
    assert_eq!(a.wait_outcome(ticket, TIMEOUT).unwrap(), Status::Ok);
    wait_moved(&mut a, 0, from, 0.001);
    // The actarray's stop: every speed 0.
    let stop = a.move_at_speed_multi(&[0.0; 7]).unwrap();
    let done = a.wait_done(ticket, TIMEOUT).unwrap();
    assert_eq!(done.result(), MotionResult::Stopped, "{done}");
    a.wait_done(stop, TIMEOUT).unwrap();
    // It decelerates (within 0.1 s at this speed) and then holds, short of the goal.
    for _ in 0..30 {
        position(&mut a, 0);
    }
    let p = holds(&mut a, 0, 5);
    assert!(p < from + 1.0, "{p}");
}

#[test]
fn a_replacement_mid_way_takes_over_from_its_start_time() {
    let d = Domain::unique_for_test();
    let _drv = start(&d, Obstacles::default());
    let ctx = Context::new(&d, Role::Client, "traj").unwrap();
    let mut a = arm(&ctx);
    let from = position(&mut a, 0);
    let first = move_joint(&mut a, 0, from + 2.0, 20.0, 0.1, 0.01);
    let first = a.follow_trajectory(&first).unwrap();
    assert_eq!(a.wait_outcome(first, TIMEOUT).unwrap(), Status::Ok);
    wait_moved(&mut a, 0, from, 0.001);
    // The new one goes back to where the joint started, from now (start time 0).
    let mut back = JointTrajectory::new(&[0]).unwrap();
    back.push(0.5, &[from], Some(&[0.0]), None).unwrap();
    back.set_goal_tolerance(&[0.001]).unwrap();
    let second = a.follow_trajectory(&back).unwrap();
    let done = a.wait_done(first, TIMEOUT).unwrap();
    assert_eq!(done.result(), MotionResult::Preempted, "{done}");
    let done = a.wait_done(second, TIMEOUT).unwrap();
    assert_eq!(done.result(), MotionResult::Reached, "{done}");
    assert!((done.positions()[0] - from).abs() <= 0.001, "{done}");
}

#[test]
fn a_scaling_of_zero_pauses_it_and_one_resumes_it() {
    let d = Domain::unique_for_test();
    let _drv = start(&d, Obstacles::default());
    let ctx = Context::new(&d, Role::Client, "traj").unwrap();
    let mut a = arm(&ctx);
    let from = position(&mut a, 0);
    let t = move_joint(&mut a, 0, from + 0.5, 2.0, 0.1, 0.001);
    let ticket = a.follow_trajectory(&t).unwrap();
    assert_eq!(a.wait_outcome(ticket, TIMEOUT).unwrap(), Status::Ok);
    wait_moved(&mut a, 0, from, 0.001);
    let pause = a.set_trajectory_scale(0.0).unwrap();
    assert_eq!(a.wait_outcome(pause, TIMEOUT).unwrap(), Status::Ok);
    position(&mut a, 0);
    let fb = a.wait_state(TIMEOUT).unwrap().trajectory;
    assert_eq!((fb.active, fb.scale, fb.points), (1, 0.0, 2), "{fb:?}");
    let paused = holds(&mut a, 0, 20);
    assert!(paused < from + 0.5);
    assert_eq!(a.done(ticket).unwrap(), None, "paused, not ended");
    let resume = a.set_trajectory_scale(1.0).unwrap();
    assert_eq!(a.wait_outcome(resume, TIMEOUT).unwrap(), Status::Ok);
    let done = a.wait_done(ticket, TIMEOUT).unwrap();
    assert_eq!(done.result(), MotionResult::Reached, "{done}");
    // Above 1 is clamped, and said so.
    let fast = a.set_trajectory_scale(2.0).unwrap();
    assert_eq!(a.wait_outcome(fast, TIMEOUT).unwrap(), Status::Clamped);
}

#[test]
fn invalid_goals_are_refused_with_their_cause() {
    let d = Domain::unique_for_test();
    let _drv = start(&d, Obstacles::default());
    let ctx = Context::new(&d, Role::Client, "traj").unwrap();
    let mut a = arm(&ctx);
    let refused = |a: &mut ActArrayClient, t: &JointTrajectory| {
        let ticket = a.follow_trajectory(t).unwrap();
        let status = a.wait_outcome(ticket, TIMEOUT).unwrap();
        assert!(a.done(ticket).unwrap().is_none());
        status
    };
    // An unknown joint (the arm has 7 actuators).
    let mut t = JointTrajectory::new(&[0, 9]).unwrap();
    t.push(1.0, &[0.0, 0.0], None, None).unwrap();
    assert_eq!(refused(&mut a, &t), Status::UnknownJoint);
    // Beyond the elbow's limits.
    let mut t = JointTrajectory::new(&[2]).unwrap();
    t.push(5.0, &[3.5], None, None).unwrap();
    assert_eq!(refused(&mut a, &t), Status::BeyondLimits);
    // Faster than the joint moves (3.15 rad/s).
    let mut t = JointTrajectory::new(&[0]).unwrap();
    t.push(0.1, &[position(&mut a, 0) + 1.0], None, None)
        .unwrap();
    assert_eq!(refused(&mut a, &t), Status::TooFast);
    // A start time 5 s in the past.
    let mut t = JointTrajectory::new(&[0]).unwrap();
    t.push(1.0, &[position(&mut a, 0)], None, None).unwrap();
    t.set_start_ns(monotonic_ns() - 5_000_000_000);
    assert_eq!(refused(&mut a, &t), Status::OldTimestamp);
    // Times not increasing and values not finite: refused before anything is sent...
    let mut t = JointTrajectory::new(&[0]).unwrap();
    t.push(1.0, &[0.0], None, None).unwrap();
    assert!(t.push(0.5, &[0.1], None, None).is_err());
    assert!(t.push(2.0, &[f64::NAN], None, None).is_err());
    // ... and by the driver when a client sends them anyway.
    let mut times = ActArrayTrajChunkCmd {
        field: traj_field::TIME,
        count: 2,
        ..Default::default()
    };
    times.values[..2].copy_from_slice(&[1.0, 0.5]);
    let mut positions = times;
    positions.field = traj_field::POSITION;
    positions.values[..2].copy_from_slice(&[0.0, 0.1]);
    let mut tolerances = ActArrayTrajChunkCmd {
        field: traj_field::PATH_TOLERANCE,
        count: 1,
        ..Default::default()
    };
    for c in [times, positions, tolerances] {
        a.send(&ActArrayCommand::TrajChunk(c)).unwrap();
    }
    tolerances.field = traj_field::GOAL_TOLERANCE;
    a.send(&ActArrayCommand::TrajChunk(tolerances)).unwrap();
    let header = ActArrayTrajCmd {
        joint_count: 1,
        point_count: 2,
        ..Default::default()
    };
    let t = a.send(&ActArrayCommand::Traj(header)).unwrap();
    assert_eq!(a.wait_outcome(t, TIMEOUT).unwrap(), Status::InvalidGoal);
    let mut raw = ActArrayCmdMsg::default();
    ActArrayCommand::TrajChunk(positions).write(&mut raw);
    raw.body[8..16].copy_from_slice(&f64::NAN.to_ne_bytes());
    assert_eq!(
        ActArrayCommand::read(&raw).unwrap_err().status(),
        Status::NotFinite
    );
    assert_eq!(raw.meta.kind, cmd::TRAJ_CHUNK);
    // The client says why before sending.
    let e = a
        .follow_trajectory(&JointTrajectory::new(&[0]).unwrap())
        .unwrap_err();
    assert!(matches!(e, TrajectorySendError::Invalid(_)), "{e}");
}

/// simarm with these obstacles.
fn start(domain: &Domain, obstacles: Obstacles) -> common::Driver {
    common::start(
        domain,
        SimArmOptions {
            obstacles,
            ..SimArmOptions::default()
        },
    )
}

#[test]
fn the_model_runs_a_trajectory_given_as_a_value_to_its_goal() {
    use limber_simarm::ArmModel;
    // No transport: the trajectory value goes straight to the model, as a limb path
    // sampled into joints does; time is the test's own.
    let mut m = ArmModel::new(
        limber_kinematics::chain::Chain::default_6dof(),
        SimArmOptions::default(),
    )
    .unwrap();
    let q = m.q();
    let mut t = JointTrajectory::new(&[0, 2]).unwrap();
    t.push(0.5, &[q[0] + 0.1, q[2] - 0.1], None, None).unwrap();
    t.push(1.0, &[q[0] + 0.2, q[2] - 0.2], None, None).unwrap();
    t.set_goal_tolerance(&[1e-9; 2]).unwrap();
    let start = 1_000_000_000u64;
    assert_eq!(m.run_trajectory(&t, start), Status::Ok);
    assert_eq!(m.arm_progress(0).end, None);
    let mut now = start;
    while m.arm_progress(0).end.is_none() {
        now += 10_000_000;
        assert!(now < start + 5_000_000_000, "not ended");
        m.step_trajectory(now);
    }
    assert_eq!(
        m.arm_progress(0).end,
        Some((MotionResult::Reached, Status::Ok))
    );
    assert_eq!(
        m.arm_progress(2).end,
        Some((MotionResult::Reached, Status::Ok))
    );
    let q1 = m.q();
    assert!((q1[0] - (q[0] + 0.2)).abs() < 1e-9 && (q1[2] - (q[2] - 0.2)).abs() < 1e-9);
    // Refused with the cause, nothing moving.
    let mut beyond = JointTrajectory::new(&[2]).unwrap();
    beyond.push(5.0, &[3.5], None, None).unwrap();
    assert_eq!(m.run_trajectory(&beyond, now), Status::BeyondLimits);
}
