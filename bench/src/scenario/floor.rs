//! `floor`: raw iceoryx2 between two processes, with the payloads of the command path
//! (a 296 B `ActArrayCmdMsg` out, a 1376 B `ActArrayData` back), no limber-services.
//!
//! * spin: both sides busy-poll `receive()`; the floor of the driver's `--spin` mode.
//! * spin, limber's shape (`spin2`): the same, but the echo publishes a state sample on a
//!   third topic before each reply, and the pinger takes it, as a driver publishes the
//!   state that shows a command before its outcome; and the topics are sized as a
//!   device's (`limber_services::qos`: a client slot for each of the default capacity's
//!   ports, the command and state buffers): the floor of the spinning command path's
//!   design, where the plain `spin` floor is iceoryx2 at its smallest (1 port a side).
//!   Like the driver, the echo loans each next sample once one is sent, off the path to
//!   the reply: back to back, that work delays the next ping instead (the one-way
//!   ping→echo pays for it, the round trip does not change); and like a spinning client,
//!   the pinger loans its next ping's sample once one is sent, so that its clock is read
//!   where a client's is, before the send alone (paced, the first touches of the
//!   publisher's memory after an idle millisecond fall after the stamp, as a client's do).
//!   Measured on this VM: the second send adds some 25 % to the round trip, the sizes
//!   some 15 % (iceoryx2's receive looks at every publisher slot).
//! * blocking (`event`): each message is followed by a `notify()` on an event service and
//!   the other side blocks in `Listener::timed_wait`; the floor of the event-driven mode.
//! * blocking (`waitset`): the same, but the echo blocks in a WaitSet with its listener
//!   attached (as a driver's `event_loop::run` does) while the pinger blocks in
//!   `Listener::timed_wait` (as a client does): separates the WaitSet's cost from the
//!   services layer's.
//!
//! Round trip is measured by the pinging parent; one-way ping→echo by the echo child
//! (the parent's `CLOCK_MONOTONIC` stamp in `meta.stamp_ns` against its clock on
//! receipt), one-way echo→ping by the parent (the echo's stamp in `header.stamp_ns`).

use std::time::{Duration, Instant};

use iceoryx2::port::listener::{Listener, ListenerWaitError};
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use iceoryx2::service::port_factory::publish_subscribe::PortFactory as PsFactory;
use limber_interfaces::prelude::*;
use limber_services::{monotonic_ns, qos};

use super::{Pace, READY_TIMEOUT, RunCtx, SAMPLE_TIMEOUT, Scenario, physical};
use crate::child::{ChildProc, ChildSpec, read_histogram};
use crate::progress::Progress;
use crate::roles;
use crate::stats::{Measurement, Metric, Strategy, new_histogram};
use crate::{BenchArgs, BenchError};

/// `meta.kind` of the message that stops an echo.
pub const STOP_KIND: u32 = u32::MAX;
/// Command and state sizes, bytes.
pub const BYTES: (usize, usize) = (
    core::mem::size_of::<ActArrayCmdMsg>(),
    core::mem::size_of::<ActArrayData>(),
);

/// The `floor` scenario.
#[derive(Debug, Clone, Copy)]
pub struct Floor;

impl Scenario for Floor {
    fn name(&self) -> &'static str {
        "floor"
    }
    fn description(&self) -> &'static str {
        "the floors, 2 processes: a futex and a spinning cache-line ping-pong in shared memory (no middleware), and raw iceoryx2, 296 B out / 1376 B back: spinning, and event wake-up (notify -> blocking listener, or WaitSet on the echo side)"
    }
    fn run(&self, ctx: &mut RunCtx) -> Result<(), BenchError> {
        if ctx.spin_enabled() {
            physical::ping_pong(ctx, physical::Wait::Spin, Pace::BackToBack)?;
            ping_pong(ctx, Echo::Spin, Pace::BackToBack)?;
            ping_pong(ctx, Echo::SpinState, Pace::BackToBack)?;
        }
        if ctx.blocking_enabled() {
            physical::ping_pong(ctx, physical::Wait::Futex, Pace::BackToBack)?;
            ping_pong(ctx, Echo::Listener, Pace::BackToBack)?;
            ping_pong(ctx, Echo::WaitSet, Pace::BackToBack)?;
        }
        Ok(())
    }
}

