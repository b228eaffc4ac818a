//! Unit tests of the closed-form Pioneer IK (a file of their own: ik.rs stays under ~800
//! lines).
use super::*;
use crate::chain::DeterministicRng;
use crate::pioneer::JointLimit;

fn limit_sets() -> [[JointLimit; PIONEER_DOF]; 3] {
    let l = JointLimit::new;
    [
        PioneerGeometry::default().limits,
        [
            l(-2.6, 2.6),
            l(-1.2, 2.0),
            l(-2.6, 2.6),
            l(-3.0, 3.0),
            l(-1.8, 1.8),
        ],
        // Narrow, one-sided, beyond ±π, and a full turn and more.
        [
            l(0.3, 0.9),
            l(-3.5, -2.9),
            l(2.0, 4.0),
            l(-7.0, 7.0),
            l(-0.2, 4.5),
        ],
    ]
}

/// The arcs accept the angles `fit_angle_to_limits` fits, and only those, away
/// from round-off at the ends.
#[test]
fn limit_arcs_agree_with_fit_angle_to_limits() {
    for limits in limit_sets() {
        let g = PioneerGeometry {
            limits,
            ..PioneerGeometry::default()
        };
        let arcs = g.limit_arcs();
        for (i, l) in limits.iter().enumerate() {
            for k in -2000..=2000 {
                let angle = k as f64 * 0.005 + 0.0001;
                let ends = [l.min, l.max];
                let near_an_end = ends.iter().any(|e| {
                    let d = wrap_pi(angle - e);
                    d.abs() < 1e-7
                });
                if near_an_end {
                    continue;
                }
                let (s, c) = angle.sin_cos();
                let want = fit_angle_to_limits(angle, l.min, l.max, 0.0, LIMIT_TOLERANCE).is_some();
                assert_eq!(
                    arcs.contains(i, s, c),
                    want,
                    "joint {i} {l:?} angle {angle}"
                );
            }
        }
    }
}

/// `reach_with_approach` says what the scored candidates and the exact selection
/// say: `Within` when an exact in-limit candidate exists, `Outside` when exact
/// ones exist outside the limits only, `None` when there is none; with
/// `in_limits_only`, `Within` or `None`.
#[test]
fn reach_with_approach_agrees_with_the_scored_candidates() {
    let mut rng = DeterministicRng::new(0x16);
    let strict = PioneerIkOptions {
        position_tolerance: EXACT_POSITION,
        orientation_tolerance: EXACT_ORIENTATION,
        ..PioneerIkOptions::default()
    };
    let mut seen = [0usize; 3];
    for limits in limit_sets() {
        let g = PioneerGeometry {
            limits,
            ..PioneerGeometry::default()
        };
        let arcs = g.limit_arcs();
        for _ in 0..3000 {
            let p = Vector3::new(
                rng.uniform(-0.45, 0.45),
                rng.uniform(-0.45, 0.45),
                rng.uniform(-0.45, 0.45),
            );
            let a = Vector3::new(
                rng.uniform(-1.0, 1.0),
                rng.uniform(-1.0, 1.0),
                rng.uniform(-1.0, 1.0),
            )
            .normalize();
            let current: Theta = std::array::from_fn(|_| rng.uniform(-1.0, 1.0));
            let want = match g
                .candidates(&p, WristGoal::Approach(&a), &current, EXACT_POSITION, false)
                .and_then(|c| c.select(&current, &strict))
            {
                Ok(_) => Reach::Within,
                Err(PioneerIkError::OutsideJointLimits) => Reach::Outside,
                Err(_) => Reach::None,
            };
            let got = g.reach_with_approach(&p, &a, &current, EXACT_POSITION, false, &arcs);
            assert_eq!(got, want, "{p:?} {a:?} {limits:?}");
            let pruned = g.reach_with_approach(&p, &a, &current, EXACT_POSITION, true, &arcs);
            let want_pruned = if want == Reach::Within {
                Reach::Within
            } else {
                Reach::None
            };
            assert_eq!(pruned, want_pruned);
            seen[want as usize] += 1;
        }
    }
    // Every answer occurs.
    assert!(seen.iter().all(|n| *n > 100), "{seen:?}");
}
