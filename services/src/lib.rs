//! # limber-services: the iceoryx2 layer
//!
//! How a driver offers a device and how any number of client processes on the same PC read
//! its state, command it and ask it things: zero-copy shared memory, no copy of a sample,
//! no broker.
//!
//! * [`naming`]: device names `robot/interface/index`, service names
//!   `limber/<robot>/<interface>/<index>/<channel>`, domain names.
//! * [`domain`]: [`Domain`] (`LIMBER_DOMAIN` → iceoryx2 prefix), its files, who may touch
//!   them (group mode), and their removal (`limber clean`).
//! * [`host`]: [`DeviceHost`] offers a device; a driver implements [`DeviceHandler`] for
//!   each interface it serves.
//! * [`device_set`]: [`DeviceSet`], the hosts of one driver process as one group, served
//!   through one [`DeviceSetHandler`].
//! * [`client`]: [`ActArrayClient`], [`LimbClient`], [`GripperClient`], in the spirit of
//!   Player's proxies, with typed errors and timeouts on every wait.
//! * [`discovery`]: [`list_devices`], with liveness.
//! * [`relay`]: the raw side of a host and a client, for bridges to other domains.
//! * [`error`]: [`Iox2Error`], the iceoryx2 cause kept inside every transport error.
//!
//! Every fallible operation has its own error enum; none is flattened into text, and
//! failures that do not end an operation (a notification that could not be sent, a reply
//! to a client that left) are counted in [`HostStats`] or logged with `tracing`.
//!
//! ## A driver in 20 lines
//!
//! ```
//! use limber_services::prelude::*;
//!
//! /// A gripper that opens and closes at once.
//! struct Instant;
//! impl DeviceHandler<Gripper> for Instant {
//!     fn command(&mut self, cmd: &GripperCommand, _: &Origin, state: &mut GripperData) -> Status {
//!         match cmd {
//!             GripperCommand::Open => { state.state = GripperState::Open as u32; Status::Ok }
//!             GripperCommand::Close => { state.state = GripperState::Closed as u32; Status::Ok }
//!             _ => Status::Unsupported,
//!         }
//!     }
//!     fn request(&mut self, _: &GripperRequest, _: &Origin, _: &mut GripperData) -> Result<GripperReply, Status> {
//!         Ok(GripperReply::Geom(GripperGeom { num_beams: 0, ..Default::default() }))
//!     }
//! }
//!
//! # let domain = Domain::unique_for_test();
//! let ctx = Context::new(&domain, Role::Driver, "instant")?;
//! let mut host = DeviceHost::<Gripper>::new(&ctx, &"demo/gripper/0".parse()?, "instant")?;
//! host.state_mut().state = GripperState::Open as u32;
//! host.publish()?;
//! # for _ in 0..1 {
//! host.process(&mut Instant)?; // in the driver's loop, after each wake-up
//! # }
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! ## A client in 10 lines
//!
//! ```no_run
//! use std::time::Duration;
//! use limber_services::prelude::*;
//!
//! let ctx = Context::client_from_env()?;
//! let mut arm = ActArrayClient::connect(&ctx, "pioneer/actarray/0")?;
//! let geom = arm.geometry()?;                       // a request: typed reply or typed error
//! let ticket = arm.move_to(2, geom.actuators[2].home)?; // a command: no wait
//! let status = arm.wait_outcome(ticket, Duration::from_secs(1))?;
//! println!("{status}; joint 2 at {:.3} rad", arm.state().unwrap().actuators[2].position);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

#![warn(missing_docs)]

pub mod client;
pub mod context;
pub mod device_set;
pub mod diagnostics;
pub mod discovery;
pub mod domain;
pub mod error;
pub mod event_loop;
pub mod host;
pub mod naming;
pub mod qos;
pub mod relay;
pub mod signals;
pub mod testing;

/// The old path of [`domain::cleanup`].
pub use domain::cleanup;
/// The old path of [`domain::dir`] (other crates use it).
pub use domain::dir as domain_dir;

pub use client::{
    ActArrayClient, AnyGeom, Client, CommandError, ConnectError, DeviceClient, Done, DoneError,
    DriverStatus, Freshness, GripperClient, Incompatibility, LaserClient, LeaseError, LeaseHolder,
    LimbClient, Outcome, RangerClient, RequestError, Ticket, TrajectorySendError, WaitError,
    WaitMode, connect_device,
};
pub use context::{Context, ContextError, Role, monotonic_ns};
pub use device_set::{DeviceError, DeviceSet, DeviceSetHandler, Drain, ShareLeaseError};
pub use discovery::{DeviceInfo, ListError, list_devices};
pub use domain::Domain;
pub use domain::DomainError;
pub use error::Iox2Error;
pub use host::{
    Activity, CLIENT_SLOTS, DeviceHandler, DeviceHost, Holder, HostError, HostStats, MAX_TRACKED,
    Motion, Origin, ProcessError, Progress, PublishError,
};
pub use naming::{Channel, DeviceName, NameError};
pub use relay::{AnswerError, PendingLease, PendingRelay, RelayedLease, RelayedRequest};

/// Everything a driver or client author needs, in one `use`.
pub mod prelude {
    pub use crate::client::{
        ActArrayClient, Client, CommandError, ConnectError, DeviceClient, Done, DoneError,
        DriverStatus, Freshness, GripperClient, LaserClient, LimbClient, RangerClient,
        RequestError, Ticket, TrajectorySendError, WaitError, WaitMode, connect_device,
    };
    pub use crate::context::{Context, Role, monotonic_ns};
    pub use crate::device_set::{DeviceSet, DeviceSetHandler};
    pub use crate::discovery::{DeviceInfo, list_devices};
    pub use crate::domain::Domain;
    pub use crate::host::{DeviceHandler, DeviceHost, Motion, Origin, Progress};
    pub use crate::naming::DeviceName;
    pub use limber_interfaces::prelude::*;
}
