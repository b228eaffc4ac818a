//! `command`: a limber-services client sends an actarray POS command, a driver process
//! (`DeviceHost` with a handler that moves at once) receives it and publishes its
//! outcome, the client sees the outcome in the next state sample
//! (`Client::move_to` + `Client::wait_outcome`).
//!
//! * spin: the driver busy-polls `DeviceHost::process`; the client spins
//!   (`WaitMode::Spin`, no wake-up events): the driver's `--spin` mode.
//! * blocking: the driver waits in `event_loop::run` (WaitSet on the wake listener); the
//!   client blocks on the notify listener (`WaitMode::Event`, the default). Four variants
//!   show what the two spin-then-block budgets give:
//!   * `event`: the defaults, the client busy-polls for its answer for
//!     `qos::default_spin_budget()` after sending and the driver keeps polling for
//!     `qos::DRIVER_LINGER` after activity (`event_loop::linger`);
//!   * `event-block`: both zero: pure blocking, one wake-up per direction;
//!   * `event-cspin`: only the client's spin; `event-linger`: only the driver's linger.
//! * spin at 1 kHz (`command.paced.spin.*`): the spinning pair again, one command per
//!   millisecond from a client that sleeps between commands (a control loop's rate), beside
//!   raw iceoryx2 in the command path's shape at the same rate (`command.paced.spin2.*`).
//!   Back to back, the client's next command reaches a driver that is still finishing the
//!   previous one (the outcome on the client's stream and the next state sample's loan come
//!   after the state that shows the outcome): the back-to-back one-way measures that work
//!   as much as the path; at a control loop's rate the driver waits, polling, for each
//!   command, as it does in use.
//!
//! Round trip: client clock before `move_to` to after `wait_outcome`. One-way
//! client→driver: `MsgMeta.stamp_ns` (set in `Client::send`) against the driver's clock
//! on receipt (`Origin::received_ns`, read by the host as `receive` returns the sample),
//! where the floor's echo reads its clock too; the host's work before the handler
//! (releasing the sample, decoding, the lease check) is in the round trip. One-way driver→client: the outcome's stamp
//! (`Outcome::stamp_ns`, taken when the driver publishes it) against the client's clock
//! when `wait_outcome_detail` returned. (The state sample that follows the outcome is not
//! what the client waits for: its stamp may belong to the previous command.)

use std::ops::ControlFlow;
use std::time::{Duration, Instant};

use limber_interfaces::prelude::*;
use limber_services::event_loop;
use limber_services::prelude::*;
use limber_services::{Role, WaitMode, monotonic_ns};

use super::floor::BYTES;
use super::floor::Echo;
use super::{Pace, READY_TIMEOUT, RunCtx, SAMPLE_TIMEOUT, Scenario};
use crate::child::{ChildProc, ChildSpec, read_histogram};
use crate::progress::Progress;
use crate::roles;
use crate::stats::{Measurement, Metric, Strategy, new_histogram};
use crate::{BenchArgs, BenchError};

/// The device the benchmark driver offers.
pub const DEVICE: &str = "bench/actarray/0";

/// The `command` scenario.
#[derive(Debug, Clone, Copy)]
pub struct Command;

impl Scenario for Command {
    fn name(&self) -> &'static str {
        "command"
    }
    fn description(&self) -> &'static str {
        "limber-services command -> driver -> published outcome seen by the client (DeviceHost/Client), spin and event-driven"
    }
    fn run(&self, ctx: &mut RunCtx) -> Result<(), BenchError> {
        let can_spin = ctx.spin_enabled();
        if can_spin {
            run_mode(ctx, true)?;
            // At a control loop's rate, beside its floor at that rate, in alternate turns.
            for _ in 0..PACED_TURNS {
                super::floor::ping_pong(ctx, Echo::SpinState, PACED)?;
                run_variant(ctx, Some(true), None, PACED)?;
            }
        }
        if ctx.blocking_enabled() {
            for v in EventVariant::ALL {
                // Spinning needs a second core: without one, only pure blocking runs.
                if v != EventVariant::Block && !can_spin {
                    continue;
                }
                run_event(ctx, v)?;
            }
        }
        Ok(())
    }
}

