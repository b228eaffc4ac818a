//! Pioneer closed-form kinematics, SETPOSE: the orientation the driver takes and how much it
//! adjusted, the nearest solution (not the flipped wrist), refusals with their cause, the
//! tolerances, and SETPOSITION's scan against a reference search.

use std::f64::consts::{FRAC_PI_2, PI};

use limber_kinematics::chain::DeterministicRng;
use limber_kinematics::fit_angle_to_limits;
use limber_kinematics::pioneer::*;
use nalgebra::Vector3;

mod pioneer_support;
use pioneer_support::{geom, opts, v};

/// The SETPOSE tolerances the Pioneer driver uses by default (1 mm, 1°).
fn pose_opts() -> PioneerIkOptions {
    PioneerIkOptions {
        position_tolerance: 1e-3,
        orientation_tolerance: 1f64.to_radians(),
        ..PioneerIkOptions::default()
    }
}

fn setpose(p: [f64; 3], a: [f64; 3], o: [f64; 3]) -> Result<PoseSolution, PioneerIkError> {
    geom().solve_setpose_nearest(&v(p), &v(a), &v(o), &[0.0; 5], &pose_opts())
}

#[test]
fn setpose_takes_the_readme_orientation_and_says_how_much_it_adjusted() {
    // The README's example: two decimals, about 1e-3 rad from a frame the arm can hold.
    let s = setpose([0.38, 0.1, 0.22], [0.0, 0.0, -1.0], [0.94, 0.34, 0.0]).unwrap();
    eprintln!("readme: {s:?}");
    assert!(s.adjusted(), "{s:?}");
    assert!(s.adjustment < 0.01, "{s:?}");
    assert!(s.position_error < 1e-9 && s.approach_error < 1e-9, "{s:?}");
    // Four decimals: still adjusted, by less.
    let s4 = setpose([0.38, 0.1, 0.22], [0.0, 0.0, -1.0], [0.9398, 0.3417, 0.0]).unwrap();
    eprintln!("4 decimals: {s4:?}");
    assert!(s4.adjusted() && s4.adjustment < s.adjustment, "{s4:?}");
    // Six decimals: round-off, carried out as asked.
    let s6 = setpose(
        [0.38, 0.1, 0.22],
        [0.0, 0.0, -1.0],
        [0.939793, 0.341743, 0.0],
    )
    .unwrap();
    eprintln!("6 decimals: {s6:?}");
    assert!(!s6.adjusted(), "{s6:?}");
    // The achieved frame is the one reported: position and approach as asked.
    assert!((s.achieved.position - v([0.38, 0.1, 0.22])).norm() < 1e-9);
    assert!((s.achieved.approach() - v([0.0, 0.0, -1.0])).norm() < 1e-9);
    // The `limber limb --help` example.
    let h = setpose([0.4, 0.0, 0.2], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]).unwrap();
    assert!(!h.adjusted(), "{h:?}");
    // Straight down at 0.3 0 0.2 needs the elbow folded by about 130°: beyond its limit.
    let e = setpose([0.3, 0.0, 0.2], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0]).unwrap_err();
    assert!(matches!(e, PioneerIkError::OutsideJointLimits), "{e:?}");
}

#[test]
fn setpose_nearest_picks_the_nearest_orientation_not_the_flipped_wrist() {
    // With limits that let the wrist roll half a turn, the opposite orientation is held
    // by the other wrist, adjusted as little as the original.
    let mut g = geom();
    g.limits[3] = JointLimit::new(-PI, PI);
    g.limits[4] = JointLimit::new(-PI, PI);
    let (p, a) = (v([0.38, 0.1, 0.22]), v([0.0, 0.0, -1.0]));
    let s = g
        .solve_setpose_nearest(&p, &a, &v([-0.94, -0.34, 0.0]), &[0.0; 5], &pose_opts())
        .unwrap();
    assert!(s.adjusted() && s.adjustment < 0.01, "{s:?}");
    let s2 = g
        .solve_setpose_nearest(&p, &a, &v([0.94, 0.34, 0.0]), &[0.0; 5], &pose_opts())
        .unwrap();
    assert!(s2.adjustment < 0.01, "{s2:?}");
    assert_ne!(s.candidate.branch.wrist, s2.candidate.branch.wrist);
    // A quarter turn away: the adjustment is about π/2 whichever wrist.
    let q = setpose([0.38, 0.1, 0.22], [0.0, 0.0, -1.0], [-0.34, 0.94, 0.0]).unwrap();
    assert!((q.adjustment - FRAC_PI_2).abs() < 0.01, "{q:?}");
}

