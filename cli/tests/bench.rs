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

#[test]
fn bench_runs_child_processes_under_a_global_domain() {
    let domain = Domain::unique_for_test();
    let dir = std::env::temp_dir().join(format!("limber-cli-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let json = dir.join("report.json");
    let out = common::output(
        Command::new(LIMBER)
            .args([
                "--domain",
                domain.name(),
                "bench",
                "--quick",
                "--scale",
                "0.05",
            ])
            .args(["--no-progress", "--only", "floor", "--json"])
            .arg(&json),
    );
    assert!(
        out.status.success(),
        "{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let report = std::fs::read_to_string(&json).unwrap();
    assert!(report.contains("\"measurements\""), "{report}");
    assert!(report.contains("\"floor\""), "{report}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bench_quick_reports_the_trajectory_tick_period_and_jitter() {
    let domain = Domain::unique_for_test();
    let dir = std::env::temp_dir().join(format!("limber-cli-bench-traj-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let json = dir.join("report.json");
    let out = common::output(
        Command::new(LIMBER)
            .args(["--domain", domain.name(), "bench", "--quick"])
            .args(["--no-progress", "--only", "traj", "--json"])
            .arg(&json),
    );
    assert!(
        out.status.success(),
        "{}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    let report = std::fs::read_to_string(&json).unwrap();
    for id in ["traj.tick", "traj.period", "traj.jitter"] {
        assert!(report.contains(&format!("\"{id}\"")), "{id}: {report}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
