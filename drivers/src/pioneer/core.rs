//! The driver's model of the robot and its command handling: what every device does with a
//! command or request, validated before anything is written to the link.

use std::time::{Duration, Instant};

use limber_interfaces::prelude::*;
use limber_services::Origin;
use limber_services::monotonic_ns;
use nalgebra::Vector3;

use crate::kinematics::pioneer::{
    ApproachPreference, DriverAngleMap, PIONEER_DOF, PioneerGeometry, PioneerIkError,
    PioneerIkOptions, Theta, VecMoveError, VecMoveOptions,
};
use crate::p2os::{
    ArmCalibration, ArmJoint, ArmPacket, Command, Connection, GripperCommand as P2Gripper,
    JointSelection, PaddleState, Sip,
};

use super::config::PioneerConfig;
use super::stats::LoopStats;

/// Joints of the arm actarray: 5 arm joints and the gripper.
pub const ARM_JOINTS: usize = 6;
/// Waypoints a VECMOVE may have (2 cm apart at most: several metres).
pub const MAX_WAYPOINTS: usize = 256;
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
    /// Commanded target tick per joint (None: hold wherever it is).
    pub target: [Option<u8>; ARM_JOINTS],
    /// Since when a joint has been still but short of its target.
    pub short_since: [Option<Instant>; ARM_JOINTS],
    /// When the last ARMpac arrived (`CLOCK_MONOTONIC` ns).
    pub stamp_ns: u64,
}

