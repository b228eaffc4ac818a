//! Generic chains: loading, FK (cross-checked against the Pioneer closed form), numeric
//! IK success rates on 5-, 6- and 7-joint arms, reach and limit failures, bad input.

use std::f64::consts::FRAC_PI_2;

use limber_kinematics::Pose;
use limber_kinematics::chain::*;
use limber_kinematics::pioneer::{PioneerGeometry, Theta};
use nalgebra::{Rotation3, Vector3};
use proptest::prelude::*;

#[test]
fn embedded_chains_load() {
    let c6 = Chain::default_6dof();
    assert_eq!((c6.name(), c6.dof()), ("arm6", 6));
    let g = c6.gripper().unwrap();
    assert!(g.stroke > 0.0 && g.max_speed > 0.0);
    assert!(
        c6.joints()
            .iter()
            .all(|j| j.max_speed > 0.0 && j.min < j.max)
    );
    assert!(c6.within_limits(&c6.home()));
    let c7 = Chain::default_7dof();
    assert_eq!((c7.name(), c7.dof()), ("arm7", 7));
    assert!(c7.gripper().is_some());
    assert!(c7.within_limits(&c7.home()));
    let p5 = Chain::pioneer5();
    assert_eq!(p5.dof(), 5);
    // Joint speeds: the slowest joint decides a synchronised move.
    let mut to = c7.home();
    to[0] += 1.0;
    to[6] += 1.0;
    let t = c7.min_travel_time(&c7.home(), &to).unwrap();
    assert!((t - 1.0 / 2.175).abs() < 1e-12, "{t}");
    assert!(c7.min_travel_time(&c7.home(), &[0.0; 3]).is_err());
    // The files on disk are the embedded ones.
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/chains/");
    assert_eq!(Chain::from_file(format!("{dir}arm6.toml")).unwrap(), c6);
    assert_eq!(Chain::from_file(format!("{dir}arm7.toml")).unwrap(), c7);
    assert_eq!(Chain::from_file(format!("{dir}pioneer5.toml")).unwrap(), p5);
}

/// The 6-joint arm's reach is UR5-like: about 0.85 m from the shoulder.
#[test]
fn arm6_reach_is_realistic() {
    let c = Chain::default_6dof();
    let mut rng = DeterministicRng::new(7);
    let shoulder = Vector3::new(0.0, 0.0, 0.089159);
    let mut far: f64 = 0.0;
    for _ in 0..3000 {
        let q = c.random_configuration(&mut rng);
        let p = c.fk(&q).unwrap().position;
        far = far.max((p - shoulder).norm());
        assert!((p - shoulder).norm() <= c.reach_bound());
    }
    assert!(far > 0.8 && far < 0.95, "{far}");
}

#[test]
fn pioneer_chain_fk_equals_the_closed_form() {
    let c = Chain::pioneer5();
    let g = PioneerGeometry::default();
    let mut rng = DeterministicRng::new(11);
    for _ in 0..500 {
        let q = c.random_configuration(&mut rng);
        let theta: Theta = std::array::from_fn(|i| q[i]);
        let a = c.fk(&q).unwrap();
        let b = g.fk(&theta).unwrap();
        assert!(a.position_error(&b) < 1e-14 && a.orientation_error(&b) < 1e-14);
    }
    // Frames: one per joint; the last frame carries the tool offset to the tip.
    let q = [0.1, 0.2, 0.3, 0.4, 0.5];
    let mut frames = [Pose::identity(); 5];
    let tip = c.fk_frames(&q, &mut frames).unwrap();
    assert!((tip.position - (frames[4].position + frames[4].approach() * g.l5)).norm() < 1e-14);
}

struct Rate {
    solved: usize,
    total: usize,
}

