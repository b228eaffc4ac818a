//! The child side: what this executable does when started with the hidden `--role`.
//!
//! | role | scenario | what it does |
//! |---|---|---|
//! | `futex-echo` / `cacheline-echo` | floor | no middleware: a shared page, `FUTEX_WAIT`/`FUTEX_WAKE` or spinning |
//! | `pubsub-echo` | floor | raw iceoryx2: spins on the ping topic, answers on the pong topic |
//! | `pubsub-state-echo` | floor | the same, publishing a state sample on a third topic before each answer |
//! | `event-echo` | floor | the same, blocking on an event listener, notifying back |
//! | `waitset-echo` | floor | the same, blocking in a WaitSet with the listener attached |
//! | `state-pub` | state | a `DeviceHost` publishing the arm state at 1 kHz after `go` |
//! | `state-sub` | state | an `ActArrayClient` blocking in `wait_state`, recording one-way latency |
//! | `fanout-sub` | state | raw iceoryx2: a subscriber blocking on an event listener (the fan-out's floor) |
//! | `futex-fanout-sub` | state | no middleware: a waiter in `FUTEX_WAIT` on a shared page (the fan-out's physical floor) |
//! | `cmd-driver-spin` / `cmd-driver-event` | command | a `DeviceHost` driver, busy-polling or in `event_loop::run` |
//! | `pioneer-driver` | request, loop | the emulator on a pty and the Pioneer driver on it |
//! | `pioneer-driver-spin` | loop | the same, the driver busy-polling |
//! | `{uds,tcp}-echo-{spin,blocking}` | peers | a socket echo with the same bytes |
//! | `zenoh-echo` | bridge | raw Zenoh: a pong for each ping, a reply for each query |
//! | `many-simarm` | many | simarm serving `--device`'s robot, its loop periods to `--out` at `quit` |
//! | `many-pioneer` | many | the emulator on a pty at its 100 ms cycle and the Pioneer driver on it, the same |
//! | `many-ticker` | many | limber's event loop on a 10 ms timer, no device: the floor of the drivers' loops |
//! | `lang-rust` | lang | the Rust client: state reads and command round trips, its samples to `--out` as the C and Python clients write theirs |

use std::io::Write;
use std::time::{Duration, Instant};

use iceoryx2::prelude::*;
use limber_pioneer::LoopMode;
use limber_services::Domain;

use crate::scenario::{command, floor, many_drivers, peers, physical, state};
use crate::{BenchArgs, BenchError};

/// Runs `role`; on failure prints `error: <why>` on stdout for the parent, and returns it.
pub fn run_role(role: &str, args: &BenchArgs) -> Result<(), BenchError> {
    match args.cpu {
        Some(cpu) => pin_to(cpu),
        // A pinned parent's affinity is inherited: give unpinned children every core.
        None => unpin(),
    }
    let r = match role {
        "futex-echo" => physical::echo_role(args, physical::Wait::Futex),
        physical::FANOUT_ROLE => physical::fanout_role(args),
        "cacheline-echo" => physical::echo_role(args, physical::Wait::Spin),
        "pubsub-echo" => floor::echo_role(args, floor::Echo::Spin),
        "pubsub-state-echo" => floor::echo_role(args, floor::Echo::SpinState),
        "event-echo" => floor::echo_role(args, floor::Echo::Listener),
        "waitset-echo" => floor::echo_role(args, floor::Echo::WaitSet),
        "state-pub" => state::publisher_role(args),
        "state-sub" => state::subscriber_role(args),
        crate::scenario::fanout_floor::ROLE => crate::scenario::fanout_floor::subscriber_role(args),
        "pioneer-driver" => crate::scenario::request::driver_role(args, LoopMode::Event),
        "pioneer-driver-spin" => crate::scenario::request::driver_role(args, LoopMode::Spin),
        "cmd-driver-spin" => command::driver_role(args, true),
        "cmd-driver-event" => command::driver_role(args, false),
        "uds-echo-spin" => peers::echo_role(args, peers::Transport::Uds, true),
        "uds-echo-blocking" => peers::echo_role(args, peers::Transport::Uds, false),
        "tcp-echo-spin" => peers::echo_role(args, peers::Transport::Tcp, true),
        "tcp-echo-blocking" => peers::echo_role(args, peers::Transport::Tcp, false),
        "zenoh-echo" => crate::scenario::zenoh_floor::echo_role(args),
        crate::scenario::lang::RUST_ROLE => crate::scenario::lang::rust_role(args),
        many_drivers::SIMARM_ROLE => many_drivers::simarm_role(args),
        many_drivers::PIONEER_ROLE => many_drivers::pioneer_role(args),
        many_drivers::TICKER_ROLE => many_drivers::ticker_role(args),
        other => Err(BenchError::Args(format!("unknown role {other:?}"))),
    };
    if let Err(e) = &r {
        announce(&format!("error: {e}"));
    }
    r
}

