//! The simulated arm itself, without any transport: joints that move toward their
//! targets at their speeds when [`ArmModel::advance`] is called, the limb's inverse
//! kinematics, VECMOVE streaming, the parallel gripper and an optional object to grasp.
//!
//! Every command is validated completely before anything moves. Nothing here allocates
//! after [`ArmModel::new`] (the VECMOVE plan has a fixed capacity) and nothing panics on
//! bad input.

use limber_interfaces::prelude::*;
use nalgebra::Vector3;

use limber_kinematics::chain::ChainIkError;
use limber_kinematics::chain::{
    Chain, IkTarget, JointKind, JointVec, MAX_JOINTS, NumericIkOptions,
};
use limber_kinematics::{Pose, fit_angle_to_limits, unit_direction};

/// Most waypoints of one VECMOVE (at [`SimArmOptions::vecmove_step`] apart).
pub const MAX_WAYPOINTS: usize = 512;

/// The gripper simulated when the chain file describes none: 8 cm stroke, 0.1 m/s.
pub const DEFAULT_GRIPPER_STROKE: f64 = 0.08;
/// Finger speed of the default gripper, m/s.
pub const DEFAULT_GRIPPER_SPEED: f64 = 0.1;

/// Largest joint jump (rad or m) accepted between two consecutive VECMOVE waypoints; a
/// bigger jump means the inverse switched branches, which would leave the line.
const MAX_WAYPOINT_JUMP: f64 = 0.5;

/// Tolerance (rad) on the perpendicularity of SETPOSE's approach and orientation.
const PERPENDICULAR_TOLERANCE: f64 = 0.05;

/// A target is reached when within this distance (rad or m).
const REACHED: f64 = 1e-12;

/// An object the gripper can close on: it stops the fingers at its width, the gripper's
/// beam (bit 0) sees it while it is between the fingers, and it follows the tool while
/// held.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SimObject {
    /// Centre, in the robot frame, m.
    pub position: [f64; 3],
    /// Width across the fingers, m (must be below the gripper's stroke to be gripped).
    pub width: f64,
    /// The object is between the fingers when the tool point is this close to its
    /// centre, m.
    pub capture_radius: f64,
}

impl SimObject {
    /// A block of `width` at `position`, captured within 2 cm.
    pub fn block(position: [f64; 3], width: f64) -> Self {
        SimObject {
            position,
            width,
            capture_radius: 0.02,
        }
    }
}

/// Options of the simulation.
#[derive(Debug, Clone, PartialEq)]
pub struct SimArmOptions {
    /// Robot name in the device names (`simarm`).
    pub robot: String,
    /// Period of the simulation and publishing tick (10 ms).
    pub tick: core::time::Duration,
    /// Simulated seconds per real second (1.0; 2.0 moves twice as fast). > 0.
    pub time_scale: f64,
    /// Distance between VECMOVE waypoints, m (5 mm).
    pub vecmove_step: f64,
    /// An object to grasp, if any.
    pub object: Option<SimObject>,
    /// Options of the numeric inverse kinematics.
    pub ik: NumericIkOptions,
}

impl Default for SimArmOptions {
    fn default() -> Self {
        SimArmOptions {
            robot: "simarm".to_string(),
            tick: core::time::Duration::from_millis(10),
            time_scale: 1.0,
            vecmove_step: 0.005,
            object: None,
            ik: NumericIkOptions::default(),
        }
    }
}

/// Why the options cannot be used.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum OptionsError {
    /// The tick is zero or longer than one second.
    #[error("tick must be in (0, 1 s]")]
    Tick,
    /// The time scale is not a finite positive number.
    #[error("time scale must be finite and > 0")]
    TimeScale,
    /// The VECMOVE step is not a finite positive number.
    #[error("vecmove step must be finite and > 0")]
    VecMoveStep,
    /// The object's width or capture radius is not finite and positive, or its position
    /// is not finite.
    #[error("object position must be finite, width and capture radius > 0")]
    Object,
    /// The chain has more joints than an actuator array can carry with the gripper.
    #[error("chain has too many joints")]
    TooManyJoints,
}

/// One actuator's motion.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Motion {
    /// Current position, rad or m.
    pos: f64,
    /// Where it is going (equal to `pos` when idle).
    target: f64,
    /// Speed of the current move (> 0 while moving), rad/s or m/s.
    speed: f64,
    /// Signed velocity during the last step, for the state.
    velocity: f64,
    /// Moving toward `target`.
    moving: bool,
    /// Blocked (the gripper squeezing an object).
    stalled: bool,
}