impl Default for ArmModel {
    fn default() -> Self {
        ArmModel {
            ticks: [0; ARM_JOINTS],
            seen: false,
            moving: 0,
            powered: false,
            target: [None; ARM_JOINTS],
            short_since: [None; ARM_JOINTS],
            stamp_ns: 0,
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

    /// Applies an ARMpac.
    pub fn update(&mut self, p: &ArmPacket, now: Instant) {
        self.ticks = p.ticks;
        self.moving = p.moving_mask();
        self.powered = p.is_powered();
        self.seen = true;
        self.stamp_ns = monotonic_ns();
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

    fn set_target(&mut self, j: usize, tick: u8) {
        self.target[j] = Some(tick);
        self.short_since[j] = None;
    }
}

/// The lift, whose position the robot does not report: estimated from time while moving.
#[derive(Debug, Clone)]
pub struct LiftModel {
    /// Estimated position, m (0 = down).
    pub position: f64,
    /// Where it is going.
    pub target: f64,
    /// Moving since (start time, start position).
    pub moving: Option<(Instant, f64)>,
    /// The switches said it is moving.
    pub switch_moving: bool,
    /// The switches said it is at a limit.
    pub at_limit: bool,
}

impl LiftModel {
    fn new(stroke: f64) -> Self {
        // Player homes the lift up; assume it starts there until the switches say more.
        LiftModel {
            position: stroke,
            target: stroke,
            moving: None,
            switch_moving: false,
            at_limit: true,
        }
    }

    /// Updates the time-based estimate.
    pub fn estimate(&mut self, now: Instant, speed: f64, stroke: f64) {
        if let Some((t0, p0)) = self.moving {
            let travelled = now.duration_since(t0).as_secs_f64() * speed;
            let dir = (self.target - p0).signum();
            let p = p0 + dir * travelled;
            let reached = if dir > 0.0 {
                p >= self.target
            } else {
                p <= self.target
            };
            self.position = if reached { self.target } else { p }.clamp(0.0, stroke);
            if reached && !self.switch_moving {
                self.moving = None;
            }
        }
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

/// The driver's state and the link.
pub struct Core {
    /// The configuration.
    pub cfg: PioneerConfig,
    /// The connection while the link is up.
    pub conn: Option<Connection>,
    /// When the link came up (commands sent earlier are refused: never replayed).
    pub link_up_since_ns: u64,
    /// When the last packet arrived.
    pub last_rx: Instant,
    /// Calibration from ARMINFO.
    pub cal: Option<ArmCalibration>,
    /// The robot answered ARM_INFO.
    pub has_arm: bool,
    /// Arm kinematics.
    pub geom: PioneerGeometry,
    /// Driver ↔ kinematic angles.
    pub map: DriverAngleMap,
    /// IK options.
    pub ik: PioneerIkOptions,
    /// The arm.
    pub arm: ArmModel,
    /// The last limb target was out of reach (cleared by the next valid limb command).
    pub limb_oor: bool,
    /// A VECMOVE being streamed.
    pub vecmove: Option<Box<VecMovePlan>>,
    /// End-effector speed for limb motions, m/s.
    pub limb_speed: f64,
    /// The lift.
    pub lift: LiftModel,
    /// The latest SIP.
    pub sip: Option<Sip>,
    /// The last body-gripper command (OPEN/CLOSE/STOP).
    pub gripper_cmd: Option<GripperCommand>,
    /// The last arm-gripper command.
    pub armgrip_cmd: Option<GripperCommand>,
    /// What changed on the link since the last publish.
    pub dirty: Dirty,
    /// Loop statistics.
    pub stats: LoopStats,
}

impl core::fmt::Debug for Core {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Core")
            .field("link_up", &self.conn.is_some())
            .field("has_arm", &self.has_arm)
            .finish()
    }
}

fn ik_status(e: &PioneerIkError) -> Status {
    match e {
        PioneerIkError::NonFinite => Status::NotFinite,
        e if e.is_out_of_reach() => Status::OutOfReach,
        _ => Status::OutOfReach,
    }
}

impl Core {
    /// A core for `cfg`, link down.
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
        Core {
            cfg,
            conn: None,
            link_up_since_ns: 0,
            last_rx: Instant::now(),
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
            limb_oor: false,
            vecmove: None,
            limb_speed,
            lift,
            sip: None,
            gripper_cmd: None,
            armgrip_cmd: None,
            dirty: Dirty::default(),
            stats: LoopStats::default(),
        }
    }

    /// Takes the calibration: sets the IK joint limits (in θ, from the driver-convention
    /// limits) and marks the arm present.
    pub fn set_calibration(&mut self, cal: ArmCalibration) {
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

    /// Writes a command to the link. Refused (LinkDown) when the link is down, or when
    /// the client sent it before the link came up (never replayed after a fault).
    pub fn send(&mut self, cmd: &Command, from: &Origin) -> Result<(), Status> {
        if from.sent_ns != 0 && from.sent_ns < self.link_up_since_ns {
            return Err(Status::LinkDown);
        }
        let conn = self.conn.as_mut().ok_or(Status::LinkDown)?;
        match conn.send(cmd) {
            Ok(()) => {
                if from.sent_ns != 0 {
                    self.stats
                        .cmd_to_wire
                        .push(monotonic_ns().saturating_sub(from.sent_ns));
                }
                Ok(())
            }
            Err(_) => {
                // The loop notices the dead link (read error or silence) and reconnects.
                Err(Status::LinkDown)
            }
        }
    }

    fn calibration(&self) -> Result<&ArmCalibration, Status> {
        if self.conn.is_none() {
            return Err(Status::LinkDown);
        }
        if !self.has_arm {
            return Err(Status::Unsupported);
        }
        self.cal.as_ref().ok_or(Status::NotCalibrated)
    }

    /// Joint `j`'s limits in radians (min <= max) and its tick for `rad`, validated.
    fn joint_tick(&self, j: usize, rad: f64) -> Result<u8, Status> {
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

    fn move_joint(&mut self, j: usize, rad: f64, from: &Origin) -> Result<(), Status> {
        let tick = self.joint_tick(j, rad)?;
        let joint = ArmJoint::from_index(j).map_err(|_| Status::UnknownJoint)?;
        self.send(&Command::ArmPos { joint, tick }, from)?;
        self.arm.set_target(j, tick);
        Ok(())
    }

    // ----- arm actarray ----------------------------------------------------------------

    /// An arm actarray command.
    pub fn arm_command(&mut self, cmd: &ActArrayCommand, from: &Origin) -> Status {
        let r = match *cmd {
            ActArrayCommand::Position { joint, position } => {
                self.vecmove = None;
                self.move_joint(joint as usize, position, from)
            }
            ActArrayCommand::MultiPosition(v) => {
                self.vecmove = None;
                // Validate every joint before sending any.
                let mut ticks = [0u8; ARM_JOINTS];
                let r = v.as_slice().iter().enumerate().try_for_each(|(j, p)| {
                    ticks[j] = self.joint_tick(j, *p)?;
                    Ok(())
                });
                r.and_then(|()| {
                    for (j, &tick) in ticks.iter().enumerate().take(v.len()) {
                        let joint = ArmJoint::from_index(j).map_err(|_| Status::UnknownJoint)?;
                        self.send(&Command::ArmPos { joint, tick }, from)?;
                        self.arm.set_target(j, tick);
                    }
                    Ok(())
                })
            }
            ActArrayCommand::Speed { joint, speed } => {
                self.move_at_speed(joint as usize, speed, from)
            }
            ActArrayCommand::MultiSpeed(v) => {
                let r = v.as_slice().iter().enumerate().try_for_each(|(j, _)| {
                    self.joint_tick(j, 0.0).map(|_| ()).or_else(|e| {
                        if e == Status::BeyondLimits {
                            Ok(())
                        } else {
                            Err(e)
                        }
                    })
                });
                r.and_then(|()| {
                    v.as_slice()
                        .iter()
                        .enumerate()
                        .try_for_each(|(j, s)| self.move_at_speed(j, *s, from))
                })
            }
            ActArrayCommand::Home(sel) => self.home(sel, from),
            ActArrayCommand::Current { .. } | ActArrayCommand::MultiCurrent(_) => {
                Err(Status::Unsupported)
            }
        };
        r.err().unwrap_or(Status::Ok)
    }

    fn move_at_speed(&mut self, j: usize, speed: f64, from: &Origin) -> Result<(), Status> {
        let cal = self.calibration()?;
        if j >= cal.num_joints().min(ARM_JOINTS) {
            return Err(Status::UnknownJoint);
        }
        let joint = ArmJoint::from_index(j).map_err(|_| Status::UnknownJoint)?;
        if !speed.is_finite() {
            return Err(Status::NotFinite);
        }
        if speed == 0.0 {
            self.send(&Command::ArmStop(JointSelection::One(joint)), from)?;
            self.arm.target[j] = None;
            return Ok(());
        }
        let ms = cal
            .speed_to_ms_per_step(joint, speed.abs())
            .map_err(|_| Status::InvalidArgument)?;
        let [a, _, b, _] = cal
            .limits_radians(joint)
            .map_err(|_| Status::NotCalibrated)?;
        let end = if speed > 0.0 { a.max(b) } else { a.min(b) };
        let tick = self.joint_tick(j, end)?;
        self.send(
            &Command::ArmSpeed {
                joint,
                ms_per_step: ms,
            },
            from,
        )?;
        self.send(&Command::ArmPos { joint, tick }, from)?;
        self.arm.set_target(j, tick);
        Ok(())
    }

    fn home(&mut self, sel: JointSel, from: &Origin) -> Result<(), Status> {
        let cal = *self.calibration()?;
        self.vecmove = None;
        match sel {
            JointSel::All => {
                self.send(&Command::ArmHome(JointSelection::All), from)?;
                for j in 0..cal.num_joints().min(ARM_JOINTS) {
                    if let Ok(c) =
                        cal.joint(ArmJoint::from_index(j).map_err(|_| Status::UnknownJoint)?)
                    {
                        self.arm.set_target(j, c.home);
                    }
                }
            }
            JointSel::One(j) => {
                let j = j as usize;
                if j >= cal.num_joints().min(ARM_JOINTS) {
                    return Err(Status::UnknownJoint);
                }
                let joint = ArmJoint::from_index(j).map_err(|_| Status::UnknownJoint)?;
                self.send(&Command::ArmHome(JointSelection::One(joint)), from)?;
                if let Ok(c) = cal.joint(joint) {
                    self.arm.set_target(j, c.home);
                }
            }
        }
        Ok(())
    }

    /// An arm actarray request.
    pub fn arm_request(
        &mut self,
        req: &ActArrayRequest,
        from: &Origin,
    ) -> Result<ActArrayReply, Status> {
        match *req {
            ActArrayRequest::Power(on) => {
                self.calibration()?;
                self.send(&Command::ArmPower(on), from)?;
                Ok(ActArrayReply::Done)
            }
            ActArrayRequest::GetGeom => Ok(ActArrayReply::Geom(self.arm_geometry()?)),
            ActArrayRequest::Speed { joint, speed } => {
                let cal = self.calibration()?;
                let j = joint as usize;
                if j >= cal.num_joints().min(ARM_JOINTS) {
                    return Err(Status::UnknownJoint);
                }
                if !(speed.is_finite() && speed > 0.0) {
                    return Err(if speed.is_finite() {
                        Status::InvalidArgument
                    } else {
                        Status::NotFinite
                    });
                }
                // This joint's own calibration (Player used joint j+1's).
                let aj = ArmJoint::from_index(j).map_err(|_| Status::UnknownJoint)?;
                let ms = cal
                    .speed_to_ms_per_step(aj, speed)
                    .map_err(|_| Status::InvalidArgument)?;
                self.send(
                    &Command::ArmSpeed {
                        joint: aj,
                        ms_per_step: ms,
                    },
                    from,
                )?;
                Ok(ActArrayReply::Done)
            }
            ActArrayRequest::Brakes(_) | ActArrayRequest::Accel { .. } => Err(Status::Unsupported),
        }
    }

    /// The arm geometry from the calibration.
    pub fn arm_geometry(&self) -> Result<ActArrayGeom, Status> {
        let cal = self
            .cal
            .as_ref()
            .ok_or(if self.has_arm || self.conn.is_none() {
                Status::NotCalibrated
            } else {
                Status::Unsupported
            })?;
        let mut g = ActArrayGeom {
            actuators_count: cal.num_joints().min(ARM_JOINTS) as u32,
            base_pos: Vec3::from(self.cfg.arm_base),
            ..Default::default()
        };
        #[allow(clippy::needless_range_loop)]
        for j in 0..g.actuators_count as usize {
            let joint = ArmJoint::from_index(j).map_err(|_| Status::UnknownJoint)?;
            let [a, c, b, h] = cal
                .limits_radians(joint)
                .map_err(|_| Status::NotCalibrated)?;
            let jc = cal.joint(joint).map_err(|_| Status::NotCalibrated)?;
            let speed = cal.ms_per_step_to_speed(joint, jc.speed).unwrap_or(0.0);
            g.actuators[j] = ActuatorGeom {
                kind: ActuatorKind::Rotary as u32,
                has_brakes: 0,
                length: self.cfg.arm_geometry_lengths[j],
                orientation: Orientation3::default(),
                axis: Vec3::from(AXES[j]),
                min: a.min(b),
                centre: c,
                max: a.max(b),
                home: h,
                config_speed: speed,
            };
        }
        Ok(g)
    }

    /// Fills the arm actarray state.
    pub fn arm_state(&self, s: &mut ActArrayData, now: Instant) {
        let n = self
            .cal
            .as_ref()
            .map(|c| c.num_joints().min(ARM_JOINTS))
            .unwrap_or(ARM_JOINTS);
        s.actuators_count = n as u32;
        s.motor_state = self.arm.powered as u32;
        let q = self.joint_angles();
        for j in 0..n {
            let a = &mut s.actuators[j];
            a.position = q.map(|q| q[j]).unwrap_or(0.0);
            a.speed = 0.0;
            a.acceleration = -1.0;
            a.current = -1.0;
            a.state = self
                .arm
                .flags(j, now, Duration::from_millis(self.cfg.stall_timeout_ms))
                .bits();
        }
        s.header.stamp_ns = self.arm.stamp_ns;
    }

    // ----- limb ------------------------------------------------------------------------

    fn send_theta(&mut self, theta: &Theta, from: &Origin) -> Result<(), Status> {
        let q = self.map.driver_from_theta(theta);
        let mut ticks = [0u8; PIONEER_DOF];
        for j in 0..PIONEER_DOF {
            ticks[j] = self.joint_tick(j, q[j]).map_err(|e| {
                if e == Status::BeyondLimits {
                    Status::OutOfReach
                } else {
                    e
                }
            })?;
        }
        self.send_ticks(&ticks, from)
    }

    fn send_ticks(&mut self, ticks: &[u8; PIONEER_DOF], from: &Origin) -> Result<(), Status> {
        for (j, &tick) in ticks.iter().enumerate() {
            let joint = ArmJoint::from_index(j).map_err(|_| Status::UnknownJoint)?;
            if self.arm.target[j] != Some(tick) || self.arm.ticks[j] != tick {
                self.send(&Command::ArmPos { joint, tick }, from)?;
            }
            self.arm.set_target(j, tick);
        }
        Ok(())
    }

    /// A limb command.
    pub fn limb_command(&mut self, cmd: &LimbCommand, from: &Origin) -> Status {
        let r = self.limb_command_inner(cmd, from);
        match r {
            Ok(()) => {
                self.limb_oor = false;
                Status::Ok
            }
            Err(Status::OutOfReach) => {
                self.limb_oor = true;
                Status::OutOfReach
            }
            Err(e) => e,
        }
    }

    fn limb_command_inner(&mut self, cmd: &LimbCommand, from: &Origin) -> Result<(), Status> {
        self.calibration()?;
        let current = self.theta().ok_or(Status::NotCalibrated)?;
        match *cmd {
            LimbCommand::Home => {
                self.vecmove = None;
                self.home(JointSel::All, from)
            }
            LimbCommand::Stop => {
                self.vecmove = None;
                // Every joint, the wrist pitch included (Player left joint 5 moving).
                self.send(&Command::ArmStop(JointSelection::All), from)?;
                self.arm.target = [None; ARM_JOINTS];
                Ok(())
            }
            LimbCommand::SetPose {
                position,
                approach,
                orientation,
            } => {
                self.vecmove = None;
                let c = self
                    .geom
                    .solve_setpose(
                        &Vector3::from(position.to_array()),
                        &Vector3::from(approach.to_array()),
                        &Vector3::from(orientation.to_array()),
                        &current,
                        &self.ik,
                    )
                    .map_err(|e| ik_status(&e))?;
                self.send_theta(&c.theta, from)
            }
            LimbCommand::SetPosition { position } => {
                self.vecmove = None;
                let p = Vector3::from(position.to_array()) - self.geom.base_offset;
                let c = self
                    .geom
                    .solve_position(&p, ApproachPreference::Current, &current, &self.ik)
                    .map_err(|e| ik_status(&e))?;
                self.send_theta(&c.theta, from)
            }
            LimbCommand::VecMove { direction, length } => {
                if length < 0.0 {
                    return Err(Status::InvalidArgument);
                }
                let opts = VecMoveOptions {
                    max_deviation: self.cfg.vecmove_deviation,
                    ik: self.ik,
                    ..VecMoveOptions::default()
                };
                let plan = self
                    .geom
                    .vecmove(
                        &current,
                        &Vector3::from(direction.to_array()),
                        length,
                        &opts,
                    )
                    .map_err(|e| match e {
                        VecMoveError::NonFinite => Status::NotFinite,
                        VecMoveError::ZeroDirection | VecMoveError::InvalidOptions => {
                            Status::InvalidArgument
                        }
                        _ => Status::OutOfReach,
                    })?;
                // Validate the whole line before moving: every waypoint reachable and
                // inside the limits.
                let mut p = Box::new(VecMovePlan {
                    waypoints: [[0; PIONEER_DOF]; MAX_WAYPOINTS],
                    len: 0,
                    next: 0,
                });
                for wp in plan {
                    let theta = wp.map_err(|_| Status::OutOfReach)?.theta;
                    if p.len == MAX_WAYPOINTS {
                        return Err(Status::InvalidArgument);
                    }
                    let q = self.map.driver_from_theta(&theta);
                    #[allow(clippy::needless_range_loop)]
                    for j in 0..PIONEER_DOF {
                        p.waypoints[p.len][j] = self.joint_tick(j, q[j]).map_err(|e| {
                            if e == Status::BeyondLimits {
                                Status::OutOfReach
                            } else {
                                e
                            }
                        })?;
                    }
                    p.len += 1;
                }
                self.vecmove = Some(p);
                self.stream_vecmove(from)
            }
        }
    }

    /// Sends the next VECMOVE waypoint once the arm has reached the current one.
    pub fn stream_vecmove(&mut self, from: &Origin) -> Result<(), Status> {
        let Some(plan) = self.vecmove.as_mut() else {
            return Ok(());
        };
        let reached =
            (0..PIONEER_DOF).all(|j| self.arm.target[j].is_none_or(|t| t == self.arm.ticks[j]));
        if plan.next > 0 && !reached {
            return Ok(());
        }
        // Skip waypoints that quantise to the ticks already commanded.
        while plan.next < plan.len
            && (0..PIONEER_DOF).all(|j| Some(plan.waypoints[plan.next][j]) == self.arm.target[j])
        {
            plan.next += 1;
        }
        if plan.next >= plan.len {
            self.vecmove = None;
            return Ok(());
        }
        let wp = plan.waypoints[plan.next];
        plan.next += 1;
        self.send_ticks(&wp, from)
    }

    /// A limb request.
    pub fn limb_request(&mut self, req: &LimbRequest, from: &Origin) -> Result<LimbReply, Status> {
        match *req {
            LimbRequest::Power(on) => {
                self.calibration()?;
                self.send(&Command::ArmPower(on), from)?;
                Ok(LimbReply::Done)
            }
            LimbRequest::Geom => Ok(LimbReply::Geom(LimbGeom {
                base_pos: Vec3::from(self.cfg.arm_base),
            })),
            LimbRequest::Speed(v) => {
                if v.is_nan() || v <= 0.0 {
                    return Err(Status::InvalidArgument);
                }
                let cal = *self.calibration()?;
                // The end effector moves at about v when each joint turns at v / r, with r
                // the arm's reach from the shoulder (≈ 0.4 m).
                let reach = self.geom.l2 + self.geom.l4 + self.geom.l5;
                for j in 0..PIONEER_DOF {
                    let joint = ArmJoint::from_index(j).map_err(|_| Status::UnknownJoint)?;
                    let ms = cal
                        .speed_to_ms_per_step(joint, v / reach)
                        .map_err(|_| Status::InvalidArgument)?;
                    self.send(
                        &Command::ArmSpeed {
                            joint,
                            ms_per_step: ms,
                        },
                        from,
                    )?;
                }
                self.limb_speed = v;
                Ok(LimbReply::Done)
            }
            LimbRequest::Brakes(_) => Err(Status::Unsupported),
        }
    }

    /// Fills the limb state: FK of the current joints, and the state.
    pub fn limb_state(&self, s: &mut LimbData, now: Instant) {
        if let Some(theta) = self.theta()
            && let Ok(pose) = self.geom.fk_robot(&theta)
        {
            let (p, a, o) = (pose.position, pose.approach(), pose.orientation());
            s.position = Vec3::new(p.x, p.y, p.z);
            s.approach = Vec3::new(a.x, a.y, a.z);
            s.orientation = Vec3::new(o.x, o.y, o.z);
        }
        let stall = Duration::from_millis(self.cfg.stall_timeout_ms);
        let flags: [ActuatorFlags; PIONEER_DOF] =
            core::array::from_fn(|j| self.arm.flags(j, now, stall));
        s.state = if self.limb_oor {
            LimbState::OutOfReach
        } else if flags.iter().any(|f| f.contains(ActuatorFlags::STALLED)) {
            LimbState::Collision
        } else if self.vecmove.is_some() || flags.iter().any(|f| f.contains(ActuatorFlags::MOVING))
        {
            LimbState::Moving
        } else {
            LimbState::Idle
        } as u32;
        s.header.stamp_ns = self.arm.stamp_ns;
    }

    // ----- arm gripper (joint 6) --------------------------------------------------------

    /// An arm-gripper command.
    pub fn armgrip_command(&mut self, cmd: &GripperCommand, from: &Origin) -> Status {
        let r = (|| {
            let cal = *self.calibration()?;
            let joint = ArmJoint::GRIPPER;
            let c = *cal.joint(joint).map_err(|_| Status::Unsupported)?;
            match cmd {
                GripperCommand::Open | GripperCommand::Close => {
                    let tick = if *cmd == GripperCommand::Open {
                        c.max.max(c.min)
                    } else {
                        c.max.min(c.min)
                    };
                    self.send(&Command::ArmPos { joint, tick }, from)?;
                    self.arm.set_target(joint.index(), tick);
                }
                GripperCommand::Stop => {
                    self.send(&Command::ArmStop(JointSelection::One(joint)), from)?;
                    self.arm.target[joint.index()] = None;
                }
                GripperCommand::Store | GripperCommand::Retrieve => {
                    return Err(Status::Unsupported);
                }
            }
            self.armgrip_cmd = Some(*cmd);
            Ok(())
        })();
        r.err().unwrap_or(Status::Ok)
    }

    /// Fills the arm-gripper state.
    pub fn armgrip_state(&self, s: &mut GripperData, now: Instant) {
        let j = ArmJoint::GRIPPER.index();
        let stall = Duration::from_millis(self.cfg.stall_timeout_ms);
        let f = self.arm.flags(j, now, stall);
        s.state = if f.contains(ActuatorFlags::MOVING) {
            GripperState::Moving
        } else {
            match self.armgrip_cmd {
                Some(GripperCommand::Close) => GripperState::Closed, // stopped at the target or on an object
                Some(GripperCommand::Open) if f.contains(ActuatorFlags::STALLED) => {
                    GripperState::Error
                }
                Some(GripperCommand::Open) => GripperState::Open,
                _ => match self
                    .cal
                    .as_ref()
                    .and_then(|c| c.joint(ArmJoint::GRIPPER).ok())
                {
                    Some(c) if self.arm.ticks[j] > c.centre => GripperState::Open,
                    Some(_) => GripperState::Closed,
                    None => GripperState::Error,
                },
            }
        } as u32;
        s.beams = 0;
        s.stored = 0;
        s.header.stamp_ns = self.arm.stamp_ns;
    }

    // ----- body gripper and lift ---------------------------------------------------------

    /// A body-gripper command.
    pub fn gripper_command(&mut self, cmd: &GripperCommand, from: &Origin) -> Status {
        let p2 = match cmd {
            GripperCommand::Open => P2Gripper::Open,
            GripperCommand::Close => P2Gripper::Close,
            GripperCommand::Stop => P2Gripper::Stop,
            GripperCommand::Store | GripperCommand::Retrieve => return Status::Unsupported,
        };
        match self.send(&Command::Gripper(p2), from) {
            Ok(()) => {
                self.gripper_cmd = Some(*cmd);
                Status::Ok
            }
            Err(e) => e,
        }
    }

    /// Fills the body-gripper state from the SIP's switch byte (ARIA's reading).
    pub fn gripper_state(&self, s: &mut GripperData) {
        let Some(sip) = self.sip.as_ref() else {
            s.state = GripperState::Error as u32;
            return;
        };
        let sw = sip.gripper_switches();
        s.state = match sw.paddles() {
            PaddleState::Open => GripperState::Open,
            PaddleState::Closed => GripperState::Closed,
            PaddleState::Moving => GripperState::Moving,
            PaddleState::Between => {
                if self.gripper_cmd == Some(GripperCommand::Close) {
                    GripperState::Closed
                } else {
                    GripperState::Open
                }
            }
        } as u32;
        // Beam 0 = outer, beam 1 = inner.
        s.beams = sw.outer_beam() as u32 | (sw.inner_beam() as u32) << 1;
        s.stored = 0;
    }

    /// A lift command (one linear actuator, metres).
    pub fn lift_command(&mut self, cmd: &ActArrayCommand, from: &Origin) -> Status {
        let stroke = self.cfg.lift_stroke;
        let r = match *cmd {
            ActArrayCommand::Position { joint, position } => {
                if joint != 0 {
                    Err(Status::UnknownJoint)
                } else if !(0.0..=stroke).contains(&position) {
                    Err(Status::BeyondLimits)
                } else {
                    self.lift_to(position, from)
                }
            }
            ActArrayCommand::MultiPosition(v) => match v.as_slice() {
                [p] if (0.0..=stroke).contains(p) => self.lift_to(*p, from),
                [_] => Err(Status::BeyondLimits),
                _ => Err(Status::UnknownJoint),
            },
            ActArrayCommand::Home(JointSel::All) | ActArrayCommand::Home(JointSel::One(0)) => {
                self.lift_to(stroke, from)
            }
            ActArrayCommand::Home(JointSel::One(_)) => Err(Status::UnknownJoint),
            ActArrayCommand::Speed {
                joint: 0,
                speed: 0.0,
            } => {
                let r = self.send(&Command::Gripper(P2Gripper::LiftStop), from);
                if r.is_ok() {
                    self.lift.target = self.lift.position;
                    self.lift.moving = None;
                }
                r
            }
            _ => Err(Status::Unsupported),
        };
        r.err().unwrap_or(Status::Ok)
    }

    fn lift_to(&mut self, target: f64, from: &Origin) -> Result<(), Status> {
        let stroke = self.cfg.lift_stroke;
        let eps = 1e-4;
        if target >= stroke - eps {
            self.send(&Command::Gripper(P2Gripper::LiftUp), from)?;
        } else if target <= eps {
            self.send(&Command::Gripper(P2Gripper::LiftDown), from)?;
        } else {
            // Relative, time-based: 20 ms units, negative = down.
            let secs = (target - self.lift.position) / self.cfg.lift_speed;
            let units = (secs / 0.02)
                .round()
                .clamp(i16::MIN as f64, i16::MAX as f64) as i16;
            if units == 0 {
                return Ok(());
            }
            self.send(&Command::Gripper(P2Gripper::LiftCarry), from)?;
            self.send(&Command::GripperValue(units), from)?;
        }
        self.lift.target = target.clamp(0.0, stroke);
        self.lift.moving = Some((Instant::now(), self.lift.position));
        Ok(())
    }

    /// The lift geometry: one linear actuator, every field set.
    pub fn lift_geometry(&self) -> ActArrayGeom {
        let mut g = ActArrayGeom {
            actuators_count: 1,
            base_pos: Vec3::from([
                self.cfg.gripper.pose[0],
                self.cfg.gripper.pose[1],
                self.cfg.gripper.pose[2],
            ]),
            ..Default::default()
        };
        g.actuators[0] = ActuatorGeom {
            kind: ActuatorKind::Linear as u32,
            has_brakes: 0,
            length: 0.0,
            orientation: Orientation3::default(),
            axis: Vec3::new(0.0, 0.0, 1.0),
            min: 0.0,
            centre: self.cfg.lift_stroke / 2.0,
            max: self.cfg.lift_stroke,
            home: self.cfg.lift_stroke,
            config_speed: self.cfg.lift_speed,
        };
        g
    }

    /// Applies a SIP to the lift model.
    pub fn lift_from_sip(&mut self, now: Instant) {
        if let Some(sip) = self.sip.as_ref() {
            let sw = sip.gripper_switches();
            self.lift.switch_moving = sw.lift_moving();
            self.lift.at_limit = sw.lift_at_limit();
            if self.lift.at_limit && !self.lift.switch_moving {
                // At a limit: which one follows from where it was going.
                let top = self.lift.target >= self.cfg.lift_stroke / 2.0;
                if self
                    .lift
                    .moving
                    .is_none_or(|(t, _)| now.duration_since(t) > Duration::from_millis(300))
                {
                    self.lift.position = if top { self.cfg.lift_stroke } else { 0.0 };
                    self.lift.target = self.lift.position;
                    self.lift.moving = None;
                }
            }
        }
        self.lift
            .estimate(now, self.cfg.lift_speed, self.cfg.lift_stroke);
    }

    /// Fills the lift state.
    pub fn lift_state(&self, s: &mut ActArrayData) {
        s.actuators_count = 1;
        s.motor_state = 1;
        let a = &mut s.actuators[0];
        a.position = self.lift.position;
        let moving = self.lift.moving.is_some() || self.lift.switch_moving;
        a.speed = if moving {
            self.cfg.lift_speed * (self.lift.target - self.lift.position).signum()
        } else {
            0.0
        };
        a.acceleration = -1.0;
        a.current = -1.0;
        a.state = if moving {
            ActuatorFlags::MOVING
        } else {
            ActuatorFlags::IDLE
        }
        .bits();
    }

    /// A lift request.
    pub fn lift_request(&mut self, req: &ActArrayRequest) -> Result<ActArrayReply, Status> {
        match req {
            ActArrayRequest::GetGeom => Ok(ActArrayReply::Geom(self.lift_geometry())),
            _ => Err(Status::Unsupported),
        }
    }
}
