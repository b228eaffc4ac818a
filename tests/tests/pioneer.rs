//! The Pioneer driver as a process, against the emulator (owned by this test process so it
//! can inject faults), with clients in this process. Each test has its own domain.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use limber_emulator::{Emulator, EmulatorConfig, Faults, ModelConfig};
use limber_examples::pick_block::{self, Devices, PickParams, Step};
use limber_examples::random_moves::{self, RandomParams};
use limber_interfaces::diagnostics::hardware;
use limber_p2os::{ArmCalibration, ArmJoint, Command};
use limber_services::diagnostics::StatsReader;
use limber_services::prelude::*;
use limber_services::{Domain, RequestError, Role, WaitError};
use limber_tests::Proc;

const PIONEER: &str = env!("CARGO_BIN_EXE_limber-test-pioneer");
const T: Duration = Duration::from_secs(5);

/// Short timeouts so faults are detected quickly in tests.
fn config_file(name: &str) -> PathBuf {
    limber_tests::pioneer_test_config(std::path::Path::new(env!("CARGO_TARGET_TMPDIR")), name, "")
}

fn start(domain: &Domain, emu: &Emulator, name: &str) -> Proc {
    let port = match emu.tcp_addr() {
        Some(a) => format!("tcp://{a}"),
        None => emu.pty_path().unwrap().display().to_string(),
    };
    limber_tests::start_pioneer(PIONEER, domain.name(), &port, &config_file(name))
}

fn ctx(domain: &Domain) -> Context {
    Context::new(domain, Role::Client, "pioneer-test").unwrap()
}

/// Fastest servo steps, so motions take fractions of a second.
fn fast(arm: &mut ActArrayClient) {
    for j in 0..6 {
        arm.set_speed_config(j, 20.0).unwrap();
    }
}

#[test]
fn the_papers_programs_run_on_the_emulated_pioneer() {
    let domain = Domain::unique_for_test();
    let emu = Emulator::start_pty(EmulatorConfig::default()).unwrap();
    let _driver = start(&domain, &emu, "programs");
    let c = ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&c, "pioneer/actarray/0", T).unwrap();
    arm.power(true).unwrap();
    fast(&mut arm);

    // Listing 1: random joint moves inside the geometry's limits.
    let geom = arm.geometry().unwrap();
    assert_eq!(geom.actuators_count, 6);
    let q = random_moves::run(
        &mut arm,
        &RandomParams {
            rounds: 2,
            ..Default::default()
        },
        &mut |_, _| {},
    )
    .unwrap();
    for (j, g) in geom.actuators().iter().enumerate() {
        assert!(
            q[j] >= g.min - 1e-9 && q[j] <= g.max + 1e-9,
            "joint {j} at {} outside [{}, {}]",
            q[j],
            g.min,
            g.max
        );
    }
    let s = arm.state().unwrap();
    assert!(
        s.actuators()
            .iter()
            .all(|a| a.flags().unwrap() == ActuatorFlags::IDLE),
        "{s:?}"
    );

    // Listing 2: pick a block with the limb and the arm gripper.
    let mut dev = Devices::connect(&c, "pioneer/limb/0", "pioneer/gripper/1", T).unwrap();
    let mut steps = Vec::new();
    let summary = pick_block::run(&mut dev, &PickParams::default(), &mut |e| {
        if let pick_block::Event::Done(step, l, _) = e {
            steps.push((step, l.position));
        }
    })
    .unwrap();
    assert_eq!(summary.steps, 11);
    // The end effector went where the program asked, to within a servo tick or so.
    for (step, p) in &steps {
        let want = match step {
            Step::Descend(x) | Step::PutDown(x) | Step::Approach(x) | Step::Carry(x) => *x,
            _ => continue,
        };
        let err =
            ((p.x - want[0]).powi(2) + (p.y - want[1]).powi(2) + (p.z - want[2]).powi(2)).sqrt();
        assert!(err < 0.01, "{step:?}: at {p:?}, {err} m from {want:?}");
    }
    assert_eq!(
        dev.limb.state().unwrap().limb_state().unwrap(),
        LimbState::Idle
    );
    assert_eq!(
        dev.gripper.state().unwrap().gripper_state().unwrap(),
        GripperState::Open
    );
    // And the emulated servos are where the driver says.
    let st = emu.state();
    let home = limber_emulator::default_arm_info();
    for j in 0..5 {
        assert_eq!(
            st.robot.servo_ticks[j], home.joints[j].home,
            "joint {j} not home"
        );
    }
}

