//! Issue 12, item 12 from the shell: `--own`, a held device refusing others with the
//! holder's name (readers unaffected), and no outcome missed under contention.

use std::time::Duration;

use limber_services::prelude::*;
use limber_services::{Context, Domain, Role};

mod common;
use common::{driver, limber, stderr, stdout};

const T: Duration = Duration::from_secs(5);

#[test]
fn own_takes_the_device_and_a_held_device_refuses_others_naming_its_holder() {
    let d = Domain::unique_for_test();
    let _stop = driver(d.name());
    let dom = d.name();
    // As README shows it: the device taken for the command, and free again after it.
    let o = limber(
        dom,
        &["actarray", "cli/actarray/0", "pos", "2", "0.5", "--own"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stdout(&o), "ok\n");

    let ctx = Context::new(&d, Role::Client, "holder").unwrap();
    let mut alice = ActArrayClient::connect_timeout(&ctx, "cli/actarray/0", T).unwrap();
    assert_eq!(alice.holder().unwrap(), None);
    alice.acquire("alice", Duration::from_secs(30)).unwrap();

    let held = "refused: held by another client (alice)";
    for args in [
        &["actarray", "cli/actarray/0", "pos", "2", "0.1"][..],
        &["actarray", "cli/actarray/0", "pos", "2", "0.1", "--own"],
        &["actarray", "cli/actarray/0", "power", "on"],
    ] {
        let o = limber(dom, args);
        assert_eq!(o.status.code(), Some(5), "{args:?}: {}", stderr(&o));
        assert!(stderr(&o).contains(held), "{args:?}: {}", stderr(&o));
    }
    // Readers are unaffected; other devices of the robot too.
    let o = limber(dom, &["actarray", "cli/actarray/0", "geom"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = limber(dom, &["gripper", "cli/gripper/0", "open", "--own"]);
    assert!(o.status.success(), "{}", stderr(&o));
    // The holder commands as usual.
    let t = alice.move_to(2, 0.2).unwrap();
    assert_eq!(alice.wait_outcome(t, T).unwrap(), Status::Ok);

    alice.release().unwrap();
    let o = limber(
        dom,
        &["actarray", "cli/actarray/0", "pos", "2", "0.1", "--own"],
    );
    assert!(o.status.success(), "{}", stderr(&o));
}

#[test]
fn a_lease_ends_with_its_holder_client_and_with_a_missed_heartbeat() {
    let d = Domain::unique_for_test();
    let _stop = driver(d.name());
    let ctx = Context::new(&d, Role::Client, "leases").unwrap();
    let mut a = ActArrayClient::connect_timeout(&ctx, "cli/actarray/0", T).unwrap();
    let mut b = ActArrayClient::connect_timeout(&ctx, "cli/actarray/0", T).unwrap();
    // A heartbeat outside the allowed range is refused.
    assert_eq!(
        a.acquire("a", Duration::from_millis(1)),
        Err(limber_services::LeaseError::Refused(
            Status::InvalidArgument
        ))
    );
    // Dropping the holder releases.
    a.acquire("a", Duration::from_secs(30)).unwrap();
    assert_eq!(b.holder().unwrap().unwrap().name, "a");
    drop(a);
    assert_eq!(b.holder().unwrap(), None);
    // A heartbeat kept: the lease lives; missed: it ends (the test driver's joint, moving
    // at a speed, stops) and the late holder learns it lost the lease.
    b.acquire("b", Duration::from_millis(200)).unwrap();
    let t = b.move_at_speed(1, 0.5).unwrap();
    assert_eq!(b.wait_outcome(t, T).unwrap(), Status::Ok);
    // Renewed at every state sample until the driver's own stamps show three heartbeat
    // periods gone by (evidence from the driver, not a sleep of this test).
    let first = b.wait_state(T).unwrap().header.stamp_ns;
    let mut kept = false;
    for _ in 0..100_000 {
        b.keep_lease().unwrap();
        let s = b.wait_state(T).unwrap();
        if s.header.stamp_ns.saturating_sub(first) >= 600_000_000 {
            kept = true;
            break;
        }
    }
    assert!(kept, "the driver's stamps never covered three heartbeats");
    assert_eq!(b.holder().unwrap().unwrap().name, "b");
    let s = b.wait_state(T).unwrap();
    assert_eq!(s.actuators[1].state, ActuatorFlags::MOVING.bits());
    // Unrenewed, the lease ends: every sample is waited for with a timeout, and the
    // number of samples is bounded too.
    let mut ended = false;
    for _ in 0..10_000 {
        let s = b.wait_state(T).unwrap();
        if s.header.flags & device_flag::LEASED == 0 {
            assert_eq!(s.actuators[1].state, ActuatorFlags::IDLE.bits());
            ended = true;
            break;
        }
    }
    assert!(ended, "the lease never ended");
    assert_eq!(b.renew(), Err(limber_services::LeaseError::Lost));
    assert!(!b.holds_lease());
}

/// Under contention (another client flooding the device with commands) every command of
/// the CLI gets its own outcome: "ok", exit 0 — never exit 6 for a command carried out,
/// never another client's outcome.
#[test]
fn the_cli_never_misses_its_outcome_under_contention() {
    let d = Domain::unique_for_test();
    let _stop = driver(d.name());
    let (stop_tx, stop_rx) = std::sync::mpsc::channel::<()>();
    let (ready_tx, ready_rx) = std::sync::mpsc::channel::<()>();
    let dom = d.clone();
    let flood = std::thread::spawn(move || {
        let ctx = Context::new(&dom, Role::Client, "flood").unwrap();
        let mut c = ActArrayClient::connect_timeout(&ctx, "cli/actarray/0", T).unwrap();
        let mut sent = 0u64;
        // Bursts longer than the state channel's buffer (16 samples): a client reading
        // its outcome from the state header alone would find it overwritten.
        while stop_rx.try_recv().is_err() {
            for _ in 0..24 {
                c.move_to(3, (sent % 100) as f64 * 1e-3).unwrap();
                sent += 1;
            }
            if sent == 240 {
                ready_tx.send(()).unwrap();
            }
            std::thread::sleep(Duration::from_millis(1));
        }
        sent
    });
    ready_rx.recv_timeout(T).unwrap();
    let dom = d.name().to_string();
    let clis: Vec<_> = (0..6)
        .map(|i| {
            let dom = dom.clone();
            std::thread::spawn(move || {
                let pos = format!("0.{i}");
                let args = [
                    "actarray",
                    "cli/actarray/0",
                    "pos",
                    "0",
                    &pos,
                    "--timeout",
                    "10",
                ];
                limber(&dom, &args)
            })
        })
        .collect();
    for h in clis {
        let o = h.join().unwrap();
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        assert_eq!(stdout(&o), "ok\n");
    }
    stop_tx.send(()).unwrap();
    let sent = flood.join().unwrap();
    assert!(sent > 240);
}

/// README, "Concurrent use and ownership", as written against `limber pioneer --emulated`:
/// `--own` carries the command out, and refuses naming the holder while another holds it.
#[test]
fn the_readme_own_example_runs_as_written() {
    let d = Domain::unique_for_test();
    let _p = common::pioneer_emulated(d.name());
    let dom = d.name();
    let example = ["actarray", "pioneer/actarray/0", "pos", "2", "0.5", "--own"];
    let o = limber(dom, &["actarray", "pioneer/actarray/0", "power", "on"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = limber(dom, &example);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(stdout(&o), "ok\n");

    let ctx = Context::new(&d, Role::Client, "alice").unwrap();
    let mut alice = ActArrayClient::connect_timeout(&ctx, "pioneer/actarray/0", T).unwrap();
    alice.acquire("alice", Duration::from_secs(30)).unwrap();
    let o = limber(dom, &example);
    assert_eq!(o.status.code(), Some(5), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("refused: held by another client (alice)"),
        "{}",
        stderr(&o)
    );
}
