//! The driver's link as a user meets it, with `limber emulator` and `limber pioneer` as
//! separate processes: a robot that falls silent (the emulator SIGSTOPped) does not freeze
//! the driver (issue 12 item 4), a TCP endpoint held by another driver is said so (item 6),
//! an arm that answers late is served, and what a robot lacks is said (issue 13 item 5).

use std::path::PathBuf;
use std::time::{Duration, Instant};

use limber_services::prelude::*;
use limber_services::{Domain, Role};

mod common;
use common::{Bg, limber, stderr, stdout};

const T: Duration = Duration::from_secs(10);

/// A driver configuration with short timeouts (a silent robot is found in 0.4 s).
fn config(name: &str) -> PathBuf {
    let path = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(format!("link-{name}.toml"));
    std::fs::write(
        &path,
        "link_timeout_ms = 400\nreconnect_interval_ms = 100\narm_info_timeout_ms = 500\n",
    )
    .unwrap();
    path
}

/// Starts `limber emulator` (`--pty` or `--tcp 0`, plus `extra`) and returns it with the
/// `--port` value that reaches it.
fn emulator(domain: &Domain, tcp: bool, extra: &[&str]) -> (Bg, String) {
    let mut args = if tcp {
        vec!["emulator", "--tcp", "0", "--ignore-stdin"]
    } else {
        vec!["emulator", "--pty", "--ignore-stdin"]
    };
    args.extend_from_slice(extra);
    let mut emu = Bg::spawn(domain.name(), &args);
    let first = emu.line(|l| !l.is_empty());
    let port = if tcp { format!("tcp://{first}") } else { first };
    (emu, port)
}

fn pioneer(domain: &Domain, port: &str, cfg: &str, extra: &[&str]) -> Bg {
    let mut args = vec!["pioneer", "--port", port, "--config", cfg];
    args.extend_from_slice(extra);
    let mut d = Bg::spawn(domain.name(), &args);
    d.line(|l| l.ends_with("ready"));
    d
}

/// Waits (bounded) for a state sample whose LINK_UP flag is `up`.
fn wait_link(arm: &mut ActArrayClient, up: bool, timeout: Duration) -> bool {
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

/// Waits (bounded) for a state sample that satisfies `pred`; returns the last sample.
fn wait_arm(
    arm: &mut ActArrayClient,
    timeout: Duration,
    pred: impl Fn(&ActArrayData) -> bool,
) -> (bool, ActArrayData) {
    let deadline = Instant::now() + timeout;
    let mut last = ActArrayData::default();
    while Instant::now() < deadline {
        if let Ok(s) = arm.wait_state(Duration::from_millis(200)) {
            last = *s;
            if pred(s) {
                return (true, last);
            }
        }
    }
    (false, last)
}

/// Issue 12 item 4: with the robot SIGSTOPped, the driver answers requests, refuses
/// commands ("link down") and ends on SIGTERM with exit 0; when the robot continues, the
/// link recovers and the command refused meanwhile is not replayed.
fn a_stopped_robot_does_not_freeze_the_driver(tcp: bool) {
    let kind = if tcp { "tcp" } else { "pty" };
    let d = Domain::unique_for_test();
    let (mut emu, port) = emulator(&d, tcp, &[]);
    let cfg = config(&format!("stopped-{kind}"));
    let mut drv = pioneer(&d, &port, cfg.to_str().unwrap(), &[]);
    let ctx = Context::new(&d, Role::Client, "link-test").unwrap();
    let mut arm = ActArrayClient::connect_timeout(&ctx, "pioneer/actarray/0", T).unwrap();
    assert!(wait_link(&mut arm, true, T));
    for j in 0..6 {
        arm.set_speed_config(j, 20.0).unwrap();
    }
    let j0 = arm.wait_state(T).unwrap().actuators[0].position;

    emu.signal(libc::SIGSTOP);
    assert!(
        wait_link(&mut arm, false, T),
        "{kind}: the silent robot was not detected"
    );
    // While the driver reconnects: a request is answered...
    let t0 = Instant::now();
    let o = limber(
        d.name(),
        &["actarray", "pioneer/actarray/0", "geom", "--timeout", "20"],
    );
    eprintln!(
        "{kind}: geom with the robot stopped took {:?}",
        t0.elapsed()
    );
    assert!(o.status.success(), "{kind}: geom: {}", stderr(&o));
    assert!(stdout(&o).contains("rotary"), "{}", stdout(&o));
    // ... and a command refused, with its cause.
    let o = limber(
        d.name(),
        &["actarray", "pioneer/actarray/0", "pos", "0", "0.5"],
    );
    assert_eq!(o.status.code(), Some(5), "{kind}: {}", stderr(&o));
    assert!(stderr(&o).contains("link"), "{kind}: {}", stderr(&o));

    // The robot continues: the link comes back.
    emu.signal(libc::SIGCONT);
    assert!(
        wait_link(&mut arm, true, Duration::from_secs(30)),
        "{kind}: the link did not recover"
    );
    // The refused command is not replayed. The barrier: a later command on joint 1 that
    // the robot carries out; a replay would have come before it, and joint 0 (as fast)
    // would have moved by then.
    let t = arm.move_to(1, 0.3).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);
    let (arrived, st) = wait_arm(&mut arm, T, |s| {
        (s.actuators[1].position - 0.3).abs() < 0.02
    });
    assert!(
        arrived,
        "{kind}: joint 1 never arrived: {:?}",
        st.actuators[1]
    );
    assert!(
        (st.actuators[0].position - j0).abs() < 0.05,
        "{kind}: the refused command was replayed: joint 0 at {} (was {j0})",
        st.actuators[0].position
    );

    // Stopped again, SIGTERM ends the driver at once with exit 0, its link down. The arm
    // was idle (the barrier above finished; commands since were refused), and a
    // controller that lost its client parks the arm by its autopark watchdog.
    emu.signal(libc::SIGSTOP);
    assert!(wait_link(&mut arm, false, T), "{kind}: not detected twice");
    let t0 = Instant::now();
    assert_eq!(drv.term(), Some(0), "{kind}: exit status after SIGTERM");
    eprintln!(
        "{kind}: SIGTERM to exit with the robot stopped: {:?}",
        t0.elapsed()
    );
    emu.signal(libc::SIGCONT);
    // The arm was left still: a new driver finds every joint idle.
    drop(arm);
    let mut again = pioneer(&d, &port, cfg.to_str().unwrap(), &[]);
    let mut arm = ActArrayClient::connect_timeout(&ctx, "pioneer/actarray/0", T).unwrap();
    let (idle, st) = wait_arm(&mut arm, T, |s| {
        s.header.link_up()
            && s.actuators[..6]
                .iter()
                .all(|a| a.state & ActuatorFlags::MOVING.bits() == 0)
    });
    assert!(idle, "{kind}: the arm moves after the driver ended: {st:?}");
    assert_eq!(again.term(), Some(0));
    assert_eq!(emu.term(), Some(0));
}

