//! Link supervision: reading the robot's packets into the model, writing the model's
//! outbox, silence and write failures, reconnection on a thread of its own, ARM_INFO
//! retries and an arm that appears late.

use std::sync::mpsc::{self, TryRecvError};
use std::time::{Duration, Instant};

use limber_p2os::{
    ArmStatusMode, Command, ConfigProbe, ConnectError, ConnectOptions, Connection, LinkError,
    LinkTarget,
};

use super::serve::flush;
use super::{
    ARM_DEVICES, BODY_DEVICES, DRIVER, Failure, PioneerDriver, gripper_decision, hardware_bits,
};
use crate::config::{BodyGripper, PioneerConfig};
use crate::robot::PacketEffect;

/// The handshake's options from the configuration.
pub(super) fn options(cfg: &PioneerConfig, target: &LinkTarget) -> ConnectOptions {
    let mut o = ConnectOptions {
        arm_info_timeout: Duration::from_millis(cfg.arm_info_timeout_ms),
        pulse_interval: Duration::from_millis(cfg.pulse_interval_ms),
        arm_status: ArmStatusMode::Continuous,
        // What the robot has: asked at start (the reconnections keep what was decided).
        config: true,
        config_timeout: Duration::from_millis(cfg.arm_info_timeout_ms),
        config_attempts: if cfg.body_gripper == BodyGripper::Auto {
            3
        } else {
            1
        },
        ..ConnectOptions::default()
    };
    if let (Some(b), LinkTarget::Serial(_)) = (cfg.baud, target) {
        o.baud_rates = vec![b];
    }
    o
}

/// Longest wait between two ARM_INFO retries of the loop.
const ARM_PROBE_MAX: Duration = Duration::from_secs(30);

/// ARM_INFO retries of the loop, while the link is up but no ARMINFOpac answered the
/// handshake's: sent from the timer (never waited for), the reply is read by
/// [`PioneerDriver::read_link`]; the wait doubles after each, up to [`ARM_PROBE_MAX`].
#[derive(Debug, Clone, Copy)]
pub(super) struct ArmProbe {
    next: Instant,
    delay: Duration,
    sent: u32,
}

impl ArmProbe {
    pub(super) fn new(now: Instant, first: Duration) -> Self {
        let delay = first.clamp(Duration::from_millis(10), ARM_PROBE_MAX);
        ArmProbe {
            next: now + delay,
            delay,
            sent: 0,
        }
    }
}

/// Longest wait between two reconnection attempts while the endpoint is held by another
/// client.
const TAKEN_BACKOFF_MAX: Duration = Duration::from_secs(10);

/// How often a robot that stays away is logged again.
const RECONNECT_LOG_EVERY: Duration = Duration::from_secs(10);

/// Failed reconnection attempts: the first is logged at once, then one line at most every
/// [`RECONNECT_LOG_EVERY`] with the count since. While the endpoint is held by another
/// client (a TCP server of one client at a time closed the connection before the
/// handshake), the wait before the next attempt doubles, up to [`TAKEN_BACKOFF_MAX`]:
/// the other client is left alone.
#[derive(Debug, Default)]
pub(super) struct ReconnectLog {
    failed: u64,
    unlogged: u64,
    last_logged: Option<Instant>,
    taken_backoff: Option<Duration>,
}

impl ReconnectLog {
    /// Notes a failed attempt; returns how long to wait before the next one (zero: the
    /// configured interval) and whether it was logged.
    fn failed(&mut self, port: &str, e: &ConnectError, now: Instant) -> (Duration, bool) {
        self.failed += 1;
        let wait = if matches!(e, ConnectError::ClosedBeforeSync) {
            let w = self
                .taken_backoff
                .map_or(Duration::from_secs(1), |w| (w * 2).min(TAKEN_BACKOFF_MAX));
            self.taken_backoff = Some(w);
            w
        } else {
            self.taken_backoff = None;
            Duration::ZERO
        };
        let due = self
            .last_logged
            .is_none_or(|t| now.duration_since(t) >= RECONNECT_LOG_EVERY);
        if due {
            let retry = if wait.is_zero() {
                String::new()
            } else {
                format!("; the endpoint is held by another client: next attempt in {wait:?}")
            };
            tracing::warn!(
                "reconnecting to {port} failed ({} attempts so far, {} since the last \
                 report): {e}{retry}",
                self.failed,
                self.unlogged + 1
            );
            self.last_logged = Some(now);
            self.unlogged = 0;
        } else {
            self.unlogged += 1;
        }
        (wait, due)
    }

