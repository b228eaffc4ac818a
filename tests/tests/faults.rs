//! The fault suite: what the other multi-process tests do not already cover (see
//! TESTING.md for the map). Link faults (silence, garbage, bad checksums, a killed link and
//! its reconnection, no replay of a refused command) are in `pioneer.rs`; a killed driver
//! noticed and a restarted one picked up, and a client killed mid-request, in `services.rs`;
//! SIGSTOP/SIGCONT of the driver and a SIGKILLed driver's arm parking in `pioneer.rs`.
//! Every test has a domain of its own, and every wait a bound.

use std::path::PathBuf;
use std::process::Command;
use std::time::{Duration, Instant};

use limber_bounded_run::output_within;
use limber_services::domain_dir::euid;
use limber_services::prelude::*;
use limber_services::{Domain, RequestError, Role};
use limber_tests::Proc;

const DRIVER: &str = env!("CARGO_BIN_EXE_limber-test-driver");
const CLIENT: &str = env!("CARGO_BIN_EXE_limber-test-client");
const CLI: &str = env!("CARGO_BIN_EXE_limber-test-cli");
const PIONEER: &str = env!("CARGO_BIN_EXE_limber-test-pioneer");
const T: Duration = Duration::from_secs(5);
const LIMIT: Duration = Duration::from_secs(30);

fn start_driver(domain: &Domain, extra: &[&str]) -> Proc {
    Proc::spawn_ready(DRIVER, domain.name(), extra)
}

fn ctx(domain: &Domain) -> Context {
    Context::new(domain, Role::Client, "faults").unwrap()
}

/// A client of this process commands joint 1 and sees the outcome and a fresh state.
fn commands_work(domain: &Domain, position: f64) {
    let c = ctx(domain);
    let mut arm = ActArrayClient::connect_timeout(&c, "test/actarray/0", T).unwrap();
    let t = arm.move_to(1, position).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);
    let s = arm.wait_state(T).unwrap();
    assert_eq!(s.actuators[1].position, position);
}

fn shm_files(domain: &Domain) -> Vec<PathBuf> {
    let prefix = domain.prefix().unwrap().to_string();
    let mut v: Vec<_> = std::fs::read_dir("/dev/shm")
        .unwrap()
        .filter_map(Result::ok)
        .filter(|e| e.file_name().to_string_lossy().starts_with(&prefix))
        .map(|e| e.path())
        .collect();
    v.sort();
    v
}

/// `key=value` of the driver's last `stats ...` line.
fn stat(out: &str, key: &str) -> u64 {
    let line = out
        .lines()
        .find(|l| l.starts_with("stats "))
        .unwrap_or_else(|| panic!("no stats line: {out}"));
    line.split(' ')
        .find_map(|f| f.strip_prefix(&format!("{key}=")))
        .unwrap_or_else(|| panic!("no {key} in {line}"))
        .parse()
        .unwrap()
}

