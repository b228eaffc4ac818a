//! The driver's model of the robot and its command handling: what every device does with a
//! command or request, validated before anything is written to the link.
//!
//! [`RobotModel`] holds the calibration, what the robot last said and what was commanded;
//! it has no link. It takes the robot's packets ([`RobotModel::on_packet`]) and the link's
//! comings and goings ([`RobotModel::link_up`], [`RobotModel::link_down`]), and every
//! command it accepts leaves P2OS [`Command`]s in its [`Outbox`], which the driver writes
//! to the link. Its methods are split by device, one private module each: `arm` (the arm
//! actarray), `limb` (the end effector and its IK), `grippers` (the arm gripper and the body
//! gripper) and `lift`.

mod arm;
mod grippers;
mod lift;
mod limb;
mod motion;
mod outbox;
mod progress;
mod trajectory;

pub use lift::LiftModel;
pub use outbox::{OUTBOX_CAPACITY, Outbox, OutboxFull, Queued};

use std::time::{Duration, Instant};

use limber_interfaces::limb_outcome::LimbOutcome;
use limber_interfaces::prelude::*;
use limber_services::Origin;
use limber_services::monotonic_ns;
use nalgebra::Vector3;

use limber_kinematics::FrameError;
use limber_kinematics::pioneer::{
    DriverAngleMap, PIONEER_DOF, PioneerGeometry, PioneerIkError, PioneerIkOptions, Theta,
};
use limber_p2os::{ArmCalibration, ArmJoint, ArmPacket, ArmpacLayout, Command, RobotPacket, Sip};

use crate::config::PioneerConfig;

/// The driver itself as the origin of a command (its own power, autopark and stream
/// commands, VECMOVE waypoints, the deadman's stops): never refused as stale.
pub const INTERNAL: Origin = Origin {
    client_id: 0,
    seq: 0,
    sent_ns: 0,
    received_ns: 0,
};

/// Joints of the arm actarray: 5 arm joints and the gripper.
pub const ARM_JOINTS: usize = 6;
/// Waypoints a VECMOVE may have (2 cm apart at most: several metres).
pub const MAX_WAYPOINTS: usize = 256;
/// ARMpacs saying "unpowered" believed only after this many arrived since a power-on was
/// sent (the first may have left the controller before it read the command)...
const POWER_ON_GRACE_PACKETS: u8 = 3;
/// ...and only those that arrived this long after it: packets queued in the link's
/// buffers while the driver was busy (e.g. offering its services at start) all predate the
/// command, however many they are. Two and a half controller cycles.
const POWER_ON_SETTLE: Duration = Duration::from_millis(250);
/// Rotation axes of the arm joints in the geometry (Player's aa_axes).
const AXES: [[f64; 3]; ARM_JOINTS] = [
    [0.0, 0.0, -1.0],
    [0.0, -1.0, 0.0],
    [0.0, -1.0, 0.0],
    [1.0, 0.0, 0.0],
    [0.0, 1.0, 0.0],
    [0.0, 0.0, 1.0],
];