#[test]
fn a_stopped_robot_on_a_pty_does_not_freeze_the_driver() {
    a_stopped_robot_does_not_freeze_the_driver(false);
}

#[test]
fn a_stopped_robot_over_tcp_does_not_freeze_the_driver() {
    a_stopped_robot_does_not_freeze_the_driver(true);
}

/// Issue "Nobody moves the arm who may not", item 7: the robot SIGSTOPped, a command
/// 0.3 s into its silence (before the link is declared down, after the default 1 s) is not
/// answered "ok" (the robot has been silent longer than `command_silence_ms`: "link
/// down"), and once the robot continues and the link is back the arm has not moved to it:
/// nothing queued before a link loss is sent after it.
#[test]
fn a_command_in_the_silence_before_a_link_loss_is_refused_and_never_carried_out() {
    let d = Domain::unique_for_test();
    let (mut emu, port) = emulator(&d, false, &[]);
    // The default link timeout (1 s): the second before a silent robot is declared down.
    let cfg = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("link-silent-second.toml");
    std::fs::write(
        &cfg,
        "reconnect_interval_ms = 100\narm_info_timeout_ms = 500\n",
    )
    .unwrap();
    let mut drv = pioneer(&d, &port, cfg.to_str().unwrap(), &[]);
    let ctx = Context::new(&d, Role::Client, "link-test").unwrap();
    let mut arm = ActArrayClient::connect_timeout(&ctx, "pioneer/actarray/0", T).unwrap();
    assert!(wait_link(&mut arm, true, T));
    let j2 = arm.wait_state(T).unwrap().actuators[2].position;
    assert!((j2 - 0.3).abs() > 0.2, "joint 2 starts at {j2}");

    emu.signal(libc::SIGSTOP);
    // The scenario's 0.3 s of silence: time that has to pass, not a wait for evidence.
    std::thread::sleep(Duration::from_millis(300));
    let o = limber(
        d.name(),
        &["actarray", "pioneer/actarray/0", "pos", "2", "0.3"],
    );
    assert!(
        wait_link(&mut arm, false, T),
        "the silent robot was not detected"
    );
    emu.signal(libc::SIGCONT);
    assert!(
        wait_link(&mut arm, true, Duration::from_secs(30)),
        "the link did not recover"
    );
    // The barrier: a later command on joint 1 that the robot carries out; a command left
    // in the link's buffers would have been carried out before it.
    let t = arm.move_to(1, 0.3).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);
    let (arrived, st) = wait_arm(&mut arm, T, |s| {
        (s.actuators[1].position - 0.3).abs() < 0.02
    });
    assert!(arrived, "joint 1 never arrived: {:?}", st.actuators[1]);
    assert!(
        (st.actuators[2].position - j2).abs() < 0.05,
        "the command of the silence was carried out after the reconnect: joint 2 at {} \
         (was {j2}); its answer: {:?} {}",
        st.actuators[2].position,
        o.status.code(),
        stdout(&o)
    );
    assert_eq!(
        o.status.code(),
        Some(5),
        "answered {:?} {}: {}",
        o.status.code(),
        stdout(&o),
        stderr(&o)
    );
    assert!(stderr(&o).contains("link"), "{}", stderr(&o));
    assert_eq!(drv.term(), Some(0));
    assert_eq!(emu.term(), Some(0));
}

