//! The driver process: one thread that owns the link, serves the devices and recovers from
//! link faults. The robot model ([`RobotModel`]) decides; this module and its parts move
//! its outbox to the link and its state to the clients:
//!
//! * [`hardware`]: what the robot has and which devices are served for it;
//! * [`link`]: link supervision (reading, silence, reconnection, ARM_INFO retries);
//! * [`serve`]: device routing (the [`limber_services::DeviceSetHandler`]);
//! * [`run`]: the event-driven and the spinning loop, and the timer's work.

mod hardware;
mod link;
mod run;
mod serve;

use std::sync::mpsc::Receiver;
use std::time::Instant;

use limber_interfaces::diagnostics::{self, DriverStats, loop_mode};
use limber_interfaces::prelude::*;
use limber_services::diagnostics::{StatsPublisher, put_clients, put_loop};
use limber_services::{Context, DeviceSet, Drain, HostError, monotonic_ns};
use thiserror::Error;

use limber_p2os::{Command, ConfigProbe, ConnectError, Connection, LinkTarget};

use hardware::{ARM_DEVICES, BODY_DEVICES, hardware_bits};
pub use hardware::{Hardware, gripper_decision};
use link::{ArmProbe, ReconnectLog, options};
use serve::Serve;

use crate::config::{BodyGripper, PioneerConfig};
use crate::robot::RobotModel;
use crate::stats::LoopStats;

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
    /// The arm's devices could not be made to share one lease.
    #[error(transparent)]
    ShareLease(#[from] limber_services::ShareLeaseError),
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

/// Options of a driver start.
#[derive(Debug, Clone, Copy, Default)]
pub struct StartOptions {
    /// The robot is an emulator (`limber pioneer --emulated`, the demo): every device's
    /// state header says [`device_flag::SIMULATED`]. Never set for a real robot's port.
    pub simulated: bool,
}

/// What [`PioneerDriver::shutdown`] did to the arm.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ArmAtShutdown {
    /// ARM_STOP was written to the robot: the arm stops where it is.
    Stopped,
    /// The robot has no arm served: nothing to stop.
    NoArm,
    /// ARM_STOP could not be written (the link was down or the write failed): the arm was
    /// not stopped by the driver (the controller's autopark parks it later).
    NotStopped(Status),
}

/// What [`PioneerDriver::shutdown`] did to the link.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LinkAtShutdown {
    /// CLOSE was written and the link closed.
    Closed,
    /// CLOSE could not be written; the link was closed anyway (logged).
    ClosedWithoutClose,
    /// The link was already down (the robot silent or gone).
    AlreadyDown,
}

/// What [`PioneerDriver::shutdown`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ShutdownReport {
    /// The arm.
    pub arm: ArmAtShutdown,
    /// The link.
    pub link: LinkAtShutdown,
}

impl core::fmt::Display for ShutdownReport {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self.arm {
            ArmAtShutdown::Stopped => f.write_str("stopped the arm")?,
            ArmAtShutdown::NoArm => f.write_str("no arm to stop")?,
            ArmAtShutdown::NotStopped(status) => {
                write!(f, "could not stop the arm ({status})")?;
            }
        }
        match self.link {
            LinkAtShutdown::Closed => f.write_str(" and closed the link"),
            LinkAtShutdown::ClosedWithoutClose => {
                f.write_str("; closed the link without telling the robot (CLOSE failed)")
            }
            LinkAtShutdown::AlreadyDown => f.write_str("; the link had already closed"),
        }
    }
}

/// The driver's name in device attributes and statistics.
const DRIVER: &str = "pioneer";

/// The Pioneer driver: serves `<robot>/actarray/0` (arm), `<robot>/limb/0`,
/// `<robot>/gripper/0` (body gripper), `<robot>/gripper/1` (arm gripper) and
/// `<robot>/actarray/1` (lift), and `<robot>/driver/0` (statistics). The arm's devices only
/// if the robot answers ARM_INFO; the body gripper's and the lift only if it has them
/// ([`gripper_decision`]).
pub struct PioneerDriver {
    ctx: Context,
    target: LinkTarget,
    robot: RobotModel,
    /// The link while it is up.
    conn: Option<Connection>,
    /// The loop's timing: periods, jitter, command-to-wire latencies.
    timing: LoopStats,
    hosts: DeviceSet,
    stats_pub: StatsPublisher,
    stats: DriverStats,
    hardware: Hardware,
    reconnects: u64,
    link_faults: u64,
    next_reconnect: Instant,
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
    /// The link's count of packets that did not parse, as last seen.
    malformed_seen: u64,
    /// The body gripper's devices are offered (they stay once offered; a robot that lost
    /// its gripper has their commands refused).
    gripper_offered: bool,
    /// The robot is an emulator: every state says [`device_flag::SIMULATED`].
    simulated: bool,
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

impl core::fmt::Debug for PioneerDriver {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("PioneerDriver")
            .field("hardware", &self.hardware)
            .finish()
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
        Self::start_with(ctx, cfg, target, StartOptions::default())
    }

