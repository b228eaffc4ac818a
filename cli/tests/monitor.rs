//! `limber monitor`: the model and the drawing against the test driver (rendered into
//! ratatui's TestBackend), key commands read back from the device, a Pioneer driver
//! (emulated) with its statistics and its death, and the binary's `--once`.

use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crossterm::event::KeyCode;
use limber_services::prelude::*;
use limber_services::{Context, Domain, Role};
use ratatui::Terminal;
use ratatui::backend::TestBackend;
use ratatui::style::Color;

mod common;
use common::{LIMBER, driver, stdout};

// The monitor lives in the binary; its model and drawing are plain modules without
// terminal code, so the tests compile them in directly.
#[allow(dead_code)]
#[path = "../src/monitor/app.rs"]
mod app;
#[allow(dead_code)]
#[path = "../src/monitor/ui.rs"]
mod ui;

use app::{App, StatusKind};

fn monitor(domain: &Domain) -> App {
    let ctx = Context::new(domain, Role::Client, "monitor-test").unwrap();
    let mut app = App::new(ctx);
    app.settle(Duration::from_secs(5));
    app
}

fn select(app: &mut App, device: &str) {
    app.handle_key(KeyCode::Home);
    for _ in 0..app.devices.len() {
        if app.selected_device().unwrap().info.name.to_string() == device {
            return;
        }
        app.handle_key(KeyCode::Char('j'));
    }
    panic!("{device} is not listed");
}

/// Presses `key` and ticks until its outcome is on the status line.
fn press(app: &mut App, key: char) -> app::StatusLine {
    app.handle_key(KeyCode::Char(key));
    let deadline = Instant::now() + Duration::from_secs(10);
    while app.is_pending() && Instant::now() < deadline {
        app.tick();
        std::thread::sleep(Duration::from_millis(5));
    }
    assert!(!app.is_pending(), "no outcome for {key}");
    // Let the state that carried the outcome be taken.
    app.tick();
    app.status.clone().expect("a status line")
}

fn gripper_state(app: &App, device: &str) -> u32 {
    let d = app
        .devices
        .iter()
        .find(|d| d.info.name.to_string() == device)
        .unwrap();
    match &d.conn {
        Ok(c) => {
            c.state::<Gripper>()
                .unwrap_or_else(|| panic!("{device} is not a gripper with a state"))
                .state
        }
        Err(e) => panic!("{device} is not connected: {e}"),
    }
}

/// The line of `text` that contains `needle`.
fn line_with<'a>(text: &'a str, needle: &str) -> &'a str {
    text.lines()
        .find(|l| l.contains(needle))
        .unwrap_or_else(|| panic!("no line with {needle:?} in\n{text}"))
}

#[test]
fn shows_every_device_with_joints_limits_states_and_the_pose() {
    let domain = Domain::unique_for_test();
    let _stop = driver(domain.name());
    let app = monitor(&domain);
    let text = ui::render_text(&app, 120);

    assert!(text.contains("limber monitor"), "{text}");
    assert!(text.contains(domain.name()), "{text}");
    assert!(text.contains("3 devices, 3 alive"), "{text}");
    for dev in ["cli/actarray/0", "cli/limb/0", "cli/gripper/0"] {
        let title = line_with(&text, dev);
        assert!(
            title.contains("testdriver") && title.contains("ALIVE"),
            "{title}"
        );
    }
    // Six joints, at 0 between -π and π: half the bar filled, idle.
    for j in 0..6 {
        let line = line_with(&text, &format!("j{j} "));
        assert!(line.contains("+0.0000 rad"), "{line}");
        assert!(line.contains("[-3.142, +3.142]"), "{line}");
        assert!(line.contains("idle"), "{line}");
        assert!(line.contains('█') && line.contains('░'), "{line}");
        let filled = line.matches('█').count();
        let empty = line.matches('░').count();
        assert!(filled.abs_diff(empty) <= 1, "{line}");
    }
    assert!(line_with(&text, "power").contains("off"), "{text}");
    // The limb's pose and state, the gripper's state and its two beams.
    assert!(line_with(&text, "position (").contains("idle"), "{text}");
    let grip = line_with(&text, "beams");
    assert!(grip.contains("open") && grip.contains("○○"), "{grip}");
    // The robot's driver: alive, no statistics channel (the test driver has none).
    let drv = line_with(&text, "driver cli");
    assert!(drv.contains("testdriver") && drv.contains("ALIVE"), "{drv}");
    assert!(text.contains("no driver statistics"), "{text}");
}