#[test]
fn out_of_reach_is_reported_and_cleared_by_the_next_valid_command() {
    let domain = Domain::unique_for_test();
    let emu = Emulator::start_pty(EmulatorConfig::default()).unwrap();
    let _driver = start(&domain, &emu, "oor");
    let c = ctx(&domain);
    let mut limb = LimbClient::connect_timeout(&c, "pioneer/limb/0", T).unwrap();
    // Barriers: a joint speed (ARM_SPEED) that the robot has taken; the link keeps the
    // order, so everything sent before it has arrived.
    let mut arm = ActArrayClient::connect_timeout(&c, "pioneer/actarray/0", T).unwrap();
    let cal = ArmCalibration::from(limber_emulator::default_arm_info());
    let joint = ArmJoint::new(1).unwrap();
    let mut barrier = |speed: f64| {
        arm.set_speed_config(0, speed).unwrap();
        let ms = cal.speed_to_ms_per_step(joint, speed).unwrap();
        let (arrived, st) = emu.wait_for(T, |s| s.robot.ms_per_step[0] == ms);
        assert!(
            arrived,
            "the barrier (speed {speed}) never reached the robot"
        );
        st
    };
    let speed_bytes = Command::ArmSpeed {
        joint,
        ms_per_step: 1,
    }
    .encode()
    .unwrap()
    .as_bytes()
    .len() as u64;
    let (slow, fast) = (0.3, 1.0);
    assert_ne!(
        cal.speed_to_ms_per_step(joint, slow).unwrap(),
        cal.speed_to_ms_per_step(joint, fast).unwrap()
    );
    let st0 = barrier(slow);
    let t = limb
        .set_pose([1.5, 0.0, 0.3], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0])
        .unwrap();
    assert_eq!(limb.wait_outcome(t, T).unwrap(), Status::OutOfReach);
    assert_eq!(
        limb.state().unwrap().limb_state().unwrap(),
        LimbState::OutOfReach
    );
    // Nothing reached the robot for the refused pose (only keep-alives may have).
    let st1 = barrier(fast);
    let sent = st1.stats.bytes_in - st0.stats.bytes_in;
    assert!(
        sent >= speed_bytes && (sent - speed_bytes).is_multiple_of(6),
        "{sent} bytes (the barrier is {speed_bytes}) sent after a refused pose"
    );
    assert_eq!(
        st1.robot.servo_targets, st0.robot.servo_targets,
        "a refused pose moved the arm"
    );
    let t = limb.set_position([0.35, 0.0, 0.25]).unwrap();
    assert_eq!(limb.wait_outcome(t, T).unwrap(), Status::Ok);
    assert_ne!(
        limb.state().unwrap().limb_state().unwrap(),
        LimbState::OutOfReach
    );
}

fn wait_flag(arm: &mut ActArrayClient, up: bool, timeout: Duration) -> bool {
    let deadline = Instant::now() + timeout;
    while Instant::now() < deadline {
        if let Ok(s) = arm.wait_state(Duration::from_millis(200))
            && s.header.link_up() == up
        {
            return true;
        }
    }
    false
}

