//! `--wait` (issue 28): the CLI waits for a command's motion to end and says how, with the
//! largest final error, against `limber simarm`; a move cut short by another exits 1 with
//! the result.

use std::time::Duration;

use limber_services::Domain;

mod common;
use common::{Bg, limber, stderr, stdout};

#[test]
fn wait_says_the_result_and_the_final_error() {
    let d = Domain::unique_for_test();
    let dom = d.name();
    // Slower than real time: the long move below is still running when the stop comes.
    let mut sim = Bg::spawn(dom, &["simarm", "--time-scale", "0.2"]);
    sim.line(|l| l.ends_with("ready"));
    let o = limber(
        dom,
        // Up (-): +0.4 would bring the tool to simarm's floor, where it stops (COLLISION).
        &[
            "actarray",
            "simarm/actarray/0",
            "pos",
            "1",
            "-0.4",
            "--wait",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let out = stdout(&o);
    assert!(
        out.contains("done: reached the goal within the tolerance; largest final error 0.0000"),
        "{out}"
    );
    let o = limber(dom, &["limb", "simarm/limb/0", "home", "--wait=30"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("done: reached"), "{}", stdout(&o));
    // Cut short by a stop from another process: exit 1, the result in words.
    let mut slow = Bg::spawn(
        dom,
        &["actarray", "simarm/actarray/0", "pos", "0", "-6", "--wait"],
    );
    slow.line(|l| l == "ok");
    let o = limber(dom, &["actarray", "simarm/actarray/0", "speed", "0", "0"]);
    assert!(o.status.success(), "{}", stderr(&o));
    // Its stdout closes as it ends.
    while slow.1.recv_timeout(Duration::from_secs(30)).is_ok() {}
    let status = slow.0.wait().expect("the waiting CLI ends");
    assert_eq!(status.code(), Some(1));
}
