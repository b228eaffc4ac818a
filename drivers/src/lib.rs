//! limber-drivers: the P2OS protocol, the Pioneer controller emulator, kinematics,
//! the Pioneer driver and the simulated arm.

pub mod emulator;
pub mod kinematics;
pub mod p2os;
pub mod pioneer;
pub mod simarm;
