#![doc = include_str!("../README.md")]
//! ## The library
//!
//! * [`record`]: every state, outcome and driver statistics of a
//!   domain (or of the devices named) into an MCAP file, with its acquisition and receive
//!   times, in a process and thread of its own and in bounded memory.
//! * [`info()`]: what a file holds (channels, counts, time span).
//! * [`replay()`]: a recorded file republished into a domain, its devices
//!   hosted as if their drivers were live.
//! * [`view()`]: the devices live in Foxglove (the `foxglove.websocket.v1`
//!   protocol over [`ws`]), with a URDF of each arm whose chain limber knows ([`urdf`]).
//!
//! The file format is MCAP ([`mcap`]), written and read by this crate from the
//! specification. Each device has the channels `/<device>/state` and `/<device>/outcome`
//! (limber's wire structs, schema from the layout manifest: [`schema::layout_schema`]),
//! `/<device>/geometry` (one message: its reply to the geometry request), an actuator
//! array also `/<device>/joint_states` (Foxglove's `foxglove.JointStates`, JSON); each
//! robot `/<robot>/driver` (its driver's statistics). See README.md.

pub mod files;
pub mod info;
pub mod mcap;
pub mod recorder;
pub mod replay;
pub mod schema;
pub mod urdf;
pub mod urdf_in;
pub mod view;
pub mod ws;

pub use info::{Info, InfoError, info};
pub use recorder::{Progress, RecordConfig, RecordError, RecordEvent, record};
pub use replay::{ReplayConfig, ReplayError, ReplayEvent, replay};
pub use view::{ViewConfig, ViewError, ViewEvent, view};