/// Pins the calling thread to core `cpu` (ignored if impossible). Any online core: not
/// only those of the inherited affinity (a pinned parent's children inherit its one
/// core).
pub fn pin_to(cpu: usize) {
    if cpu >= rustix::thread::CpuSet::MAX_CPU {
        tracing::warn!("no CPU {cpu}: running unpinned");
        return;
    }
    let mut set = rustix::thread::CpuSet::new();
    set.set(cpu);
    if let Err(e) = rustix::thread::sched_setaffinity(None, &set) {
        tracing::warn!("cannot pin to CPU {cpu} ({e}): running unpinned");
    }
}

/// Allows the calling thread to run on every online core.
pub fn unpin() {
    // Every CPU the set can name: the kernel ignores those that are not online (and
    // `available_parallelism` would count only the CPUs this thread is pinned to).
    let mut set = rustix::thread::CpuSet::new();
    for cpu in 0..rustix::thread::CpuSet::MAX_CPU {
        set.set(cpu);
    }
    if let Err(e) = rustix::thread::sched_setaffinity(None, &set) {
        tracing::warn!("cannot unpin this process: {e}");
    }
}

/// Prints a line for the parent and flushes.
pub fn announce(line: &str) {
    let mut out = std::io::stdout().lock();
    let _ = writeln!(out, "{line}");
    let _ = out.flush();
}

/// The child's domain.
pub fn child_domain(args: &BenchArgs) -> Result<Domain, BenchError> {
    let name = args
        .domain
        .as_deref()
        .ok_or_else(|| BenchError::Args("--domain is required for this role".into()))?;
    Domain::new(name).map_err(|e| BenchError::Args(e.to_string()))
}

/// The child's deadline, from now.
pub fn child_deadline(args: &BenchArgs) -> Instant {
    Instant::now() + Duration::from_millis(args.deadline_ms)
}

/// Writes the child's histogram where the parent expects it.
pub fn write_histogram(
    args: &BenchArgs,
    h: &hdrhistogram::Histogram<u64>,
) -> Result<(), BenchError> {
    let path = args
        .out
        .as_ref()
        .ok_or_else(|| BenchError::Args("--out is required for this role".into()))?;
    write_histogram_to(path, h)
}

/// Writes `h` to `path`, for the parent's [`crate::child::read_histogram`].
pub fn write_histogram_to(
    path: &std::path::Path,
    h: &hdrhistogram::Histogram<u64>,
) -> Result<(), BenchError> {
    let bytes = crate::stats::serialize(h)?;
    std::fs::write(path, bytes).map_err(|e| BenchError::io(path.display().to_string(), e))
}

/// A raw iceoryx2 node in `domain` (no signal handling: the parent kills children).
pub fn raw_node(domain: &Domain) -> Result<Node<ipc::Service>, BenchError> {
    set_log_level_from_env_or(LogLevel::Error);
    let config = domain
        .config()
        .map_err(|e| BenchError::transport("preparing the domain's files", e))?;
    let node = NodeBuilder::new()
        .config(config)
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(|e| BenchError::transport("creating an iceoryx2 node", e))?;
    if let Ok(prefix) = domain.prefix() {
        let group = domain.group().ok().flatten();
        limber_services::domain_dir::secure_shm(prefix, group)
            .map_err(|e| BenchError::transport("securing the domain's node counter", e))?;
    }
    Ok(node)
}

/// Lines from stdin, read by a thread (so that waiting for them has a timeout).
pub fn stdin_lines() -> std::sync::mpsc::Receiver<String> {
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        use std::io::BufRead;
        for l in std::io::stdin().lock().lines() {
            match l {
                Ok(l) => {
                    if tx.send(l).is_err() {
                        break;
                    }
                }
                Err(_) => break,
            }
        }
    });
    rx
}

/// Starts the emulator on a pty with `emulator` and the Pioneer driver on it with `config`,
/// the emulator's thread on `--emulator-cpu` and the driver's on `--cpu` when given (a
/// thread starts with its creator's affinity: the emulator's is created on its own core,
/// then this thread goes back to the driver's).
pub fn start_emulated_pioneer(
    args: &BenchArgs,
    ctx: &limber_services::Context,
    emulator: limber_emulator::EmulatorConfig,
    config: limber_pioneer::PioneerConfig,
) -> Result<(limber_emulator::Emulator, limber_pioneer::PioneerDriver), BenchError> {
    if let Some(cpu) = args.emulator_cpu {
        pin_to(cpu);
    }
    let emu = limber_emulator::Emulator::start_pty(emulator);
    match (args.emulator_cpu, args.cpu) {
        (None, _) => {}
        (Some(_), Some(cpu)) => pin_to(cpu),
        (Some(_), None) => unpin(),
    }
    let emu = emu.map_err(|e| BenchError::Transport {
        context: "emulator".into(),
        reason: e.to_string(),
    })?;
    let driver = limber_pioneer::PioneerDriver::start_with(
        ctx,
        config,
        emu.link_target(),
        limber_pioneer::StartOptions { simulated: true },
    )
    .map_err(|e| BenchError::Transport {
        context: "pioneer driver".into(),
        reason: e.to_string(),
    })?;
    if !driver.hardware().arm {
        return Err(BenchError::Transport {
            context: "pioneer driver".into(),
            reason: "the emulated robot has no arm".into(),
        });
    }
    Ok((emu, driver))
}
