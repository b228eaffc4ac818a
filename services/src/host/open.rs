//! Opening a device's channels: [`DeviceHost::new`].

use core::marker::PhantomData;
use core::sync::atomic::{AtomicU64, Ordering};

use iceoryx2::prelude::*;
use iceoryx2::service::attribute::{AttributeKey, AttributeValue};
use limber_interfaces::prelude::*;

use super::arbiter::Arbiter;
use super::{DeviceHost, HostError, HostStats};
use crate::context::Context;
use crate::error::Iox2Error;
use crate::naming::{Channel, DeviceName, attr};
use crate::qos;

/// The next host's arbiter tag (see `Arbiter::with_tag`).
static NEXT_ARBITER_TAG: AtomicU64 = AtomicU64::new(1);

fn attribute_verifier(
    device: &DeviceName,
    driver: &str,
    capacity: qos::Capacity,
) -> Result<AttributeVerifier, HostError> {
    let err = |e: Iox2Error| HostError::Transport {
        device: device.to_string(),
        channel: "attributes",
        source: e,
    };
    let kv = |k: &str, v: &str| -> Result<(AttributeKey, AttributeValue), HostError> {
        Ok((
            AttributeKey::new(k.as_bytes()).map_err(|e| err(e.into()))?,
            AttributeValue::new(v.as_bytes()).map_err(|e| err(e.into()))?,
        ))
    };
    let mut v = AttributeVerifier::new();
    for (k, val) in [
        (attr::ROBOT, device.robot().to_string()),
        (attr::INTERFACE, device.interface().name().to_string()),
        (attr::INDEX, device.index().to_string()),
        (attr::DRIVER, driver.to_string()),
        (attr::LAYOUT, limber_interfaces::LAYOUT_VERSION.to_string()),
        (attr::MAX_CLIENTS, capacity.max_clients().to_string()),
        (attr::RESERVED_CLIENTS, qos::RESERVED_CLIENTS.to_string()),
    ] {
        let (k, val) = kv(k, &val)?;
        v = v.require(&k, &val).map_err(|e| err(e.into()))?;
    }
    Ok(v)
}

impl<I: Interface> DeviceHost<I> {
    /// Offers `device` in the context's domain, as driver `driver` (shown by
    /// `limber list`). The initial state is all zero: set it with [`DeviceHost::state_mut`]
    /// and [`DeviceHost::publish`] before clients act on it.
    pub fn new(ctx: &Context, device: &DeviceName, driver: &str) -> Result<Self, HostError> {
        if device.interface() != I::KIND {
            return Err(HostError::WrongInterface {
                device: device.to_string(),
                expected: I::KIND,
            });
        }
        let node = ctx.node();
        let dev = device.to_string();
        // Every client slot of every channel: the ordinary clients and the reserved ones
        // (the clients keep count of the ordinary ones: `Client::connect`).
        let capacity = ctx.capacity();
        let (ports, nodes) = (capacity.ports(), capacity.nodes());
        let verifier = attribute_verifier(device, driver, capacity)?;
        let transport = |channel: &'static str, e: Iox2Error| {
            if e.is_incompatible_attributes_or_types() {
                HostError::Incompatible {
                    device: dev.clone(),
                    source: e,
                }
            } else {
                HostError::Transport {
                    device: dev.clone(),
                    channel,
                    source: e,
                }
            }
        };

        let data_svc = node
            .service_builder(&device.service_name(Channel::Data))
            .publish_subscribe::<I::Data>()
            .history_size(1)
            .subscriber_max_buffer_size(qos::DATA_BUFFER)
            .subscriber_max_borrowed_samples(qos::DATA_BORROWED)
            .max_publishers(qos::DATA_PUBLISHERS)
            .max_subscribers(ports)
            .max_nodes(nodes)
            .enable_safe_overflow(true)
            .open_or_create_with_attributes(&verifier)
            .map_err(|e| transport("data", e.into()))?;
        // A live driver already publishing this device: refuse to serve it twice.
        if data_svc.dynamic_config().number_of_publishers() > 0 {
            ctx.domain().cleanup_dead_nodes(&data_svc);
            if data_svc.dynamic_config().number_of_publishers() > 0 {
                if let Some(owner) = ctx.domain().dead_node_of_another_user(&data_svc) {
                    return Err(HostError::DeadDriverOfAnotherMember { device: dev, owner });
                }
                return Err(HostError::AlreadyServed { device: dev });
            }
        }
        // One sample loaned ahead for the next publication, one for anybody else.
        let publisher = data_svc
            .publisher_builder()
            .max_loaned_samples(2)
            .create()
            .map_err(|e| transport("data", e.into()))?;

        let cmd_svc = node
            .service_builder(&device.service_name(Channel::Cmd))
            .publish_subscribe::<I::CmdMsg>()
            .history_size(0)
            .subscriber_max_buffer_size(qos::CMD_BUFFER)
            .subscriber_max_borrowed_samples(qos::CMD_BORROWED)
            .max_publishers(ports)
            .max_subscribers(qos::CMD_SUBSCRIBERS)
            .max_nodes(nodes)
            .enable_safe_overflow(true)
            .open_or_create_with_attributes(&verifier)
            .map_err(|e| transport("cmd", e.into()))?;
        let commands = cmd_svc
            .subscriber_builder()
            .buffer_size(qos::CMD_BUFFER)
            .create()
            .map_err(|e| transport("cmd", e.into()))?;