/// How the echo side waits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Echo {
    /// Busy-polls `receive()` (the pinger spins too).
    Spin,
    /// Busy-polls, and publishes a state sample before each reply (the pinger takes it).
    SpinState,
    /// Blocks in `Listener::timed_wait` (the pinger too).
    Listener,
    /// Blocks in a WaitSet with the listener attached, like a driver's event loop (the
    /// pinger blocks in `Listener::timed_wait`, like a client).
    WaitSet,
}

impl Echo {
    fn key(self) -> &'static str {
        match self {
            Echo::Spin => "spin",
            Echo::SpinState => "spin2",
            Echo::Listener => "event",
            Echo::WaitSet => "waitset",
        }
    }
    /// The child role.
    pub fn role(self) -> &'static str {
        match self {
            Echo::Spin => "pubsub-echo",
            Echo::SpinState => "pubsub-state-echo",
            Echo::Listener => "event-echo",
            Echo::WaitSet => "waitset-echo",
        }
    }

    fn spins(self) -> bool {
        matches!(self, Echo::Spin | Echo::SpinState)
    }
}

type Ping = Publisher<ipc::Service, ActArrayCmdMsg, ()>;
/// A ping's sample, loaned ahead.
type PingLoan = iceoryx2::sample_mut_uninit::SampleMutUninit<
    ipc::Service,
    core::mem::MaybeUninit<ActArrayCmdMsg>,
    (),
>;
type Pong = Subscriber<ipc::Service, ActArrayData, ()>;

struct Services {
    a2b: PsFactory<ipc::Service, ActArrayCmdMsg, ()>,
    b2a: PsFactory<ipc::Service, ActArrayData, ()>,
    /// The echo's state samples (`Echo::SpinState` only).
    state: Option<PsFactory<ipc::Service, ActArrayData, ()>>,
    ev_a2b: iceoryx2::service::port_factory::event::PortFactory<ipc::Service>,
    ev_b2a: iceoryx2::service::port_factory::event::PortFactory<ipc::Service>,
}

/// The sizes of the command and reply topics: iceoryx2's smallest, or a device's
/// (`Echo::SpinState`).
struct Sizes {
    /// Publishers of commands, subscribers of replies (and of states).
    clients: usize,
    cmd_buffer: usize,
    /// The subscriber's borrow limit (`None`: iceoryx2's default, as the plain floors).
    cmd_borrowed: Option<usize>,
    cmd_subscribers: usize,
    reply_buffer: usize,
}

impl Sizes {
    fn of(echo: Echo) -> Self {
        match echo {
            Echo::SpinState => Sizes {
                clients: qos::Capacity::default().ports(),
                cmd_buffer: qos::CMD_BUFFER,
                cmd_borrowed: Some(qos::CMD_BORROWED),
                cmd_subscribers: qos::CMD_SUBSCRIBERS,
                reply_buffer: qos::TOLD_BUFFER,
            },
            _ => Sizes {
                clients: 1,
                cmd_buffer: 4,
                cmd_borrowed: None,
                cmd_subscribers: 1,
                reply_buffer: 4,
            },
        }
    }
}