#[test]
fn a_killed_link_is_detected_reported_and_recovered_without_restart() {
    let domain = Domain::unique_for_test();
    let emu =
        Emulator::start_tcp(EmulatorConfig::default(), "127.0.0.1:0".parse().unwrap()).unwrap();
    let _driver = start(&domain, &emu, "recover");
    let c = ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&c, "pioneer/actarray/0", T).unwrap();
    assert!(wait_flag(&mut arm, true, T));

    emu.disconnect();
    // The fault is detected and recovered from (a reconnect takes a fraction of a second,
    // so the link-down samples may be superseded before this client reads them: the
    // statistics count both).
    let mut stats = StatsReader::open(&c, "pioneer").unwrap();
    let deadline = Instant::now() + Duration::from_secs(15);
    loop {
        if let Ok(s) = stats.wait(Duration::from_secs(2))
            && s.link_faults >= 1
            && s.reconnects >= 1
            && s.header.flags & limber_interfaces::device_flag::LINK_UP != 0
        {
            break;
        }
        assert!(Instant::now() < deadline, "link not recovered");
    }
    assert!(wait_flag(&mut arm, true, T));
    arm.power(true).unwrap();
    let t = arm.move_to(0, 0.3).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);
}

#[test]
fn silence_and_garbage_are_detected_and_survived() {
    let domain = Domain::unique_for_test();
    let emu = Emulator::start_pty(EmulatorConfig::default()).unwrap();
    let _driver = start(&domain, &emu, "faults");
    let c = ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&c, "pioneer/actarray/0", T).unwrap();
    assert!(wait_flag(&mut arm, true, T));

    // Garbage and bad checksums: counted, and the arm keeps working.
    emu.set_faults(Faults {
        garbage_rate: 0.2,
        bad_checksum_rate: 0.1,
        ..Faults::default()
    });
    // The driver sees the faults (counted), and the arm keeps working meanwhile.
    let mut stats = StatsReader::open(&c, "pioneer").unwrap();
    let deadline = Instant::now() + Duration::from_secs(5);
    loop {
        let s = *stats.wait(Duration::from_secs(3)).unwrap();
        if s.bad_checksums > 0 && s.resync_bytes > 0 {
            break;
        }
        assert!(Instant::now() < deadline, "faults not counted: {s:?}");
    }
    let t = arm.move_to(1, -0.5).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);

    // Silence: the link is reported down, and recovered once the robot talks again.
    emu.set_faults(Faults {
        silent: true,
        ..Faults::default()
    });
    assert!(wait_flag(&mut arm, false, T), "silence not detected");
    // Commands while the link is down are refused, not queued.
    let t = arm.move_to(1, 0.2).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::LinkDown);
    emu.set_faults(Faults::default());
    assert!(
        wait_flag(&mut arm, true, Duration::from_secs(10)),
        "not recovered"
    );
    // The refused command was not replayed after recovery. The barrier: a later command
    // (joint 1 to 0.3) that the robot has carried out; a replay would have come before it.
    let cal = limber_p2os::ArmCalibration::from(limber_emulator::default_arm_info());
    let tick = |joint: u8, rad: f64| {
        cal.radians_to_ticks(limber_p2os::ArmJoint::new(joint).unwrap(), rad)
            .unwrap()
            .tick
    };
    let t = arm.move_to(0, 0.3).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);
    let (arrived, st) = emu.wait_for(T, |s| s.robot.servo_targets[0] == tick(1, 0.3));
    assert!(arrived, "the later command never reached the robot");
    assert_ne!(
        st.robot.servo_targets[1],
        tick(2, 0.2),
        "a refused command was replayed"
    );
}

