//! Pioneer closed-form kinematics: reference FK vectors, FK→IK→FK round trips, reach,
//! orientation consistency, limits, NaN handling, SETPOSITION and VECMOVE (SETPOSE and the
//! nearest-solution search: `pioneer_setpose.rs`).

use std::f64::consts::{FRAC_PI_2, PI};

use limber_kinematics::Pose;
use limber_kinematics::pioneer::*;
use nalgebra::{Rotation3, Vector3};
use proptest::prelude::*;

mod fk_vectors;
mod pioneer_support;
use fk_vectors::FK_CASES;
use pioneer_support::{geom, opts, v};

#[test]
fn fk_matches_the_40_reference_vectors() {
    assert_eq!(FK_CASES.len(), 40);
    let g = geom();
    for (i, c) in FK_CASES.iter().enumerate() {
        let pose = g.fk(&c.theta).unwrap();
        for (name, got, want) in [
            ("p", pose.position, v(c.p)),
            ("a", pose.approach(), v(c.a)),
            ("o", pose.orientation(), v(c.o)),
            ("n", pose.normal(), v(c.n)),
        ] {
            assert!(
                (got - want).norm() < 2e-12,
                "case {i} {name}: got {got:?} want {want:?}"
            );
        }
    }
}

#[test]
fn fk_at_zero_is_stretched_forward_and_robot_frame_adds_the_base() {
    let g = geom();
    let p = g.fk(&[0.0; 5]).unwrap();
    assert!((p.position - Vector3::new(0.47971, 0.0, 0.0)).norm() < 1e-15);
    let r = g.fk_robot(&[0.0; 5]).unwrap();
    assert!((r.position - Vector3::new(0.58471, 0.0, 0.3185)).norm() < 1e-15);
    assert_eq!(g.robot_to_base(&r).position, p.position);
}

/// Player's a_y carries +c1·s4·s5; with it the frame is not orthonormal, with the
/// corrected sign it is.
#[test]
fn player_sign_error_is_corrected() {
    let t = [0.3, -0.4, 0.9, -0.7, 0.5];
    let pose = geom().fk(&t).unwrap();
    let (s1, c1) = t[0].sin_cos();
    let (s23, c23) = (t[1] + t[2]).sin_cos();
    let (s4, c4) = t[3].sin_cos();
    let (s5, c5) = t[4].sin_cos();
    let player_ay = s1 * c23 * c5 + c1 * s4 * s5 - s1 * s23 * c4 * s5;
    let mut a_player = pose.approach();
    a_player.y = player_ay;
    assert!(
        (a_player.norm() - 1.0).abs() > 1e-3,
        "Player's a is not unit"
    );
    assert!((pose.approach().norm() - 1.0).abs() < 1e-15);
    assert!((pose.normal() - pose.orientation().cross(&pose.approach())).norm() < 1e-15);
}

#[test]
fn driver_angle_map_round_trips_and_swaps_reversed_limits() {
    let map = DriverAngleMap {
        offsets: [0.1, -0.2, 0.3, 0.05, -0.4],
    };
    let j = [0.5, -0.25, 1.0, 0.3, -0.7];
    let t = map.theta_from_driver(&j);
    assert!((t[0] - -(0.5 - 0.1)).abs() < 1e-15);
    assert!((t[1] - (-0.25 + 0.2)).abs() < 1e-15);
    assert!((t[3] - -(0.3 - 0.05)).abs() < 1e-15);
    let back = map.driver_from_theta(&t);
    for i in 0..5 {
        assert!((back[i] - j[i]).abs() < 1e-15);
    }
    // ARMINFO limits of joints 0-2 come out reversed (min > max) in driver radians.
    let lim = DriverAngleMap::default()
        .limits_from_driver(&[1.5, 1.4, 1.3, -1.0, -1.1], &[-1.5, -1.4, -1.3, 1.0, 1.2]);
    assert_eq!(lim[0], JointLimit::new(-1.5, 1.5));
    assert_eq!(lim[1], JointLimit::new(-1.4, 1.4));
    assert_eq!(lim[4], JointLimit::new(-1.2, 1.1));
}

