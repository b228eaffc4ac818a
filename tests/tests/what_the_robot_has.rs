//! Issue 13 item 4, what the robot has: the driver asks CONFIG at connect and serves the
//! body gripper (`pioneer/gripper/0`) and the lift (`pioneer/actarray/1`) only when the
//! robot's CONFIGpac says a gripper is fitted, or when `body_gripper = true` says so for a
//! controller that does not answer. The driver and the `limber` command line run as
//! processes, each test in a domain of its own; the emulator runs in this process so that
//! its count of the gripper commands it received (and ignored) can be read.

use std::process::{Command, Output, Stdio};
use std::sync::mpsc;
use std::time::Duration;

use limber_emulator::{Emulator, EmulatorConfig};
use limber_services::Domain;
use limber_tests::Proc;

const PIONEER: &str = env!("CARGO_BIN_EXE_limber-test-pioneer");
const CLI: &str = env!("CARGO_BIN_EXE_limber-test-cli");
const T: Duration = Duration::from_secs(10);

fn emulator(gripper: bool, answers_config: bool) -> Emulator {
    let mut cfg = EmulatorConfig::default();
    cfg.model.gripper = gripper;
    cfg.faults.no_config = !answers_config;
    Emulator::start_pty(cfg).unwrap()
}

/// Starts the driver (a process) on `emu` with the tests' short timeouts and `extra` keys.
fn driver(domain: &Domain, emu: &Emulator, name: &str, extra: &str) -> Proc {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"));
    let cfg = limber_tests::pioneer_test_config(dir, &format!("has-{name}"), extra);
    let port = emu.pty_path().unwrap().display().to_string();
    limber_tests::start_pioneer(PIONEER, domain.name(), &port, &cfg)
}

/// Runs `limber args...` in `domain`; fails the test if it takes longer than `T`.
fn limber(domain: &Domain, args: &[&str]) -> Output {
    let mut cmd = Command::new(CLI);
    cmd.args(args)
        .env("LIMBER_DOMAIN", domain.name())
        .stdin(Stdio::null());
    let (tx, rx) = mpsc::channel();
    std::thread::spawn(move || {
        let _ = tx.send(cmd.output());
    });
    rx.recv_timeout(T)
        .unwrap_or_else(|_| panic!("limber {args:?} did not end within {T:?}"))
        .unwrap_or_else(|e| panic!("cannot run limber {args:?}: {e}"))
}

fn text(o: &Output) -> String {
    format!(
        "exit {:?}\nstdout: {}\nstderr: {}",
        o.status.code(),
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

fn devices(domain: &Domain) -> Vec<String> {
    let mut names: Vec<String> = limber_services::list_devices(domain)
        .unwrap()
        .iter()
        .filter(|d| d.alive)
        .map(|d| d.name.to_string())
        .collect();
    names.sort();
    names
}

const BODY: [&str; 2] = ["pioneer/actarray/1", "pioneer/gripper/0"];

/// The gripper and lift commands the robot received and ignored (it has none).
fn ignored(emu: &Emulator) -> (u64, u64) {
    let r = emu.state().robot;
    (
        r.unsupported_gripper_commands,
        r.unsupported_gripperval_commands,
    )
}

#[test]
fn a_robot_whose_configpac_says_gripper_gets_gripper_and_lift_served() {
    let domain = Domain::unique_for_test();
    let emu = emulator(true, true);
    let mut drv = driver(&domain, &emu, "gripper", "");
    assert!(emu.state().robot.config_requests >= 1);
    let names = devices(&domain);
    for d in BODY {
        assert!(names.iter().any(|n| n == d), "{d} not served: {names:?}");
    }
    let o = limber(&domain, &["gripper", "pioneer/gripper/0", "open"]);
    assert!(o.status.success(), "{}", text(&o));
    let (opened, st) = emu.wait_for(T, |s| s.robot.paddles >= 1.0);
    assert!(opened, "the paddles never opened: {:?}", st.robot);
    let o = limber(&domain, &["list"]);
    assert!(!text(&o).contains("has no gripper"), "{}", text(&o));
    drv.signal(libc::SIGTERM);
    assert_eq!(drv.wait_timeout(T), Some(0));
}

#[test]
fn a_robot_without_a_gripper_is_never_sent_a_gripper_or_lift_command() {
    let domain = Domain::unique_for_test();
    let emu = emulator(false, true);
    let mut drv = driver(&domain, &emu, "no-gripper", "");
    assert!(emu.state().robot.config_requests >= 1);
    let names = devices(&domain);
    assert_eq!(
        names,
        ["pioneer/actarray/0", "pioneer/gripper/1", "pioneer/limb/0"],
        "the arm only"
    );
    // `limber list` and the verbs say what the robot lacks.
    let o = limber(&domain, &["list"]);
    assert!(
        String::from_utf8_lossy(&o.stdout)
            .contains("robot pioneer has no gripper, no lift (driver pioneer)"),
        "{}",
        text(&o)
    );
    let o = limber(
        &domain,
        &["gripper", "pioneer/gripper/0", "open", "--timeout", "0.5"],
    );
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("robot pioneer has no gripper"),
        "{}",
        text(&o)
    );
    let o = limber(
        &domain,
        &[
            "actarray",
            "pioneer/actarray/1",
            "pos",
            "0",
            "0.03",
            "--timeout",
            "0.5",
        ],
    );
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("robot pioneer has no lift"),
        "{}",
        text(&o)
    );
    // The arm works, and the commands went to the robot in order: a barrier (an arm
    // command the emulator carried out) proves the driver's writes so far have arrived.
    let o = limber(
        &domain,
        &["actarray", "pioneer/actarray/0", "pos", "0", "0.2"],
    );
    assert!(o.status.success(), "{}", text(&o));
    drv.signal(libc::SIGTERM);
    assert_eq!(drv.wait_timeout(T), Some(0));
    // The driver's whole life, start to close: not one GRIPPER or GRIPPERVAL.
    assert_eq!(ignored(&emu), (0, 0));
    assert_eq!(emu.state().robot.gripper_commands, 0);
}

