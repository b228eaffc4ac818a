//! The connection state machine: sync, OPEN, keep-alive, arm set-up, CLOSE.

use super::command::{ArmStatusMode, Command};
use super::configpac::{ConfigPacket, ConfigPacketError};
use super::convert::ArmCalibration;
use super::link::{Link, LinkError, LinkTarget, OpenError};
use super::packet::{ArmPacket, GripperPacket, RobotIdentity, RobotPacket, Sip, ptype};
use std::os::fd::{AsRawFd, RawFd};
use std::time::{Duration, Instant};
use thiserror::Error;

/// Baud rates tried by the sync, in the reference's order.
pub const BAUD_RATES: [u32; 5] = [9600, 38400, 19200, 115200, 57600];

/// Options of [`Connection::establish`]. Every wait has a timeout.
#[derive(Debug, Clone)]
pub struct ConnectOptions {
    /// Baud rates to try, in order (serial links only).
    pub baud_rates: Vec<u32>,
    /// SYNC0 attempts per baud rate.
    pub sync_attempts: u32,
    /// How long to wait for each sync reply. A real simulator answers in
    /// 100–200 ms, so keep this above 300 ms for real robots.
    pub sync_timeout: Duration,
    /// After CLOSE to a robot still running from an earlier connection, how
    /// long to wait before flushing and syncing again.
    pub close_wait: Duration,
    /// How long to wait for the first SIP after OPEN.
    pub first_sip_timeout: Duration,
    /// Sonar setting sent after OPEN (`None` = leave as is).
    pub sonar: Option<bool>,
    /// Set up the arm: ARM_STATUS and ARM_INFO.
    pub arm: bool,
    /// ARMpac stream mode requested when the arm is set up.
    pub arm_status: ArmStatusMode,
    /// How long to wait for the ARMINFOpac after each ARM_INFO.
    pub arm_info_timeout: Duration,
    /// ARM_INFO attempts (each waiting `arm_info_timeout`) before deciding there is no
    /// arm: one lost reply (a bad checksum) must not remove the arm.
    pub arm_info_attempts: u32,
    /// Send PULSE when nothing was sent for this long ([`Connection::keep_alive`]).
    pub pulse_interval: Duration,
    /// Ask CONFIG (18) after OPEN and read the CONFIGpac: what the robot has
    /// ([`Connection::config`]). Off by default.
    pub config: bool,
    /// How long to wait for the CONFIGpac after each CONFIG.
    pub config_timeout: Duration,
    /// CONFIG attempts before the robot counts as not answering it (one lost reply must
    /// not decide what the robot has).
    pub config_attempts: u32,
}

/// What the CONFIG probe of the handshake found ([`ConnectOptions::config`]).
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub enum ConfigProbe {
    /// CONFIG was not sent.
    #[default]
    NotAsked,
    /// The robot answered with this CONFIGpac.
    Answered(Box<ConfigPacket>),
    /// No CONFIGpac within the timeout, after every attempt.
    Unanswered {
        /// CONFIG commands sent.
        attempts: u32,
    },
    /// The robot answered with a packet of type 0x20 that is not a CONFIGpac limber can
    /// read (after every attempt).
    Malformed(ConfigPacketError),
}

impl Default for ConnectOptions {
    fn default() -> Self {
        ConnectOptions {
            baud_rates: BAUD_RATES.to_vec(),
            sync_attempts: 5,
            sync_timeout: Duration::from_millis(400),
            close_wait: Duration::from_millis(400),
            first_sip_timeout: Duration::from_secs(2),
            sonar: Some(false),
            arm: true,
            arm_status: ArmStatusMode::Continuous,
            arm_info_timeout: Duration::from_secs(1),
            arm_info_attempts: 3,
            pulse_interval: Duration::from_secs(1),
            config: false,
            config_timeout: Duration::from_secs(1),
            config_attempts: 3,
        }
    }
}

/// Why a connection could not be established.
#[derive(Debug, Error)]
pub enum ConnectError {
    /// The link could not be opened.
    #[error(transparent)]
    Open(#[from] OpenError),
    /// No sync at any baud rate (or, over TCP, after all attempts). Over TCP the
    /// message says nothing of baud rates.
    #[error("no sync reply after {attempts} attempts{}", at_bauds(bauds))]
    NoSync {
        /// SYNC0 attempts made.
        attempts: u32,
        /// Baud rates tried (empty over TCP).
        bauds: Vec<u32>,
    },
    /// Over TCP, the other end closed the connection before answering the first SYNC0: a
    /// server of one client at a time (a simulator, the emulator) that serves another
    /// client. (A serial line that closes is [`ConnectError::Link`].)
    #[error(
        "the other end closed the connection before answering SYNC0 (a TCP endpoint that \
         serves one client at a time is held by another client)"
    )]
    ClosedBeforeSync,
    /// Synced, but no SIP arrived after OPEN.
    #[error("no SIP within {0:?} after OPEN")]
    NoSip(Duration),
    /// The link failed (closed, I/O error).
    #[error("link failed during the handshake: {0}")]
    Link(#[from] LinkError),
}