/// The arm as the last ARMpac described it, and what was commanded.
#[derive(Debug, Clone)]
pub struct ArmModel {
    /// Latest ticks.
    pub ticks: [u8; ARM_JOINTS],
    /// An ARMpac arrived.
    pub seen: bool,
    /// Moving bits (joint i = bit i).
    pub moving: u8,
    /// Powered, per the status word.
    pub powered: bool,
    /// A power-on command went out and the controller has not confirmed it yet: ARMpacs
    /// still to tolerate saying "unpowered" (packets already in flight) before believing
    /// them. Commands written after the power-on reach the controller after it, so they
    /// are carried out powered.
    pub power_on_pending: u8,
    /// When the last power-on was written: "unpowered" reports before
    /// `POWER_ON_SETTLE` after it are not counted against the grace.
    pub power_on_sent: Option<Instant>,
    /// When the last power-off was written: ARMpacs saying "powered" for
    /// `POWER_ON_SETTLE` after it left the controller before it read the command.
    pub power_off_sent: Option<Instant>,
    /// Commanded target tick per joint (None: hold wherever it is).
    pub target: [Option<u8>; ARM_JOINTS],
    /// Since when a joint has been still but short of its target.
    pub short_since: [Option<Instant>; ARM_JOINTS],
    /// The goal a client asked for, in radians, per joint (POS, MULTI_POS): a motion's
    /// final error is against it; `None`: the target tick is the goal (HOME, SPEED, a
    /// VECMOVE waypoint).
    pub goal: [Option<f64>; ARM_JOINTS],
    /// The ticks of the ARMpac before the last, and when it arrived: the speed is
    /// estimated from successive positions (the ARMpac has none).
    pub prev_ticks: [u8; ARM_JOINTS],
    /// When the ARMpac before the last arrived.
    pub prev_packet: Option<Instant>,
    /// When the last ARMpac arrived (`CLOCK_MONOTONIC` ns).
    pub stamp_ns: u64,
    /// When the last ARMpac arrived, on the model's clock.
    pub last_packet: Option<Instant>,
    /// ARMpacs whose status bytes make sense only in the other layout than the
    /// configured `armpac_layout` (see [`ArmPacket::suggests_other_layout`]).
    pub layout_mismatches: u64,
    /// When each joint's target was set, and how many ticks it had to go: the time bound
    /// of its motion (TIMED_OUT past it).
    pub target_set: [Option<(Instant, u8)>; ARM_JOINTS],
    /// The servo speed last commanded per joint, ms per step (0: the calibration's).
    pub servo_ms: [u8; ARM_JOINTS],
}

impl Default for ArmModel {
    fn default() -> Self {
        ArmModel {
            ticks: [0; ARM_JOINTS],
            seen: false,
            moving: 0,
            powered: false,
            power_on_pending: 0,
            power_on_sent: None,
            power_off_sent: None,
            target: [None; ARM_JOINTS],
            short_since: [None; ARM_JOINTS],
            goal: [None; ARM_JOINTS],
            prev_ticks: [0; ARM_JOINTS],
            prev_packet: None,
            stamp_ns: 0,
            last_packet: None,
            layout_mismatches: 0,
            target_set: [None; ARM_JOINTS],
            servo_ms: [0; ARM_JOINTS],
        }
    }
}

impl ArmModel {
    /// Honest per-joint state: MOVING while the controller says so (or a fresh target is
    /// not yet reached), IDLE at the target, STALLED when still and short of it for longer
    /// than `stall`.
    pub fn flags(&self, j: usize, now: Instant, stall: Duration) -> ActuatorFlags {
        if self.moving & (1 << j) != 0 {
            return ActuatorFlags::MOVING;
        }
        match self.target[j] {
            None => ActuatorFlags::IDLE,
            Some(t) if t == self.ticks[j] => ActuatorFlags::IDLE,
            Some(_) => match self.short_since[j] {
                Some(since) if now.duration_since(since) >= stall => ActuatorFlags::STALLED,
                _ => ActuatorFlags::MOVING,
            },
        }
    }

    /// Applies an ARMpac, reading its status bytes in `layout`. A packet that only makes
    /// sense in the other layout is counted, and the first one is logged.
    pub fn update(&mut self, p: &ArmPacket, layout: ArmpacLayout, now: Instant) {
        if p.suggests_other_layout(layout) {
            if self.layout_mismatches == 0 {
                tracing::warn!(
                    status_bytes = ?p.status_bytes,
                    "the ARMpac status bytes make sense only in the {} layout, not the configured {} \
                     (set armpac_layout = \"{}\" if this robot reads them that way)",
                    layout.other(),
                    layout,
                    layout.other()
                );
            }
            self.layout_mismatches += 1;
        }
        let status = p.status(layout);
        if self.seen {
            self.prev_ticks = self.ticks;
            self.prev_packet = self.last_packet;
        } else {
            self.prev_ticks = p.ticks;
            self.prev_packet = Some(now);
        }
        self.ticks = p.ticks;
        self.moving = status.moving_mask();
        // "Powered" from a packet in flight when the power-off left is not believed.
        self.powered = status.powered
            && self
                .power_off_sent
                .is_none_or(|t| now.saturating_duration_since(t) >= POWER_ON_SETTLE);
        if self.powered {
            self.power_on_pending = 0;
        } else if self
            .power_on_sent
            .is_none_or(|t| now.saturating_duration_since(t) >= POWER_ON_SETTLE)
        {
            self.power_on_pending = self.power_on_pending.saturating_sub(1);
        }
        self.seen = true;
        self.stamp_ns = monotonic_ns();
        self.last_packet = Some(now);
        for j in 0..ARM_JOINTS {
            let short =
                self.moving & (1 << j) == 0 && self.target[j].is_some_and(|t| t != self.ticks[j]);
            if !short {
                self.short_since[j] = None;
            } else if self.short_since[j].is_none() {
                self.short_since[j] = Some(now);
            }
        }
    }