fn theta_in_limits() -> impl Strategy<Value = Theta> {
    let l = geom().limits;
    (
        l[0].min..l[0].max,
        l[1].min..l[1].max,
        l[2].min..l[2].max,
        l[3].min..l[3].max,
        l[4].min..l[4].max,
    )
        .prop_map(|(a, b, c, d, e)| [a, b, c, d, e])
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 2000,
        failure_persistence: None,
        rng_algorithm: proptest::test_runner::RngAlgorithm::ChaCha,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x11B3),
        ..ProptestConfig::default()
    })]

    /// FK→IK→FK reproduces the pose to 1e-9 m and 1e-9 rad for every in-limit
    /// configuration, from the zero configuration and from the configuration itself.
    #[test]
    fn fk_ik_fk_round_trip(theta in theta_in_limits(), other in theta_in_limits()) {
        let g = geom();
        let target = g.fk(&theta).unwrap();
        for current in [[0.0; 5], theta, other] {
            let sol = g.solve_pose(&target, &current, &opts()).unwrap();
            prop_assert!(g.within_limits(&sol.theta));
            let back = g.fk(&sol.theta).unwrap();
            prop_assert!(back.position_error(&target) < 1e-9);
            prop_assert!(back.orientation_error(&target) < 1e-9);
        }
        // Started at the configuration itself, IK returns it.
        let sol = g.solve_pose(&target, &theta, &opts()).unwrap();
        for i in 0..5 {
            prop_assert!((sol.theta[i] - theta[i]).abs() < 1e-6, "{:?} vs {:?}", sol.theta, theta);
        }
    }

    /// The FK frame is orthonormal and right-handed, and equals the rotation product.
    #[test]
    fn fk_frame_is_orthonormal_right_handed(theta in theta_in_limits()) {
        let p = geom().fk(&theta).unwrap();
        let m = p.rotation.matrix();
        prop_assert!((m.transpose() * m - nalgebra::Matrix3::identity()).norm() < 1e-14);
        prop_assert!((m.determinant() - 1.0).abs() < 1e-14);
        prop_assert!((p.normal() - p.orientation().cross(&p.approach())).norm() < 1e-14);
        let r = Rotation3::from_axis_angle(&Vector3::z_axis(), theta[0])
            * Rotation3::from_axis_angle(&Vector3::y_axis(), -(theta[1] + theta[2]))
            * Rotation3::from_axis_angle(&Vector3::x_axis(), theta[3])
            * Rotation3::from_axis_angle(&Vector3::y_axis(), -theta[4]);
        prop_assert!((r.matrix() - m).norm() < 1e-14);
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 150,
        failure_persistence: None,
        rng_algorithm: proptest::test_runner::RngAlgorithm::ChaCha,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x11B3),
        ..ProptestConfig::default()
    })]

    /// SETPOSITION reaches any position of an in-limit configuration, inside the limits.
    #[test]
    fn setposition_reaches_reachable_positions(theta in theta_in_limits()) {
        let g = geom();
        let target = g.fk(&theta).unwrap().position;
        let sol = g.solve_position(&target, ApproachPreference::Current, &[0.0; 5], &opts()).unwrap();
        prop_assert!(g.within_limits(&sol.theta));
        prop_assert!((g.fk(&sol.theta).unwrap().position - target).norm() < 1e-9);
    }
}

