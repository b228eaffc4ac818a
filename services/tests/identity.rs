//! Who a client is comes from the transport, not from the bytes it writes: a process that
//! writes the lease holder's client id into its commands, requests and lease requests is
//! still refused as another client (issue "Nobody moves the arm who may not", item 2, the
//! local part: before, `arm._client_id = arm.holder().client_id` let a Python client move a
//! held arm, and a forged RELEASE freed it).

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::{Duration, Instant};

use limber_interfaces::message::Message as _;
use limber_services::prelude::*;
use limber_services::testing::TestArm;
use limber_services::{LeaseError, RequestError};

const T: Duration = Duration::from_secs(5);
const DEVICE: &str = "ident/actarray/0";

/// A driver of a 2-joint test arm on a thread of this process until `stop`; with `refused`,
/// it keeps the count of commands it refused there.
fn test_driver(
    domain: &Domain,
    stop: &Arc<AtomicBool>,
    refused: Option<Arc<AtomicU64>>,
) -> std::thread::JoinHandle<()> {
    let (stop, domain) = (Arc::clone(stop), domain.clone());
    std::thread::spawn(move || {
        let ctx = Context::new(&domain, Role::Driver, "ident").unwrap();
        let mut host = DeviceHost::<ActArray>::new(&ctx, &DEVICE.parse().unwrap(), "t").unwrap();
        host.state_mut().actuators_count = 2;
        host.publish().unwrap();
        let mut arm = TestArm::new(2);
        while !stop.load(Ordering::Relaxed) {
            host.process_spin(&mut arm).unwrap();
            if let Some(r) = &refused {
                r.store(host.stats().refused, Ordering::Relaxed);
            }
            std::thread::yield_now();
        }
    })
}

#[test]
fn a_client_that_writes_the_holders_id_is_not_the_holder() {
    let domain = Domain::unique_for_test();
    let stop = Arc::new(AtomicBool::new(false));
    let driver = test_driver(&domain, &stop, None);
    // The holder and the forger: two processes as far as iceoryx2 knows (a node each).
    let hctx = Context::new(&domain, Role::Client, "alice").unwrap();
    let mut holder = ActArrayClient::connect_timeout(&hctx, DEVICE, T).unwrap();
    holder.set_request_timeout(T);
    holder.acquire("alice", Duration::from_secs(30)).unwrap();
    let fctx = Context::new(&domain, Role::Client, "mallory").unwrap();
    let mut forger = ActArrayClient::connect_timeout(&fctx, DEVICE, T).unwrap();
    forger.set_request_timeout(T);

    // A command as the holder: its id, a sequence number of its own.
    let mut raw = ActArrayCmdMsg::default();
    ActArrayCommand::position(1, 0.7).unwrap().write(&mut raw);
    raw.meta.client_id = holder.client_id();
    raw.meta.seq = 1_000_000;
    forger.relay_send(&raw).unwrap();
    let deadline = Instant::now() + T;
    let shown = loop {
        let s = *holder.wait_state(T).unwrap();
        if s.header.last_cmd.cmd_seq == raw.meta.seq {
            break s;
        }
        assert!(
            Instant::now() < deadline,
            "the forged command was never decided"
        );
    };
    assert_eq!(
        Status::try_from(shown.header.last_cmd.status),
        Ok(Status::Leased),
        "a command with the holder's id from another process is refused"
    );
    assert_ne!(shown.actuators[1].position, 0.7, "the joint did not move");

    // A request that changes the device, as the holder: refused.
    let mut req = ActArrayReqMsg::default();
    ActArrayRequest::Power(false).write(&mut req);
    req.meta.client_id = holder.client_id();
    req.meta.seq = 1;
    let pending = forger.relay_request(&req).unwrap();
    let reply = loop {
        if let Some(r) = pending.try_reply().unwrap() {
            break r;
        }
        assert!(Instant::now() < deadline + T, "no reply");
        std::thread::yield_now();
    };
    assert!(
        matches!(ActArrayReply::read(&reply), Ok(Err(Status::Leased))),
        "a POWER with the holder's id from another process is refused"
    );

    // A RELEASE as the holder (the node id it carries is the holder's too): refused, and
    // the holder keeps the arm.
    let mut release = LeaseReq {
        client_id: holder.client_id(),
        seq: 1,
        op: lease_op::RELEASE,
        ..LeaseReq::default()
    };
    release.set_node_id(hctx.node().id().value());
    let pending = forger.relay_lease(&release).unwrap();
    let reply = loop {
        if let Some(r) = pending.try_reply().unwrap() {
            break r;
        }
        assert!(Instant::now() < deadline + T, "no lease reply");
        std::thread::yield_now();
    };
    assert_eq!(Status::try_from(reply.status), Ok(Status::Leased));
    holder.renew().expect("the holder still holds the arm");
    assert!(matches!(
        forger.power(false),
        Err(RequestError::Nack(Status::Leased))
    ));
    assert!(matches!(
        forger.acquire("mallory", Duration::from_secs(1)),
        Err(LeaseError::Held { .. })
    ));
    // The holder's own command is carried out. (Its outcome is not waited for: the forged
    // command's number, far above the holder's own, makes the holder's outcome table take
    // its later commands for missed, which the transport cannot tell yet: outcomes are
    // addressed by client id.)
    holder.move_to(1, 0.5).unwrap();
    let deadline = Instant::now() + T;
    while holder.wait_state(T).unwrap().actuators[1].position != 0.5 {
        assert!(
            Instant::now() < deadline,
            "the holder's command was not carried out"
        );
    }

    stop.store(true, Ordering::Relaxed);
    driver.join().unwrap();
}

