//! `limber bridge` (issue 17): the emulated Pioneer in domain A, `bridge expose` there,
//! `bridge mirror --from A` into domain B over A's private Unix socket (TCP with
//! user/password authentication, and between two network namespaces, where it says so),
//! and unchanged clients in domain B
//! (the Rust client, the CLI) commanding the arm. Killing the driver or either bridge
//! makes the mirrored devices gone for B's clients, within a bound, without a hang.
//!
//! Each test uses its own two domains (and its own port where it uses TCP); every wait is
//! bounded. Who may reach a bridge, forged identities and TLS: `bridge_access.rs`.

use std::time::{Duration, Instant};

use limber_services::prelude::*;
use limber_services::{DriverStatus, RequestError};
use limber_tests::Proc;

mod bridging;
use bridging::{
    CLI, arm_in, expose_with, free_port, mirror_with, mirrored_nothing, start_driver,
    usrpwd_configs, wait_mirrored,
};

/// How long a mirrored device may take to be gone after its driver or a bridge dies.
const GONE_BOUND: Duration = Duration::from_secs(10);

/// The processes first: they end before the domains, which then remove their files.
struct Setup {
    driver: Proc,
    expose: Proc,
    mirror: Proc,
    a: Domain,
    b: Domain,
}

/// `bridge expose` on its default listener, domain A's private Unix socket.
fn start_expose(a: &Domain) -> Proc {
    let mut e = Proc::spawn(CLI, a.name(), &["bridge", "expose"]);
    assert!(
        e.read_until(|l| l == "exposed pioneer/actarray/0")
            .is_some(),
        "expose did not expose the arm"
    );
    e
}

/// `bridge mirror --from A` into domain B.
fn start_mirror(b: &Domain, a: &Domain) -> Proc {
    let mut m = Proc::spawn(CLI, b.name(), &["bridge", "mirror", "--from", a.name()]);
    wait_mirrored(&mut m);
    m
}

fn setup() -> Setup {
    let a = Domain::unique_for_test();
    let b = Domain::unique_for_test();
    let driver = start_driver(&a);
    let expose = start_expose(&a);
    let mirror = start_mirror(&b, &a);
    Setup {
        driver,
        expose,
        mirror,
        a,
        b,
    }
}

/// Waits (bounded) until joint `j` of the arm is within 0.02 rad of `target`.
fn wait_joint(arm: &mut ActArrayClient, j: usize, target: f64) {
    let deadline = Instant::now() + Duration::from_secs(20);
    loop {
        let s = arm.wait_state(Duration::from_secs(2)).expect("a state");
        let p = s.actuators[j].position;
        if (p - target).abs() < 0.02 {
            return;
        }
        assert!(
            Instant::now() < deadline,
            "joint {j} at {p}, not {target}, after 20 s"
        );
    }
}

fn cli_in(b: &Domain, args: &[&str]) -> (Option<i32>, String) {
    let mut p = Proc::spawn(CLI, b.name(), args);
    let code = p.wait_timeout(Duration::from_secs(20));
    (code, p.rest_of_stdout())
}