#[test]
fn candidates_cover_the_branches() {
    let g = geom();
    // Wrist centre close to the yaw axis, so reaching over the top is possible too.
    let theta = [0.3, 1.2, 1.0, -0.2, 0.6];
    let target = g.fk(&theta).unwrap();
    let c = g.pose_candidates(&target, &[0.0; 5], &opts()).unwrap();
    assert_eq!(c.len(), 4);
    assert!(
        c.as_slice()
            .iter()
            .all(|c| c.theta.iter().all(|t| t.is_finite()))
    );
    // A 5-DOF arm reaches a full frame only where its normal is perpendicular to the
    // forearm, so the other branches generally miss the orientation; the original
    // configuration's branch is exact.
    let exact: Vec<_> = c
        .as_slice()
        .iter()
        .filter(|c| c.position_error < 1e-9 && c.orientation_error < 1e-9)
        .collect();
    assert!(exact.iter().any(|c| c.branch.shoulder == Shoulder::Front
        && c.branch.elbow == Elbow::Down
        && (c.theta[3] - theta[3]).abs() < 1e-9));
    // Every candidate reaches the position (only the wrist can miss).
    assert!(c.as_slice().iter().all(|c| c.position_error < 0.3));
    let with_approach = g
        .approach_candidates(&target.position, &target.approach(), &[0.0; 5], &opts())
        .unwrap();
    assert_eq!(with_approach.len(), 8);
    let exact_approach = with_approach
        .as_slice()
        .iter()
        .filter(|c| c.position_error < 1e-9 && c.orientation_error < 1e-9)
        .count();
    assert_eq!(exact_approach, 8, "{:?}", with_approach.as_slice());
}

/// Wide limits: the other branches become valid, and the choice follows `current`.
#[test]
fn choice_is_nearest_to_current() {
    let mut g = geom();
    g.limits = [JointLimit::new(-PI, PI); 5];
    let theta = [0.3, 0.4, 0.5, -0.2, 0.6];
    let target = g.fk(&theta).unwrap();
    let all = g.pose_candidates(&target, &[0.0; 5], &opts()).unwrap();
    let exact = all
        .as_slice()
        .iter()
        .filter(|c| c.position_error < 1e-9 && c.orientation_error < 1e-9);
    for c in exact {
        let sol = g.solve_pose(&target, &c.theta, &opts()).unwrap();
        assert_eq!(sol.branch, c.branch);
    }
    // Deterministic.
    let a = g.solve_pose(&target, &[0.1; 5], &opts()).unwrap();
    let b = g.solve_pose(&target, &[0.1; 5], &opts()).unwrap();
    assert_eq!(a, b);
}

fn stretched_target(extra: f64) -> Pose {
    // Fully stretched along +x: wrist at L1 + L2 + L4, approach +x.
    let g = geom();
    let x = g.l1 + g.l2 + g.l4 + g.l5 + extra;
    Pose::new(Vector3::new(x, 0.0, 0.0), Rotation3::identity())
}

#[test]
fn reach_at_inside_and_beyond() {
    let g = geom();
    let o = opts();
    let at = g.solve_pose(&stretched_target(0.0), &[0.0; 5], &o).unwrap();
    assert!(at.theta.iter().all(|t| t.abs() < 1e-6), "{:?}", at.theta);
    let inside = g
        .solve_pose(&stretched_target(-1e-6), &[0.0; 5], &o)
        .unwrap();
    assert!(
        g.fk(&inside.theta)
            .unwrap()
            .position_error(&stretched_target(-1e-6))
            < 1e-9
    );
    // Within the position tolerance beyond: accepted (clamped by at most 1e-6 m).
    assert!(g.solve_pose(&stretched_target(5e-7), &[0.0; 5], &o).is_ok());
    for extra in [2e-6, 1e-4, 0.01, 1.0, 1e6, 1e300] {
        let e = g
            .solve_pose(&stretched_target(extra), &[0.0; 5], &o)
            .unwrap_err();
        match e {
            PioneerIkError::OutOfReach { distance, min, max } => {
                assert!(distance.is_finite() && distance > max && min >= 0.0);
            }
            other => panic!("expected OutOfReach for +{extra}: {other:?}"),
        }
        assert!(e.is_out_of_reach());
    }
    // Wrist centre closer to the shoulder than |L2 - L4| = 0.02225 m (with L1 = 0 so
    // that reaching over the top does not help either).
    let mut g0 = g;
    g0.l1 = 0.0;
    let near = Pose::new(Vector3::new(0.001 + g.l5, 0.0, 0.0), Rotation3::identity());
    assert!(matches!(
        g0.solve_pose(&near, &[0.0; 5], &o),
        Err(PioneerIkError::OutOfReach { .. })
    ));
}

