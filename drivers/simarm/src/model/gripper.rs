//! The parallel gripper and the object it grips: the fingers stop on the object's width,
//! the beam sees it between the fingers, and it is held until the fingers open.

use limber_interfaces::prelude::*;
use nalgebra::Vector3;

use super::ArmModel;

/// The largest grip effort of the simulated fingers, N (a GOAL's `effort` above it is
/// clamped to it; 0 asks for it). The fingers are rigid: they hold the object at any
/// effort, and stop on it whatever the effort.
pub const GRIPPER_MAX_EFFORT: f64 = 10.0;

/// What the gripper was last told.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum GripperCmd {
    None,
    Open,
    Close,
}

impl ArmModel {
    /// Moves the fingers by `dt` s: they stop on the object's width when they close on
    /// it, and let go of it when they open past it.
    pub(super) fn step_gripper(&mut self, dt: f64) {
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
    /// Carries out or refuses a gripper command: OPEN and CLOSE move the fingers at the
    /// gripper speed (a GOAL to the whole stroke or to 0), GOAL to its gap, STOP stops them, STORE and RETRIEVE use the gripper's store
    /// (`store`).
    pub fn gripper_command(&mut self, cmd: &GripperCommand) -> Status {
        match cmd {
            GripperCommand::Open | GripperCommand::Close => {
                if let Err(e) = self.powered() {
                    return e;
                }
                let open = *cmd == GripperCommand::Open;
                let target = if open { self.gripper_stroke } else { 0.0 };
                self.gripper_goal(target, 0.0, 0.0)
            }
            GripperCommand::Goal { gap, effort, speed } => {
                if let Err(e) = self.powered() {
                    return e;
                }
                self.gripper_goal(*gap, *effort, *speed)
            }
            GripperCommand::Stop => {
                self.gripper.stop();
                Status::Ok
            }
            GripperCommand::Store => self.store_object().err().unwrap_or(Status::Ok),
            GripperCommand::Retrieve => self.retrieve_object().err().unwrap_or(Status::Ok),
        }
    }

    /// A GOAL: the fingers to `gap` (clamped to the stroke) at `speed` (0: the configured
    /// speed; clamped to the maximum), gripping with at most `effort` (clamped to
    /// [`GRIPPER_MAX_EFFORT`]); [`Status::Clamped`] when any of them was.
    fn gripper_goal(&mut self, gap: f64, effort: f64, speed: f64) -> Status {
        self.preempt_trajectory(1 << self.n);
        let clamped = gap > self.gripper_stroke
            || speed > self.gripper_max_speed
            || effort > GRIPPER_MAX_EFFORT;
        let target = gap.min(self.gripper_stroke);
        let speed = if speed == 0.0 {
            self.gripper_config_speed
        } else {
            speed.min(self.gripper_max_speed)
        };
        self.gripper.go(target, speed);
        self.gripper_cmd = if target >= self.gripper_stroke {
            GripperCmd::Open
        } else if target == 0.0 {
            GripperCmd::Close
        } else {
            GripperCmd::None
        };
        // Already closed on the object, asked to close further: stays stalled on it.
        if self.held {
            let w = self.object.map(|o| o.width).unwrap_or(0.0);
            if target < w && self.gripper.pos <= w + 1e-6 {
                self.gripper.stop();
                self.gripper.stalled = true;
            }
        }
        if clamped {
            tracing::info!(
                gap,
                effort,
                speed,
                stroke = self.gripper_stroke,
                max_speed = self.gripper_max_speed,
                max_effort = GRIPPER_MAX_EFFORT,
                "gripper goal clamped to the gripper's limits"
            );
            Status::Clamped
        } else {
            Status::Ok
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
                capacity: self.store.capacity(),
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
        s.stored = self.store.len();
    }
}