/// The "done when": in domain B, the Rust client and `limber actarray ... pos 1
/// 0.3` move the arm of domain A and see its state; a request (geometry) works; a
/// refusal keeps its reason; a preemption reaches the client whose motion was cut short.
#[test]
fn clients_in_another_domain_command_the_arm_through_a_bridge_pair() {
    let s = setup();
    let mut arm = arm_in(&s.b);
    arm.current(Duration::from_secs(10)).expect("a first state");

    // A request through the bridge.
    let geom = arm.geometry().expect("the geometry through the bridge");
    assert_eq!(geom.actuators_count, 6);

    // A command: accepted, and the state shows it done.
    let t = arm.move_to(2, 0.5).expect("send");
    assert_eq!(
        arm.wait_outcome(t, Duration::from_secs(5))
            .expect("outcome"),
        Status::Ok
    );
    wait_joint(&mut arm, 2, 0.5);

    // A refusal keeps its reason.
    let t = arm.move_to(1, 9.0).expect("send");
    assert_eq!(
        arm.wait_outcome(t, Duration::from_secs(5))
            .expect("outcome"),
        Status::BeyondLimits
    );

    // The CLI, unchanged, in domain B.
    let (code, out) = cli_in(&s.b, &["actarray", "pioneer/actarray/0", "pos", "1", "0.3"]);
    assert_eq!(code, Some(0), "limber actarray pos: {out}");
    assert!(out.contains("ok"), "{out}");
    wait_joint(&mut arm, 1, 0.3);
    let (code, out) = cli_in(&s.b, &["list"]);
    assert_eq!(code, Some(0));
    assert!(
        out.lines()
            .any(|l| l.starts_with("pioneer/actarray/0") && l.contains("alive")),
        "{out}"
    );

    // Two clients of B: the second cuts the first's motion short, and the first is told.
    let mut other = arm_in(&s.b);
    let first = arm.move_to(0, 1.5).expect("send");
    assert_eq!(
        arm.wait_outcome(first, Duration::from_secs(5))
            .expect("outcome"),
        Status::Ok
    );
    // Wait until the first motion runs before cutting it short.
    let deadline = Instant::now() + Duration::from_secs(10);
    while arm
        .wait_state(Duration::from_secs(2))
        .expect("a state")
        .actuators[0]
        .position
        < 0.2
    {
        assert!(Instant::now() < deadline, "joint 0 did not start moving");
    }
    let second = other.move_to(0, -0.5).expect("send");
    assert_eq!(
        other
            .wait_outcome(second, Duration::from_secs(5))
            .expect("outcome"),
        Status::Ok
    );
    let deadline = Instant::now() + Duration::from_secs(5);
    loop {
        if let Some(p) = arm.preempted(first).expect("outcomes") {
            assert_eq!(p.status, Status::Preempted);
            break;
        }
        assert!(Instant::now() < deadline, "the preemption did not arrive");
        let _ = arm.wait_state(Duration::from_millis(200));
    }
    drop(s);
}

/// The driver statistics cross the bridge pair: in domain B, the robot's `driver` channel
/// (what `limber monitor` and `limber echo pioneer/driver` read) carries the remote
/// driver's loop statistics.
#[test]
fn the_remote_drivers_statistics_reach_the_other_domain() {
    let s = setup();
    let ctx = Context::new(&s.b, Role::Client, "bridge-test").expect("join domain B");
    let deadline = Instant::now() + Duration::from_secs(10);
    let mut reader = loop {
        match limber_services::diagnostics::StatsReader::open(&ctx, "pioneer") {
            Ok(r) => break r,
            Err(e) => {
                assert!(
                    Instant::now() < deadline,
                    "no driver statistics in domain B: {e}"
                );
                std::thread::sleep(Duration::from_millis(50));
            }
        }
    };
    let stats = reader
        .wait(Duration::from_secs(5))
        .expect("statistics through the bridge");
    assert!(stats.cycles > 0, "the remote driver's loop has run");
    assert_ne!(
        stats.header.flags & limber_interfaces::prelude::device_flag::LINK_UP,
        0
    );
}

