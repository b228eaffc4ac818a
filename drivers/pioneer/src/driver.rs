//! The driver process: one thread that owns the link, serves the devices and recovers from
//! link faults.

use core::ops::ControlFlow;
use std::sync::mpsc::{self, Receiver, TryRecvError};
use std::time::{Duration, Instant};

use limber_interfaces::diagnostics::{self, DriverStats, hardware, loop_mode};
use limber_interfaces::prelude::*;
use limber_services::diagnostics::StatsPublisher;
use limber_services::event_loop::{self, FdSource, LoopExit, Wake};
use limber_services::{
    Context, DeviceSet, DeviceSetHandler, Drain, HostError, Motion, Origin, monotonic_ns,
};
use thiserror::Error;

use limber_p2os::{
    ArmStatusMode, Command, ConfigProbe, ConnectError, ConnectOptions, Connection, LinkError,
    LinkTarget, RobotIdentity, RobotPacket,
};

use super::config::{BodyGripper, PioneerConfig};
use crate::robot::RobotModel;

/// The driver could not start or failed.
#[derive(Debug, Error)]
pub enum DriverError {
    /// The first connection to the robot failed (nothing is served).
    #[error("cannot connect to the robot at {port}: {source}")]
    Connect {
        /// The port.
        port: String,
        /// The cause.
        source: limber_p2os::ConnectError,
    },
    /// A device could not be offered.
    #[error(transparent)]
    Host(#[from] HostError),
    /// A running driver already serves devices of this robot name: refused before the
    /// link is opened, so the other driver's link is left alone.
    #[error(
        "robot {robot} is already served in domain {domain} by a running driver ({}); \
         choose another robot name",
        devices.join(", ")
    )]
    AlreadyServed {
        /// The robot name.
        robot: String,
        /// The domain.
        domain: String,
        /// The devices a live driver serves.
        devices: Vec<String>,
    },
    /// The domain's devices could not be listed (to check the robot name is free).
    #[error("cannot check that robot {robot} is free: {source}")]
    List {
        /// The robot name.
        robot: String,
        /// The cause.
        source: limber_services::ListError,
    },
    /// The configured robot name does not make valid device names.
    #[error("invalid robot name {robot:?}: {source}")]
    RobotName {
        /// The name from the configuration.
        robot: String,
        /// Why it is invalid.
        source: limber_services::NameError,
    },
    /// The statistics channel could not be offered.
    #[error("cannot offer the driver statistics: {0}")]
    Stats(#[source] limber_services::diagnostics::DiagnosticsError),
    /// The event loop failed.
    #[error("event loop: {0}")]
    Loop(#[source] limber_services::event_loop::LoopError),
}

/// How the loop waits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LoopMode {
    /// Event-driven: a WaitSet on the link, the clients and a timer.
    #[default]
    Event,
    /// Busy-polling (take a whole core; pin it with `--cpu`).
    Spin,
}

/// Options of a driver run.
#[derive(Debug, Clone, Copy, Default)]
pub struct RunOptions {
    /// How the loop waits.
    pub mode: LoopMode,
}

/// What the robot turned out to have.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Hardware {
    /// The robot's identity (SYNC2).
    pub identity: RobotIdentity,
    /// ARM_INFO was answered.
    pub arm: bool,
    /// The body gripper and lift are served: the robot's CONFIGpac said so, or the
    /// configuration's `body_gripper = true` ([`gripper_decision`]).
    pub gripper: bool,
    /// Why the body gripper and lift are (not) served, in a sentence for the log.
    pub gripper_note: String,
    /// What the CONFIG probe at start found.
    pub config: ConfigProbe,
}

/// Whether to serve the body gripper and its lift, from the configuration's
/// `body_gripper` and the CONFIG probe, with the sentence that says why (`robot`: the
/// robot name in device names). Safe by default: `auto` serves them only when the robot's
/// CONFIGpac says a gripper is fitted; `true` serves them whatever the robot says (the
/// user knows the robot; a CONFIGpac saying "none" is warned of, and the commands then
/// reach a controller that ignores them); `false` never does.
pub fn gripper_decision(setting: BodyGripper, probe: &ConfigProbe, robot: &str) -> (bool, String) {
    let devices = format!("{robot}/gripper/0 (body gripper) and {robot}/actarray/1 (lift)");
    let says = match probe {
        ConfigProbe::Answered(c) => Some(c.has_gripper()),
        _ => None,
    };
    let unanswered = match probe {
        ConfigProbe::Unanswered { attempts } => {
            format!("the robot did not answer CONFIG (18) ({attempts} attempts)")
        }
        ConfigProbe::Malformed(e) => format!("the robot's CONFIGpac is unreadable ({e})"),
        ConfigProbe::NotAsked => "CONFIG (18) was not asked".into(),
        ConfigProbe::Answered(_) => String::new(),
    };
    match (setting, says) {
        (BodyGripper::Auto, Some(true)) => (
            true,
            format!("the robot's CONFIGpac says a gripper is fitted: serving {devices}"),
        ),
        (BodyGripper::Auto, Some(false)) => (
            false,
            format!("the robot's CONFIGpac says no gripper is fitted: not serving {devices}"),
        ),
        (BodyGripper::Auto, None) => (
            false,
            format!(
                "{unanswered}: not serving {devices}; if the robot has the body gripper, set \
                 body_gripper = true in the configuration (false to silence this warning)"
            ),
        ),
        (BodyGripper::Fitted, Some(false)) => (
            true,
            format!(
                "body_gripper = true: serving {devices} although the robot's CONFIGpac says no \
                 gripper is fitted; its commands are sent to the robot, which may ignore them"
            ),
        ),
        (BodyGripper::Fitted, _) => (true, format!("body_gripper = true: serving {devices}")),
        (BodyGripper::Absent, Some(true)) => (
            false,
            format!(
                "body_gripper = false: not serving {devices} although the robot's CONFIGpac \
                 says a gripper is fitted"
            ),
        ),
        (BodyGripper::Absent, _) => (
            false,
            format!("body_gripper = false: not serving {devices}"),
        ),
    }
}