fn ctx_err(what: &str) -> impl Fn(String) -> BenchError + '_ {
    move |reason| BenchError::Transport {
        context: what.to_string(),
        reason,
    }
}

/// The event-driven variants: which spin-then-block budgets are on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EventVariant {
    /// Both defaults (the client's spin budget and the driver's linger).
    Default,
    /// Neither: pure blocking.
    Block,
    /// Only the client's spin budget.
    ClientSpin,
    /// Only the driver's linger.
    Linger,
}

impl EventVariant {
    /// Every variant, the default first.
    pub const ALL: [EventVariant; 4] = [
        EventVariant::Default,
        EventVariant::Block,
        EventVariant::ClientSpin,
        EventVariant::Linger,
    ];
    fn key(self) -> &'static str {
        match self {
            EventVariant::Default => "event",
            EventVariant::Block => "event-block",
            EventVariant::ClientSpin => "event-cspin",
            EventVariant::Linger => "event-linger",
        }
    }
    fn label(self) -> &'static str {
        match self {
            EventVariant::Default => "",
            EventVariant::Block => " (pure blocking)",
            EventVariant::ClientSpin => " (client spin only)",
            EventVariant::Linger => " (driver linger only)",
        }
    }
    fn client_spin(self) -> Duration {
        match self {
            EventVariant::Default | EventVariant::ClientSpin => {
                limber_services::qos::default_spin_budget()
            }
            _ => Duration::ZERO,
        }
    }
    fn driver_linger(self) -> Duration {
        match self {
            EventVariant::Default | EventVariant::Linger => limber_services::qos::DRIVER_LINGER,
            _ => Duration::ZERO,
        }
    }
}

/// The spinning pair at a control loop's rate: `command.paced.spin.*`, and its floor
/// `command.paced.spin2.*`, in alternate turns.
const PACED: Pace = Pace::Paced {
    period: Duration::from_millis(1),
    scenario: "command",
    beside: None,
    turns: PACED_TURNS,
};
/// The turns of [`PACED`].
const PACED_TURNS: u32 = 3;

fn run_event(ctx: &mut RunCtx, v: EventVariant) -> Result<(), BenchError> {
    run_variant(ctx, None, Some(v), Pace::BackToBack)
}

fn run_mode(ctx: &mut RunCtx, spin: bool) -> Result<(), BenchError> {
    run_variant(ctx, Some(spin), None, Pace::BackToBack)
}

