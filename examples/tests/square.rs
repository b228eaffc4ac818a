//! The square example (issue 28) as a user runs it: the `square` binary against simarm (a
//! thread of this process, its own domain): a PTP to the first corner, four straight
//! edges, each waited for with `wait_done`; every motion ends REACHED with its final error
//! within the tolerance. A square out of reach is refused before anything moves.

use std::process::{Command, Output};
use std::time::Duration;

use limber_kinematics::chain::Chain;
use limber_services::Domain;
use limber_simarm::{SimArmOptions, SimArmThread};

const SQUARE: &str = env!("CARGO_BIN_EXE_square");
const RUN_TIMEOUT: Duration = Duration::from_secs(120);

/// simarm (5x real time) on a thread of this process.
fn simarm(domain: &Domain) -> SimArmThread {
    let options = SimArmOptions {
        time_scale: 5.0,
        ..SimArmOptions::default()
    };
    SimArmThread::start(
        domain.name(),
        Chain::default_6dof(),
        options,
        Duration::from_secs(20),
    )
    .expect("simarm starts")
}

fn run(domain: &Domain, args: &[&str]) -> Output {
    let mut cmd = Command::new(SQUARE);
    cmd.args(args).env("LIMBER_DOMAIN", domain.name());
    limber_bounded_run::output_within(cmd, RUN_TIMEOUT)
}

#[test]
fn the_square_is_drawn_and_every_edge_ends_within_the_tolerance() {
    let d = Domain::unique_for_test();
    let _drv = simarm(&d);
    let o = run(
        &d,
        &["--limb", "simarm/limb/0", "--side", "0.1", "--speed", "0.1"],
    );
    let out = String::from_utf8_lossy(&o.stdout).into_owned();
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(0), "{out}{err}");
    let strokes: Vec<&str> = out
        .lines()
        .filter(|l| l.starts_with("ptp ") || l.starts_with("line "))
        .collect();
    assert_eq!(strokes.len(), 5, "{out}");
    assert!(
        strokes[0].starts_with("ptp 0 to (0.350, -0.050, 0.250)"),
        "{out}"
    );
    assert!(
        strokes[4].starts_with("line 4 to (0.350, -0.050, 0.250)"),
        "{out}"
    );
    for s in &strokes {
        // ... : REACHED error E tolerance T
        let w: Vec<&str> = s.split_whitespace().collect();
        let n = w.len();
        assert_eq!(w[n - 5], "REACHED", "{s}");
        let (error, tolerance): (f64, f64) = (w[n - 3].parse().unwrap(), w[n - 1].parse().unwrap());
        assert!(error <= tolerance, "{s}");
    }
    assert!(out.ends_with("square drawn\n"), "{out}");
}

#[test]
fn a_square_out_of_reach_is_refused_with_the_reason() {
    let d = Domain::unique_for_test();
    let _drv = simarm(&d);
    let o = run(
        &d,
        &["--limb", "simarm/limb/0", "--centre", "1.5", "0", "0.25"],
    );
    assert_eq!(o.status.code(), Some(1));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("square: motion 0: the command was refused: out of reach"),
        "{err}"
    );
}
