//! Domains, device names and service names.
//!
//! A device is named `robot/interface/index` (e.g. `pioneer/actarray/0`); each device has
//! the iceoryx2 services `limber/<robot>/<interface>/<index>/<channel>` with channels
//! `data` (state, pub/sub, history 1), `cmd` (commands, pub/sub, many clients), `req`
//! (request/response), `wake` (event: clients → driver) and `notify` (event: driver →
//! clients, new state or reply ready). A domain maps onto an iceoryx2 prefix and root
//! path of its owner's (see [`crate::domain`]), so robots and tests on one PC never
//! meet and no other user can read, command or deny a domain.
//!
//! Names only: no file is touched here, and nothing of [`crate::domain`] is used (the
//! domain module uses the names of this one, never the other way round).

use core::fmt;
use std::str::FromStr;

use iceoryx2::prelude::ServiceName;
use limber_interfaces::InterfaceKind;
use thiserror::Error;

/// The environment variable that selects the domain.
pub const DOMAIN_ENV: &str = "LIMBER_DOMAIN";
/// The domain used when [`DOMAIN_ENV`] is not set.
pub const DEFAULT_DOMAIN: &str = "limber";
/// Longest domain name.
pub const MAX_DOMAIN_LEN: usize = limber_interfaces::protocol::MAX_DOMAIN_LEN;
/// Longest robot name.
pub const MAX_ROBOT_LEN: usize = limber_interfaces::protocol::MAX_ROBOT_LEN;

/// A name could not be parsed or is not allowed.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum NameError {
    /// A domain name is empty, too long, or has characters other than `[A-Za-z0-9_-]`.
    #[error("invalid domain {0:?}: use 1 to 48 characters of [A-Za-z0-9_-]")]
    Domain(String),
    /// A robot name is empty, too long, or has characters other than `[A-Za-z0-9_-]`.
    #[error("invalid robot name {0:?}: use 1 to 64 characters of [A-Za-z0-9_-]")]
    Robot(String),
    /// A device name is not `robot/interface/index`.
    #[error(
        "invalid device name {0:?}: expected robot/interface/index, e.g. pioneer/actarray/0 (interfaces: actarray, limb, gripper, ranger)"
    )]
    Device(String),
}

pub(crate) fn valid_ident(s: &str, max: usize) -> bool {
    !s.is_empty()
        && s.len() <= max
        && s.bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-')
}

/// A channel of a device.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Channel {
    /// State, driver → clients (publish-subscribe, history 1).
    Data,
    /// Commands, clients → driver (publish-subscribe).
    Cmd,
    /// Requests and replies (request-response).
    Req,
    /// Wake-up of the driver (event, clients → driver).
    Wake,
    /// Wake-up of the clients (event, driver → clients: new state, reply ready).
    Notify,
    /// The outcome of every command, driver → whoever watches them all (publish-subscribe:
    /// a bridge, `limber record`); a client reads its own on [`Channel::Told`].
    Outcome,
    /// The control lease: acquire, renew, release, query (request-response).
    Lease,
    /// Each client's own outcomes, driver → that client (request-response: a client asks
    /// once, with its client id, and the driver answers with every outcome of its commands).
    Told,
}

impl Channel {
    /// The last segment of the service name.
    pub const fn name(self) -> &'static str {
        match self {
            Channel::Data => "data",
            Channel::Cmd => "cmd",
            Channel::Req => "req",
            Channel::Wake => "wake",
            Channel::Notify => "notify",
            Channel::Outcome => "outcome",
            Channel::Lease => "lease",
            Channel::Told => "told",
        }
    }
}

/// The name of a device: robot, interface, index.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct DeviceName {
    robot: String,
    interface: InterfaceKind,
    index: u16,
}

impl DeviceName {
    /// A device name; the robot name must be 1 to 64 characters of `[A-Za-z0-9_-]`.
    pub fn new(robot: &str, interface: InterfaceKind, index: u16) -> Result<Self, NameError> {
        if !valid_ident(robot, MAX_ROBOT_LEN) {
            return Err(NameError::Robot(robot.to_string()));
        }
        Ok(DeviceName {
            robot: robot.to_string(),
            interface,
            index,
        })
    }