#[test]
fn setpose_nearest_refuses_what_cannot_be_reached_with_its_cause() {
    let e = setpose([1.5, 0.0, 0.3], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]).unwrap_err();
    assert!(matches!(e, PioneerIkError::OutOfReach { .. }), "{e:?}");
    // Behind the robot: reachable only with the base yawed beyond ±90°.
    let e = setpose([-0.1, 0.0, 0.35], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]).unwrap_err();
    assert!(matches!(e, PioneerIkError::OutsideJointLimits), "{e:?}");
}

#[test]
fn setpose_nearest_honours_its_tolerances() {
    let g = geom();
    // Just beyond the stretched reach: within 1 mm accepted, with 1 µm refused.
    let max = g.wrist_reach().1;
    let base = g.base_offset;
    let p = base + v([g.l1 + max + 0.0005 + g.l5, 0.0, 0.0]);
    let (a, o) = (v([1.0, 0.0, 0.0]), v([0.0, 0.0, 1.0]));
    let s = g
        .solve_setpose_nearest(&p, &a, &o, &[0.0; 5], &pose_opts())
        .unwrap();
    assert!(s.position_error > 4e-4 && s.position_error <= 1e-3, "{s:?}");
    let tight = PioneerIkOptions {
        position_tolerance: 1e-6,
        ..pose_opts()
    };
    let e = g
        .solve_setpose_nearest(&p, &a, &o, &[0.0; 5], &tight)
        .unwrap_err();
    assert!(matches!(e, PioneerIkError::OutOfReach { .. }), "{e:?}");
}

/// Steps 1 to 3 of SETPOSITION as they were written before the search tested the
/// closed form without the FK (issue 16): every approach scored by the FK and the
/// selection, the plane scanned outward in `approach_search_step`, the first feasible
/// elevation refined by bisection towards the preferred one to 1e-9 rad, then the
/// yaw-limit circles in a full sort. `None` when none of these reaches the target
/// (the cones of step 4 then decide).
fn reference_search(
    g: &PioneerGeometry,
    p: &Vector3<f64>,
    preferred: &Vector3<f64>,
    current: &Theta,
    o: &PioneerIkOptions,
) -> Option<(Theta, u8)> {
    let strict = PioneerIkOptions {
        position_tolerance: EXACT_POSITION,
        orientation_tolerance: EXACT_ORIENTATION,
        ..*o
    };
    let attempt = |a: &Vector3<f64>| {
        g.approach_candidates(p, a, current, &strict)
            .ok()?
            .select(current, &strict)
            .ok()
            .map(|c| c.theta)
    };
    if let Some(t) = attempt(preferred) {
        return Some((t, 1));
    }
    let h = p.x.hypot(p.y);
    let yaw = if h > 1e-12 {
        p.y.atan2(p.x)
    } else {
        current[0]
    };
    let radial = Vector3::new(yaw.cos(), yaw.sin(), 0.0);
    let in_plane = |phi: f64| radial * phi.cos() + Vector3::z() * phi.sin();
    let phi0 = preferred.z.atan2(preferred.dot(&radial));
    let step = o.approach_search_step;
    let steps = (PI / step).ceil() as usize;
    for k in 0..=steps {
        for sign in [1.0, -1.0] {
            let phi = phi0 + sign * (k as f64 * step).min(PI);
            if let Some(found) = attempt(&in_plane(phi)) {
                if k == 0 {
                    return Some((found, 2));
                }
                let mut good = (phi, found);
                let mut bad = phi0 + sign * ((k - 1) as f64 * step);
                while (good.0 - bad).abs() > 1e-9 {
                    let mid = 0.5 * (good.0 + bad);
                    match attempt(&in_plane(mid)) {
                        Some(t) => good = (mid, t),
                        None => bad = mid,
                    }
                }
                return Some((good.1, 2));
            }
            if k == 0 {
                break;
            }
        }
    }
    // 3. θ1 held on a yaw limit (when the plane, or its opposite, is beyond the
    //    limits): every approach on both circles, scored, fully sorted, the first that
    //    an exact in-limit solution attains.
    let l = g.limits[0];
    let yaw_ok =
        |y: f64| fit_angle_to_limits(y, l.min, l.max, current[0], LIMIT_TOLERANCE).is_some();
    if yaw_ok(yaw) && yaw_ok(yaw + PI) {
        return None;
    }
    let per_circle = 2 * steps;
    let mut scored = vec![];
    for (circle, t1) in [l.min, l.max].into_iter().enumerate() {
        let normal = Vector3::new(-t1.sin(), t1.cos(), 0.0);
        let off = p.dot(&normal);
        if off.abs() >= g.l5 {
            continue;
        }
        let r = (g.l5 * g.l5 - off * off).sqrt();
        let centre = p - normal * off;
        let e1 = Vector3::new(t1.cos(), t1.sin(), 0.0);
        for j in 0..per_circle {
            let psi = j as f64 * step;
            let w = centre + (e1 * psi.cos() + Vector3::z() * psi.sin()) * r;
            let a = (p - w) / g.l5;
            scored.push((-a.dot(preferred), circle * per_circle + j, a));
        }
    }
    scored.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    scored
        .iter()
        .find_map(|(_, _, a)| attempt(a))
        .map(|t| (t, 3))
}

