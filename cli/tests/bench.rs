//! `limber bench` through the `limber` command, as `.ci/run` runs it: the global
//! `--domain` and the benchmark's own child processes (spawned as `limber bench --role
//! ...`) must not collide. Asserts that it runs and reports, never a speed.

use std::process::Command;

use limber_services::Domain;

mod common;
use common::LIMBER;

#[test]
fn bench_lists_its_scenarios() {
    let out = common::output(Command::new(LIMBER).args(["bench", "--list"]));
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    for s in ["floor", "command", "loop", "ik"] {
        assert!(text.contains(s), "{text}");
    }
}

/// Runs `limber --domain D bench --quick --no-progress --only ONLY --json F [EXTRA]`,
/// asserting success; the JSON report.
fn quick_report(only: &str, extra: &[&str]) -> String {
    let domain = Domain::unique_for_test();
    let dir = std::env::temp_dir().join(format!("limber-cli-bench-{only}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let json = dir.join("report.json");
    let out = common::output(
        Command::new(LIMBER)
            .args(["--domain", domain.name(), "bench", "--quick"])
            .args(extra)
            .args(["--no-progress", "--only", only, "--json"])
            .arg(&json),
    );
    assert!(
        out.status.success(),
        "{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let report = std::fs::read_to_string(&json).unwrap();
    std::fs::remove_dir_all(&dir).unwrap();
    report
}

#[test]
fn bench_runs_child_processes_under_a_global_domain() {
    let report = quick_report("floor", &["--scale", "0.05"]);
    assert!(report.contains("\"measurements\""), "{report}");
    assert!(report.contains("\"floor\""), "{report}");
}

#[test]
fn bench_quick_reports_the_trajectory_tick_period_and_jitter() {
    let report = quick_report("traj", &[]);
    for id in ["traj.tick", "traj.period", "traj.jitter"] {
        assert!(report.contains(&format!("\"{id}\"")), "{id}: {report}");
    }
}

/// `limber bench --only floor,command --spin` (the benchmarks page's spinning runs), quick:
/// the spinning pair back to back and at 1 kHz beside its floors, through the CLI.
#[test]
fn bench_quick_runs_the_spinning_pair_back_to_back_and_at_1_khz() {
    let report = quick_report("floor,command", &["--spin", "--scale", "0.2"]);
    for id in [
        "floor.spin.oneway",
        "floor.spin2.oneway",
        "command.spin.oneway",
        "command.paced.spin.oneway",
        "command.paced.spin2.oneway",
    ] {
        assert!(report.contains(&format!("\"{id}\"")), "{id}: {report}");
    }
}