#[test]
fn inconsistent_orientation_is_reported_not_approximated() {
    let g = geom();
    let theta = [0.3, 0.4, 0.5, -0.2, 0.6];
    let target = g.fk(&theta).unwrap();
    // Roll the frame about its approach: the normal leaves the plane perpendicular to
    // the forearm, which the 5-DOF wrist cannot follow.
    for (angle, ok) in [(1e-8, true), (1e-5, false), (0.1, false)] {
        let rolled = Pose::new(
            target.position,
            target.rotation * Rotation3::from_axis_angle(&Vector3::x_axis(), angle),
        );
        let r = g.solve_pose(&rolled, &[0.0; 5], &opts());
        if ok {
            assert!(r.is_ok(), "{angle}: {r:?}");
        } else {
            match r {
                Err(PioneerIkError::UnreachableOrientation { error }) => {
                    assert!(error > 1e-6 && error.is_finite())
                }
                other => panic!("{angle}: {other:?}"),
            }
        }
    }
}

#[test]
fn outside_the_limits_is_out_of_reach() {
    let mut g = geom();
    g.limits[0] = JointLimit::new(-0.5, 0.5);
    let target = g.fk(&[1.0, 0.2, 0.3, 0.1, 0.2]).unwrap();
    let e = g.solve_pose(&target, &[0.0; 5], &opts()).unwrap_err();
    assert_eq!(e, PioneerIkError::OutsideJointLimits);
    assert!(e.is_out_of_reach());
    // On the limit itself (round-off tolerated).
    let on = g.fk(&[0.5, 0.2, 0.3, 0.1, 0.2]).unwrap();
    let sol = g.solve_pose(&on, &[0.0; 5], &opts()).unwrap();
    assert!((sol.theta[0] - 0.5).abs() < 1e-9 && sol.theta[0] <= 0.5);
}

#[test]
fn nan_and_bad_input_are_errors() {
    let g = geom();
    let o = opts();
    let good = g.fk(&[0.1; 5]).unwrap();
    assert_eq!(g.fk(&[f64::NAN; 5]), Err(PioneerFkError::NonFinite));
    let mut bad = good;
    bad.position.x = f64::NAN;
    assert_eq!(
        g.solve_pose(&bad, &[0.0; 5], &o),
        Err(PioneerIkError::NonFinite)
    );
    let mut cur = [0.0; 5];
    cur[2] = f64::INFINITY;
    assert_eq!(
        g.solve_pose(&good, &cur, &o),
        Err(PioneerIkError::NonFinite)
    );
    assert!(matches!(
        g.solve_setpose(
            &good.position,
            &Vector3::zeros(),
            &Vector3::z(),
            &[0.0; 5],
            &o
        ),
        Err(PioneerIkError::Frame(_))
    ));
    assert!(matches!(
        g.solve_setpose(&good.position, &Vector3::x(), &Vector3::x(), &[0.0; 5], &o),
        Err(PioneerIkError::Frame(_))
    ));
    let p = Vector3::new(f64::NAN, 0.0, 0.0);
    assert_eq!(
        g.solve_position(&p, ApproachPreference::Down, &[0.0; 5], &o),
        Err(PioneerIkError::NonFinite)
    );
    let mut bad_opts = o;
    bad_opts.position_tolerance = f64::NAN;
    assert_eq!(
        g.solve_pose(&good, &[0.0; 5], &bad_opts),
        Err(PioneerIkError::InvalidOptions)
    );
    let mut bad_geom = g;
    bad_geom.l2 = -1.0;
    assert!(matches!(
        bad_geom.solve_pose(&good, &[0.0; 5], &o),
        Err(PioneerIkError::Geometry(_))
    ));
    assert!(matches!(
        g.vecmove(
            &[0.0; 5],
            &Vector3::zeros(),
            0.1,
            &VecMoveOptions::default()
        ),
        Err(VecMoveError::ZeroDirection)
    ));
    assert!(matches!(
        g.vecmove(
            &[0.0; 5],
            &Vector3::x(),
            f64::NAN,
            &VecMoveOptions::default()
        ),
        Err(VecMoveError::NonFinite)
    ));
}

