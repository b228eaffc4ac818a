//! How a motion ended (issue 28), from C and C++: `tests/c/done.c` and `tests/c/done.cpp`
//! against the emulated Pioneer: a move ends reached with its final error within the
//! tolerance (and the core's sentence); a move replaced at once ends preempted.

mod common;
use common::*;

/// The `error E tolerance T` line of a program's output.
fn error_and_tolerance(out: &str) -> (f64, f64) {
    let line = out
        .lines()
        .find(|l| l.starts_with("error "))
        .unwrap_or_else(|| panic!("no error line in:\n{out}"));
    let v: Vec<f64> = line.split(' ').filter_map(|w| w.parse().ok()).collect();
    (v[0], v[1])
}

#[test]
fn c_and_cpp_wait_for_a_motions_result() {
    let dir = scratch("done");
    let (c, cpp) = (dir.join("done"), dir.join("done_cpp"));
    compile("done.c", &c, &[]);
    compile("done.cpp", &cpp, &[]);
    let p = Pioneer::start();
    for exe in [&c, &cpp] {
        let o = run_in(&p, exe, &[]);
        let out = text(&o.stdout);
        assert!(o.status.success(), "{out}\n{}", text(&o.stderr));
        assert!(
            out.contains("reached: reached the goal within the tolerance"),
            "{out}"
        );
        let (error, tolerance) = error_and_tolerance(&out);
        assert!(error <= tolerance && tolerance > 0.0, "{out}");
        if exe == &c {
            assert!(out.contains("first: PREEMPTED"), "{out}");
        }
    }
}
