//! LINE and PTP on simarm (issue 28, item 3): a line ends REACHED within the tolerance and
//! its tool stays on the line all the way (sampled from the published states); a line out
//! of reach or through an obstacle is refused before anything moves, the limb state naming
//! where; a PTP reaches its goal; a STOP ends a running line STOPPED. The driver runs on a
//! thread of the test process, in its own domain per test.

use std::time::Duration;

use limber_interfaces::limb::cmd as limb_cmd;
use limber_kinematics::chain::Chain;
use limber_services::prelude::*;
use limber_services::{Domain, Role};
use limber_simarm::model::TOLERANCE;
use limber_simarm::{Obstacles, SimArmOptions, SimArmThread, SimObstacle};

const TIMEOUT: Duration = Duration::from_secs(20);
/// Where the lines start: the tool over the table, pointing down.
const START: [f64; 3] = [0.4, 0.0, 0.3];
const DOWN: [f64; 3] = [0.0, 0.0, -1.0];
const FORWARD: [f64; 3] = [1.0, 0.0, 0.0];
/// How far the tool may stray from the straight line while it runs, m: the samples are
/// 5 mm apart and the joints move linearly between them (measured: well under this).
const ON_LINE: f64 = 0.001;

/// simarm (6 joints, 5x real time) with these obstacles.
fn start(domain: &Domain, obstacles: Obstacles) -> SimArmThread {
    let options = SimArmOptions {
        time_scale: 5.0,
        obstacles,
        ..SimArmOptions::default()
    };
    SimArmThread::start(domain.name(), Chain::default_6dof(), options, TIMEOUT)
        .expect("simarm starts")
}

/// A limb client with the tool at [`START`], pointing down.
fn limb_at_start(ctx: &Context) -> LimbClient {
    let mut limb = LimbClient::connect_timeout(ctx, "simarm/limb/0", TIMEOUT).unwrap();
    let t = limb.set_pose(START, DOWN, FORWARD).unwrap();
    let done = limb.wait_done(t, TIMEOUT).unwrap();
    assert!(done.reached(), "{done}");
    limb
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

/// The distance of `p` from the segment `a`–`b`.
fn off_segment(p: [f64; 3], a: [f64; 3], b: [f64; 3]) -> f64 {
    let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let len2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    let t = (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1] + (p[2] - a[2]) * d[2]) / len2)
        .clamp(0.0, 1.0);
    dist(p, [a[0] + t * d[0], a[1] + t * d[1], a[2] + t * d[2]])
}

fn position(s: &LimbData) -> [f64; 3] {
    s.position.to_array()
}

#[test]
fn a_line_is_reached_and_the_tool_stays_on_it() {
    let d = Domain::unique_for_test();
    let _drv = start(&d, Obstacles::default());
    let ctx = Context::new(&d, Role::Client, "paths").unwrap();
    let mut limb = limb_at_start(&ctx);
    let goal = [0.35, 0.15, 0.22];
    let t = limb.line(goal, None, 0.2).unwrap();
    assert_eq!(limb.wait_outcome(t, TIMEOUT).unwrap(), Status::Ok);
    // Every state while it runs: on the line, the path named with its progress.
    let (mut worst, mut moving, mut last_progress) = (0.0f64, 0, 0.0);
    loop {
        let s = *limb.wait_state(TIMEOUT).unwrap();
        worst = worst.max(off_segment(position(&s), START, goal));
        if s.path_kind == 0 {
            break;
        }
        assert_eq!(s.path_kind, limb_cmd::LINE);
        assert!(s.path_progress >= last_progress, "progress only grows");
        last_progress = s.path_progress;
        moving += 1;
    }
    assert!(moving >= 3, "the line was seen running ({moving} states)");
    assert!(worst <= ON_LINE, "the tool strayed {worst} m from the line");
    let done = limb.wait_done(t, TIMEOUT).unwrap();
    assert_eq!(
        (done.result(), done.cause()),
        (MotionResult::Reached, Status::Ok),
        "{done}"
    );
    assert!(done.errors().iter().all(|e| e.abs() <= TOLERANCE), "{done}");
    let s = *limb.current(TIMEOUT).unwrap();
    assert!(
        dist(position(&s), goal) < 1e-3,
        "at the goal: {:?}",
        s.position
    );
    // The orientation was kept: still pointing down.
    assert!((s.approach.z + 1.0).abs() < 1e-3, "{:?}", s.approach);
    println!("largest distance from the line: {worst:.6} m");
}