#[test]
fn setpose_from_player_vectors_in_the_robot_frame() {
    let g = geom();
    let theta = [0.2, 0.3, 0.4, 0.0, -0.3];
    let robot = g.fk_robot(&theta).unwrap();
    // Unnormalised vectors as a client might send them.
    let sol = g
        .solve_setpose(
            &robot.position,
            &(robot.approach() * 2.0),
            &(robot.orientation() * 0.5),
            &[0.0; 5],
            &opts(),
        )
        .unwrap();
    let back = g.fk_robot(&sol.theta).unwrap();
    assert!(back.position_error(&robot) < 1e-9 && back.orientation_error(&robot) < 1e-9);
}

#[test]
fn setposition_pointing_down_and_out_of_reach() {
    let g = geom();
    let target = Vector3::new(0.3, 0.05, -0.15);
    let sol = g
        .solve_position(&target, ApproachPreference::Down, &[0.0; 5], &opts())
        .unwrap();
    let pose = g.fk(&sol.theta).unwrap();
    assert!((pose.position - target).norm() < 1e-6);
    assert!(
        (pose.approach() + Vector3::z()).norm() < 1e-6,
        "{:?}",
        pose.approach()
    );
    let far = Vector3::new(0.6, 0.0, 0.2);
    assert!(matches!(
        g.solve_position(&far, ApproachPreference::Current, &[0.0; 5], &opts()),
        Err(PioneerIkError::OutOfReach { .. })
    ));
    // Behind the robot: within the geometric reach but never within the limits.
    let behind = Vector3::new(-0.25, 0.0, -0.1);
    let e = g
        .solve_position(&behind, ApproachPreference::Current, &[0.0; 5], &opts())
        .unwrap_err();
    assert!(e.is_out_of_reach(), "{e:?}");
}

#[test]
fn vecmove_follows_the_line_with_bounded_deviation() {
    let g = geom();
    let start = [0.1, 0.3, 0.6, 0.2, 0.4];
    let p0 = g.fk(&start).unwrap();
    let dir = Vector3::new(0.3, -1.0, -0.4).normalize();
    let len = 0.08;
    let options = VecMoveOptions {
        max_deviation: 5e-4,
        ..VecMoveOptions::default()
    };
    let mut last = None;
    let mut count = 0;
    for w in g.vecmove(&start, &dir, len, &options).unwrap() {
        let w = w.unwrap();
        count += 1;
        assert!(w.deviation <= 5e-4);
        assert!(g.within_limits(&w.theta));
        let pose = g.fk(&w.theta).unwrap();
        let expect = p0.position + dir * w.distance;
        assert!((pose.position - expect).norm() < 1e-6);
        assert!((pose.approach() - p0.approach()).norm() < 1e-6);
        last = Some(w);
    }
    let last = last.unwrap();
    assert!((last.distance - len).abs() < 1e-15);
    assert!(count >= 4, "{count} waypoints");
}

#[test]
fn vecmove_out_of_reach_stops_with_an_error() {
    let g = geom();
    let start = [0.0, 0.2, 0.3, 0.0, 0.0];
    let items: Vec<_> = g
        .vecmove(&start, &Vector3::x(), 0.5, &VecMoveOptions::default())
        .unwrap()
        .collect();
    let (last, before) = items.split_last().unwrap();
    assert!(before.iter().all(|w| w.is_ok()));
    match last {
        Err(VecMoveError::Unreachable { distance, cause }) => {
            assert!(distance.is_finite() && *distance < 0.5);
            assert!(cause.is_out_of_reach());
        }
        other => panic!("{other:?}"),
    }
    assert!(items.len() > 1);
    // Zero length: no waypoint.
    assert_eq!(
        g.vecmove(&start, &Vector3::x(), 0.0, &VecMoveOptions::default())
            .unwrap()
            .count(),
        0
    );
    let _ = FRAC_PI_2;
}