impl Motion {
    fn at(pos: f64) -> Self {
        Motion {
            pos,
            target: pos,
            speed: 0.0,
            velocity: 0.0,
            moving: false,
            stalled: false,
        }
    }

    fn go(&mut self, target: f64, speed: f64) {
        self.target = target;
        self.speed = speed;
        self.stalled = false;
        self.moving = (target - self.pos).abs() > REACHED && speed > 0.0;
        if !self.moving {
            self.pos = target;
            self.velocity = 0.0;
        }
    }

    fn stop(&mut self) {
        self.target = self.pos;
        self.moving = false;
        self.velocity = 0.0;
    }

    /// Advances by `dt` seconds.
    fn step(&mut self, dt: f64) {
        if !self.moving {
            self.velocity = 0.0;
            return;
        }
        let d = self.target - self.pos;
        let max = self.speed * dt;
        if d.abs() <= max + 1e-12 {
            self.pos = self.target;
            self.moving = false;
            self.velocity = if dt > 0.0 { d / dt } else { 0.0 };
        } else {
            self.pos += max.copysign(d);
            self.velocity = self.speed.copysign(d);
        }
    }
}

/// What the gripper was last told.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum GripperCmd {
    None,
    Open,
    Close,
}

/// The VECMOVE being streamed.
#[derive(Debug)]
struct VecMovePlan {
    waypoints: Vec<JointVec>,
    /// Where a new line is solved, swapped with `waypoints` once every waypoint is
    /// known, so a refused line leaves the running one untouched.
    scratch: Vec<JointVec>,
    next: usize,
    /// Tool distance between waypoints, m.
    step: f64,
    active: bool,
}

/// The simulated arm: a chain's joints, its gripper, the limb state and an optional
/// object. Actuator `i < dof` is chain joint `i`; actuator `dof` is the gripper
/// opening (linear, 0 = closed to the stroke = open, m).
#[derive(Debug)]
pub struct ArmModel {
    chain: Chain,
    n: usize,
    joints: [Motion; MAX_JOINTS],
    /// Configured speed per joint (the chain's max speed unless changed), rad/s or m/s.
    config_speed: [f64; MAX_JOINTS],
    gripper: Motion,
    gripper_stroke: f64,
    gripper_max_speed: f64,
    gripper_config_speed: f64,
    gripper_cmd: GripperCmd,
    /// End-effector speed set by the limb's SPEED request, m/s (`None`: joints at their
    /// configured speeds).
    limb_speed: Option<f64>,
    limb_oor: bool,
    powered: bool,
    vecmove: VecMovePlan,
    object: Option<SimObject>,
    held: bool,
    options: SimArmOptions,
    /// Simulated time, s.
    time: f64,
}

fn finite3(v: &[f64; 3]) -> bool {
    v.iter().all(|x| x.is_finite())
}

impl ArmModel {
    /// The arm at its home configuration, gripper open, powered.
    pub fn new(chain: Chain, options: SimArmOptions) -> Result<Self, OptionsError> {
        if options.tick.is_zero() || options.tick > core::time::Duration::from_secs(1) {
            return Err(OptionsError::Tick);
        }
        if !(options.time_scale.is_finite() && options.time_scale > 0.0) {
            return Err(OptionsError::TimeScale);
        }
        if !(options.vecmove_step.is_finite() && options.vecmove_step > 0.0) {
            return Err(OptionsError::VecMoveStep);
        }
        if let Some(o) = &options.object {
            let pos = |v: f64| v.is_finite() && v > 0.0;
            if !(finite3(&o.position) && pos(o.width) && pos(o.capture_radius)) {
                return Err(OptionsError::Object);
            }
        }
        let n = chain.dof();
        if n > MAX_JOINTS || n + 1 > MAX_ACTUATORS {
            return Err(OptionsError::TooManyJoints);
        }
        let mut joints = [Motion::at(0.0); MAX_JOINTS];
        let mut config_speed = [0.0; MAX_JOINTS];
        for (i, j) in chain.joints().iter().enumerate() {
            joints[i] = Motion::at(j.home);
            config_speed[i] = j.max_speed;
        }
        let (stroke, gspeed) = chain
            .gripper()
            .map(|g| (g.stroke, g.max_speed))
            .unwrap_or((DEFAULT_GRIPPER_STROKE, DEFAULT_GRIPPER_SPEED));
        let object = options.object;
        Ok(ArmModel {
            n,
            joints,
            config_speed,
            gripper: Motion::at(stroke),
            gripper_stroke: stroke,
            gripper_max_speed: gspeed,
            gripper_config_speed: gspeed,
            gripper_cmd: GripperCmd::Open,
            limb_speed: None,
            limb_oor: false,
            powered: true,
            vecmove: VecMovePlan {
                waypoints: Vec::with_capacity(MAX_WAYPOINTS),
                scratch: Vec::with_capacity(MAX_WAYPOINTS),
                next: 0,
                step: options.vecmove_step,
                active: false,
            },
            object,
            held: false,
            options,
            time: 0.0,
            chain,
        })
    }

