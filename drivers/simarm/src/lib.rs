#![doc = include_str!("../README.md")]

mod driver;
pub mod model;
mod thread;

pub use driver::{DRIVER_NAME, SimArm, SimArmError, SimArmFailures};
pub use model::{
    ArmModel, Contact, MAX_STORE_CAPACITY, MotorModel, Obstacles, OptionsError, SimArmOptions,
    SimObject, SimObstacle,
};
pub use thread::{SimArmThread, SimArmThreadError};
