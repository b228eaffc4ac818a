//! The client side, in the spirit of Player's proxies: [`Client<I>`] for any interface, with
//! typed conveniences for each ([`ActArrayClient`], [`LimbClient`], [`GripperClient`],
//! [`RangerClient`]).
//!
//! Read in this order: `connection.rs` opens the channels of a device, `waiting.rs` reads states and waits for outcomes, `commands.rs` and
//! `requests.rs` send, and `actarray.rs`, `limb.rs`, `gripper.rs`, `ranger.rs` are the typed proxies.
//! The errors of each operation are in `error.rs`.

use core::time::Duration;

mod actarray;
mod commands;
mod connection;
mod device;
mod done;
mod error;
mod gripper;
mod limb;
mod ownership;
mod ranger;
mod requests;
mod waiting;

pub use commands::Ticket;
use connection::OUTCOME_SLOTS;
pub use connection::{
    ActArrayClient, Client, GripperClient, LaserClient, LimbClient, RangerClient,
};
pub use device::{AnyGeom, DeviceClient, connect_device};
pub use done::{Done, DoneError};
pub use error::{
    CommandError, ConnectError, Incompatibility, LeaseError, RequestError, TrajectorySendError,
    WaitError,
};
pub use ownership::{LeaseHolder, Outcome};
pub use waiting::{DriverStatus, FRESHNESS_CHECK_AGE, Freshness, WaitMode};

/// Default time a request waits for its reply.
pub const DEFAULT_REQUEST_TIMEOUT: Duration = Duration::from_secs(2);
/// How often a waiting client checks that the driver is still alive.
pub const LIVENESS_PERIOD: Duration = Duration::from_millis(20);