    /// The robot.
    pub fn robot(&self) -> &str {
        &self.robot
    }

    /// The interface.
    pub fn interface(&self) -> InterfaceKind {
        self.interface
    }

    /// The index.
    pub fn index(&self) -> u16 {
        self.index
    }

    /// The iceoryx2 service name of one channel.
    pub fn service_name(&self, channel: Channel) -> ServiceName {
        let s = format!(
            "limber/{}/{}/{}/{}",
            self.robot,
            self.interface.name(),
            self.index,
            channel.name()
        );
        // Only [A-Za-z0-9_/-] and at most ~100 bytes: always a valid service name.
        ServiceName::new(&s).expect("device service names are valid")
    }

    /// Parses a service name `limber/<robot>/<interface>/<index>/<channel>`.
    pub fn from_service_name(s: &str) -> Option<(DeviceName, Channel)> {
        let mut it = s.split('/');
        if it.next()? != "limber" {
            return None;
        }
        let dev: DeviceName = format!("{}/{}/{}", it.next()?, it.next()?, it.next()?)
            .parse()
            .ok()?;
        let ch = match it.next()? {
            "data" => Channel::Data,
            "cmd" => Channel::Cmd,
            "req" => Channel::Req,
            "wake" => Channel::Wake,
            "notify" => Channel::Notify,
            _ => return None,
        };
        if it.next().is_some() {
            return None;
        }
        Some((dev, ch))
    }
}

impl fmt::Display for DeviceName {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}/{}", self.robot, self.interface.name(), self.index)
    }
}

impl FromStr for DeviceName {
    type Err = NameError;
    fn from_str(s: &str) -> Result<Self, NameError> {
        let bad = || NameError::Device(s.to_string());
        let mut it = s.split('/');
        let (Some(robot), Some(iface), Some(index), None) =
            (it.next(), it.next(), it.next(), it.next())
        else {
            return Err(bad());
        };
        let interface = InterfaceKind::from_name(iface).ok_or_else(bad)?;
        let index: u16 = index.parse().map_err(|_| bad())?;
        DeviceName::new(robot, interface, index)
    }
}

/// Keys of the service attributes a driver sets on every service of a device.
pub mod attr {
    /// The robot name.
    pub const ROBOT: &str = "limber.robot";
    /// The interface (`actarray`, `limb`, `gripper`, `ranger`).
    pub const INTERFACE: &str = "limber.interface";
    /// The device index.
    pub const INDEX: &str = "limber.index";
    /// The driver's name (e.g. `pioneer`, `simarm`).
    pub const DRIVER: &str = "limber.driver";
    /// The layout version of the wire contract.
    pub const LAYOUT: &str = "limber.layout";
    /// Ordinary clients the device admits ([`crate::qos::Capacity::max_clients`]).
    pub const MAX_CLIENTS: &str = "limber.max_clients";
    /// Slots beyond them kept for priority clients ([`crate::qos::RESERVED_CLIENTS`]).
    pub const RESERVED_CLIENTS: &str = "limber.reserved_clients";
}

/// The node name prefix of driver processes (liveness checks look for it).
pub const DRIVER_NODE_PREFIX: &str = "limber-driver:";
/// The node name prefix of client processes.
pub const CLIENT_NODE_PREFIX: &str = "limber-client:";

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn device_names_parse_and_print() {
        let d: DeviceName = "pioneer/actarray/0".parse().unwrap();
        assert_eq!(d.robot(), "pioneer");
        assert_eq!(d.interface(), InterfaceKind::ActArray);
        assert_eq!(d.to_string(), "pioneer/actarray/0");
        assert_eq!(
            d.service_name(Channel::Cmd).as_str(),
            "limber/pioneer/actarray/0/cmd"
        );
        let (back, ch) = DeviceName::from_service_name("limber/pioneer/actarray/0/cmd").unwrap();
        assert_eq!((back, ch), (d, Channel::Cmd));
        for bad in [
            "pioneer/arm/0",
            "pioneer/actarray",
            "pioneer/actarray/x",
            "pi oneer/limb/0",
            "a/limb/0/1",
            "/limb/0",
        ] {
            assert!(bad.parse::<DeviceName>().is_err(), "{bad}");
        }
    }
}
