//! `limber limb DEV line|ptp` and `limber gripper DEV goal` (issue 28, items 3 and 4), end
//! to end against `limber simarm` and `limber pioneer --emulated`: a line and a PTP wait
//! for their results; a line out of reach or into the floor is refused (exit 5) with where,
//! and nothing moved; a gripper goal is reached, or stalls on the block with the object
//! present (exit 1); the Pioneer's paddles refuse a gap between open and closed.

mod common;
use common::{Bg, limber, pioneer_emulated, stderr, stdout};

use limber_services::Domain;

const LIMB: &str = "simarm/limb/0";

fn ok(dom: &str, args: &[&str]) -> String {
    let o = limber(dom, args);
    assert!(o.status.success(), "{args:?}: {}{}", stdout(&o), stderr(&o));
    stdout(&o)
}

#[test]
fn line_and_ptp_wait_for_their_results_and_a_refusal_says_where() {
    let d = Domain::unique_for_test();
    let dom = d.name();
    let mut sim = Bg::spawn(dom, &["simarm", "--time-scale", "5"]);
    sim.line(|l| l.ends_with("ready"));
    #[rustfmt::skip]
    ok(dom, &["limb", LIMB, "setpose", "0.4", "0", "0.3", "--approach", "0", "0", "-1", "--orient", "1", "0", "0", "--wait"]);
    let out = ok(
        dom,
        &[
            "limb", LIMB, "line", "0.35", "0.15", "0.22", "--speed", "0.2", "--wait",
        ],
    );
    assert!(out.starts_with("ok\n"), "{out}");
    assert!(
        out.contains("done: reached the goal within the tolerance"),
        "{out}"
    );
    #[rustfmt::skip]
    let out = ok(dom, &["limb", LIMB, "ptp", "0.3", "-0.2", "0.35", "--approach", "0", "0", "-1", "--orient", "1", "0", "0", "--wait"]);
    assert!(out.contains("done: reached"), "{out}");
    let before = ok(dom, &["echo", LIMB, "--count", "1"]);
    // Out of reach: refused with where, exit 5, nothing moved.
    let o = limber(dom, &["limb", LIMB, "line", "2", "0", "0.3", "--wait"]);
    assert_eq!(o.status.code(), Some(5), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(err.contains("refused: out of reach at "), "{err}");
    assert!(err.contains("% of the path, the tool at ("), "{err}");
    assert!(err.contains("nothing moved"), "{err}");
    // Into the floor (z = 0 on simarm): the path would hit it.
    let o = limber(dom, &["limb", LIMB, "line", "0.3", "-0.2", "-0.1"]);
    assert_eq!(o.status.code(), Some(5), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("refused: the path would hit the floor or an obstacle at "),
        "{}",
        stderr(&o)
    );
    let after = ok(dom, &["echo", LIMB, "--count", "1"]);
    let pos = |s: &str| s.split("pos ").nth(1).map(|p| p[..30].to_string());
    assert_eq!(
        pos(&before),
        pos(&after),
        "nothing moved:\n{before}\n{after}"
    );
    // Bad input: a usage error, nothing sent.
    let o = limber(
        dom,
        &["limb", LIMB, "line", "0.3", "0", "0.3", "--speed", "-1"],
    );
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("speed is negative"), "{}", stderr(&o));
}

#[test]
fn a_gripper_goal_is_reached_or_stalls_on_the_block() {
    let d = Domain::unique_for_test();
    let dom = d.name();
    // The default world: one block at (0.38, 0.10), its grasp point 0.17 m up.
    let mut sim = Bg::spawn(dom, &["simarm", "--time-scale", "5"]);
    sim.line(|l| l.ends_with("ready"));
    let out = ok(
        dom,
        &[
            "gripper",
            "simarm/gripper/0",
            "goal",
            "0.03",
            "--speed",
            "0.05",
            "--wait",
        ],
    );
    assert!(
        out.contains("done: reached the goal within the tolerance"),
        "{out}"
    );
    let out = ok(
        dom,
        &[
            "gripper",
            "simarm/gripper/0",
            "goal",
            "1",
            "--effort",
            "500",
        ],
    );
    assert_eq!(out, "ok, clamped to the limit\n");
    #[rustfmt::skip]
    ok(dom, &["limb", LIMB, "setpose", "0.38", "0.10", "0.17", "--approach", "0", "0", "-1", "--orient", "1", "0", "0", "--wait"]);
    let o = limber(dom, &["gripper", "simarm/gripper/0", "goal", "0", "--wait"]);
    assert_eq!(
        o.status.code(),
        Some(1),
        "stalled short of 0: {}",
        stderr(&o)
    );
    assert!(
        stderr(&o).contains("done: stalled short of the goal (an object is between the fingers)"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn the_pioneers_paddles_open_or_close_and_say_what_they_cannot() {
    let d = Domain::unique_for_test();
    let dom = d.name();
    let _p = pioneer_emulated(dom);
    let dev = "pioneer/gripper/0";
    let out = ok(dom, &["gripper", dev, "goal", "0", "--wait"]);
    assert!(out.contains("done: reached"), "{out}");
    for (args, why) in [
        (
            &["0.05"][..],
            "refused: this gripper only opens or closes fully",
        ),
        (
            &["0", "--effort", "5"][..],
            "refused: this gripper has no effort setting",
        ),
        (
            &["0", "--speed", "0.1"][..],
            "refused: this gripper has no speed setting",
        ),
    ] {
        let mut a = vec!["gripper", dev, "goal"];
        a.extend_from_slice(args);
        let o = limber(dom, &a);
        assert_eq!(o.status.code(), Some(5), "{a:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(why), "{a:?}: {}", stderr(&o));
    }
    let out = ok(dom, &["gripper", dev, "goal", "5", "--wait"]);
    assert!(out.starts_with("ok, clamped to the limit\n"), "{out}");
    assert!(out.contains("done: reached"), "{out}");
}