/// Starts `limber emulator` on TCP port `port` (a robot that comes back where it was).
fn emulator_at(domain: &Domain, port: &str, extra: &[&str]) -> Bg {
    let mut args = vec!["emulator", "--tcp", port, "--ignore-stdin"];
    args.extend_from_slice(extra);
    let mut emu = Bg::spawn(domain.name(), &args);
    emu.line(|l| !l.is_empty());
    emu
}

/// Issue "Nobody moves the arm who may not", item 10: what the robot has is asked at every
/// connection (CONFIG), not only the first: a robot that comes back without its body
/// gripper has its gripper commands refused "unsupported", and one that comes back with it
/// is served again.
#[test]
fn what_the_robot_has_is_asked_again_at_every_reconnect() {
    let d = Domain::unique_for_test();
    let (emu, addr) = emulator(&d, true, &[]);
    let port = addr.rsplit(':').next().unwrap().to_string();
    let cfg = config("reconfig");
    let mut drv = pioneer(&d, &addr, cfg.to_str().unwrap(), &[]);
    let ctx = Context::new(&d, Role::Client, "link-test").unwrap();
    let mut arm = ActArrayClient::connect_timeout(&ctx, "pioneer/actarray/0", T).unwrap();
    assert!(wait_link(&mut arm, true, T));
    let open = || limber(d.name(), &["gripper", "pioneer/gripper/0", "open"]);
    let o = open();
    assert!(o.status.success(), "with its gripper: {}", stderr(&o));

    let mut emu = emu;
    for (extra, has) in [(&["--no-gripper"][..], false), (&[][..], true)] {
        assert_eq!(emu.term(), Some(0));
        assert!(
            wait_link(&mut arm, false, T),
            "the robot's end was not seen"
        );
        emu = emulator_at(&d, &port, extra);
        assert!(
            wait_link(&mut arm, true, Duration::from_secs(30)),
            "the link did not come back ({extra:?})"
        );
        let o = open();
        if has {
            assert!(o.status.success(), "gripper back: {}", stderr(&o));
        } else {
            assert_eq!(
                o.status.code(),
                Some(5),
                "gripper gone, answered {:?} {}: {}",
                o.status.code(),
                stdout(&o),
                stderr(&o)
            );
            assert!(stderr(&o).contains("unsupported"), "{}", stderr(&o));
        }
    }
    assert_eq!(drv.term(), Some(0));
    assert_eq!(emu.term(), Some(0));
}

/// Item 10, the other way: a driver started on a robot without its body gripper serves
/// none; the robot comes back with one, and the gripper is served from then on.
#[test]
fn a_gripper_that_appears_at_a_reconnect_is_served() {
    let d = Domain::unique_for_test();
    let (mut emu, addr) = emulator(&d, true, &["--no-gripper"]);
    let port = addr.rsplit(':').next().unwrap().to_string();
    let cfg = config("gained");
    let mut drv = pioneer(&d, &addr, cfg.to_str().unwrap(), &[]);
    let ctx = Context::new(&d, Role::Client, "link-test").unwrap();
    let mut arm = ActArrayClient::connect_timeout(&ctx, "pioneer/actarray/0", T).unwrap();
    assert!(wait_link(&mut arm, true, T));
    let open = || {
        limber(
            d.name(),
            &["gripper", "pioneer/gripper/0", "open", "--timeout", "5"],
        )
    };
    let o = open();
    assert!(!o.status.success(), "no gripper, yet: {}", stdout(&o));

    assert_eq!(emu.term(), Some(0));
    assert!(
        wait_link(&mut arm, false, T),
        "the robot's end was not seen"
    );
    let mut emu = emulator_at(&d, &port, &[]);
    assert!(
        wait_link(&mut arm, true, Duration::from_secs(30)),
        "the link did not come back"
    );
    let o = open();
    assert!(
        o.status.success(),
        "the gripper that appeared is not served: {:?} {}",
        o.status.code(),
        stderr(&o)
    );
    assert_eq!(drv.term(), Some(0));
    assert_eq!(emu.term(), Some(0));
}

