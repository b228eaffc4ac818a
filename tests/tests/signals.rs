//! Every signal that would end a process by default either stops the arm and ends the
//! Pioneer driver as SIGTERM does, or is ignored (`limber_services::signals`): watched
//! through the emulator (owned by this test process), not through the driver's word.
//! The bridges, too, survive the signals they ignore.

use std::time::Duration;

use limber_emulator::{Emulator, EmulatorConfig, EmulatorState, SyncStage};
use limber_services::prelude::*;
use limber_services::{Domain, Role};
use limber_tests::Proc;

const PIONEER: &str = env!("CARGO_BIN_EXE_limber-test-pioneer");
const CLI: &str = env!("CARGO_BIN_EXE_limber-test-cli");
const T: Duration = Duration::from_secs(5);

fn start(domain: &Domain, emu: &Emulator, label: &str) -> Proc {
    start_with(domain, emu, label, &[])
}

/// The driver with `extra` arguments (`--spin`), once it is ready.
fn start_with(domain: &Domain, emu: &Emulator, label: &str, extra: &[&str]) -> Proc {
    let cfg = limber_tests::pioneer_test_config(
        std::path::Path::new(env!("CARGO_TARGET_TMPDIR")),
        label,
        "",
    );
    let port = emu.pty_path().unwrap().display().to_string();
    let mut args = vec!["--port", &port, "--config", cfg.to_str().unwrap()];
    args.extend_from_slice(extra);
    let mut d = Proc::spawn(PIONEER, domain.name(), &args);
    assert!(
        d.read_until(|l| l.ends_with("ready")).is_some(),
        "driver did not start"
    );
    d
}

/// Joint 0 moving slowly towards its limit, as the emulator shows it.
fn move_joint_0(arm: &mut ActArrayClient, emu: &Emulator) {
    arm.power(true).unwrap();
    let t = arm.move_at_speed(0, 0.1).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);
    let (moving, st) = emu.wait_for(T, |s| s.robot.servo_targets[0] != s.robot.servo_ticks[0]);
    assert!(moving, "the joint does not move: {:?}", st.robot);
}

fn name(sig: i32) -> String {
    let names = [
        (libc::SIGQUIT, "SIGQUIT"),
        (libc::SIGXCPU, "SIGXCPU"),
        (libc::SIGPWR, "SIGPWR"),
        (libc::SIGALRM, "SIGALRM"),
        (libc::SIGIO, "SIGIO"),
        (libc::SIGSTKFLT, "SIGSTKFLT"),
        (libc::SIGXFSZ, "SIGXFSZ"),
        (libc::SIGSYS, "SIGSYS"),
        (libc::SIGTRAP, "SIGTRAP"),
        (libc::SIGUSR1, "SIGUSR1"),
        (libc::SIGUSR2, "SIGUSR2"),
        (libc::SIGVTALRM, "SIGVTALRM"),
        (libc::SIGPROF, "SIGPROF"),
    ];
    match names.iter().find(|(s, _)| *s == sig) {
        Some((_, n)) => n.to_string(),
        None if sig >= libc::SIGRTMIN() => format!("SIGRTMIN+{}", sig - libc::SIGRTMIN()),
        None => format!("signal {sig}"),
    }
}

/// `sig` ends the driver with exit 0 after it stopped the arm where it was (ARM_STOP) and
/// closed the link (CLOSE), while joint 0 was moving.
fn stops_the_arm_and_ends(sig: i32) {
    let domain = Domain::unique_for_test();
    let emu = Emulator::start_pty(EmulatorConfig::default()).unwrap();
    let mut driver = start(&domain, &emu, &name(sig));
    let c = Context::new(&domain, Role::Client, "signals-test").unwrap();
    let mut arm = ActArrayClient::connect_timeout(&c, "pioneer/actarray/0", T).unwrap();
    move_joint_0(&mut arm, &emu);
    driver.signal(sig);
    assert_eq!(
        driver.wait_timeout(T),
        Some(0),
        "exit status after {}",
        name(sig)
    );
    let (closed, st) = emu.wait_for(T, |s| s.robot.stage == SyncStage::NoSync);
    assert!(closed, "no CLOSE after {}: {:?}", name(sig), st.robot.stage);
    assert_eq!(
        st.robot.servo_targets[0],
        st.robot.servo_ticks[0],
        "the arm was left moving after {}",
        name(sig)
    );
}

#[test]
fn sigquit_stops_the_arm_and_ends_the_driver() {
    stops_the_arm_and_ends(libc::SIGQUIT);
}

/// What the kernel sends a `--rt` task over RLIMIT_RTTIME (SIGKILL follows).
#[test]
fn sigxcpu_stops_the_arm_and_ends_the_driver() {
    stops_the_arm_and_ends(libc::SIGXCPU);
}

#[test]
fn sigpwr_stops_the_arm_and_ends_the_driver() {
    stops_the_arm_and_ends(libc::SIGPWR);
}

/// The target of joint 3 as the emulator has it.
fn target_3(s: &EmulatorState) -> u8 {
    s.robot.servo_targets[3]
}