fn run_variant(
    ctx: &mut RunCtx,
    spin: Option<bool>,
    variant: Option<EventVariant>,
    pace: Pace,
) -> Result<(), BenchError> {
    let spin = spin.unwrap_or(false);
    let variant = variant.unwrap_or(EventVariant::Default);
    let domain = ctx.domain();
    let (warm, n) = if spin {
        pace.counts(ctx, ((5_000, 1_000), (100_000, 10_000)))
    } else {
        pace.counts(ctx, ((500, 100), (5_000, 1_000)))
    };
    let key = if spin { "spin" } else { variant.key() };
    let label = if spin {
        pace.label()
    } else {
        format!("{}{}", variant.label(), pace.label())
    };
    // `command.<key>.*` back to back, `command.paced.<key>.*` paced.
    let id = |suffix: &str| match pace {
        Pace::BackToBack => format!("command.{key}.{suffix}"),
        Pace::Paced { .. } => pace.id(key, suffix),
    };
    let out = ctx.tmp_file(&format!("{}.hdr", id("oneway")));
    let mut child = ChildProc::spawn(&ChildSpec {
        role: format!("cmd-driver-{}", if spin { "spin" } else { "event" }),
        domain: Some(domain.name().to_string()),
        out: Some(out.clone()),
        cpu: ctx.child_cpu(),
        warmup: warm,
        deadline: pace.deadline(ctx, warm + n, Duration::from_micros(100)),
        linger: (!spin).then(|| variant.driver_linger()),
        ..Default::default()
    })?;
    child.expect("ready", READY_TIMEOUT)?;

    let cctx = Context::new(&domain, Role::Client, "bench-client")
        .map_err(|e| ctx_err("client context")(e.to_string()))?;
    let mut client = ActArrayClient::connect_timeout(&cctx, DEVICE, READY_TIMEOUT)
        .map_err(|e| ctx_err("connect")(e.to_string()))?;
    if spin {
        client.set_wait_mode(WaitMode::Spin);
        client.set_wake_driver(false);
    } else {
        client.set_spin_budget(variant.client_spin());
    }

    let mut rtt = new_histogram()?;
    let mut back = new_histogram()?;
    let progress = Progress::new(ctx.progress, &format!("command {key}{label}"), warm + n);
    let start = Instant::now();
    for i in 1..=warm + n {
        pace.wait_turn(start, i);
        let target = if i % 2 == 0 { 0.25 } else { -0.25 };
        let t0 = monotonic_ns();
        let ticket = client
            .move_to(0, target)
            .map_err(|e| ctx_err("move_to")(e.to_string()))?;
        let outcome = client
            .wait_outcome_detail(ticket, SAMPLE_TIMEOUT)
            .map_err(|e| match e {
                limber_services::WaitError::Timeout(t) => BenchError::Timeout {
                    what: format!("outcome of command {i}"),
                    timeout: t,
                },
                other => ctx_err("wait_outcome")(other.to_string()),
            })?;
        let t1 = monotonic_ns();
        if outcome.status != Status::Ok {
            return Err(ctx_err("command")(format!("refused: {}", outcome.status)));
        }
        if i > warm {
            rtt.saturating_record(t1.saturating_sub(t0));
            back.saturating_record(t1.saturating_sub(outcome.stamp_ns));
        }
        progress.tick(i);
    }
    progress.finish();
    // HOME all joints stops the driver.
    // (If the command cannot be sent, the child's deadline below ends it.)
    if let Err(e) = client.home(None) {
        tracing::warn!("cannot tell the driver child to stop: {e}");
    }
    child.finish(Duration::from_secs(10))?;
    let oneway = read_histogram(&out)?;

    let strategy = if spin {
        Strategy::Spin
    } else {
        Strategy::Blocking
    };
    ctx.push(Measurement {
        scenario: "command",
        id: id("rtt"),
        label: format!("command→outcome{label}"),
        strategy,
        metric: Metric::RoundTrip,
        bytes: Some(BYTES),
        hist: rtt,
    });
    ctx.push(Measurement {
        scenario: "command",
        id: id("oneway"),
        label: format!("command client→driver{label}"),
        strategy,
        metric: Metric::OneWay,
        bytes: Some(BYTES),
        hist: oneway,
    });
    ctx.push(Measurement {
        scenario: "command",
        id: id("back"),
        label: format!("outcome driver→client{label}"),
        strategy,
        metric: Metric::OneWay,
        bytes: Some(BYTES),
        hist: back,
    });
    Ok(())
}

/// Starts the event-driven driver child (`cmd-driver-event`, the default linger) in
/// `domain`, writing its histogram to the scratch file `out`, and waits for its `ready`.
pub(crate) fn start_event_driver(
    ctx: &RunCtx,
    domain: &Domain,
    out: &str,
    deadline: Duration,
) -> Result<ChildProc, BenchError> {
    let mut driver = ChildProc::spawn(&ChildSpec {
        role: "cmd-driver-event".into(),
        domain: Some(domain.name().to_string()),
        out: Some(ctx.tmp_file(out)),
        cpu: ctx.child_cpu(),
        warmup: 0,
        deadline,
        linger: Some(limber_services::qos::DRIVER_LINGER),
        ..Default::default()
    })?;
    driver.expect("ready", READY_TIMEOUT)?;
    Ok(driver)
}

/// The benchmark arm: 6 joints that move at once; records the one-way latency of every
/// command after the warm-up; HOME (all joints) asks the driver to stop.
struct BenchArm {
    oneway: hdrhistogram::Histogram<u64>,
    warmup: u64,
    stop: bool,
}