fn services(node: &Node<ipc::Service>, echo: Echo) -> Result<Services, BenchError> {
    let tag = format!("floor-{}", echo.key());
    let z = Sizes::of(echo);
    let name = |ch: &str| -> Result<ServiceName, BenchError> {
        ServiceName::new(&format!("limber-bench/{tag}/{ch}"))
            .map_err(|e| BenchError::transport("service name", e))
    };
    let mut a2b = node
        .service_builder(&name("a2b")?)
        .publish_subscribe::<ActArrayCmdMsg>()
        .max_publishers(z.clients)
        .max_subscribers(z.cmd_subscribers)
        .history_size(0)
        .subscriber_max_buffer_size(z.cmd_buffer);
    if let Some(n) = z.cmd_borrowed {
        a2b = a2b.subscriber_max_borrowed_samples(n);
    }
    let a2b = a2b
        .open_or_create()
        .map_err(|e| BenchError::transport("floor a2b service", e))?;
    let b2a = node
        .service_builder(&name("b2a")?)
        .publish_subscribe::<ActArrayData>()
        .max_publishers(1)
        .max_subscribers(z.clients)
        .history_size(0)
        .subscriber_max_buffer_size(z.reply_buffer)
        .open_or_create()
        .map_err(|e| BenchError::transport("floor b2a service", e))?;
    // The state topic as a device's `data` channel.
    let state = match echo {
        Echo::SpinState => Some(
            node.service_builder(&name("state")?)
                .publish_subscribe::<ActArrayData>()
                .max_publishers(qos::DATA_PUBLISHERS)
                .max_subscribers(z.clients)
                .history_size(1)
                .subscriber_max_buffer_size(qos::DATA_BUFFER)
                .open_or_create()
                .map_err(|e| BenchError::transport("floor state service", e))?,
        ),
        _ => None,
    };
    let ev_a2b = node
        .service_builder(&name("ev_a2b")?)
        .event()
        .open_or_create()
        .map_err(|e| BenchError::transport("floor ev_a2b service", e))?;
    let ev_b2a = node
        .service_builder(&name("ev_b2a")?)
        .event()
        .open_or_create()
        .map_err(|e| BenchError::transport("floor ev_b2a service", e))?;
    Ok(Services {
        a2b,
        b2a,
        state,
        ev_a2b,
        ev_b2a,
    })
}

/// Sends ping `seq` in `loan`, or in a sample loaned now.
fn send_ping(p: &Ping, seq: u64, kind: u32, loan: Option<PingLoan>) -> Result<(), BenchError> {
    let loan = match loan {
        Some(l) => l,
        None => p
            .loan_uninit()
            .map_err(|e| BenchError::transport("loan ping", e))?,
    };
    let mut s = loan.write_payload(ActArrayCmdMsg::default());
    let m = &mut s.payload_mut().meta;
    m.seq = seq;
    m.kind = kind;
    m.stamp_ns = monotonic_ns();
    s.send()
        .map_err(|e| BenchError::transport("send ping", e))?;
    Ok(())
}

/// Waits for the pong of `seq`: returns (receipt time, the echo's stamp).
fn recv_pong(
    sub: &Pong,
    states: Option<&Pong>,
    listener: Option<&Listener<ipc::Service>>,
    seq: u64,
    timeout: Duration,
) -> Result<(u64, u64), BenchError> {
    let mut spins = 0u32;
    let mut deadline: Option<Instant> = None;
    loop {
        if let Some(states) = states {
            while states
                .receive()
                .map_err(|e| BenchError::transport("receive state", e))?
                .is_some()
            {}
        }
        while let Some(s) = sub
            .receive()
            .map_err(|e| BenchError::transport("receive pong", e))?
        {
            let t1 = monotonic_ns();
            if s.header.seq == seq {
                return Ok((t1, s.header.stamp_ns));
            }
        }
        match listener {
            Some(l) => {
                let d = *deadline.get_or_insert_with(|| Instant::now() + timeout);
                let left = d.saturating_duration_since(Instant::now());
                // Under a microsecond iceoryx2's socket timeout is zero, which blocks for good.
                if left < Duration::from_micros(1) {
                    return Err(BenchError::Timeout {
                        what: format!("floor pong {seq}"),
                        timeout,
                    });
                }
                wait_through_signals(l, left, "wait for pong")?;
            }
            None => {
                spins = spins.wrapping_add(1);
                if spins & 0x3fff == 0 {
                    let d = *deadline.get_or_insert_with(|| Instant::now() + timeout);
                    if Instant::now() >= d {
                        return Err(BenchError::Timeout {
                            what: format!("floor pong {seq}"),
                            timeout,
                        });
                    }
                }
                core::hint::spin_loop();
            }
        }
    }
}

