//! The machine's own floors (part of `floor`): two processes exchanging a sequence number
//! and a stamp through one page of shared memory, with no middleware at all.
//!
//! * `futex` (blocking): each side publishes on its own cache line and wakes the other
//!   with `FUTEX_WAKE`; the other sleeps in `FUTEX_WAIT`. This is what any blocking
//!   shared-memory exchange pays at least: two system calls and a wake-up of a sleeping
//!   process per direction.
//! * `cacheline` (spin): both sides busy-poll the other's cache line. This is what any
//!   spinning exchange pays at least: one cache-line transfer between cores per direction.
//!
//! Round trip, one-way ping→echo and one-way echo→ping are measured as in the iceoryx2
//! floor, so that every other scenario can be divided by them (`x phys` in the table).

use std::fs::OpenOptions;
use std::os::unix::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU32, AtomicU64, Ordering};
use std::time::{Duration, Instant};

use limber_services::monotonic_ns;
use rustix::mm::{MapFlags, ProtFlags};
use rustix::thread::futex;

use super::{Pace, READY_TIMEOUT, RunCtx, SAMPLE_TIMEOUT};
use crate::child::{ChildProc, ChildSpec, read_histogram};
use crate::progress::Progress;
use crate::stats::{Measurement, Metric, Strategy, new_histogram};
use crate::{BenchArgs, BenchError};

/// The sequence number that stops an echo.
const STOP: u32 = u32::MAX;
/// Bytes carried each way: a 4-byte sequence number and an 8-byte stamp.
pub const BYTES: (usize, usize) = (12, 12);

/// How both sides wait.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Wait {
    /// `FUTEX_WAIT` / `FUTEX_WAKE` on the sequence word.
    Futex,
    /// Busy-polling the other side's cache line.
    Spin,
}

impl Wait {
    fn key(self) -> &'static str {
        match self {
            Wait::Futex => "futex",
            Wait::Spin => "cacheline",
        }
    }
    /// The child role.
    pub fn role(self) -> &'static str {
        match self {
            Wait::Futex => "futex-echo",
            Wait::Spin => "cacheline-echo",
        }
    }
}

/// One side's message, alone on its cache line.
#[repr(C, align(64))]
struct Line {
    seq: AtomicU32,
    _pad: u32,
    stamp: AtomicU64,
}

/// The shared page: the pinger writes `ping`, the echo writes `pong`.
#[repr(C)]
struct Page {
    ping: Line,
    pong: Line,
}

const PAGE: usize = 4096;
const _: () = assert!(core::mem::size_of::<Page>() <= PAGE);

/// One page of a file mapped shared into this process.
struct Shared {
    ptr: *mut core::ffi::c_void,
}

impl Shared {
    /// Creates (the pinger) or opens (the echo) the file at `path` and maps it.
    fn map(path: &Path, create: bool) -> Result<Self, BenchError> {
        let io = |e: std::io::Error| BenchError::io(path.display().to_string(), e);
        let file = if create {
            OpenOptions::new()
                .read(true)
                .write(true)
                .create_new(true)
                .mode(0o600)
                .open(path)
                .map_err(io)?
        } else {
            OpenOptions::new()
                .read(true)
                .write(true)
                .open(path)
                .map_err(io)?
        };
        if create {
            // Zero-filled: both sequence words start at 0.
            file.set_len(PAGE as u64).map_err(io)?;
        }
        // SAFETY: a fresh shared mapping of one page of a file we hold open, at an address
        // the kernel chooses; nothing else in this process aliases it. The mapping outlives
        // the file descriptor (closed at the end of this function), as mmap(2) allows.
        let ptr = unsafe {
            rustix::mm::mmap(
                core::ptr::null_mut(),
                PAGE,
                ProtFlags::READ | ProtFlags::WRITE,
                MapFlags::SHARED,
                &file,
                0,
            )
        }
        .map_err(|e| io(e.into()))?;
        Ok(Shared { ptr })
    }

    fn page(&self) -> &Page {
        // SAFETY: `ptr` is a live, page-aligned mapping of PAGE bytes (≥ size_of::<Page>),
        // zero-initialised (a valid `Page`: atomics of 0), accessed only through atomics by
        // both processes; it stays mapped until `self` is dropped.
        unsafe { &*(self.ptr as *const Page) }
    }
}