impl DeviceHandler<ActArray> for BenchArm {
    fn command(
        &mut self,
        cmd: &ActArrayCommand,
        from: &Origin,
        state: &mut ActArrayData,
    ) -> Status {
        let status = match *cmd {
            ActArrayCommand::Position { joint, position } => {
                if from.seq > self.warmup {
                    self.oneway
                        .saturating_record(from.received_ns.saturating_sub(from.sent_ns));
                }
                match state.actuators.get_mut(joint as usize) {
                    Some(a) => {
                        a.position = position;
                        Status::Ok
                    }
                    None => Status::UnknownJoint,
                }
            }
            ActArrayCommand::Home(_) => {
                self.stop = true;
                Status::Ok
            }
            _ => Status::Unsupported,
        };
        // The state is "acquired" now.
        state.header.stamp_ns = monotonic_ns();
        status
    }

    fn request(
        &mut self,
        _req: &ActArrayRequest,
        _from: &Origin,
        _state: &mut ActArrayData,
    ) -> Result<ActArrayReply, Status> {
        Err(Status::Unsupported)
    }
}

/// The driver child (`cmd-driver-spin`, `cmd-driver-event`).
pub fn driver_role(args: &BenchArgs, spin: bool) -> Result<(), BenchError> {
    let domain = roles::child_domain(args)?;
    let deadline = roles::child_deadline(args);
    let ctx = Context::new(&domain, Role::Driver, "bench-driver")
        .map_err(|e| ctx_err("driver context")(e.to_string()))?;
    let device: DeviceName = args
        .device
        .as_deref()
        .unwrap_or(DEVICE)
        .parse()
        .map_err(|e: limber_services::NameError| ctx_err("device")(e.to_string()))?;
    let mut host = DeviceHost::<ActArray>::new(&ctx, &device, "bench")
        .map_err(|e| ctx_err("driver host")(e.to_string()))?;
    host.state_mut().actuators_count = 6;
    host.publish()
        .map_err(|e| ctx_err("publish")(e.to_string()))?;
    let mut arm = BenchArm {
        oneway: new_histogram()?,
        warmup: args.warmup,
        stop: false,
    };
    if spin {
        roles::announce("ready");
        let mut i = 0u32;
        loop {
            let a = host
                .process_spin(&mut arm)
                .map_err(|e| ctx_err("process")(e.to_string()))?;
            if arm.stop {
                break;
            }
            if a.commands == 0 {
                i = i.wrapping_add(1);
                if i & 0xffff == 0 && Instant::now() > deadline {
                    return Err(ctx_err("driver")("deadline passed".into()));
                }
                core::hint::spin_loop();
            }
        }
    } else {
        let wake = host
            .take_wake_listener()
            .ok_or_else(|| ctx_err("driver")("no wake listener".into()))?;
        let listeners = [wake];
        roles::announce("ready");
        let mut failure = None;
        let linger = Duration::from_micros(args.linger_us);
        event_loop::run(&listeners, Duration::from_millis(50), None, |_wake| {
            if let Err(e) = host.process(&mut arm) {
                failure = Some(e.to_string());
                return ControlFlow::Break(());
            }
            event_loop::linger(linger, || {
                if arm.stop || failure.is_some() {
                    return false;
                }
                match host.process_linger(&mut arm) {
                    Ok(a) => a.commands + a.requests > 0,
                    Err(e) => {
                        failure = Some(e.to_string());
                        false
                    }
                }
            });
            if failure.is_some() {
                return ControlFlow::Break(());
            }
            if arm.stop || Instant::now() > deadline {
                ControlFlow::Break(())
            } else {
                ControlFlow::Continue(())
            }
        })
        .map_err(|e| ctx_err("event loop")(e.to_string()))?;
        if let Some(f) = failure {
            return Err(ctx_err("process")(f));
        }
        if !arm.stop {
            return Err(ctx_err("driver")("deadline passed".into()));
        }
    }
    roles::write_histogram(args, &arm.oneway)
}