    fn succeeded(&mut self) {
        *self = ReconnectLog::default();
    }
}

impl PioneerDriver {
    /// Sets the arm's autopark watchdog (AUTOPARK, `autopark_s`), at every connection: a
    /// driver that dies without a word (SIGKILL) leaves the arm to park itself.
    pub(super) fn set_autopark(&mut self) {
        if !self.hardware.arm {
            return;
        }
        let s = self.robot.cfg.autopark_s;
        if let Err(status) = self.send_internal(&Command::ArmAutoPark(s)) {
            tracing::warn!("cannot set the arm's autopark watchdog to {s} s: {status}");
        }
    }

    /// Starts the ARM_INFO retries (the first after `arm_info_timeout_ms`).
    pub(super) fn start_arm_probe(&mut self, now: Instant) {
        let first = Duration::from_millis(self.robot.cfg.arm_info_timeout_ms);
        self.arm_probe = Some(ArmProbe::new(now, first));
    }

    /// Sends the next ARM_INFO retry when due (the timer's work; the reply is read by
    /// `read_link`). Returns false when the link failed.
    pub(super) fn probe_arm(&mut self, now: Instant) -> bool {
        let Some(p) = self.arm_probe.as_mut() else {
            return true;
        };
        if now < p.next {
            return true;
        }
        let Some(conn) = self.conn.as_mut() else {
            return true;
        };
        if let Err(e) = conn.send(&Command::ArmInfo) {
            tracing::warn!("cannot send ARM_INFO: {e}");
            return false;
        }
        p.sent += 1;
        p.next = now + p.delay;
        p.delay = (p.delay * 2).min(ARM_PROBE_MAX);
        true
    }

    /// An ARMINFOpac arrived in the loop (an answer to a retry, or a late answer).
    pub(super) fn on_arm_info(&mut self) {
        let Some(p) = self.arm_probe.take() else {
            return;
        };
        if self.hardware.arm {
            // The reconnection's handshake stopped the ARMpac stream when it got no
            // answer: start it again.
            if let Err(status) = self.send_internal(&Command::ArmStatus(ArmStatusMode::Continuous))
            {
                tracing::warn!("cannot restart the ARMpac stream: {status}");
            }
            tracing::info!(
                "ARMINFOpac received after {} retries: arm calibration and status stream restored",
                p.sent
            );
            self.robot.dirty.arm = true;
        } else {
            self.arm_appeared(p.sent);
        }
    }

    /// The robot answered ARM_INFO after the driver started without an arm: offer the
    /// arm's devices now (the loop takes their wake listeners), start the ARMpac stream,
    /// power the arm and set its autopark watchdog, as at a start with an arm.
    fn arm_appeared(&mut self, retries: u32) {
        let robot = self.robot.cfg.robot.clone();
        if let Err(e) = self.hosts.add(&self.ctx, &robot, DRIVER, &ARM_DEVICES) {
            tracing::error!(
                "the robot answers ARM_INFO now (after {retries} retries), but its arm cannot \
                 be offered: {e}"
            );
            return;
        }
        // The joints, the end effector and the arm's gripper: one lease holds them.
        if let Err(e) = self.hosts.share_lease(&ARM_DEVICES) {
            tracing::error!("the arm's devices cannot share one lease: {e}");
        }
        self.devices_added = true;
        self.hardware.arm = true;
        self.stats.hardware = hardware_bits(&self.hardware);
        for cmd in [
            Command::ArmStatus(ArmStatusMode::Continuous),
            Command::ArmPower(true),
        ] {
            if let Err(status) = self.send_internal(&cmd) {
                tracing::warn!("cannot set up the arm that appeared ({cmd:?}): {status}");
            }
        }
        self.set_autopark();
        self.robot.dirty.arm = true;
        tracing::info!(
            "the robot answers ARM_INFO now (after {retries} retries): serving {robot}/actarray/0 \
             (arm), {robot}/limb/0, {robot}/gripper/1 (arm gripper)"
        );
    }