impl Drop for Shared {
    fn drop(&mut self) {
        // SAFETY: unmaps exactly the mapping made in `map`; no reference from `page()`
        // outlives `self`.
        if let Err(e) = unsafe { rustix::mm::munmap(self.ptr, PAGE) } {
            tracing::warn!("cannot unmap the physical floor's page: {e}");
        }
    }
}

/// Where the shared page lives: RAM-backed `/dev/shm` when there is one.
fn page_path(ctx: &RunCtx, wait: Wait) -> PathBuf {
    let shm = Path::new("/dev/shm");
    if shm.is_dir() {
        shm.join(format!(
            "limber-bench-{}-{}-{}",
            std::process::id(),
            wait.key(),
            monotonic_ns()
        ))
    } else {
        ctx.tmp_file(&format!("{}.page", wait.key()))
    }
}

/// Publishes `seq` (with a fresh stamp) on `line`, waking a futex waiter.
fn publish(line: &Line, seq: u32, wait: Wait) {
    publish_to(line, seq, wait, 1);
}

/// Publishes `seq` (with a fresh stamp) on `line`, waking up to `sleepers` futex waiters.
fn publish_to(line: &Line, seq: u32, wait: Wait, sleepers: u32) {
    line.stamp.store(monotonic_ns(), Ordering::Relaxed);
    line.seq.store(seq, Ordering::Release);
    if wait == Wait::Futex {
        // The number of woken waiters does not matter; an error cannot happen for a valid
        // address, and the other side re-checks with a timeout anyway.
        if let Err(e) = futex::wake(&line.seq, futex::Flags::empty(), sleepers) {
            tracing::debug!("futex wake: {e}");
        }
    }
}

/// Waits until `line.seq` differs from `old`; returns (receipt time, new seq, its stamp),
/// or `None` when `deadline` passes.
fn await_change(line: &Line, old: u32, wait: Wait, deadline: Instant) -> Option<(u64, u32, u64)> {
    let mut spins = 0u32;
    loop {
        let seq = line.seq.load(Ordering::Acquire);
        if seq != old {
            let t = monotonic_ns();
            return Some((t, seq, line.stamp.load(Ordering::Relaxed)));
        }
        match wait {
            Wait::Futex => {
                let left = deadline.saturating_duration_since(Instant::now());
                if left.is_zero() {
                    return None;
                }
                let left = left.min(Duration::from_millis(50));
                let ts = futex::Timespec {
                    tv_sec: left.as_secs() as i64,
                    tv_nsec: left.subsec_nanos() as i64,
                };
                match futex::wait(&line.seq, futex::Flags::empty(), old, Some(&ts)) {
                    // Woken, changed before we slept, timed out, interrupted: look again.
                    Ok(())
                    | Err(rustix::io::Errno::AGAIN)
                    | Err(rustix::io::Errno::TIMEDOUT)
                    | Err(rustix::io::Errno::INTR) => {}
                    Err(e) => {
                        tracing::warn!("futex wait: {e}");
                        std::thread::yield_now();
                    }
                }
            }
            Wait::Spin => {
                spins = spins.wrapping_add(1);
                if spins & 0xffff == 0 && Instant::now() >= deadline {
                    return None;
                }
                core::hint::spin_loop();
            }
        }
    }
}

/// Runs the physical floor with `wait`, spaced as `pace` says, and adds its three
/// measurements.
pub fn ping_pong(ctx: &mut RunCtx, wait: Wait, pace: Pace) -> Result<(), BenchError> {
    let path = page_path(ctx, wait);
    let shared = Shared::map(&path, true)?;
    let result = run(ctx, wait, pace, &shared, &path);
    if let Err(e) = std::fs::remove_file(&path) {
        tracing::warn!("cannot remove {}: {e}", path.display());
    }
    result
}

