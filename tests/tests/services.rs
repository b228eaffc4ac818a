//! The services layer across real processes, each test in a domain of its own.

use std::time::{Duration, Instant};

use limber_services::prelude::*;
use limber_services::{ConnectError, Domain, Role};
use limber_tests::Proc;

const DRIVER: &str = env!("CARGO_BIN_EXE_limber-test-driver");
const CLIENT: &str = env!("CARGO_BIN_EXE_limber-test-client");
const T: Duration = Duration::from_secs(5);

fn start_driver(domain: &Domain, extra: &[&str]) -> Proc {
    Proc::spawn_ready(DRIVER, domain.name(), extra)
}

fn client_ctx(domain: &Domain) -> Context {
    Context::new(domain, Role::Client, "test").unwrap()
}

#[test]
fn several_client_processes_at_once() {
    let domain = Domain::unique_for_test();
    let _driver = start_driver(&domain, &[]);
    let mut clients: Vec<Proc> = (0..3)
        .map(|_| Proc::spawn(CLIENT, domain.name(), &["basic"]))
        .collect();
    for c in &mut clients {
        assert_eq!(c.wait_timeout(Duration::from_secs(20)), Some(0));
        assert!(c.rest_of_stdout().contains("ok"));
    }
}

#[test]
fn state_commands_requests_and_refusals_from_this_process() {
    let domain = Domain::unique_for_test();
    let _driver = start_driver(&domain, &[]);
    let ctx = client_ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&ctx, "test/actarray/0", T).unwrap();
    let s = arm.wait_state(T).unwrap();
    assert_eq!(s.actuators_count, 6);
    // A refused command is visible to its sender, with the reason.
    let t = arm.move_to(7, 0.1).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::UnknownJoint);
    let t = arm.move_to(2, 4.0).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::BeyondLimits);
    let t = arm.move_to(2, 1.0).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);
    assert_eq!(arm.state().unwrap().actuators[2].position, 1.0);
    // Invalid values never leave the client.
    assert!(matches!(
        arm.move_to(2, f64::NAN),
        Err(CommandError::Invalid(_))
    ));
    // Requests: typed ACK payloads and NACK reasons.
    assert_eq!(arm.geometry().unwrap().actuators_count, 6);
    assert_eq!(
        arm.brakes(true),
        Err(RequestError::Nack(Status::Unsupported))
    );
    assert_eq!(
        arm.set_speed_config(9, 1.0),
        Err(RequestError::Nack(Status::UnknownJoint))
    );
    // The other two interfaces.
    let mut limb = LimbClient::connect(&ctx, "test/limb/0").unwrap();
    let t = limb
        .set_pose([3.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0])
        .unwrap();
    assert_eq!(limb.wait_outcome(t, T).unwrap(), Status::OutOfReach);
    assert_eq!(
        limb.state().unwrap().limb_state().unwrap(),
        LimbState::OutOfReach
    );
    let t = limb.set_position([0.3, 0.0, 0.2]).unwrap();
    assert_eq!(limb.wait_outcome(t, T).unwrap(), Status::Ok);
    assert_eq!(limb.state().unwrap().limb_state().unwrap(), LimbState::Idle);
    let mut grip = GripperClient::connect(&ctx, "test/gripper/0").unwrap();
    let t = grip.close().unwrap();
    assert_eq!(grip.wait_outcome(t, T).unwrap(), Status::Ok);
    assert_eq!(
        grip.state().unwrap().gripper_state().unwrap(),
        GripperState::Closed
    );
    assert_eq!(grip.geometry().unwrap().num_beams, 2);
    let t = grip.store().unwrap();
    assert_eq!(grip.wait_outcome(t, T).unwrap(), Status::Unsupported);
    // A wrong interface or an absent device is a clear error.
    assert!(matches!(
        LimbClient::connect(&ctx, "test/actarray/0"),
        Err(ConnectError::Incompatible { .. })
    ));
    assert!(matches!(
        GripperClient::connect(&ctx, "test/gripper/5"),
        Err(ConnectError::NoDriver { .. })
    ));
}

