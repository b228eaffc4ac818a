//! Path checks (issue 28, item 3): a straight line of the tool and a point-to-point move
//! are sampled and every sample checked (reachable, within the limits, without a jump,
//! clear of the floor and the obstacles) before anything moves; the first bad sample says
//! where (the tool point, the fraction of the path) and why.

use limber_kinematics::Pose;
use limber_kinematics::chain::{Chain, IkTarget};
use limber_kinematics::path::{
    Box3, Contact, Orientation, PathFault, PathOptions, Scene, line, ptp,
};
use nalgebra::{Rotation3, Vector3};

/// The 6-joint chain, its tool over the table pointing down at (0.4, 0.0, 0.3) (home is
/// the arm stretched up: a singular place to start a line from).
fn arm() -> (Chain, Vec<f64>, Pose) {
    let chain = Chain::default_6dof();
    let pose = Pose::from_approach_orientation(
        Vector3::new(0.4, 0.0, 0.3),
        Vector3::new(0.0, 0.0, -1.0),
        Vector3::new(1.0, 0.0, 0.0),
        1e-9,
    )
    .unwrap();
    let q = chain
        .ik(&IkTarget::Pose(pose), &chain.home(), &Default::default())
        .unwrap()
        .q
        .to_vec();
    let start = chain.fk(&q).unwrap();
    (chain, q, start)
}

/// The distance of `p` from the line through `a` and `b`.
fn off_line(p: &Vector3<f64>, a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
    let d = (b - a).normalize();
    let v = p - a;
    (v - d * v.dot(&d)).norm()
}

#[test]
fn a_free_line_is_sampled_on_the_line_with_the_orientation_kept() {
    let (chain, home, start) = arm();
    let goal = start.translated(&Vector3::new(0.0, 0.15, -0.05));
    let o = PathOptions::default();
    let s = line(
        &chain,
        &Scene::default(),
        &home,
        &goal,
        Orientation::Keep,
        &o,
    )
    .unwrap();
    let length = (goal.position - start.position).norm();
    assert_eq!(s.q.len(), (length / o.step).ceil() as usize);
    assert!(s.spacing <= o.step + 1e-12);
    for q in &s.q {
        let p = chain.fk(q).unwrap();
        assert!(off_line(&p.position, &start.position, &goal.position) < 1e-5);
        assert!(p.orientation_error(&start) < 1e-5, "orientation kept");
    }
    let last = chain.fk(s.q.last().unwrap()).unwrap();
    assert!(last.position_error(&goal) < 1e-5);
}

#[test]
fn an_interpolated_orientation_turns_evenly_to_the_goals() {
    let (chain, home, start) = arm();
    let turned = start.rotation * Rotation3::from_euler_angles(0.3, 0.0, 0.0);
    let goal = Pose::new(start.position + Vector3::new(0.0, 0.1, 0.0), turned);
    let o = PathOptions::default();
    let s = line(
        &chain,
        &Scene::default(),
        &home,
        &goal,
        Orientation::Interpolate,
        &o,
    )
    .unwrap();
    let mid = chain.fk(&s.q[s.q.len() / 2 - 1]).unwrap();
    let half = start
        .rotation
        .slerp(&turned, (s.q.len() / 2) as f64 / s.q.len() as f64);
    assert!(limber_kinematics::angle_between_rotations(&mid.rotation, &half) < 1e-4);
    let last = chain.fk(s.q.last().unwrap()).unwrap();
    assert!(last.orientation_error(&goal) < 1e-5);
}

#[test]
fn a_line_out_of_reach_is_refused_where_it_leaves_the_reach() {
    let (chain, home, start) = arm();
    let dir = Vector3::new(1.0, 0.0, 0.0);
    let goal = start.translated(&(dir * 2.0));
    let e = line(
        &chain,
        &Scene::default(),
        &home,
        &goal,
        Orientation::Keep,
        &PathOptions::default(),
    )
    .unwrap_err();
    assert!(
        matches!(
            e.why,
            PathFault::OutOfReach | PathFault::UnreachableOrientation
        ),
        "{e}"
    );
    assert!(e.fraction > 0.0 && e.fraction < 1.0, "{e}");
    // Where: on the line, at that fraction.
    let expected = start.position + (goal.position - start.position) * e.fraction;
    assert!((e.point - expected).norm() < 1e-9, "{e}");
    assert!(e.to_string().starts_with("refused at "), "{e}");
}

