//! The emulator's I/O thread: wire endpoint, fault injection, timing.

use super::model::{Robot, SyncStage, Timing};
use super::{Control, EmulatorConfig, EmulatorError, EmulatorStats, Faults, Shared, lock};
use limber_p2os::sys::wait_readable;
use limber_p2os::{Decoder, Frame, MAX_FRAME, ptype};
use rand::rngs::SmallRng;
use rand::{Rng as _, RngCore as _, SeedableRng};
use serialport::{SerialPort, TTYPort};
use std::io::{self, Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::os::fd::AsRawFd;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

pub(super) enum Endpoint {
    Pty {
        master: Option<TTYPort>,
        // Kept open so the master never sees a hang-up when a client closes.
        slave: Option<TTYPort>,
        path: PathBuf,
    },
    Tcp {
        listener: TcpListener,
        client: Option<TcpStream>,
    },
}

impl Endpoint {
    pub(super) fn pty() -> Result<Endpoint, EmulatorError> {
        let (mut master, slave) = TTYPort::pair()?;
        let path = slave
            .name()
            .map(PathBuf::from)
            .ok_or_else(|| EmulatorError::Thread("the pty has no name".into()))?;
        master.set_timeout(Duration::from_millis(50))?;
        Ok(Endpoint::Pty {
            master: Some(master),
            slave: Some(slave),
            path,
        })
    }

    pub(super) fn tcp(bind: SocketAddr) -> Result<Endpoint, EmulatorError> {
        let listener =
            TcpListener::bind(bind).map_err(|source| EmulatorError::Bind { addr: bind, source })?;
        listener.set_nonblocking(true)?;
        Ok(Endpoint::Tcp {
            listener,
            client: None,
        })
    }

    pub(super) fn pty_path(&self) -> Option<PathBuf> {
        match self {
            Endpoint::Pty { path, .. } => Some(path.clone()),
            Endpoint::Tcp { .. } => None,
        }
    }

    pub(super) fn tcp_addr(&self) -> Option<SocketAddr> {
        match self {
            Endpoint::Pty { .. } => None,
            Endpoint::Tcp { listener, .. } => listener.local_addr().ok(),
        }
    }

    fn connected(&self) -> bool {
        match self {
            Endpoint::Pty { master, .. } => master.is_some(),
            Endpoint::Tcp { client, .. } => client.is_some(),
        }
    }

    fn disconnect(&mut self) {
        match self {
            Endpoint::Pty { master, slave, .. } => {
                *master = None;
                *slave = None;
            }
            Endpoint::Tcp { client, .. } => {
                if let Some(c) = client.take()
                    && let Err(e) = c.shutdown(std::net::Shutdown::Both)
                {
                    // The client may have closed its end already.
                    tracing::debug!(error = %e, "shutting down the emulator's TCP client");
                }
            }
        }
    }

    /// The line's baud rate (pty).
    fn line_baud(&self) -> Option<u32> {
        match self {
            Endpoint::Pty { slave: Some(s), .. } => s.baud_rate().ok(),
            _ => None,
        }
    }

    fn write(&mut self, bytes: &[u8]) -> io::Result<()> {
        match self {
            Endpoint::Pty {
                master: Some(m), ..
            } => m.write_all(bytes),
            Endpoint::Tcp {
                client: Some(c), ..
            } => c.write_all(bytes),
            _ => Ok(()),
        }
    }
}

enum Input {
    Nothing,
    Bytes(usize),
    NewClient,
    Refused,
    Gone,
}

fn wait_input(
    ep: &mut Endpoint,
    buf: &mut [u8],
    timeout: Duration,
    deaf: bool,
) -> io::Result<Input> {
    match ep {
        _ if deaf => {
            std::thread::sleep(timeout);
            Ok(Input::Nothing)
        }
        Endpoint::Pty { master: None, .. } => {
            std::thread::sleep(timeout);
            Ok(Input::Nothing)
        }
        Endpoint::Pty {
            master: Some(m), ..
        } => {
            if wait_readable(&[m.as_raw_fd()], timeout)? == 0 {
                return Ok(Input::Nothing);
            }
            match m.read(buf) {
                Ok(0) => Ok(Input::Nothing),
                Ok(n) => Ok(Input::Bytes(n)),
                Err(e) if is_transient(&e) => Ok(Input::Nothing),
                Err(e) => Err(e),
            }
        }
        Endpoint::Tcp { listener, client } => {
            let fds = [
                listener.as_raw_fd(),
                client.as_ref().map_or(-1, |c| c.as_raw_fd()),
            ];
            let ready = wait_readable(&fds, timeout)?;
            // The connected client first: its last bytes and its end (EOF) are handled
            // before a newcomer is considered.
            if ready & 2 != 0
                && let Some(c) = client.as_mut()
            {
                match c.read(buf) {
                    Ok(0) => {
                        *client = None;
                        return Ok(Input::Gone);
                    }
                    Ok(n) => return Ok(Input::Bytes(n)),
                    Err(e) if is_transient(&e) => {}
                    Err(_) => {
                        *client = None;
                        return Ok(Input::Gone);
                    }
                }
            }
            if ready & 1 != 0 {
                match listener.accept() {
                    // One client at a time, like a P2OS simulator: while one is
                    // connected, a newcomer is closed at once (before any reply), and the
                    // connected client keeps its link.
                    Ok((s, peer)) if client.is_some() => {
                        tracing::info!(%peer, "refusing a second TCP client: one client at a time");
                        if let Err(e) = s.shutdown(std::net::Shutdown::Both) {
                            tracing::debug!(error = %e, "shutting down a refused TCP client");
                        }
                        return Ok(Input::Refused);
                    }
                    Ok((s, _)) => {
                        s.set_nonblocking(false)?;
                        if let Err(e) = s.set_nodelay(true) {
                            tracing::warn!(
                                error = %e,
                                "cannot set TCP_NODELAY on the emulator's client; replies may be delayed"
                            );
                        }
                        s.set_write_timeout(Some(Duration::from_millis(200)))?;
                        *client = Some(s);
                        return Ok(Input::NewClient);
                    }
                    Err(e) if is_transient(&e) => {}
                    Err(e) => return Err(e),
                }
            }
            Ok(Input::Nothing)
        }
    }
}

fn is_transient(e: &io::Error) -> bool {
    matches!(
        e.kind(),
        io::ErrorKind::WouldBlock | io::ErrorKind::TimedOut | io::ErrorKind::Interrupted
    )
}

/// The seeded generator of fault injection.
struct Rng(SmallRng);

impl Rng {
    fn next_u64(&mut self) -> u64 {
        self.0.next_u64()
    }

    fn chance(&mut self, p: f64) -> bool {
        p > 0.0 && self.0.random::<f64>() < p
    }
}

struct Wire {
    rng: Rng,
    stats: EmulatorStats,
}

impl Wire {
    fn send(&mut self, ep: &mut Endpoint, mut frame: Frame, faults: &Faults) -> io::Result<()> {
        if faults.silent || !ep.connected() {
            return Ok(());
        }
        match frame.payload().first() {
            Some(&t) if (ptype::SIP_FIRST..=ptype::SIP_LAST).contains(&t) => {
                self.stats.sips_out += 1
            }
            Some(&ptype::ARM) => self.stats.arm_packets_out += 1,
            Some(&ptype::ARM_INFO) => {
                if self.stats.arm_info_dropped < u64::from(faults.drop_arm_info_replies) {
                    self.stats.arm_info_dropped += 1;
                    return Ok(());
                }
                self.stats.arm_info_out += 1;
            }
            Some(&ptype::CONFIG) if faults.no_config => {
                self.stats.config_dropped += 1;
                return Ok(());
            }
            _ => {}
        }
        self.stats.packets_out += 1;
        if self.rng.chance(faults.bad_checksum_rate) {
            frame.corrupt_checksum();
            self.stats.bad_checksums_out += 1;
        }
        let mut buf = [0u8; 16 + MAX_FRAME];
        let mut n = 0;
        if self.rng.chance(faults.garbage_rate) {
            let k = 1 + (self.rng.next_u64() % 16) as usize;
            for b in &mut buf[..k] {
                *b = self.rng.next_u64() as u8;
            }
            n = k;
            self.stats.garbage_out += k as u64;
        }
        for &b in frame.as_bytes() {
            if self.rng.chance(faults.drop_rate) {
                self.stats.bytes_dropped += 1;
                continue;
            }
            let b = if self.rng.chance(faults.corrupt_rate) {
                self.stats.bytes_corrupted += 1;
                b ^ (1 << (self.rng.next_u64() % 8))
            } else {
                b
            };
            buf[n] = b;
            n += 1;
        }
        ep.write(&buf[..n])?;
        self.stats.bytes_out += n as u64;
        if let Some(baud) = faults.slow_wire_baud.filter(|&b| b > 0) {
            let secs = (n as f64) * 10.0 / f64::from(baud);
            std::thread::sleep(Duration::from_secs_f64(secs));
        }
        Ok(())
    }
}

pub(super) fn run(
    config: EmulatorConfig,
    mut ep: Endpoint,
    mut robot: Robot,
    shared: Arc<Shared>,
) -> Result<(), EmulatorError> {
    let cycle = config
        .cycle
        .clamp(Duration::from_millis(1), Duration::from_secs(86_400));
    let mut decoder = Decoder::new();
    let mut out: Vec<Frame> = Vec::with_capacity(16);
    let mut wire = Wire {
        rng: Rng(SmallRng::seed_from_u64(config.seed)),
        stats: EmulatorStats::default(),
    };
    let mut buf = [0u8; 512];
    let mut next_cycle = Instant::now() + cycle;
    let mut last_command = Instant::now();
    let mut faults;
    while !shared.stop.load(Ordering::SeqCst) {
        {
            let mut c: std::sync::MutexGuard<'_, Control> = lock(&shared.control);
            faults = c.faults.clone();
            if std::mem::take(&mut c.disconnect) {
                ep.disconnect();
                robot.reset_connection();
                decoder.clear();
            }
            if let Some(o) = c.object.take() {
                robot.set_object(o);
            }
        }
        let now = Instant::now();
        let mut wake = next_cycle.min(now + Duration::from_millis(20));
        if let Some(t) = robot.next_event(now) {
            wake = wake.min(t);
        }
        let mut close_after_send = false;
        let input = wait_input(
            &mut ep,
            &mut buf,
            wake.saturating_duration_since(now),
            faults.deaf,
        )?;
        let now = Instant::now();
        match input {
            Input::Nothing => {}
            Input::Refused => wire.stats.refused_clients += 1,
            Input::NewClient => {
                wire.stats.connections += 1;
                robot.reset_connection();
                decoder.clear();
            }
            Input::Gone => {
                robot.reset_connection();
                decoder.clear();
            }
            Input::Bytes(n) => {
                wire.stats.bytes_in += n as u64;
                let wrong_baud = config.baud.is_some_and(|b| ep.line_baud() != Some(b));
                if wrong_baud {
                    wire.stats.wrong_baud_bytes += n as u64;
                } else if !faults.silent {
                    let was_open = robot.stage() == SyncStage::Open;
                    let mut closed = false;
                    decoder.decode(&buf[..n], |p| {
                        last_command = now;
                        robot.handle(p, now, &mut out);
                        closed |= was_open && robot.stage() == SyncStage::NoSync;
                    });
                    wire.stats.bad_checksums_in = decoder.stats().bad_checksums;
                    close_after_send = closed;
                    if !was_open
                        && robot.stage() == SyncStage::Open
                        && config.timing == Timing::Fast
                    {
                        // Fast mode: the first SIP goes out right after OPEN.
                        next_cycle = now;
                    }
                }
            }
        }
        let now = Instant::now();
        if let Some(w) = config.watchdog
            && robot.stage() == SyncStage::Open
            && now.saturating_duration_since(last_command) >= w
        {
            robot.reset_connection();
            wire.stats.watchdog_trips += 1;
        }
        robot.advance(now, &mut out);
        if now >= next_cycle {
            robot.cycle(now, &mut out);
            next_cycle += cycle;
            if next_cycle <= now {
                next_cycle = now + cycle;
            }
        }
        // Publish the state before sending: a client that sees a packet
        // finds the snapshot at least as new.
        publish(&shared, &robot, &wire, &ep);
        for f in out.drain(..) {
            if let Err(e) = wire.send(&mut ep, f, &faults) {
                if matches!(ep, Endpoint::Tcp { .. }) {
                    ep.disconnect();
                    robot.reset_connection();
                } else if !is_transient(&e) {
                    return Err(e.into());
                }
            }
        }
        if close_after_send && matches!(ep, Endpoint::Tcp { .. }) {
            // Like the simulator: CLOSE drops the TCP connection.
            ep.disconnect();
        }
        publish(&shared, &robot, &wire, &ep);
    }
    Ok(())
}

fn publish(shared: &Shared, robot: &Robot, wire: &Wire, ep: &Endpoint) {
    let mut st = lock(&shared.state);
    st.robot = robot.state();
    st.stats = wire.stats;
    st.connected = ep.connected();
}