#[test]
fn a_robot_that_stops_reading_is_a_send_timeout_not_a_frozen_loop() {
    let domain = Domain::unique_for_test();
    let emu = Emulator::start_pty(EmulatorConfig::fast()).unwrap();
    let _driver = start(&domain, &emu, "deaf");
    let c = ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&c, "pioneer/actarray/0", T).unwrap();
    assert!(wait_flag(&mut arm, true, T));
    arm.power(true).unwrap();

    // The robot stops reading but keeps talking: the driver's commands fill the pty (some
    // 20 KB, about 2000 commands), then a send waits the link's write timeout and that
    // command is refused as LINK_DOWN. Every command gets its outcome meanwhile.
    emu.set_faults(Faults {
        deaf: true,
        ..Faults::default()
    });
    let deadline = Instant::now() + Duration::from_secs(60);
    let mut sent = 0u32;
    loop {
        assert!(
            Instant::now() < deadline,
            "no command refused after {sent} sent to a robot that reads nothing"
        );
        let target = if sent.is_multiple_of(2) { 0.1 } else { -0.1 };
        let t = arm.move_to(0, target).unwrap();
        sent += 1;
        match arm.wait_outcome(t, T).unwrap() {
            Status::Ok => {}
            Status::LinkDown => break,
            other => panic!("command {sent}: {other:?}"),
        }
    }
    assert!(
        sent > 100,
        "refused after {sent} commands: the pty was not full"
    );
    // The loop still answers requests.
    assert_eq!(arm.geometry().unwrap().actuators_count, 6);
    // The robot reads again: commands are carried out.
    emu.set_faults(Faults::default());
    assert!(
        wait_flag(&mut arm, true, Duration::from_secs(15)),
        "not recovered"
    );
    arm.power(true).unwrap();
    let deadline = Instant::now() + Duration::from_secs(15);
    loop {
        let t = arm.move_to(0, 0.3).unwrap();
        match arm.wait_outcome(t, T).unwrap() {
            Status::Ok => break,
            // The pty may still be draining the commands of the deaf phase.
            Status::LinkDown => assert!(Instant::now() < deadline, "commands still refused"),
            other => panic!("after recovery: {other:?}"),
        }
    }
}

/// `sig` ends the driver with exit 0 after it stopped the arm (ARM_STOP) and closed the
/// link (CLOSE), while a joint was moving at a slow speed.
fn a_termination_signal_stops_the_arm(sig: i32, name: &str) {
    let domain = Domain::unique_for_test();
    let emu = Emulator::start_pty(EmulatorConfig::default()).unwrap();
    let mut driver = start(&domain, &emu, name);
    let c = ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&c, "pioneer/actarray/0", T).unwrap();
    arm.power(true).unwrap();
    let t = arm.move_at_speed(0, 0.1).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);
    let (moving, st) = emu.wait_for(T, |s| s.robot.servo_targets[0] != s.robot.servo_ticks[0]);
    assert!(moving, "the joint does not move: {:?}", st.robot);
    driver.signal(sig);
    assert_eq!(
        driver.wait_timeout(T),
        Some(0),
        "exit status after signal {sig}"
    );
    let (closed, st) = emu.wait_for(T, |s| s.robot.stage == limber_emulator::SyncStage::NoSync);
    assert!(closed, "no CLOSE: {:?}", st.robot.stage);
    // The arm was stopped where it was, not left running to the old target.
    assert_eq!(st.robot.servo_targets[0], st.robot.servo_ticks[0]);
    drop(arm);
}

#[test]
fn sigterm_stops_the_arm_closes_the_link_and_exits_zero() {
    a_termination_signal_stops_the_arm(libc::SIGTERM, "sigterm");
}

#[test]
fn sighup_stops_the_arm_closes_the_link_and_exits_zero() {
    a_termination_signal_stops_the_arm(libc::SIGHUP, "sighup");
}

#[test]
fn sigint_stops_the_arm_closes_the_link_and_exits_zero() {
    a_termination_signal_stops_the_arm(libc::SIGINT, "sigint");
}