#[test]
fn states_are_coloured_and_the_selected_device_is_marked() {
    let domain = Domain::unique_for_test();
    let _stop = driver(domain.name());
    let mut app = monitor(&domain);
    select(&mut app, "cli/actarray/0");
    let mut term = Terminal::new(TestBackend::new(110, ui::full_height(&app))).unwrap();
    term.draw(|f| ui::draw(f, &app)).unwrap();
    let buf = term.backend().buffer().clone();
    let text = ui::buffer_text(&buf);
    let width = buf.area.width as usize;
    // The word "idle" of joint 0 is green; "open" of the gripper is green too.
    let cell_fg = |needle: &str, word: &str| -> Color {
        let (row, line) = text
            .lines()
            .enumerate()
            .find(|(_, l)| l.contains(needle))
            .unwrap();
        let col = line[..line.rfind(word).unwrap()].chars().count();
        buf.content()[row * width + col].fg
    };
    assert_eq!(cell_fg("j0 ", "idle"), Color::Green, "{text}");
    assert_eq!(cell_fg("beams", "open"), Color::Green, "{text}");
    assert!(line_with(&text, "cli/actarray/0").contains('▶'), "{text}");
    assert!(!line_with(&text, "cli/limb/0").contains('▶'), "{text}");

    // Closed grippers are blue.
    select(&mut app, "cli/gripper/0");
    assert_eq!(press(&mut app, 'c').kind, StatusKind::Ok);
    term.draw(|f| ui::draw(f, &app)).unwrap();
    let buf = term.backend().buffer().clone();
    let text = ui::buffer_text(&buf);
    let (row, line) = text
        .lines()
        .enumerate()
        .find(|(_, l)| l.contains("beams"))
        .unwrap();
    let col = line[..line.find("closed").unwrap()].chars().count();
    assert_eq!(buf.content()[row * width + col].fg, Color::Blue, "{text}");
}

#[test]
fn keys_command_the_selected_device_and_the_status_line_tells_the_outcome() {
    let domain = Domain::unique_for_test();
    let _stop = driver(domain.name());
    let mut app = monitor(&domain);

    // The gripper: c closes it (read back from its state), o opens it.
    select(&mut app, "cli/gripper/0");
    let s = press(&mut app, 'c');
    assert_eq!(s.kind, StatusKind::Ok, "{s:?}");
    assert_eq!(s.text, "close cli/gripper/0: ok");
    assert_eq!(
        gripper_state(&app, "cli/gripper/0"),
        GripperState::Closed as u32
    );
    let text = ui::render_text(&app, 120);
    assert!(line_with(&text, "beams").contains("closed"), "{text}");
    assert!(
        line_with(&text, "last:").contains("close cli/gripper/0: ok"),
        "{text}"
    );
    let s = press(&mut app, 'o');
    assert_eq!(s.text, "open cli/gripper/0: ok");
    assert_eq!(
        gripper_state(&app, "cli/gripper/0"),
        GripperState::Open as u32
    );
    // Home is not a gripper command: said at once, nothing sent.
    app.handle_key(KeyCode::Char('h'));
    let s = app.status.clone().unwrap();
    assert_eq!(s.kind, StatusKind::Error);
    assert!(s.text.contains("not a command of a gripper"), "{s:?}");

    // The limb: h homes it (the test limb's home is (0.5, 0, 0)); s stops it.
    select(&mut app, "cli/limb/0");
    assert_eq!(press(&mut app, 'h').text, "home cli/limb/0: ok");
    let text = ui::render_text(&app, 120);
    assert!(
        line_with(&text, "position (").contains("(+0.5000, +0.0000, +0.0000)"),
        "{text}"
    );
    assert_eq!(press(&mut app, 's').text, "stop cli/limb/0: ok");

    // The arm: h homes every joint; s (speed 0 for every joint) is refused by the test
    // arm, which does not do speed control, and the status line says why.
    select(&mut app, "cli/actarray/0");
    assert_eq!(press(&mut app, 'h').text, "home cli/actarray/0: ok");
    let s = press(&mut app, 's');
    assert_eq!(s.kind, StatusKind::Error);
    assert!(
        s.text.starts_with("stop cli/actarray/0: refused: "),
        "{s:?}"
    );
    assert!(line_with(&ui::render_text(&app, 120), "last:").contains("refused"));

    // Selection stays within the list; q quits.
    for _ in 0..10 {
        app.handle_key(KeyCode::Up);
    }
    assert_eq!(app.selected, 0);
    for _ in 0..10 {
        app.handle_key(KeyCode::Down);
    }
    assert_eq!(app.selected, app.devices.len() - 1);
    assert!(!app.should_quit());
    app.handle_key(KeyCode::Char('q'));
    assert!(app.should_quit());
}