#[test]
fn a_flood_from_eight_clients_is_accounted_command_by_command() {
    let domain = Domain::unique_for_test();
    let mut driver = start_driver(&domain, &["--period-ms", "10"]);
    let n = 160u64;
    let ns = n.to_string();
    let mut clients: Vec<Proc> = (0..8)
        .map(|_| Proc::spawn(CLIENT, domain.name(), &["flood", &ns]))
        .collect();
    // Meanwhile the loop keeps publishing: this process sees new states during the flood.
    let c = ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&c, "test/actarray/0", T).unwrap();
    let first = arm.wait_state(T).unwrap().header.seq;
    let deadline = Instant::now() + T;
    while arm.wait_state(T).unwrap().header.seq < first + 5 {
        assert!(Instant::now() < deadline, "the loop stopped publishing");
    }
    for c in &mut clients {
        assert_eq!(c.wait_timeout(LIMIT), Some(0));
        assert_eq!(c.rest_of_stdout().trim(), format!("sent {n}"));
    }
    driver.signal(libc::SIGTERM);
    assert_eq!(driver.wait_timeout(T), Some(0));
    let out = driver.rest_of_stdout();
    // Every command arrived, once, in order, per client.
    let mut per_client: std::collections::BTreeMap<u64, Vec<u64>> = Default::default();
    for line in out.lines().filter(|l| l.starts_with("cmd ")) {
        let f: Vec<u64> = line[4..].split(' ').map(|x| x.parse().unwrap()).collect();
        per_client.entry(f[0]).or_default().push(f[1]);
    }
    assert_eq!(per_client.len(), 8, "{out}");
    for seqs in per_client.values() {
        assert_eq!(seqs, &(1..=n).collect::<Vec<_>>(), "lost or reordered");
    }
    // sent = carried out + refused, with no phantom counts: joints 6 and 7 of a 6-joint
    // arm (a quarter of each flood) are refused, the rest carried out.
    let sent = 8 * n;
    let refused = 8 * (0..n).filter(|i| i % 8 >= 6).count() as u64;
    assert_eq!(stat(&out, "commands"), sent, "{out}");
    assert_eq!(stat(&out, "refused"), refused, "{out}");
    assert_eq!(stat(&out, "overflows"), 0, "{out}");
}

#[test]
fn clients_killed_or_stopped_while_holding_samples_do_not_hurt_the_driver() {
    let domain = Domain::unique_for_test();
    let mut driver = start_driver(&domain, &["--period-ms", "10"]);
    let mut holders: Vec<Proc> = (0..2)
        .map(|_| Proc::spawn(CLIENT, domain.name(), &["hold-samples"]))
        .collect();
    for h in &mut holders {
        assert!(h.read_until(|l| l.starts_with("holding ")).is_some());
    }
    commands_work(&domain, 0.1);
    // One dies holding its samples, the other is stopped holding them.
    holders[0].signal(libc::SIGKILL);
    assert_eq!(holders[0].wait_timeout(T), None);
    holders[1].signal(libc::SIGSTOP);
    commands_work(&domain, 0.2);
    // A client stopped in the middle of its own work, then continued.
    let c = ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&c, "test/actarray/0", T).unwrap();
    let mut burst = Proc::spawn(CLIENT, domain.name(), &["burst", "200"]);
    burst.signal(libc::SIGSTOP);
    let t = arm.move_to(2, 0.3).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);
    burst.signal(libc::SIGCONT);
    assert_eq!(
        burst.wait_timeout(LIMIT),
        Some(0),
        "the continued client finishes"
    );
    holders[1].signal(libc::SIGCONT);
    commands_work(&domain, 0.4);
    assert!(
        driver.child.try_wait().unwrap().is_none(),
        "the driver lives"
    );
    driver.signal(libc::SIGTERM);
    assert_eq!(driver.wait_timeout(T), Some(0));
    let out = driver.rest_of_stdout();
    assert_eq!(stat(&out, "overflows"), 0, "{out}");
}

#[test]
fn a_stopped_driver_is_a_request_timeout_and_a_continued_one_serves_again() {
    let domain = Domain::unique_for_test();
    let driver = start_driver(&domain, &[]);
    let c = ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&c, "test/actarray/0", T).unwrap();
    arm.set_request_timeout(Duration::from_millis(300));
    arm.geometry().unwrap();
    driver.signal(libc::SIGSTOP);
    let err = arm.geometry().expect_err("a stopped driver cannot answer");
    assert!(matches!(err, RequestError::Timeout { .. }), "{err:?}");
    driver.signal(libc::SIGCONT);
    arm.set_request_timeout(T);
    arm.geometry().expect("the continued driver answers");
    let t = arm.move_to(0, 0.5).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);
}

