//! `limber list` against a running driver.

use std::process::Command;

use limber_services::Domain;

mod common;
use common::{LIMBER, driver};

#[test]
fn list_shows_devices_drivers_and_liveness() {
    let domain = Domain::unique_for_test();
    let _stop = driver(domain.name());
    let out = common::output(Command::new(LIMBER).args(["list", "--domain", domain.name()]));
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    for dev in ["cli/actarray/0", "cli/limb/0", "cli/gripper/0"] {
        let line = text
            .lines()
            .find(|l| l.starts_with(dev))
            .unwrap_or_else(|| panic!("{text}"));
        assert!(
            line.contains("testdriver") && line.contains("alive"),
            "{line}"
        );
    }
    let out = common::output(
        Command::new(LIMBER)
            .args(["list", "--json"])
            .env("LIMBER_DOMAIN", domain.name()),
    );
    let text = String::from_utf8(out.stdout).unwrap();
    assert_eq!(text.lines().count(), 3);
    assert!(text.contains(r#""device":"cli/limb/0""#), "{text}");
}

#[test]
fn list_of_an_empty_domain_says_so_and_bad_domains_are_refused() {
    let out = common::output(Command::new(LIMBER).args([
        "list",
        "--domain",
        Domain::unique_for_test().name(),
    ]));
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stdout).contains("no devices"));
    let out = common::output(Command::new(LIMBER).args(["list", "--domain", "a b"]));
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("invalid domain"));
}

/// `-v` (`limber --help`: more log output, repeatable) is accepted by every verb and
/// changes nothing else: the empty domain is still reported on stdout, exit 0.
#[test]
fn verbose_flag_is_global() {
    let d = Domain::unique_for_test();
    for v in ["-v", "-vv", "-vvv"] {
        let out = common::output(Command::new(LIMBER).args([v, "list", "--domain", d.name()]));
        assert!(out.status.success(), "{v}");
        assert!(
            String::from_utf8_lossy(&out.stdout).contains("no devices"),
            "{v}"
        );
    }
}

/// Issue "Nobody moves the arm who may not", item 14: a driver that serves only its
/// statistics (a robot without arm or gripper) is listed, with what its robot lacks, rather
/// than "no devices in domain".
#[test]
fn a_driver_serving_only_statistics_is_listed_with_what_it_lacks() {
    use limber_interfaces::diagnostics::{DriverStats, hardware, put_text};
    use limber_services::diagnostics::StatsPublisher;
    use limber_services::{Context, Role};
    use std::sync::mpsc;
    use std::time::Duration;

    let domain = Domain::unique_for_test();
    let (stop_tx, stop_rx) = mpsc::channel::<()>();
    let (ready_tx, ready_rx) = mpsc::channel();
    let name = domain.name().to_string();
    let served = std::thread::spawn(move || {
        let domain = Domain::new(&name).unwrap();
        let ctx = Context::new(&domain, Role::Driver, "pioneer").unwrap();
        let mut publisher = StatsPublisher::new(&ctx, "bare").unwrap();
        let mut stats = DriverStats::default();
        put_text(&mut stats.driver, "pioneer");
        stats.hardware = hardware::NO_ARM | hardware::NO_GRIPPER | hardware::NO_LIFT;
        publisher.publish(&mut stats).unwrap();
        ready_tx.send(()).unwrap();
        // As a driver does, once per period until the test is done (a new reader gets the
        // history at the next publication).
        while let Err(mpsc::RecvTimeoutError::Timeout) =
            stop_rx.recv_timeout(Duration::from_millis(10))
        {
            publisher.publish(&mut stats).unwrap();
        }
    });
    ready_rx.recv_timeout(Duration::from_secs(10)).unwrap();
    let out = common::output(Command::new(LIMBER).args(["list", "--domain", domain.name()]));
    stop_tx.send(()).unwrap();
    served.join().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(!text.contains("no devices"), "{text}");
    assert!(
        text.contains("robot bare has no arm, no gripper, no lift (driver pioneer)"),
        "{text}"
    );
}