/// Signals that are not termination requests (a stop and continue as Ctrl-Z and `bg` do,
/// a terminal resize, SIGCHLD) only interrupt the driver's wait: it goes on
/// serving, the link stays open, and a later SIGTERM still ends it cleanly.
fn other_signals_do_not_end_the_driver(extra: &[&str], name: &str) {
    let domain = Domain::unique_for_test();
    let emu = Emulator::start_pty(EmulatorConfig::default()).unwrap();
    let port = emu.pty_path().unwrap().display().to_string();
    let cfg = config_file(name);
    let mut args = vec!["--port", &port, "--config", cfg.to_str().unwrap()];
    args.extend_from_slice(extra);
    let mut driver = Proc::spawn(PIONEER, domain.name(), &args);
    assert!(driver.read_until(|l| l.ends_with("ready")).is_some());
    let c = ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&c, "pioneer/actarray/0", T).unwrap();
    arm.set_wake_driver(extra.is_empty());
    // The loop is running (the "ready" line comes just before it starts waiting).
    assert_eq!(arm.geometry().unwrap().actuators_count, 6);
    for sigs in [
        &[libc::SIGCONT][..],
        &[libc::SIGWINCH][..],
        &[libc::SIGCHLD][..],
        &[libc::SIGSTOP, libc::SIGCONT][..],
        // Ctrl-Z: caught (by iceoryx2), so the driver is not even suspended.
        &[libc::SIGTSTP][..],
    ] {
        for &sig in sigs {
            driver.signal(sig);
        }
        // A round trip after each: the loop is back in its wait before the next signal.
        assert_eq!(arm.geometry().unwrap().actuators_count, 6, "{sigs:?}");
    }
    // Requests are answered and commands carried out, by the same driver on the same link.
    assert_eq!(arm.geometry().unwrap().actuators_count, 6);
    let t = arm.move_to(3, 0.4).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);
    assert!(
        matches!(driver.child.try_wait(), Ok(None)),
        "the driver ended"
    );
    let st = emu.state();
    assert_eq!(st.robot.stage, limber_emulator::SyncStage::Open);
    driver.signal(libc::SIGTERM);
    assert_eq!(driver.wait_timeout(T), Some(0));
}

#[test]
fn sigcont_sigwinch_and_stop_continue_do_not_end_the_driver() {
    other_signals_do_not_end_the_driver(&[], "othersignals");
}

#[test]
fn sigcont_sigwinch_and_stop_continue_do_not_end_the_spinning_driver() {
    other_signals_do_not_end_the_driver(&["--spin"], "othersignals-spin");
}

#[test]
fn a_robot_without_an_arm_is_served_for_what_it_has() {
    let domain = Domain::unique_for_test();
    let cfg = EmulatorConfig {
        model: ModelConfig {
            arm: None,
            ..ModelConfig::default()
        },
        ..EmulatorConfig::default()
    };
    let emu = Emulator::start_pty(cfg).unwrap();
    let _driver = start(&domain, &emu, "noarm");
    let c = ctx(&domain);
    let names: Vec<String> = list_devices(&domain)
        .unwrap()
        .iter()
        .map(|d| d.name.to_string())
        .collect();
    assert_eq!(names, ["pioneer/actarray/1", "pioneer/gripper/0"]);
    let mut stats = StatsReader::open(&c, "pioneer").unwrap();
    let s = stats.wait(Duration::from_secs(3)).unwrap();
    assert_eq!(s.hardware & hardware::ARM, 0);
    assert_ne!(s.hardware & hardware::GRIPPER, 0);
    let mut grip = GripperClient::connect(&c, "pioneer/gripper/0").unwrap();
    let t = grip.close().unwrap();
    assert_eq!(grip.wait_outcome(t, T).unwrap(), Status::Ok);
    assert!(matches!(
        ActArrayClient::connect(&c, "pioneer/actarray/0"),
        Err(limber_services::ConnectError::NoDriver { .. })
    ));
    let _ = (RequestError::Timeout(T), WaitError::Timeout(T));
}