    /// Reads every packet the link has into the model and writes what the model queued
    /// (the next VECMOVE waypoint); returns false when the link failed.
    pub(super) fn read_link(&mut self, now: Instant) -> bool {
        loop {
            let Some(conn) = self.conn.as_mut() else {
                return false;
            };
            let effect = match conn.link_mut().poll_packet() {
                Ok(Some(p)) => self.robot.on_packet(&p, now),
                Ok(None) => break,
                Err(LinkError::Timeout(_)) => break,
                Err(e) => {
                    tracing::warn!("reading the link failed: {e}");
                    return false;
                }
            };
            match effect {
                PacketEffect::Sip => self.timing.sips_this_second += 1,
                PacketEffect::ArmInfo => self.arm_info_arrived = true,
                PacketEffect::None => {}
            }
        }
        // Packets that did not parse (a truncated ARMpac...): dropped by the link, counted
        // and logged here.
        if let Some(conn) = self.conn.as_ref() {
            let malformed = conn.link().stats().malformed;
            let new = malformed.saturating_sub(self.malformed_seen);
            if new > 0 {
                self.malformed_seen = malformed;
                self.robot
                    .note_malformed(new, &"packets that do not parse (dropped)");
            }
        }
        if let Err(status) = flush(&mut self.robot, self.conn.as_mut(), &mut self.timing) {
            // The next waypoint could not be written (the link is failing): the line is
            // abandoned (the model forgot it), never resumed on a later link.
            self.failures.note(Failure::VecMove, &status);
        }
        true
    }

    /// The link failed: closed, the model told (nothing queued is sent later), and a
    /// reconnection due at once.
    pub(super) fn link_failed(&mut self, why: &str) {
        if let Some(conn) = self.conn.take() {
            tracing::warn!("link down ({why}); reconnecting");
            drop(conn);
            self.link_faults += 1;
        }
        let dropped = self.robot.link_down();
        if dropped > 0 {
            tracing::warn!("{dropped} commands not yet written are dropped with the link");
        }
        self.next_reconnect = Instant::now();
        // The retries start again with the next link.
        self.arm_probe = None;
    }

    /// Reconnection, never blocking the loop: the handshake runs on a thread of its own
    /// (it waits for the robot, up to seconds when the robot is silent), which hands the
    /// connection back; the loop takes it at a later tick. Meanwhile requests are answered
    /// and commands refused (LinkDown) as usual.
    pub(super) fn try_reconnect(&mut self) {
        let now = Instant::now();
        if let Some(rx) = self.connecting.as_ref() {
            match rx.try_recv() {
                Err(TryRecvError::Empty) => {}
                Ok(Ok(conn)) => {
                    self.connecting = None;
                    self.reconnect_log.succeeded();
                    self.link_up_again(conn);
                }
                Ok(Err(e)) => {
                    self.connecting = None;
                    let (wait, _) = self.reconnect_log.failed(&self.robot.cfg.port, &e, now);
                    let base = Duration::from_millis(self.robot.cfg.reconnect_interval_ms);
                    self.next_reconnect = now + wait.max(base);
                }
                Err(TryRecvError::Disconnected) => {
                    // The thread ended without an answer (it panicked): try again.
                    self.connecting = None;
                    tracing::error!("the reconnection thread ended without an answer");
                }
            }
            return;
        }
        if now < self.next_reconnect {
            return;
        }
        self.next_reconnect = now + Duration::from_millis(self.robot.cfg.reconnect_interval_ms);
        let mut opts = options(&self.robot.cfg, &self.target);
        opts.sync_attempts = 2;
        // What the robot has, asked again: a robot may come back without its gripper,
        // or with one. Once: an unanswered CONFIG keeps the last decision.
        opts.config = true;
        opts.config_attempts = 1;
        opts.arm = self.hardware.arm;
        // One ARM_INFO in the handshake; if it goes unanswered, the loop asks again
        // without waiting (a bounded backoff), as after a start.
        opts.arm_info_attempts = 1;
        let target = self.target.clone();
        let (tx, rx) = mpsc::sync_channel(1);
        let spawned = std::thread::Builder::new()
            .name("limber-connect".into())
            .spawn(move || {
                let r = Connection::open(&target, &opts);
                // Nobody waits any more (the driver ended): close what was opened.
                if let Err(mpsc::SendError(Ok(conn))) = tx.send(r)
                    && let Err(e) = conn.close()
                {
                    tracing::debug!("closing an unwanted connection: {e}");
                }
            });
        match spawned {
            Ok(_) => self.connecting = Some(rx),
            Err(e) => tracing::error!("cannot start a reconnection thread: {e}"),
        }
    }

