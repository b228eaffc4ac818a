//! A joint trajectory from C (issue 28): `tests/c/traj.c` against simarm: followed to its
//! goal within the tolerance (`limber_actarray_wait_done`), one whose times go backwards
//! refused with the reason before anything is sent, one naming a joint the arm lacks
//! refused by the driver with the cause.

mod common;
use common::*;

#[test]
fn c_follows_a_joint_trajectory_and_is_told_why_a_bad_one_is_refused() {
    let dir = scratch("traj");
    let exe = dir.join("traj");
    compile("traj.c", &exe, &[]);
    let sim = SimArmRun::start([0.5, -0.3]);
    let o = run_in(&sim, &exe, &[]);
    let out = text(&o.stdout);
    assert!(o.status.success(), "{out}\n{}", text(&o.stderr));
    assert!(
        out.contains("reached: reached the goal within the tolerance"),
        "{out}"
    );
    let line = out.lines().find(|l| l.starts_with("error ")).expect(&out);
    let v: Vec<f64> = line.split(' ').filter_map(|w| w.parse().ok()).collect();
    assert!(v[0] <= v[1] && v[1] == 0.001, "{out}");
    assert!(
        out.contains("invalid: point 1: time 0.5 s is not after the previous point's 1 s"),
        "{out}"
    );
    assert!(out.contains("unknown joint: UNKNOWN_JOINT"), "{out}");
}
