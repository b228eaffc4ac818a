//! `state`: a driver process (`DeviceHost<ActArray>`) publishes the 1376 B arm state at
//! 1 kHz; 1, 4 and 16 subscriber processes (`ActArrayClient`, `WaitMode::Event`) block in
//! `wait_state`, asleep on the device's wake word (a futex the driver bumps with every
//! state) — never more spinning processes than cores, so nobody spins here. One-way
//! latency: the state's `header.stamp_ns` (taken just before `publish`) against the
//! subscriber's clock when `wait_state` returned. Samples of all subscribers of one
//! fan-out are merged into one histogram.
//!
//! Its floors run first, at the same rate (`state.paced.futex.*`, `state.paced.event.*`):
//! the physical futex ping-pong and the raw iceoryx2 event ping-pong of `floor`, one
//! exchange per millisecond from a sleeping sender, so that the echo's wake-up
//! (`*.oneway`) comes after the idle millisecond a subscriber's does. Before each fan-out,
//! its floors: the same publication and notify in raw iceoryx2 to as many listener
//! processes (`state.raw.<N>.oneway`, [`super::fanout_floor`]), and a stamped number on a
//! shared page with one `FUTEX_WAKE` to as many waiter processes
//! (`state.futex.<N>.oneway`, [`physical::fanout`]).

use std::time::{Duration, Instant};

use limber_interfaces::prelude::*;
use limber_services::prelude::*;
use limber_services::{Role, WaitError, monotonic_ns};

use super::command::DEVICE;
use super::floor::{self, BYTES, Echo};
use super::{Pace, READY_TIMEOUT, RunCtx, Scenario, physical};
use crate::child::{ChildProc, ChildSpec, read_histogram};
use crate::roles;
use crate::stats::{Measurement, Metric, Strategy, new_histogram};
use crate::{BenchArgs, BenchError};

/// The fan-outs measured.
pub const FANOUTS: [usize; 3] = [1, 4, 16];
/// The publishing period.
pub const PERIOD: Duration = Duration::from_millis(1);
/// `motor_state` of the sample that tells subscribers to stop.
pub const STOP_MARK: u32 = 0x5709;

/// The `state` scenario.
#[derive(Debug, Clone, Copy)]
pub struct StateFanout;

impl Scenario for StateFanout {
    fn name(&self) -> &'static str {
        "state"
    }
    fn description(&self) -> &'static str {
        "driver publishes the arm state at 1 kHz; 1, 4, 16 subscriber processes block in wait_state on the device's wake word (one-way); beside it its floors paced at the same 1 kHz: a futex wake and a raw iceoryx2 event wake, and before each fan-out raw iceoryx2's own (a sample and a notify to as many listener processes) and the kernel's (one futex wake of as many waiter processes)"
    }
    fn run(&self, ctx: &mut RunCtx) -> Result<(), BenchError> {
        if !ctx.blocking_enabled() {
            ctx.notes
                .push("state runs blocking subscribers only; skipped by --strategy spin".into());
            return Ok(());
        }
        // The floors at the path's rate, in the same run: a wake-up after an idle
        // millisecond, through a futex (the kernel alone) and through a raw iceoryx2 event
        // (a sample, `notify`, a listener blocked in `timed_wait`).
        let pace = Pace::Paced {
            period: PERIOD,
            scenario: "state",
            beside: None,
            turns: 1,
        };
        physical::ping_pong(ctx, physical::Wait::Futex, pace)?;
        floor::ping_pong(ctx, Echo::Listener, pace)?;
        for fan in FANOUTS {
            super::fanout_floor::fanout(ctx, fan)?;
            physical::fanout(ctx, fan)?;
            fanout(ctx, fan)?;
        }
        Ok(())
    }
}

fn err(what: &str, reason: String) -> BenchError {
    BenchError::Transport {
        context: what.to_string(),
        reason,
    }
}

fn fanout(ctx: &mut RunCtx, fan: usize) -> Result<(), BenchError> {
    let domain = ctx.domain();
    let (warm, n) = (ctx.count(200, 50), ctx.count(3_000, 300));
    let deadline = Duration::from_secs(30) + PERIOD * ((warm + n) as u32) * 3;
    let mut publisher = ChildProc::spawn(&ChildSpec {
        role: "state-pub".into(),
        domain: Some(domain.name().to_string()),
        cpu: ctx.child_cpu(),
        warmup: warm,
        count: n,
        deadline,
        ..Default::default()
    })?;
    publisher.expect("ready", READY_TIMEOUT)?;
    let mut subs = Subscribers::spawn(ctx, &domain, "state-sub", fan, warm, deadline, None)?;
    ctx.say(format_args!(
        "  state fan-out {fan}: {} samples at {} Hz",
        warm + n,
        1_000_000_000 / PERIOD.as_nanos().max(1)
    ));
    publisher.send_line("go")?;
    let until = Instant::now() + deadline;
    while !subs.all_exited() && Instant::now() < until {
        std::thread::sleep(Duration::from_millis(10));
    }
    if let Err(e) = publisher.send_line("quit") {
        tracing::warn!("cannot tell the publisher child to quit: {e}");
    }
    publisher.finish(Duration::from_secs(5))?;
    subs.merge_into(
        ctx,
        format!("state.{fan}.oneway"),
        format!("state → {fan} subscriber(s), 1 kHz"),
    )
}

/// The subscriber children of one fan-out, each writing its histogram of one-way times.
pub(super) struct Subscribers {
    procs: Vec<ChildProc>,
    outs: Vec<std::path::PathBuf>,
}