/// A fourth interface crosses the bridge with no code of its own in the bridge (expose
/// and mirror reach every interface through `InterfaceKind::visit`): the emulated
/// Pioneer's laser, in domain B, answers its geometry and gives its scans, in which the
/// world's block (0.38, 0.10 by default) is the closest thing; the CLI reads it too.
#[test]
fn the_laser_crosses_the_bridge_as_every_interface_does() {
    let s = setup();
    let ctx = Context::new(&s.b, Role::Client, "bridge-test").expect("join domain B");
    let mut laser =
        RangerClient::connect_timeout(&ctx, "pioneer/ranger/0", Duration::from_secs(10))
            .expect("the mirrored laser");
    let g = laser
        .geometry()
        .expect("the laser's geometry through the bridge");
    assert_eq!((g.ranges_count, g.max_range), (181, 8.0));
    assert_eq!(g.pose.position.to_array(), [0.16, 0.0, 0.20]);
    let scan = *laser
        .wait_state(Duration::from_secs(5))
        .expect("a scan through the bridge");
    let r = scan.ranges();
    assert_eq!(r.len(), 181);
    let (i, closest) = r
        .iter()
        .copied()
        .enumerate()
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .expect("ranges");
    let expected = (0.38f64 - 0.16).hypot(0.10) - 0.02;
    assert!(
        (closest - expected).abs() < 0.015,
        "closest {closest} m, not {expected}"
    );
    // The closest beam hits the block (radius 0.02 m at 0.24 m: within 0.085 rad of its
    // centre's bearing); which beam it is moves with the laser's 2 mm noise.
    assert!((scan.bearing(i) - (0.10f64).atan2(0.22)).abs() < 0.085);
    let (code, out) = cli_in(&s.b, &["ranger", "pioneer/ranger/0", "geom"]);
    assert_eq!(code, Some(0), "{out}");
    assert!(out.contains("181 ranges over -90.0..+90.0 deg"), "{out}");
}

/// Kill the driver in A, then (after a restart) the exposing bridge, then the mirror:
/// each time B's clients learn the arm is gone within a bound, and never hang.
#[test]
fn a_dead_driver_or_bridge_makes_the_mirrored_arm_gone() {
    let mut s = setup();
    let mut arm = arm_in(&s.b);
    arm.current(Duration::from_secs(10)).expect("a first state");

    // The driver dies.
    s.driver.signal(libc::SIGKILL);
    assert!(
        s.mirror
            .read_until_within(GONE_BOUND, |l| l == "gone pioneer/actarray/0")
            .is_some()
    );
    assert_ne!(arm.driver_status(), DriverStatus::Alive);
    // NoDriver or DriverGone, not Timeout: the request ended at once, it did not wait.
    let r = arm.geometry();
    assert!(
        matches!(r, Err(RequestError::NoDriver | RequestError::DriverGone)),
        "{r:?}"
    );
    let (code, _) = cli_in(&s.b, &["actarray", "pioneer/actarray/0", "geom"]);
    assert!(
        matches!(code, Some(3 | 4)),
        "the CLI says no driver or driver gone: {code:?}"
    );

    // It comes back, and so does the mirrored arm.
    s.driver = start_driver(&s.a);
    wait_mirrored(&mut s.mirror);
    let mut arm = arm_in(&s.b);
    arm.geometry().expect("the geometry after the restart");

    // The exposing bridge dies.
    s.expose.signal(libc::SIGKILL);
    assert!(
        s.mirror
            .read_until_within(GONE_BOUND, |l| l == "gone pioneer/actarray/0")
            .is_some()
    );
    // NoDriver or DriverGone, not Timeout: the request ended at once, it did not wait.
    let r = arm.geometry();
    assert!(
        matches!(r, Err(RequestError::NoDriver | RequestError::DriverGone)),
        "{r:?}"
    );

    // It comes back; then the mirror dies.
    s.expose = start_expose(&s.a);
    wait_mirrored(&mut s.mirror);
    let mut arm = arm_in(&s.b);
    arm.geometry()
        .expect("the geometry after the bridge's restart");
    s.mirror.signal(libc::SIGKILL);
    let deadline = Instant::now() + GONE_BOUND;
    while arm.driver_status() == DriverStatus::Alive {
        assert!(
            Instant::now() < deadline,
            "the dead mirror still looks alive"
        );
        let _ = arm.wait_state(Duration::from_millis(100));
    }
    // NoDriver or DriverGone, not Timeout: the request ended at once, it did not wait.
    let r = arm.geometry();
    assert!(
        matches!(r, Err(RequestError::NoDriver | RequestError::DriverGone)),
        "{r:?}"
    );
}

