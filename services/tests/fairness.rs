//! The driver takes the commands of its clients fairly: a client that floods the device
//! neither holds the driver's loop nor puts its commands before another client's.
//!
//! The transport hands out the samples of its first connection that has data first; the
//! driver that drained sample by sample carried out every queued command of one client
//! before any of the next (the CLI, under a flood, waited past its timeout for a command
//! the driver had not yet taken: `limber-cli::ownership`'s contention test).

use std::time::Duration;

use limber_interfaces::prelude::*;
use limber_services::prelude::*;
use limber_services::testing::TestArm;

const T: Duration = Duration::from_secs(5);
const DEVICE: &str = "fair/actarray/0";

/// A [`TestArm`] that records whose command it carried out, in order.
struct Recording {
    arm: TestArm,
    from: Vec<u64>,
}

impl DeviceHandler<ActArray> for Recording {
    fn command(
        &mut self,
        cmd: &ActArrayCommand,
        from: &Origin,
        state: &mut ActArrayData,
    ) -> Status {
        self.from.push(from.client_id);
        self.arm.command(cmd, from, state)
    }

    fn request(
        &mut self,
        req: &ActArrayRequest,
        from: &Origin,
        state: &mut ActArrayData,
    ) -> Result<ActArrayReply, Status> {
        self.arm.request(req, from, state)
    }
}

#[test]
fn every_client_is_served_in_rounds_and_one_call_takes_a_bounded_number() {
    let domain = Domain::unique_for_test();
    let ctx = Context::new(&domain, Role::Driver, "fair").unwrap();
    let mut host = DeviceHost::<ActArray>::new(&ctx, &DEVICE.parse().unwrap(), "t").unwrap();
    host.state_mut().actuators_count = 2;
    host.publish().unwrap();
    let mut handler = Recording {
        arm: TestArm::new(2),
        from: Vec::new(),
    };
    let cctx = Context::new(&domain, Role::Client, "fair-clients").unwrap();
    let mut flood = ActArrayClient::connect_timeout(&cctx, DEVICE, T).unwrap();
    let mut other = ActArrayClient::connect_timeout(&cctx, DEVICE, T).unwrap();
    // The flood fills its whole buffer; the other client sends a few.
    let flood_sent = limber_services::qos::CMD_BUFFER;
    for i in 0..flood_sent {
        flood.move_to(0, (i % 10) as f64 * 0.01).unwrap();
    }
    for _ in 0..3 {
        other.move_to(1, 0.1).unwrap();
    }
    let first = host.process(&mut handler).unwrap();
    assert!(
        first.commands <= limber_services::qos::CMD_BUFFER,
        "one call took {} commands",
        first.commands
    );
    // The other client's three come within the first three rounds, whoever connected
    // first: each round takes at most CMD_BORROWED of each client.
    let rounds = 3 * (limber_services::qos::CMD_BORROWED + 1);
    let early: Vec<_> = handler.from.iter().take(rounds).collect();
    let others = early.iter().filter(|&&&c| c == other.client_id()).count();
    assert_eq!(
        others,
        3,
        "the other client's commands came at {:?} of {}",
        handler
            .from
            .iter()
            .enumerate()
            .filter(|(_, c)| **c == other.client_id())
            .map(|(i, _)| i)
            .collect::<Vec<_>>(),
        handler.from.len()
    );
    // The rest is taken by the next calls, nothing lost.
    let mut total = first.commands;
    for _ in 0..4 {
        total += host.process(&mut handler).unwrap().commands;
    }
    assert_eq!(total, flood_sent + 3);
    assert_eq!(handler.from.len(), flood_sent + 3);
}

/// The bridge's mirror relays its local clients' commands the same way: in rounds.
#[test]
fn the_relay_takes_commands_in_rounds_too() {
    let domain = Domain::unique_for_test();
    let ctx = Context::new(&domain, Role::Driver, "fair-relay").unwrap();
    let mut host = DeviceHost::<ActArray>::new(&ctx, &DEVICE.parse().unwrap(), "t").unwrap();
    host.state_mut().actuators_count = 2;
    host.publish().unwrap();
    let cctx = Context::new(&domain, Role::Client, "fair-relay-clients").unwrap();
    let mut flood = ActArrayClient::connect_timeout(&cctx, DEVICE, T).unwrap();
    let mut other = ActArrayClient::connect_timeout(&cctx, DEVICE, T).unwrap();
    for _ in 0..100 {
        flood.move_to(0, 0.1).unwrap();
        other.move_to(1, 0.1).unwrap();
    }
    let mut from = Vec::new();
    let n = host
        .relay_commands(|raw| from.push(raw.meta.client_id))
        .unwrap();
    assert_eq!(n, 200);
    // Whoever connected first, the first round has the commands of both.
    let first_round = &from[..2 * limber_services::qos::CMD_BORROWED];
    for c in [flood.client_id(), other.client_id()] {
        assert!(
            first_round.contains(&c),
            "client {c} missing from the first round {first_round:?}"
        );
    }
}