/// When the preferred approach is impossible, SETPOSITION takes the in-plane approach
/// (gripper level, wrist roll 0 or π) nearest to it: one step closer is infeasible.
#[test]
fn setposition_falls_back_to_the_nearest_in_plane_approach() {
    let g = geom();
    let o = opts();
    let target = Vector3::new(0.22, 0.08, -0.25);
    let preferred = Vector3::new(1.0, 0.0, 0.0);
    assert!(
        g.solve_position_approach(&target, &preferred, &[0.0; 5], &o)
            .is_err()
    );
    let sol = g
        .solve_position(
            &target,
            ApproachPreference::Direction(preferred),
            &[0.0; 5],
            &o,
        )
        .unwrap();
    let pose = g.fk(&sol.theta).unwrap();
    assert!((pose.position - target).norm() < 1e-6);
    let a = pose.approach();
    // In the vertical plane through the yaw axis and the target.
    let plane_normal = Vector3::new(-target.y, target.x, 0.0).normalize();
    assert!(a.dot(&plane_normal).abs() < 1e-6, "{a:?}");
    // Nearest: tilting it 1e-4 rad towards the preferred elevation fails.
    let radial = Vector3::new(target.x, target.y, 0.0).normalize();
    let phi = a.z.atan2(a.dot(&radial));
    let closer = phi + 1e-4 * (0.0 - phi).signum();
    let a2 = radial * closer.cos() + Vector3::z() * closer.sin();
    assert!(
        g.solve_position_approach(&target, &a2, &[0.0; 5], &o)
            .is_err()
    );
}

/// Positions reachable only with θ1 on its limit (the target's vertical plane is
/// beyond it) are still found.
#[test]
fn setposition_at_the_yaw_limit() {
    let g = geom();
    let theta = [
        1.5124862068729268,
        -1.5480789923911729,
        -0.15774691699986487,
        -1.4035144795892425,
        0.1289359815486788,
    ];
    let target = g.fk(&theta).unwrap().position;
    let sol = g
        .solve_position(&target, ApproachPreference::Current, &[0.0; 5], &opts())
        .unwrap();
    assert!(g.within_limits(&sol.theta));
    assert!((g.fk(&sol.theta).unwrap().position - target).norm() < 1e-6);
}

/// Issue 12, item 8: a huge direction is a direction (its norm overflows; scaling by the
/// largest component first keeps it), the zero vector is not.
#[test]
fn vecmove_direction_of_huge_components_is_normalised_without_overflow() {
    let g = geom();
    let start = [0.1, 0.3, 0.6, 0.2, 0.4];
    let options = VecMoveOptions::default();
    let plan = |dir: Vector3<f64>| -> Vec<[f64; 5]> {
        g.vecmove(&start, &dir, 0.02, &options)
            .unwrap()
            .map(|w| w.unwrap().theta)
            .collect()
    };
    let same = |a: &[[f64; 5]], b: &[[f64; 5]]| {
        a.len() == b.len()
            && a.iter()
                .zip(b)
                .all(|(x, y)| x.iter().zip(y).all(|(p, q)| (p - q).abs() < 1e-9))
    };
    let small = plan(Vector3::new(0.5, -1.0, -0.5));
    let huge = plan(Vector3::new(0.5e308, -1e308, -0.5e308));
    assert!(!huge.is_empty());
    assert!(same(&small, &huge), "{small:?} vs {huge:?}");
    let p0 = g.fk(&start).unwrap().position;
    let end = g.fk(huge.last().unwrap()).unwrap().position;
    assert!(
        ((end - p0).norm() - 0.02).abs() < 1e-6,
        "{}",
        (end - p0).norm()
    );
    // Subnormal components are a direction too; zero is not.
    assert!(same(
        &plan(Vector3::new(0.5e-320, -1e-320, -0.5e-320)),
        &small
    ));
    assert!(matches!(
        g.vecmove(&start, &Vector3::zeros(), 0.02, &options),
        Err(VecMoveError::ZeroDirection)
    ));
    let u =
        limber_kinematics::unit_direction(&Vector3::new(f64::MAX, -f64::MAX, f64::MAX)).unwrap();
    assert!((u - Vector3::new(1.0, -1.0, 1.0) / 3f64.sqrt()).norm() < 1e-15);
    assert_eq!(limber_kinematics::unit_direction(&Vector3::zeros()), None);
}
