//! The Pioneer driver: one real-time process that owns the P2OS link and serves the arm,
//! the limb (inverse kinematics inside), the body gripper, the arm gripper and the lift.
//!
//! Devices (robot name `pioneer` by default):
//!
//! | device | what |
//! |---|---|
//! | `pioneer/actarray/0` | the arm: 6 actuators (5 joints and the gripper joint), rad |
//! | `pioneer/limb/0` | the end effector: HOME, STOP, SETPOSE, SETPOSITION, VECMOVE |
//! | `pioneer/gripper/0` | the body gripper (paddles, two break beams), if fitted |
//! | `pioneer/gripper/1` | the arm gripper (joint 6) |
//! | `pioneer/actarray/1` | the lift (with the body gripper): 0 (down) to 0.07 m (up) |
//! | `pioneer/driver/0` | loop, link and robot statistics ([`limber_interfaces::diagnostics`]) |
//!
//! Every command is validated (finite, known joint, inside the limits, calibration
//! present, link up) before a byte is written; a refused command reaches its sender as the
//! status of the next state sample. Requests are answered as soon as they arrive.
//!
//! What the robot has is asked at connect: the arm's devices need an answer to ARM_INFO,
//! the body gripper's and the lift's a CONFIGpac saying a gripper is fitted (or
//! `body_gripper = true`: [`BodyGripper`], [`gripper_decision`]).

mod config;
mod driver;
mod realtime;
pub mod robot;
mod stats;

pub use config::{BodyGripper, ConfigError, GripperGeometry, PioneerConfig};
pub use driver::{
    ArmAtShutdown, DriverError, Hardware, LinkAtShutdown, LoopMode, PioneerDriver, RunOptions,
    ShutdownReport, StartOptions, gripper_decision,
};
pub use realtime::{CpuError, RealtimeWarning, apply_realtime, check_cpu};
pub use robot::{INTERNAL, Outbox, PacketEffect, Queued, RobotModel};
pub use stats::{LoopStats, Ring};