fn success_rate(chain: &Chain, n: usize, pose: bool, seed: u64) -> Rate {
    let mut rng = DeterministicRng::new(seed);
    let opts = NumericIkOptions::default();
    let mut solved = 0;
    for _ in 0..n {
        let q = chain.random_configuration(&mut rng);
        let target_pose = chain.fk(&q).unwrap();
        let target = if pose {
            IkTarget::Pose(target_pose)
        } else {
            IkTarget::Position(target_pose.position)
        };
        match chain.ik(&target, &chain.home(), &opts) {
            Ok(s) => {
                assert!(chain.within_limits(&s.q));
                let got = chain.fk(&s.q).unwrap();
                assert!(got.position_error(&target_pose) <= 1e-6);
                if pose {
                    assert!(got.orientation_error(&target_pose) <= 1e-6);
                }
                solved += 1;
            }
            Err(e) => {
                assert!(e.is_out_of_reach(), "{e:?}");
                if let ChainIkError::NotConverged {
                    position_error,
                    orientation_error,
                    best,
                } = e
                {
                    assert!(position_error.is_finite() && orientation_error.is_finite());
                    assert!(chain.within_limits(&best));
                }
            }
        }
    }
    Rate { solved, total: n }
}

fn check_rate(chain: &Chain, n: usize, pose: bool, seed: u64) {
    let r = success_rate(chain, n, pose, seed);
    let pct = 100.0 * r.solved as f64 / r.total as f64;
    println!(
        "{} {}: {}/{} = {pct:.1} % solved within 1e-6 m{}",
        chain.name(),
        if pose { "pose" } else { "position" },
        r.solved,
        r.total,
        if pose { " / 1e-6 rad" } else { "" },
    );
    assert!(pct >= 99.0, "{pct} %");
}

#[test]
fn numeric_ik_solves_99_percent_6dof_pose() {
    check_rate(&Chain::default_6dof(), 300, true, 1);
}

#[test]
fn numeric_ik_solves_99_percent_7dof_pose() {
    check_rate(&Chain::default_7dof(), 300, true, 2);
}

#[test]
fn numeric_ik_solves_99_percent_position_only() {
    check_rate(&Chain::default_6dof(), 100, false, 3);
    check_rate(&Chain::default_7dof(), 100, false, 4);
}

#[test]
fn numeric_ik_solves_the_5dof_pioneer_chain() {
    check_rate(&Chain::pioneer5(), 150, true, 5);
    check_rate(&Chain::pioneer5(), 100, false, 6);
}

/// A wrist joint that the solver drives onto a limit, while the target lies across the
/// gap of its range, crosses the gap and the first attempt converges (it used to stall
/// there and cost two restarts).
#[test]
fn a_joint_stalled_on_a_limit_crosses_its_gap() {
    let c = Chain::default_7dof();
    let mut goal = c.home();
    goal[6] = -1.5;
    let mut seed = c.home();
    seed[6] = 2.85;
    let target = c.fk(&goal).unwrap();
    let s = c
        .ik(&IkTarget::Pose(target), &seed, &NumericIkOptions::default())
        .unwrap();
    assert_eq!(s.restarts, 0);
    assert!(s.q[6] < 0.0, "j7 {} stayed on the seed's side", s.q[6]);
    assert!(c.within_limits(&s.q));
    let got = c.fk(&s.q).unwrap();
    assert!(got.position_error(&target) <= 1e-6);
    assert!(got.orientation_error(&target) <= 1e-6);
}