/// Every other signal that would end a process by default, sent one after another to one
/// driver while joint 0 moves: the driver goes on serving through the same link (after
/// each, a command reaches the robot: the emulator's target of joint 3 changes), and a
/// SIGTERM still ends it cleanly, stopping the arm.
fn the_other_terminating_signals_are_ignored(extra: &[&str], label: &str) {
    let domain = Domain::unique_for_test();
    let emu = Emulator::start_pty(EmulatorConfig::default()).unwrap();
    let mut driver = start_with(&domain, &emu, label, extra);
    let c = Context::new(&domain, Role::Client, "signals-test").unwrap();
    let mut arm = ActArrayClient::connect_timeout(&c, "pioneer/actarray/0", T).unwrap();
    // A spinning driver needs no wake-up.
    arm.set_wake_driver(extra.is_empty());
    move_joint_0(&mut arm, &emu);
    let signals = [
        libc::SIGALRM,
        libc::SIGIO,
        libc::SIGSTKFLT,
        libc::SIGXFSZ,
        libc::SIGSYS,
        libc::SIGTRAP,
        libc::SIGUSR1,
        libc::SIGUSR2,
        libc::SIGVTALRM,
        libc::SIGPROF,
        libc::SIGRTMIN(),
        libc::SIGRTMIN() + 1,
        libc::SIGRTMAX(),
    ];
    let mut target = 0.2;
    for sig in signals {
        let before = target_3(&emu.state());
        driver.signal(sig);
        // The driver's next command after the signal reaches the robot.
        target = -target;
        let t = arm
            .move_to(3, target)
            .unwrap_or_else(|e| panic!("after {}: {e}", name(sig)));
        assert_eq!(
            arm.wait_outcome(t, T)
                .unwrap_or_else(|e| panic!("after {}: {e}", name(sig))),
            Status::Ok,
            "after {}",
            name(sig)
        );
        let (arrived, st) = emu.wait_for(T, |s| target_3(s) != before);
        assert!(
            arrived,
            "after {}, the command did not reach the robot: {:?}",
            name(sig),
            st.robot
        );
        assert!(
            matches!(driver.child.try_wait(), Ok(None)),
            "the driver ended on {}",
            name(sig)
        );
        assert_eq!(st.robot.stage, SyncStage::Open, "after {}", name(sig));
    }
    // Joint 0 is still under way (nobody stopped it); SIGTERM stops it and ends the driver.
    driver.signal(libc::SIGTERM);
    assert_eq!(driver.wait_timeout(T), Some(0));
    let (closed, st) = emu.wait_for(T, |s| s.robot.stage == SyncStage::NoSync);
    assert!(closed, "no CLOSE: {:?}", st.robot.stage);
    assert_eq!(st.robot.servo_targets[0], st.robot.servo_ticks[0]);
}

#[test]
fn the_other_terminating_signals_are_ignored_by_the_driver() {
    the_other_terminating_signals_are_ignored(&[], "ignored");
}

#[test]
fn the_other_terminating_signals_are_ignored_by_the_spinning_driver() {
    the_other_terminating_signals_are_ignored(&["--spin"], "ignored-spin");
}

/// Both bridges ignore SIGALRM and SIGUSR1 (and the like): the arm of domain A is still
/// served in domain B through them; SIGTERM then ends each with exit 0.
#[test]
fn bridges_survive_sigalrm_and_sigusr1() {
    let a = Domain::unique_for_test();
    let b = Domain::unique_for_test();
    let mut driver = Proc::spawn(CLI, a.name(), &["pioneer", "--emulated"]);
    assert!(driver.read_until(|l| l.ends_with("ready")).is_some());
    let mut expose = Proc::spawn(CLI, a.name(), &["bridge", "expose"]);
    assert!(
        expose
            .read_until(|l| l == "exposed pioneer/actarray/0")
            .is_some()
    );
    let mut mirror = Proc::spawn(CLI, b.name(), &["bridge", "mirror", "--from", a.name()]);
    assert!(
        mirror
            .read_until(|l| l == "mirrored pioneer/actarray/0 as pioneer/actarray/0")
            .is_some()
    );
    let ctx = Context::new(&b, Role::Client, "signals-test").unwrap();
    let mut arm =
        ActArrayClient::connect_timeout(&ctx, "pioneer/actarray/0", Duration::from_secs(10))
            .unwrap();
    for sig in [
        libc::SIGALRM,
        libc::SIGUSR1,
        libc::SIGUSR2,
        libc::SIGIO,
        libc::SIGRTMIN(),
    ] {
        expose.signal(sig);
        mirror.signal(sig);
        // A request through both bridges, answered by the driver: both still relay.
        let g = arm
            .geometry()
            .unwrap_or_else(|e| panic!("after {}: {e}", name(sig)));
        assert_eq!(g.actuators_count, 6);
        assert!(
            matches!(expose.child.try_wait(), Ok(None)),
            "expose ended on {}",
            name(sig)
        );
        assert!(
            matches!(mirror.child.try_wait(), Ok(None)),
            "mirror ended on {}",
            name(sig)
        );
    }
    drop(arm);
    mirror.signal(libc::SIGTERM);
    assert_eq!(mirror.wait_timeout(Duration::from_secs(10)), Some(0));
    expose.signal(libc::SIGTERM);
    assert_eq!(expose.wait_timeout(Duration::from_secs(10)), Some(0));
    driver.signal(libc::SIGTERM);
    assert_eq!(driver.wait_timeout(Duration::from_secs(10)), Some(0));
}