    /// The chain.
    pub fn chain(&self) -> &Chain {
        &self.chain
    }

    /// The options.
    pub fn options(&self) -> &SimArmOptions {
        &self.options
    }

    /// Number of actuators of the actuator array (joints + the gripper).
    pub fn actuators(&self) -> usize {
        self.n + 1
    }

    /// Index of the gripper actuator in the actuator array (= the chain's joint count).
    pub fn gripper_actuator(&self) -> usize {
        self.n
    }

    /// The current joint values.
    pub fn q(&self) -> JointVec {
        let mut q = JointVec::zeros(self.n).unwrap_or_else(|| self.chain.home());
        for (v, m) in q.iter_mut().zip(&self.joints) {
            *v = m.pos;
        }
        q
    }

    /// The gripper opening, m.
    pub fn gripper_opening(&self) -> f64 {
        self.gripper.pos
    }

    /// The object, where it is now (it follows the tool while held).
    pub fn object(&self) -> Option<SimObject> {
        self.object
    }

    /// True while the gripper holds the object.
    pub fn holding(&self) -> bool {
        self.held
    }

    /// Simulated seconds since the start.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// The tool pose now.
    pub fn tool_pose(&self) -> Pose {
        let q = self.q();
        self.chain.fk(&q).unwrap_or_else(|_| *self.chain.base())
    }

    /// True when any chain joint moves or a VECMOVE is being streamed.
    pub fn limb_moving(&self) -> bool {
        self.vecmove.active || self.joints[..self.n].iter().any(|m| m.moving)
    }

    // ----- time ------------------------------------------------------------------------

    /// Advances the simulation by `real_dt` real seconds (scaled by the time scale):
    /// joints and fingers move, the object is gripped or carried, the next VECMOVE
    /// waypoint is started when the previous one is reached.
    pub fn advance(&mut self, real_dt: f64) {
        if !(real_dt.is_finite() && real_dt > 0.0) {
            return;
        }
        let dt = real_dt * self.options.time_scale;
        self.time += dt;
        // Sub-steps so each VECMOVE waypoint starts the moment the previous one is
        // reached (a tick may span many short segments at a large time scale).
        let mut left = dt;
        for _ in 0..MAX_WAYPOINTS + 2 {
            if left <= 0.0 {
                break;
            }
            let step = self.step_until_waypoint(left);
            left -= step;
        }
        self.step_gripper(dt);
        if self.held {
            let p = self.tool_pose().position;
            if let Some(o) = self.object.as_mut() {
                o.position = [p.x, p.y, p.z];
            }
        }
    }

    /// Moves the joints by at most `dt` s, stopping early when a VECMOVE waypoint is
    /// reached (and starting the next one). Returns the time used.
    fn step_until_waypoint(&mut self, dt: f64) -> f64 {
        let mut used = dt;
        if self.vecmove.active {
            // Time until the current segment ends: the slowest joint decides.
            let t = self.joints[..self.n]
                .iter()
                .filter(|m| m.moving)
                .map(|m| (m.target - m.pos).abs() / m.speed)
                .fold(0.0, f64::max);
            if t < dt {
                used = t.max(1e-9).min(dt);
            }
        }
        for m in &mut self.joints[..self.n] {
            m.step(used);
        }
        if self.vecmove.active && !self.joints[..self.n].iter().any(|m| m.moving) {
            self.next_waypoint();
        }
        used
    }

    fn step_gripper(&mut self, dt: f64) {
        let before = self.gripper.pos;
        self.gripper.step(dt);
        let between = self.object_between_fingers();
        if let (Some(o), true) = (self.object, between) {
            // Closing onto the object: the fingers stop at its width.
            if before >= o.width && self.gripper.pos < o.width {
                self.gripper.pos = o.width;
                self.gripper.moving = false;
                self.gripper.stalled = true;
                self.gripper.velocity = 0.0;
                self.held = true;
            }
        }
        if self.held {
            let w = self.object.map(|o| o.width).unwrap_or(0.0);
            if self.gripper.pos > w + 1e-6 {
                self.held = false;
                self.gripper.stalled = false;
            }
        }
    }