/// Issue 16: targets at the hard places of the workspace still solve, pose and
/// position, from home and from a far seed, each answer inside the limits and checked
/// by the FK: the 6-joint arm's wrist singularity (wrist_2 = 0, wrist_1 and wrist_3
/// aligned), its straight and folded elbow, and the 7-joint arm with joints on their
/// limits (j2 at ±101°, j4 at −4° next to the straight elbow, j6 at both ends) or
/// next to its wrist singularity.
#[test]
fn hard_targets_near_singularities_and_limits_solve() {
    let c6 = Chain::default_6dof();
    let c7 = Chain::default_7dof();
    let cases: [(&Chain, &[f64]); 10] = [
        (&c6, &[0.3, -1.2, 1.1, -0.5, 0.0, 0.2]),
        (&c6, &[-2.0, -0.7, 0.0, 1.0, 0.9, -0.4]),
        (&c6, &[1.1, -2.2, 3.1, -1.7, 1e-7, 2.5]),
        (&c6, &[0.0, -FRAC_PI_2, 0.0, -FRAC_PI_2, 0.0, 0.0]),
        (&c7, &[0.3, 1.7628, -0.4, -0.0698, 0.2, 1.9, 0.4]),
        (&c7, &[-1.0, -1.7628, 0.8, -1.5, -0.5, -0.0175, 1.2]),
        (&c7, &[2.0, 0.4, -2.8973, -0.0698, 2.8973, 3.7525, -2.8973]),
        (&c7, &[0.0, 0.0, 0.0, -0.0698, 0.0, -0.0175, 0.0]),
        (&c7, &[-2.8973, 1.2, 0.0, -3.0718, 0.0, 3.7525, 2.8973]),
        // Next to the wrist singularity (j5 ≈ 0): the attempt used to be stopped as
        // stalled 2e-6 from the target.
        (
            &c7,
            &[
                -1.3534127530408548,
                -0.32881995226685845,
                2.7381185873814045,
                -0.4651073065845237,
                0.00020768662511949643,
                1.6807073861199362,
                -0.18333754869551777,
            ],
        ),
    ];
    let o = NumericIkOptions::default();
    for (chain, q) in cases {
        let target = chain.fk(q).unwrap();
        let mut far = chain.home();
        for (v, j) in far.iter_mut().zip(chain.joints()) {
            *v = 0.8 * j.max + 0.2 * j.min;
        }
        for seed in [chain.home(), far] {
            for pose in [true, false] {
                let goal = if pose {
                    IkTarget::Pose(target)
                } else {
                    IkTarget::Position(target.position)
                };
                let s = chain
                    .ik(&goal, &seed, &o)
                    .unwrap_or_else(|e| panic!("{} {q:?} pose {pose}: {e:?}", chain.name()));
                assert!(chain.within_limits(&s.q));
                let got = chain.fk(&s.q).unwrap();
                assert!(got.position_error(&target) <= o.position_tolerance);
                if pose {
                    assert!(got.orientation_error(&target) <= o.orientation_tolerance);
                }
            }
        }
    }
}

#[test]
fn numeric_ik_is_deterministic() {
    let c = Chain::default_7dof();
    let target = IkTarget::Pose(c.fk(&[0.3, 0.2, -0.4, -1.5, 0.2, 1.9, 0.4]).unwrap());
    let o = NumericIkOptions::default();
    assert_eq!(c.ik(&target, &c.home(), &o), c.ik(&target, &c.home(), &o));
}

#[test]
fn reach_at_inside_and_beyond() {
    // Pioneer chain: stretched along +x is exactly the reach bound L1+L2+L4+L5.
    let c = Chain::pioneer5();
    let o = NumericIkOptions::default();
    let reach = 0.47971;
    assert!((c.reach_bound() - reach).abs() < 1e-12);
    for x in [reach, reach - 1e-7, reach - 1e-3] {
        let s = c
            .ik(
                &IkTarget::Position(Vector3::new(x, 0.0, 0.0)),
                &c.home(),
                &o,
            )
            .unwrap_or_else(|e| panic!("{x}: {e:?}"));
        assert!(s.position_error <= 1e-6);
    }
    for x in [reach + 1e-5, reach + 0.01, 10.0, 1e300] {
        let e = c
            .ik(
                &IkTarget::Position(Vector3::new(x, 0.0, 0.0)),
                &c.home(),
                &o,
            )
            .unwrap_err();
        assert!(matches!(e, ChainIkError::OutOfReach { distance, .. } if distance.is_finite()));
    }
    // The 6-joint arm, far away in every direction.
    let c6 = Chain::default_6dof();
    let first_joint = Vector3::new(0.0, 0.0, 0.089159);
    for d in [
        Vector3::x(),
        -Vector3::y(),
        Vector3::z(),
        Vector3::new(1.0, 1.0, -1.0),
    ] {
        let p = first_joint + d.normalize() * (c6.reach_bound() + 0.01);
        let e = c6.ik(&IkTarget::Position(p), &c6.home(), &o).unwrap_err();
        assert!(matches!(e, ChainIkError::OutOfReach { .. }), "{e:?}");
    }
}