    /// True when the arm is powered, or a power-on was sent and not yet contradicted.
    pub fn powered_or_pending(&self) -> bool {
        self.powered || self.power_on_pending > 0
    }

    /// Records a power command written to the link.
    fn power_commanded(&mut self, on: bool) {
        if on {
            self.power_on_pending = POWER_ON_GRACE_PACKETS;
            self.power_on_sent = Some(Instant::now());
            self.power_off_sent = None;
        } else {
            // Off at once: no motion command is accepted after it.
            self.power_on_pending = 0;
            self.powered = false;
            self.power_off_sent = Some(Instant::now());
        }
    }

    pub(super) fn set_target(&mut self, j: usize, tick: u8) {
        self.target[j] = Some(tick);
        self.goal[j] = None;
        self.short_since[j] = None;
        self.target_set[j] = Some((Instant::now(), tick.abs_diff(self.ticks[j])));
    }
}

/// What happened on the link, for the loop.
#[derive(Debug, Clone, Copy, Default)]
pub struct Dirty {
    /// The arm state changed: publish arm, limb and arm gripper.
    pub arm: bool,
    /// A SIP arrived: publish body gripper and lift.
    pub body: bool,
}

/// A VECMOVE in progress: precomputed waypoints streamed one after another.
#[derive(Debug, Clone)]
pub struct VecMovePlan {
    waypoints: [[u8; PIONEER_DOF]; MAX_WAYPOINTS],
    len: usize,
    next: usize,
}

/// The link as the model sees it: up or down, since when, and when the robot last spoke.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LinkState {
    /// The link is up: commands are accepted.
    pub(crate) up: bool,
    /// When the link came up (`CLOCK_MONOTONIC` ns; commands sent earlier are refused:
    /// never replayed).
    pub(crate) up_since_ns: u64,
    /// When the last packet arrived.
    pub(crate) last_rx: Instant,
    /// When the link came up.
    pub(crate) up_at: Instant,
}

/// What a packet changed that the driver acts on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PacketEffect {
    /// Nothing beyond the model's state.
    None,
    /// A SIP arrived (the driver counts them).
    Sip,
    /// An ARMINFOpac arrived: the calibration is (re)set.
    ArmInfo,
}

/// The driver's model of the robot: calibration, what the robot last said, what was
/// commanded, and the commands waiting for the link. No link inside.
pub struct RobotModel {
    /// The configuration.
    pub(crate) cfg: PioneerConfig,
    /// The link's state.
    pub(crate) link: LinkState,
    /// Commands accepted and not yet written to the link.
    pub(crate) outbox: Outbox,
    /// Calibration from ARMINFO.
    pub(crate) cal: Option<ArmCalibration>,
    /// The robot answered ARM_INFO.
    pub(crate) has_arm: bool,
    /// Arm kinematics.
    pub(crate) geom: PioneerGeometry,
    /// Driver ↔ kinematic angles.
    pub(crate) map: DriverAngleMap,
    /// IK options.
    pub(crate) ik: PioneerIkOptions,
    /// The arm.
    pub(crate) arm: ArmModel,
    /// Malformed input from the robot so far.
    pub(crate) malformed: u64,
    /// The arm was reporting at the last [`RobotModel::check_arm_reporting`].
    pub(crate) arm_reported: bool,
    /// The body gripper and lift are served (the robot's CONFIGpac or the configuration
    /// says so); otherwise their commands are refused UNSUPPORTED.
    pub(crate) body_gripper: bool,
    /// OUT_OF_REACH and the orientation adjustment of the last limb command.
    pub(crate) limb: LimbOutcome,
    /// A VECMOVE being streamed.
    pub(crate) vecmove: Option<Box<VecMovePlan>>,
    /// End-effector speed for limb motions, m/s.
    pub(crate) limb_speed: f64,
    /// The lift.
    pub(crate) lift: LiftModel,
    /// The latest SIP.
    pub(crate) sip: Option<Sip>,
    /// The last body-gripper command (OPEN/CLOSE/STOP).
    pub(crate) gripper_cmd: Option<GripperCommand>,
    /// The last arm-gripper command.
    pub(crate) armgrip_cmd: Option<GripperCommand>,
    /// What changed on the link since the last publish.
    pub(crate) dirty: Dirty,
    /// Joint trajectories: the executor, the upload, what was streamed.
    pub(crate) traj: trajectory::Trajectories,
}