    /// True when the object is between the fingers (the tool point within its capture
    /// radius, or held).
    pub fn object_between_fingers(&self) -> bool {
        match &self.object {
            None => false,
            Some(_) if self.held => true,
            Some(o) => {
                let p = self.tool_pose().position;
                let d = p - Vector3::from(o.position);
                d.norm() <= o.capture_radius
            }
        }
    }

    // ----- helpers ---------------------------------------------------------------------

    fn joint_limits(&self, j: usize) -> Option<(f64, f64)> {
        if j < self.n {
            let s = &self.chain.joints()[j];
            Some((s.min, s.max))
        } else if j == self.n {
            Some((0.0, self.gripper_stroke))
        } else {
            None
        }
    }

    fn check(&self, j: usize, v: f64) -> Result<(), Status> {
        let (lo, hi) = self.joint_limits(j).ok_or(Status::UnknownJoint)?;
        if !v.is_finite() {
            return Err(Status::NotFinite);
        }
        if v < lo || v > hi {
            return Err(Status::BeyondLimits);
        }
        Ok(())
    }

    /// Motion needs power: refused as POWERED_OFF otherwise (it would not move).
    fn powered(&self) -> Result<(), Status> {
        if self.powered {
            Ok(())
        } else {
            Err(Status::PoweredOff)
        }
    }

    /// Starts actuator `j` toward `v` at its configured speed (validated already).
    fn move_actuator(&mut self, j: usize, v: f64, speed: Option<f64>) {
        if j < self.n {
            let s = speed.unwrap_or(self.config_speed[j]);
            self.joints[j].go(v, s);
        } else {
            let s = speed.unwrap_or(self.gripper_config_speed);
            self.gripper_cmd = GripperCmd::None;
            self.gripper.go(v, s);
        }
    }

    /// Joint speed limit for limb moves: the configured speed, scaled down when the
    /// limb SPEED request asked for a slower end effector.
    fn limb_joint_speed(&self, j: usize) -> f64 {
        let s = self.config_speed[j];
        match self.limb_speed {
            None => s,
            Some(v) => {
                let spec = &self.chain.joints()[j];
                let cap = match spec.kind {
                    JointKind::Rotary => v / self.chain.reach_bound().max(1e-3),
                    JointKind::Linear => v,
                };
                s.min(cap)
            }
        }
    }

    /// Starts a coordinated move of the chain joints to `q`: every joint arrives at the
    /// same time, `min_time` s at least.
    fn move_joints_together(&mut self, q: &[f64], min_time: f64) {
        let mut t = min_time.max(0.0);
        for (j, (m, v)) in self.joints.iter().zip(q).enumerate().take(self.n) {
            let s = self.limb_joint_speed(j);
            if s > 0.0 {
                t = t.max((v - m.pos).abs() / s);
            }
        }
        for (m, v) in self.joints.iter_mut().zip(q).take(self.n) {
            let d = (v - m.pos).abs();
            let speed = if t > 0.0 { d / t } else { 0.0 };
            m.go(*v, speed);
        }
    }

    fn stop_all_joints(&mut self) {
        self.vecmove.active = false;
        for m in &mut self.joints[..self.n] {
            m.stop();
        }
    }

    // ----- actarray --------------------------------------------------------------------

    /// Carries out or refuses an actuator-array command. A SPEED above the actuator's
    /// maximum speed runs at the maximum and is answered CLAMPED.
    pub fn arm_command(&mut self, cmd: &ActArrayCommand) -> Status {
        self.arm_command_inner(cmd).unwrap_or_else(|e| e)
    }