#[test]
fn a_line_through_an_obstacle_or_the_floor_is_refused_at_the_contact() {
    let (chain, home, start) = arm();
    let goal = start.translated(&Vector3::new(0.0, 0.2, 0.0));
    // A box across the middle of the line.
    let c = start.position + Vector3::new(0.0, 0.1, 0.0);
    let scene = Scene {
        floor: None,
        boxes: vec![Box3 {
            min: [c.x - 0.05, c.y - 0.02, c.z - 0.05],
            max: [c.x + 0.05, c.y + 0.02, c.z + 0.05],
        }],
    };
    let e = line(
        &chain,
        &scene,
        &home,
        &goal,
        Orientation::Keep,
        &PathOptions::default(),
    )
    .unwrap_err();
    assert_eq!(e.why, PathFault::Collision(Contact::Obstacle(0)), "{e}");
    // The first sample inside the box: its near face is at 0.08 of 0.2 m.
    assert!(e.fraction > 0.35 && e.fraction <= 0.45, "{e}");
    assert!(e.to_string().contains("it would hit obstacle 0"), "{e}");
    // Down from 0.3 m to 0 through a floor at 0.05 m (the shoulder's frame stands at
    // 0.089 m).
    let down = start.translated(&Vector3::new(0.0, 0.0, -0.3));
    let floor = Scene {
        floor: Some(0.05),
        boxes: vec![],
    };
    let e = line(
        &chain,
        &floor,
        &home,
        &down,
        Orientation::Keep,
        &PathOptions::default(),
    )
    .unwrap_err();
    assert_eq!(e.why, PathFault::Collision(Contact::Floor), "{e}");
    assert!(
        e.point.z < 0.05 && e.point.z > 0.044,
        "the first sample below it: {e}"
    );
}

#[test]
fn a_long_line_is_sampled_no_finer_than_max_samples() {
    let (chain, home, start) = arm();
    let goal = start.translated(&Vector3::new(0.0, 0.3, 0.0));
    let o = PathOptions {
        max_samples: 10,
        ..PathOptions::default()
    };
    let s = line(
        &chain,
        &Scene::default(),
        &home,
        &goal,
        Orientation::Keep,
        &o,
    )
    .unwrap();
    assert_eq!(s.q.len(), 10);
    assert!((s.spacing - 0.03).abs() < 1e-9);
}

#[test]
fn a_point_to_point_move_interpolates_the_joints_and_is_checked_on_the_way() {
    let (chain, home, _) = arm();
    let mut goal = home.clone();
    goal[0] += 0.8;
    let o = PathOptions::default();
    let s = ptp(&chain, &Scene::default(), &home, &goal, &o).unwrap();
    assert_eq!(s.q.len(), (0.8 / o.joint_step).ceil() as usize);
    assert!((s.q.last().unwrap()[0] - goal[0]).abs() < 1e-12);
    // An obstacle where the tool passes half-way: refused there.
    let mut mid = home.clone();
    mid[0] += 0.4;
    let p = chain.fk(&mid).unwrap().position;
    let scene = Scene {
        floor: None,
        boxes: vec![Box3 {
            min: [p.x - 0.03, p.y - 0.03, p.z - 0.03],
            max: [p.x + 0.03, p.y + 0.03, p.z + 0.03],
        }],
    };
    let e = ptp(&chain, &scene, &home, &goal, &o).unwrap_err();
    assert_eq!(e.why, PathFault::Collision(Contact::Obstacle(0)), "{e}");
    assert!(e.fraction > 0.3 && e.fraction <= 0.5, "{e}");
    // A goal beyond a joint's limit: refused at the goal.
    let mut far = home.clone();
    far[1] = chain.joints()[1].max + 0.5;
    let e = ptp(&chain, &Scene::default(), &home, &far, &o).unwrap_err();
    assert_eq!((e.why, e.fraction), (PathFault::BeyondLimits, 1.0));
}
