//! Domains, device names and service names.
//!
//! A device is named `robot/interface/index` (e.g. `pioneer/actarray/0`); each device has
//! the iceoryx2 services `limber/<robot>/<interface>/<index>/<channel>` with channels
//! `data` (state, pub/sub, history 1), `cmd` (commands, pub/sub, many clients), `req`
//! (request/response), `wake` (event: clients → driver) and `notify` (event: driver →
//! clients, new state or reply ready). A domain maps onto an iceoryx2 prefix and root
//! path of its owner's (see [`crate::domain_dir`]), so robots and tests on one PC never
//! meet and no other user can read, command or deny a domain.

use core::fmt;
use std::str::FromStr;
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, OnceLock};

use iceoryx2::config::Config;
use iceoryx2::prelude::{FileName, Path as IoxPath, SemanticString, ServiceName};
use limber_interfaces::InterfaceKind;
use thiserror::Error;

use crate::domain_dir::{self, DomainError};

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
        "invalid device name {0:?}: expected robot/interface/index, e.g. pioneer/actarray/0 (interfaces: actarray, limb, gripper)"
    )]
    Device(String),
}

fn valid_ident(s: &str, max: usize) -> bool {
    !s.is_empty()
        && s.len() <= max
        && s.bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-')
}

/// A domain: the set of devices and clients that can see each other.
#[derive(Debug, Clone)]
pub struct Domain {
    name: String,
    /// The iceoryx2 configuration, made on first use (it needs the domain's files).
    config: Arc<OnceLock<Resolved>>,
    /// A test's domain ([`Domain::unique_for_test`]): removes the domain's files when the
    /// last clone is dropped.
    remove_on_drop: Option<Arc<RemoveOnDrop>>,
}

/// Removes the files of a test's domain when dropped ([`crate::cleanup`]).
#[derive(Debug)]
struct RemoveOnDrop(String);

impl Drop for RemoveOnDrop {
    fn drop(&mut self) {
        crate::cleanup::remove_when_idle(&self.0, crate::cleanup::IDLE_WAIT);
    }
}

/// A domain's iceoryx2 configuration, prefix and group, made once.
#[derive(Debug)]
struct Resolved {
    config: Config,
    prefix: String,
    root: std::path::PathBuf,
    group: Option<domain_dir::Group>,
}

impl Domain {
    /// A domain by name (`[A-Za-z0-9_-]`, 1 to 48 characters).
    pub fn new(name: &str) -> Result<Self, NameError> {
        if !valid_ident(name, MAX_DOMAIN_LEN) {
            return Err(NameError::Domain(name.to_string()));
        }
        Ok(Domain {
            name: name.to_string(),
            config: Arc::new(OnceLock::new()),
            remove_on_drop: None,
        })
    }

    /// The domain named by `LIMBER_DOMAIN`, or `limber`.
    pub fn from_env() -> Result<Self, NameError> {
        match std::env::var(DOMAIN_ENV) {
            Ok(v) if !v.is_empty() => Domain::new(&v),
            _ => Domain::new(DEFAULT_DOMAIN),
        }
    }