    fn arm_command_inner(&mut self, cmd: &ActArrayCommand) -> Result<Status, Status> {
        match *cmd {
            ActArrayCommand::Position { joint, position } => {
                let j = joint as usize;
                self.check(j, position)?;
                self.powered()?;
                if j < self.n {
                    self.vecmove.active = false;
                }
                self.move_actuator(j, position, None);
                Ok(Status::Ok)
            }
            ActArrayCommand::MultiPosition(v) => {
                let v = v.as_slice();
                if v.len() > self.actuators() {
                    return Err(Status::UnknownJoint);
                }
                for (j, p) in v.iter().enumerate() {
                    self.check(j, *p)?;
                }
                self.powered()?;
                self.vecmove.active = false;
                for (j, p) in v.iter().enumerate() {
                    self.move_actuator(j, *p, None);
                }
                Ok(Status::Ok)
            }
            ActArrayCommand::Speed { joint, speed } => {
                let j = joint as usize;
                self.check_speed_target(j, speed)?;
                if speed != 0.0 {
                    self.powered()?;
                }
                if j < self.n {
                    self.vecmove.active = false;
                }
                Ok(self.move_at_speed(j, speed))
            }
            ActArrayCommand::MultiSpeed(v) => {
                let v = v.as_slice();
                if v.len() > self.actuators() {
                    return Err(Status::UnknownJoint);
                }
                for (j, s) in v.iter().enumerate() {
                    self.check_speed_target(j, *s)?;
                }
                if v.iter().any(|s| *s != 0.0) {
                    self.powered()?;
                }
                self.vecmove.active = false;
                let mut status = Status::Ok;
                for (j, s) in v.iter().enumerate() {
                    if self.move_at_speed(j, *s) == Status::Clamped {
                        status = Status::Clamped;
                    }
                }
                Ok(status)
            }
            ActArrayCommand::Home(JointSel::All) => {
                self.powered()?;
                self.vecmove.active = false;
                for j in 0..self.n {
                    let h = self.chain.joints()[j].home;
                    self.move_actuator(j, h, None);
                }
                let open = self.gripper_stroke;
                self.move_actuator(self.n, open, None);
                self.gripper_cmd = GripperCmd::Open;
                Ok(Status::Ok)
            }
            ActArrayCommand::Home(JointSel::One(j)) => {
                let j = j as usize;
                if j > self.n {
                    return Err(Status::UnknownJoint);
                }
                self.powered()?;
                if j < self.n {
                    self.vecmove.active = false;
                    let h = self.chain.joints()[j].home;
                    self.move_actuator(j, h, None);
                } else {
                    let open = self.gripper_stroke;
                    self.move_actuator(j, open, None);
                    self.gripper_cmd = GripperCmd::Open;
                }
                Ok(Status::Ok)
            }
            ActArrayCommand::Current { .. } | ActArrayCommand::MultiCurrent(_) => {
                Err(Status::Unsupported)
            }
        }
    }

    fn check_speed_target(&self, j: usize, speed: f64) -> Result<(), Status> {
        self.joint_limits(j).ok_or(Status::UnknownJoint)?;
        if !speed.is_finite() {
            return Err(Status::NotFinite);
        }
        Ok(())
    }

    /// Moves actuator `j` toward its limit in the direction of `speed`'s sign at
    /// |speed|, capped at the actuator's maximum speed (then `Status::Clamped`); 0 stops
    /// it.
    fn move_at_speed(&mut self, j: usize, speed: f64) -> Status {
        if speed == 0.0 {
            if j < self.n {
                self.joints[j].stop();
            } else {
                self.gripper.stop();
            }
            return Status::Ok;
        }
        let Some((lo, hi)) = self.joint_limits(j) else {
            return Status::UnknownJoint;
        };
        let end = if speed > 0.0 { hi } else { lo };
        let max = if j < self.n {
            self.chain.joints()[j].max_speed
        } else {
            self.gripper_max_speed
        };
        self.move_actuator(j, end, Some(speed.abs().min(max)));
        if speed.abs() > max {
            tracing::debug!(joint = j, speed, max, "speed clamped");
            Status::Clamped
        } else {
            Status::Ok
        }
    }

    /// Answers an actuator-array request.
    pub fn arm_request(&mut self, req: &ActArrayRequest) -> Result<ActArrayReply, Status> {
        match *req {
            ActArrayRequest::Power(on) => {
                self.set_power(on);
                Ok(ActArrayReply::Done)
            }
            ActArrayRequest::GetGeom => Ok(ActArrayReply::Geom(self.arm_geometry())),
            ActArrayRequest::Speed { joint, speed } => {
                let j = joint as usize;
                if j > self.n {
                    return Err(Status::UnknownJoint);
                }
                if !speed.is_finite() {
                    return Err(Status::NotFinite);
                }
                if speed <= 0.0 {
                    return Err(Status::InvalidArgument);
                }
                if j < self.n {
                    self.config_speed[j] = speed.min(self.chain.joints()[j].max_speed);
                } else {
                    self.gripper_config_speed = speed.min(self.gripper_max_speed);
                }
                Ok(ActArrayReply::Done)
            }
            ActArrayRequest::Brakes(_) | ActArrayRequest::Accel { .. } => Err(Status::Unsupported),
        }
    }

