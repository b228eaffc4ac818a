#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

mod model;
mod server;

pub use limber_p2os::{ArmpacLayout, GripperByteLayout};
pub use model::{
    AUTOPARK_DEFAULT_S, ModelConfig, ObjectPlacement, Robot, RobotState, SyncStage, Timing,
    default_arm_info,
};

use limber_p2os::LinkTarget;
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};
use thiserror::Error;

/// Errors of the emulator.
#[derive(Debug, Error)]
pub enum EmulatorError {
    /// The pty pair could not be created.
    #[error("cannot create a pty pair: {0}")]
    Pty(#[from] serialport::Error),
    /// The TCP port could not be bound.
    #[error("cannot listen on {addr}: {source}")]
    Bind {
        /// The address.
        addr: SocketAddr,
        /// The cause.
        source: std::io::Error,
    },
    /// An I/O error in the emulator thread or the CLI.
    #[error("emulator I/O error: {0}")]
    Io(#[from] std::io::Error),
    /// The emulator thread died unexpectedly.
    #[error("emulator thread failed: {0}")]
    Thread(String),
    /// Bad command-line arguments.
    #[error("invalid arguments: {0}")]
    Args(String),
}

/// Fault injection knobs; all off by default. Probabilities are in 0..=1.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Faults {
    /// Probability that an outgoing byte is dropped.
    pub drop_rate: f64,
    /// Probability that an outgoing byte has a bit flipped.
    pub corrupt_rate: f64,
    /// Probability that an outgoing packet carries a wrong checksum.
    pub bad_checksum_rate: f64,
    /// Probability that 1..16 random bytes go out before a packet.
    pub garbage_rate: f64,
    /// Go silent: send nothing and ignore everything received (a dead robot).
    pub silent: bool,
    /// Slow wire: after each packet, wait the time it takes at this baud
    /// (10 bits per byte).
    pub slow_wire_baud: Option<u32>,
    /// Drop this many ARMINFOpac replies (counted from the emulator's start, across
    /// connections; see [`EmulatorStats::arm_info_dropped`]): a deterministic "lost
    /// ARM_INFO reply". Raising it later drops that many in all.
    pub drop_arm_info_replies: u32,
    /// Never answer CONFIG (18), like a controller or simulator that does not implement
    /// it: the CONFIGpacs are dropped ([`EmulatorStats::config_dropped`]).
    pub no_config: bool,
    /// Stop reading the wire, still talking (a controller whose input hangs): what the
    /// client sends stays in the pty or socket until its buffer is full. A new TCP
    /// client is not accepted meanwhile.
    pub deaf: bool,
}

/// Configuration of an emulator.
#[derive(Debug, Clone)]
pub struct EmulatorConfig {
    /// The robot.
    pub model: ModelConfig,
    /// Controller cycle (SIP period), 100 ms by default.
    pub cycle: Duration,
    /// pty only: answer only when the line is set to this baud (a robot
    /// configured for one rate). `None` answers at any rate.
    pub baud: Option<u32>,
    /// Initial faults.
    pub faults: Faults,
    /// Seed of the fault generator.
    pub seed: u64,
    /// When packets go out: like the controller (default) or at once.
    pub timing: Timing,
    /// Like the simulator: after this long without any command (PULSE
    /// counts) the controller stops streaming and forgets the client, who
    /// must sync again. `None` (the default) disables it.
    pub watchdog: Option<Duration>,
}

impl EmulatorConfig {
    /// The default configuration in [`Timing::Fast`] (immediate replies).
    pub fn fast() -> EmulatorConfig {
        EmulatorConfig {
            timing: Timing::Fast,
            ..EmulatorConfig::default()
        }
    }
}

impl Default for EmulatorConfig {
    fn default() -> Self {
        EmulatorConfig {
            model: ModelConfig::default(),
            cycle: Duration::from_millis(100),
            baud: None,
            faults: Faults::default(),
            seed: 0x5EED,
            timing: Timing::Controller,
            watchdog: None,
        }
    }
}

/// Counters of the emulator's wire side.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct EmulatorStats {
    /// Bytes received.
    pub bytes_in: u64,
    /// Bytes written.
    pub bytes_out: u64,
    /// Packets written (before byte-level faults).
    pub packets_out: u64,
    /// SIPs written.
    pub sips_out: u64,
    /// ARMpacs written.
    pub arm_packets_out: u64,
    /// Received commands with a bad checksum (dropped silently, like a real
    /// controller).
    pub bad_checksums_in: u64,
    /// Bytes dropped by fault injection.
    pub bytes_dropped: u64,
    /// Bytes corrupted by fault injection.
    pub bytes_corrupted: u64,
    /// Packets sent with a wrong checksum by fault injection.
    pub bad_checksums_out: u64,
    /// Garbage bytes inserted by fault injection.
    pub garbage_out: u64,
    /// Bytes ignored because the pty was at the wrong baud.
    pub wrong_baud_bytes: u64,
    /// TCP clients accepted.
    pub connections: u64,
    /// TCP clients refused because another client was connected (one client at a time,
    /// like a P2OS simulator): each was closed at once, before any reply.
    pub refused_clients: u64,
    /// Times the command watchdog stopped the stream.
    pub watchdog_trips: u64,
    /// ARMINFOpac replies dropped by [`Faults::drop_arm_info_replies`].
    pub arm_info_dropped: u64,
    /// ARMINFOpac replies written (not dropped).
    pub arm_info_out: u64,
    /// CONFIGpac replies dropped by [`Faults::no_config`].
    pub config_dropped: u64,
}

/// A snapshot of the emulator.
#[derive(Debug, Clone, PartialEq)]
pub struct EmulatorState {
    /// The robot.
    pub robot: RobotState,
    /// Wire counters.
    pub stats: EmulatorStats,
    /// A client is connected (TCP), or the pty is open on our side.
    pub connected: bool,
}

