//! `--no-wait` (issue "Nobody moves the arm who may not", item 11): a command the CLI
//! calls "sent" reaches the driver, even though the CLI ends at once. 30 commands back to
//! back with alternating targets, each by a CLI process of its own: the driver's statistics
//! count all 30 (before, the command went down with the CLI's publisher when the driver
//! had not read it yet: 23 of 30 reached it).

mod common;
use common::{limber, pioneer_emulated, stdout};
use limber_services::Domain;

const SENT: u64 = 30;

/// The `clients.commands` count of the driver's statistics (`limber echo --json`).
fn commands_counted(domain: &str) -> u64 {
    let out = limber(
        domain,
        &["echo", "--json", "pioneer/driver", "--count", "1"],
    );
    let text = stdout(&out);
    let at = text
        .find("\"commands\":")
        .unwrap_or_else(|| panic!("no command count in {text}"));
    text[at + "\"commands\":".len()..]
        .chars()
        .take_while(char::is_ascii_digit)
        .collect::<String>()
        .parse()
        .unwrap()
}

#[test]
fn every_command_sent_without_waiting_reaches_the_driver() {
    let d = Domain::unique_for_test();
    let mut driver = pioneer_emulated(d.name());
    for i in 0..SENT {
        let target = if i % 2 == 0 { "0.2" } else { "0.3" };
        let out = limber(
            d.name(),
            &[
                "actarray",
                "pioneer/actarray/0",
                "pos",
                "2",
                target,
                "--no-wait",
            ],
        );
        assert!(out.status.success(), "{}", common::stderr(&out));
        assert_eq!(stdout(&out).trim(), "sent");
    }
    // The statistics come about once a second: look until they count 30, for a few of
    // their periods at most (nothing more is sent, so a count short of 30 stays short).
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(10);
    let mut seen = commands_counted(d.name());
    while seen < SENT && std::time::Instant::now() < deadline {
        seen = commands_counted(d.name());
    }
    assert_eq!(
        seen, SENT,
        "the driver counted {seen} of {SENT} commands sent"
    );
    driver.term();
}