    fn set_power(&mut self, on: bool) {
        self.powered = on;
        if !on {
            self.stop_all_joints();
            self.gripper.stop();
        }
    }

    /// The actuator-array geometry: per joint its kind, axis, rest orientation (roll,
    /// pitch, yaw), link length (the joint's origin offset), limits, centre, home and
    /// configured speed; the gripper last (linear, 0 to the stroke, home open); the
    /// chain base.
    pub fn arm_geometry(&self) -> ActArrayGeom {
        let mut g = ActArrayGeom {
            actuators_count: self.actuators() as u32,
            ..Default::default()
        };
        for (i, j) in self.chain.joints().iter().enumerate() {
            let (roll, pitch, yaw) = j.rest.euler_angles();
            let axis = j.axis.into_inner();
            g.actuators[i] = ActuatorGeom {
                kind: match j.kind {
                    JointKind::Rotary => ActuatorKind::Rotary,
                    JointKind::Linear => ActuatorKind::Linear,
                } as u32,
                has_brakes: 0,
                length: j.origin.norm(),
                orientation: Orientation3 { roll, pitch, yaw },
                axis: Vec3::new(axis.x, axis.y, axis.z),
                min: j.min,
                centre: 0.5 * (j.min + j.max),
                max: j.max,
                home: j.home,
                config_speed: self.config_speed[i],
            };
        }
        g.actuators[self.n] = ActuatorGeom {
            kind: ActuatorKind::Linear as u32,
            has_brakes: 0,
            length: 0.0,
            orientation: Orientation3::default(),
            axis: Vec3::new(0.0, 1.0, 0.0),
            min: 0.0,
            centre: 0.5 * self.gripper_stroke,
            max: self.gripper_stroke,
            home: self.gripper_stroke,
            config_speed: self.gripper_config_speed,
        };
        let base = self.chain.base();
        let (roll, pitch, yaw) = base.rotation.euler_angles();
        g.base_pos = Vec3::new(base.position.x, base.position.y, base.position.z);
        g.base_orientation = Orientation3 { roll, pitch, yaw };
        g
    }

    /// Fills the actuator-array state (positions, velocities, IDLE/MOVING/STALLED).
    pub fn arm_state(&self, s: &mut ActArrayData) {
        s.actuators_count = self.actuators() as u32;
        s.motor_state = self.powered as u32;
        let all = self.joints[..self.n].iter().chain(Some(&self.gripper));
        for (a, m) in s.actuators.iter_mut().zip(all) {
            a.position = m.pos;
            a.speed = m.velocity;
            a.acceleration = -1.0;
            a.current = -1.0;
            a.state = if m.stalled {
                ActuatorFlags::STALLED
            } else if m.moving {
                ActuatorFlags::MOVING
            } else {
                ActuatorFlags::IDLE
            }
            .bits();
        }
    }

    // ----- limb ------------------------------------------------------------------------

    /// Carries out or refuses a limb command. OUT_OF_REACH sets the limb state to
    /// out-of-reach until the next valid limb command.
    pub fn limb_command(&mut self, cmd: &LimbCommand) -> Status {
        match self.limb_command_inner(cmd) {
            Ok(()) => {
                self.limb_oor = false;
                Status::Ok
            }
            Err(e) => {
                // The limb cannot get there: beyond its reach, an orientation its joints
                // cannot hold, or a joint limit in the way.
                if matches!(
                    e,
                    Status::OutOfReach | Status::UnreachableOrientation | Status::BeyondLimits
                ) {
                    self.limb_oor = true;
                }
                e
            }
        }
    }

    fn ik_to(&self, target: &IkTarget, seed: &[f64]) -> Result<JointVec, Status> {
        let sol = self
            .chain
            .ik(target, seed, &self.options.ik)
            .map_err(|e| self.ik_status(&e))?;
        let mut q = sol.q;
        // Take the turn of each revolute joint nearest to the seed (less travel).
        for ((v, j), s) in q.iter_mut().zip(self.chain.joints()).zip(seed) {
            if j.kind == JointKind::Rotary
                && let Some(w) = fit_angle_to_limits(*v, j.min, j.max, *s, 0.0)
            {
                *v = w;
            }
        }
        if !self.chain.within_limits(&q) {
            return Err(Status::BeyondLimits);
        }
        Ok(q)
    }