fn at_bauds(bauds: &[u32]) -> String {
    if bauds.is_empty() {
        String::new()
    } else {
        format!(" at baud rates {bauds:?}")
    }
}

/// Why an orderly close failed.
#[derive(Debug, Error)]
pub enum CloseError {
    /// The STOP or CLOSE could not be sent.
    #[error("cannot send the close sequence: {0}")]
    Link(#[from] LinkError),
}

/// An established P2OS connection: the link plus what the handshake learnt
/// and the latest state packets seen.
#[derive(Debug)]
pub struct Connection {
    link: Link,
    identity: RobotIdentity,
    baud: Option<u32>,
    arm: Option<ArmCalibration>,
    last_sip: Option<Sip>,
    last_arm: Option<ArmPacket>,
    last_gripper: Option<GripperPacket>,
    pulse_interval: Duration,
    config: ConfigProbe,
}

enum SyncWait {
    Got(RobotIdentity),
    Timeout,
    Running,
}

fn wait_sync(
    link: &mut Link,
    step: u8,
    timeout: Duration,
    ignore_running: bool,
) -> Result<SyncWait, LinkError> {
    let deadline = crate::sys::deadline(timeout);
    loop {
        let left = deadline.saturating_duration_since(Instant::now());
        let p = match link.recv(left) {
            Ok(p) => p,
            Err(LinkError::Timeout(_)) => return Ok(SyncWait::Timeout),
            Err(e) => return Err(e),
        };
        match p {
            RobotPacket::Sync { step: s, rest } if s == step => {
                let identity = if step == 2 {
                    RobotIdentity::parse(rest)
                } else {
                    RobotIdentity::default()
                };
                return Ok(SyncWait::Got(identity));
            }
            // A stale echo of an earlier step (duplicate SYNC0 replies).
            RobotPacket::Sync { .. } => {}
            _ if !ignore_running => return Ok(SyncWait::Running),
            _ => {}
        }
    }
}

impl Connection {
    /// Opens `target` and establishes the connection.
    pub fn open(target: &LinkTarget, opts: &ConnectOptions) -> Result<Connection, ConnectError> {
        let link = Link::open(target)?;
        Connection::establish(link, opts)
    }

    /// Runs the handshake on an open link: sync (trying the baud rates in
    /// order on a serial link, never over TCP), read the robot's identity,
    /// OPEN, PULSE, wait for the first SIP, set the sonar, if asked read the
    /// CONFIGpac ([`ConnectOptions::config`], [`Connection::config`]), and, if
    /// asked, start the ARMpac stream and read the ARMINFOpac (no answer within
    /// the timeout = no arm).
    pub fn establish(mut link: Link, opts: &ConnectOptions) -> Result<Connection, ConnectError> {
        let (identity, baud) = Self::sync(&mut link, opts)?;
        link.send(&Command::Open)?;
        link.send(&Command::Pulse)?;
        let mut conn = Connection {
            link,
            identity,
            baud,
            arm: None,
            last_sip: None,
            last_arm: None,
            last_gripper: None,
            pulse_interval: opts.pulse_interval,
            config: ConfigProbe::NotAsked,
        };
        let got_sip = conn.wait_until(opts.first_sip_timeout, |p| matches!(p, RobotPacket::Sip(_)));
        match got_sip {
            Ok(()) => {}
            Err(LinkError::Timeout(_)) => return Err(ConnectError::NoSip(opts.first_sip_timeout)),
            Err(e) => return Err(e.into()),
        }
        if let Some(on) = opts.sonar {
            conn.send(&Command::Sonar(on))?;
        }
        if opts.config {
            conn.config = conn.probe_config(opts.config_timeout, opts.config_attempts)?;
        }
        if opts.arm {
            conn.send(&Command::ArmStatus(opts.arm_status))?;
            let attempts = opts.arm_info_attempts.max(1);
            for attempt in 1..=attempts {
                if conn.request_arm_info(opts.arm_info_timeout)?.is_some() {
                    break;
                }
                if attempt < attempts {
                    tracing::debug!(
                        "no ARMINFOpac within {:?} (attempt {attempt} of {attempts}); asking again",
                        opts.arm_info_timeout
                    );
                }
            }
            if conn.arm.is_none() && opts.arm_status != ArmStatusMode::Stop {
                conn.send(&Command::ArmStatus(ArmStatusMode::Stop))?;
            }
        }
        Ok(conn)
    }

