//! The Zenoh key expressions of a device `robot/interface/index` and the type names of
//! their payloads.
//!
//! | key | what | payload |
//! | --- | --- | --- |
//! | `limber/<robot>/<interface>/<index>/state` | put by `expose` on every state sample | the interface's state struct (e.g. `limber.v6.ActArrayData`) |
//! | `limber/<robot>/<interface>/<index>/cmd/<principal>/<session>` | put by a remote client | the command envelope (e.g. `limber.v6.ActArrayCmdMsg`) |
//! | `limber/<robot>/<interface>/<index>/outcome/<principal>/<session>` | put by `expose` for each command of that sender | `limber.v6.OutcomeMsg` |
//! | `limber/<robot>/<interface>/<index>/req/<principal>/<session>` | queryable of `expose` | query: the request envelope; reply: the reply envelope |
//! | `limber/<robot>/<interface>/<index>/lease/<principal>/<session>` | queryable of `expose` | query: `limber.v6.LeaseReq`; reply: `limber.v6.LeaseReply` |
//! | `limber/<robot>/<interface>/<index>/alive` | liveliness token of `expose` | none |
//! | `limber/<robot>/driver/0/stats` | put by `expose` about once a second | `limber.v6.DriverStats` |
//!
//! `<principal>` is who the sender is as Zenoh's authentication established it (its user
//! name or certificate common name; `local` on the owner's Unix socket): the exposing
//! bridge's access-control rules let a session put and ask only under its own principal
//! ([`crate::access`]). `<session>` is a chunk the sender chooses to tell its sessions
//! apart (the mirror uses its Zenoh id). Together they are the sender's *origin*.
//!
//! A query that the driver does not answer in time (or cannot be relayed) gets an error
//! reply whose payload is a `Status` code, 4 bytes little-endian (encoding schema
//! `limber.Status`).
//!
//! Every sample's encoding is `application/octet-stream` with the type name as its schema.

use limber_interfaces::message::{Envelope, ReplyBody, ReplyEnvelope};
use limber_interfaces::prelude::Status;
use limber_interfaces::{Interface, WireStruct};
use limber_services::DeviceName;
use limber_services::monotonic_ns;

/// The first chunk of every key.
pub const ROOT: &str = "limber";

/// The key of one channel of `device` (`state`, `cmd`, `req`, `alive`).
pub fn device_key(device: &DeviceName, channel: &str) -> String {
    format!(
        "{ROOT}/{}/{}/{}/{channel}",
        device.robot(),
        device.interface().name(),
        device.index()
    )
}

/// The key of channel `channel` (`cmd`, `req`, `lease`) of `device` for the sender
/// `origin` (`<principal>/<session>`).
pub fn sender_key(device: &DeviceName, channel: &str, origin: &str) -> String {
    format!("{}/{origin}", device_key(device, channel))
}

/// The key expression of channel `channel` of `device` for every sender.
pub fn all_senders(device: &DeviceName, channel: &str) -> String {
    format!("{}/*/*", device_key(device, channel))
}

/// The origin (`<principal>/<session>`) of key `key` on channel `channel` of `device`, if
/// both chunks are valid.
pub fn origin_of<'k>(key: &'k str, device: &DeviceName, channel: &str) -> Option<&'k str> {
    let rest = key
        .strip_prefix(&device_key(device, channel))?
        .strip_prefix('/')?;
    let (principal, session) = rest.split_once('/')?;
    (valid_chunk(principal) && valid_chunk(session)).then_some(rest)
}

/// The origin of a sender: its principal and a session chunk of its choosing.
pub fn origin(principal: &str, session: &str) -> String {
    format!("{principal}/{session}")
}

/// The key of the outcomes of `device` for the commands of `origin`.
pub fn outcome_key(device: &DeviceName, origin: &str) -> String {
    format!("{}/{origin}", device_key(device, "outcome"))
}

/// The key of the driver statistics of `robot` (`limber.v6.DriverStats`, put by `expose`
/// about once a second).
pub fn driver_stats_key(robot: &str) -> String {
    format!("{ROOT}/{robot}/driver/0/stats")
}

/// The key expression that matches the driver statistics of every robot.
pub fn all_driver_stats() -> String {
    format!("{ROOT}/*/driver/0/stats")
}

/// The robot of a driver statistics key.
pub fn parse_driver_stats(key: &str) -> Option<&str> {
    key.strip_prefix(ROOT)?
        .strip_prefix('/')?
        .strip_suffix("/driver/0/stats")
        .filter(|r| valid_chunk(r))
}

/// The key expression that matches channel `channel` of every device.
pub fn all_devices(channel: &str) -> String {
    format!("{ROOT}/*/*/*/{channel}")
}

