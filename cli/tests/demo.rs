//! `limber demo` end to end: it starts the robot and its world (a block where `--block`
//! says, or at a seeded random place), the laser finds the block (the paper's Listing 2),
//! the arm picks it up and puts it down; it prints where it found the block against where
//! it was and where the block is now, and exits 0.

use limber_services::Domain;

mod common;
use common::{limber, stderr, stdout};

/// The three points of the demo's last line: `the block was at (x, y); the laser found it
/// at (x, y), N mm off; it is now at (x, y)`.
fn was_found_now(out: &str) -> [[f64; 2]; 3] {
    let line = out
        .lines()
        .find(|l| l.starts_with("the block was at ("))
        .unwrap_or_else(|| panic!("no summary of the block in:\n{out}"));
    let pts: Vec<[f64; 2]> = line
        .split('(')
        .skip(1)
        .map(|p| {
            let v: Vec<f64> = p[..p.find(')').expect("a point")]
                .split(", ")
                .map(|x| x.parse().expect("a number"))
                .collect();
            [v[0], v[1]]
        })
        .collect();
    [pts[0], pts[1], pts[2]]
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

const DROP: [f64; 2] = [0.38, -0.10];

#[test]
fn demo_on_the_emulated_pioneer_finds_the_block_with_the_laser_and_moves_it() {
    let d = Domain::unique_for_test();
    let o = limber(
        d.name(),
        &[
            "demo",
            "--fast",
            "--block",
            "0.40",
            "0.07",
            "--laser-noise",
            "0",
        ],
    );
    let out = stdout(&o);
    assert!(o.status.success(), "{out}\n{}", stderr(&o));
    assert!(
        out.contains(
            "placed a block of 40 mm at (0.400, 0.070); the laser pioneer/ranger/0 will find it"
        ),
        "{out}"
    );
    assert!(out.contains("[ 0/11] the laser's closest point"), "{out}");
    assert!(out.contains("[ 1/11] home"), "{out}");
    assert!(out.contains("[11/11] home again"), "{out}");
    assert!(
        out.contains("and put it down at (0.38, -0.10): 11 steps"),
        "{out}"
    );
    let [was, found, now] = was_found_now(&out);
    assert_eq!(was, [0.40, 0.07]);
    assert!(dist(found, was) < 0.005, "{out}");
    assert!(dist(now, DROP) < 0.03, "{out}");
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
fn the_same_program_runs_on_simarm_with_a_block_at_a_seeded_random_place() {
    let d = Domain::unique_for_test();
    let o = limber(
        d.name(),
        &[
            "demo",
            "--on",
            "simarm",
            "--fast",
            "--seed",
            "7",
            "--laser-noise",
            "0",
        ],
    );
    let out = stdout(&o);
    assert!(o.status.success(), "{out}\n{}", stderr(&o));
    assert!(out.contains("started simarm"), "{out}");
    assert!(out.contains("(random, seed 7)"), "{out}");
    assert!(out.contains("[11/11] home again"), "{out}");
    assert!(out.contains("11 steps"), "{out}");
    assert!(
        out.contains("the gripper's beam saw the block while it was held"),
        "{out}"
    );
    let [was, found, now] = was_found_now(&out);
    let seeded = limber_world::World::random_block(
        7,
        limber_cli::world::RANDOM_REGION[0],
        limber_cli::world::RANDOM_REGION[1],
    );
    assert!(dist(was, [seeded.x, seeded.y]) < 0.001, "{out}");
    assert!(dist(found, was) < 0.005, "{out}");
    assert!(dist(now, DROP) < 0.03, "{out}");
}