/// `expose --device ... --allow-command ...`: only the allowed device is exposed, and a
/// command not allowed is refused ("unsupported") to its sender, and so is a request that
/// changes the device (POWER) that no `--allow-request` names (SPEED, named, passes); `--read-only` refuses
/// every command and the requests that change the device, and lets geometry through.
#[test]
fn the_allow_list_keeps_devices_and_commands_out() {
    let a = Domain::unique_for_test();
    let _driver = start_driver(&a);

    let b = Domain::unique_for_test();
    let mut expose = Proc::spawn(
        CLI,
        a.name(),
        &[
            "bridge",
            "expose",
            "--device",
            "pioneer/actarray/0",
            "--allow-command",
            "actarray:pos",
            "--allow-request",
            "actarray:speed",
        ],
    );
    assert!(
        expose
            .read_until(|l| l == "exposed pioneer/actarray/0")
            .is_some()
    );
    let _mirror = start_mirror(&b, &a);
    let mut arm = arm_in(&b);
    arm.geometry().expect("a read-only request passes");
    let t = arm.move_to(2, 0.4).expect("send");
    assert_eq!(
        arm.wait_outcome(t, Duration::from_secs(5))
            .expect("outcome"),
        Status::Ok
    );
    let t = arm.home(None).expect("send");
    assert_eq!(
        arm.wait_outcome(t, Duration::from_secs(5))
            .expect("outcome"),
        Status::Unsupported
    );
    // Requests that change the arm pass the same filter: with POS and the SPEED request
    // listed, POWER is refused (it was carried out before) and SPEED passes.
    assert!(
        matches!(
            arm.power(false),
            Err(RequestError::Nack(Status::Unsupported))
        ),
        "power must be refused"
    );
    arm.set_speed_config(2, 0.5)
        .expect("the listed SPEED request passes");
    // One discovery pass found every device of A: it ends before the bridge does.
    expose.signal(libc::SIGTERM);
    assert_eq!(expose.wait_timeout(Duration::from_secs(20)), Some(0));
    let rest = expose.rest_of_stdout();
    assert!(!rest.contains("exposed "), "{rest}");

    let b = Domain::unique_for_test();
    let mut expose = Proc::spawn(CLI, a.name(), &["bridge", "expose", "--read-only"]);
    assert!(
        expose
            .read_until(|l| l == "exposed pioneer/actarray/0")
            .is_some()
    );
    let _mirror = start_mirror(&b, &a);
    let mut arm = arm_in(&b);
    arm.geometry().expect("a read-only request passes");
    assert!(
        matches!(
            arm.power(false),
            Err(RequestError::Nack(Status::Unsupported))
        ),
        "power must be refused"
    );
    let t = arm.move_to(2, 0.2).expect("send");
    assert_eq!(
        arm.wait_outcome(t, Duration::from_secs(5))
            .expect("outcome"),
        Status::Unsupported
    );
}

const CLIENT: &str = env!("CARGO_BIN_EXE_limber-test-client");

/// Waits (bounded) until joint `j` has the flag `want` in three samples in a row.
fn wait_joint_flag(a: &mut ActArrayClient, j: usize, want: ActuatorFlags, what: &str) {
    let deadline = Instant::now() + Duration::from_secs(15);
    let mut run = 0;
    while run < 3 {
        assert!(Instant::now() < deadline, "joint {j} never {what}");
        let s = a.wait_state(Duration::from_secs(2)).expect("a state");
        if ActuatorFlags::from_bits_truncate(s.actuators[j].state).contains(want) {
            run += 1;
        } else {
            run = 0;
        }
    }
}