#[test]
fn no_driver_is_reported_at_once() {
    let domain = Domain::unique_for_test();
    let ctx = client_ctx(&domain);
    let start = Instant::now();
    let err = ActArrayClient::connect(&ctx, "nobody/actarray/0").unwrap_err();
    assert!(matches!(err, ConnectError::NoDriver { .. }), "{err}");
    assert!(
        err.to_string()
            .contains("no driver offers nobody/actarray/0")
    );
    let err =
        ActArrayClient::connect_timeout(&ctx, "nobody/actarray/0", Duration::from_millis(100))
            .unwrap_err();
    assert!(matches!(err, ConnectError::NoDriver { .. }));
    let _ = start;
}

#[test]
fn a_client_dying_mid_request_does_not_hurt_the_driver() {
    let domain = Domain::unique_for_test();
    let mut driver = start_driver(&domain, &["--hold-first-request"]);
    let mut victim = Proc::spawn(CLIENT, domain.name(), &["hold-request"]);
    // The driver has the request in hand (and holds it): kill its sender now.
    let held = driver.read_until(|l| l.starts_with("request "));
    assert!(held.is_some(), "the driver never received the request");
    victim.signal(libc::SIGKILL);
    assert_eq!(victim.wait_timeout(T), None, "the client was not killed");
    // Let the driver answer the dead client (undeliverable); it goes on serving.
    driver.write_line("go");
    let ctx = client_ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&ctx, "test/actarray/0", T).unwrap();
    for _ in 0..3 {
        assert_eq!(arm.geometry().unwrap().actuators_count, 6);
    }
    driver.signal(libc::SIGTERM);
    assert_eq!(driver.wait_timeout(T), Some(0));
    let out = driver.rest_of_stdout();
    assert!(
        out.contains("requests=4 "),
        "the held request was not answered: {out}"
    );
}

#[test]
fn a_killed_driver_is_noticed_and_a_restarted_one_picked_up() {
    let domain = Domain::unique_for_test();
    let mut driver = start_driver(&domain, &[]);
    let ctx = client_ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&ctx, "test/actarray/0", T).unwrap();
    arm.wait_state(T).unwrap();
    assert_eq!(arm.driver_status(), DriverStatus::Alive);

    driver.signal(libc::SIGKILL);
    let _ = driver.wait_timeout(T);
    // Noticed within a bounded time, well before the (long) timeout.
    let mut noticed = false;
    for _ in 0..5 {
        match arm.wait_state(Duration::from_secs(30)) {
            Err(WaitError::DriverGone) => {
                noticed = true;
                break;
            }
            Ok(_) => continue, // samples still buffered from before the kill
            Err(e) => panic!("expected DriverGone, got {e}"),
        }
    }
    assert!(noticed);
    assert_ne!(arm.driver_status(), DriverStatus::Alive);
    assert!(matches!(
        arm.geometry(),
        Err(RequestError::NoDriver | RequestError::DriverGone)
    ));
    let devices = list_devices(&domain).unwrap();
    assert!(devices.iter().all(|d| !d.alive), "{devices:?}");

    // Restart: the same client object works again, without reconnecting.
    let _driver2 = start_driver(&domain, &[]);
    let deadline = Instant::now() + T;
    loop {
        match arm.geometry() {
            Ok(g) => {
                assert_eq!(g.actuators_count, 6);
                break;
            }
            Err(e) if Instant::now() < deadline => {
                let _ = e;
                std::thread::sleep(Duration::from_millis(20));
            }
            Err(e) => panic!("restarted driver not picked up: {e}"),
        }
    }
    let t = arm.move_to(0, 0.5).unwrap();
    assert_eq!(arm.wait_outcome(t, T).unwrap(), Status::Ok);
    assert_eq!(arm.driver_status(), DriverStatus::Alive);
}