fn notify(n: Option<&Notifier<ipc::Service>>) -> Result<(), BenchError> {
    if let Some(n) = n {
        n.notify().map_err(|e| BenchError::transport("notify", e))?;
    }
    Ok(())
}

/// Sends ping 0 until its pong arrives: both sides are connected afterwards.
fn sync(
    p: &Ping,
    sub: &Pong,
    notifier: Option<&Notifier<ipc::Service>>,
    listener: Option<&Listener<ipc::Service>>,
) -> Result<(), BenchError> {
    let deadline = Instant::now() + READY_TIMEOUT;
    loop {
        send_ping(p, 0, 0, None)?;
        notify(notifier)?;
        match recv_pong(sub, None, listener, 0, Duration::from_millis(10)) {
            Ok(_) => return Ok(()),
            Err(BenchError::Timeout { .. }) if Instant::now() < deadline => {}
            Err(e) => return Err(e),
        }
    }
}

/// Runs the raw iceoryx2 floor with `echo`, spaced as `pace` says, and adds its three
/// measurements.
pub fn ping_pong(ctx: &mut RunCtx, echo: Echo, pace: Pace) -> Result<(), BenchError> {
    let event = !echo.spins();
    let domain = ctx.domain();
    let node = roles::raw_node(&domain)?;
    let tag = format!("floor-{}", echo.key());
    let tag = tag.as_str();
    let svc = services(&node, echo)?;
    let publisher = svc
        .a2b
        .publisher_builder()
        .create()
        .map_err(|e| BenchError::transport("floor publisher", e))?;
    let subscriber = svc
        .b2a
        .subscriber_builder()
        .create()
        .map_err(|e| BenchError::transport("floor subscriber", e))?;
    let states = svc
        .state
        .as_ref()
        .map(|f| f.subscriber_builder().create())
        .transpose()
        .map_err(|e| BenchError::transport("floor state subscriber", e))?;
    let (notifier, listener) = if event {
        (
            Some(
                svc.ev_a2b
                    .notifier_builder()
                    .create()
                    .map_err(|e| BenchError::transport("floor notifier", e))?,
            ),
            Some(
                svc.ev_b2a
                    .listener_builder()
                    .create()
                    .map_err(|e| BenchError::transport("floor listener", e))?,
            ),
        )
    } else {
        (None, None)
    };
    let (warm, n) = if event {
        pace.counts(ctx, ((500, 100), (5_000, 1_000)))
    } else {
        pace.counts(ctx, ((5_000, 1_000), (100_000, 10_000)))
    };
    let out = ctx.tmp_file(&format!("{tag}.hdr"));
    let mut child = ChildProc::spawn(&ChildSpec {
        role: echo.role().into(),
        domain: Some(domain.name().to_string()),
        out: Some(out.clone()),
        cpu: ctx.child_cpu(),
        warmup: warm,
        deadline: pace.deadline(ctx, warm + n, Duration::from_micros(100)),
        ..Default::default()
    })?;
    child.expect("ready", READY_TIMEOUT)?;
    sync(
        &publisher,
        &subscriber,
        notifier.as_ref(),
        listener.as_ref(),
    )?;

    let mut rtt = new_histogram()?;
    let mut back = new_histogram()?;
    let label = format!("{} {}{}", pace.scenario(), echo.key(), pace.label());
    let progress = Progress::new(ctx.progress, &label, warm + n);
    let start = Instant::now();
    let mut ping_loan = None;
    for seq in 1..=warm + n {
        pace.wait_turn(start, seq);
        let t0 = monotonic_ns();
        send_ping(&publisher, seq, 0, ping_loan.take())?;
        notify(notifier.as_ref())?;
        // In the command path's shape the pinger, as a spinning client does, loans its
        // next ping's sample once one is sent, while the echo answers.
        if echo == Echo::SpinState {
            ping_loan = Some(
                publisher
                    .loan_uninit()
                    .map_err(|e| BenchError::transport("loan ping", e))?,
            );
        }
        let (t1, stamp) = recv_pong(
            &subscriber,
            states.as_ref(),
            listener.as_ref(),
            seq,
            SAMPLE_TIMEOUT,
        )?;
        if seq > warm {
            rtt.saturating_record(t1.saturating_sub(t0));
            back.saturating_record(t1.saturating_sub(stamp));
        }
        progress.tick(seq);
    }
    progress.finish();
    send_ping(&publisher, warm + n + 1, STOP_KIND, ping_loan.take())?;
    notify(notifier.as_ref())?;
    child.finish(Duration::from_secs(10))?;
    let oneway = read_histogram(&out)?;

    let strategy = if event {
        Strategy::Blocking
    } else {
        Strategy::Spin
    };
    let key = echo.key();
    let via = match echo {
        Echo::WaitSet => ", echo in WaitSet",
        Echo::SpinState => ", limber's shape (a state sample before each reply, a device's sizes)",
        _ => "",
    };
    let via = format!("{via}{}", pace.label());
    ctx.push(Measurement {
        scenario: pace.scenario(),
        id: pace.id(key, "rtt"),
        label: format!("iceoryx2 ping-pong{via}"),
        strategy,
        metric: Metric::RoundTrip,
        bytes: Some(BYTES),
        hist: rtt,
    });
    ctx.push(Measurement {
        scenario: pace.scenario(),
        id: pace.id(key, "oneway"),
        label: format!("iceoryx2 ping→echo{via}"),
        strategy,
        metric: Metric::OneWay,
        bytes: Some(BYTES),
        hist: oneway,
    });
    ctx.push(Measurement {
        scenario: pace.scenario(),
        id: pace.id(key, "back"),
        label: format!("iceoryx2 echo→ping{via}"),
        strategy,
        metric: Metric::OneWay,
        bytes: Some(BYTES),
        hist: back,
    });
    Ok(())
}