#[test]
fn beyond_the_true_reach_or_the_limits_is_reported_with_a_residual() {
    let c = Chain::pioneer5();
    let o = NumericIkOptions {
        max_restarts: 5,
        ..NumericIkOptions::default()
    };
    // Inside the (loose) bound, but behind the arm: needs |θ1| > π/2.
    let e = c
        .ik(
            &IkTarget::Position(Vector3::new(-0.4, 0.0, 0.0)),
            &c.home(),
            &o,
        )
        .unwrap_err();
    match e {
        ChainIkError::NotConverged {
            position_error,
            best,
            ..
        } => {
            assert!(position_error > 0.1 && position_error.is_finite());
            assert!(c.within_limits(&best));
        }
        other => panic!("{other:?}"),
    }
    assert!(e.is_out_of_reach());
    // A 5-DOF arm cannot roll about an arbitrary axis: a rolled frame does not converge.
    let t = c.fk(&[0.3, 0.4, 0.5, -0.2, 0.6]).unwrap();
    let rolled = Pose::new(
        t.position,
        t.rotation * Rotation3::from_axis_angle(&Vector3::x_axis(), 0.3),
    );
    let e = c.ik(&IkTarget::Pose(rolled), &c.home(), &o).unwrap_err();
    assert!(
        matches!(e, ChainIkError::NotConverged { orientation_error, .. } if orientation_error > 1e-3)
    );
}

#[test]
fn bad_input_is_an_error() {
    let c = Chain::default_6dof();
    let o = NumericIkOptions::default();
    let t = IkTarget::Position(Vector3::new(0.3, 0.2, 0.3));
    assert!(matches!(
        c.ik(&t, &[0.0; 5], &o),
        Err(ChainIkError::WrongJointCount {
            expected: 6,
            got: 5
        })
    ));
    assert_eq!(
        c.ik(
            &IkTarget::Position(Vector3::new(f64::NAN, 0.0, 0.0)),
            &c.home(),
            &o
        ),
        Err(ChainIkError::NonFinite)
    );
    let mut seed = c.home();
    seed[2] = f64::INFINITY;
    assert_eq!(c.ik(&t, &seed, &o), Err(ChainIkError::NonFinite));
    let bad = NumericIkOptions {
        position_tolerance: -1.0,
        ..o
    };
    assert_eq!(c.ik(&t, &c.home(), &bad), Err(ChainIkError::InvalidOptions));
    assert_eq!(
        c.fk(&[0.0; 3]),
        Err(ChainFkError::WrongJointCount {
            expected: 6,
            got: 3
        })
    );
    assert_eq!(c.fk(&[f64::NAN; 6]), Err(ChainFkError::NonFinite));
    // Seeds outside the limits are clamped, not rejected.
    let s = c.ik(&t, &[100.0; 6], &o).unwrap();
    assert!(c.within_limits(&s.q));
}