/// The driver's name in device attributes and statistics.
const DRIVER: &str = "pioneer";

/// The devices of the arm: `actarray/0`, `limb/0` and the arm gripper `gripper/1`.
const ARM_DEVICES: [(InterfaceKind, u16); 3] = [
    (InterfaceKind::ActArray, 0),
    (InterfaceKind::Limb, 0),
    (InterfaceKind::Gripper, 1),
];

/// [`DriverStats::hardware`]: what the robot has, and what the driver looked for and
/// found missing (`NO_*`, shown by `limber list` and the CLI's "no driver" message).
fn hardware_bits(hw: &Hardware) -> u32 {
    let arm = if hw.arm {
        hardware::ARM
    } else {
        hardware::NO_ARM
    };
    let body = if hw.gripper {
        hardware::GRIPPER | hardware::LIFT
    } else {
        hardware::NO_GRIPPER | hardware::NO_LIFT
    };
    arm | body
}

fn origin_internal() -> Origin {
    Origin {
        client_id: 0,
        seq: 0,
        sent_ns: 0,
        received_ns: 0,
    }
}

fn options(cfg: &PioneerConfig, target: &LinkTarget) -> ConnectOptions {
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

/// The Pioneer driver: serves `<robot>/actarray/0` (arm), `<robot>/limb/0`,
/// `<robot>/gripper/0` (body gripper), `<robot>/gripper/1` (arm gripper) and
/// `<robot>/actarray/1` (lift), and `<robot>/driver/0` (statistics). The arm's devices only
/// if the robot answers ARM_INFO; the body gripper's and the lift only if it has them
/// ([`gripper_decision`]).
pub struct PioneerDriver {
    ctx: Context,
    target: LinkTarget,
    robot: RobotModel,
    hosts: DeviceSet,
    stats_pub: StatsPublisher,
    stats: DriverStats,
    hardware: Hardware,
    reconnects: u64,
    link_faults: u64,
    next_reconnect: Instant,
    last_stats: Instant,
    last_cleanup: Instant,
    mode: LoopMode,
    wakeups: u64,
    tick_found_work: u64,
    /// A clients' wake-up came since the last tick.
    woken_since_tick: bool,
    /// Ticks in a row that found work without any wake-up in between.
    deaf_ticks: u32,
    failures: Failures,
    arm_probe: Option<ArmProbe>,
    arm_info_arrived: bool,
    connecting: Option<Receiver<Result<Connection, ConnectError>>>,
    reconnect_log: ReconnectLog,
    devices_added: bool,
}

/// Longest wait between two ARM_INFO retries of the loop.
const ARM_PROBE_MAX: Duration = Duration::from_secs(30);

/// Ticks in a row that find clients' work without a wake-up before the driver warns that
/// wake-ups are lost.
const DEAF_TICKS: u32 = 20;

/// ARM_INFO retries of the loop, while the link is up but no ARMINFOpac answered the
/// handshake's: sent from the timer (never waited for), the reply is read by
/// [`PioneerDriver::read_link`]; the wait doubles after each, up to [`ARM_PROBE_MAX`].
#[derive(Debug, Clone, Copy)]
struct ArmProbe {
    next: Instant,
    delay: Duration,
    sent: u32,
}

impl ArmProbe {
    fn new(now: Instant, first: Duration) -> Self {
        let delay = first.clamp(Duration::from_millis(10), ARM_PROBE_MAX);
        ArmProbe {
            next: now + delay,
            delay,
            sent: 0,
        }
    }
}

/// A failure the loop survives (it is retried on the next cycle or the next event).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Failure {
    /// Publishing a state or the statistics.
    Publish,
    /// Receiving a device's commands or requests.
    Process,
    /// Writing the next VECMOVE waypoint.
    VecMove,
}

/// Counts the failures the loop survives and logs them: each kind at its first
/// occurrence and then at powers of two, so a persistent fault is visible without
/// flooding the log.
#[derive(Debug, Default)]
struct Failures {
    counts: [u64; 3],
}