#[test]
fn devices_appearing_and_dying_are_picked_up() {
    let domain = Domain::unique_for_test();
    let mut app = monitor(&domain);
    assert!(app.devices.is_empty());
    let text = ui::render_text(&app, 100);
    assert!(text.contains("no devices in domain"), "{text}");
    // A key without devices says so.
    app.handle_key(KeyCode::Char('c'));
    assert!(app.status.as_ref().unwrap().text.contains("no device"));

    let stop = driver(domain.name());
    let deadline = Instant::now() + Duration::from_secs(10);
    while app.devices.len() < 3 && Instant::now() < deadline {
        app.tick();
        std::thread::sleep(Duration::from_millis(20));
    }
    assert_eq!(app.devices.len(), 3);
    app.settle(Duration::from_secs(5));
    assert!(ui::render_text(&app, 120).contains("j5 "));

    // The driver stops: its devices stay listed (this monitor still holds their
    // channels), DEAD, with their last values; commands say there is no driver.
    drop(stop);
    let deadline = Instant::now() + Duration::from_secs(10);
    while app.devices.iter().any(|d| d.alive()) && Instant::now() < deadline {
        app.tick();
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(app.devices.iter().all(|d| !d.alive()));
    let text = ui::render_text(&app, 120);
    assert!(text.contains("3 devices, 0 alive"), "{text}");
    assert!(line_with(&text, "cli/gripper/0").contains("DEAD"), "{text}");
    assert!(line_with(&text, "driver cli").contains("DEAD"), "{text}");
    assert!(line_with(&text, "j5 ").contains("+0.0000 rad"), "{text}");
    select(&mut app, "cli/gripper/0");
    app.handle_key(KeyCode::Char('c'));
    let s = app.status.clone().unwrap();
    assert_eq!(s.kind, StatusKind::Error);
    assert!(s.text.contains("no driver"), "{s:?}");
}

/// `limber pioneer --emulated` in `domain`, once it says it is ready.
fn pioneer(domain: &Domain) -> common::Bg {
    common::pioneer_emulated(domain.name())
}

#[test]
fn a_pioneer_driver_shows_its_statistics_lift_and_grippers_and_its_death() {
    let domain = Domain::unique_for_test();
    let mut p = pioneer(&domain);
    let mut app = monitor(&domain);
    let text = ui::render_text(&app, 130);
    for dev in [
        "pioneer/actarray/0",
        "pioneer/actarray/1",
        "pioneer/limb/0",
        "pioneer/gripper/0",
        "pioneer/gripper/1",
    ] {
        assert!(line_with(&text, dev).contains("ALIVE"), "{text}");
    }
    // The driver's panel: link up, statistics.
    let drv = line_with(&text, "driver pioneer");
    assert!(drv.contains("link UP") && drv.contains("ALIVE"), "{text}");
    for s in [
        "cycles",
        "SIPs",
        "bad checksums",
        "reconnects",
        "link faults",
    ] {
        assert!(text.contains(s), "{s} in\n{text}");
    }
    assert!(
        line_with(&text, "hw: ").contains("arm gripper lift"),
        "{text}"
    );
    // The lift: one linear actuator, in m.
    assert!(
        line_with(&text, "pioneer/actarray/1").contains("lift"),
        "{text}"
    );
    assert!(line_with(&text, "│lift ").contains(" m "), "{text}");

    // The driver is killed: its devices turn DEAD (greyed), commands say no driver,
    // and nothing waits on it.
    select(&mut app, "pioneer/gripper/0");
    p.0.kill().unwrap();
    p.0.wait().unwrap();
    let deadline = Instant::now() + Duration::from_secs(10);
    while app.devices.iter().any(|d| d.alive()) && Instant::now() < deadline {
        app.tick();
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(app.devices.iter().all(|d| !d.alive()));
    let text = ui::render_text(&app, 130);
    assert!(
        line_with(&text, "pioneer/gripper/0").contains("DEAD"),
        "{text}"
    );
    assert!(
        line_with(&text, "driver pioneer").contains("DEAD"),
        "{text}"
    );
    app.handle_key(KeyCode::Char('c'));
    let s = app.status.clone().unwrap();
    assert_eq!(s.kind, StatusKind::Error);
    assert!(s.text.contains("no driver"), "{s:?}");
    // Greyed.
    let mut term = Terminal::new(TestBackend::new(130, ui::full_height(&app))).unwrap();
    term.draw(|f| ui::draw(f, &app)).unwrap();
    let buf = term.backend().buffer();
    let text = ui::buffer_text(buf);
    let row = text.lines().position(|l| l.contains("beams")).unwrap();
    let w = buf.area.width as usize;
    assert_eq!(buf.content()[row * w + 2].fg, Color::DarkGray, "{text}");
}

#[test]
fn the_binary_prints_one_frame_with_once_or_when_stdout_is_not_a_terminal() {
    let domain = Domain::unique_for_test();
    let _stop = driver(domain.name());
    for args in [&["monitor", "--once"][..], &["monitor"][..]] {
        let out = common::output(
            Command::new(LIMBER)
                .args(args)
                .env("LIMBER_DOMAIN", domain.name())
                .stdin(Stdio::null()),
        );
        assert!(out.status.success(), "{args:?}: {out:?}");
        let text = stdout(&out);
        for dev in ["cli/actarray/0", "cli/limb/0", "cli/gripper/0"] {
            assert!(line_with(&text, dev).contains("ALIVE"), "{text}");
        }
        assert!(line_with(&text, "j3 ").contains("idle"), "{text}");
        assert!(line_with(&text, "beams").contains("open"), "{text}");
        // Plain text: no escape sequences.
        assert!(!text.contains('\x1b'), "{text:?}");
    }
    let out = common::output(
        Command::new(LIMBER)
            .args(["monitor", "--once", "--width", "80"])
            .env("LIMBER_DOMAIN", domain.name()),
    );
    let text = stdout(&out);
    assert!(text.lines().all(|l| l.chars().count() <= 80), "{text}");
    assert!(text.contains("cli/gripper/0"), "{text}");
}

/// Issue 12, item 12: the monitor shows who holds a device, and stops showing it when the
/// lease ends.
#[test]
fn the_monitor_shows_who_holds_a_device() {
    let domain = Domain::unique_for_test();
    let _stop = driver(domain.name());
    let ctx = Context::new(&domain, Role::Client, "holder").unwrap();
    let mut holder =
        ActArrayClient::connect_timeout(&ctx, "cli/actarray/0", Duration::from_secs(5)).unwrap();
    holder.acquire("alice", Duration::from_secs(30)).unwrap();
    let mut app = monitor(&domain);
    let deadline = Instant::now() + Duration::from_secs(10);
    let held = |app: &App| {
        line_with(&ui::render_text(app, 140), "cli/actarray/0").contains("held by alice")
    };
    while !held(&app) {
        assert!(Instant::now() < deadline, "{}", ui::render_text(&app, 140));
        app.tick();
        std::thread::sleep(Duration::from_millis(10));
    }
    // Only the held device says so.
    assert!(!line_with(&ui::render_text(&app, 140), "cli/limb/0").contains("held by"));
    holder.release().unwrap();
    let deadline = Instant::now() + Duration::from_secs(10);
    while held(&app) {
        assert!(Instant::now() < deadline, "{}", ui::render_text(&app, 140));
        app.tick();
        std::thread::sleep(Duration::from_millis(10));
    }
}

/// Issue 28: the limb's panel shows a running path and how far it got, and where a path
/// was refused (against `limber simarm`).
#[test]
fn the_limb_panel_shows_a_running_path_and_a_refused_one() {
    let domain = Domain::unique_for_test();
    let mut sim = common::Bg::spawn(domain.name(), &["simarm"]);
    sim.line(|l| l.ends_with("ready"));
    let ctx = Context::new(&domain, Role::Client, "path-test").unwrap();
    let mut limb =
        LimbClient::connect_timeout(&ctx, "simarm/limb/0", Duration::from_secs(10)).unwrap();
    let t = limb
        .set_pose([0.4, 0.0, 0.3], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0])
        .unwrap();
    assert!(
        limb.wait_done(t, Duration::from_secs(30))
            .unwrap()
            .reached()
    );
    // A slow line (2 cm/s over 15 cm): running while the monitor looks.
    let t = limb.line([0.4, 0.15, 0.3], None, 0.02).unwrap();
    assert_eq!(
        limb.wait_outcome(t, Duration::from_secs(10)).unwrap(),
        Status::Ok
    );
    let mut app = monitor(&domain);
    let deadline = Instant::now() + Duration::from_secs(10);
    let mut text = ui::render_text(&app, 140);
    while !text.contains("  line ") && Instant::now() < deadline {
        app.tick();
        text = ui::render_text(&app, 140);
    }
    assert!(line_with(&text, "position").contains("  line "), "{text}");
    limb.stop().unwrap();
    // Out of reach: refused, and the panel says where.
    let t = limb.line([2.0, 0.0, 0.3], None, 0.0).unwrap();
    assert_ne!(
        limb.wait_outcome(t, Duration::from_secs(10)).unwrap(),
        Status::Ok
    );
    let deadline = Instant::now() + Duration::from_secs(10);
    while !text.contains("line refused at ") && Instant::now() < deadline {
        app.tick();
        text = ui::render_text(&app, 140);
    }
    assert!(
        line_with(&text, "position").contains("line refused at "),
        "{text}"
    );
}