struct Control {
    faults: Faults,
    disconnect: bool,
    object: Option<Option<ObjectPlacement>>,
}

struct Shared {
    stop: AtomicBool,
    control: Mutex<Control>,
    state: Mutex<EmulatorState>,
}

fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|e| e.into_inner())
}

/// A running emulator (background thread). Dropping it stops the thread.
pub struct Emulator {
    shared: Arc<Shared>,
    thread: Option<JoinHandle<Result<(), EmulatorError>>>,
    pty_path: Option<PathBuf>,
    tcp_addr: Option<SocketAddr>,
}

impl std::fmt::Debug for Emulator {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Emulator")
            .field("pty_path", &self.pty_path)
            .field("tcp_addr", &self.tcp_addr)
            .finish()
    }
}

impl Emulator {
    /// Starts an emulator on a new pty pair; connect to [`Emulator::pty_path`].
    pub fn start_pty(config: EmulatorConfig) -> Result<Emulator, EmulatorError> {
        let ep = server::Endpoint::pty()?;
        Self::spawn(config, ep)
    }

    /// Starts an emulator listening on TCP `bind` (port 0 = ephemeral; see
    /// [`Emulator::tcp_addr`]). One client at a time; a new connection
    /// replaces the old one.
    pub fn start_tcp(config: EmulatorConfig, bind: SocketAddr) -> Result<Emulator, EmulatorError> {
        let ep = server::Endpoint::tcp(bind)?;
        Self::spawn(config, ep)
    }

    fn spawn(config: EmulatorConfig, ep: server::Endpoint) -> Result<Emulator, EmulatorError> {
        let pty_path = ep.pty_path();
        let tcp_addr = ep.tcp_addr();
        let mut robot = Robot::new(config.model.clone(), Instant::now());
        robot.set_timing(config.timing);
        robot.set_controller(config.cycle, config.watchdog);
        let shared = Arc::new(Shared {
            stop: AtomicBool::new(false),
            control: Mutex::new(Control {
                faults: config.faults.clone(),
                disconnect: false,
                object: None,
            }),
            state: Mutex::new(EmulatorState {
                robot: robot.state(),
                stats: EmulatorStats::default(),
                connected: pty_path.is_some(),
            }),
        });
        let s2 = Arc::clone(&shared);
        let thread = std::thread::Builder::new()
            .name("p2os-emulator".into())
            .spawn(move || server::run(config, ep, robot, s2))?;
        Ok(Emulator {
            shared,
            thread: Some(thread),
            pty_path,
            tcp_addr,
        })
    }

    /// The pty device to open (pty emulators).
    pub fn pty_path(&self) -> Option<&Path> {
        self.pty_path.as_deref()
    }

    /// The TCP address listened on (TCP emulators).
    pub fn tcp_addr(&self) -> Option<SocketAddr> {
        self.tcp_addr
    }

    /// Where a [`limber_p2os::Link`] should connect.
    pub fn link_target(&self) -> LinkTarget {
        match (&self.pty_path, self.tcp_addr) {
            (Some(p), _) => LinkTarget::Serial(p.clone()),
            (None, Some(a)) => LinkTarget::Tcp(a.to_string()),
            (None, None) => LinkTarget::Tcp(String::new()),
        }
    }

    /// Replaces the fault settings.
    pub fn set_faults(&self, faults: Faults) {
        lock(&self.shared.control).faults = faults;
    }

    /// The current fault settings.
    pub fn faults(&self) -> Faults {
        lock(&self.shared.control).faults.clone()
    }

    /// Drops the connection: closes the TCP client, or closes the pty (the
    /// device goes away for good, like an unplugged cable).
    pub fn disconnect(&self) {
        lock(&self.shared.control).disconnect = true;
    }

    /// Places (or with `None` removes) the simulated object in front of the
    /// gripper.
    pub fn set_object(&self, object: Option<ObjectPlacement>) {
        lock(&self.shared.control).object = Some(object);
    }

    /// A snapshot of the state (refreshed by the emulator thread each time
    /// it wakes, at least every few ms).
    pub fn state(&self) -> EmulatorState {
        lock(&self.shared.state).clone()
    }

    /// Polls the state until `pred` holds or `timeout` passes; returns the
    /// last state seen and whether `pred` held.
    pub fn wait_for(
        &self,
        timeout: Duration,
        mut pred: impl FnMut(&EmulatorState) -> bool,
    ) -> (bool, EmulatorState) {
        let deadline = limber_p2os::sys::deadline(timeout);
        loop {
            let s = self.state();
            if pred(&s) {
                return (true, s);
            }
            if Instant::now() >= deadline {
                return (false, s);
            }
            std::thread::sleep(Duration::from_millis(2));
        }
    }

    /// The emulator thread is still running.
    pub fn is_running(&self) -> bool {
        self.thread.as_ref().is_some_and(|t| !t.is_finished())
    }

    /// Stops the thread and reports how it ended.
    pub fn stop(mut self) -> Result<(), EmulatorError> {
        self.shutdown()
    }

    fn shutdown(&mut self) -> Result<(), EmulatorError> {
        self.shared.stop.store(true, Ordering::SeqCst);
        match self.thread.take() {
            Some(t) => match t.join() {
                Ok(r) => r,
                Err(_) => Err(EmulatorError::Thread("the emulator thread panicked".into())),
            },
            None => Ok(()),
        }
    }
}

impl Drop for Emulator {
    fn drop(&mut self) {
        // `stop` reports how the thread ended; dropped without it, the log does.
        if let Err(e) = self.shutdown() {
            tracing::warn!(error = %e, "the emulator ended with an error");
        }
    }
}