#[test]
fn chain_files_are_validated() {
    let joint = |extra: &str| {
        format!(
            "name = \"x\"\n[[joints]]\nname = \"j\"\ntype = \"rotary\"\naxis = [0.0, 0.0, 1.0]\nmin = -1.0\nmax = 1.0\nmax_speed = 1.0\n{extra}"
        )
    };
    assert!(Chain::from_toml_str(&joint("")).is_ok());
    let invalid = |text: &str| {
        matches!(
            Chain::from_toml_str(text),
            Err(ChainLoadError::Invalid { .. })
        )
    };
    assert!(invalid("name = \"x\"\njoints = []\n"));
    assert!(invalid(&joint("home = 2.0\n")));
    assert!(invalid(&joint(
        "[gripper]\nstroke = -1.0\nmax_speed = 1.0\n"
    )));
    assert!(invalid(&joint("").replace("min = -1.0", "min = 2.0")));
    assert!(invalid(
        &joint("").replace("axis = [0.0, 0.0, 1.0]", "axis = [0.0, 0.0, 0.0]")
    ));
    assert!(invalid(
        &joint("").replace("max_speed = 1.0", "max_speed = nan")
    ));
    let seventeen = (0..17).fold("name = \"x\"\n".to_owned(), |s, i| {
        s + &format!("[[joints]]\nname = \"j{i}\"\ntype = \"linear\"\naxis = [1.0, 0.0, 0.0]\nmin = 0.0\nmax = 0.1\nmax_speed = 0.1\n")
    });
    assert!(invalid(&seventeen));
    assert!(matches!(
        Chain::from_toml_str(&joint("").replace("rotary", "spherical")),
        Err(ChainLoadError::Parse(_))
    ));
    assert!(matches!(
        Chain::from_toml_str(&joint("colour = 3\n")),
        Err(ChainLoadError::Parse(_))
    ));
    assert!(matches!(
        Chain::from_file("/nonexistent/chain.toml"),
        Err(ChainLoadError::Io { .. })
    ));
}

#[test]
fn linear_joints_work() {
    // A gantry: x, y, z slides and a yaw.
    let text = r#"
name = "gantry"
[[joints]]
name = "x"
type = "linear"
axis = [1.0, 0.0, 0.0]
min = 0.0
max = 1.0
max_speed = 0.5
[[joints]]
name = "y"
type = "linear"
axis = [0.0, 1.0, 0.0]
min = 0.0
max = 1.0
max_speed = 0.5
[[joints]]
name = "z"
type = "linear"
axis = [0.0, 0.0, -1.0]
min = 0.0
max = 0.5
max_speed = 0.5
[[joints]]
name = "yaw"
type = "rotary"
axis = [0.0, 0.0, 1.0]
min = -3.0
max = 3.0
max_speed = 2.0
[tool]
xyz = [0.1, 0.0, 0.0]
"#;
    let c = Chain::from_toml_str(text).unwrap();
    let p = c.fk(&[0.2, 0.3, 0.1, std::f64::consts::FRAC_PI_2]).unwrap();
    assert!((p.position - Vector3::new(0.2, 0.4, -0.1)).norm() < 1e-12);
    let s = c
        .ik(
            &IkTarget::Pose(p),
            &[0.5, 0.5, 0.0, 0.0],
            &NumericIkOptions::default(),
        )
        .unwrap();
    assert!((s.q[0] - 0.2).abs() < 1e-6 && (s.q[3] - std::f64::consts::FRAC_PI_2).abs() < 1e-6);
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 64,
        failure_persistence: None,
        rng_algorithm: proptest::test_runner::RngAlgorithm::ChaCha,
        rng_seed: proptest::test_runner::RngSeed::Fixed(0x11B3),
        ..ProptestConfig::default()
    })]

    /// The chain FK frame is always orthonormal and right-handed.
    #[test]
    fn chain_fk_frames_are_rotations(seed in any::<u64>()) {
        for c in [Chain::default_6dof(), Chain::default_7dof()] {
            let q = c.random_configuration(&mut DeterministicRng::new(seed));
            let m = *c.fk(&q).unwrap().rotation.matrix();
            prop_assert!((m.transpose() * m - nalgebra::Matrix3::identity()).norm() < 1e-12);
            prop_assert!((m.determinant() - 1.0).abs() < 1e-12);
        }
    }
}