    /// [`PioneerDriver::start`] with options (an emulated robot's states flagged
    /// [`device_flag::SIMULATED`]).
    pub fn start_with(
        ctx: &Context,
        cfg: PioneerConfig,
        target: LinkTarget,
        opts: StartOptions,
    ) -> Result<Self, DriverError> {
        // The devices admit `max_clients` clients each (checked by `validate`; a value out
        // of range keeps the context's capacity).
        match limber_services::qos::Capacity::new(cfg.max_clients) {
            Ok(c) => ctx.set_capacity(c),
            Err(e) => tracing::warn!(
                "{e}: devices admit {} clients",
                ctx.capacity().max_clients()
            ),
        }
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
        let malformed_seen = conn.link().stats().malformed;
        let calibrated = conn
            .arm_calibration()
            .is_some_and(|cal| model.take_calibration(*cal));
        if let Some(sip) = conn.last_sip() {
            model.set_sip(*sip);
        }
        model.link_up(Instant::now());

        let robot = cfg.robot.as_str();
        let mut serve = Vec::new();
        if hardware.arm {
            serve.extend(ARM_DEVICES);
        }
        if hardware.gripper {
            serve.extend(BODY_DEVICES);
        }
        model.set_body_gripper(hardware.gripper);
        let gripper_offered = hardware.gripper;
        let mut hosts = DeviceSet::new(ctx, robot, DRIVER, &serve)?;
        if hardware.arm {
            // The joints, the end effector and the arm's gripper: one lease holds them.
            hosts.share_lease(&ARM_DEVICES)?;
        }
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
            conn: Some(conn),
            timing: LoopStats::default(),
            hosts,
            stats_pub,
            stats,
            hardware,
            reconnects: 0,
            link_faults: 0,
            next_reconnect: Instant::now(),
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
            malformed_seen,
            gripper_offered,
            simulated: opts.simulated,
        };
        if d.hardware.arm && !calibrated {
            // The ARMINFOpac was not a calibration (logged): ask again.
            d.start_arm_probe(Instant::now());
        }
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
            && let Err(status) = d.send_internal(&Command::ArmPower(true))
        {
            tracing::warn!("cannot power the arm at start: {status}");
        }
        d.set_autopark();
        d.robot.dirty.arm = true;
        d.robot.dirty.body = true;
        d.publish_all(Instant::now());
        Ok(d)
    }

    /// Queues one of the driver's own commands in the model and writes it to the link.
    fn send_internal(&mut self, cmd: &Command) -> Result<(), Status> {
        self.robot.send_internal(cmd)?;
        serve::flush(&mut self.robot, self.conn.as_mut(), &mut self.timing)
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
        self.stats.header.seq + h.published + h.outcomes + h.told
    }

    /// The loop's timing: periods, jitter, command-to-wire latencies.
    pub fn loop_stats(&self) -> &crate::stats::LoopStats {
        &self.timing
    }

    /// True while the link is up.
    pub fn link_up(&self) -> bool {
        self.conn.is_some()
    }

    fn flags(&self) -> u32 {
        let mut f = 0;
        if self.conn.is_some() {
            f |= device_flag::LINK_UP;
        }
        if self.robot.cal.is_some() {
            f |= device_flag::CALIBRATED;
        }
        f | self.simulated_flag()
    }

    /// [`device_flag::SIMULATED`] when the robot is an emulator, else 0.
    fn simulated_flag(&self) -> u32 {
        if self.simulated {
            device_flag::SIMULATED
        } else {
            0
        }
    }

    /// Publishes the devices whose state changed, and the statistics once a second.
    fn publish_all(&mut self, now: Instant) {
        let flags = self.flags();
        // The arm's devices say LINK_UP only while the arm reports (ARMpacs arrive).
        let arm_flags = if self.robot.arm_reporting(now) {
            flags
        } else {
            flags & !device_flag::LINK_UP
        };
        let robot = &mut self.robot;
        let failures = &mut self.failures;
        if robot.dirty.arm {
            if let Some(h) = self.hosts.actarray_mut(0) {
                h.set_flags(arm_flags);
                robot.arm_state(h.state_mut(), now);
                if let Err(e) = h.publish() {
                    failures.note(Failure::Publish, &e);
                }
            }
            if let Some(h) = self.hosts.limb_mut(0) {
                h.set_flags(arm_flags);
                robot.limb_state(h.state_mut(), now);
                if let Err(e) = h.publish() {
                    failures.note(Failure::Publish, &e);
                }
            }
            if let Some(h) = self.hosts.gripper_mut(1) {
                h.set_flags(arm_flags);
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
                h.set_flags(flags & (device_flag::LINK_UP | device_flag::SIMULATED));
                robot.gripper_state(h.state_mut());
                h.state_mut().header.stamp_ns = monotonic_ns();
                if let Err(e) = h.publish() {
                    failures.note(Failure::Publish, &e);
                }
            }
            if let Some(h) = self.hosts.actarray_mut(1) {
                h.set_flags(flags & (device_flag::LINK_UP | device_flag::SIMULATED));
                robot.lift_state(h.state_mut());
                h.state_mut().header.stamp_ns = monotonic_ns();
                if let Err(e) = h.publish() {
                    failures.note(Failure::Publish, &e);
                }
            }
            robot.dirty.body = false;
        }
        // After the states that show them: the results of the motions that ended.
        let mut handler = serve::Serve {
            robot: &mut self.robot,
            conn: None,
            stats: &mut self.timing,
        };
        self.hosts.check_motions(&mut handler);
        if self.stats_pub.due(now) {
            self.publish_stats();
        }
    }

    fn publish_stats(&mut self) {
        let simulated = self.simulated_flag();
        let s = &mut self.stats;
        let ls = &self.timing;
        s.header.flags = if self.conn.is_some() {
            device_flag::LINK_UP
        } else {
            0
        } | simulated;
        let mode = match self.mode {
            LoopMode::Event => loop_mode::EVENT,
            LoopMode::Spin => loop_mode::SPIN,
        };
        put_loop(s, mode, &ls.ticks);
        (
            s.cmd_to_wire_p50_ns,
            s.cmd_to_wire_p99_ns,
            s.cmd_to_wire_max_ns,
        ) = ls.cmd_to_wire.summary();
        s.sips_per_s = ls.sips_per_s;
        if let Some(c) = self.conn.as_ref() {
            let st = c.link().stats();
            s.bytes_in = st.decoder.bytes_in;
            s.bytes_out = st.bytes_out;
            s.packets_in = st.decoder.packets_ok;
            s.bad_checksums = st.decoder.bad_checksums;
            s.resync_bytes = st.decoder.garbage_bytes;
        }
        s.reconnects = self.reconnects;
        s.link_faults = self.link_faults;
        put_clients(s, &self.hosts.stats());
        if let Err(e) = self.stats_pub.publish(s) {
            self.failures.note(Failure::Publish, &e);
        }
    }

    /// Handles the pending commands and requests of every device, the way `how` says;
    /// returns whether there was any.
    fn process_clients(&mut self, how: Drain) -> bool {
        // A robot that seems silent may only be unread (the loop was busy, e.g. in a write
        // that waited for a full link): read what it sent before its silence is judged.
        if self.conn.is_some() {
            let now = Instant::now();
            if now.saturating_duration_since(self.robot.last_rx())
                > self.robot.cfg.command_silence() / 2
                && !self.read_link(now)
            {
                self.link_failed("read failed");
            }
        }
        let mut handler = Serve {
            robot: &mut self.robot,
            conn: self.conn.as_mut(),
            stats: &mut self.timing,
        };
        let r = self.hosts.process_as(&mut handler, how);
        match r {
            Ok(a) => a.commands + a.requests > 0,
            Err(e) => {
                self.failures.note(Failure::Process, &e);
                false
            }
        }
    }

    /// Stops the arm, stops the ARMpac stream and closes the link (STOP, CLOSE); says
    /// what it could do (a robot that does not listen is not stopped).
    pub fn shutdown(&mut self) -> ShutdownReport {
        // A handshake still running on its thread closes what it opens.
        self.connecting = None;
        let arm = if !self.hardware.arm {
            ArmAtShutdown::NoArm
        } else {
            match self.send_internal(&Command::ArmStop(limber_p2os::JointSelection::All)) {
                Ok(()) => ArmAtShutdown::Stopped,
                Err(status) => {
                    tracing::warn!("cannot stop the arm at shutdown: {status}");
                    ArmAtShutdown::NotStopped(status)
                }
            }
        };
        let link = match self.conn.take() {
            None => LinkAtShutdown::AlreadyDown,
            Some(conn) => match conn.close() {
                Ok(()) => LinkAtShutdown::Closed,
                Err(e) => {
                    tracing::warn!("closing the link: {e}");
                    LinkAtShutdown::ClosedWithoutClose
                }
            },
        };
        self.robot.link_down();
        self.robot.dirty.arm = true;
        self.robot.dirty.body = true;
        self.publish_all(Instant::now());
        self.publish_stats();
        ShutdownReport { arm, link }
    }
}