/// Issue 16: the SETPOSITION search that tests each approach by the closed form alone
/// and scores only the one it keeps finds the same joints as the search that scored
/// every approach, on a grid of reachable positions (FK of a grid of joint angles),
/// and of random ones, with the default limits and with wide ones (where the base can
/// turn round), for
/// several current configurations and preferences, at the default search step and a
/// coarser one; where neither the plane nor the
/// yaw limits do, its answer still reaches the position inside the limits.
#[test]
fn setposition_finds_what_the_scored_scan_found() {
    let wide = PioneerGeometry {
        limits: [
            JointLimit::new(-2.6, 2.6),
            JointLimit::new(-1.2, 2.0),
            JointLimit::new(-2.6, 2.6),
            JointLimit::new(-3.0, 3.0),
            JointLimit::new(-1.8, 1.8),
        ],
        ..geom()
    };
    // The default step (its cosines and sines made once per process) and a coarser
    // one (made on the stack by each search).
    let coarse = PioneerIkOptions {
        approach_search_step: 3f64.to_radians(),
        ..opts()
    };
    let mut by_step = [0usize; 4];
    for (g, o) in [
        (geom(), opts()),
        (wide, opts()),
        (geom(), coarse),
        (wide, coarse),
    ] {
        let frac = [0.07, 0.36, 0.64, 0.93];
        let at = |i: usize, f: f64| g.limits[i].min + f * (g.limits[i].max - g.limits[i].min);
        let currents = [
            [0.0; 5],
            [at(0, 0.8), at(1, 0.3), at(2, 0.6), 0.0, at(4, 0.2)],
        ];
        let grid = frac
            .iter()
            .flat_map(|a| frac.iter().map(move |b| (*a, *b)))
            .flat_map(|(a, b)| frac.iter().map(move |c| (a, b, *c)))
            .flat_map(|(a, b, c)| [0.2, 0.85].map(|d| [a, b, c, 0.5, d]));
        // And random ones, where some positions have no in-plane approach.
        let mut rng = DeterministicRng::new(0xB0A7_5EED);
        let random: Vec<[f64; 5]> = (0..250)
            .map(|_| std::array::from_fn(|_| rng.next_f64()))
            .collect();
        for (n, f) in grid.chain(random).enumerate() {
            let theta: Theta = std::array::from_fn(|i| at(i, f[i]));
            let p = g.fk(&theta).unwrap().position;
            let current = currents[n % 2];
            let preferences = [
                (
                    ApproachPreference::Current,
                    g.fk(&current).unwrap().approach(),
                ),
                (ApproachPreference::Down, -Vector3::z()),
            ];
            for (preference, preferred) in preferences {
                let got = g.solve_position(&p, preference, &current, &o);
                match reference_search(&g, &p, &preferred, &current, &o) {
                    Some((want, step)) => {
                        let got = got.unwrap().theta;
                        let d = got.iter().zip(&want).map(|(a, b)| (a - b).abs());
                        assert!(d.fold(0.0, f64::max) < 1e-6, "{p:?}: {got:?} vs {want:?}");
                        by_step[usize::from(step) - 1] += 1;
                    }
                    None => {
                        let got = got.unwrap().theta;
                        assert!(g.within_limits(&got));
                        assert!((g.fk(&got).unwrap().position - p).norm() <= 1e-6);
                        by_step[3] += 1;
                    }
                }
            }
        }
    }
    // The preferred approach, the plane and the yaw limits each answer some targets.
    println!("answered by step 1, 2, 3, later: {by_step:?}");
    assert!(by_step[..3].iter().all(|n| *n > 10), "{by_step:?}");
}