fn run(
    ctx: &mut RunCtx,
    wait: Wait,
    pace: Pace,
    shared: &Shared,
    path: &Path,
) -> Result<(), BenchError> {
    let page = shared.page();
    let (warm, n) = match wait {
        Wait::Futex => pace.counts(ctx, ((1_000, 100), (20_000, 2_000))),
        Wait::Spin => pace.counts(ctx, ((10_000, 1_000), (200_000, 20_000))),
    };
    let key = wait.key();
    let out = ctx.tmp_file(&format!("{key}.hdr"));
    let mut child = ChildProc::spawn(&ChildSpec {
        role: wait.role().into(),
        shm: Some(path.to_path_buf()),
        out: Some(out.clone()),
        cpu: ctx.child_cpu(),
        warmup: warm,
        deadline: pace.deadline(ctx, warm + n, Duration::from_micros(50)),
        ..Default::default()
    })?;
    child.expect("ready", READY_TIMEOUT)?;

    let mut rtt = new_histogram()?;
    let mut back = new_histogram()?;
    let progress = Progress::new(
        ctx.progress,
        &format!("{} {key}{}", pace.scenario(), pace.label()),
        warm + n,
    );
    let total = u32::try_from(warm + n)
        .ok()
        .filter(|t| *t < STOP)
        .ok_or_else(|| BenchError::Args(format!("too many samples for the {key} floor")))?;
    let start = Instant::now();
    for seq in 1..=total {
        pace.wait_turn(start, u64::from(seq));
        let t0 = monotonic_ns();
        publish(&page.ping, seq, wait);
        let deadline = Instant::now() + SAMPLE_TIMEOUT;
        let mut last = seq.wrapping_sub(1);
        let (t1, stamp) = loop {
            match await_change(&page.pong, last, wait, deadline) {
                Some((t1, s, stamp)) if s == seq => break (t1, stamp),
                Some((_, s, _)) => last = s,
                None => {
                    return Err(BenchError::Timeout {
                        what: format!("{key} floor pong {seq}"),
                        timeout: SAMPLE_TIMEOUT,
                    });
                }
            }
        };
        if u64::from(seq) > warm {
            rtt.saturating_record(t1.saturating_sub(t0));
            back.saturating_record(t1.saturating_sub(stamp));
        }
        progress.tick(u64::from(seq));
    }
    progress.finish();
    publish(&page.ping, STOP, wait);
    child.finish(Duration::from_secs(10))?;
    let oneway = read_histogram(&out)?;

    let (strategy, what) = match wait {
        Wait::Futex => (Strategy::Blocking, "futex ping-pong (shm)"),
        Wait::Spin => (Strategy::Spin, "cache-line ping-pong (shm)"),
    };
    let paced = pace.label();
    for (suffix, metric, label, hist) in [
        ("rtt", Metric::RoundTrip, format!("{what}{paced}"), rtt),
        (
            "oneway",
            Metric::OneWay,
            format!("{key} ping→echo{paced}"),
            oneway,
        ),
        (
            "back",
            Metric::OneWay,
            format!("{key} echo→ping{paced}"),
            back,
        ),
    ] {
        ctx.push(Measurement {
            scenario: pace.scenario(),
            id: pace.id(key, suffix),
            label,
            strategy,
            metric,
            bytes: Some(BYTES),
            hist,
        });
    }
    Ok(())
}

/// The child role of a futex fan-out waiter.
pub const FANOUT_ROLE: &str = "futex-fanout-sub";

/// The futex floor of the `state` fan-out (limber's state waiters sleep on a futex, the
/// device's wake word): the bench process publishes a stamped sequence number on one page
/// at 1 kHz and wakes every sleeper with one `FUTEX_WAKE`; `fan` child processes sleep in
/// `FUTEX_WAIT` and record each number's age (`state.futex.<fan>.oneway`, merged as
/// `state.<fan>.oneway` is): what the kernel alone pays to wake that many processes.
pub fn fanout(ctx: &mut RunCtx, fan: usize) -> Result<(), BenchError> {
    let path = page_path(ctx, Wait::Futex);
    let shared = Shared::map(&path, true)?;
    let result = run_fanout(ctx, fan, &shared, &path);
    if let Err(e) = std::fs::remove_file(&path) {
        tracing::warn!("cannot remove {}: {e}", path.display());
    }
    result
}

