//! Exit codes and messages of the command line as docs/guide/cli.md's table states them, and a
//! closed stdout (`| head -1`) ending a verb quietly.

use std::io::{BufRead, BufReader};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use limber_services::Domain;

mod common;
use common::{LIMBER, driver, limber, stderr};

/// `--timeout` covers waiting for the driver to appear: a verb started before its driver
/// waits for it (here longer than the 0.5 s it used to) and is answered.
#[test]
fn timeout_covers_waiting_for_the_driver_to_appear() {
    let d = Domain::unique_for_test();
    let mut verb = Command::new(LIMBER)
        .args(["actarray", "cli/actarray/0", "geom", "--timeout", "30"])
        .env("LIMBER_DOMAIN", d.name())
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::inherit())
        .spawn()
        .unwrap();
    // The driver is late: it appears only after the verb has been waiting for a while,
    // and the verb is still waiting then.
    let late = Instant::now() + Duration::from_millis(1500);
    while Instant::now() < late {
        assert!(
            matches!(verb.try_wait(), Ok(None)),
            "the verb gave up before its --timeout: {:?}",
            verb.try_wait()
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    let _stop = driver(d.name());
    let deadline = Instant::now() + Duration::from_secs(60);
    let status = loop {
        if let Some(s) = verb.try_wait().unwrap() {
            break s;
        }
        assert!(Instant::now() < deadline, "the verb never ended");
        std::thread::sleep(Duration::from_millis(20));
    };
    assert_eq!(status.code(), Some(0));
}

/// Without a driver, the verb ends with 3 once its --timeout has passed.
#[test]
fn no_driver_within_the_timeout_exits_3() {
    let d = Domain::unique_for_test();
    let o = limber(
        d.name(),
        &["actarray", "nobody/actarray/0", "geom", "--timeout", "0.2"],
    );
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    assert!(stderr(&o).contains("no driver offers"), "{}", stderr(&o));
}

#[test]
fn bad_values_and_verbs_of_the_wrong_interface_exit_2() {
    let d = Domain::unique_for_test();
    let _stop = driver(d.name());
    let dom = d.name();
    let usage = |args: &[&str], says: &str| {
        let o = limber(dom, args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(says), "{args:?}: {}", stderr(&o));
    };
    // A verb of another interface than the device's.
    usage(
        &["limb", "cli/actarray/0", "geom"],
        "it is an actarray device, not a limb",
    );
    usage(
        &["gripper", "cli/actarray/0", "open"],
        "it is an actarray device, not a gripper",
    );
    // Bad flag values.
    for t in ["nan", "-1", "inf", "x"] {
        let flag = format!("--timeout={t}");
        usage(&["actarray", "cli/actarray/0", "geom", &flag], "timeout");
        usage(&["echo", "cli/actarray/0", &flag], "timeout");
    }
    // A bad configuration value.
    let cfg = std::env::temp_dir().join(format!("limber-bad-{}.toml", std::process::id()));
    std::fs::write(&cfg, "autopark_s = 1\npulse_interval_ms = 1000\n").unwrap();
    usage(
        &[
            "pioneer",
            "--config",
            cfg.to_str().unwrap(),
            "--print-config",
        ],
        "autopark_s",
    );
    std::fs::write(&cfg, "tick_ms = 0\n").unwrap();
    usage(&["pioneer", "--config", cfg.to_str().unwrap()], "tick_ms");
    // Issue "Nobody moves the arm who may not", item 16: a zero keep-alive interval (a
    // PULSE flood) or ARM_INFO wait (nothing of the arm or gripper served) is refused.
    for (text, says) in [
        (
            "pulse_interval_ms = 0\n",
            "pulse_interval_ms must be >= 100",
        ),
        (
            "arm_info_timeout_ms = 0\n",
            "arm_info_timeout_ms must be >= 100",
        ),
    ] {
        std::fs::write(&cfg, text).unwrap();
        usage(&["pioneer", "--config", cfg.to_str().unwrap()], says);
    }
    // A baud rate P2OS does not speak (0 would hang up a real serial line), from the
    // flag or the file, is refused before any port is opened.
    for b in ["0", "12345"] {
        let says = format!("baud {b} is not a rate a P2OS controller speaks");
        usage(&["pioneer", "--emulated", "--baud", b], &says);
        usage(&["pioneer", "--baud", b, "--print-config"], &says);
    }
    std::fs::write(&cfg, "baud = 4800\n").unwrap();
    usage(
        &["pioneer", "--config", cfg.to_str().unwrap()],
        "baud 4800 is not a rate",
    );
    // A core this process may not use is refused, not a warning and an unpinned driver.
    usage(
        &["pioneer", "--emulated", "--cpu", "4096"],
        "--cpu 4096: no such core among those this process may use",
    );
    std::fs::remove_file(&cfg).unwrap();
    // An empty domain is an error with a sentence, not silently "limber".
    usage(&["list", "--domain", ""], "the domain name is empty");
    let o = common::output(Command::new(LIMBER).args(["list"]).env("LIMBER_DOMAIN", ""));
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("the domain name is empty"),
        "{}",
        stderr(&o)
    );
}