    /// The cause of an IK failure: beyond the reach; a position reached but not the
    /// orientation (the joints cannot hold it); or neither within the joint limits.
    fn ik_status(&self, e: &ChainIkError) -> Status {
        let ik = &self.options.ik;
        match *e {
            ChainIkError::NonFinite => Status::NotFinite,
            ChainIkError::WrongJointCount { .. } | ChainIkError::InvalidOptions => {
                Status::InvalidArgument
            }
            ChainIkError::OutOfReach { .. } => Status::OutOfReach,
            ChainIkError::NotConverged {
                position_error,
                orientation_error,
                ..
            } => {
                if position_error <= ik.position_tolerance
                    && orientation_error > ik.orientation_tolerance
                {
                    Status::UnreachableOrientation
                } else {
                    Status::OutOfReach
                }
            }
        }
    }

    fn limb_command_inner(&mut self, cmd: &LimbCommand) -> Result<(), Status> {
        let current = self.q();
        match *cmd {
            LimbCommand::Home => {
                self.powered()?;
                self.vecmove.active = false;
                let home = self.chain.home();
                self.move_joints_together(&home, 0.0);
                Ok(())
            }
            LimbCommand::Stop => {
                self.stop_all_joints();
                Ok(())
            }
            LimbCommand::SetPose {
                position,
                approach,
                orientation,
            } => {
                let pose = Pose::from_approach_orientation(
                    Vector3::from(position.to_array()),
                    Vector3::from(approach.to_array()),
                    Vector3::from(orientation.to_array()),
                    PERPENDICULAR_TOLERANCE,
                )
                .map_err(|e| match e {
                    limber_kinematics::FrameError::NonFinite => Status::NotFinite,
                    _ => Status::InvalidArgument,
                })?;
                self.powered()?;
                let q = self.ik_to(&IkTarget::Pose(pose), &current)?;
                self.vecmove.active = false;
                self.move_joints_together(&q, 0.0);
                Ok(())
            }
            LimbCommand::SetPosition { position } => {
                if !position.is_finite() {
                    return Err(Status::NotFinite);
                }
                self.powered()?;
                let p = Vector3::from(position.to_array());
                let q = self.ik_to(&IkTarget::Position(p), &current)?;
                self.vecmove.active = false;
                self.move_joints_together(&q, 0.0);
                Ok(())
            }
            LimbCommand::VecMove { direction, length } => {
                if !(direction.is_finite() && length.is_finite()) {
                    return Err(Status::NotFinite);
                }
                // Normalised without overflow: (1e308, 1e308, 0) is a direction too.
                let dir = unit_direction(&Vector3::from(direction.to_array()));
                let Some(dir) = dir.filter(|_| length >= 0.0) else {
                    return Err(Status::InvalidArgument);
                };
                self.powered()?;
                self.plan_vecmove(&dir, length)
            }
        }
    }

    /// Plans the straight line from the current tool pose (orientation kept) and starts
    /// streaming it; every waypoint is solved before anything moves.
    fn plan_vecmove(&mut self, dir: &Vector3<f64>, length: f64) -> Result<(), Status> {
        let start = self.tool_pose();
        let step = self.options.vecmove_step;
        let count = (length / step).ceil() as usize;
        if count > MAX_WAYPOINTS {
            return Err(Status::InvalidArgument);
        }
        // Solve into the scratch buffer so a refusal leaves the running line intact.
        let mut seed = self.q();
        let mut plan = core::mem::take(&mut self.vecmove.scratch);
        plan.clear();
        let mut result = Ok(());
        for k in 1..=count {
            let d = (k as f64 * step).min(length);
            let target = start.translated(&(dir * d));
            match self.ik_to(&IkTarget::Pose(target), &seed) {
                Ok(q) => {
                    let jump = q
                        .iter()
                        .zip(seed.iter())
                        .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
                    if jump > MAX_WAYPOINT_JUMP {
                        result = Err(Status::OutOfReach);
                        break;
                    }
                    plan.push(q);
                    seed = q;
                }
                Err(e) => {
                    result = Err(e);
                    break;
                }
            }
        }
        if let Err(e) = result {
            self.vecmove.scratch = plan;
            return Err(e);
        }
        self.vecmove.scratch = core::mem::replace(&mut self.vecmove.waypoints, plan);
        self.vecmove.step = if count > 0 {
            length / count as f64
        } else {
            0.0
        };
        self.vecmove.next = 0;
        self.vecmove.active = true;
        for m in &mut self.joints[..self.n] {
            m.stop();
        }
        self.next_waypoint();
        Ok(())
    }

