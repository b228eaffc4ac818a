//! `loop`: the full control loop through the emulator over a pty. A client moves joint 0
//! of the Pioneer arm (driver and emulator in the `pioneer-driver` child process,
//! event-driven); the command goes to the driver, out as P2OS bytes on the pty, the
//! emulator (in fast mode, `EmulatorConfig::fast`: a real controller would answer at its
//! next 100 ms cycle) acts on it and answers with an ARMpac at once, the driver reads it and
//! publishes the arm state, and the client sees it. Split by stage with the stamps on
//! the way:
//!
//! * `command → robot reply read by the driver`: the client's send stamp to the state's
//!   acquisition stamp (`StateHeader::stamp_ns` = when the driver read the ARMpac):
//!   client → driver, validation, the serial write, the emulator, the ARMpac back;
//! * `command arrival → bytes on the pty`: inside that, the driver's own cost, from taking
//!   the command off its channel to the P2OS bytes written (validation, encoding, the
//!   write), measured by the driver (`LoopStats::arrival_to_wire`; the last 512 commands);
//!   and inside it the link's send alone (`LoopStats::link_write`: encoding and the
//!   `write(2)`, clock read before and after it), the kernel's share, and what comes
//!   before that send (`LoopStats::arrival_to_send`: taking the command, validation, the
//!   handler), the driver's work without the kernel's. A pty's write wakes
//!   the tty's buffer worker (a kernel thread), which, woken on the writer's core, runs
//!   as the write returns and before the driver reads its clock: on a spinning core
//!   that is most writes, so the spinning stage counts the kernel's pty work too;
//! * `reply read → client sees the state`: acquisition stamp to the client's receipt
//!   (driver publish, notify, client wake-up);
//! * the total, client send → client receipt.
//!
//! With the spinning variant comes its floor, `loop.spin.pty_write`: a bare `write(2)` of
//! an ARM_POS command's 9 bytes on a pty whose other end a blocked thread reads (as the
//! emulator does), from a thread that spins between writes (on the driver's core when
//! pinned), clock read before and after: what the kernel takes for the driver's send.
//!
//! Run twice when both strategies are enabled: with the event-driven driver (ids
//! `loop.*`), and with the busy-polling driver (`limber pioneer --spin`; ids `loop.spin.*`,
//! labels ending `[driver spinning]`), whose `driver` stage is the driver's own cost when
//! it is awake. The client waits on events in both, so the emulator thread keeps a core.
//! With `--pin`, the driver runs on the child's core and the emulator thread on the
//! client's (see `RunCtx::client_cpu`), so the emulator never takes the driver's core.

use std::time::{Duration, Instant};

use limber_interfaces::prelude::*;
use limber_services::prelude::*;
use limber_services::{Role, monotonic_ns};

use super::request::{DEVICE, START_TIMEOUT};
use super::{RunCtx, Scenario};
use crate::BenchError;
use crate::child::{ChildProc, ChildSpec, read_histogram};
use crate::progress::Progress;
use crate::stats::{Measurement, Metric, Strategy, new_histogram};

/// The `loop` scenario.
#[derive(Debug, Clone, Copy)]
pub struct Loop;

fn err(what: &str, reason: String) -> BenchError {
    BenchError::Transport {
        context: what.to_string(),
        reason,
    }
}

impl Scenario for Loop {
    fn name(&self) -> &'static str {
        "loop"
    }
    fn description(&self) -> &'static str {
        "full loop through the emulator over a pty, fast mode (command → P2OS → emulator → ARMpac → state), split by stage"
    }
    fn run(&self, ctx: &mut RunCtx) -> Result<(), BenchError> {
        if ctx.blocking_enabled() {
            run_variant(ctx, Variant::Event)?;
        }
        if ctx.spin_enabled() {
            run_variant(ctx, Variant::DriverSpin)?;
            pty_write_floor(ctx)?;
        }
        Ok(())
    }
}

