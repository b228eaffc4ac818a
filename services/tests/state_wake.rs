//! A client waiting for a state sleeps on its device's wake word (one futex per device,
//! bumped by the driver with every state), not on the device's iceoryx2 event: a driver
//! wakes all its state waiters with one system call instead of one datagram each, and a
//! sleeper wakes sooner (`limber bench --only state`).

use std::os::unix::fs::{MetadataExt, OpenOptionsExt};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;

use iceoryx2::prelude::PortFactory;
use limber_interfaces::prelude::*;
use limber_services::prelude::*;
use limber_services::{Channel, DriverStatus};

const T: Duration = Duration::from_secs(5);
const DEVICE: &str = "wake/actarray/0";

/// A driver on a thread of this process that publishes a state every millisecond (its
/// loop's period) until `stop`.
fn driver_thread(domain: &Domain, stop: &Arc<AtomicBool>) -> std::thread::JoinHandle<()> {
    let (domain, stop) = (domain.clone(), Arc::clone(stop));
    let (ready_tx, ready_rx) = std::sync::mpsc::channel();
    let h = std::thread::spawn(move || {
        let ctx = Context::new(&domain, Role::Driver, "wake").unwrap();
        let mut host = DeviceHost::<ActArray>::new(&ctx, &DEVICE.parse().unwrap(), "t").unwrap();
        host.state_mut().actuators_count = 2;
        host.publish().unwrap();
        ready_tx.send(()).unwrap();
        while !stop.load(Ordering::SeqCst) {
            host.state_mut().actuators[0].position += 0.001;
            host.publish().unwrap();
            std::thread::sleep(Duration::from_millis(1));
        }
    });
    ready_rx.recv_timeout(T).expect("the driver started");
    h
}

/// How many listeners the device's notify event has (each client that waited on it made one).
fn notify_listeners(ctx: &Context) -> usize {
    let dev: DeviceName = DEVICE.parse().unwrap();
    ctx.node()
        .service_builder(&dev.service_name(Channel::Notify))
        .event()
        .open()
        .unwrap()
        .dynamic_config()
        .number_of_listeners()
}

/// Waits for `n` new states, each within `T`.
fn wait_states(arm: &mut ActArrayClient, n: usize) {
    let mut last = arm.state().map_or(0, |s| s.header.seq);
    for _ in 0..n {
        let seq = arm.wait_state(T).unwrap().header.seq;
        assert!(seq > last, "wait_state returned an old state");
        last = seq;
    }
}

#[test]
fn a_client_waiting_for_states_sleeps_on_the_wake_word_not_on_the_event() {
    let domain = Domain::unique_for_test();
    let stop = Arc::new(AtomicBool::new(false));
    let driver = driver_thread(&domain, &stop);
    let cctx = Context::new(&domain, Role::Client, "wake-clients").unwrap();
    let mut arm = ActArrayClient::connect_timeout(&cctx, DEVICE, T).unwrap();
    wait_states(&mut arm, 50);
    // Old code: 1 (the client blocked on a listener of its own).
    assert_eq!(notify_listeners(&cctx), 0);

    // A driver that starts again opens the same word: the client keeps sleeping on it.
    stop.store(true, Ordering::SeqCst);
    driver.join().unwrap();
    stop.store(false, Ordering::SeqCst);
    let driver = driver_thread(&domain, &stop);
    assert_eq!(arm.driver_status(), DriverStatus::Alive);
    wait_states(&mut arm, 20);
    assert_eq!(notify_listeners(&cctx), 0);
    stop.store(true, Ordering::SeqCst);
    driver.join().unwrap();
}

#[test]
fn a_wake_word_of_another_user_is_refused_and_its_clients_wait_on_the_event() {
    if rustix::process::geteuid().as_raw() != 0 {
        eprintln!("skipped: making a file of another user needs root");
        return;
    }
    let domain = Domain::unique_for_test();
    let path = domain.wake_word_path(&DEVICE.parse().unwrap()).unwrap();
    // Another user's file where the word would be, open to anybody.
    let f = std::fs::OpenOptions::new()
        .write(true)
        .create_new(true)
        .mode(0o666)
        .open(&path)
        .unwrap();
    f.set_len(4096).unwrap();
    std::os::unix::fs::fchown(&f, Some(65534), Some(65534)).unwrap();
    drop(f);
    std::fs::set_permissions(&path, std::os::unix::fs::PermissionsExt::from_mode(0o666)).unwrap();

    let stop = Arc::new(AtomicBool::new(false));
    let driver = driver_thread(&domain, &stop);
    let cctx = Context::new(&domain, Role::Client, "wake-clients").unwrap();
    let mut arm = ActArrayClient::connect_timeout(&cctx, DEVICE, T).unwrap();
    // Neither the driver nor the client uses it; the client waits on the event.
    wait_states(&mut arm, 20);
    assert_eq!(notify_listeners(&cctx), 1);
    let md = std::fs::metadata(&path).unwrap();
    assert_eq!(md.uid(), 65534);
    let untouched = std::fs::read(&path).unwrap();
    assert!(
        untouched.iter().all(|&b| b == 0),
        "the foreign file was written"
    );
    stop.store(true, Ordering::SeqCst);
    driver.join().unwrap();
    std::fs::remove_file(&path).unwrap();
}
