//! # limber-gateway: Player's own programs on limber devices
//!
//! A server of Player's TCP protocol (Player 3.x, written from the protocol's facts; no
//! Player code) in front of a limber domain: libplayerc and libplayerc++ programs, their
//! Python bindings, playerv, playerprint and playerjoy connect to it as to a Player
//! server and use every limber device of the domain, through limber's shared memory.
//!
//! * [`xdr`], [`header`]: the wire: XDR words with doubled array counts, the 40-byte
//!   header.
//! * [`player`]: the `player` interface (DEVLIST, DRIVERINFO, DEV, DATA, DATAMODE,
//!   ADD_REPLACE_RULE), the capability query and the banner.
//! * [`translate`]: one module per interface (actarray, limb, gripper; a ranger as Player's
//!   laser), Player's messages to limber's and back.
//! * [`map`]: limber's `robot/interface/index` to Player's `interface:index`.
//! * [`queue`]: PUSH and PULL, replace rules.
//! * [`session`], [`server`]: one limber client per Player client (its own identity and
//!   leases), a thread each.
//!
//! How it differs from Player's own p2os driver (the reference's bugs, section 6) is in
//! the README's "Player's programs" section.

#![warn(missing_docs)]

pub mod header;
pub mod map;
pub mod player;
pub mod queue;
pub mod server;
pub mod session;
pub mod translate;
pub mod xdr;

pub use map::{MapEntry, MapError};
pub use server::{DEFAULT_PORT, GatewayConfig, GatewayError, GatewayEvent, run};
pub use translate::Conventions;