    fn next_waypoint(&mut self) {
        let i = self.vecmove.next;
        let Some(q) = self.vecmove.waypoints.get(i).copied() else {
            self.vecmove.active = false;
            return;
        };
        self.vecmove.next += 1;
        let min_time = match self.limb_speed {
            Some(v) if v > 0.0 => self.vecmove.step / v,
            _ => 0.0,
        };
        self.move_joints_together(&q, min_time);
    }

    /// Answers a limb request.
    pub fn limb_request(&mut self, req: &LimbRequest) -> Result<LimbReply, Status> {
        match *req {
            LimbRequest::Power(on) => {
                self.set_power(on);
                Ok(LimbReply::Done)
            }
            LimbRequest::Geom => {
                let b = self.chain.base().position;
                Ok(LimbReply::Geom(LimbGeom {
                    base_pos: Vec3::new(b.x, b.y, b.z),
                }))
            }
            LimbRequest::Speed(v) => {
                if !v.is_finite() {
                    return Err(Status::NotFinite);
                }
                if v <= 0.0 {
                    return Err(Status::InvalidArgument);
                }
                self.limb_speed = Some(v);
                Ok(LimbReply::Done)
            }
            LimbRequest::Brakes(_) => Err(Status::Unsupported),
        }
    }

    /// Fills the limb state: the tool pose (FK of the current joints) and
    /// OUT_OF_REACH / MOVING / IDLE.
    pub fn limb_state(&self, s: &mut LimbData) {
        let pose = self.tool_pose();
        let (p, a, o) = (pose.position, pose.approach(), pose.orientation());
        s.position = Vec3::new(p.x, p.y, p.z);
        s.approach = Vec3::new(a.x, a.y, a.z);
        s.orientation = Vec3::new(o.x, o.y, o.z);
        s.state = if self.limb_oor {
            LimbState::OutOfReach
        } else if self.limb_moving() {
            LimbState::Moving
        } else {
            LimbState::Idle
        } as u32;
    }

    // ----- gripper ---------------------------------------------------------------------

    /// Carries out or refuses a gripper command: OPEN and CLOSE move the fingers at the
    /// gripper speed, STOP stops them, STORE and RETRIEVE are unsupported.
    pub fn gripper_command(&mut self, cmd: &GripperCommand) -> Status {
        match cmd {
            GripperCommand::Open | GripperCommand::Close => {
                if let Err(e) = self.powered() {
                    return e;
                }
                let open = *cmd == GripperCommand::Open;
                let target = if open { self.gripper_stroke } else { 0.0 };
                let speed = self.gripper_config_speed;
                self.gripper.go(target, speed);
                self.gripper_cmd = if open {
                    GripperCmd::Open
                } else {
                    GripperCmd::Close
                };
                // Already closed on the object: stays stalled on it.
                if !open && self.held {
                    let w = self.object.map(|o| o.width).unwrap_or(0.0);
                    if self.gripper.pos <= w + 1e-6 {
                        self.gripper.stop();
                        self.gripper.stalled = true;
                    }
                }
                Status::Ok
            }
            GripperCommand::Stop => {
                self.gripper.stop();
                Status::Ok
            }
            GripperCommand::Store | GripperCommand::Retrieve => Status::Unsupported,
        }
    }

    /// Answers a gripper request: the geometry (the inner width is the stroke).
    pub fn gripper_request(&mut self, req: &GripperRequest) -> Result<GripperReply, Status> {
        match req {
            GripperRequest::GetGeom => Ok(GripperReply::Geom(GripperGeom {
                inner_size: Bbox3 {
                    width: self.gripper_stroke,
                    length: 0.0,
                    height: 0.0,
                },
                num_beams: 1,
                capacity: 0,
                ..Default::default()
            })),
        }
    }

    /// Fills the gripper state: MOVING while the fingers move; then CLOSED after CLOSE
    /// (at the end of the stroke or on the object), OPEN after OPEN, and by the opening
    /// otherwise. Beam bit 0: the object is between the fingers.
    pub fn gripper_state(&self, s: &mut GripperData) {
        s.state = if self.gripper.moving {
            GripperState::Moving
        } else {
            match self.gripper_cmd {
                GripperCmd::Close => GripperState::Closed,
                GripperCmd::Open => GripperState::Open,
                GripperCmd::None if self.gripper.pos > 0.5 * self.gripper_stroke => {
                    GripperState::Open
                }
                GripperCmd::None => GripperState::Closed,
            }
        } as u32;
        s.beams = self.object_between_fingers() as u32;
        s.stored = 0;
    }
}