        let req_svc = node
            .service_builder(&device.service_name(Channel::Req))
            .request_response::<I::ReqMsg, I::ReplyMsg>()
            .max_clients(ports)
            .max_servers(qos::REQ_SERVERS)
            .max_nodes(nodes)
            .max_active_requests_per_client(qos::MAX_ACTIVE_REQUESTS)
            .max_response_buffer_size(2)
            .enable_fire_and_forget_requests(false)
            .open_or_create_with_attributes(&verifier)
            .map_err(|e| transport("req", e.into()))?;
        let server = req_svc
            .server_builder()
            .create()
            .map_err(|e| transport("req", e.into()))?;

        let wake_svc = node
            .service_builder(&device.service_name(Channel::Wake))
            .event()
            .max_listeners(qos::WAKE_LISTENERS)
            .max_notifiers(ports)
            .max_nodes(nodes)
            .open_or_create_with_attributes(&verifier)
            .map_err(|e| transport("wake", e.into()))?;
        let wake = wake_svc
            .listener_builder()
            .create()
            .map_err(|e| transport("wake", e.into()))?;

        let notify_svc = node
            .service_builder(&device.service_name(Channel::Notify))
            .event()
            .max_listeners(ports)
            .max_notifiers(qos::NOTIFY_NOTIFIERS)
            .max_nodes(nodes)
            .open_or_create_with_attributes(&verifier)
            .map_err(|e| transport("notify", e.into()))?;
        let notify = notify_svc
            .notifier_builder()
            .create()
            .map_err(|e| transport("notify", e.into()))?;

        let lease_svc = node
            .service_builder(&device.service_name(Channel::Lease))
            .request_response::<LeaseReq, LeaseReply>()
            .max_clients(ports)
            .max_servers(qos::REQ_SERVERS)
            .max_nodes(nodes)
            .max_active_requests_per_client(qos::MAX_ACTIVE_REQUESTS)
            .max_response_buffer_size(2)
            .enable_fire_and_forget_requests(false)
            .open_or_create_with_attributes(&verifier)
            .map_err(|e| transport("lease", e.into()))?;
        let lease_server = lease_svc
            .server_builder()
            .create()
            .map_err(|e| transport("lease", e.into()))?;

        // Each client's own outcomes: one stream per client (see `told.rs`).
        let told_svc = node
            .service_builder(&device.service_name(Channel::Told))
            .request_response::<u64, OutcomeMsg>()
            .max_clients(ports)
            .max_servers(qos::REQ_SERVERS)
            .max_nodes(nodes)
            .max_active_requests_per_client(qos::TOLD_STREAMS)
            .max_response_buffer_size(qos::TOLD_BUFFER)
            .enable_safe_overflow_for_responses(true)
            .enable_fire_and_forget_requests(false)
            .open_or_create_with_attributes(&verifier)
            .map_err(|e| transport("told", e.into()))?;
        let told = told_svc
            .server_builder()
            .create()
            .map_err(|e| transport("told", e.into()))?;

        // Last: a client connects only once it has opened the `outcome` channel (the last
        // it opens), so it finds every other port of this driver made: its first request
        // or lease never goes to a server that is not there yet.
        let outcome_svc = node
            .service_builder(&device.service_name(Channel::Outcome))
            .publish_subscribe::<OutcomeMsg>()
            .history_size(0)
            .subscriber_max_buffer_size(qos::OUTCOME_BUFFER)
            .subscriber_max_borrowed_samples(2)
            .max_publishers(qos::DATA_PUBLISHERS)
            .max_subscribers(ports)
            .max_nodes(nodes)
            .enable_safe_overflow(true)
            .open_or_create_with_attributes(&verifier)
            .map_err(|e| transport("outcome", e.into()))?;
        let all_outcomes = outcome_svc
            .publisher_builder()
            .max_loaned_samples(2)
            .create()
            .map_err(|e| transport("outcome", e.into()))?;

        // The clients that wait for a state sleep on it (a client without it waits on the
        // notify event: slower, not wrong).
        let state_wake = match crate::wake::WakeWord::create(ctx.domain(), device) {
            Ok(w) => Some(w),
            Err(e) => {
                tracing::warn!(device = %dev, error = %e, "no wake word: clients waiting for a state wait on the notify event");
                None
            }
        };
        // Group mode: this device's files open to the group at once.
        ctx.domain().widen_now();
        Ok(DeviceHost {
            state_wake,
            domain: ctx.domain().clone(),
            device: device.clone(),
            data_svc,
            publisher,
            commands,
            cmd_round: Vec::with_capacity(ports * qos::CMD_BORROWED),
            cmd_svc,
            req_svc,
            cmd_senders: super::senders::PortNodes::new(ports),
            forged: 0,
            peers_seen: 0,
            full_cleanup_at: std::cell::Cell::new(None),
            req_senders: super::senders::PortNodes::new(ports),
            lease_senders: super::senders::PortNodes::new(ports),
            server,
            wake: Some(wake),
            notify,
            out: super::told::Outcomes::new(outcome_svc, all_outcomes, told_svc, told, ports),
            lease_svc,
            lease_server,
            // A tag of its own: of the hosts that share a lease, the one that granted it
            // looks up the holder's node.
            arbiter: Arbiter::with_tag(NEXT_ARBITER_TAG.fetch_add(1, Ordering::Relaxed)),
            motions: super::motions::Motions::new(),
            lease_ended: None,
            state: I::Data::default(),
            seq: 0,
            outcome: CmdOutcome::default(),
            flags: 0,
            stats: HostStats::default(),
            publish_each_outcome: true,
            spin_calls: 0,
            state_loan: None,
            _i: PhantomData,
        })
    }
}
