//! The simulated arm itself, without any transport: joints that move toward their
//! targets at their speeds when [`ArmModel::advance`] is called, the limb's inverse
//! kinematics, VECMOVE streaming, the parallel gripper and an optional object to grasp.
//!
//! Every command is validated completely before anything moves. Nothing here allocates
//! after [`ArmModel::new`] (the VECMOVE plan has a fixed capacity) and nothing panics on
//! bad input.
//!
//! This module holds the model's state, its construction, time and the joint helpers
//! every interface uses; the options and the object are in `options`, one actuator's
//! motion in `motion`, and each interface's commands, requests and state in
//! `actarray`, `limb` (inverse kinematics and VECMOVE) and `gripper` (with the object
//! it grips).

use limber_interfaces::prelude::*;

use limber_kinematics::Pose;
use limber_kinematics::chain::{Chain, JointKind, JointVec, MAX_JOINTS};

mod actarray;
mod brakes;
mod collision;
mod current;
mod fingers;
mod gripper;
mod limb;
mod motion;
mod options;
mod paths;
mod preemption;
mod store;
mod trajectory;

pub use collision::{Contact, Obstacles, SimObstacle};
use gripper::GripperCmd;
use limb::VecMovePlan;
use motion::Motion;
pub use options::{MotorModel, OptionsError, SimArmOptions, SimObject};
pub use preemption::TOLERANCE;
pub use store::MAX_STORE_CAPACITY;
use store::Store;

/// Most waypoints of one VECMOVE (at [`SimArmOptions::vecmove_step`] apart).
pub const MAX_WAYPOINTS: usize = 512;

/// The gripper simulated when the chain file describes none: 8 cm stroke, 0.1 m/s.
pub const DEFAULT_GRIPPER_STROKE: f64 = 0.08;
/// Finger speed of the default gripper, m/s.
pub const DEFAULT_GRIPPER_SPEED: f64 = 0.1;

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
    /// Acceleration limit per actuator set by the ACCEL request (joints, then the
    /// gripper at index `n`), rad/s² or m/s²; infinite until set.
    config_accel: [f64; MAX_JOINTS + 1],
    /// The brakes are on (every chain joint BRAKED, motion refused).
    brakes: bool,
    /// The objects the gripper stored (STORE), given back by RETRIEVE.
    store: Store,
    gripper: Motion,
    gripper_stroke: f64,
    gripper_max_speed: f64,
    gripper_config_speed: f64,
    gripper_cmd: GripperCmd,
    /// End-effector speed set by the limb's SPEED request, m/s (`None`: joints at their
    /// configured speeds).
    limb_speed: Option<f64>,
    /// OUT_OF_REACH and the orientation adjustment of the last limb command (the rules
    /// shared with the Pioneer driver: [`limber_interfaces::limb_outcome`]).
    limb: limber_interfaces::limb_outcome::LimbOutcome,
    powered: bool,
    vecmove: VecMovePlan,
    /// LINE and PTP: their executor and what runs.
    path: paths::PathRun,
    object: Option<SimObject>,
    held: bool,
    /// The contact that stopped the limb (COLLISION until the next limb command).
    collision: Option<Contact>,
    /// The limb was in contact when its command started: it may move until it is clear.
    leaving_contact: bool,
    options: SimArmOptions,
    /// Simulated time, s.
    time: f64,
    /// Joint trajectories: the executor and the upload.
    traj: trajectory::Trajectories,
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
        options.motor.check()?;
        if options.store_capacity > store::MAX_STORE_CAPACITY {
            return Err(OptionsError::StoreCapacity);
        }
        let object = options.object;
        let store = Store::new(options.store_capacity);
        Ok(ArmModel {
            n,
            joints,
            config_speed,
            config_accel: [f64::INFINITY; MAX_JOINTS + 1],
            brakes: false,
            store,
            gripper: Motion::at(stroke),
            gripper_stroke: stroke,
            gripper_max_speed: gspeed,
            gripper_config_speed: gspeed,
            gripper_cmd: GripperCmd::Open,
            limb_speed: None,
            limb: Default::default(),
            powered: true,
            path: paths::PathRun::default(),
            vecmove: VecMovePlan {
                waypoints: Vec::with_capacity(MAX_WAYPOINTS),
                scratch: Vec::with_capacity(MAX_WAYPOINTS),
                next: 0,
                step: options.vecmove_step,
                active: false,
            },
            object,
            held: false,
            collision: None,
            leaving_contact: false,
            options,
            time: 0.0,
            traj: trajectory::Trajectories::new(n + 1),
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
        // Current-driven actuators: aimed by the motor model from where they are now.
        self.drive_currents();
        // Sub-steps so each VECMOVE waypoint starts the moment the previous one is
        // reached (a tick may span many short segments at a large time scale).
        let mut left = dt;
        for _ in 0..MAX_WAYPOINTS + 2 {
            if left <= 0.0 {
                break;
            }
            let step = self.step_until_waypoint(left);
            left -= step;
            self.stop_at_contact();
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

    /// Starts actuator `j` toward `v` at its configured speed and acceleration
    /// (validated already).
    fn move_actuator(&mut self, j: usize, v: f64, speed: Option<f64>) {
        let a = self.config_accel.get(j).copied().unwrap_or(f64::INFINITY);
        if j < self.n {
            let s = speed.unwrap_or(self.config_speed[j]);
            self.joints[j].go_accel(v, s, a);
        } else {
            let s = speed.unwrap_or(self.gripper_config_speed);
            self.gripper_cmd = GripperCmd::None;
            self.gripper.go_accel(v, s, a);
        }
    }

    /// Actuator `j`'s motion (the gripper at `n`).
    fn actuator(&self, j: usize) -> Option<&Motion> {
        if j < self.n {
            self.joints.get(j)
        } else if j == self.n {
            Some(&self.gripper)
        } else {
            None
        }
    }

    /// Actuator `j`'s motion, mutable.
    fn actuator_mut(&mut self, j: usize) -> Option<&mut Motion> {
        if j < self.n {
            self.joints.get_mut(j)
        } else if j == self.n {
            Some(&mut self.gripper)
        } else {
            None
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
}
