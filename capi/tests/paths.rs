//! Limb paths and gripper goals from C and C++ (issue 28): `tests/c/paths.c` and
//! `tests/c/paths.cpp` on simarm with its block: a line reached, a line out of reach
//! refused with where (C), a PTP to the block, a goal that stalls on it with
//! OBJECT_PRESENT.

mod common;
use common::*;

#[test]
fn c_draws_a_line_is_told_where_a_path_is_refused_and_grips_the_block() {
    let dir = scratch("paths");
    let exe = dir.join("paths");
    compile("paths.c", &exe, &[]);
    let sim = SimArmRun::start([0.36, 0.06]);
    let o = run_in(&sim, &exe, &[]);
    let out = text(&o.stdout);
    assert!(o.status.success(), "{out}\n{}", text(&o.stderr));
    assert!(
        out.contains("line: reached the goal within the tolerance"),
        "{out}"
    );
    assert!(out.contains("refused: OUT_OF_REACH at "), "{out}");
    assert!(
        out.contains("ptp: reached the goal within the tolerance"),
        "{out}"
    );
    assert!(out.contains("goal: STALLED OBJECT_PRESENT"), "{out}");
}

#[test]
fn cpp_moves_on_a_line_and_a_ptp_and_grips_the_block() {
    let dir = scratch("paths_cpp");
    let exe = dir.join("paths_cpp");
    compile("paths.cpp", &exe, &[]);
    let sim = SimArmRun::start([0.36, 0.06]);
    let o = run_in(&sim, &exe, &[]);
    let out = text(&o.stdout);
    assert!(o.status.success(), "{out}\n{}", text(&o.stderr));
    assert!(
        out.contains("ptp: reached the goal within the tolerance"),
        "{out}"
    );
    assert!(
        out.contains("line: reached the goal within the tolerance"),
        "{out}"
    );
    assert!(out.contains("goal: STALLED OBJECT_PRESENT"), "{out}");
}