    /// A fresh domain for one test: `limber_t<pid>_<n>_<nanos>`, unique on this machine.
    ///
    /// It cleans up after itself: when its last clone is dropped, once no process runs in it
    /// any more (waiting a few seconds at most for processes just killed or told to stop),
    /// every file of the domain is removed, those of processes the test killed included
    /// ([`crate::cleanup::remove_domain_files`]). Keep it alive for as long as the test uses
    /// the domain, also when only its name is handed to other processes.
    pub fn unique_for_test() -> Self {
        static N: AtomicU32 = AtomicU32::new(0);
        let n = N.fetch_add(1, Ordering::Relaxed);
        // The pid alone repeats over a long run of test processes, and a test that
        // SIGKILLs a driver leaves its files behind: the clock makes a reused pid a new
        // domain.
        let nanos = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.subsec_nanos());
        let name = format!("limber_t{}_{}_{nanos:x}", std::process::id(), n);
        Domain::for_test(&name).expect("generated test domain names are valid")
    }

    /// A test's domain of a name the test chose (one made from a [`Domain::unique_for_test`]
    /// name, for a test that needs several domains): it cleans up after itself as that one
    /// does.
    pub fn for_test(name: &str) -> Result<Self, NameError> {
        let mut domain = Domain::new(name)?;
        domain.remove_on_drop = Some(Arc::new(RemoveOnDrop(name.to_string())));
        Ok(domain)
    }

    /// The name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The iceoryx2 configuration of this domain: iceoryx2's built-in defaults (a stray
    /// `./config/iceoryx2.toml` does not change a robot's behaviour) with the root path and
    /// prefix of the domain's files, which are prepared (and checked) on the first call; see
    /// [`crate::domain_dir`].
    pub fn config(&self) -> Result<&Config, DomainError> {
        Ok(&self.resolved()?.config)
    }

    /// The iceoryx2 prefix of this domain's files (`limber_<token>_`).
    pub fn prefix(&self) -> Result<&str, DomainError> {
        Ok(&self.resolved()?.prefix)
    }

    /// The iceoryx2 root path of this domain's files (`<runtime>/iceoryx2/`).
    pub fn root(&self) -> Result<&std::path::Path, DomainError> {
        Ok(&self.resolved()?.root)
    }

    /// The Unix group that shares this domain (group mode, `LIMBER_GROUP`), or None: the
    /// domain is its user's alone.
    pub fn group(&self) -> Result<Option<&domain_dir::Group>, DomainError> {
        Ok(self.resolved()?.group.as_ref())
    }

    /// In group mode, opens this user's files of the domain to the group now (the watch of
    /// [`crate::widen`] does as they appear; this covers the files a port made before a
    /// short-lived process ends). Nothing otherwise.
    pub(crate) fn widen_now(&self) {
        if let Some(r) = self.config.get()
            && let Some(g) = &r.group
        {
            crate::widen::sweep(&r.prefix, &r.root, g);
        }
    }

    fn resolved(&self) -> Result<&Resolved, DomainError> {
        if let Some(c) = self.config.get() {
            return Ok(c);
        }
        let files = domain_dir::prepare(&self.name)?;
        let mut config = Config::default();
        let bad = |what: &str| DomainError::Io {
            what: "use",
            path: files.root.clone(),
            source: std::io::Error::new(std::io::ErrorKind::InvalidInput, what.to_string()).into(),
        };
        config.global.prefix = FileName::new(files.prefix.as_bytes())
            .map_err(|_| bad("an invalid iceoryx2 prefix"))?;
        let root = files
            .root
            .to_str()
            .ok_or_else(|| bad("a path that is not UTF-8"))?;
        config.global.set_root_path(
            &IoxPath::new(root.as_bytes()).map_err(|_| bad("an invalid iceoryx2 root path"))?,
        );
        if files.group.is_some() {
            // Each member cleans up after its own dead processes only (crate::widen).
            config.global.node.cleanup_dead_nodes_on_creation = false;
            config.global.node.cleanup_dead_nodes_on_destruction = false;
            config.global.service.cleanup_dead_nodes_on_open = false;
        }
        Ok(self.config.get_or_init(|| Resolved {
            config,
            prefix: files.prefix,
            root: files.root,
            group: files.group,
        }))
    }
}

impl fmt::Display for Domain {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name)
    }
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
    /// The outcome of every command, driver → clients (publish-subscribe; each client
    /// keeps its own).
    Outcome,
    /// The control lease: acquire, renew, release, query (request-response).
    Lease,
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
    /// The interface (`actarray`, `limb`, `gripper`).
    pub const INTERFACE: &str = "limber.interface";
    /// The device index.
    pub const INDEX: &str = "limber.index";
    /// The driver's name (e.g. `pioneer`, `simarm`).
    pub const DRIVER: &str = "limber.driver";
    /// The layout version of the wire contract.
    pub const LAYOUT: &str = "limber.layout";
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

    #[test]
    fn domains_validate() {
        assert!(Domain::new("robot_1").is_ok());
        assert!(Domain::new("").is_err());
        assert!(Domain::new("a b").is_err());
        assert!(Domain::new(&"x".repeat(49)).is_err());
        assert_ne!(
            Domain::unique_for_test().name(),
            Domain::unique_for_test().name()
        );
    }
}
