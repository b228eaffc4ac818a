//! The two programs as a user runs them: the `random_moves` and `pick_block` binaries
//! against the test driver (instant joints) on a thread of this process, each test in a
//! domain of its own. Their output and exit codes are checked; every run is bounded.

use std::process::{Command, Output};
use std::sync::mpsc;
use std::time::Duration;

use limber_services::testing::TestDriver;
use limber_services::{Context, Domain, Role};

const RANDOM_MOVES: &str = env!("CARGO_BIN_EXE_random_moves");
const PICK_BLOCK: &str = env!("CARGO_BIN_EXE_pick_block");
/// How long one run of a program may take before the test fails.
const RUN_TIMEOUT: Duration = Duration::from_secs(60);

/// Runs the test driver (robot `ex`) on a thread of this process until the sender is
/// dropped.
fn driver(domain: &Domain) -> mpsc::Sender<()> {
    let (tx, rx) = mpsc::channel::<()>();
    let (ready_tx, ready_rx) = mpsc::channel();
    // A handle of its own: the test's, dropped last, then removes the domain's files once
    // this thread's driver is gone.
    let name = domain.name().to_string();
    std::thread::spawn(move || {
        let domain = Domain::new(&name).unwrap();
        let ctx = Context::new(&domain, Role::Driver, "testdriver").unwrap();
        let mut d = TestDriver::new(&ctx, "ex", 6).unwrap();
        ready_tx.send(()).unwrap();
        let _ = d.run(Duration::from_millis(10), || {
            !matches!(rx.try_recv(), Err(mpsc::TryRecvError::Empty))
        });
    });
    ready_rx
        .recv_timeout(Duration::from_secs(10))
        .expect("the test driver starts");
    tx
}

/// Runs `exe args` in `domain`; fails the test if it runs longer than [`RUN_TIMEOUT`].
fn run(exe: &str, domain: &Domain, args: &[&str]) -> Output {
    let mut cmd = Command::new(exe);
    cmd.args(args).env("LIMBER_DOMAIN", domain.name());
    limber_bounded_run::output_within(cmd, RUN_TIMEOUT)
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// The `round ...` lines of a random_moves run.
fn moves(o: &Output) -> Vec<String> {
    text(&o.stdout)
        .lines()
        .filter(|l| l.starts_with("round "))
        .map(str::to_string)
        .collect()
}

#[test]
fn random_moves_binary_moves_every_joint_each_round_within_limits() {
    let d = Domain::unique_for_test();
    let _stop = driver(&d);
    let o = run(
        RANDOM_MOVES,
        &d,
        &["--arm", "ex/actarray/0", "--rounds", "2", "--seed", "7"],
    );
    let out = text(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{out}{}", text(&o.stderr));
    let m = moves(&o);
    assert_eq!(m.len(), 2 * 6, "{out}");
    for (i, line) in m.iter().enumerate() {
        // round R joint J -> T (limits LO .. HI)
        let f: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(f[1], (i / 6).to_string(), "{line}");
        assert_eq!(f[3], (i % 6).to_string(), "{line}");
        let num = |s: &str| s.trim_matches(['(', ')']).parse::<f64>().unwrap();
        let (target, lo, hi) = (num(f[5]), num(f[7]), num(f[9]));
        assert!(lo < target && target < hi, "{line}");
    }
    assert!(out.contains("final joints: ["), "{out}");

    // The same seed gives the same moves; another seed others.
    let again = run(
        RANDOM_MOVES,
        &d,
        &["--arm", "ex/actarray/0", "--rounds", "2", "--seed", "7"],
    );
    assert_eq!(again.status.code(), Some(0));
    assert_eq!(moves(&again), m);
    let other = run(
        RANDOM_MOVES,
        &d,
        &["--arm", "ex/actarray/0", "--rounds", "2", "--seed", "8"],
    );
    assert_eq!(other.status.code(), Some(0));
    assert_ne!(moves(&other), m);
}

#[test]
fn random_moves_binary_without_a_driver_fails_with_a_message() {
    let d = Domain::unique_for_test();
    let o = run(RANDOM_MOVES, &d, &["--arm", "ex/actarray/0"]);
    assert_eq!(o.status.code(), Some(1));
    let err = text(&o.stderr);
    assert!(err.starts_with("random_moves: "), "{err}");
    assert!(err.contains("ex/actarray/0"), "{err}");
    assert!(moves(&o).is_empty());
}

#[test]
fn pick_block_binary_picks_and_places_the_block() {
    let d = Domain::unique_for_test();
    let _stop = driver(&d);
    let o = run(
        PICK_BLOCK,
        &d,
        // The test driver has no laser: the block is given (the laser's part runs on the
        // simulated robots: cli/tests/demo.rs, and examples/pick_block/README.md's
        // commands in cli/tests/readme.rs).
        &[
            "--limb",
            "ex/limb/0",
            "--gripper",
            "ex/gripper/0",
            "--block",
            "0.38",
            "0.10",
        ],
    );
    let out = text(&o.stdout);
    assert_eq!(o.status.code(), Some(0), "{out}{}", text(&o.stderr));
    let steps: Vec<&str> = out.lines().filter(|l| l.ends_with(" ...")).collect();
    assert_eq!(steps.len(), 11, "{out}");
    assert_eq!(steps.first(), Some(&"Home ..."), "{out}");
    assert_eq!(steps.last(), Some(&"HomeAgain ..."), "{out}");
    assert!(steps.contains(&"Grip ..."), "{out}");
    assert_eq!(
        out.lines().filter(|l| l.contains("done:")).count(),
        11,
        "{out}"
    );
    assert!(out.contains("picked and placed in 11 steps"), "{out}");
}

#[test]
fn pick_block_binary_reports_a_block_out_of_reach_and_a_missing_driver() {
    let d = Domain::unique_for_test();
    let _stop = driver(&d);
    let o = run(
        PICK_BLOCK,
        &d,
        &[
            "--limb",
            "ex/limb/0",
            "--gripper",
            "ex/gripper/0",
            "--block",
            "3.0",
            "0.0",
        ],
    );
    assert_eq!(o.status.code(), Some(1), "{}", text(&o.stdout));
    let err = text(&o.stderr);
    assert!(err.starts_with("pick_block: Approach("), "{err}");
    assert!(err.contains("target out of reach"), "{err}");
    assert!(!text(&o.stdout).contains("picked and placed"));

    let nobody = Domain::unique_for_test();
    let o = run(
        PICK_BLOCK,
        &nobody,
        &["--limb", "ex/limb/0", "--gripper", "ex/gripper/0"],
    );
    assert_eq!(o.status.code(), Some(3), "{}", text(&o.stderr));
    assert!(text(&o.stderr).starts_with("pick_block: "));
}