/// A client of domain B takes the arm of domain A through the bridges: B's other clients
/// are refused with its name; when it dies mid-motion its renewals stop, and the driver's
/// deadman stops the joint and frees the arm.
#[test]
fn a_remote_holder_that_dies_triggers_the_deadman() {
    let s = setup();
    let mut me = arm_in(&s.b);
    me.current(Duration::from_secs(10)).expect("a first state");
    let mut h = Proc::spawn(
        CLIENT,
        s.b.name(),
        &[
            "--robot",
            "pioneer",
            "own",
            "--name",
            "remote",
            // Generous: renewals cross two bridges on a loaded machine.
            "--heartbeat-ms",
            "3000",
        ],
    );
    assert!(
        h.read_until(|l| l.starts_with("owning")).is_some(),
        "the holder did not take the arm through the bridge"
    );
    let held = me.holder().expect("ask").expect("held");
    assert_eq!(held.name, "remote");
    let t = me.move_to(2, 0.2).expect("send");
    let o = me
        .wait_outcome_detail(t, Duration::from_secs(5))
        .expect("outcome");
    assert_eq!(o.status, Status::Leased);
    assert_eq!(o.other_name(), "remote");
    wait_joint_flag(&mut me, 0, ActuatorFlags::MOVING, "moving");

    h.signal(libc::SIGKILL);
    wait_joint_flag(&mut me, 0, ActuatorFlags::IDLE, "stopped");
    let deadline = Instant::now() + Duration::from_secs(10);
    while me.holder().expect("ask").is_some() {
        assert!(Instant::now() < deadline, "the lease never ended");
        let _ = me.wait_state(Duration::from_millis(100));
    }
    let t = me.move_to(0, 0.0).expect("send");
    assert!(
        me.wait_outcome(t, Duration::from_secs(5))
            .expect("outcome")
            .is_carried_out()
    );
}

/// Zenoh's user/password authentication, as bridge/README.md sets it up: a mirror with the
/// wrong password gets nothing, one with the right password mirrors the arm.
#[test]
fn a_mirror_with_the_wrong_password_gets_nothing() {
    let (dir, robot, good, bad) = usrpwd_configs("usrpwd");

    let a = Domain::unique_for_test();
    let _driver = start_driver(&a);
    let endpoint = format!("tcp/127.0.0.1:{}", free_port());
    let _expose = expose_with(&a, &["--listen", &endpoint, "--zenoh-config", &robot]);
    let b_bad = Domain::unique_for_test();
    let intruder = mirror_with(&b_bad, &["--connect", &endpoint, "--zenoh-config", &bad]);
    let b = Domain::unique_for_test();
    let mut mirror = mirror_with(&b, &["--connect", &endpoint, "--zenoh-config", &good]);
    wait_mirrored(&mut mirror);
    let mut arm = arm_in(&b);
    arm.geometry()
        .expect("the geometry with the right password");
    // The intruder started first and had as long: it mirrored nothing.
    mirrored_nothing(intruder);
    let _ = std::fs::remove_dir_all(&dir);
}

/// Two network namespaces joined by a veth pair, made (as root) by the test and removed when
/// it ends: the robot's host (the driver and `bridge expose`) in one, the operator's host
/// (`bridge mirror` and the clients of domain B) in the other. Their only link is the veth
/// pair, on link-local addresses that exist nowhere else.
struct NetnsPair {
    robot: String,
    operator: String,
}

/// The address of the robot's end of the veth pair; the operator's end is .2.
const ROBOT_ADDR: &str = "169.254.77.1";