/// `loop.spin.pty_write`: the floor of the spinning driver's send (see the module doc).
fn pty_write_floor(ctx: &mut RunCtx) -> Result<(), BenchError> {
    use serialport::SerialPort;
    use std::io::{Read, Write};
    use std::os::unix::fs::OpenOptionsExt;
    use std::sync::Arc;
    use std::sync::atomic::{AtomicBool, Ordering};

    let (warm, n) = (ctx.count(50, 20), ctx.count(1_000, 200));
    let pty = |e: serialport::Error| err("pty", e.to_string());
    let (mut master, slave) = serialport::TTYPort::pair().map_err(pty)?;
    let path = slave
        .name()
        .ok_or_else(|| err("pty", "the pty has no name".into()))?;
    // Writes go straight to write(2): no poll first, no buffering.
    let mut writer = std::fs::OpenOptions::new()
        .write(true)
        .custom_flags(rustix::fs::OFlags::NOCTTY.bits() as i32)
        .open(&path)
        .map_err(|e| BenchError::io(path.clone(), e))?;
    master
        .set_timeout(Duration::from_millis(100))
        .map_err(pty)?;
    let stop = Arc::new(AtomicBool::new(false));
    let (reader_cpu, writer_cpu) = (ctx.client_cpu(), ctx.child_cpu());
    let stop2 = Arc::clone(&stop);
    let reader = std::thread::spawn(move || {
        if let Some(cpu) = reader_cpu {
            crate::roles::pin_to(cpu);
        }
        let mut buf = [0u8; 512];
        let mut bytes = 0u64;
        while !stop2.load(Ordering::Relaxed) {
            match master.read(&mut buf) {
                Ok(k) => bytes += k as u64,
                // The read's own timeout: look at the stop flag again.
                Err(e) if e.kind() == std::io::ErrorKind::TimedOut => {}
                Err(e) => return Err(e),
            }
        }
        Ok(bytes)
    });
    let progress = Progress::new(ctx.progress, "bare pty write (floor)", warm + n);
    let writing = std::thread::spawn(move || {
        if let Some(cpu) = writer_cpu {
            crate::roles::pin_to(cpu);
        }
        let mut h = new_histogram()?;
        for i in 1..=warm + n {
            // Spin between writes, as the spinning driver does between commands.
            let until = Instant::now() + Duration::from_micros(50);
            while Instant::now() < until {
                std::hint::spin_loop();
            }
            let t0 = monotonic_ns();
            writer
                .write_all(&ARM_POS_FRAME)
                .map_err(|e| BenchError::io("pty write", e))?;
            let t1 = monotonic_ns();
            if i > warm {
                h.saturating_record(t1.saturating_sub(t0));
            }
            progress.tick(i);
        }
        progress.finish();
        Ok::<_, BenchError>(h)
    });
    let written = writing
        .join()
        .map_err(|_| err("pty write", "the writer thread panicked".into()));
    stop.store(true, Ordering::Relaxed);
    let read = reader
        .join()
        .map_err(|_| err("pty read", "the reader thread panicked".into()))?
        .map_err(|e| BenchError::io("pty read", e))?;
    let hist = written??;
    tracing::debug!("pty floor: {read} bytes read");
    ctx.push(Measurement {
        scenario: "loop",
        id: "loop.spin.pty_write".into(),
        label: "  floor: bare write(2) of the same bytes on a pty, spinning writer".into(),
        strategy: Strategy::Spin,
        metric: Metric::OneWay,
        bytes: None,
        hist,
    });
    Ok(())
}

/// An ARM_POS command as the loop sends it (ARM_POS 77, joint 1, tick 120), 9 bytes.
const ARM_POS_FRAME: [u8; 9] = [0xFA, 0xFB, 0x06, 0x4D, 0x3B, 0x78, 0x01, 0xC5, 0x3C];

/// How the driver child waits; the client always waits on events (its spin budget
/// included), so the emulator thread keeps a core when the driver spins on the other.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Variant {
    /// The event-driven driver (the default).
    Event,
    /// The busy-polling driver (`limber pioneer --spin`).
    DriverSpin,
}

impl Variant {
    /// The child role, the id prefix, the label suffix and the driver stage's strategy.
    fn parts(self) -> (&'static str, &'static str, &'static str, Strategy) {
        match self {
            Variant::Event => ("pioneer-driver", "loop", "", Strategy::Blocking),
            Variant::DriverSpin => (
                "pioneer-driver-spin",
                "loop.spin",
                " [driver spinning]",
                Strategy::Spin,
            ),
        }
    }
}