#[test]
fn bursts_from_two_clients_lose_nothing_and_keep_order() {
    let domain = Domain::unique_for_test();
    let mut driver = start_driver(&domain, &["--period-ms", "50"]);
    let n = 200u64;
    let ns = n.to_string();
    let mut a = Proc::spawn(CLIENT, domain.name(), &["burst", &ns]);
    let mut b = Proc::spawn(CLIENT, domain.name(), &["burst", &ns]);
    assert_eq!(a.wait_timeout(Duration::from_secs(20)), Some(0));
    assert_eq!(b.wait_timeout(Duration::from_secs(20)), Some(0));
    driver.signal(libc::SIGTERM);
    assert_eq!(driver.wait_timeout(T), Some(0));
    let out = driver.rest_of_stdout();
    let mut per_client: std::collections::BTreeMap<u64, Vec<u64>> = Default::default();
    for line in out.lines().filter(|l| l.starts_with("cmd ")) {
        let f: Vec<u64> = line[4..].split(' ').map(|x| x.parse().unwrap()).collect();
        per_client.entry(f[0]).or_default().push(f[1]);
    }
    assert_eq!(per_client.len(), 2, "{out}");
    for seqs in per_client.values() {
        assert_eq!(
            seqs,
            &(1..=n).collect::<Vec<_>>(),
            "lost or reordered commands"
        );
    }
    assert!(out.contains("overflows=0"), "{out}");
    assert!(out.contains("exit Signal"), "{out}");
}

#[test]
fn discovery_lists_devices_with_driver_and_liveness() {
    let domain = Domain::unique_for_test();
    let _driver = start_driver(&domain, &["--robot", "r2"]);
    let devices = list_devices(&domain).unwrap();
    let names: Vec<String> = devices.iter().map(|d| d.name.to_string()).collect();
    assert_eq!(names, ["r2/actarray/0", "r2/limb/0", "r2/gripper/0"]);
    assert!(devices.iter().all(|d| d.alive
        && d.driver == "testdriver"
        && d.layout == limber_interfaces::LAYOUT_VERSION.to_string()));
    // Another domain sees nothing.
    assert!(list_devices(&Domain::unique_for_test()).unwrap().is_empty());
}

/// Issue 12, item 11: the driver follows the sequence numbers of `CLIENT_SLOTS` clients per
/// device; after more than that many others commanded, a long-lived client's next command
/// was counted as (seq - 1) lost commands. Counters stay exact: nothing was lost, nothing
/// is counted.
#[test]
fn many_clients_do_not_make_a_long_lived_client_look_lossy() {
    let domain = Domain::unique_for_test();
    let mut driver = start_driver(&domain, &[]);
    let ctx = client_ctx(&domain);
    let mut long = ActArrayClient::connect_timeout(&ctx, "test/actarray/0", T).unwrap();
    let mut sent = 0u64;
    for i in 0..20 {
        let t = long.move_to(0, 0.01 * f64::from(i)).unwrap();
        assert_eq!(long.wait_outcome(t, T).unwrap(), Status::Ok);
        sent += 1;
    }
    let others = limber_services::CLIENT_SLOTS + 6;
    for _ in 0..others {
        // One at a time (a device serves a bounded number of clients at once).
        let mut c = ActArrayClient::connect_timeout(&ctx, "test/actarray/0", T).unwrap();
        let t = c.move_to(1, 0.2).unwrap();
        assert_eq!(c.wait_outcome(t, T).unwrap(), Status::Ok);
        sent += 1;
    }
    let t = long.move_to(0, 0.3).unwrap();
    assert_eq!(long.wait_outcome(t, T).unwrap(), Status::Ok);
    sent += 1;
    let s = long.state().expect("the state with the outcome");
    assert_eq!(s.header.cmd_overflows, 0, "commands counted as lost");
    driver.signal(libc::SIGTERM);
    assert_eq!(driver.wait_timeout(T), Some(0));
    let out = driver.rest_of_stdout();
    assert!(
        out.contains(&format!("stats commands={sent} refused=0 overflows=0 ")),
        "{out}"
    );
}