    fn sync(
        link: &mut Link,
        opts: &ConnectOptions,
    ) -> Result<(RobotIdentity, Option<u32>), ConnectError> {
        let bauds: Vec<Option<u32>> = if link.is_serial() {
            opts.baud_rates.iter().copied().map(Some).collect()
        } else {
            vec![None]
        };
        let mut close_sent = false;
        let mut attempts = 0;
        let mut answered = false;
        // Over TCP only: a serial line that closes is a device gone, not a held endpoint.
        let tcp = !link.is_serial();
        let closed_early = |e: LinkError, answered: bool| match e {
            LinkError::Closed if tcp && !answered => ConnectError::ClosedBeforeSync,
            e => ConnectError::Link(e),
        };
        for baud in bauds {
            if let Some(b) = baud {
                link.set_baud_rate(b)?;
                link.flush_input()?;
            }
            for _ in 0..opts.sync_attempts.max(1) {
                attempts += 1;
                link.send(&Command::Sync0)
                    .map_err(|e| closed_early(e, answered))?;
                match wait_sync(link, 0, opts.sync_timeout, close_sent)
                    .map_err(|e| closed_early(e, answered))?
                {
                    SyncWait::Got(_) => answered = true,
                    SyncWait::Timeout => continue,
                    SyncWait::Running => {
                        // Still running from an earlier connection: CLOSE once.
                        answered = true;
                        close_sent = true;
                        link.send(&Command::Close)?;
                        std::thread::sleep(opts.close_wait);
                        link.flush_input()?;
                        continue;
                    }
                }
                link.send(&Command::Sync1)?;
                if !matches!(
                    wait_sync(link, 1, opts.sync_timeout, true)?,
                    SyncWait::Got(_)
                ) {
                    continue;
                }
                link.send(&Command::Sync2)?;
                if let SyncWait::Got(id) = wait_sync(link, 2, opts.sync_timeout, true)? {
                    return Ok((id, baud));
                }
            }
        }
        Err(ConnectError::NoSync {
            attempts,
            bauds: if link.is_serial() {
                opts.baud_rates.clone()
            } else {
                Vec::new()
            },
        })
    }

    /// Sends CONFIG and waits up to `timeout` for the CONFIGpac (other packets are
    /// recorded meanwhile), up to `attempts` times while nothing readable arrives.
    pub fn probe_config(
        &mut self,
        timeout: Duration,
        attempts: u32,
    ) -> Result<ConfigProbe, LinkError> {
        let attempts = attempts.max(1);
        let mut last = ConfigProbe::Unanswered { attempts };
        for attempt in 1..=attempts {
            self.send(&Command::Config)?;
            let mut got = None;
            let r = self.wait_until(timeout, |p| match p {
                RobotPacket::Other {
                    packet_type: ptype::CONFIG,
                    payload,
                } => {
                    got = Some(ConfigPacket::parse(payload));
                    true
                }
                _ => false,
            });
            match (r, got) {
                (Ok(()), Some(Ok(c))) => return Ok(ConfigProbe::Answered(Box::new(c))),
                (Ok(()), Some(Err(e))) => {
                    tracing::warn!("unreadable CONFIGpac (attempt {attempt} of {attempts}): {e}");
                    last = ConfigProbe::Malformed(e);
                }
                (Err(LinkError::Timeout(_)), _) | (Ok(()), None) => {
                    tracing::debug!(
                        "no CONFIGpac within {timeout:?} (attempt {attempt} of {attempts})"
                    );
                }
                (Err(e), _) => return Err(e),
            }
        }
        Ok(last)
    }

    /// What the handshake's CONFIG probe found ([`ConnectOptions::config`]).
    pub fn config(&self) -> &ConfigProbe {
        &self.config
    }

    /// Sends ARM_INFO and waits up to `timeout` for the ARMINFOpac (other
    /// packets are recorded meanwhile). `Ok(None)` = no answer (no arm).
    pub fn request_arm_info(
        &mut self,
        timeout: Duration,
    ) -> Result<Option<ArmCalibration>, LinkError> {
        self.send(&Command::ArmInfo)?;
        match self.wait_until(timeout, |p| matches!(p, RobotPacket::ArmInfo(_))) {
            Ok(()) => Ok(self.arm),
            Err(LinkError::Timeout(_)) => Ok(None),
            Err(e) => Err(e),
        }
    }

    /// The robot's name, class and subclass from the SYNC2 reply.
    pub fn identity(&self) -> &RobotIdentity {
        &self.identity
    }

    /// The baud rate the sync succeeded at (`None` over TCP).
    pub fn baud_rate(&self) -> Option<u32> {
        self.baud
    }

    /// The arm calibration (`None`: no arm, or no ARMINFOpac yet).
    pub fn arm_calibration(&self) -> Option<&ArmCalibration> {
        self.arm.as_ref()
    }