#[test]
fn a_sigkilled_drivers_files_are_listed_dead_and_a_restart_cleans_them() {
    let domain = Domain::unique_for_test();
    let mut driver = start_driver(&domain, &[]);
    commands_work(&domain, 0.1);
    driver.signal(libc::SIGKILL);
    assert_eq!(driver.wait_timeout(T), None);
    // Left behind (but for the node counter, which iceoryx2 keeps by design, and the
    // devices' wake words, which the next driver of each device takes over so that a client
    // asleep on one keeps waiting on the word it bumps), and listed as dead.
    let stale: Vec<_> = shm_files(&domain)
        .into_iter()
        .filter(|f| {
            let f = f.to_string_lossy();
            !f.ends_with(".global_mgmt") && !f.ends_with(".wake")
        })
        .collect();
    assert!(!stale.is_empty(), "a SIGKILLed driver leaves its files");
    let list = |domain: &Domain| {
        let out = output_within(
            Command::new(CLI)
                .arg("list")
                .env("LIMBER_DOMAIN", domain.name()),
            LIMIT,
        );
        assert!(out.status.success(), "{out:?}");
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    let text = list(&domain);
    let arm_line = text
        .lines()
        .find(|l| l.starts_with("test/actarray/0"))
        .unwrap_or_else(|| panic!("{text}"));
    assert!(arm_line.contains("dead"), "{text}");
    // A restart cleans them; its devices are alive and work.
    let _driver = start_driver(&domain, &[]);
    commands_work(&domain, 0.2);
    let text = list(&domain);
    assert!(!text.contains("dead"), "{text}");
    let left: Vec<_> = stale.iter().filter(|f| f.exists()).collect();
    assert!(left.is_empty(), "stale files left: {left:?}");
}

/// Runs `script` (with `sh -c`, `$1` = the Pioneer driver) in a private mount namespace.
fn in_private_mounts(script: &str, domain: &Domain) -> Option<std::process::Output> {
    if euid() != 0 {
        eprintln!("SKIPPED: a private /dev/shm (unshare -m, mount) needs root (CI runs as root)");
        return None;
    }
    let out = output_within(
        Command::new("unshare")
            .args(["-m", "sh", "-c", script, "sh", PIONEER])
            .env("LIMBER_DOMAIN", domain.name()),
        LIMIT,
    );
    // unshare(1) or mount(8) refused (a container without CAP_SYS_ADMIN): the driver never
    // ran.
    let err = String::from_utf8_lossy(&out.stderr);
    if err.contains("unshare failed") || err.starts_with("mount:") {
        eprintln!("SKIPPED: no private mounts here: {err}");
        return None;
    }
    Some(out)
}

#[test]
fn a_dev_shm_too_small_is_a_clear_error_at_start() {
    let domain = Domain::unique_for_test();
    let Some(out) = in_private_mounts(
        "mount -t tmpfs -o size=1m tmpfs /dev/shm && exec \"$1\" --emulated",
        &domain,
    ) else {
        return;
    };
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{out:?}");
    assert!(
        err.contains("/dev/shm has") && err.contains("--shm-size"),
        "{err}"
    );
}

#[test]
fn a_runtime_directory_that_cannot_be_written_is_a_clear_error_at_start() {
    let domain = Domain::unique_for_test();
    let base = std::env::temp_dir().join(format!("limber-ro-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&base);
    std::fs::create_dir_all(&base).unwrap();
    // Root writes anywhere a mode forbids: a read-only bind mount stops it too.
    let Some(out) = in_private_mounts(
        &format!(
            "mount --bind '{b}' '{b}' && mount -o remount,bind,ro '{b}' && LIMBER_RUNTIME_DIR='{b}/rt' exec \"$1\" --emulated",
            b = base.display()
        ),
        &domain,
    ) else {
        let _ = std::fs::remove_dir_all(&base);
        return;
    };
    let _ = std::fs::remove_dir_all(&base);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{out:?}");
    assert!(
        err.contains(&format!("cannot create {}/rt", base.display()))
            && err.contains("Read-only file system"),
        "{err}"
    );
}

#[test]
fn a_driver_killed_in_the_middle_of_a_request_is_reported_and_new_clients_find_its_successor() {
    let domain = Domain::unique_for_test();
    let mut driver = start_driver(&domain, &["--hold-first-request"]);
    let d2 = domain.clone();
    let (tx, rx) = std::sync::mpsc::channel();
    let asker = std::thread::spawn(move || {
        let c = ctx(&d2);
        let mut arm = ActArrayClient::connect_timeout(&c, "test/actarray/0", T).unwrap();
        // Far longer than the test's own bound below: the answer must come from noticing
        // the driver's death, not from the request timing out.
        arm.set_request_timeout(Duration::from_secs(120));
        tx.send(()).unwrap();
        arm.geometry()
    });
    rx.recv_timeout(T).unwrap();
    assert!(driver.read_until(|l| l.starts_with("request ")).is_some());
    driver.signal(libc::SIGKILL);
    assert_eq!(driver.wait_timeout(T), None);
    let deadline = Instant::now() + LIMIT;
    while !asker.is_finished() {
        assert!(
            Instant::now() < deadline,
            "the client did not notice the death"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    let err = asker
        .join()
        .unwrap()
        .expect_err("no answer from a dead driver");
    assert!(
        matches!(err, RequestError::DriverGone | RequestError::NoDriver),
        "{err:?}"
    );
    // A new client process finds the restarted driver.
    let _driver = start_driver(&domain, &[]);
    let mut c = Proc::spawn(CLIENT, domain.name(), &["basic"]);
    assert_eq!(c.wait_timeout(LIMIT), Some(0));
    assert!(c.rest_of_stdout().contains("ok"));
}

/// Every path under `dir` (recursively) whose name contains `token`.
fn named_with(dir: &std::path::Path, token: &str) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir)
        .into_iter()
        .flatten()
        .filter_map(Result::ok)
    {
        if e.file_name().to_string_lossy().contains(token) {
            out.push(e.path());
        }
        if e.file_type().is_ok_and(|t| t.is_dir()) {
            out.extend(named_with(&e.path(), token));
        }
    }
    out
}

#[test]
fn a_test_domain_removes_the_files_of_the_processes_its_test_killed() {
    let domain = Domain::unique_for_test();
    let name = domain.name().to_string();
    let mut driver = start_driver(&domain, &[]);
    let mut holder = Proc::spawn(CLIENT, &name, &["hold-samples"]);
    assert!(holder.read_until(|l| l.starts_with("holding ")).is_some());
    commands_work(&domain, 0.1);
    for p in [&mut holder, &mut driver] {
        p.signal(libc::SIGKILL);
        assert_eq!(p.wait_timeout(T), None);
    }
    // The token is the domain's part of every name: in the runtime directory (the token
    // file, the iceoryx2 files of the domain's processes) and in /dev/shm.
    let token = domain.prefix().unwrap().trim_end_matches('_').to_string();
    let runtime = limber_services::domain_dir::runtime_dir();
    let everywhere = || {
        let mut v = named_with(&runtime, &token);
        v.extend(named_with(std::path::Path::new("/dev/shm"), &token));
        v.extend(named_with(&runtime, &name));
        v
    };
    let before = everywhere();
    let nodes = runtime.join("iceoryx2").join("nodes");
    assert!(
        before.iter().any(|p| p.starts_with(&nodes)),
        "the killed processes leave their nodes: {before:?}"
    );
    assert!(
        before
            .iter()
            .any(|p| p.starts_with("/dev/shm") && !p.to_string_lossy().ends_with(".global_mgmt")),
        "and their segments: {before:?}"
    );
    // The node directories (named by the node's id) of the domain.
    let node_dirs: std::collections::BTreeSet<PathBuf> = before
        .iter()
        .filter_map(|p| p.parent())
        .filter(|d| d.parent() == Some(nodes.as_path()))
        .map(PathBuf::from)
        .collect();
    assert!(!node_dirs.is_empty(), "{before:?}");
    drop((holder, driver));
    drop(domain);
    assert_eq!(everywhere(), Vec::<PathBuf>::new(), "left behind");
    let dirs_left: Vec<_> = node_dirs.iter().filter(|d| d.exists()).collect();
    assert!(dirs_left.is_empty(), "node directories left: {dirs_left:?}");
}