/// `--print-config` shows the autopark key with its meaning.
#[test]
fn print_config_documents_autopark() {
    let o = limber("limber", &["pioneer", "--print-config"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = common::stdout(&o);
    assert!(text.contains("autopark_s = 10"), "{text}");
    assert!(text.contains("# autopark_s:"), "{text}");
}

/// Runs `limber <args>` with its stdout a pipe that this test closes after the first
/// line; the exit status and stderr.
fn first_line_then_close(domain: &str, args: &[&str]) -> (Option<i32>, String) {
    let mut child = Command::new(LIMBER)
        .args(args)
        .env("LIMBER_DOMAIN", domain)
        .env("RUST_BACKTRACE", "1")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut out = BufReader::new(child.stdout.take().unwrap());
    let mut line = String::new();
    out.read_line(&mut line).unwrap();
    assert!(!line.is_empty(), "{args:?}: no first line");
    drop(out); // the reader goes away, as `head -1` does
    let mut err = child.stderr.take().unwrap();
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let mut s = String::new();
        let r = std::io::Read::read_to_string(&mut err, &mut s);
        let _ = tx.send((r.is_ok(), s));
    });
    let deadline = Instant::now() + Duration::from_secs(30);
    let code = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s.code();
        }
        if Instant::now() >= deadline {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{args:?} still running 30 s after its stdout closed");
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let (_, err) = rx.recv_timeout(Duration::from_secs(30)).unwrap();
    (code, err)
}