    /// What the robot has, asked again at a reconnection: a CONFIGpac decides again
    /// whether the body gripper and lift are served (an unanswered or unreadable one
    /// leaves the last decision). A gripper that appeared is offered (if it was not yet);
    /// one that went has its commands refused UNSUPPORTED.
    fn gripper_again(&mut self, probe: &ConfigProbe) {
        if !matches!(probe, ConfigProbe::Answered(_)) {
            return;
        }
        self.hardware.config = probe.clone();
        let robot = self.robot.cfg.robot.clone();
        let (served, note) = gripper_decision(self.robot.cfg.body_gripper, probe, &robot);
        if served == self.hardware.gripper {
            return;
        }
        if served && !self.gripper_offered {
            if let Err(e) = self.hosts.add(&self.ctx, &robot, DRIVER, &BODY_DEVICES) {
                tracing::error!("{note}, but the devices cannot be offered: {e}");
                return;
            }
            self.devices_added = true;
            self.gripper_offered = true;
        }
        self.hardware.gripper = served;
        self.hardware.gripper_note = note;
        self.stats.hardware = hardware_bits(&self.hardware);
        self.robot.set_body_gripper(served);
        tracing::warn!(
            "what the robot has changed (reconnect #{}): {}",
            self.reconnects,
            self.hardware.gripper_note
        );
    }

    /// Takes a connection the reconnection thread established.
    fn link_up_again(&mut self, conn: Connection) {
        let answered = conn
            .arm_calibration()
            .is_some_and(|cal| self.robot.take_calibration(*cal));
        let config = conn.config().clone();
        self.malformed_seen = conn.link().stats().malformed;
        if let Some(sip) = conn.last_sip() {
            self.robot.set_sip(*sip);
        }
        self.conn = Some(conn);
        // Commands sent before this instant were sent to a dead link: refused. Whatever
        // was commanded before is void; hold where the arm is.
        self.robot.link_up(Instant::now());
        self.set_autopark();
        // An arm that lost contact with its controller reverts to HOME with power off
        // (the vendor's manuals): power it again, as at start.
        if self.hardware.arm
            && let Err(status) = self.send_internal(&Command::ArmPower(true))
        {
            tracing::warn!("cannot power the arm after reconnecting: {status}");
        }
        self.reconnects += 1;
        self.gripper_again(&config);
        tracing::info!("link up again (reconnect #{})", self.reconnects);
        if !answered {
            if self.hardware.arm {
                tracing::warn!(
                    "no ARMINFOpac after reconnect #{}: keeping the last calibration, asking \
                     again in the background",
                    self.reconnects
                );
            }
            self.start_arm_probe(Instant::now());
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn no_sync() -> ConnectError {
        ConnectError::NoSync {
            attempts: 2,
            bauds: Vec::new(),
        }
    }

    #[test]
    fn failed_reconnects_are_logged_at_once_then_at_most_every_ten_seconds() {
        let mut log = ReconnectLog::default();
        let t0 = Instant::now();
        let logged: Vec<bool> = (0..50u32)
            .map(|i| {
                log.failed("tcp://x:1", &no_sync(), t0 + Duration::from_millis(100) * i)
                    .1
            })
            .collect();
        // 5 s of attempts every 100 ms: the first only.
        assert_eq!(logged.iter().filter(|&&l| l).count(), 1);
        assert!(logged[0]);
        assert_eq!(log.unlogged, 49);
        let (_, l) = log.failed("tcp://x:1", &no_sync(), t0 + RECONNECT_LOG_EVERY);
        assert!(l, "not logged again after {RECONNECT_LOG_EVERY:?}");
        assert_eq!((log.unlogged, log.failed), (0, 51));
        log.succeeded();
        let (_, l) = log.failed("tcp://x:1", &no_sync(), t0 + RECONNECT_LOG_EVERY);
        assert!(l, "a new outage is logged at once");
    }

    #[test]
    fn a_held_endpoint_backs_off_doubling_up_to_the_limit() {
        let mut log = ReconnectLog::default();
        let t0 = Instant::now();
        let waits: Vec<Duration> = (0..8)
            .map(|_| {
                log.failed("tcp://x:1", &ConnectError::ClosedBeforeSync, t0)
                    .0
            })
            .collect();
        assert_eq!(waits[0], Duration::from_secs(1));
        assert_eq!(waits[1], Duration::from_secs(2));
        assert!(waits.windows(2).all(|w| w[1] >= w[0]));
        assert_eq!(*waits.last().unwrap(), TAKEN_BACKOFF_MAX);
        // Any other failure: the configured interval again.
        assert_eq!(log.failed("tcp://x:1", &no_sync(), t0).0, Duration::ZERO);
    }
}