/// `body_gripper = true` on a robot whose CONFIGpac says "no gripper": the user decides.
/// The devices are served and their commands reach the robot, which ignores them (the
/// emulator counts them, as AMRISim logs "unsupported command 33"); the driver warned at
/// start. The state reads the switch byte such a robot sends (zero: paddles open), so an
/// OPEN ends "ok": forcing it is the user's word that the gripper is there.
#[test]
fn body_gripper_true_serves_the_gripper_whatever_the_robot_says() {
    let domain = Domain::unique_for_test();
    let emu = emulator(false, true);
    let mut drv = driver(&domain, &emu, "forced", "body_gripper = true");
    let names = devices(&domain);
    for d in BODY {
        assert!(names.iter().any(|n| n == d), "{d} not served: {names:?}");
    }
    let o = limber(&domain, &["gripper", "pioneer/gripper/0", "open"]);
    assert!(o.status.success(), "{}", text(&o));
    let (reached, _) = emu.wait_for(T, |s| s.robot.unsupported_gripper_commands >= 1);
    assert!(
        reached,
        "the OPEN never reached the robot: {:?}",
        ignored(&emu)
    );
    drv.signal(libc::SIGTERM);
    assert_eq!(drv.wait_timeout(T), Some(0));
    assert_eq!(ignored(&emu), (1, 0));
}

/// A controller that does not answer CONFIG: with `auto` (the default) the driver decides
/// safely (no gripper, no lift, a warning saying how to force it); `true` forces them.
#[test]
fn a_robot_that_does_not_answer_config_gets_no_gripper_unless_forced() {
    let domain = Domain::unique_for_test();
    let emu = emulator(true, false);
    let mut drv = driver(&domain, &emu, "unanswered", "");
    assert!(emu.state().stats.config_dropped >= 3);
    let names = devices(&domain);
    for d in BODY {
        assert!(!names.iter().any(|n| n == d), "{d} served: {names:?}");
    }
    drv.signal(libc::SIGTERM);
    assert_eq!(drv.wait_timeout(T), Some(0));
    assert_eq!(emu.state().robot.gripper_commands, 0);

    let domain = Domain::unique_for_test();
    let mut drv = driver(&domain, &emu, "unanswered-forced", "body_gripper = true");
    let names = devices(&domain);
    for d in BODY {
        assert!(names.iter().any(|n| n == d), "{d} not served: {names:?}");
    }
    let o = limber(&domain, &["gripper", "pioneer/gripper/0", "open"]);
    assert!(o.status.success(), "{}", text(&o));
    let (opened, st) = emu.wait_for(T, |s| s.robot.paddles >= 1.0);
    assert!(opened, "the paddles never opened: {:?}", st.robot);
    drv.signal(libc::SIGTERM);
    assert_eq!(drv.wait_timeout(T), Some(0));
}