/// Issue 12 item 6: a second driver (another robot name) on a TCP endpoint that serves one
/// client at a time is told the endpoint is held, and the first driver's link is left
/// alone (no reconnect, no fault).
#[test]
fn a_second_driver_on_a_held_tcp_endpoint_says_so_and_leaves_the_first_alone() {
    let d = Domain::unique_for_test();
    let (mut emu, port) = emulator(&d, true, &[]);
    let cfg = config("held");
    let mut first = pioneer(&d, &port, cfg.to_str().unwrap(), &[]);
    let o = limber(
        d.name(),
        &[
            "pioneer",
            "--port",
            &port,
            "--config",
            cfg.to_str().unwrap(),
            "--robot",
            "other",
        ],
    );
    assert!(!o.status.success(), "the second driver started");
    assert!(
        stderr(&o).contains("held by another client"),
        "{}",
        stderr(&o)
    );
    let o = limber(
        d.name(),
        &["echo", "pioneer/driver", "--count", "1", "--json"],
    );
    let v: serde_json::Value = serde_json::from_str(stdout(&o).trim()).unwrap();
    assert_eq!(
        (
            v["link"]["reconnects"].as_u64(),
            v["link"]["faults"].as_u64()
        ),
        (Some(0), Some(0)),
        "{v}"
    );
    let o = limber(
        d.name(),
        &["actarray", "pioneer/actarray/0", "pos", "0", "0.3"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(first.term(), Some(0));
    assert_eq!(emu.term(), Some(0));
}

/// Issue 13 item 5: on a robot without an arm, the arm's devices are "not there because the
/// robot has no arm", in `limber list` and in the verbs' exit-3 message.
#[test]
fn what_a_robot_lacks_is_said_by_list_and_by_the_verbs() {
    let d = Domain::unique_for_test();
    let (mut emu, port) = emulator(&d, false, &["--no-arm"]);
    let cfg = config("armless");
    let mut drv = pioneer(&d, &port, cfg.to_str().unwrap(), &[]);
    let o = limber(d.name(), &["list"]);
    assert!(
        stdout(&o).contains("robot pioneer has no arm (driver pioneer)"),
        "{}",
        stdout(&o)
    );
    let o = limber(
        d.name(),
        &["actarray", "pioneer/actarray/0", "geom", "--timeout", "0.5"],
    );
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("robot pioneer has no arm"),
        "{}",
        stderr(&o)
    );
    // A device of a robot nobody serves keeps the old message.
    let o = limber(
        d.name(),
        &["actarray", "nobody/actarray/0", "geom", "--timeout", "0.2"],
    );
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("is the driver running?"),
        "{}",
        stderr(&o)
    );
    assert_eq!(drv.term(), Some(0));
    assert_eq!(emu.term(), Some(0));
}