#[test]
fn spin_mode_with_pinning_serves_and_stops_cleanly() {
    let domain = Domain::unique_for_test();
    let emu = Emulator::start_pty(EmulatorConfig::default()).unwrap();
    let port = emu.pty_path().unwrap().display().to_string();
    let cfg = config_file("spin");
    let mut d = Proc::spawn(
        PIONEER,
        domain.name(),
        &[
            "--port",
            &port,
            "--config",
            cfg.to_str().unwrap(),
            "--spin",
            "--cpu",
            "0",
        ],
    );
    assert!(
        d.read_until(|l| l.ends_with("ready")).is_some(),
        "driver did not start"
    );
    let c = ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&c, "pioneer/actarray/0", T).unwrap();
    arm.set_wake_driver(false); // a spinning driver needs no wake-up
    assert_eq!(arm.geometry().unwrap().actuators_count, 6);
    let t = arm.move_to(3, 0.4).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);
    let mut stats = StatsReader::open(&c, "pioneer").unwrap();
    let s = stats.wait(Duration::from_secs(3)).unwrap();
    assert_eq!(s.loop_mode, limber_interfaces::diagnostics::loop_mode::SPIN);
    d.signal(libc::SIGTERM);
    assert_eq!(d.wait_timeout(T), Some(0));
}

/// SIGKILL leaves the driver no chance to stop the arm: the arm's autopark watchdog, which
/// the driver sets at connection (`autopark_s`), homes it and powers it off once no command
/// arrives. While the driver lives, its PULSE keep-alives count as contact: the arm moving
/// slowly for longer than the watchdog's time, with no client command, is not parked.
#[test]
fn a_sigkilled_drivers_arm_parks_by_itself() {
    let domain = Domain::unique_for_test();
    let emu = Emulator::start_pty(EmulatorConfig::default()).unwrap();
    let port = emu.pty_path().unwrap().display().to_string();
    let cfg = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("autopark.toml");
    std::fs::write(&cfg, "autopark_s = 2\npulse_interval_ms = 1000\n").unwrap();
    let mut driver = Proc::spawn(
        PIONEER,
        domain.name(),
        &["--port", &port, "--config", cfg.to_str().unwrap()],
    );
    assert!(driver.read_until(|l| l.ends_with("ready")).is_some());
    let (set, st) = emu.wait_for(T, |s| s.robot.autopark_s == 2);
    assert!(set, "AUTOPARK not set: {:?}", st.robot);
    let c = ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&c, "pioneer/actarray/0", T).unwrap();
    arm.power(true).unwrap();
    let t = arm.move_at_speed(0, 0.05).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);
    let (moving, st) = emu.wait_for(T, |s| s.robot.servo_targets[0] != s.robot.servo_ticks[0]);
    assert!(moving, "the joint does not move: {:?}", st.robot);
    // Twice the watchdog's time with only keep-alives on the link: no park.
    let (parked, st) = emu.wait_for(Duration::from_secs(4), |s| {
        s.robot.autoparks > 0 || !s.robot.arm_powered
    });
    assert!(!parked, "a live driver's arm parked: {:?}", st.robot);

    driver.signal(libc::SIGKILL);
    assert_eq!(driver.wait_timeout(T), None, "SIGKILL leaves no exit code");
    let home: Vec<u8> = limber_emulator::default_arm_info()
        .calibrations()
        .iter()
        .map(|c| c.home)
        .collect();
    let (parked, st) = emu.wait_for(Duration::from_secs(20), |s| {
        s.robot.autoparks == 1 && !s.robot.arm_powered && s.robot.servo_ticks[..] == home[..]
    });
    assert!(parked, "the arm did not park: {:?}", st.robot);
    drop(arm);
}

fn emulator_with(faults: Faults) -> Emulator {
    let cfg = EmulatorConfig {
        faults,
        ..EmulatorConfig::default()
    };
    Emulator::start_tcp(cfg, "127.0.0.1:0".parse().unwrap()).unwrap()
}

