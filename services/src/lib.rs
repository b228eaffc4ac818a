#![doc = include_str!("../README.md")]
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
pub mod loop_stats;
pub mod naming;
pub mod qos;
pub mod relay;
pub mod signals;
pub mod testing;
pub(crate) mod wake;

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