impl core::fmt::Debug for RobotModel {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("RobotModel")
            .field("link_up", &self.link.up)
            .field("has_arm", &self.has_arm)
            .field("outbox", &self.outbox.len())
            .finish()
    }
}

/// Why an ARMINFOpac cannot be a calibration: no joint, or a joint without ticks per 90°
/// (every angle would be infinite) or without a range.
fn calibration_problem(cal: &ArmCalibration) -> Option<String> {
    let n = cal.num_joints();
    if n == 0 {
        return Some("it has no joint".into());
    }
    for j in 0..n.min(ARM_JOINTS) {
        let Ok(joint) = ArmJoint::from_index(j) else {
            return Some(format!("joint index {j} is unknown"));
        };
        let Ok(c) = cal.joint(joint) else {
            return Some(format!("joint {} has no calibration", joint.number()));
        };
        if c.ticks_per_90 == 0 {
            return Some(format!("joint {} has 0 ticks per 90°", joint.number()));
        }
        if c.min == c.max {
            return Some(format!(
                "joint {} has no range (min = max = {})",
                joint.number(),
                c.min
            ));
        }
    }
    None
}

/// The cause of an IK failure, as the status a refused limb command carries.
pub(crate) fn ik_status(e: &PioneerIkError) -> Status {
    match e {
        PioneerIkError::NonFinite | PioneerIkError::Frame(FrameError::NonFinite) => {
            Status::NotFinite
        }
        // Zero-length or parallel approach and orientation vectors make no frame: the
        // argument is malformed, whether or not the position is reachable.
        PioneerIkError::Frame(_) => Status::InvalidArgument,
        PioneerIkError::OutOfReach { .. } => Status::OutOfReach,
        PioneerIkError::UnreachableOrientation { .. } => Status::UnreachableOrientation,
        PioneerIkError::OutsideJointLimits => Status::BeyondLimits,
        // The driver's own geometry or options are wrong: not the client's doing.
        PioneerIkError::Geometry(_) | PioneerIkError::InvalidOptions => Status::Unsupported,
    }
}

impl RobotModel {
    /// The model for `cfg`, link down.
    pub fn new(cfg: PioneerConfig) -> Self {
        let mut geom = PioneerGeometry::default();
        let [l1, l2, l4, l5] = cfg.arm_links;
        geom.l1 = l1;
        geom.l2 = l2;
        geom.l4 = l4;
        geom.l5 = l5;
        geom.base_offset = Vector3::from(cfg.arm_base);
        let map = DriverAngleMap {
            offsets: cfg.limb_offsets,
        };
        let lift = LiftModel::new(cfg.lift_stroke);
        let limb_speed = cfg.limb_speed;
        RobotModel {
            cfg,
            link: LinkState {
                up: false,
                up_since_ns: 0,
                last_rx: Instant::now(),
                up_at: Instant::now(),
            },
            arm_reported: true,
            outbox: Outbox::default(),
            cal: None,
            has_arm: false,
            geom,
            map,
            ik: PioneerIkOptions {
                // Tick quantisation makes the achieved pose differ by millimetres; the
                // solver itself is exact, so requested poses are checked tightly.
                position_tolerance: 1e-6,
                orientation_tolerance: 0.02,
                ..PioneerIkOptions::default()
            },
            arm: ArmModel::default(),
            malformed: 0,
            body_gripper: false,
            limb: LimbOutcome::default(),
            vecmove: None,
            limb_speed,
            lift,
            sip: None,
            gripper_cmd: None,
            armgrip_cmd: None,
            dirty: Dirty::default(),
            traj: trajectory::Trajectories::default(),
        }
    }