fn device_names(domain: &Domain) -> Vec<String> {
    list_devices(domain)
        .unwrap()
        .iter()
        .map(|d| d.name.to_string())
        .collect()
}

#[test]
fn a_lost_arm_info_reply_at_start_does_not_remove_the_arm() {
    let domain = Domain::unique_for_test();
    let emu = emulator_with(Faults {
        drop_arm_info_replies: 1,
        ..Faults::default()
    });
    let _driver = start(&domain, &emu, "armlost1");
    assert_eq!(emu.state().stats.arm_info_dropped, 1);
    assert!(
        device_names(&domain).contains(&"pioneer/actarray/0".to_string()),
        "the arm is not served"
    );
    let c = ctx(&domain);
    let mut stats = StatsReader::open(&c, "pioneer").unwrap();
    let s = stats.wait(Duration::from_secs(3)).unwrap();
    assert_ne!(s.hardware & hardware::ARM, 0);
    let mut arm = ActArrayClient::connect_timeout(&c, "pioneer/actarray/0", T).unwrap();
    assert!(wait_flag(&mut arm, true, T));
    arm.power(true).unwrap();
    let t = arm.move_to(0, 0.3).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);
}

#[test]
fn arm_info_lost_at_a_reconnect_is_retried_by_the_loop_and_the_arm_stream_restored() {
    let domain = Domain::unique_for_test();
    let emu = emulator_with(Faults::default());
    let _driver = start(&domain, &emu, "armlost2");
    let c = ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&c, "pioneer/actarray/0", T).unwrap();
    assert!(wait_flag(&mut arm, true, T));
    let answered_at_start = emu.state().stats.arm_info_out;
    assert!(answered_at_start >= 1);

    // Every ARM_INFO of the reconnection's handshake goes unanswered (3 attempts): the
    // handshake stops the ARMpac stream; the loop asks again and restarts it.
    emu.set_faults(Faults {
        drop_arm_info_replies: 3,
        ..Faults::default()
    });
    emu.disconnect();
    let (ok, st) = emu.wait_for(Duration::from_secs(15), |s| {
        s.stats.arm_info_dropped == 3 && s.stats.arm_info_out > answered_at_start
    });
    assert!(
        ok,
        "no ARM_INFO answered after the lost ones: {:?}",
        st.stats
    );
    // That answer came after the handshake's ARM_STATUS stop: the stream runs again.
    let (ok, st) = emu.wait_for(T, |s| s.robot.arm_status_mode == 2);
    assert!(ok, "the ARMpac stream was not restarted: {:?}", st.robot);
    let before = emu.state().stats.arm_packets_out;
    let (ok, _) = emu.wait_for(T, |s| s.stats.arm_packets_out > before + 3);
    assert!(ok, "no ARMpacs after the restart");
    assert!(wait_flag(&mut arm, true, T));
    let t = arm.move_to(0, 0.3).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);
}