/// The device and the channel (everything after the index) of a key, if it is one of
/// ours.
pub fn parse(key: &str) -> Option<(DeviceName, &str)> {
    let rest = key.strip_prefix(ROOT)?.strip_prefix('/')?;
    let mut parts = rest.splitn(4, '/');
    let (robot, interface, index) = (parts.next()?, parts.next()?, parts.next()?);
    let channel = parts.next()?;
    let device = format!("{robot}/{interface}/{index}").parse().ok()?;
    Some((device, channel))
}

/// Whether `s` may be one chunk of a key expression chosen by a peer (an origin id): no
/// wildcard, separator or special character.
pub fn valid_chunk(s: &str) -> bool {
    !s.is_empty()
        && s.len() <= 64
        && s.bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-' || b == b'.')
}

/// The type names of the payloads of one interface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TypeNames {
    /// The state.
    pub data: &'static str,
    /// The command envelope.
    pub cmd: &'static str,
    /// The request envelope.
    pub req: &'static str,
    /// The reply envelope.
    pub reply: &'static str,
}

/// The type names of interface `I`'s payloads.
pub fn type_names<I: limber_interfaces::Interface>() -> TypeNames {
    TypeNames {
        data: <I::Data as WireStruct>::LAYOUT.type_name,
        cmd: <I::CmdMsg as WireStruct>::LAYOUT.type_name,
        req: <I::ReqMsg as WireStruct>::LAYOUT.type_name,
        reply: <I::ReplyMsg as WireStruct>::LAYOUT.type_name,
    }
}

/// The type name of a lease request.
pub fn lease_req_type() -> &'static str {
    <limber_interfaces::prelude::LeaseReq as WireStruct>::LAYOUT.type_name
}

/// The type name of a lease reply.
pub fn lease_reply_type() -> &'static str {
    <limber_interfaces::prelude::LeaseReply as WireStruct>::LAYOUT.type_name
}

/// The type name of a driver's statistics.
pub fn driver_stats_type() -> &'static str {
    <limber_interfaces::diagnostics::DriverStats as WireStruct>::LAYOUT.type_name
}

/// The type name of an outcome.
pub fn outcome_type() -> &'static str {
    <limber_interfaces::prelude::OutcomeMsg as WireStruct>::LAYOUT.type_name
}

/// The encoding of a payload of type `type_name`.
pub fn encoding(type_name: &str) -> zenoh::bytes::Encoding {
    zenoh::bytes::Encoding::APPLICATION_OCTET_STREAM.with_schema(type_name)
}

/// The type name of an error reply to a query: a `Status` code as 4 bytes, little-endian.
pub const STATUS_TYPE: &str = "limber.Status";

/// The NACK of `req` with `status`.
pub(crate) fn nack<I: Interface>(req: &I::ReqMsg, status: Status) -> I::ReplyMsg {
    let mut out = I::ReplyMsg::default();
    let meta = *req.meta();
    I::Reply::write(meta.kind, Err(status), &mut out);
    let m = out.meta_mut();
    m.client_id = meta.client_id;
    m.seq = meta.seq;
    m.stamp_ns = monotonic_ns();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn keys_round_trip() {
        let d: DeviceName = "pioneer/actarray/0".parse().unwrap();
        assert_eq!(device_key(&d, "state"), "limber/pioneer/actarray/0/state");
        assert_eq!(
            parse("limber/pioneer/actarray/0/state"),
            Some((d.clone(), "state"))
        );
        assert_eq!(
            parse(&outcome_key(&d, "abc")),
            Some((d.clone(), "outcome/abc"))
        );
        let k = sender_key(&d, "cmd", &origin("alice", "0f3a"));
        assert_eq!(k, "limber/pioneer/actarray/0/cmd/alice/0f3a");
        assert_eq!(origin_of(&k, &d, "cmd"), Some("alice/0f3a"));
        assert_eq!(origin_of(&k, &d, "req"), None);
        for bad in [
            "cmd/alice",
            "cmd/alice/*",
            "cmd/a/b/c",
            "cmd/**/x",
            "cmdx/a/b",
        ] {
            let key = format!("limber/pioneer/actarray/0/{bad}");
            assert_eq!(origin_of(&key, &d, "cmd"), None, "{bad}");
        }
        assert_eq!(parse("limber/pioneer/arm/0/state"), None);
        assert_eq!(parse("other/pioneer/actarray/0/state"), None);
        assert!(!valid_chunk("a/b") && !valid_chunk("*") && valid_chunk("0f3a"));
        assert_eq!(
            parse_driver_stats(&driver_stats_key("pioneer")),
            Some("pioneer")
        );
        assert_eq!(parse_driver_stats("limber/a/b/driver/0/stats"), None);
    }
}