/// Issue 12 item 5: a driver that started while the robot did not answer ARM_INFO serves
/// the arm as soon as it answers: `limber list` shows it and a verb uses it.
#[test]
fn an_arm_that_answers_late_appears_in_list() {
    let d = Domain::unique_for_test();
    // The start's three ARM_INFO go unanswered; the loop's first retry is answered.
    let (mut emu, port) = emulator(&d, true, &["--drop-arm-info", "3"]);
    let cfg = config("late-arm");
    let mut drv = pioneer(&d, &port, cfg.to_str().unwrap(), &[]);
    let deadline = Instant::now() + Duration::from_secs(20);
    loop {
        let o = limber(d.name(), &["list"]);
        let text = stdout(&o);
        if text.contains("pioneer/actarray/0") && text.contains("pioneer/limb/0") {
            assert!(!text.contains("has no arm"), "{text}");
            break;
        }
        assert!(Instant::now() < deadline, "the arm never appeared: {text}");
    }
    let o = limber(
        d.name(),
        &[
            "actarray",
            "pioneer/actarray/0",
            "pos",
            "0",
            "0.3",
            "--timeout",
            "10",
        ],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(drv.term(), Some(0));
    assert_eq!(emu.term(), Some(0));
}

/// Issue 13 item 4 with the commands a user types: `limber emulator --pty --no-gripper` is
/// a robot whose CONFIGpac says "no gripper"; `limber pioneer` (`body_gripper` "auto")
/// serves neither the gripper nor the lift and says so in `limber list` and the verbs'
/// exit 3; forced with `body_gripper = true` it serves them, and the emulator, which
/// ignores such commands, reports at exit the one it received: none came before.
#[test]
fn a_gripperless_emulator_gets_no_gripper_command_unless_forced() {
    let d = Domain::unique_for_test();
    let (mut emu, port) = emulator(&d, false, &["--no-gripper"]);
    let cfg = config("gripperless");
    let mut drv = pioneer(&d, &port, cfg.to_str().unwrap(), &[]);
    let o = limber(d.name(), &["list"]);
    assert!(
        stdout(&o).contains("robot pioneer has no gripper, no lift (driver pioneer)"),
        "{}",
        stdout(&o)
    );
    let o = limber(
        d.name(),
        &["gripper", "pioneer/gripper/0", "open", "--timeout", "0.5"],
    );
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("robot pioneer has no gripper"),
        "{}",
        stderr(&o)
    );
    assert_eq!(drv.term(), Some(0));

    let forced = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("link-gripper-forced.toml");
    std::fs::write(
        &forced,
        "link_timeout_ms = 400\nreconnect_interval_ms = 100\narm_info_timeout_ms = 500\n\
         body_gripper = true\n",
    )
    .unwrap();
    let mut drv = pioneer(&d, &port, forced.to_str().unwrap(), &[]);
    let o = limber(d.name(), &["gripper", "pioneer/gripper/0", "open"]);
    assert!(o.status.success(), "{}", stderr(&o));
    // A barrier: a later arm command the emulator carried out (the link keeps order).
    let o = limber(
        d.name(),
        &["actarray", "pioneer/actarray/0", "pos", "0", "0.2"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(drv.term(), Some(0));
    assert_eq!(emu.term(), Some(0));
    let report = emu.line(|l| l.starts_with("unsupported commands received"));
    assert!(
        report.ends_with("GRIPPER (33) x1, GRIPPERVAL (36) x0"),
        "{report}"
    );
}

/// Issue "Nobody moves the arm who may not", item 16: SIGTERM to a driver whose robot is
/// SIGSTOPped printed "stopped the arm and closed the link" after "cannot stop the arm:
/// link down". It says what happened: the arm could not be stopped, the link was down.
#[test]
fn a_driver_ended_with_its_robot_stopped_does_not_claim_it_stopped_the_arm() {
    use std::process::{Command, Stdio};
    let d = Domain::unique_for_test();
    let (mut emu, port) = emulator(&d, false, &[]);
    let cfg = config("claim");
    let log = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("link-claim.stderr");
    let mut child = Command::new(common::LIMBER)
        .args([
            "pioneer",
            "--port",
            &port,
            "--config",
            cfg.to_str().unwrap(),
        ])
        .env("LIMBER_DOMAIN", d.name())
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(&log).unwrap())
        .spawn()
        .unwrap();
    let ctx = Context::new(&d, Role::Client, "link-test").unwrap();
    let mut arm = ActArrayClient::connect_timeout(&ctx, "pioneer/actarray/0", T).unwrap();
    assert!(wait_link(&mut arm, true, T), "the link never came up");
    emu.signal(libc::SIGSTOP);
    assert!(
        wait_link(&mut arm, false, T),
        "the silent robot was not detected"
    );
    // SAFETY: kill(2) on our own child; no memory is involved.
    unsafe { libc::kill(child.id() as i32, libc::SIGTERM) };
    let deadline = Instant::now() + T;
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if Instant::now() > deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("the driver did not end within {T:?} of SIGTERM");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    emu.signal(libc::SIGCONT);
    let text = std::fs::read_to_string(&log).unwrap();
    assert_eq!(status.code(), Some(0), "{text}");
    assert!(
        !text.contains("stopped the arm"),
        "claims it stopped the arm: {text}"
    );
    assert!(
        text.contains("limber pioneer: could not stop the arm (link to the hardware is down); the link had already closed"),
        "does not say what happened: {text}"
    );
    assert_eq!(emu.term(), Some(0));
}
