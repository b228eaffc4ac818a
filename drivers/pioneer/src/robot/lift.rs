//! The lift (`<robot>/actarray/1`): one linear actuator whose position is estimated from time.

use std::time::{Duration, Instant};

use limber_interfaces::prelude::*;
use limber_services::Origin;

use limber_p2os::{Command, GripperCommand as P2Gripper, LiftState};

use super::*;

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
    pub(super) fn new(stroke: f64) -> Self {
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

impl RobotModel {
    /// A lift command (one linear actuator, metres).
    pub fn lift_command(&mut self, cmd: &ActArrayCommand, from: &Origin) -> Status {
        if !self.body_gripper {
            return Status::Unsupported;
        }
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

    pub(super) fn lift_to(&mut self, target: f64, from: &Origin) -> Result<(), Status> {
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
            let lift = sip.gripper_reading(self.cfg.gripper_byte).lift;
            self.lift.switch_moving = lift == LiftState::Moving;
            self.lift.at_limit =
                matches!(lift, LiftState::Up | LiftState::Down | LiftState::AtLimit);
            if self.lift.at_limit {
                // At a limit: the manual's byte says which; ARIA's one limit bit does
                // not, and it follows from where it was going.
                let top = match lift {
                    LiftState::Up => true,
                    LiftState::Down => false,
                    _ => self.lift.target >= self.cfg.lift_stroke / 2.0,
                };
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