/// The echo child (`pubsub-echo`, `pubsub-state-echo`, `event-echo`, `waitset-echo`).
pub fn echo_role(args: &BenchArgs, echo: Echo) -> Result<(), BenchError> {
    let event = !echo.spins();
    let domain = roles::child_domain(args)?;
    let deadline = roles::child_deadline(args);
    let node = roles::raw_node(&domain)?;
    let svc = services(&node, echo)?;
    let sub = svc
        .a2b
        .subscriber_builder()
        .create()
        .map_err(|e| BenchError::transport("echo subscriber", e))?;
    let publisher = svc
        .b2a
        .publisher_builder()
        .create()
        .map_err(|e| BenchError::transport("echo publisher", e))?;
    let state_pub = svc
        .state
        .as_ref()
        .map(|f| f.publisher_builder().create())
        .transpose()
        .map_err(|e| BenchError::transport("echo state publisher", e))?;
    let (listener, notifier) = if event {
        (
            Some(
                svc.ev_a2b
                    .listener_builder()
                    .create()
                    .map_err(|e| BenchError::transport("echo listener", e))?,
            ),
            Some(
                svc.ev_b2a
                    .notifier_builder()
                    .create()
                    .map_err(|e| BenchError::transport("echo notifier", e))?,
            ),
        )
    } else {
        (None, None)
    };
    let mut oneway = new_histogram()?;
    let waitset = if echo == Echo::WaitSet {
        Some(
            WaitSetBuilder::new()
                .create::<ipc::Service>()
                .map_err(|e| BenchError::transport("echo waitset", e))?,
        )
    } else {
        None
    };
    let guard = match (&waitset, &listener) {
        (Some(ws), Some(l)) => Some(
            ws.attach_notification(l)
                .map_err(|e| BenchError::transport("echo waitset attach", e))?,
        ),
        _ => None,
    };
    let (mut state_loan, mut reply_loan) = (None, None);
    roles::announce("ready");
    let mut spins = 0u32;
    loop {
        while let Some(s) = sub
            .receive()
            .map_err(|e| BenchError::transport("echo receive", e))?
        {
            let now = monotonic_ns();
            let meta = s.meta;
            drop(s);
            if meta.kind == STOP_KIND {
                return roles::write_histogram(args, &oneway);
            }
            if meta.seq > args.warmup {
                oneway.saturating_record(now.saturating_sub(meta.stamp_ns));
            }
            // Limber's shape loans each next sample as soon as one is sent, off the path
            // to the reply (as the driver does); the plain floor loans on the path.
            if let Some(p) = &state_pub {
                let loan = match state_loan.take() {
                    Some(l) => l,
                    None => p
                        .loan_uninit()
                        .map_err(|e| BenchError::transport("echo state loan", e))?,
                };
                let mut st = loan.write_payload(ActArrayData::default());
                st.payload_mut().header.seq = meta.seq;
                st.send()
                    .map_err(|e| BenchError::transport("echo state send", e))?;
            }
            let loan = match reply_loan.take() {
                Some(l) => l,
                None => publisher
                    .loan_uninit()
                    .map_err(|e| BenchError::transport("echo loan", e))?,
            };
            let mut r = loan.write_payload(ActArrayData::default());
            let h = &mut r.payload_mut().header;
            h.seq = meta.seq;
            h.stamp_ns = monotonic_ns();
            r.send()
                .map_err(|e| BenchError::transport("echo send", e))?;
            if let Some(p) = &state_pub {
                state_loan = Some(
                    p.loan_uninit()
                        .map_err(|e| BenchError::transport("echo state loan", e))?,
                );
                reply_loan = Some(
                    publisher
                        .loan_uninit()
                        .map_err(|e| BenchError::transport("echo loan", e))?,
                );
            }
            notify(notifier.as_ref())?;
        }
        match &listener {
            Some(l) => {
                match (&waitset, &guard) {
                    (Some(ws), Some(g)) => {
                        ws.wait_and_process_once_with_timeout(
                            |id| {
                                if id.has_event_from(g)
                                    && let Err(e) = l.try_wait(|_| {})
                                {
                                    tracing::debug!("echo: consuming the wake-up: {e}");
                                }
                                CallbackProgression::Continue
                            },
                            Duration::from_millis(50),
                        )
                        .map_err(|e| BenchError::transport("echo waitset wait", e))?;
                    }
                    _ => {
                        wait_through_signals(l, Duration::from_millis(50), "echo wait")?;
                    }
                }
                if Instant::now() > deadline {
                    return Err(BenchError::Timeout {
                        what: "echo: the ping side stopped".into(),
                        timeout: Duration::from_millis(args.deadline_ms),
                    });
                }
            }
            None => {
                spins = spins.wrapping_add(1);
                if spins & 0xffff == 0 && Instant::now() > deadline {
                    return Err(BenchError::Timeout {
                        what: "echo: the ping side stopped".into(),
                        timeout: Duration::from_millis(args.deadline_ms),
                    });
                }
                core::hint::spin_loop();
            }
        }
    }
}

/// `l.timed_wait` for up to `d`, for a loop that looks again after it: a wait interrupted
/// by a signal (a stop and continue, Ctrl-Z and `fg`) is no failure.
fn wait_through_signals(
    l: &Listener<ipc::Service>,
    d: Duration,
    what: &'static str,
) -> Result<(), BenchError> {
    match l.timed_wait(|_| {}, d) {
        Ok(_) | Err(ListenerWaitError::InterruptSignal) => Ok(()),
        Err(e) => Err(BenchError::transport(what, e)),
    }
}