/// A closed stdout ends every verb quietly with exit 0, as Unix tools do (it used to
/// panic: "failed printing to stdout: Broken pipe", exit 101).
#[test]
fn a_closed_stdout_ends_the_verb_quietly() {
    let d = Domain::unique_for_test();
    let _stop = driver(d.name());
    for args in [
        &["echo", "cli/actarray/0", "--count", "100000"][..],
        &["echo", "cli/actarray/0", "--json"][..],
        &["echo", "cli/actarray/0"][..],
        &["layout"][..],
        &["list"][..],
        &["monitor", "--once"][..],
        &["actarray", "cli/actarray/0", "geom"][..],
    ] {
        let (code, err) = first_line_then_close(d.name(), args);
        assert_eq!(code, Some(0), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert!(!err.contains("Broken pipe"), "{args:?}: {err}");
    }
}

/// `limber demo | head -1` ends the demo quietly too, on either robot (its driver, and so
/// the arm, stopped with it).
#[test]
fn a_closed_stdout_ends_the_demo_quietly() {
    for on in ["pioneer", "simarm"] {
        let d = Domain::unique_for_test();
        let args = ["demo", "--on", on];
        let (code, err) = first_line_then_close(d.name(), &args);
        assert_eq!(code, Some(0), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
}

/// `limber bench --only` with a scenario that does not exist is a usage error (exit 2),
/// refused with a sentence that names the scenarios there are.
#[test]
fn bench_only_an_unknown_scenario_is_a_usage_error() {
    let d = Domain::unique_for_test();
    let o = limber(d.name(), &["bench", "--only", "nonsense"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let err = stderr(&o);
    assert!(err.contains("unknown scenario \"nonsense\""), "{err}");
    assert!(
        err.contains("the scenarios are floor, state, command"),
        "{err}"
    );
}

/// A device full of clients refuses one more verb with exit 5 and a sentence naming the
/// device, its limit and what to do; `--priority` (or `LIMBER_PRIORITY=1`) gets in.
#[test]
fn a_full_device_refuses_a_verb_with_exit_5_and_priority_gets_in() {
    use limber_services::prelude::*;
    use limber_services::qos::Capacity;
    use limber_services::testing::TestDriver;
    use std::sync::mpsc;

    let d = Domain::unique_for_test();
    let (stop_tx, stop_rx) = mpsc::channel::<()>();
    let (ready_tx, ready_rx) = mpsc::channel();
    let name = d.name().to_string();
    let served = std::thread::spawn(move || {
        let domain = Domain::new(&name).unwrap();
        let ctx = Context::new(&domain, Role::Driver, "testdriver").unwrap();
        ctx.set_capacity(Capacity::new(2).unwrap());
        let mut drv = TestDriver::new(&ctx, "cli", 6).unwrap();
        ready_tx.send(()).unwrap();
        let _ = drv.run(Duration::from_millis(10), || {
            !matches!(stop_rx.try_recv(), Err(mpsc::TryRecvError::Empty))
        });
    });
    ready_rx.recv_timeout(Duration::from_secs(10)).unwrap();
    let ctx = Context::new(&d, Role::Client, "filler").unwrap();
    ctx.set_priority(false);
    let _fill: Vec<_> = (0..2)
        .map(|_| ActArrayClient::connect(&ctx, "cli/actarray/0").unwrap())
        .collect();
    let verb = |args: &[&str], priority: Option<&str>| {
        let mut cmd = Command::new(LIMBER);
        cmd.args(args)
            .env("LIMBER_DOMAIN", d.name())
            .env_remove("LIMBER_PRIORITY");
        if let Some(p) = priority {
            cmd.env("LIMBER_PRIORITY", p);
        }
        common::output(&mut cmd)
    };
    let o = verb(&["actarray", "cli/actarray/0", "geom"], None);
    assert_eq!(o.status.code(), Some(5), "{}", stderr(&o));
    for needle in [
        "cli/actarray/0 is full",
        "admits 2 clients",
        "--max-clients",
        "LIMBER_PRIORITY=1",
    ] {
        assert!(stderr(&o).contains(needle), "{needle:?}: {}", stderr(&o));
    }
    assert!(!stderr(&o).contains("ExceedsMax"), "{}", stderr(&o));
    let o = verb(&["actarray", "cli/actarray/0", "geom", "--priority"], None);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let o = verb(&["actarray", "cli/actarray/0", "geom"], Some("1"));
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    stop_tx.send(()).unwrap();
    served.join().unwrap();
}

/// `--max-clients` is the driver's `max_clients`, checked like every value.
#[test]
fn max_clients_is_a_setting_of_the_drivers() {
    let d = Domain::unique_for_test();
    let o = limber(
        d.name(),
        &["pioneer", "--print-config", "--max-clients", "80"],
    );
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(
        String::from_utf8_lossy(&o.stdout).contains("max_clients = 80"),
        "{}",
        String::from_utf8_lossy(&o.stdout)
    );
    for args in [
        &["pioneer", "--print-config", "--max-clients", "0"][..],
        &["simarm", "--max-clients", "0"][..],
    ] {
        let o = limber(d.name(), args);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(
            stderr(&o).contains("max_clients must be between 1 and"),
            "{args:?}: {}",
            stderr(&o)
        );
    }
}
