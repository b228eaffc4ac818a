#![doc = include_str!("../README.md")]

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
pub use stats::{LoopStats, Ring, TickStats};