#[test]
fn a_driver_that_started_without_an_answer_serves_the_arm_when_it_answers() {
    let domain = Domain::unique_for_test();
    let emu = emulator_with(Faults {
        drop_arm_info_replies: 3,
        ..Faults::default()
    });
    let _driver = start(&domain, &emu, "armlost3");
    assert_eq!(emu.state().stats.arm_info_dropped, 3);
    assert!(!device_names(&domain).contains(&"pioneer/actarray/0".to_string()));
    // The loop asks again (in the background: the driver is ready meanwhile) and the robot
    // answers: the arm's devices are offered while the driver runs.
    let (ok, st) = emu.wait_for(Duration::from_secs(10), |s| s.stats.arm_info_out >= 1);
    assert!(ok, "the driver stopped asking for the arm: {:?}", st.stats);
    let c = ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&c, "pioneer/actarray/0", T).unwrap();
    assert!(wait_flag(&mut arm, true, T));
    for dev in ["pioneer/limb/0", "pioneer/gripper/1"] {
        assert!(device_names(&domain).contains(&dev.to_string()), "{dev}");
    }
    // The statistics say the robot has an arm now.
    let mut stats = StatsReader::open(&c, "pioneer").unwrap();
    let deadline = Instant::now() + T;
    loop {
        let s = *stats.wait(Duration::from_secs(3)).unwrap();
        if s.hardware & hardware::ARM != 0 {
            assert_eq!(s.hardware & hardware::NO_ARM, 0);
            break;
        }
        assert!(
            Instant::now() < deadline,
            "hardware bits: {:#x}",
            s.hardware
        );
    }
    // The new devices wake the loop (their listeners were attached): a command is carried
    // out, with the ARMpac stream started and the arm powered as at a start.
    let (ok, st) = emu.wait_for(T, |s| s.robot.arm_status_mode == 2 && s.robot.arm_powered);
    assert!(ok, "the arm was not set up: {:?}", st.robot);
    let t = arm.move_to(0, 0.3).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);
    let cal = ArmCalibration::from(limber_emulator::default_arm_info());
    let tick = cal
        .radians_to_ticks(ArmJoint::new(1).unwrap(), 0.3)
        .unwrap()
        .tick;
    let (ok, st) = emu.wait_for(T, |s| s.robot.servo_targets[0] == tick);
    assert!(ok, "the command did not reach the arm: {:?}", st.robot);
    // It keeps serving what it offered from the start.
    let mut grip = GripperClient::connect(&c, "pioneer/gripper/0").unwrap();
    let t = grip.close().unwrap();
    assert_eq!(grip.wait_outcome(t, T).unwrap(), Status::Ok);
}

#[test]
fn a_second_driver_with_the_same_robot_name_is_refused_before_it_opens_the_link() {
    let domain = Domain::unique_for_test();
    let emu = emulator_with(Faults::default());
    let _first = start(&domain, &emu, "twice1");
    let c = ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&c, "pioneer/actarray/0", T).unwrap();
    assert!(wait_flag(&mut arm, true, T));
    assert_eq!(emu.state().stats.connections, 1);

    let port = format!("tcp://{}", emu.tcp_addr().unwrap());
    let cfg = config_file("twice2");
    let mut second = Proc::spawn(
        PIONEER,
        domain.name(),
        &["--port", &port, "--config", cfg.to_str().unwrap()],
    );
    let code = second.wait_timeout(Duration::from_secs(10));
    assert!(
        matches!(code, Some(c) if c != 0),
        "the second driver was not refused: {code:?}"
    );
    // It never connected: the first driver's link was left alone.
    let st = emu.state();
    assert_eq!(st.stats.connections, 1, "the second driver opened the link");
    assert!(st.connected);
    let mut stats = StatsReader::open(&c, "pioneer").unwrap();
    let s = stats.wait(Duration::from_secs(3)).unwrap();
    assert_eq!((s.link_faults, s.reconnects), (0, 0));
    let t = arm.move_to(0, 0.3).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);
}

/// The soak found a device whose clients' wake-ups stopped reaching the event-driven loop
/// (its commands and requests then waited for ever). A client that never wakes the driver
/// stands in for it: its commands and requests are still served, at the driver's ticks.
#[test]
fn commands_without_a_wake_up_are_still_served_at_the_next_tick() {
    let domain = Domain::unique_for_test();
    let emu = Emulator::start_pty(EmulatorConfig::default()).unwrap();
    let _driver = start(&domain, &emu, "nowake");
    let c = ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&c, "pioneer/actarray/0", T).unwrap();
    arm.power(true).unwrap();
    arm.set_wake_driver(false);
    arm.set_spin_budget(Duration::ZERO);
    for target in [0.2, -0.2, 0.1] {
        let t = arm.move_to(0, target).unwrap();
        assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);
    }
    assert_eq!(arm.geometry().unwrap().actuators_count, 6);
}