impl Failures {
    fn note(&mut self, kind: Failure, cause: &dyn std::fmt::Display) {
        let n = &mut self.counts[kind as usize];
        *n += 1;
        if n.is_power_of_two() {
            tracing::warn!("{kind:?} failed ({} so far): {cause}", *n);
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
struct ReconnectLog {
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

impl core::fmt::Debug for PioneerDriver {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("PioneerDriver")
            .field("hardware", &self.hardware)
            .finish()
    }
}

// The handler of every device: borrows the robot model for the duration of a `process`
// call. `actarray/0` is the arm, `actarray/1` the lift, `gripper/0` the body gripper and
// `gripper/1` the arm gripper.
struct Serve<'a>(&'a mut RobotModel);

impl DeviceSetHandler for Serve<'_> {
    fn actarray_motion(&mut self, index: u16, cmd: &ActArrayCommand, _s: &ActArrayData) -> Motion {
        if index == 0 {
            self.0.arm_motion(cmd)
        } else {
            self.0.lift_motion()
        }
    }
    fn actarray_stop(&mut self, index: u16, _s: &mut ActArrayData) -> Status {
        if index == 0 {
            self.0.arm_stop()
        } else {
            self.0.lift_stop()
        }
    }
    fn limb_motion(&mut self, _index: u16, cmd: &LimbCommand, _s: &LimbData) -> Motion {
        self.0.limb_motion(cmd)
    }
    fn limb_stop(&mut self, _index: u16, _s: &mut LimbData) -> Status {
        self.0.arm_stop()
    }
    fn gripper_motion(&mut self, index: u16, _cmd: &GripperCommand, _s: &GripperData) -> Motion {
        if index == 0 {
            self.0.gripper_motion()
        } else {
            self.0.armgrip_motion()
        }
    }
    fn gripper_stop(&mut self, index: u16, _s: &mut GripperData) -> Status {
        if index == 0 {
            self.0.gripper_stop()
        } else {
            self.0.armgrip_stop()
        }
    }
    fn actarray_command(
        &mut self,
        index: u16,
        cmd: &ActArrayCommand,
        from: &Origin,
        s: &mut ActArrayData,
    ) -> Status {
        if index == 0 {
            self.0.arm_command(cmd, from)
        } else {
            let st = self.0.lift_command(cmd, from);
            self.0.lift_state(s);
            st
        }
    }
    fn actarray_request(
        &mut self,
        index: u16,
        req: &ActArrayRequest,
        from: &Origin,
        _s: &mut ActArrayData,
    ) -> Result<ActArrayReply, Status> {
        if index == 0 {
            self.0.arm_request(req, from)
        } else {
            self.0.lift_request(req)
        }
    }
    fn limb_command(
        &mut self,
        _index: u16,
        cmd: &LimbCommand,
        from: &Origin,
        s: &mut LimbData,
    ) -> Status {
        let st = self.0.limb_command(cmd, from);
        self.0.limb_state(s, Instant::now());
        st
    }
    fn limb_request(
        &mut self,
        _index: u16,
        req: &LimbRequest,
        from: &Origin,
        _s: &mut LimbData,
    ) -> Result<LimbReply, Status> {
        self.0.limb_request(req, from)
    }
    fn gripper_command(
        &mut self,
        index: u16,
        cmd: &GripperCommand,
        from: &Origin,
        _s: &mut GripperData,
    ) -> Status {
        if index == 0 {
            self.0.gripper_command(cmd, from)
        } else {
            self.0.armgrip_command(cmd, from)
        }
    }
    fn gripper_request(
        &mut self,
        index: u16,
        _req: &GripperRequest,
        _from: &Origin,
        _s: &mut GripperData,
    ) -> Result<GripperReply, Status> {
        let geom = if index == 0 {
            gripper_geom(&self.0.cfg.gripper, 2)
        } else {
            gripper_geom(&self.0.cfg.arm_gripper, 0)
        };
        Ok(GripperReply::Geom(geom))
    }
}

fn gripper_geom(g: &super::config::GripperGeometry, beams: u32) -> GripperGeom {
    GripperGeom {
        pose: Pose3 {
            position: Vec3::new(g.pose[0], g.pose[1], g.pose[2]),
            orientation: Orientation3 {
                roll: g.pose[3],
                pitch: g.pose[4],
                yaw: g.pose[5],
            },
        },
        outer_size: Bbox3 {
            width: g.outer[0],
            length: g.outer[1],
            height: g.outer[2],
        },
        inner_size: Bbox3 {
            width: g.inner[0],
            length: g.inner[1],
            height: g.inner[2],
        },
        num_beams: beams,
        capacity: 0,
    }
}

impl PioneerDriver {
    /// Connects to the robot (the handshake, the arm calibration; no arm within the
    /// timeout means no arm), then offers the devices the robot has.
    pub fn start(
        ctx: &Context,
        cfg: PioneerConfig,
        target: LinkTarget,
    ) -> Result<Self, DriverError> {
        Self::check_name_free(ctx, &cfg.robot)?;
        let conn = Connection::open(&target, &options(&cfg, &target)).map_err(|source| {
            DriverError::Connect {
                port: cfg.port.clone(),
                source,
            }
        })?;
        let mut model = RobotModel::new(cfg.clone());
        let (gripper, gripper_note) = gripper_decision(cfg.body_gripper, conn.config(), &cfg.robot);
        let hardware = Hardware {
            identity: conn.identity().clone(),
            arm: conn.arm_calibration().is_some(),
            gripper,
            gripper_note,
            config: conn.config().clone(),
        };
        let surprising = match (cfg.body_gripper, conn.config()) {
            (BodyGripper::Auto, ConfigProbe::Answered(_)) => false,
            (BodyGripper::Auto, _) => true,
            (BodyGripper::Fitted, ConfigProbe::Answered(c)) => !c.has_gripper(),
            (BodyGripper::Absent, ConfigProbe::Answered(c)) => c.has_gripper(),
            _ => false,
        };
        if surprising {
            tracing::warn!("{}", hardware.gripper_note);
        } else {
            tracing::info!("{}", hardware.gripper_note);
        }
        if let Some(cal) = conn.arm_calibration() {
            model.set_calibration(*cal);
        }
        if let Some(sip) = conn.last_sip() {
            model.sip = Some(*sip);
        }
        model.conn = Some(conn);
        model.link_up_since_ns = monotonic_ns();
        model.last_rx = Instant::now();

        let robot = cfg.robot.as_str();
        let mut serve = Vec::new();
        if hardware.arm {
            serve.extend(ARM_DEVICES);
        }
        if hardware.gripper {
            serve.extend([(InterfaceKind::Gripper, 0), (InterfaceKind::ActArray, 1)]);
        }
        let hosts = DeviceSet::new(ctx, robot, DRIVER, &serve)?;
        let stats_pub = StatsPublisher::new(ctx, robot).map_err(DriverError::Stats)?;
        let mut stats = DriverStats::default();
        diagnostics::put_text(&mut stats.driver, DRIVER);
        diagnostics::put_text(&mut stats.robot_name, &hardware.identity.name);
        diagnostics::put_text(&mut stats.robot_class, &hardware.identity.class);
        diagnostics::put_text(&mut stats.robot_subclass, &hardware.identity.subclass);
        stats.hardware = hardware_bits(&hardware);
        let mut d = PioneerDriver {
            ctx: ctx.clone(),
            target,
            robot: model,
            hosts,
            stats_pub,
            stats,
            hardware,
            reconnects: 0,
            link_faults: 0,
            next_reconnect: Instant::now(),
            last_stats: Instant::now() - Duration::from_secs(10),
            last_cleanup: Instant::now(),
            mode: LoopMode::Event,
            wakeups: 0,
            tick_found_work: 0,
            woken_since_tick: false,
            deaf_ticks: 0,
            failures: Failures::default(),
            arm_probe: None,
            arm_info_arrived: false,
            connecting: None,
            reconnect_log: ReconnectLog::default(),
            devices_added: false,
        };
        if !d.hardware.arm {
            tracing::warn!(
                "no ARMINFOpac after {} ARM_INFO requests: serving no arm; asking again in the \
                 background",
                options(&d.robot.cfg, &d.target).arm_info_attempts
            );
            d.start_arm_probe(Instant::now());
        }
        // Like Player when the first client subscribes: power the arm. (Left on at exit:
        // an unpowered arm drops under gravity.)
        if d.hardware.arm
            && let Err(status) = d.robot.send(&Command::ArmPower(true), &origin_internal())
        {
            tracing::warn!("cannot power the arm at start: {status}");
        }
        d.set_autopark();
        d.robot.dirty.arm = true;
        d.robot.dirty.body = true;
        d.publish_all(Instant::now());
        Ok(d)
    }