impl NetnsPair {
    /// Makes the pair; None (with the reason printed) when not root. As root, a step that
    /// fails fails the test: CI runs as root, and must run this test.
    fn create() -> Option<NetnsPair> {
        if limber_services::domain_dir::euid() != 0 {
            eprintln!(
                "SKIPPED: network namespaces and a veth pair need root (this test runs as root in CI)"
            );
            return None;
        }
        let id = std::process::id();
        let pair = NetnsPair {
            robot: format!("limber-robot-{id}"),
            operator: format!("limber-op-{id}"),
        };
        // Interface names have at most 15 bytes.
        let (va, vb) = (format!("lbr{id}"), format!("lbo{id}"));
        let ip = |args: &[&str]| {
            let out = limber_bounded_run::output_within(
                std::process::Command::new("ip").args(args),
                Duration::from_secs(20),
            );
            assert!(
                out.status.success(),
                "ip {}: {}",
                args.join(" "),
                String::from_utf8_lossy(&out.stderr)
            );
        };
        ip(&["netns", "add", &pair.robot]);
        ip(&["netns", "add", &pair.operator]);
        ip(&["link", "add", &va, "type", "veth", "peer", "name", &vb]);
        ip(&["link", "set", &va, "netns", &pair.robot]);
        ip(&["link", "set", &vb, "netns", &pair.operator]);
        for (ns, dev, addr) in [
            (&pair.robot, &va, format!("{ROBOT_ADDR}/30")),
            (&pair.operator, &vb, "169.254.77.2/30".to_string()),
        ] {
            ip(&["-n", ns, "addr", "add", &addr, "dev", dev]);
            ip(&["-n", ns, "link", "set", dev, "up"]);
            ip(&["-n", ns, "link", "set", "lo", "up"]);
        }
        Some(pair)
    }

    /// `limber <args>` in domain `domain`, inside namespace `ns`.
    fn spawn(ns: &str, domain: &Domain, args: &[&str]) -> Proc {
        let mut c = std::process::Command::new("ip");
        c.args(["netns", "exec", ns, CLI])
            .args(args)
            .env("LIMBER_DOMAIN", domain.name());
        Proc::spawn_command(c)
    }
}

impl Drop for NetnsPair {
    fn drop(&mut self) {
        // Removing a namespace removes its end of the veth pair, and so the pair.
        for ns in [&self.robot, &self.operator] {
            let out = limber_bounded_run::output_within(
                std::process::Command::new("ip").args(["netns", "del", ns]),
                Duration::from_secs(20),
            );
            if !out.status.success() {
                eprintln!(
                    "could not remove network namespace {ns}: {}",
                    String::from_utf8_lossy(&out.stderr)
                );
            }
        }
    }
}

/// Issue 17, item 4: the same as on loopback, between two network namespaces joined by a
/// veth pair. The robot's namespace runs the emulated Pioneer and `bridge expose` on its
/// veth address; the operator's runs `bridge mirror`, and there `limber actarray ... pos`
/// moves the arm and `limber list` sees it. Killing the driver, then the exposing bridge,
/// makes the arm gone in the operator's domain, and requests there end at once.
#[test]
fn a_bridge_pair_between_two_network_namespaces_moves_the_arm() {
    // Declared first, dropped last: every process below ends before the namespaces go.
    let Some(net) = NetnsPair::create() else {
        return;
    };
    let a = Domain::unique_for_test();
    let b = Domain::unique_for_test();
    let endpoint = format!("tcp/{ROBOT_ADDR}:{}", free_port());
    // A listener another host reaches needs credentials.
    let (dir, robot, good, _) = usrpwd_configs("netns");

    let mut driver = NetnsPair::spawn(&net.robot, &a, &["pioneer", "--emulated"]);
    assert!(
        driver.read_until(|l| l.ends_with("ready")).is_some(),
        "the driver did not start in the robot's namespace"
    );
    let mut expose = NetnsPair::spawn(
        &net.robot,
        &a,
        &[
            "bridge",
            "expose",
            "--listen",
            &endpoint,
            "--zenoh-config",
            &robot,
        ],
    );
    assert!(
        expose
            .read_until(|l| l == "exposed pioneer/actarray/0")
            .is_some(),
        "expose did not expose the arm on the veth address"
    );
    let mut mirror = NetnsPair::spawn(
        &net.operator,
        &b,
        &[
            "bridge",
            "mirror",
            "--connect",
            &endpoint,
            "--zenoh-config",
            &good,
        ],
    );
    wait_mirrored(&mut mirror);

    // The CLI in the operator's namespace and domain moves the arm.
    let mut pos = NetnsPair::spawn(
        &net.operator,
        &b,
        &["actarray", "pioneer/actarray/0", "pos", "1", "0.3"],
    );
    let code = pos.wait_timeout(Duration::from_secs(20));
    let out = pos.rest_of_stdout();
    assert_eq!(
        code,
        Some(0),
        "limber actarray pos in the operator's namespace: {out}"
    );
    assert!(out.contains("ok"), "{out}");
    let mut arm = arm_in(&b);
    wait_joint(&mut arm, 1, 0.3);
    let mut list = NetnsPair::spawn(&net.operator, &b, &["list"]);
    assert_eq!(list.wait_timeout(Duration::from_secs(20)), Some(0));
    let out = list.rest_of_stdout();
    assert!(
        out.lines()
            .any(|l| l.starts_with("pioneer/actarray/0") && l.contains("alive")),
        "{out}"
    );

    // The driver dies: the operator's clients learn it; it comes back, and so does the arm.
    driver.signal(libc::SIGKILL);
    assert!(
        mirror
            .read_until_within(GONE_BOUND, |l| l == "gone pioneer/actarray/0")
            .is_some(),
        "the mirror did not say the arm is gone after the driver died"
    );
    assert_ne!(arm.driver_status(), DriverStatus::Alive);
    let mut driver = NetnsPair::spawn(&net.robot, &a, &["pioneer", "--emulated"]);
    assert!(
        driver.read_until(|l| l.ends_with("ready")).is_some(),
        "the driver did not restart"
    );
    wait_mirrored(&mut mirror);
    let mut arm = arm_in(&b);
    arm.geometry().expect("the geometry after the restart");

    // The exposing bridge dies: the operator's clients learn the arm is gone.
    expose.signal(libc::SIGKILL);
    assert!(
        mirror
            .read_until_within(GONE_BOUND, |l| l == "gone pioneer/actarray/0")
            .is_some(),
        "the mirror did not say the arm is gone"
    );
    let r = arm.geometry();
    assert!(
        matches!(r, Err(RequestError::NoDriver | RequestError::DriverGone)),
        "{r:?}"
    );
    drop((driver, mirror));
    let _ = std::fs::remove_dir_all(&dir);
}