/// Issue "Nobody moves the arm who may not", item 14: `freshness(max_age)` looks at the
/// driver's process once the state is older than a short bound, not only after `max_age`:
/// a SIGKILLed driver is gone long before a generous `max_age` has passed.
#[test]
fn freshness_says_gone_soon_after_the_driver_dies_whatever_max_age() {
    let domain = Domain::unique_for_test();
    let mut driver = start_driver(&domain, &[]);
    let ctx = client_ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&ctx, "test/actarray/0", T).unwrap();
    arm.wait_state(T).unwrap();
    let generous = Duration::from_secs(3600);
    assert_eq!(arm.freshness(generous), Freshness::Fresh);
    driver.signal(libc::SIGKILL);
    assert_eq!(driver.wait_timeout(T), None, "killed");
    // The driver is dead: the state only ages. Gone well within max_age (the bound here
    // is the test's, not a claim of speed).
    let deadline = Instant::now() + Duration::from_secs(30);
    let mut seen = arm.freshness(generous);
    while seen == Freshness::Fresh && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(5));
        seen = arm.freshness(generous);
    }
    assert_eq!(seen, Freshness::Gone);
}

/// Item 14: a SIGKILLed driver reads DEAD (its node is found dead, then cleaned up), not
/// ABSENT, and a connection to its device fails even while another client keeps the
/// device's services open.
#[test]
fn a_killed_driver_reads_dead_and_its_device_refuses_new_connections() {
    let domain = Domain::unique_for_test();
    let mut driver = start_driver(&domain, &[]);
    let ctx = client_ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&ctx, "test/actarray/0", T).unwrap();
    arm.wait_state(T).unwrap();
    driver.signal(libc::SIGKILL);
    assert_eq!(driver.wait_timeout(T), None, "killed");
    // Found dead (and cleaned up on the way): dead it stays for this client, through its
    // own looks (freshness, waits) as through a monitor's repeated ones, until a driver is
    // back.
    assert_eq!(arm.driver_status(), DriverStatus::Dead);
    assert_eq!(arm.freshness(Duration::from_secs(3600)), Freshness::Gone);
    assert_eq!(
        arm.driver_status(),
        DriverStatus::Dead,
        "until a driver is back"
    );
    let other = Context::new(&domain, Role::Client, "late").unwrap();
    // `arm` keeps the services open: a new client must not be told it is connected.
    let err = ActArrayClient::connect(&other, "test/actarray/0").unwrap_err();
    assert!(matches!(err, ConnectError::NoDriver { .. }), "{err}");
    assert!(
        err.to_string().contains("no driver offers test/actarray/0"),
        "{err}"
    );
    drop(arm);
}

/// Item 14: a driver that ended cleanly (SIGTERM) while a client was attached is not
/// listed as dead: its devices are simply not offered any more.
#[test]
fn a_cleanly_stopped_driver_is_not_listed_dead() {
    let domain = Domain::unique_for_test();
    let mut driver = start_driver(&domain, &[]);
    let ctx = client_ctx(&domain);
    let mut arm = ActArrayClient::connect_timeout(&ctx, "test/actarray/0", T).unwrap();
    arm.wait_state(T).unwrap();
    driver.signal(libc::SIGTERM);
    assert_eq!(driver.wait_timeout(T), Some(0));
    let devices = list_devices(&domain).unwrap();
    assert!(devices.iter().all(|d| d.alive), "{devices:?}");
    assert_ne!(arm.driver_status(), DriverStatus::Dead);
    drop(arm);
}
