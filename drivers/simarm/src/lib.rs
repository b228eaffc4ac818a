#![doc = include_str!("../README.md")]

mod driver;
pub mod model;

pub use driver::{DRIVER_NAME, SimArm, SimArmError, SimArmFailures};
pub use model::{
    ArmModel, Contact, MAX_STORE_CAPACITY, MotorModel, Obstacles, OptionsError, SimArmOptions,
    SimObject, SimObstacle,
};