/// The environment variable that makes [`forger_process`] the forging child of
/// [`a_command_with_another_processs_client_id_is_dropped`]: `<domain> <victim id>`.
const FORGE_ENV: &str = "LIMBER_TEST_FORGE";

/// Not a test of its own: the child process of the test below, which sends one POS with
/// the victim's client id (a process of its own, as iceoryx2 knows it) and ends.
#[test]
fn forger_process() {
    let Ok(spec) = std::env::var(FORGE_ENV) else {
        return;
    };
    let (domain, victim) = spec.split_once(' ').unwrap();
    let domain = Domain::new(domain).unwrap();
    let ctx = Context::new(&domain, Role::Client, "mallory").unwrap();
    let mut c = ActArrayClient::connect_timeout(&ctx, DEVICE, T).unwrap();
    let mut raw = ActArrayCmdMsg::default();
    ActArrayCommand::position(1, 0.9).unwrap().write(&mut raw);
    raw.meta.client_id = victim.parse().unwrap();
    raw.meta.seq = 1;
    c.relay_send(&raw).unwrap();
    // Open until the parent saw the driver take it (it closes our stdin): a publisher
    // that goes at once may take its sample along.
    let mut line = String::new();
    let _ = std::io::stdin().read_line(&mut line);
}

/// A client id names the process that made it: a command from another process that carries
/// a victim's id is dropped and counted refused, never carried out, and no outcome reaches
/// the victim for a command it never sent (before, the outcome came to the victim, whose
/// table then took its own later commands for missed).
#[test]
fn a_command_with_another_processs_client_id_is_dropped() {
    let domain = Domain::unique_for_test();
    let stop = Arc::new(AtomicBool::new(false));
    let refused = Arc::new(AtomicU64::new(0));
    let driver = test_driver(&domain, &stop, Some(Arc::clone(&refused)));
    let vctx = Context::new(&domain, Role::Client, "victim").unwrap();
    let mut victim = ActArrayClient::connect_timeout(&vctx, DEVICE, T).unwrap();
    let before = victim.wait_state(T).unwrap().actuators[1].position;
    let mut child = std::process::Command::new(std::env::current_exe().unwrap())
        .args(["--exact", "forger_process", "--nocapture"])
        .env(
            FORGE_ENV,
            format!("{} {}", domain.name(), victim.client_id()),
        )
        .stdin(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let deadline = Instant::now() + T;
    while refused.load(Ordering::Relaxed) == 0 {
        assert!(
            Instant::now() < deadline,
            "the forged command was not refused (carried out, or never seen)"
        );
        std::thread::yield_now();
    }
    drop(child.stdin.take());
    assert!(child.wait().unwrap().success());
    // The victim's own first command: its outcome is its own, ok; the joint never went to
    // the forged target.
    let t = victim.move_to(0, 0.3).unwrap();
    let o = victim.wait_outcome(t, T);
    assert!(matches!(o, Ok(Status::Ok)), "{o:?}");
    // The state that shows the victim's command went out before its outcome.
    let s = *victim.state().expect("the latest state");
    assert_eq!(
        s.actuators[1].position, before,
        "the forged POS moved joint 1"
    );
    stop.store(true, Ordering::Relaxed);
    driver.join().unwrap();
}
