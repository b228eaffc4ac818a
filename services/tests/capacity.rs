//! How many clients a device admits: the driver's capacity (default
//! [`qos::DEFAULT_MAX_CLIENTS`], configurable), a clear refusal when it is full, and the
//! slots kept for priority clients (the owner's control program).

use limber_services::prelude::*;
use limber_services::qos::{self, Capacity};
use limber_services::testing::TestDriver;
use limber_services::{ActArrayClient, ConnectError};

const ARM: &str = "cap/actarray/0";

fn connect_many(ctx: &Context, n: usize) -> Vec<ActArrayClient> {
    (0..n)
        .map(|i| {
            ActArrayClient::connect(ctx, ARM)
                .unwrap_or_else(|e| panic!("client {} of {n} must connect: {e}", i + 1))
        })
        .collect()
}

#[test]
fn a_full_device_refuses_clearly_and_still_admits_priority_clients() {
    let domain = Domain::unique_for_test();
    let dctx = Context::new(&domain, Role::Driver, "cap").unwrap();
    let mut driver = TestDriver::new(&dctx, "cap", 2).unwrap();
    let ctx = Context::new(&domain, Role::Client, "ordinary").unwrap();
    ctx.set_priority(false);
    // More than the 32 of old: the default is enough for a robot PC.
    let mut clients = connect_many(&ctx, qos::DEFAULT_MAX_CLIENTS);
    let err = ActArrayClient::connect(&ctx, ARM).unwrap_err();
    assert_eq!(
        err,
        ConnectError::Full {
            device: ARM.into(),
            max: qos::DEFAULT_MAX_CLIENTS,
            reserved: qos::RESERVED_CLIENTS,
            priority: false,
        }
    );
    let text = err.to_string();
    for needle in [
        ARM,
        "is full",
        "64 clients",
        "--max-clients",
        "LIMBER_PRIORITY=1",
    ] {
        assert!(text.contains(needle), "{needle:?} not in {text:?}");
    }

    // The owner's control program gets in, into the reserved slots.
    let owner = Context::new(&domain, Role::Client, "owner").unwrap();
    owner.set_priority(true);
    let mut priority = connect_many(&owner, qos::RESERVED_CLIENTS);
    driver.publish_all().unwrap();
    priority[0]
        .current(std::time::Duration::from_secs(5))
        .expect("a priority client reads the state");
    // Beyond them, a priority client is refused as clearly.
    let err = ActArrayClient::connect(&owner, ARM).unwrap_err();
    assert!(
        matches!(err, ConnectError::Full { priority: true, .. }),
        "{err}"
    );
    assert!(
        err.to_string().contains("priority clients at once"),
        "{err}"
    );

    // An ordinary slot that frees up is taken again (priority clients count too: an
    // ordinary client never leaves fewer than the reserved slots free).
    priority.clear();
    clients.pop();
    clients.push(ActArrayClient::connect(&ctx, ARM).expect("a freed slot is taken"));
}

#[test]
fn the_driver_sets_the_capacity_and_publishes_it() {
    let domain = Domain::unique_for_test();
    let dctx = Context::new(&domain, Role::Driver, "cap").unwrap();
    dctx.set_capacity(Capacity::new(3).unwrap());
    let _driver = TestDriver::new(&dctx, "cap", 2).unwrap();
    let ctx = Context::new(&domain, Role::Client, "ordinary").unwrap();
    ctx.set_priority(false);
    let _clients = connect_many(&ctx, 3);
    let err = ActArrayClient::connect(&ctx, ARM).unwrap_err();
    assert!(
        matches!(
            err,
            ConnectError::Full {
                max: 3,
                priority: false,
                ..
            }
        ),
        "{err}"
    );
    assert!(err.to_string().contains("admits 3 clients"), "{err}");
    assert!(Capacity::new(0).is_err());
    assert!(Capacity::new(qos::MAX_CLIENTS_LIMIT + 1).is_err());
}