impl Subscribers {
    /// Spawns `fan` children of `role` in `domain` and waits for each one's "ready".
    /// `shm`: the page a futex waiter maps ([`physical::fanout`]).
    pub(super) fn spawn(
        ctx: &RunCtx,
        domain: &Domain,
        role: &str,
        fan: usize,
        warm: u64,
        deadline: Duration,
        shm: Option<&std::path::Path>,
    ) -> Result<Self, BenchError> {
        let mut subs = Subscribers {
            procs: Vec::with_capacity(fan),
            outs: Vec::with_capacity(fan),
        };
        for i in 0..fan {
            let out = ctx.tmp_file(&format!("{role}-{fan}-{i}.hdr"));
            subs.procs.push(ChildProc::spawn(&ChildSpec {
                role: role.into(),
                domain: Some(domain.name().to_string()),
                out: Some(out.clone()),
                shm: shm.map(std::path::Path::to_path_buf),
                warmup: warm,
                deadline,
                ..Default::default()
            })?);
            subs.outs.push(out);
        }
        for s in &mut subs.procs {
            s.expect("ready", READY_TIMEOUT)?;
        }
        Ok(subs)
    }

    /// Whether every subscriber has exited.
    pub(super) fn all_exited(&mut self) -> bool {
        self.procs.iter_mut().all(|s| s.exited())
    }

    /// Waits for the subscribers to end and adds their merged histograms as `id`.
    pub(super) fn merge_into(
        self,
        ctx: &mut RunCtx,
        id: String,
        label: String,
    ) -> Result<(), BenchError> {
        let mut merged = new_histogram()?;
        for s in self.procs {
            s.finish(Duration::from_secs(5))?;
        }
        for out in &self.outs {
            merged
                .add(read_histogram(out)?)
                .map_err(|e| BenchError::Histogram(e.to_string()))?;
        }
        ctx.push(Measurement {
            scenario: "state",
            id,
            label,
            strategy: Strategy::Blocking,
            metric: Metric::OneWay,
            bytes: Some((0, BYTES.1)),
            hist: merged,
        });
        Ok(())
    }
}

/// The publishing driver child (`state-pub`).
pub fn publisher_role(args: &BenchArgs) -> Result<(), BenchError> {
    let domain = roles::child_domain(args)?;
    let deadline = roles::child_deadline(args);
    let ctx = Context::new(&domain, Role::Driver, "bench-state")
        .map_err(|e| err("driver context", e.to_string()))?;
    let device: DeviceName = DEVICE
        .parse()
        .map_err(|e: limber_services::NameError| err("device", e.to_string()))?;
    let mut host = DeviceHost::<ActArray>::new(&ctx, &device, "bench")
        .map_err(|e| err("driver host", e.to_string()))?;
    host.state_mut().actuators_count = 6;
    host.publish_acquired(monotonic_ns())
        .map_err(|e| err("publish", e.to_string()))?;
    let lines = roles::stdin_lines();
    roles::announce("ready");
    let wait_for = |word: &str| -> Result<(), BenchError> {
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            match lines.recv_timeout(left) {
                Ok(l) if l.trim() == word => return Ok(()),
                Ok(_) => {}
                Err(_) => {
                    return Err(err(
                        "state publisher",
                        format!("no `{word}` from the parent"),
                    ));
                }
            }
        }
    };
    wait_for("go")?;
    let start = Instant::now();
    for i in 1..=(args.warmup + args.count) {
        let next = start + PERIOD * (i as u32);
        let now = Instant::now();
        if next > now {
            std::thread::sleep(next - now);
        }
        host.publish_acquired(monotonic_ns())
            .map_err(|e| err("publish", e.to_string()))?;
    }
    host.state_mut().motor_state = STOP_MARK;
    loop {
        host.publish_acquired(monotonic_ns())
            .map_err(|e| err("publish", e.to_string()))?;
        match lines.recv_timeout(Duration::from_millis(10)) {
            Ok(l) if l.trim() == "quit" => return Ok(()),
            Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => return Ok(()),
            _ => {}
        }
        if Instant::now() > deadline {
            return Ok(());
        }
    }
}

/// The subscriber child (`state-sub`).
pub fn subscriber_role(args: &BenchArgs) -> Result<(), BenchError> {
    let domain = roles::child_domain(args)?;
    let deadline = roles::child_deadline(args);
    let ctx = Context::new(&domain, Role::Client, "bench-sub")
        .map_err(|e| err("client context", e.to_string()))?;
    let mut client = ActArrayClient::connect_timeout(&ctx, DEVICE, READY_TIMEOUT)
        .map_err(|e| err("connect", e.to_string()))?;
    // The first wait takes the initial state; the second creates the notify listener.
    // A timeout here is expected (no new state yet); anything else is an error.
    for _ in 0..2 {
        match client.wait_state(Duration::from_millis(1)) {
            Ok(_) | Err(limber_services::WaitError::Timeout(_)) => {}
            Err(e) => return Err(err("wait for the first state", e.to_string())),
        }
    }
    let mut oneway = new_histogram()?;
    roles::announce("ready");
    // Sample 1 is the initial state; the warm-up follows it.
    let first = 1 + args.warmup;
    loop {
        match client.wait_state(Duration::from_millis(200)) {
            Ok(d) => {
                let now = monotonic_ns();
                if d.motor_state == STOP_MARK {
                    break;
                }
                if d.header.seq > first {
                    oneway.saturating_record(now.saturating_sub(d.header.stamp_ns));
                }
            }
            Err(WaitError::Timeout(_)) => {
                if Instant::now() > deadline {
                    return Err(err("state subscriber", "deadline passed".into()));
                }
            }
            Err(e) => return Err(err("wait_state", e.to_string())),
        }
    }
    roles::write_histogram(args, &oneway)
}
