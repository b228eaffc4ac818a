#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

pub mod chain;
pub mod path;
pub mod pioneer;
mod pose;

pub use pose::{FrameError, Pose, angle_between_rotations, fit_angle_to_limits, unit_direction};
