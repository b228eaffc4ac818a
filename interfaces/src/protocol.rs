//! Protocol numbers beside the wire layouts: name limits, event ids and the outcome
//! buffers. `limber-services` uses them, and the manifest carries them so the
//! C header and the Python module are generated with the same values.

use crate::manifest::{Constant, ConstantGroup};

/// Longest domain name.
pub const MAX_DOMAIN_LEN: usize = 48;
/// Longest robot name.
pub const MAX_ROBOT_LEN: usize = 64;

/// Event id on a device's `wake` channel: a command was sent.
pub const WAKE_COMMAND: usize = 1;
/// Event id on `wake`: a request was sent.
pub const WAKE_REQUEST: usize = 2;
/// Event id on `wake`: a client connected (the driver hands it the latest state).
pub const WAKE_HELLO: usize = 3;
/// Event id on a device's `notify` channel: a state sample was published.
pub const NOTIFY_STATE: usize = 1;
/// Event id on `notify`: a reply was sent.
pub const NOTIFY_REPLY: usize = 2;

/// Outcomes buffered per watcher on the `outcome` channel (a bridge, a recorder: it sees
/// every outcome of the device).
pub const OUTCOME_BUFFER: usize = 256;

/// Outcomes buffered per client on its own stream of the `told` channel (only the outcomes
/// and results of its own commands: this many may be decided between two looks of the
/// client before the oldest is overwritten).
pub const TOLD_BUFFER: usize = 64;

pub(crate) const NAME_GROUP: ConstantGroup = ConstantGroup {
    name: "NAME",
    doc: "Name limits (domain and robot names are [A-Za-z0-9_-]+)",
    constants: &[
        Constant {
            name: "MAX_DOMAIN_LEN",
            value: MAX_DOMAIN_LEN as i64,
            doc: "longest domain name",
        },
        Constant {
            name: "MAX_ROBOT_LEN",
            value: MAX_ROBOT_LEN as i64,
            doc: "longest robot name",
        },
    ],
};

pub(crate) const WAKE_GROUP: ConstantGroup = ConstantGroup {
    name: "WAKE",
    doc: "Event ids on a device's wake channel (client to driver)",
    constants: &[
        Constant {
            name: "COMMAND",
            value: WAKE_COMMAND as i64,
            doc: "a command was sent",
        },
        Constant {
            name: "REQUEST",
            value: WAKE_REQUEST as i64,
            doc: "a request was sent",
        },
        Constant {
            name: "HELLO",
            value: WAKE_HELLO as i64,
            doc: "a client connected",
        },
    ],
};

pub(crate) const NOTIFY_GROUP: ConstantGroup = ConstantGroup {
    name: "NOTIFY",
    doc: "Event ids on a device's notify channel (driver to clients)",
    constants: &[
        Constant {
            name: "STATE",
            value: NOTIFY_STATE as i64,
            doc: "a state sample was published",
        },
        Constant {
            name: "REPLY",
            value: NOTIFY_REPLY as i64,
            doc: "a reply was sent",
        },
    ],
};

pub(crate) const QOS_GROUP: ConstantGroup = ConstantGroup {
    name: "QOS",
    doc: "Buffer sizes a client opens its ports with",
    constants: &[
        Constant {
            name: "OUTCOME_BUFFER",
            value: OUTCOME_BUFFER as i64,
            doc: "outcomes buffered per watcher on the outcome channel",
        },
        Constant {
            name: "TOLD_BUFFER",
            value: TOLD_BUFFER as i64,
            doc: "outcomes of its own commands buffered per client on the told channel",
        },
    ],
};
