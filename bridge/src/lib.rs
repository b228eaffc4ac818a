#![doc = include_str!("../README.md")]
//! ## The library
//!
//! limber is shared memory on one PC. This crate carries devices to other hosts over
//! [Zenoh](https://zenoh.io) (the `zenoh` crate, 1.x, TCP only), in two roles:
//!
//! * [`expose()`]: on the robot's PC, joins domain A as a client of every device there and
//!   publishes each device's state, takes commands and requests from Zenoh and hands them
//!   to the driver, and holds a liveliness token per device.
//! * [`mirror()`]: on another host, hosts every remote device in domain B under the same
//!   name (or with a prefix on the robot name), as a driver would, so that unchanged
//!   clients use it: their commands, requests and outcomes travel to the robot and back.
//!
//! The payloads are the interfaces' fixed layouts as bytes; the key expressions are in
//! [`keys`] and documented in this crate's README.

pub mod access;
pub mod allow;
mod dirwatch;
pub mod expose;
mod inbox;
pub mod keys;
mod malformed;
pub mod mirror;
mod session;
mod waiting;

pub use access::{AccessError, LOCAL_PRINCIPAL};
pub use allow::{Allow, AllowError, CommandKind, DevicePattern, RequestKind};
pub use expose::{ExposeConfig, ExposeError, ExposeEvent, expose};
pub use inbox::InboxError;
pub use mirror::{MirrorConfig, MirrorError, MirrorEvent, mirror};
pub use session::{NetConfig, SessionError};
