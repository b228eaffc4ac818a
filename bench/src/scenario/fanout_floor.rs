//! The floor of the `state` scenario's fan-out, raw iceoryx2 without limber-services: the
//! bench process publishes the 1376 B `ActArrayData` at 1 kHz (stamped just before `send`)
//! and then notifies one event service, as a driver does; 1, 4 or 16 subscriber processes
//! each block in `Listener::timed_wait` and take the sample. What one publication and the
//! wake-ups of N listeners cost iceoryx2 itself (`state.raw.<N>.oneway`, merged over the
//! subscribers as `state.<N>.oneway` is): the floor the `state` fan-out is compared with.

use std::time::{Duration, Instant};

use iceoryx2::port::listener::ListenerWaitError;
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::event::PortFactory as EventFactory;
use iceoryx2::service::port_factory::publish_subscribe::PortFactory as PsFactory;
use limber_interfaces::prelude::*;
use limber_services::monotonic_ns;

use super::state::{FANOUTS, PERIOD, STOP_MARK, Subscribers};
use super::{Pace, RunCtx};
use crate::roles;
use crate::stats::new_histogram;
use crate::{BenchArgs, BenchError};

/// The child role of a raw subscriber.
pub const ROLE: &str = "fanout-sub";

/// The raw services: the state samples and the wake-up event.
type Services = (
    PsFactory<ipc::Service, ActArrayData, ()>,
    EventFactory<ipc::Service>,
);

/// Opens (or creates) the raw services.
fn services(node: &Node<ipc::Service>) -> Result<Services, BenchError> {
    let name = |ch: &str| -> Result<ServiceName, BenchError> {
        ServiceName::new(&format!("limber-bench/fanout/{ch}"))
            .map_err(|e| BenchError::transport("service name", e))
    };
    let most = FANOUTS.iter().copied().max().unwrap_or(1);
    let data = node
        .service_builder(&name("data")?)
        .publish_subscribe::<ActArrayData>()
        .max_publishers(1)
        .max_subscribers(most)
        .history_size(0)
        .subscriber_max_buffer_size(4)
        .open_or_create()
        .map_err(|e| BenchError::transport("fan-out floor data service", e))?;
    let wake = node
        .service_builder(&name("wake")?)
        .event()
        .max_listeners(most)
        .open_or_create()
        .map_err(|e| BenchError::transport("fan-out floor event service", e))?;
    Ok((data, wake))
}

/// Runs the raw fan-out to `fan` subscriber processes and adds `state.raw.<fan>.oneway`.
pub fn fanout(ctx: &mut RunCtx, fan: usize) -> Result<(), BenchError> {
    let domain = ctx.domain();
    let node = roles::raw_node(&domain)?;
    let (data, wake) = services(&node)?;
    let publisher = data
        .publisher_builder()
        .create()
        .map_err(|e| BenchError::transport("fan-out floor publisher", e))?;
    let notifier = wake
        .notifier_builder()
        .create()
        .map_err(|e| BenchError::transport("fan-out floor notifier", e))?;
    let pace = Pace::Paced {
        period: PERIOD,
        scenario: "state",
        beside: None,
        turns: 1,
    };
    let (warm, n) = pace.counts(ctx, ((0, 0), (0, 0)));
    let deadline = pace.deadline(ctx, warm + n, PERIOD);
    let mut subs = Subscribers::spawn(ctx, &domain, ROLE, fan, warm, deadline, None)?;
    let publish = |seq: u64, mark: u32| -> Result<(), BenchError> {
        let loan = publisher
            .loan_uninit()
            .map_err(|e| BenchError::transport("fan-out floor loan", e))?;
        let mut s = loan.write_payload(ActArrayData::default());
        let d = s.payload_mut();
        d.motor_state = mark;
        d.header.seq = seq;
        d.header.stamp_ns = monotonic_ns();
        s.send()
            .map_err(|e| BenchError::transport("fan-out floor send", e))?;
        notifier
            .notify()
            .map_err(|e| BenchError::transport("fan-out floor notify", e))?;
        Ok(())
    };
    let start = Instant::now();
    for seq in 1..=warm + n {
        pace.wait_turn(start, seq);
        publish(seq, 0)?;
    }
    // The stop sample, again until every subscriber has gone (one may be between a wait
    // and its next receive).
    let until = Instant::now() + deadline;
    while !subs.all_exited() && Instant::now() < until {
        publish(warm + n + 1, STOP_MARK)?;
        std::thread::sleep(Duration::from_millis(10));
    }
    subs.merge_into(
        ctx,
        format!("state.raw.{fan}.oneway"),
        format!("iceoryx2 → {fan} listener(s), 1 kHz"),
    )
}

/// The raw subscriber child (`fanout-sub`): blocks on the event, takes every sample, and
/// records each one's age after the warm-up until the stop sample.
pub fn subscriber_role(args: &BenchArgs) -> Result<(), BenchError> {
    let domain = roles::child_domain(args)?;
    let deadline = roles::child_deadline(args);
    let node = roles::raw_node(&domain)?;
    let (data, wake) = services(&node)?;
    let subscriber = data
        .subscriber_builder()
        .create()
        .map_err(|e| BenchError::transport("fan-out floor subscriber", e))?;
    let listener = wake
        .listener_builder()
        .create()
        .map_err(|e| BenchError::transport("fan-out floor listener", e))?;
    let mut oneway = new_histogram()?;
    roles::announce("ready");
    loop {
        while let Some(s) = subscriber
            .receive()
            .map_err(|e| BenchError::transport("fan-out floor receive", e))?
        {
            let now = monotonic_ns();
            if s.motor_state == STOP_MARK {
                return roles::write_histogram(args, &oneway);
            }
            if s.header.seq > args.warmup {
                oneway.saturating_record(now.saturating_sub(s.header.stamp_ns));
            }
        }
        match listener.timed_wait(|_| {}, Duration::from_millis(50)) {
            Ok(_) | Err(ListenerWaitError::InterruptSignal) => {}
            Err(e) => return Err(BenchError::transport("fan-out floor wait", e)),
        }
        if Instant::now() > deadline {
            return Err(BenchError::Timeout {
                what: "fan-out floor: the publisher stopped".into(),
                timeout: Duration::from_millis(args.deadline_ms),
            });
        }
    }
}