fn run_fanout(
    ctx: &mut RunCtx,
    fan: usize,
    shared: &Shared,
    path: &Path,
) -> Result<(), BenchError> {
    use super::state::{PERIOD, Subscribers};
    let page = shared.page();
    let pace = Pace::Paced {
        period: PERIOD,
        scenario: "state",
        beside: None,
        turns: 1,
    };
    let (warm, n) = pace.counts(ctx, ((0, 0), (0, 0)));
    let deadline = pace.deadline(ctx, warm + n, PERIOD);
    let subs = Subscribers::spawn(
        ctx,
        &ctx.domain(),
        FANOUT_ROLE,
        fan,
        warm,
        deadline,
        Some(path),
    )?;
    let total = u32::try_from(warm + n)
        .ok()
        .filter(|t| *t < STOP)
        .ok_or_else(|| BenchError::Args("too many samples for the futex fan-out".into()))?;
    let all = u32::try_from(fan).unwrap_or(u32::MAX);
    let start = Instant::now();
    for seq in 1..=total {
        pace.wait_turn(start, u64::from(seq));
        publish_to(&page.ping, seq, Wait::Futex, all);
    }
    publish_to(&page.ping, STOP, Wait::Futex, all);
    subs.merge_into(
        ctx,
        format!("state.futex.{fan}.oneway"),
        format!("futex broadcast → {fan} waiter(s), 1 kHz"),
    )
}

/// The futex fan-out's waiter child (`futex-fanout-sub`): sleeps until the number
/// changes, records its age after the warm-up, until STOP.
pub fn fanout_role(args: &BenchArgs) -> Result<(), BenchError> {
    follow(args, Wait::Futex, false)
}

/// The echo child (`futex-echo`, `cacheline-echo`).
pub fn echo_role(args: &BenchArgs, wait: Wait) -> Result<(), BenchError> {
    follow(args, wait, true)
}

/// Waits for each new number on the ping line, records its age after the warm-up, and
/// (`echo`) answers it on the pong line, until STOP.
fn follow(args: &BenchArgs, wait: Wait, echo: bool) -> Result<(), BenchError> {
    let path = args
        .shm
        .as_ref()
        .ok_or_else(|| BenchError::Args("--shm is required for this role".into()))?;
    let deadline = crate::roles::child_deadline(args);
    let shared = Shared::map(path, false)?;
    let page = shared.page();
    let mut oneway = new_histogram()?;
    crate::roles::announce("ready");
    let mut last = 0u32;
    loop {
        let Some((now, seq, stamp)) = await_change(&page.ping, last, wait, deadline) else {
            return Err(BenchError::Timeout {
                what: "the ping side stopped".into(),
                timeout: Duration::from_millis(args.deadline_ms),
            });
        };
        if seq == STOP {
            return crate::roles::write_histogram(args, &oneway);
        }
        if u64::from(seq) > args.warmup {
            oneway.saturating_record(now.saturating_sub(stamp));
        }
        if echo {
            publish(&page.pong, seq, wait);
        }
        last = seq;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The protocol works within one process (two threads): every round answered, and the
    /// echo sees STOP.
    #[test]
    fn both_waits_exchange_in_order() {
        for wait in [Wait::Futex, Wait::Spin] {
            let dir = std::env::temp_dir().join(format!(
                "limber-physical-test-{}-{}",
                std::process::id(),
                wait.key()
            ));
            let _ = std::fs::remove_file(&dir);
            let a = Shared::map(&dir, true).expect("map");
            let deadline = Instant::now() + Duration::from_secs(20);
            let echo = std::thread::scope(|s| {
                let dir = &dir;
                let h = s.spawn(move || {
                    // Mapped a second time, as the echo process does.
                    let b = Shared::map(dir, false).expect("map again");
                    let p = b.page();
                    let mut last = 0;
                    let mut n = 0;
                    loop {
                        let (_, seq, _) = await_change(&p.ping, last, wait, deadline)
                            .expect("ping within the deadline");
                        if seq == STOP {
                            return n;
                        }
                        publish(&p.pong, seq, wait);
                        last = seq;
                        n += 1;
                    }
                });
                let p = a.page();
                for seq in 1..=200u32 {
                    publish(&p.ping, seq, wait);
                    let (_, got, stamp) = await_change(&p.pong, seq - 1, wait, deadline)
                        .expect("pong within the deadline");
                    assert_eq!(got, seq);
                    assert!(stamp > 0);
                }
                publish(&p.ping, STOP, wait);
                h.join().expect("echo thread")
            });
            assert_eq!(echo, 200, "{wait:?}");
            std::fs::remove_file(&dir).expect("remove");
        }
    }
}
