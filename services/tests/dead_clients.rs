//! A driver's housekeeping after its clients (`DeviceHost::cleanup_dead`, once a second in
//! every driver): it looks at iceoryx2's registries of the device's ports and asks each
//! client's process whether it lives, and cleans up (iceoryx2's look at every node's
//! files, 1 ms with 64 clients and up to 15 ms on the project's VM, inside the driver's
//! loop) only when one is gone, or a minute after the last time. A client killed after
//! that look is still cleaned up at the next call, not a minute later.

use std::time::Duration;

use limber_interfaces::prelude::*;
use limber_services::list_devices;
use limber_services::prelude::*;

const CHILD_ENV: &str = "LIMBER_TEST_DEAD_CLIENT_DOMAIN";
const DEVICE: &str = "dead/actarray/0";

/// Run by `a_client_killed_after_a_cleanup_is_cleaned_up_at_the_next` as a process of its
/// own (a no-op otherwise): a client of the parent's device, then waits to be killed.
#[test]
fn dead_client_child() {
    let Ok(name) = std::env::var(CHILD_ENV) else {
        return;
    };
    let domain = Domain::new(&name).unwrap();
    let cctx = Context::new(&domain, Role::Client, "dead-client").unwrap();
    let _client = ActArrayClient::connect_timeout(&cctx, DEVICE, Duration::from_secs(10)).unwrap();
    println!("READY");
    let mut line = String::new();
    let _ = std::io::stdin().read_line(&mut line);
}

/// The processes attached to the device's state channel (the driver and its clients,
/// dead ones included until they are cleaned up).
fn nodes(domain: &Domain) -> usize {
    list_devices(domain)
        .unwrap()
        .into_iter()
        .find(|d| d.name.to_string() == DEVICE)
        .map_or(0, |d| d.nodes)
}

#[test]
fn a_client_killed_after_a_cleanup_is_cleaned_up_at_the_next() {
    let domain = Domain::unique_for_test();
    let ctx = Context::new(&domain, Role::Driver, "dead-driver").unwrap();
    let mut host = DeviceHost::<ActArray>::new(&ctx, &DEVICE.parse().unwrap(), "t").unwrap();
    host.publish().unwrap();
    let mut child = limber_services::testing::TestProcess::start(
        "dead_client_child",
        CHILD_ENV,
        domain.name(),
        "READY",
    )
    .child;
    host.publish().unwrap();
    assert_eq!(nodes(&domain), 2, "the driver and its client");
    // A client that lives is left alone (the first call looks at every node).
    host.cleanup_dead();
    host.cleanup_dead();
    assert_eq!(nodes(&domain), 2, "a live client was cleaned up");
    child.kill().unwrap();
    child.wait().unwrap();
    assert_eq!(nodes(&domain), 2, "dead, not cleaned up yet");
    // The next housekeeping finds its process gone and cleans up after it.
    host.cleanup_dead();
    assert_eq!(nodes(&domain), 1, "the killed client's node is still there");
    host.publish().unwrap();
}