    /// The IK options of SETPOSE and REACH: the configured position and approach
    /// tolerances.
    pub fn setpose_options(&self) -> PioneerIkOptions {
        PioneerIkOptions {
            position_tolerance: self.cfg.setpose_position_tolerance,
            orientation_tolerance: self.cfg.setpose_approach_tolerance_deg.to_radians(),
            ..self.ik
        }
    }

    /// Takes the calibration: sets the IK joint limits (in θ, from the driver-convention
    /// limits) and marks the arm present.
    fn set_calibration(&mut self, cal: ArmCalibration) {
        let mut min = [0.0; PIONEER_DOF];
        let mut max = [0.0; PIONEER_DOF];
        for j in 0..PIONEER_DOF {
            if let Ok(joint) = ArmJoint::from_index(j)
                && let Ok([a, _, b, _]) = cal.limits_radians(joint)
            {
                min[j] = a.min(b);
                max[j] = a.max(b);
            }
        }
        self.geom.limits = self.map.limits_from_driver(&min, &max);
        self.cal = Some(cal);
        self.has_arm = true;
        self.dirty.arm = true;
    }

    /// Queues a command for the link. Refused (LinkDown) when the link is down, when the
    /// client sent it before the link came up (never replayed after a fault), or when the
    /// robot has been silent longer than [`PioneerConfig::command_silence`].
    pub(crate) fn send(&mut self, cmd: &Command, from: &Origin) -> Result<(), Status> {
        if !self.link.up || (from.sent_ns != 0 && from.sent_ns < self.link.up_since_ns) {
            return Err(Status::LinkDown);
        }
        // A robot silent for a while may be gone: a client's command written now could be
        // carried out much later (from the link's buffers, after a reconnect), or never.
        if from.sent_ns != 0 {
            let silent = Instant::now().saturating_duration_since(self.link.last_rx);
            if silent > self.cfg.command_silence() {
                tracing::debug!(?silent, "{cmd:?} refused: the robot is silent");
                return Err(Status::LinkDown);
            }
        }
        if let Err(e) = self.outbox.push(Queued {
            cmd: *cmd,
            from: *from,
        }) {
            // The driver drains the outbox after every call: a bug, never the client's.
            tracing::error!("cannot queue {cmd:?}: {e}");
            return Err(Status::Busy);
        }
        if let Command::ArmPower(on) = *cmd {
            self.arm.power_commanded(on);
            self.dirty.arm = true;
        }
        if let Command::ArmSpeed { joint, ms_per_step } = *cmd
            && let Some(ms) = self.arm.servo_ms.get_mut(joint.index())
        {
            *ms = ms_per_step;
        }
        Ok(())
    }

    /// Queues one of the driver's own commands (power, autopark, the ARMpac stream).
    pub fn send_internal(&mut self, cmd: &Command) -> Result<(), Status> {
        self.send(cmd, &INTERNAL)
    }

    /// The commands waiting for the link (the driver drains them after every call).
    pub fn outbox_mut(&mut self) -> &mut Outbox {
        &mut self.outbox
    }

    /// The commands waiting for the link.
    pub fn outbox(&self) -> &Outbox {
        &self.outbox
    }

    /// Writing `failed` to the link failed: it and everything queued after it are
    /// dropped, and what they would have started is forgotten (the joints hold wherever
    /// they are, a VECMOVE is abandoned, never resumed on a later link).
    pub fn write_failed(&mut self, failed: &Queued) {
        let dropped = self.outbox.clear();
        tracing::debug!("dropped {dropped} queued commands after {:?}", failed.cmd);
        if failed.cmd == Command::ArmPower(true) {
            self.arm.power_on_pending = 0;
        }
        self.arm.target = [None; ARM_JOINTS];
        self.vecmove = None;
        self.abort_trajectory(Status::LinkDown);
        self.dirty.arm = true;
    }

    /// The link came up at `now`: commands are accepted again, those sent before refused;
    /// whatever was commanded before is void (the arm holds where it is).
    pub fn link_up(&mut self, now: Instant) {
        self.link = LinkState {
            up: true,
            up_since_ns: monotonic_ns(),
            last_rx: now,
            up_at: now,
        };
        self.arm.target = [None; ARM_JOINTS];
        self.dirty.arm = true;
        self.dirty.body = true;
    }

