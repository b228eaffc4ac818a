//! The exposing bridge as a raw Zenoh peer sees it, through the private Unix socket, as
//! principal `local` (the only one it may act as there): under a flood of malformed
//! messages (commands of the wrong size, commands and requests without a valid origin) it
//! logs the first one and then a count, not one line per message, and keeps serving; the
//! outcome of a command comes back express, at the control priority, ahead of the states.

use std::path::PathBuf;
use std::process::Command;
use std::time::Duration;

use limber_interfaces::message::{Envelope, Message};
use limber_interfaces::prelude::*;
use limber_services::Domain;
use limber_tests::Proc;
use zenoh::Wait;
use zenoh::qos::{CongestionControl, Priority};
use zerocopy::{FromBytes, IntoBytes};

const CLI: &str = env!("CARGO_BIN_EXE_limber-test-cli");

/// A Zenoh client session of the test's own, connected to `endpoint` only.
fn session(endpoint: &str) -> zenoh::Session {
    let mut config = zenoh::Config::default();
    for (key, value) in [
        ("mode", "\"client\"".to_string()),
        ("connect/endpoints", format!("[\"{endpoint}\"]")),
        ("scouting/multicast/enabled", "false".to_string()),
    ] {
        config.insert_json5(key, &value).unwrap();
    }
    zenoh::open(config).wait().unwrap()
}

/// The private socket of `bridge expose` in `a`, and `limber pioneer --emulated` there, ready.
fn driver_in(a: &Domain) -> (String, Proc) {
    let endpoint = format!(
        "unixsock-stream/{}/bridge/{}.sock",
        a.runtime_dir().expect("the runtime directory").display(),
        a.name()
    );
    let mut driver = Proc::spawn(CLI, a.name(), &["pioneer", "--emulated"]);
    assert!(driver.read_until(|l| l.ends_with("ready")).is_some());
    (endpoint, driver)
}

#[test]
fn a_flood_of_malformed_messages_is_counted_not_logged_one_by_one() {
    let a = Domain::unique_for_test();
    let (endpoint, mut driver) = driver_in(&a);
    let log = PathBuf::from(env!("CARGO_TARGET_TMPDIR"))
        .join(format!("bridge-malformed-{}.log", std::process::id()));
    let mut c = Command::new("sh");
    c.args([
        "-c",
        "exec \"$0\" bridge expose 2>\"$1\"",
        CLI,
        log.to_str().unwrap(),
    ])
    .env("LIMBER_DOMAIN", a.name());
    let mut expose = Proc::spawn_command(c);
    assert!(
        expose
            .read_until(|l| l == "exposed pioneer/actarray/0")
            .is_some()
    );
    let s = session(&endpoint);
    // 1,000 commands of the wrong size, 788 without a valid origin.
    for i in 0..1788 {
        let session = if i < 1000 {
            "tester"
        } else {
            "not a valid origin!"
        };
        let cmd = format!("limber/pioneer/actarray/0/cmd/local/{session}");
        s.put(cmd, vec![0u8; 3])
            .congestion_control(CongestionControl::Block)
            .wait()
            .unwrap();
    }
    // Then a request of the wrong size, refused: its answer comes after the commands
    // before it were handled (one link, handled in order).
    let replies = s
        .get("limber/pioneer/actarray/0/req/local/tester")
        .payload(vec![0u8; 5])
        .timeout(Duration::from_secs(10))
        .wait()
        .unwrap();
    let reply = replies.recv().expect("the bridge answers the request");
    assert!(
        reply.result().is_err(),
        "a malformed request was answered ok"
    );
    s.close().wait().unwrap();
    for p in [&mut expose, &mut driver] {
        p.signal(libc::SIGTERM);
        assert_eq!(p.wait_timeout(Duration::from_secs(10)), Some(0));
    }
    let text = std::fs::read_to_string(&log).unwrap();
    std::fs::remove_file(&log).unwrap();
    let lines: Vec<&str> = text
        .lines()
        .filter(|l| {
            l.contains("malformed") || l.contains("wrong size") || l.contains("valid origin")
        })
        .collect();
    assert!(
        lines.len() <= 3,
        "{} log lines about 1,789 malformed messages:\n{}",
        lines.len(),
        lines[..lines.len().min(10)].join("\n")
    );
    assert!(
        text.contains("(1789 in all)"),
        "no count of all 1,789 malformed messages:\n{text}"
    );
}

/// An outcome the exposing bridge puts is `express` at `InteractiveHigh` (commands and
/// outcomes have a queue of their own, never batched behind a state): without it an outcome
/// that found a state in the batch being filled waited for Zenoh's 1 ms backoff timer, a
/// command round trip through the bridge pair of 1.3 ms in 1 of 50 (`limber bench --only
/// bridge`). The old code put it batched at Zenoh's default priority, `Data`.
#[test]
fn an_outcome_comes_back_express_ahead_of_the_states() {
    let a = Domain::unique_for_test();
    let (endpoint, mut driver) = driver_in(&a);
    let mut expose = Proc::spawn(CLI, a.name(), &["bridge", "expose"]);
    assert!(
        expose
            .read_until(|l| l == "exposed pioneer/actarray/0")
            .is_some()
    );
    let s = session(&endpoint);
    let outcomes = s
        .declare_subscriber("limber/pioneer/actarray/0/outcome/local/tester")
        .wait()
        .unwrap();
    let mut cmd = ActArrayCmdMsg::default();
    ActArrayCommand::Home(JointSel::All).write(&mut cmd);
    cmd.meta_mut().client_id = 1;
    // Until the subscription is known to the bridge an outcome may go nowhere: send again
    // (each a new command) until one comes back, for 10 s at most.
    let until = std::time::Instant::now() + Duration::from_secs(10);
    let sample = loop {
        cmd.meta_mut().seq += 1;
        s.put(
            "limber/pioneer/actarray/0/cmd/local/tester",
            cmd.as_bytes().to_vec(),
        )
        .congestion_control(CongestionControl::Block)
        .wait()
        .unwrap();
        if let Some(sample) = outcomes.recv_timeout(Duration::from_millis(500)).unwrap() {
            break sample;
        }
        assert!(std::time::Instant::now() < until, "no outcome came back");
    };
    let o = OutcomeMsg::read_from_bytes(&sample.payload().to_bytes()).expect("an outcome");
    assert_eq!(o.client_id, 1, "{o:?}");
    assert!(sample.express(), "the outcome was batched");
    assert_eq!(sample.priority(), Priority::InteractiveHigh);
    s.close().wait().unwrap();
    for p in [&mut expose, &mut driver] {
        p.signal(libc::SIGTERM);
        assert_eq!(p.wait_timeout(Duration::from_secs(10)), Some(0));
    }
}
