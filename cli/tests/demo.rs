//! `limber demo` end to end: it starts the robot, runs the pick-a-block program, prints a
//! summary and exits 0.

use limber_services::Domain;

mod common;
use common::{limber, stderr, stdout};

#[test]
fn demo_on_the_emulated_pioneer_exits_zero_with_a_summary() {
    let d = Domain::unique_for_test();
    let o = limber(d.name(), &["demo", "--fast"]);
    let out = stdout(&o);
    assert!(o.status.success(), "{out}\n{}", stderr(&o));
    assert!(out.contains("[ 1/11] home"), "{out}");
    assert!(out.contains("[11/11] home again"), "{out}");
    assert!(
        out.contains("picked the block at (0.38, 0.10) and put it down at (0.38, -0.10): 11 steps"),
        "{out}"
    );
    assert!(
        out.contains("driver: limber-emulator Pioneer p3dx"),
        "{out}"
    );
    assert!(out.trim_end().ends_with("done."), "{out}");
}

#[test]
fn demo_reports_an_unreachable_block_and_fails() {
    let d = Domain::unique_for_test();
    let o = limber(d.name(), &["demo", "--fast", "--block", "1.5", "0"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("out of reach"), "{}", stderr(&o));
}

#[test]
fn the_same_program_runs_on_simarm() {
    let d = Domain::unique_for_test();
    let o = limber(d.name(), &["demo", "--on", "simarm", "--fast"]);
    let out = stdout(&o);
    assert!(o.status.success(), "{out}\n{}", stderr(&o));
    assert!(out.contains("started simarm"), "{out}");
    assert!(out.contains("[11/11] home again"), "{out}");
    assert!(out.contains("11 steps"), "{out}");
}
