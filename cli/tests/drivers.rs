//! The driver verbs as a user runs them: `limber emulator` in one process, `limber pioneer`
//! on its pty in another, `limber simarm`; the shell verbs against them; SIGTERM ends
//! each with exit 0.

use std::time::Duration;

use limber_services::Domain;

mod common;
use common::{Bg, limber, stderr, stdout};

#[test]
fn emulator_and_pioneer_as_separate_commands() {
    let d = Domain::unique_for_test();
    let mut emu = Bg::spawn(d.name(), &["emulator", "--pty", "--ignore-stdin"]);
    let pty = emu.line(|l| l.starts_with("/dev/"));
    let mut drv = Bg::spawn(d.name(), &["pioneer", "--port", &pty]);
    drv.line(|l| l.ends_with("ready"));
    let o = limber(d.name(), &["list"]);
    let text = stdout(&o);
    for dev in [
        "pioneer/actarray/0",
        "pioneer/actarray/1",
        "pioneer/limb/0",
        "pioneer/gripper/0",
        "pioneer/gripper/1",
    ] {
        assert!(text.contains(dev), "{text}");
    }
    let o = limber(
        d.name(),
        &["actarray", "pioneer/actarray/0", "pos", "2", "0.5"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    let o = limber(
        d.name(),
        &["echo", "pioneer/driver", "--count", "1", "--json"],
    );
    assert!(
        stdout(&o).contains(r#""name":"limber-emulator""#),
        "{}",
        stdout(&o)
    );
    assert_eq!(drv.term(), Some(0));
    assert_eq!(emu.term(), Some(0));
}

#[test]
fn simarm_serves_and_stops_on_sigterm() {
    let d = Domain::unique_for_test();
    let mut sim = Bg::spawn(d.name(), &["simarm", "--builtin", "7dof"]);
    sim.line(|l| l.ends_with("ready"));
    let o = limber(d.name(), &["actarray", "simarm/actarray/0", "geom"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(
        stdout(&o).lines().filter(|l| l.contains("rotary")).count(),
        7,
        "{}",
        stdout(&o)
    );
    let o = limber(
        d.name(),
        &["limb", "simarm/limb/0", "setposition", "0.5", "0.1", "0.3"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(sim.term(), Some(0));
}

/// The README's `limber emulator --pty --armpac-layout aria` and `limber emulator --pty
/// --fast`, run as written (stdin kept open, as in a terminal): a P2OS client syncs, gets
/// the calibration, and reads the ARMpac status bytes in the layout asked for.
#[test]
fn emulator_layout_and_fast_flags_as_documented() {
    use limber_p2os::{ArmpacLayout, Command as P2, ConnectOptions, Connection, LinkTarget};
    for (args, layout) in [
        (
            &["emulator", "--pty", "--armpac-layout", "aria"][..],
            ArmpacLayout::Aria,
        ),
        (&["emulator", "--pty", "--fast"][..], ArmpacLayout::Manual),
    ] {
        let d = Domain::unique_for_test();
        let mut argv = args.to_vec();
        argv.push("--ignore-stdin");
        let mut emu = Bg::spawn(d.name(), &argv);
        let pty = emu.line(|l| l.starts_with("/dev/"));
        let mut c =
            Connection::open(&LinkTarget::Serial(pty.into()), &ConnectOptions::default()).unwrap();
        assert!(c.arm_calibration().is_some(), "{args:?}");
        c.send(&P2::ArmPower(true)).unwrap();
        let r = c.wait_until(
            Duration::from_secs(5),
            |p| matches!(p, limber_p2os::RobotPacket::Arm(a) if a.status(layout).powered),
        );
        assert!(r.is_ok(), "{args:?}: {r:?}; last {:?}", c.last_arm());
        let a = *c.last_arm().unwrap();
        assert!(!a.suggests_other_layout(layout), "{args:?}: {a:?}");
        c.close().unwrap();
        assert_eq!(emu.term(), Some(0));
    }
}

/// The README's `limber pioneer --print-config`: every key with its default, including the
/// ARMpac layout (the manuals'), documented in a comment; the output loads back.
#[test]
fn pioneer_print_config_documents_the_armpac_layout() {
    let d = Domain::unique_for_test();
    let o = limber(d.name(), &["pioneer", "--print-config"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stdout(&o);
    assert!(text.contains("armpac_layout = \"manual\""), "{text}");
    assert!(text.contains("\"aria\""), "{text}");
    let cfg = limber_pioneer::PioneerConfig::from_toml(&text).unwrap();
    assert_eq!(cfg, limber_pioneer::PioneerConfig::default());
    let aria = limber_pioneer::PioneerConfig::from_toml("armpac_layout = \"aria\"").unwrap();
    assert_eq!(aria.armpac_layout, limber_p2os::ArmpacLayout::Aria);
    assert!(limber_pioneer::PioneerConfig::from_toml("armpac_layout = \"player\"").is_err());
    // The gripper state byte likewise: the manual's by default, ARIA's on request.
    assert!(text.contains("gripper_byte = \"manual\""), "{text}");
    let aria = limber_pioneer::PioneerConfig::from_toml("gripper_byte = \"aria\"").unwrap();
    assert_eq!(aria.gripper_byte, limber_p2os::GripperByteLayout::Aria);
    assert!(limber_pioneer::PioneerConfig::from_toml("gripper_byte = \"player\"").is_err());
}

/// Signals that only interrupt a wait (a stop and continue, a terminal resize, a child's
/// end) do not end a driver; SIGHUP does, cleanly (exit 0), like SIGTERM.
#[test]
fn simarm_and_emulator_survive_sigcont_and_sigwinch_and_end_on_sighup() {
    let d = Domain::unique_for_test();
    let mut sim = Bg::spawn(d.name(), &["simarm"]);
    sim.line(|l| l.ends_with("ready"));
    let mut emu = Bg::spawn(d.name(), &["emulator", "--pty", "--ignore-stdin"]);
    emu.line(|l| l.starts_with("/dev/"));
    // simarm's loop is running (its "ready" line comes just before it starts waiting).
    let o = limber(d.name(), &["actarray", "simarm/actarray/0", "geom"]);
    assert!(o.status.success(), "{}", stderr(&o));
    for sig in [
        libc::SIGCONT,
        libc::SIGWINCH,
        libc::SIGCHLD,
        libc::SIGSTOP,
        libc::SIGCONT,
    ] {
        sim.signal(sig);
        emu.signal(sig);
    }
    // Still serving: a request is answered and a command carried out.
    let o = limber(d.name(), &["actarray", "simarm/actarray/0", "geom"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = limber(
        d.name(),
        &["actarray", "simarm/actarray/0", "pos", "1", "0.2"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(matches!(sim.0.try_wait(), Ok(None)), "simarm ended");
    assert!(matches!(emu.0.try_wait(), Ok(None)), "the emulator ended");
    assert_eq!(sim.end_with(libc::SIGHUP), Some(0));
    assert_eq!(emu.end_with(libc::SIGHUP), Some(0));
}

#[test]
fn a_second_simarm_of_the_same_robot_name_is_refused_with_a_sentence() {
    let d = Domain::unique_for_test();
    let mut sim = Bg::spawn(d.name(), &["simarm"]);
    sim.line(|l| l.ends_with("ready"));
    let o = limber(d.name(), &["simarm", "--builtin", "7dof"]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let want = format!("robot simarm is already served in domain {}", d.name());
    assert!(stderr(&o).contains(&want), "{}", stderr(&o));
    // The first one serves on.
    let o = limber(d.name(), &["actarray", "simarm/actarray/0", "geom"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(sim.term(), Some(0));
}

#[test]
fn bad_simarm_option_values_exit_2() {
    let d = Domain::unique_for_test();
    for args in [
        &["simarm", "--time-scale", "0"][..],
        &["simarm", "--time-scale", "nan"][..],
        &["simarm", "--robot", "a b"][..],
    ] {
        let o = limber(d.name(), args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
    }
}

/// Issue 12, items 7 to 10, as a user types them against `limber pioneer --emulated`:
/// "ok" only when the arm will do it, the cause in words otherwise.
#[test]
fn ok_means_it_on_the_emulated_pioneer() {
    let d = Domain::unique_for_test();
    let mut drv = Bg::spawn(d.name(), &["pioneer", "--emulated"]);
    drv.line(|l| l.ends_with("ready"));
    let run = |args: &[&str]| limber(d.name(), args);
    let arm = |args: &[&str]| {
        let mut a = vec!["actarray", "pioneer/actarray/0"];
        a.extend_from_slice(args);
        run(&a)
    };
    let limb = |args: &[&str]| {
        let mut a = vec!["limb", "pioneer/limb/0"];
        a.extend_from_slice(args);
        run(&a)
    };
    let refused = |o: &std::process::Output, why: &str| {
        assert_eq!(o.status.code(), Some(5), "{}{}", stdout(o), stderr(o));
        assert!(
            stderr(o).contains(&format!("refused: {why}")),
            "{}",
            stderr(o)
        );
    };
    // Item 7.
    assert!(arm(&["power", "off"]).status.success());
    refused(&arm(&["pos", "2", "0.3"]), "powered off");
    refused(&limb(&["vecmove", "1", "1", "0", "0.02"]), "powered off");
    let o = arm(&["power", "on"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = arm(&["pos", "2", "0.3"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stdout(&o).trim(), "ok");
    // Item 9.
    let o = arm(&["speed", "2", "1e308"]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stdout(&o).trim(), "ok, clamped to the limit");
    let o = arm(&["speed", "2", "0"]);
    assert_eq!(stdout(&o).trim(), "ok", "{}", stderr(&o));
    // Item 8.
    let o = limb(&["setposition", "0.35", "0", "0.25"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = limb(&["vecmove", "1e308", "1e308", "0", "0.02"]);
    assert_eq!(stdout(&o).trim(), "ok", "{}", stderr(&o));
    let o = limb(&["vecmove", "0", "0", "0", "0.02"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    // Item 10.
    refused(
        &limb(&[
            "setpose",
            "0.35",
            "0",
            "0.25",
            "--approach",
            "1",
            "0",
            "0",
            "--orient",
            "1",
            "0",
            "0",
        ]),
        "invalid argument",
    );
    refused(&limb(&["setposition", "1.5", "0", "0.3"]), "out of reach");
    assert_eq!(drv.term(), Some(0));
}

/// A finite approach vector whose length overflows (1e308 per component) is a direction
/// like any other: SETPOSE answers for it what it answers for the unit vector, never "not
/// finite" or "invalid argument" because a norm overflowed.
#[test]
fn setpose_with_a_huge_finite_approach_is_the_unit_approach() {
    let d = Domain::unique_for_test();
    let mut drv = Bg::spawn(d.name(), &["pioneer", "--emulated"]);
    drv.line(|l| l.ends_with("ready"));
    let setpose = |a: [&str; 3], o: [&str; 3]| {
        let mut args = vec!["limb", "pioneer/limb/0", "setpose", "0.38", "0.1", "0.22"];
        args.push("--approach");
        args.extend(a);
        args.push("--orient");
        args.extend(o);
        let out = limber(d.name(), &args);
        (out.status.code(), stdout(&out), stderr(&out))
    };
    for (huge, unit, o) in [
        (
            ["0", "0", "-1e308"],
            ["0", "0", "-1"],
            ["0.94", "0.34", "0"],
        ),
        (
            ["1e308", "1e308", "-1e308"],
            ["1", "1", "-1"],
            ["1", "0", "1"],
        ),
    ] {
        let want = setpose(unit, o);
        let got = setpose(huge, o);
        assert_eq!(got, want, "approach {huge:?} against {unit:?}");
        assert!(!got.2.contains("not finite"), "{got:?}");
    }
    // The first one is the README's pose: carried out.
    let (code, out, _) = setpose(["0", "0", "-1e308"], ["0.94", "0.34", "0"]);
    assert_eq!(code, Some(0), "{out}");
    assert_eq!(drv.term(), Some(0));
}

/// The `header.flags` of the first state `limber echo DEVICE --count 1 --json` prints.
fn echoed_flags(domain: &str, device: &str) -> u64 {
    let o = limber(domain, &["echo", device, "--count", "1", "--json"]);
    assert!(o.status.success(), "echo {device}: {}", stderr(&o));
    let text = stdout(&o);
    let line = text.lines().next().unwrap_or_default();
    let v: serde_json::Value = serde_json::from_str(line).unwrap_or_else(|e| panic!("{e}: {text}"));
    v["header"]["flags"]
        .as_u64()
        .unwrap_or_else(|| panic!("no header.flags: {text}"))
}

/// The devices of an emulated Pioneer (the gripper's and lift's included).
const PIONEER_DEVICES: [&str; 6] = [
    "pioneer/actarray/0",
    "pioneer/actarray/1",
    "pioneer/limb/0",
    "pioneer/gripper/0",
    "pioneer/gripper/1",
    "pioneer/driver",
];

/// Issue "One protocol core", item 5: `limber pioneer --emulated` drives its built-in
/// emulator, and every device's state says SIMULATED (as simarm's do); a driver on a port
/// (`--port`, here `limber emulator`'s pty, which it cannot tell from a robot) never does.
#[test]
fn the_built_in_emulator_is_simulated_and_a_port_is_not() {
    let d = Domain::unique_for_test();
    let mut drv = common::pioneer_emulated(d.name());
    for dev in PIONEER_DEVICES {
        let flags = echoed_flags(d.name(), dev);
        assert_ne!(flags & 4, 0, "{dev} under --emulated: flags {flags}");
    }
    assert_eq!(drv.term(), Some(0));

    let d = Domain::unique_for_test();
    let mut emu = Bg::spawn(d.name(), &["emulator", "--pty", "--ignore-stdin"]);
    let pty = emu.line(|l| l.starts_with("/dev/"));
    let mut drv = Bg::spawn(d.name(), &["pioneer", "--port", &pty]);
    drv.line(|l| l.ends_with("ready"));
    for dev in PIONEER_DEVICES {
        let flags = echoed_flags(d.name(), dev);
        assert_eq!(flags & 4, 0, "{dev} on --port: flags {flags}");
    }
    assert_eq!(drv.term(), Some(0));
    assert_eq!(emu.term(), Some(0));
}