/// `bridge/zenoh-lowlatency.json5` (Zenoh's LowLatency transport, docs/guide/bridge.md
/// "How fast") given to both bridges, or to one of them only: the pair connects and
/// carries a request and a command, and each bridge ends cleanly on SIGTERM.
#[test]
fn the_lowlatency_file_on_both_ends_or_on_one_carries_requests_and_commands() {
    let file = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../bridge/zenoh-lowlatency.json5"
    );
    let a = Domain::unique_for_test();
    let _driver = start_driver(&a);
    for (on_expose, on_mirror) in [(true, true), (true, false), (false, true)] {
        let what = format!("LowLatency on expose: {on_expose}, on mirror: {on_mirror}");
        let b = Domain::unique_for_test();
        let cfg = |on: bool| {
            if on {
                vec!["--zenoh-config", file]
            } else {
                Vec::new()
            }
        };
        let mut expose = expose_with(&a, &cfg(on_expose));
        let args = [
            &["bridge", "mirror", "--from", a.name()][..],
            &cfg(on_mirror),
        ]
        .concat();
        let mut mirror = Proc::spawn(CLI, b.name(), &args);
        wait_mirrored(&mut mirror);
        let mut arm = arm_in(&b);
        let geom = arm
            .geometry()
            .unwrap_or_else(|e| panic!("{what}: geometry: {e}"));
        assert_eq!(geom.actuators_count, 6, "{what}");
        let t = arm.move_to(1, 0.2).expect("send");
        assert_eq!(
            arm.wait_outcome(t, Duration::from_secs(10))
                .unwrap_or_else(|e| panic!("{what}: outcome: {e}")),
            Status::Ok,
            "{what}"
        );
        drop(arm);
        for p in [&mut mirror, &mut expose] {
            p.signal(libc::SIGTERM);
            assert_eq!(p.wait_timeout(Duration::from_secs(30)), Some(0), "{what}");
        }
    }
}
