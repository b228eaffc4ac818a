#![doc = include_str!("../README.md")]
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