#[test]
fn a_line_out_of_reach_is_refused_before_anything_moves_naming_where() {
    let d = Domain::unique_for_test();
    let _drv = start(&d, Obstacles::default());
    let ctx = Context::new(&d, Role::Client, "paths").unwrap();
    let mut limb = limb_at_start(&ctx);
    let before = position(limb.current(TIMEOUT).unwrap());
    let goal = [2.0, 0.0, 0.3];
    let t = limb.line(goal, None, 0.0).unwrap();
    let st = limb.wait_outcome(t, TIMEOUT).unwrap();
    assert!(
        matches!(st, Status::OutOfReach | Status::UnreachableOrientation),
        "{st}"
    );
    // The state that shows the refusal went out before its outcome: where.
    let s = *limb.current(TIMEOUT).unwrap();
    assert_eq!(s.refused_kind, limb_cmd::LINE);
    assert!(s.refused_fraction > 0.0 && s.refused_fraction < 1.0);
    let expected: Vec<f64> = (0..3)
        .map(|k| before[k] + (goal[k] - before[k]) * s.refused_fraction)
        .collect();
    assert!(dist(position(&s), before) < 1e-9, "nothing moved");
    assert!(
        dist(
            s.refused_at.to_array(),
            [expected[0], expected[1], expected[2]]
        ) < 1e-6,
        "where: {:?}",
        s.refused_at
    );
    assert!(matches!(
        limb.wait_done(t, Duration::from_millis(200)),
        Err(DoneError::Refused(_))
    ));
}

#[test]
fn a_line_through_an_obstacle_or_the_floor_is_refused_at_it() {
    let d = Domain::unique_for_test();
    // A box across the line from START to the goal (y from 0.07 to 0.09), clear of the
    // way the arm takes from home to START.
    let post = SimObstacle {
        min: [0.37, 0.07, 0.25],
        max: [0.43, 0.09, 0.35],
    };
    let _drv = start(
        &d,
        Obstacles {
            floor: Some(0.0),
            boxes: vec![post],
        },
    );
    let ctx = Context::new(&d, Role::Client, "paths").unwrap();
    let mut limb = limb_at_start(&ctx);
    let before = position(limb.current(TIMEOUT).unwrap());
    let t = limb.line([0.4, 0.15, 0.3], None, 0.0).unwrap();
    assert_eq!(limb.wait_outcome(t, TIMEOUT).unwrap(), Status::PathCollides);
    let s = *limb.current(TIMEOUT).unwrap();
    assert_eq!(s.refused_kind, limb_cmd::LINE);
    assert!(dist(position(&s), before) < 1e-9, "nothing moved");
    // The first sample inside the post: at its near face (y 0.07) or within a step past.
    assert!(
        s.refused_at.y > 0.07 && s.refused_at.y < 0.07 + 0.006,
        "{:?}",
        s.refused_at
    );
    // Into the floor: refused too.
    let t = limb.line([0.4, 0.0, -0.05], None, 0.0).unwrap();
    assert_eq!(limb.wait_outcome(t, TIMEOUT).unwrap(), Status::PathCollides);
    let s = *limb.current(TIMEOUT).unwrap();
    assert!(
        s.refused_at.z < 0.0 && s.refused_at.z > -0.006,
        "{:?}",
        s.refused_at
    );
    // A free line is accepted after the refusals, and the refusal is cleared.
    let t = limb.line([0.4, -0.1, 0.3], None, 0.0).unwrap();
    assert!(limb.wait_done(t, TIMEOUT).unwrap().reached());
    assert_eq!(limb.current(TIMEOUT).unwrap().refused_kind, 0);
}

#[test]
fn a_ptp_reaches_its_goal_and_a_stop_ends_a_line_stopped() {
    let d = Domain::unique_for_test();
    let _drv = start(&d, Obstacles::default());
    let ctx = Context::new(&d, Role::Client, "paths").unwrap();
    let mut limb = limb_at_start(&ctx);
    let goal = [0.3, -0.2, 0.35];
    let t = limb.ptp(goal, Some((DOWN, FORWARD)), 0.0).unwrap();
    let done = limb.wait_done(t, TIMEOUT).unwrap();
    assert!(done.reached(), "{done}");
    let s = *limb.current(TIMEOUT).unwrap();
    assert!(dist(position(&s), goal) < 1e-3, "{:?}", s.position);
    // A slow line, stopped on its way.
    let t = limb.line(START, None, 0.01).unwrap();
    assert_eq!(limb.wait_outcome(t, TIMEOUT).unwrap(), Status::Ok);
    // Bounded: the line takes seconds at 1 cm/s.
    for _ in 0..1000 {
        if limb.wait_state(TIMEOUT).unwrap().path_kind == limb_cmd::LINE {
            break;
        }
    }
    limb.stop().unwrap();
    let done = limb.wait_done(t, TIMEOUT).unwrap();
    assert_eq!(done.result(), MotionResult::Stopped, "{done}");
}