    /// The link went down: commands are refused (LinkDown), nothing queued is sent later,
    /// a VECMOVE is abandoned. Returns how many queued commands were dropped.
    pub fn link_down(&mut self) -> usize {
        self.link.up = false;
        self.vecmove = None;
        self.abort_trajectory(Status::LinkDown);
        self.dirty.arm = true;
        self.dirty.body = true;
        self.outbox.clear()
    }

    /// True while the arm reports: the link is up and an ARMpac arrived within
    /// `link_timeout_ms` (counted from the link's coming up before the first). Otherwise
    /// what the model holds of the arm is stale: its state does not say LINK_UP and its
    /// commands are refused LINK_DOWN (the ARMpacs may be lost, or arrive malformed,
    /// while the SIPs keep the link up).
    pub fn arm_reporting(&self, now: Instant) -> bool {
        let since = self
            .arm
            .last_packet
            .map_or(self.link.up_at, |t| t.max(self.link.up_at));
        self.link.up
            && now.saturating_duration_since(since)
                <= Duration::from_millis(self.cfg.link_timeout_ms)
    }

    /// Notes whether the arm reports (the timer's work): a change is logged and makes the
    /// arm's devices publish their state.
    pub fn check_arm_reporting(&mut self, now: Instant) {
        let reporting = !self.has_arm || self.arm_reporting(now);
        if reporting == self.arm_reported {
            return;
        }
        self.arm_reported = reporting;
        self.dirty.arm = true;
        if reporting {
            tracing::info!("the arm reports again (ARMpacs arrive)");
        } else if self.link.up {
            tracing::warn!(
                "no ARMpac for {} ms while the link is up: the arm's state is stale, its \
                 commands are refused until ARMpacs arrive ({} malformed packets so far)",
                self.cfg.link_timeout_ms,
                self.malformed
            );
        }
    }

    /// True while the link is up.
    pub fn is_link_up(&self) -> bool {
        self.link.up
    }

    /// When the robot last sent a packet.
    pub fn last_rx(&self) -> Instant {
        self.link.last_rx
    }

    /// Malformed input from the robot so far: packets that do not parse and ARMINFOpacs
    /// that cannot be a calibration.
    pub fn malformed(&self) -> u64 {
        self.malformed
    }

    /// Counts malformed input from the robot and logs it: the first, then at powers of
    /// two, so a robot that keeps sending it is visible without flooding the log.
    pub fn note_malformed(&mut self, n: u64, what: &dyn core::fmt::Display) {
        for _ in 0..n {
            self.malformed += 1;
            if self.malformed.is_power_of_two() {
                tracing::warn!(
                    "malformed input from the robot ({} so far): {what}",
                    self.malformed
                );
            }
        }
    }

    /// Takes an ARMINFOpac's calibration if it can be one (at least one joint, each
    /// with ticks per 90° and a range); otherwise it is counted and logged as malformed
    /// and the calibration held (if any) stays. Returns whether it was taken.
    pub fn take_calibration(&mut self, cal: ArmCalibration) -> bool {
        // The robot answered ARM_INFO: it has an arm, calibrated or not.
        self.has_arm = true;
        self.dirty.arm = true;
        match calibration_problem(&cal) {
            None => {
                self.set_calibration(cal);
                true
            }
            Some(problem) => {
                self.note_malformed(1, &format_args!("ARMINFOpac not taken: {problem}"));
                false
            }
        }
    }

    /// Whether the body gripper and lift are served: the robot has them now (asked at
    /// every connection) or the configuration forces them.
    pub fn set_body_gripper(&mut self, served: bool) {
        self.body_gripper = served;
        self.dirty.body = true;
    }

    /// True once the robot answered ARM_INFO with a calibration.
    pub fn calibrated(&self) -> bool {
        self.cal.is_some()
    }

    /// The configuration.
    pub fn config(&self) -> &PioneerConfig {
        &self.cfg
    }

    /// The arm as the last ARMpac described it, and what was commanded.
    pub fn arm(&self) -> &ArmModel {
        &self.arm
    }

    /// Takes a SIP that arrived outside the loop (the handshake's last).
    pub fn set_sip(&mut self, sip: Sip) {
        self.sip = Some(sip);
        self.dirty.body = true;
    }

