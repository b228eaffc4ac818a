//! The paper's Listing 2 in C and C++ (`examples/c`, `examples/cpp`), built the way their
//! READMEs say (install.sh, pkg-config, their Makefiles), run against the emulated Pioneer
//! and against simarm, each with its world on a thread of this process and the block where
//! the test puts it: the laser finds it, the arm picks it up and puts it down at the drop
//! point (the world's block moved there), or, out of reach, the program says so and exits 2.

mod common;
use common::*;

use std::path::Path;

/// Where the programs put the block down.
const DROP: [f64; 2] = [0.38, -0.10];

/// The `(x, y)` of the program's line `found the block at (x, y)`.
fn found(out: &str) -> [f64; 2] {
    let prefix = "found the block at (";
    let line = out
        .lines()
        .find(|l| l.starts_with(prefix))
        .unwrap_or_else(|| panic!("no line {prefix:?} in:\n{out}"));
    let v: Vec<f64> = line[prefix.len()..line.len() - 1]
        .split(", ")
        .map(|x| x.parse().expect("a number"))
        .collect();
    [v[0], v[1]]
}

fn dist(a: [f64; 2], b: [f64; 2]) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

/// Runs `exe` with `args` on `robot` with the block at `block`: found within 1 cm, picked
/// up once, put down at the drop point, where the world has it now.
fn picks(
    robot: &impl InDomain,
    world: &SimWorld,
    exe: &Path,
    args: &[&str],
    block: [f64; 2],
) -> String {
    world.place(block[0], block[1]);
    let o = run_in(robot, exe, args);
    let out = text(&o.stdout);
    let exe = exe.display();
    assert!(o.status.success(), "{exe}: {out}\n{}", text(&o.stderr));
    assert!(dist(found(&out), block) < 0.01, "{exe}: {out}");
    assert_eq!(out.matches("gripper closed").count(), 1, "{exe}: {out}");
    assert!(
        out.ends_with("done: block picked up and put down\n"),
        "{exe}: {out}"
    );
    let b = world.block();
    assert!(
        dist([b.x, b.y], DROP) < 0.03 && b.lifted == 0.0,
        "{exe}: the block is at ({}, {}), lifted {}: {out}",
        b.x,
        b.y,
        b.lifted
    );
    out
}

/// Out of reach: the program says so, goes home and exits 2; the block stays.
fn out_of_reach(robot: &impl InDomain, world: &SimWorld, exe: &Path, args: &[&str]) {
    world.place(2.0, 0.0);
    let o = run_in(robot, exe, args);
    let out = text(&o.stdout);
    let exe = exe.display();
    assert_eq!(
        o.status.code(),
        Some(2),
        "{exe}: {out}\n{}",
        text(&o.stderr)
    );
    assert!(
        out.contains("Target out of reach, terminating"),
        "{exe}: {out}"
    );
    assert!(!out.contains("gripper closed"), "{exe}: {out}");
    let b = world.block();
    assert_eq!((b.x, b.y), (2.0, 0.0));
}

#[test]
fn the_examples_build_as_their_readmes_say_and_find_pick_and_put_down_the_block() {
    let dir = scratch("listing2");
    run_readme_build_lines("examples/c/README.md", &dir.join("c"));
    run_readme_build_lines("examples/cpp/README.md", &dir.join("cpp"));
    let (c, cpp) = (dir.join("c/pick_block"), dir.join("cpp/pick_block_cpp"));

    // The emulated Pioneer: the programs' default devices.
    let p = Pioneer::with_world(&[[0.38, 0.06]]);
    let world = p.world.as_ref().expect("its world");
    let out = picks(&p, world, &c, &[], [0.38, 0.06]);
    assert!(
        near(position_at(&out, "descend"), [0.38, 0.06, 0.17], 0.01),
        "{out}"
    );
    assert!(
        near(position_at(&out, "put down"), [0.38, -0.10, 0.17], 0.01),
        "{out}"
    );
    picks(&p, world, &cpp, &[], [0.41, 0.10]);
    for exe in [&c, &cpp] {
        out_of_reach(&p, world, exe, &[]);
    }
    drop(p);

    // simarm: the very same programs, given its devices.
    let s = SimArmRun::start([0.36, 0.06]);
    let devices = ["simarm/limb/0", "simarm/gripper/0", "simarm/ranger/0"];
    picks(&s, &s.world, &c, &devices, [0.36, 0.06]);
    picks(&s, &s.world, &cpp, &devices, [0.36, 0.06]);
    for exe in [&c, &cpp] {
        out_of_reach(&s, &s.world, exe, &devices);
    }
}