/// One run of the loop with the driver child of `variant`.
fn run_variant(ctx: &mut RunCtx, variant: Variant) -> Result<(), BenchError> {
    let (role, prefix, suffix, driver_strategy) = variant.parts();
    let domain = ctx.domain();
    let (warm, n) = (ctx.count(50, 20), ctx.count(1_000, 200));
    let out = ctx.tmp_file(&format!("{prefix}-driver.hdr"));
    let mut child = ChildProc::spawn(&ChildSpec {
        role: role.into(),
        domain: Some(domain.name().to_string()),
        out: Some(out.clone()),
        cpu: ctx.child_cpu(),
        // Pinned, the emulator thread runs on the client's core, not on the driver's:
        // the client waits on events, the driver may spin (and a reader woken on the
        // writer's core preempts it as its write returns, before its clock read).
        emulator_cpu: ctx.client_cpu(),
        deadline: ctx.deadline_for(warm + n, Duration::from_millis(20)),
        ..Default::default()
    })?;
    child.expect("ready", START_TIMEOUT)?;
    let cctx = Context::new(&domain, Role::Client, "bench-loop")
        .map_err(|e| err("client context", e.to_string()))?;
    let mut arm = ActArrayClient::connect_timeout(&cctx, DEVICE, START_TIMEOUT)
        .map_err(|e| err("connect", e.to_string()))?;
    arm.set_request_timeout(super::SAMPLE_TIMEOUT);
    arm.power(true).map_err(|e| err("power", e.to_string()))?;
    let (mut to_robot, mut to_client, mut total) =
        (new_histogram()?, new_histogram()?, new_histogram()?);
    let progress = Progress::new(
        ctx.progress,
        &format!("loop through the emulator{suffix}"),
        warm + n,
    );
    for i in 1..=warm + n {
        let target = if i % 2 == 0 { 0.15 } else { -0.15 };
        let t0 = monotonic_ns();
        arm.move_to(0, target)
            .map_err(|e| err("command", e.to_string()))?;
        // The first state acquired after the command was sent: the emulator's prompt
        // ARMpac, read by the driver.
        let deadline = Instant::now() + super::SAMPLE_TIMEOUT;
        let (stamp, seen) = loop {
            let s = arm
                .wait_state(deadline.saturating_duration_since(Instant::now()))
                .map_err(|e| err("state", e.to_string()))?;
            let stamp = s.header.stamp_ns;
            if stamp > t0 {
                break (stamp, monotonic_ns());
            }
        };
        if i > warm {
            to_robot.saturating_record(stamp.saturating_sub(t0));
            to_client.saturating_record(seen.saturating_sub(stamp));
            total.saturating_record(seen.saturating_sub(t0));
        }
        progress.tick(i);
    }
    progress.finish();
    drop(arm);
    if let Err(e) = child.send_line("quit") {
        tracing::warn!("cannot tell the client child to quit: {e}");
    }
    child.finish(Duration::from_secs(10))?;
    let driver = read_histogram(&out)?;
    let send = read_histogram(&super::request::link_write_path(&out))?;
    let work = read_histogram(&super::request::driver_work_path(&out))?;
    let bytes = Some((
        core::mem::size_of::<ActArrayCmdMsg>(),
        core::mem::size_of::<ActArrayData>(),
    ));
    for (stage, label, strategy, metric, hist) in [
        (
            "to_robot",
            "command → robot reply read by the driver (emulator fast mode)",
            Strategy::Blocking,
            Metric::OneWay,
            to_robot,
        ),
        (
            "driver",
            "command arrival → bytes on the pty (the driver's own cost)",
            driver_strategy,
            Metric::OneWay,
            driver,
        ),
        (
            "driver_send",
            "  of which the link's send (encoding, write(2) on the pty)",
            driver_strategy,
            Metric::OneWay,
            send,
        ),
        (
            "driver_work",
            "  and before it, the driver's work (validation, the handler)",
            driver_strategy,
            Metric::OneWay,
            work,
        ),
        (
            "to_client",
            "reply read → client sees the state",
            Strategy::Blocking,
            Metric::OneWay,
            to_client,
        ),
        (
            "total",
            "command → state, through the emulator (fast mode)",
            Strategy::Blocking,
            Metric::RoundTrip,
            total,
        ),
    ] {
        let label = format!("{label}{suffix}");
        ctx.push(Measurement {
            scenario: "loop",
            id: format!("{prefix}.{stage}"),
            label,
            strategy,
            metric,
            bytes,
            hist,
        });
    }
    Ok(())
}