    /// Takes a packet from the robot at `now`: a SIP, an ARMpac (the next VECMOVE
    /// waypoint is queued when the arm reached the current one) or an ARMINFOpac.
    pub fn on_packet(&mut self, pkt: &RobotPacket<'_>, now: Instant) -> PacketEffect {
        self.link.last_rx = now;
        match pkt {
            RobotPacket::Sip(s) => {
                self.set_sip(*s);
                PacketEffect::Sip
            }
            RobotPacket::Arm(a) => {
                self.arm.update(a, self.cfg.armpac_layout, now);
                self.dirty.arm = true;
                if let Err(status) = self.stream_vecmove(&INTERNAL) {
                    // The next waypoint could not be queued (the link is down): the line
                    // is abandoned, never resumed on a later link.
                    tracing::warn!("VECMOVE abandoned: {status}");
                    self.vecmove = None;
                }
                PacketEffect::None
            }
            RobotPacket::ArmInfo(i) => {
                if self.take_calibration(ArmCalibration::from(*i)) {
                    PacketEffect::ArmInfo
                } else {
                    PacketEffect::None
                }
            }
            _ => PacketEffect::None,
        }
    }

    /// Motion needs a powered arm: an unpowered one would leave the command undone (and
    /// the joint STALLED), so it is refused as POWERED_OFF. Stopping needs no power.
    pub(super) fn require_power(&self) -> Result<(), Status> {
        if self.arm.powered_or_pending() {
            Ok(())
        } else {
            Err(Status::PoweredOff)
        }
    }

    pub(super) fn calibration(&self) -> Result<&ArmCalibration, Status> {
        if !self.link.up {
            return Err(Status::LinkDown);
        }
        if !self.has_arm {
            return Err(Status::Unsupported);
        }
        if !self.arm_reporting(Instant::now()) {
            return Err(Status::LinkDown);
        }
        self.cal.as_ref().ok_or(Status::NotCalibrated)
    }

    /// Joint `j`'s limits in radians (min <= max) and its tick for `rad`, validated.
    pub(super) fn joint_tick(&self, j: usize, rad: f64) -> Result<u8, Status> {
        if !rad.is_finite() {
            return Err(Status::NotFinite);
        }
        let cal = self.calibration()?;
        if j >= cal.num_joints().min(ARM_JOINTS) {
            return Err(Status::UnknownJoint);
        }
        let joint = ArmJoint::from_index(j).map_err(|_| Status::UnknownJoint)?;
        let [a, _, b, _] = cal
            .limits_radians(joint)
            .map_err(|_| Status::NotCalibrated)?;
        let (lo, hi) = (a.min(b), a.max(b));
        // Half a tick of slack for angles that round-trip through ticks.
        let slack = 0.5 * (hi - lo) / 255.0;
        if rad < lo - slack || rad > hi + slack {
            return Err(Status::BeyondLimits);
        }
        let t = cal
            .radians_to_ticks(joint, rad.clamp(lo, hi))
            .map_err(|_| Status::BeyondLimits)?;
        Ok(t.tick)
    }

    /// Current joint angles (driver convention), when calibrated.
    pub fn joint_angles(&self) -> Option<[f64; ARM_JOINTS]> {
        let cal = self.cal.as_ref()?;
        let mut out = [0.0; ARM_JOINTS];
        for (j, o) in out
            .iter_mut()
            .enumerate()
            .take(cal.num_joints().min(ARM_JOINTS))
        {
            let joint = ArmJoint::from_index(j).ok()?;
            *o = cal.ticks_to_radians(joint, self.arm.ticks[j]).ok()?;
        }
        Some(out)
    }

    /// Current kinematic θ.
    pub fn theta(&self) -> Option<Theta> {
        let q = self.joint_angles()?;
        Some(self.map.theta_from_driver(&[q[0], q[1], q[2], q[3], q[4]]))
    }

    pub(super) fn move_joint(&mut self, j: usize, rad: f64, from: &Origin) -> Result<(), Status> {
        let tick = self.joint_tick(j, rad)?;
        self.require_power()?;
        let joint = ArmJoint::from_index(j).map_err(|_| Status::UnknownJoint)?;
        self.send(&Command::ArmPos { joint, tick }, from)?;
        self.arm.set_target(j, tick);
        self.arm.goal[j] = Some(rad);
        Ok(())
    }
}
