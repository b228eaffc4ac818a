//! Typed views of the actarray state and geometry, and their validation.

use super::{ActArrayData, ActArrayGeom, ActuatorFlags, ActuatorGeom, ActuatorKind, ActuatorState};
use crate::common::{MAX_ACTUATORS, finite, finite_vec};
use crate::error::{DecodeError, ValueError};

impl ActArrayData {
    /// The valid actuators (empty if `actuators_count` is beyond the capacity; call
    /// [`ActArrayData::validate`] to find out).
    pub fn actuators(&self) -> &[ActuatorState] {
        self.actuators
            .get(..self.actuators_count as usize)
            .unwrap_or(&[])
    }

    /// Checks the count, every state code and that every number is finite.
    pub fn validate(&self) -> Result<(), DecodeError> {
        if self.actuators_count as usize > MAX_ACTUATORS {
            return Err(ValueError::TooMany {
                field: "actuators_count",
                count: self.actuators_count as usize,
                max: MAX_ACTUATORS,
            }
            .into());
        }
        if self.motor_state > 1 {
            return Err(DecodeError::UnknownCode {
                field: "motor_state",
                value: self.motor_state as i64,
            });
        }
        let t = &self.trajectory;
        if t.active > 2 {
            return Err(DecodeError::UnknownCode {
                field: "trajectory.active",
                value: t.active as i64,
            });
        }
        if t.result != 0 {
            crate::control::MotionResult::try_from(t.result)?;
        }
        finite("trajectory.max_error", t.max_error)?;
        finite("trajectory.time", t.time)?;
        finite("trajectory.scale", t.scale)?;
        for a in self.actuators() {
            a.flags()?;
            finite("position", a.position)?;
            finite("speed", a.speed)?;
            finite("acceleration", a.acceleration)?;
            finite("current", a.current)?;
        }
        Ok(())
    }
}

impl ActuatorState {
    /// The state bits, rejecting undefined bits.
    pub fn flags(&self) -> Result<ActuatorFlags, DecodeError> {
        ActuatorFlags::from_bits(self.state).ok_or(DecodeError::UnknownBits {
            field: "actuator state",
            bits: self.state & !ActuatorFlags::all().bits(),
        })
    }
}

impl ActuatorGeom {
    /// The actuator type, rejecting unknown codes.
    pub fn actuator_kind(&self) -> Result<ActuatorKind, DecodeError> {
        ActuatorKind::try_from(self.kind)
    }

    /// True when `v` lies within `[min, max]`.
    pub fn contains(&self, v: f64) -> bool {
        v >= self.min && v <= self.max
    }

    fn validate(&self) -> Result<(), DecodeError> {
        self.actuator_kind()?;
        for (f, v) in [
            ("length", self.length),
            ("min", self.min),
            ("centre", self.centre),
            ("max", self.max),
            ("home", self.home),
            ("config_speed", self.config_speed),
        ] {
            finite(f, v)?;
        }
        finite_vec("axis", self.axis)?;
        if !self.orientation.is_finite() {
            return Err(DecodeError::not_finite("orientation"));
        }
        Ok(())
    }
}

impl ActArrayGeom {
    /// The valid actuator geometries.
    pub fn actuators(&self) -> &[ActuatorGeom] {
        self.actuators
            .get(..self.actuators_count as usize)
            .unwrap_or(&[])
    }

    /// Checks the count, every code and that every number is finite.
    pub fn validate(&self) -> Result<(), DecodeError> {
        if self.actuators_count as usize > MAX_ACTUATORS {
            return Err(ValueError::TooMany {
                field: "actuators_count",
                count: self.actuators_count as usize,
                max: MAX_ACTUATORS,
            }
            .into());
        }
        for a in self.actuators() {
            a.validate()?;
        }
        finite_vec("base_pos", self.base_pos)?;
        if !self.base_orientation.is_finite() {
            return Err(DecodeError::not_finite("base_orientation"));
        }
        Ok(())
    }
}
