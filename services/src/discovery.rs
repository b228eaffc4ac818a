//! Discovery: every device of a domain, with its driver and whether it is alive.

use iceoryx2::prelude::*;
use iceoryx2::service::ServiceListError;
use iceoryx2::service::static_config::messaging_pattern::MessagingPattern as Pattern;
use limber_interfaces::InterfaceKind;
use thiserror::Error;

use crate::domain::Domain;
use crate::naming::{Channel, DRIVER_NODE_PREFIX, DeviceName, attr};

/// One device found in a domain.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord)]
pub struct DeviceInfo {
    /// Its name (`robot/interface/index`).
    pub name: DeviceName,
    /// The driver that offers it (its `limber.driver` attribute).
    pub driver: String,
    /// The layout version it speaks.
    pub layout: String,
    /// True while the driver's process lives.
    pub alive: bool,
    /// Processes attached to its state channel (driver and clients).
    pub nodes: usize,
}

impl DeviceInfo {
    /// The interface.
    pub fn interface(&self) -> InterfaceKind {
        self.name.interface()
    }
}

/// Listing the devices failed.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum ListError {
    /// The domain's files could not be prepared or belong to another user.
    #[error("cannot use domain {domain}: {source}")]
    Domain {
        /// The domain.
        domain: String,
        /// Why.
        #[source]
        source: Box<crate::domain::DomainError>,
    },
    /// iceoryx2 could not read the service directory (permissions?).
    #[error("cannot list the services of domain {domain}: {source}")]
    Transport {
        /// The domain.
        domain: String,
        /// iceoryx2's error.
        #[source]
        source: ServiceListError,
    },
}

/// Every device of `domain`, sorted by name. A device whose driver died is listed as not
/// alive until its services are cleaned up; one whose driver ended cleanly is not listed,
/// even while clients still hold its services open.
pub fn list_devices(domain: &Domain) -> Result<Vec<DeviceInfo>, ListError> {
    let mut out = Vec::new();
    let config = domain.config().map_err(|e| ListError::Domain {
        domain: domain.name().to_string(),
        source: Box::new(e),
    })?;
    ipc::Service::list(config, |details| {
        let name = details.static_details.name().as_str().to_string();
        if !matches!(
            details.static_details.messaging_pattern(),
            Pattern::PublishSubscribe(_)
        ) {
            return CallbackProgression::Continue;
        }
        let Some((device, Channel::Data)) = DeviceName::from_service_name(&name) else {
            return CallbackProgression::Continue;
        };
        let attrs = details.static_details.attributes();
        let get = |k: &str| -> String {
            attrs
                .iter()
                .find(|a| a.key().as_bytes() == k.as_bytes())
                .map(|a| a.value().to_string())
                .unwrap_or_default()
        };
        let (mut alive, mut dead, mut unknown, mut nodes) = (false, false, false, 0);
        if let Some(dynamic) = &details.dynamic_details {
            use iceoryx2::node::NodeView;
            let is_driver = |d: &Option<iceoryx2::node::NodeDetails>| {
                d.as_ref()
                    .is_some_and(|d| d.name().as_str().starts_with(DRIVER_NODE_PREFIX))
            };
            for n in &dynamic.nodes {
                nodes += 1;
                match n {
                    NodeState::Alive(v) if v.details().is_none() => unknown = true,
                    NodeState::Alive(v) => alive |= is_driver(v.details()),
                    NodeState::Dead(v) => dead |= is_driver(v.details()),
                    NodeState::Inaccessible(_) | NodeState::Undefined(_) => unknown = true,
                }
            }
        }
        // A driver that ended cleanly left no node behind: the files that clients still
        // hold are not a device any more (neither alive nor dead: not listed).
        if !(alive || dead || unknown) {
            return CallbackProgression::Continue;
        }
        out.push(DeviceInfo {
            name: device,
            driver: get(attr::DRIVER),
            layout: get(attr::LAYOUT),
            alive,
            nodes,
        });
        CallbackProgression::Continue
    })
    .map_err(|e| ListError::Transport {
        domain: domain.name().to_string(),
        source: e,
    })?;
    out.sort();
    Ok(out)
}