    /// Refuses a robot name whose devices a live driver serves, before the link is opened.
    fn check_name_free(ctx: &Context, robot: &str) -> Result<(), DriverError> {
        let devices: Vec<String> = limber_services::list_devices(ctx.domain())
            .map_err(|source| DriverError::List {
                robot: robot.to_string(),
                source,
            })?
            .into_iter()
            .filter(|d| d.alive && d.name.robot() == robot)
            .map(|d| d.name.to_string())
            .collect();
        if devices.is_empty() {
            Ok(())
        } else {
            Err(DriverError::AlreadyServed {
                robot: robot.to_string(),
                domain: ctx.domain().name().to_string(),
                devices,
            })
        }
    }

    /// Sets the arm's autopark watchdog (AUTOPARK, `autopark_s`), at every connection: a
    /// driver that dies without a word (SIGKILL) leaves the arm to park itself.
    fn set_autopark(&mut self) {
        if !self.hardware.arm {
            return;
        }
        let s = self.robot.cfg.autopark_s;
        if let Err(status) = self
            .robot
            .send(&Command::ArmAutoPark(s), &origin_internal())
        {
            tracing::warn!("cannot set the arm's autopark watchdog to {s} s: {status}");
        }
    }

    fn start_arm_probe(&mut self, now: Instant) {
        let first = Duration::from_millis(self.robot.cfg.arm_info_timeout_ms);
        self.arm_probe = Some(ArmProbe::new(now, first));
    }

