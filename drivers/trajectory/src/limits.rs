//! What the executor knows of a device ([`Config`], [`JointLimit`]) and why it refuses a
//! trajectory ([`Refusal`]).

use limber_interfaces::prelude::*;

/// One joint's limits as the executor checks them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointLimit {
    /// Lowest position, rad or m.
    pub min: f64,
    /// Highest position.
    pub max: f64,
    /// Highest speed the joint can follow (0: no limit).
    pub max_velocity: f64,
    /// Deceleration on a STOP (0: hold at once).
    pub max_deceleration: f64,
}

impl Default for JointLimit {
    fn default() -> Self {
        JointLimit {
            min: f64::NEG_INFINITY,
            max: f64::INFINITY,
            max_velocity: 0.0,
            max_deceleration: 0.0,
        }
    }
}

/// What the executor knows of the device.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Config {
    /// The device's joints (actarray indices `0..joints`).
    pub joints: usize,
    /// Each joint's limits.
    pub limits: [JointLimit; MAX_ACTUATORS],
    /// The goal time tolerance of a trajectory that gives 0, s.
    pub goal_time: f64,
    /// How far in the past a start time may lie, s.
    pub max_start_age: f64,
}

impl Config {
    /// `joints` joints without limits, a goal time of 1 s, start times up to 1 s old.
    pub fn new(joints: usize) -> Self {
        Config {
            joints: joints.min(MAX_ACTUATORS),
            limits: [JointLimit::default(); MAX_ACTUATORS],
            goal_time: 1.0,
            max_start_age: 1.0,
        }
    }
}

/// Why a trajectory was refused before it ran ([`Executor::accept`](crate::Executor::accept)).
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum Refusal {
    /// The trajectory itself is malformed.
    #[error(transparent)]
    Invalid(#[from] TrajectoryError),
    /// A joint it names is not one of the device's.
    #[error("joint {joint} does not exist: the device has joints 0 to {last}")]
    UnknownJoint {
        /// The joint.
        joint: u8,
        /// The device's last joint.
        last: usize,
    },
    /// A position (at a point or between points) lies beyond a joint's limits.
    #[error(
        "joint {joint} reaches {value:.4} on the way to point {point}: beyond its limits [{min:.4}, {max:.4}]"
    )]
    BeyondLimits {
        /// The joint.
        joint: u8,
        /// The point the segment ends at.
        point: usize,
        /// The position.
        value: f64,
        /// The joint's lower limit.
        min: f64,
        /// Its upper limit.
        max: f64,
    },
    /// A segment needs a joint faster than it moves.
    #[error(
        "joint {joint} needs {needed:.4}/s on the way to point {point}; it moves at most {possible:.4}/s"
    )]
    TooFast {
        /// The joint.
        joint: u8,
        /// The point the segment ends at.
        point: usize,
        /// The speed the segment needs.
        needed: f64,
        /// The joint's highest speed.
        possible: f64,
    },
    /// The start time lies too far in the past, or every point is past.
    #[error(
        "the start time is {age:.3} s in the past (at most {max:.3} s, and a point must be ahead)"
    )]
    OldTimestamp {
        /// How old, s.
        age: f64,
        /// The bound, s.
        max: f64,
    },
}

impl Refusal {
    /// The status a driver answers for it.
    pub const fn status(&self) -> Status {
        match self {
            Refusal::Invalid(e) => e.status(),
            Refusal::UnknownJoint { .. } => Status::UnknownJoint,
            Refusal::BeyondLimits { .. } => Status::BeyondLimits,
            Refusal::TooFast { .. } => Status::TooFast,
            Refusal::OldTimestamp { .. } => Status::OldTimestamp,
        }
    }
}