    /// The latest SIP received.
    pub fn last_sip(&self) -> Option<&Sip> {
        self.last_sip.as_ref()
    }

    /// The latest ARMpac received.
    pub fn last_arm(&self) -> Option<&ArmPacket> {
        self.last_arm.as_ref()
    }

    /// The latest 0xE0 gripper packet received.
    pub fn last_gripper(&self) -> Option<&GripperPacket> {
        self.last_gripper.as_ref()
    }

    /// The link (counters, raw fd).
    pub fn link(&self) -> &Link {
        &self.link
    }

    /// The link, mutably (for an event loop that reads it directly; call
    /// [`Connection::observe`] with each packet to keep the state here).
    pub fn link_mut(&mut self) -> &mut Link {
        &mut self.link
    }

    /// Gives the link back.
    pub fn into_link(self) -> Link {
        self.link
    }

    /// Sends a command.
    pub fn send(&mut self, cmd: &Command) -> Result<(), LinkError> {
        self.link.send(cmd)
    }

    /// Sends PULSE if nothing was sent for the pulse interval. Returns
    /// whether it sent one.
    pub fn keep_alive(&mut self) -> Result<bool, LinkError> {
        let due = self
            .link
            .last_send()
            .is_none_or(|t| t.elapsed() >= self.pulse_interval);
        if due {
            self.link.send(&Command::Pulse)?;
        }
        Ok(due)
    }

    /// Records a packet's state (latest SIP, ARMpac, calibration).
    pub fn observe(&mut self, p: &RobotPacket<'_>) {
        Self::record(
            p,
            &mut self.last_sip,
            &mut self.last_arm,
            &mut self.arm,
            &mut self.last_gripper,
        );
    }

    fn record(
        p: &RobotPacket<'_>,
        sip: &mut Option<Sip>,
        arm: &mut Option<ArmPacket>,
        cal: &mut Option<ArmCalibration>,
        grip: &mut Option<GripperPacket>,
    ) {
        match p {
            RobotPacket::Sip(s) => *sip = Some(*s),
            RobotPacket::Arm(a) => *arm = Some(*a),
            RobotPacket::ArmInfo(i) => *cal = Some(ArmCalibration::from(*i)),
            RobotPacket::Gripper(g) => *grip = Some(*g),
            _ => {}
        }
    }

    /// Waits up to `timeout` for the next packet, records its state and
    /// returns it. Sends keep-alive PULSEs while waiting.
    pub fn recv(&mut self, timeout: Duration) -> Result<RobotPacket<'_>, LinkError> {
        self.keep_alive()?;
        let p = self.link.recv(timeout)?;
        Self::record(
            &p,
            &mut self.last_sip,
            &mut self.last_arm,
            &mut self.arm,
            &mut self.last_gripper,
        );
        Ok(p)
    }

    /// Nonblocking, for an event loop woken by the fd ([`AsRawFd`]): the
    /// next packet if one is complete (at most one read), with its state
    /// recorded. Does not send keep-alives: call [`Connection::keep_alive`]
    /// from the loop's timer.
    pub fn poll(&mut self) -> Result<Option<RobotPacket<'_>>, LinkError> {
        let p = self.link.poll_packet()?;
        if let Some(p) = &p {
            Self::record(
                p,
                &mut self.last_sip,
                &mut self.last_arm,
                &mut self.arm,
                &mut self.last_gripper,
            );
        }
        Ok(p)
    }

    /// Receives packets until `pred` accepts one, at most `timeout` in all
    /// ([`LinkError::Timeout`] otherwise). Keeps the connection alive.
    pub fn wait_until(
        &mut self,
        timeout: Duration,
        mut pred: impl FnMut(&RobotPacket<'_>) -> bool,
    ) -> Result<(), LinkError> {
        let deadline = crate::sys::deadline(timeout);
        loop {
            let now = Instant::now();
            if now >= deadline {
                return Err(LinkError::Timeout(timeout));
            }
            // Wake at least every pulse interval to keep the link alive.
            let step = (deadline - now).min(self.pulse_interval);
            match self.recv(step) {
                Ok(p) => {
                    if pred(&p) {
                        return Ok(());
                    }
                }
                Err(LinkError::Timeout(_)) => {}
                Err(e) => return Err(e),
            }
        }
    }

    /// Orderly shutdown: stop the ARMpac stream (if the arm was set up),
    /// STOP, CLOSE.
    pub fn close(mut self) -> Result<(), CloseError> {
        if self.arm.is_some() {
            self.link.send(&Command::ArmStatus(ArmStatusMode::Stop))?;
        }
        self.link.send(&Command::Stop)?;
        self.link.send(&Command::Close)?;
        Ok(())
    }
}

impl AsRawFd for Connection {
    fn as_raw_fd(&self) -> RawFd {
        self.link.as_raw_fd()
    }
}