    /// Sends the next ARM_INFO retry when due (the timer's work; the reply is read by
    /// `read_link`). Returns false when the link failed.
    fn probe_arm(&mut self, now: Instant) -> bool {
        let Some(p) = self.arm_probe.as_mut() else {
            return true;
        };
        if now < p.next {
            return true;
        }
        let Some(conn) = self.robot.conn.as_mut() else {
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
    fn on_arm_info(&mut self) {
        let Some(p) = self.arm_probe.take() else {
            return;
        };
        if self.hardware.arm {
            // The reconnection's handshake stopped the ARMpac stream when it got no
            // answer: start it again.
            if let Err(status) = self.robot.send(
                &Command::ArmStatus(ArmStatusMode::Continuous),
                &origin_internal(),
            ) {
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
        self.devices_added = true;
        self.hardware.arm = true;
        self.stats.hardware = hardware_bits(&self.hardware);
        let o = origin_internal();
        for cmd in [
            Command::ArmStatus(ArmStatusMode::Continuous),
            Command::ArmPower(true),
        ] {
            if let Err(status) = self.robot.send(&cmd, &o) {
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

    /// What the robot has.
    pub fn hardware(&self) -> &Hardware {
        &self.hardware
    }

    /// The arm as the last ARMpac described it, read in the configured layout: servo power
    /// and the moving bits (joint i = bit i). `None` before the first ARMpac.
    pub fn arm_status(&self) -> Option<(bool, u8)> {
        let a = &self.robot.arm;
        a.seen.then_some((a.powered, a.moving))
    }

    /// ARMpacs received whose status bytes make sense only in the other layout than the
    /// configured `armpac_layout` (the first one is logged as a warning).
    pub fn armpac_layout_mismatches(&self) -> u64 {
        self.robot.arm.layout_mismatches
    }

    /// Samples published by all devices, states and commands' outcomes (each costs
    /// iceoryx2 one small allocation, see `tests/tests/alloc.rs`), and statistics samples.
    pub fn samples_published(&self) -> u64 {
        let h = self.hosts.stats();
        self.stats.header.seq + h.published + h.outcomes
    }

    /// The loop's timing: periods, jitter, command-to-wire latencies.
    pub fn loop_stats(&self) -> &crate::stats::LoopStats {
        &self.robot.stats
    }

    /// True while the link is up.
    pub fn link_up(&self) -> bool {
        self.robot.conn.is_some()
    }

    fn flags(&self) -> u32 {
        let mut f = 0;
        if self.robot.conn.is_some() {
            f |= device_flag::LINK_UP;
        }
        if self.robot.cal.is_some() {
            f |= device_flag::CALIBRATED;
        }
        f
    }

    /// Publishes the devices whose state changed, and the statistics once a second.
    fn publish_all(&mut self, now: Instant) {
        let flags = self.flags();
        let robot = &mut self.robot;
        let failures = &mut self.failures;
        if robot.dirty.arm {
            if let Some(h) = self.hosts.actarray_mut(0) {
                h.set_flags(flags);
                robot.arm_state(h.state_mut(), now);
                if let Err(e) = h.publish() {
                    failures.note(Failure::Publish, &e);
                }
            }
            if let Some(h) = self.hosts.limb_mut(0) {
                h.set_flags(flags);
                robot.limb_state(h.state_mut(), now);
                if let Err(e) = h.publish() {
                    failures.note(Failure::Publish, &e);
                }
            }
            if let Some(h) = self.hosts.gripper_mut(1) {
                h.set_flags(flags);
                robot.armgrip_state(h.state_mut(), now);
                if let Err(e) = h.publish() {
                    failures.note(Failure::Publish, &e);
                }
            }
            robot.dirty.arm = false;
        }
        if robot.dirty.body {
            robot.lift_from_sip(now);
            if let Some(h) = self.hosts.gripper_mut(0) {
                h.set_flags(flags & device_flag::LINK_UP);
                robot.gripper_state(h.state_mut());
                h.state_mut().header.stamp_ns = monotonic_ns();
                if let Err(e) = h.publish() {
                    failures.note(Failure::Publish, &e);
                }
            }
            if let Some(h) = self.hosts.actarray_mut(1) {
                h.set_flags(flags & device_flag::LINK_UP);
                robot.lift_state(h.state_mut());
                h.state_mut().header.stamp_ns = monotonic_ns();
                if let Err(e) = h.publish() {
                    failures.note(Failure::Publish, &e);
                }
            }
            robot.dirty.body = false;
        }
        if now.duration_since(self.last_stats) >= Duration::from_secs(1) {
            self.last_stats = now;
            self.publish_stats();
        }
    }

    fn publish_stats(&mut self) {
        let s = &mut self.stats;
        let ls = &self.robot.stats;
        s.header.flags = if self.robot.conn.is_some() {
            device_flag::LINK_UP
        } else {
            0
        };
        s.loop_mode = match self.mode {
            LoopMode::Event => loop_mode::EVENT,
            LoopMode::Spin => loop_mode::SPIN,
        };
        s.cycles = ls.cycles;
        s.overruns = ls.overruns;
        (s.period_p50_ns, s.period_p99_ns, s.period_max_ns) = ls.period.summary();
        s.jitter_p99_ns = ls.jitter.summary().1;
        (
            s.cmd_to_wire_p50_ns,
            s.cmd_to_wire_p99_ns,
            s.cmd_to_wire_max_ns,
        ) = ls.cmd_to_wire.summary();
        s.sips_per_s = ls.sips_per_s;
        if let Some(c) = self.robot.conn.as_ref() {
            let st = c.link().stats();
            s.bytes_in = st.decoder.bytes_in;
            s.bytes_out = st.bytes_out;
            s.packets_in = st.decoder.packets_ok;
            s.bad_checksums = st.decoder.bad_checksums;
            s.resync_bytes = st.decoder.garbage_bytes;
        }
        s.reconnects = self.reconnects;
        s.link_faults = self.link_faults;
        let st = self.hosts.stats();
        s.commands = st.commands;
        s.refused = st.refused;
        s.requests = st.requests;
        s.cmd_overflows = st.overflows;
        if let Err(e) = self.stats_pub.publish(s) {
            self.failures.note(Failure::Publish, &e);
        }
    }

    /// Handles the pending commands and requests of every device, the way `how` says;
    /// returns whether there was any.
    fn process_clients(&mut self, how: Drain) -> bool {
        let mut handler = Serve(&mut self.robot);
        let r = self.hosts.process_as(&mut handler, how);
        match r {
            Ok(a) => a.commands + a.requests > 0,
            Err(e) => {
                self.failures.note(Failure::Process, &e);
                false
            }
        }
    }

    /// Reads every packet the link has; returns false when the link failed.
    fn read_link(&mut self, now: Instant) -> bool {
        let robot = &mut self.robot;
        let failures = &mut self.failures;
        loop {
            let Some(conn) = robot.conn.as_mut() else {
                return false;
            };
            let pkt = match conn.link_mut().poll_packet() {
                Ok(Some(p)) => Owned::from(&p),
                Ok(None) => return true,
                Err(LinkError::Timeout(_)) => return true,
                Err(e) => {
                    tracing::warn!("reading the link failed: {e}");
                    return false;
                }
            };
            robot.last_rx = now;
            match pkt {
                Owned::Sip(s) => {
                    robot.sip = Some(s);
                    robot.dirty.body = true;
                    robot.stats.sips_this_second += 1;
                }
                Owned::Arm(a) => {
                    robot.arm.update(&a, robot.cfg.armpac_layout, now);
                    robot.dirty.arm = true;
                    if let Err(status) = robot.stream_vecmove(&origin_internal()) {
                        // The next waypoint could not be written (the link is failing):
                        // the line is abandoned, never resumed on a later link.
                        robot.vecmove = None;
                        failures.note(Failure::VecMove, &status);
                    }
                }
                Owned::ArmInfo(i) => {
                    robot.set_calibration(limber_p2os::ArmCalibration::from(i));
                    self.arm_info_arrived = true;
                }
                Owned::Other => {}
            }
        }
    }

    fn link_failed(&mut self, why: &str) {
        if let Some(conn) = self.robot.conn.take() {
            tracing::warn!("link down ({why}); reconnecting");
            drop(conn);
            self.link_faults += 1;
        }
        self.robot.vecmove = None;
        self.robot.dirty.arm = true;
        self.robot.dirty.body = true;
        self.next_reconnect = Instant::now();
        // The retries start again with the next link.
        self.arm_probe = None;
    }

    /// Reconnection, never blocking the loop: the handshake runs on a thread of its own
    /// (it waits for the robot, up to seconds when the robot is silent), which hands the
    /// connection back; the loop takes it at a later tick. Meanwhile requests are answered
    /// and commands refused (LinkDown) as usual.
    fn try_reconnect(&mut self) {
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
        // What the robot has was decided at start.
        opts.config = false;
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

    /// Takes a connection the reconnection thread established.
    fn link_up_again(&mut self, conn: Connection) {
        let answered = conn.arm_calibration().is_some();
        if let Some(cal) = conn.arm_calibration() {
            self.robot.set_calibration(*cal);
        }
        if let Some(sip) = conn.last_sip() {
            self.robot.sip = Some(*sip);
        }
        self.robot.conn = Some(conn);
        // Commands sent before this instant were sent to a dead link: refused.
        self.robot.link_up_since_ns = monotonic_ns();
        self.robot.last_rx = Instant::now();
        // Whatever was commanded before is void; hold where the arm is.
        self.robot.arm.target = [None; 6];
        self.set_autopark();
        // An arm that lost contact with its controller reverts to HOME with power off
        // (the vendor's manuals): power it again, as at start.
        if self.hardware.arm
            && let Err(status) = self
                .robot
                .send(&Command::ArmPower(true), &origin_internal())
        {
            tracing::warn!("cannot power the arm after reconnecting: {status}");
        }
        self.reconnects += 1;
        self.robot.dirty.arm = true;
        self.robot.dirty.body = true;
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

    /// Timer work: silence detection, keep-alive, estimates, housekeeping.
    fn tick(&mut self, now: Instant) {
        if self.robot.conn.is_some() {
            if now.duration_since(self.robot.last_rx)
                > Duration::from_millis(self.robot.cfg.link_timeout_ms)
            {
                self.link_failed("silent");
            } else if !self.probe_arm(now) {
                self.link_failed("write failed");
            } else if let Some(c) = self.robot.conn.as_mut()
                && let Err(e) = c.keep_alive()
            {
                tracing::warn!("keep-alive failed: {e}");
                self.link_failed("write failed");
            }
        } else {
            self.try_reconnect();
        }
        // Time-based lift estimate and stall detection move without packets.
        if self.robot.lift.moving.is_some() {
            self.robot.dirty.body = true;
        }
        // The deadman: a lease whose holder died or fell silent ends and stops its device
        // (clients wake the loop only when they send).
        if let Err(e) = self.hosts.check_leases(&mut Serve(&mut self.robot)) {
            self.failures.note(Failure::Process, &e);
        }
        // Housekeeping (allocates inside iceoryx2): resources of crashed clients.
        if now.duration_since(self.last_cleanup) > Duration::from_secs(60) {
            self.last_cleanup = now;
            self.hosts.cleanup_dead();
        }
    }

    /// Runs until SIGINT/SIGTERM/SIGHUP; then stops the arm, closes the link and returns.
    pub fn run(&mut self, opts: RunOptions) -> Result<LoopExit, DriverError> {
        let exit = self.run_until(opts, || false);
        self.shutdown();
        exit
    }

    /// Runs until SIGINT/SIGTERM/SIGHUP or until `stop` (checked at every wake-up, at least every
    /// tick) returns true. The link stays open: run again, or call
    /// [`PioneerDriver::shutdown`] to stop the arm and close it.
    pub fn run_until(
        &mut self,
        opts: RunOptions,
        mut stop: impl FnMut() -> bool,
    ) -> Result<LoopExit, DriverError> {
        self.mode = opts.mode;
        match opts.mode {
            LoopMode::Event => self.run_event(&mut stop),
            LoopMode::Spin => Ok(self.run_spin(&mut stop)),
        }
    }

    /// Wake-ups of the loop so far (each costs iceoryx2's WaitSet one small allocation).
    pub fn wakeups(&self) -> u64 {
        self.wakeups
    }

    /// Ticks of the event-driven loop that found commands or requests waiting (which a
    /// client's wake-up had not brought in first): the safety net under lost wake-ups.
    pub fn tick_found_work(&self) -> u64 {
        self.tick_found_work
    }

    /// Counts a tick that found clients' work, and warns (once per episode) when ticks
    /// keep finding work while no wake-up comes: the clients' wake-ups are lost.
    fn note_tick_work(&mut self, found: bool) {
        let woken = std::mem::take(&mut self.woken_since_tick);
        if found {
            self.tick_found_work += 1;
        }
        if found && !woken {
            self.deaf_ticks = self.deaf_ticks.saturating_add(1);
            if self.deaf_ticks == DEAF_TICKS {
                tracing::warn!(
                    "clients' commands arrive but their wake-ups do not ({DEAF_TICKS} ticks in a \
                     row): serving them at every tick until wake-ups come again"
                );
            }
        } else {
            if self.deaf_ticks >= DEAF_TICKS {
                tracing::info!("clients' wake-ups arrive again");
            }
            self.deaf_ticks = 0;
        }
    }

    fn run_event(&mut self, stop: &mut dyn FnMut() -> bool) -> Result<LoopExit, DriverError> {
        let mut listeners = self.hosts.take_wake_listeners();
        let tick = self.robot.cfg.tick();
        let nominal = tick.as_nanos() as u64;
        loop {
            // Devices offered while running (an arm that answered late) wake the loop too.
            listeners.extend(self.hosts.take_wake_listeners());
            self.devices_added = false;
            // (Re)attach the link's fd: it changes when the link is re-established.
            let fd = self
                .robot
                .conn
                .as_ref()
                .and_then(|c| FdSource::new(c.link()));
            let had_link = fd.is_some();
            let mut stopped = false;
            let exit = event_loop::run(&listeners, tick, fd.as_ref(), |wake| {
                let now = Instant::now();
                self.wakeups += 1;
                match wake {
                    Wake::Fd => {
                        if !self.read_link(now) {
                            self.link_failed("read failed");
                        }
                    }
                    Wake::Clients => {
                        self.woken_since_tick = true;
                        if self.process_clients(Drain::All) {
                            // A client in a tight loop sends its next command within the
                            // linger: picked up without a wake-up.
                            let linger = Duration::from_micros(self.robot.cfg.linger_us.into());
                            event_loop::linger(linger, || self.process_clients(Drain::Linger));
                        }
                    }
                    Wake::Tick(n) => {
                        self.robot.stats.tick(now, nominal, n);
                        // A packet may be sitting in the decoder after a send.
                        if !self.read_link(now) && self.robot.conn.is_some() {
                            self.link_failed("read failed");
                        }
                        self.tick(now);
                        // The safety net under the clients' wake-ups: a wake-up that never
                        // comes (seen in the soak: a device's listener stopped waking the
                        // loop, and its commands and requests waited for ever) delays a
                        // command by one tick at most instead of freezing that device.
                        // The polling variant: commands at every tick, requests at every
                        // 16th, and nothing allocated when nothing waits.
                        let found = self.process_clients(Drain::Spin);
                        self.note_tick_work(found);
                    }
                }
                if std::mem::take(&mut self.arm_info_arrived) {
                    self.on_arm_info();
                }
                self.publish_all(now);
                if stop() {
                    stopped = true;
                    return ControlFlow::Break(());
                }
                // Leave the wait to re-attach when the link went down or came up, or to
                // attach the listeners of new devices.
                if self.robot.conn.is_some() != had_link || self.devices_added {
                    ControlFlow::Break(())
                } else {
                    ControlFlow::Continue(())
                }
            })
            .map_err(DriverError::Loop)?;
            if exit == LoopExit::Signal {
                return Ok(LoopExit::Signal);
            }
            if stopped {
                return Ok(LoopExit::Stopped);
            }
        }
    }

    fn run_spin(&mut self, stop: &mut dyn FnMut() -> bool) -> LoopExit {
        let tick = self.robot.cfg.tick();
        let nominal = tick.as_nanos() as u64;
        let mut next_tick = Instant::now() + tick;
        let mut n: u64 = 0;
        loop {
            let now = Instant::now();
            if self.robot.conn.is_some() && !self.read_link(now) {
                self.link_failed("read failed");
            }
            self.process_clients(Drain::Spin);
            if now >= next_tick {
                let missed = (now.duration_since(next_tick).as_nanos() as u64) / nominal.max(1);
                self.robot.stats.tick(now, nominal, 1 + missed);
                next_tick += tick * (1 + missed as u32);
                self.tick(now);
            }
            if std::mem::take(&mut self.arm_info_arrived) {
                self.on_arm_info();
            }
            self.publish_all(now);
            n += 1;
            if n.is_multiple_of(1024) {
                if self.ctx.termination_requested() {
                    return LoopExit::Signal;
                }
                if stop() {
                    return LoopExit::Stopped;
                }
            }
            core::hint::spin_loop();
        }
    }

    /// Stops the arm, stops the ARMpac stream and closes the link (STOP, CLOSE).
    pub fn shutdown(&mut self) {
        // A handshake still running on its thread closes what it opens.
        self.connecting = None;
        let o = origin_internal();
        if self.hardware.arm
            && let Err(status) = self
                .robot
                .send(&Command::ArmStop(limber_p2os::JointSelection::All), &o)
        {
            tracing::warn!("cannot stop the arm at shutdown: {status}");
        }
        if let Some(conn) = self.robot.conn.take()
            && let Err(e) = conn.close()
        {
            tracing::warn!("closing the link: {e}");
        }
        self.robot.dirty.arm = true;
        self.robot.dirty.body = true;
        self.publish_all(Instant::now());
        self.publish_stats();
    }
}

/// An owned copy of the packets the driver uses.
enum Owned {
    Sip(limber_p2os::Sip),
    Arm(limber_p2os::ArmPacket),
    ArmInfo(limber_p2os::ArmInfo),
    Other,
}

impl From<&RobotPacket<'_>> for Owned {
    fn from(p: &RobotPacket<'_>) -> Self {
        match p {
            RobotPacket::Sip(s) => Owned::Sip(*s),
            RobotPacket::Arm(a) => Owned::Arm(*a),
            RobotPacket::ArmInfo(i) => Owned::ArmInfo(*i),
            _ => Owned::Other,
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
    fn the_gripper_is_served_when_the_robot_says_so_or_the_user_forces_it() {
        let says = |g: u16| {
            ConfigProbe::Answered(Box::new(limber_p2os::ConfigPacket {
                gripper: g,
                ..Default::default()
            }))
        };
        let silent = ConfigProbe::Unanswered { attempts: 3 };
        let bad = ConfigProbe::Malformed(limber_p2os::ConfigPacketError::Empty);
        for (setting, probe, served, note) in [
            (BodyGripper::Auto, says(1), true, "says a gripper is fitted"),
            (BodyGripper::Auto, says(0), false, "says no gripper"),
            (
                BodyGripper::Auto,
                silent.clone(),
                false,
                "set body_gripper = true",
            ),
            (BodyGripper::Auto, bad, false, "unreadable"),
            (BodyGripper::Fitted, says(0), true, "although"),
            (
                BodyGripper::Fitted,
                silent.clone(),
                true,
                "body_gripper = true",
            ),
            (BodyGripper::Absent, says(1), false, "although"),
            (BodyGripper::Absent, silent, false, "body_gripper = false"),
        ] {
            let (s, n) = gripper_decision(setting, &probe, "kim");
            assert_eq!(s, served, "{setting:?} {probe:?}: {n}");
            assert!(n.contains(note), "{setting:?} {probe:?}: {n}");
            assert!(
                n.contains("kim/gripper/0") && n.contains("kim/actarray/1"),
                "{n}"
            );
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
