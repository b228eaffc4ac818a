//! Tick ↔ radian and speed conversions with the ARMINFOpac calibration
//! (reference 3.9, ARIA's convention).

use super::command::ArmJoint;
use super::packet::{ArmInfo, JointCalibration};
use super::vendor_conventions as vc;
use std::f64::consts::FRAC_PI_2;
use thiserror::Error;

/// Why a conversion was refused. Unlike Player, limber never returns 0 for
/// an uncalibrated joint (which would drive a servo to tick 0).
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum ConversionError {
    /// The joint is not in the ARMINFOpac (no calibration yet, or the arm has
    /// fewer joints).
    #[error("joint {0} has no calibration (ARMINFO not received or too few joints)")]
    NotCalibrated(u8),
    /// The calibration says 0 ticks per 90 degrees.
    #[error("joint {0} has zero ticks per 90 degrees")]
    ZeroTicksPer90(u8),
    /// The input is NaN or infinite.
    #[error("value {0} is not finite")]
    NotFinite(f64),
    /// A negative speed.
    #[error("speed {0} rad/s is negative")]
    NegativeSpeed(f64),
    /// A speed of 0 ms per step has no finite angular speed.
    #[error("0 ms per step has no finite speed")]
    ZeroMsPerStep,
}

/// The arm's calibration, from an ARMINFOpac.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ArmCalibration {
    info: ArmInfo,
}

impl From<ArmInfo> for ArmCalibration {
    fn from(info: ArmInfo) -> Self {
        ArmCalibration { info }
    }
}

/// A radians → ticks result.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TickTarget {
    /// The tick to send (clamped to the joint's range).
    pub tick: u8,
    /// The angle was outside the joint's range and was clamped.
    pub clamped: bool,
}

impl ArmCalibration {
    /// The ARMINFOpac this calibration came from.
    pub fn info(&self) -> &ArmInfo {
        &self.info
    }

    /// Number of calibrated joints.
    pub fn num_joints(&self) -> usize {
        usize::from(self.info.num_joints).min(6)
    }

    /// The raw calibration of a joint.
    pub fn joint(&self, joint: ArmJoint) -> Result<&JointCalibration, ConversionError> {
        self.info
            .calibrations()
            .get(joint.index())
            .ok_or(ConversionError::NotCalibrated(joint.number()))
    }

    fn tp90(&self, joint: ArmJoint) -> Result<(&JointCalibration, f64), ConversionError> {
        let c = self.joint(joint)?;
        if c.ticks_per_90 == 0 {
            return Err(ConversionError::ZeroTicksPer90(joint.number()));
        }
        Ok((c, f64::from(c.ticks_per_90)))
    }

    /// Tick → radians: θ = s·(t − centre)·(π/2)/T, keeping the fraction.
    pub fn ticks_to_radians(&self, joint: ArmJoint, tick: u8) -> Result<f64, ConversionError> {
        let (c, t) = self.tp90(joint)?;
        let s = vc::JOINT_SIGN[joint.index()];
        Ok(s * (f64::from(tick) - f64::from(c.centre)) * FRAC_PI_2 / t)
    }

    /// Radians → tick: round(T·deg/90), signed, plus centre, clamped to
    /// [min, max].
    pub fn radians_to_ticks(
        &self,
        joint: ArmJoint,
        rad: f64,
    ) -> Result<TickTarget, ConversionError> {
        if !rad.is_finite() {
            return Err(ConversionError::NotFinite(rad));
        }
        let (c, t) = self.tp90(joint)?;
        let s = vc::JOINT_SIGN[joint.index()];
        let v = (t * rad.to_degrees() / 90.0).round();
        let v = s * v + f64::from(c.centre);
        let (lo, hi) = (f64::from(c.min.min(c.max)), f64::from(c.min.max(c.max)));
        let clamped = v < lo || v > hi;
        Ok(TickTarget {
            tick: v.clamp(lo, hi) as u8,
            clamped,
        })
    }

    /// rad/s → ms per step: 1000 / (deg/s · T/90), clamped to the vendor
    /// range [`vc::ARM_SPEED_MS_MIN`]..=[`vc::ARM_SPEED_MS_MAX`]. A speed of
    /// 0 gives the slowest setting.
    pub fn speed_to_ms_per_step(
        &self,
        joint: ArmJoint,
        rad_per_s: f64,
    ) -> Result<u8, ConversionError> {
        if !rad_per_s.is_finite() {
            return Err(ConversionError::NotFinite(rad_per_s));
        }
        if rad_per_s < 0.0 {
            return Err(ConversionError::NegativeSpeed(rad_per_s));
        }
        let (_, t) = self.tp90(joint)?;
        let ticks_per_s = rad_per_s.to_degrees() * t / 90.0;
        let ms = if ticks_per_s > 0.0 {
            (1000.0 / ticks_per_s).round()
        } else {
            f64::INFINITY
        };
        Ok(ms.clamp(
            f64::from(vc::ARM_SPEED_MS_MIN),
            f64::from(vc::ARM_SPEED_MS_MAX),
        ) as u8)
    }

    /// ms per step → rad/s: (1000/ms)/(T/90) deg/s.
    pub fn ms_per_step_to_speed(&self, joint: ArmJoint, ms: u8) -> Result<f64, ConversionError> {
        if ms == 0 {
            return Err(ConversionError::ZeroMsPerStep);
        }
        let (_, t) = self.tp90(joint)?;
        Ok(((1000.0 / f64::from(ms)) / (t / 90.0)).to_radians())
    }

    /// Limits of a joint in radians: (angle at min tick, angle at centre,
    /// angle at max tick, angle at home). For joints 1..3 the angle at the
    /// min tick is the larger one (the sign is negated).
    pub fn limits_radians(&self, joint: ArmJoint) -> Result<[f64; 4], ConversionError> {
        let c = *self.joint(joint)?;
        Ok([
            self.ticks_to_radians(joint, c.min)?,
            self.ticks_to_radians(joint, c.centre)?,
            self.ticks_to_radians(joint, c.max)?,
            self.ticks_to_radians(joint, c.home)?,
        ])
    }
}
