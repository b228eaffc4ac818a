//! Who commands a device: the per-client outcome of every command (the `outcome` channel)
//! and the control lease (the `lease` channel). Both are new in layout version 2.

use crate::common::Status;
use crate::diagnostics::{TEXT_LEN, get_text, put_text};
use crate::error::DecodeError;
use crate::manifest::{Constant, ConstantGroup};
#[allow(unused_imports)]
use crate::wire::{ZeroCopySend, wire_struct};

wire_struct! {
    /// The outcome of one command, published on the device's `outcome` channel to every
    /// client (each keeps its own, by `client_id`): one sample when the command is applied
    /// or refused, and one more with `STATUS_PREEMPTED` when another client's command
    /// cuts short the motion it started.
    pub struct OutcomeMsg : "limber.v3.OutcomeMsg", size = 72, align = 8 {
        /// The client that sent the command.
        pub client_id: u64,
        /// That client's sequence number of the command.
        pub cmd_seq: u64,
        /// The other client involved: the one that preempted this command
        /// (`STATUS_PREEMPTED`) or the one holding the device (`STATUS_LEASED`); 0 if none.
        pub other_client: u64,
        /// `CLOCK_MONOTONIC` ns when the driver decided.
        pub stamp_ns: u64,
        /// The command kind (the interface's `*_CMD` code).
        pub kind: u32,
        /// A `STATUS` code.
        pub status: u32,
        /// The name of the holder of the lease (`STATUS_LEASED`, or a preempting holder),
        /// NUL-padded UTF-8; empty if none.
        pub other_name: [u8; 32],
    }
}

wire_struct! {
    /// A request on a device's `lease` channel (`op` is a `LEASE_OP` code).
    pub struct LeaseReq : "limber.v3.LeaseReq", size = 80, align = 8 {
        /// The requesting client's id (the one its commands carry).
        pub client_id: u64,
        /// The client's sequence number of this request.
        pub seq: u64,
        /// Low 64 bits of the requester's iceoryx2 node id (the driver watches that node:
        /// when it dies, the lease ends).
        pub node_lo: u64,
        /// High 64 bits of the node id.
        pub node_hi: u64,
        /// `ACQUIRE`/`RENEW`: the heartbeat timeout in ns (the lease ends if no renewal
        /// arrives for this long).
        pub timeout_ns: u64,
        /// A `LEASE_OP` code.
        pub op: u32,
        /// Zero.
        pub _pad: u32,
        /// `ACQUIRE`: the holder's name shown to others, NUL-padded UTF-8.
        pub name: [u8; 32],
    }
}

wire_struct! {
    /// The answer to a [`LeaseReq`]: the status and who holds the device now.
    pub struct LeaseReply : "limber.v3.LeaseReply", size = 80, align = 8 {
        /// The holder's client id (0: nobody holds the device).
        pub holder_client: u64,
        /// The request's sequence number.
        pub seq: u64,
        /// Low 64 bits of the holder's iceoryx2 node id.
        pub holder_node_lo: u64,
        /// High 64 bits.
        pub holder_node_hi: u64,
        /// The holder's heartbeat timeout in ns.
        pub timeout_ns: u64,
        /// `STATUS_OK`, or why the operation was refused (`LEASED`: another client holds
        /// it; `NOT_HELD`: renewing or releasing a lease this client does not hold).
        pub status: u32,
        /// Zero.
        pub _pad: u32,
        /// The holder's name, NUL-padded UTF-8.
        pub holder_name: [u8; 32],
    }
}

/// Codes of [`LeaseReq::op`].
pub mod lease_op {
    /// Take the device (or refresh one's own lease with a new timeout).
    pub const ACQUIRE: u32 = 1;
    /// Heartbeat: the holder is alive.
    pub const RENEW: u32 = 2;
    /// Give the device back (the motion in progress goes on).
    pub const RELEASE: u32 = 3;
    /// Who holds the device (any client; changes nothing).
    pub const QUERY: u32 = 4;
}

pub(crate) const LEASE_OP_GROUP: ConstantGroup = ConstantGroup {
    name: "LEASE_OP",
    doc: "LeaseReq.op codes",
    constants: &[
        Constant {
            name: "ACQUIRE",
            value: 1,
            doc: "take the device, or refresh one's own lease",
        },
        Constant {
            name: "RENEW",
            value: 2,
            doc: "heartbeat of the holder",
        },
        Constant {
            name: "RELEASE",
            value: 3,
            doc: "give the device back",
        },
        Constant {
            name: "QUERY",
            value: 4,
            doc: "who holds the device",
        },
    ],
};

/// Copies a name into a 32-byte NUL-padded text field (truncating at a char boundary).
pub fn put_name(field: &mut [u8; 32], s: &str) {
    const _: () = assert!(TEXT_LEN == 32);
    put_text(field, s);
}

/// Reads a 32-byte NUL-padded text field.
pub fn get_name(field: &[u8; 32]) -> Result<&str, DecodeError> {
    get_text(field)
}

impl OutcomeMsg {
    /// The status, decoded.
    pub fn status(&self) -> Result<Status, DecodeError> {
        Status::try_from(self.status)
    }
}

impl LeaseReq {
    /// The requester's node id.
    pub fn node_id(&self) -> u128 {
        (self.node_hi as u128) << 64 | self.node_lo as u128
    }

    /// Sets the requester's node id.
    pub fn set_node_id(&mut self, id: u128) {
        self.node_lo = id as u64;
        self.node_hi = (id >> 64) as u64;
    }
}

impl LeaseReply {
    /// The holder's node id.
    pub fn holder_node(&self) -> u128 {
        (self.holder_node_hi as u128) << 64 | self.holder_node_lo as u128
    }

    /// Sets the holder's node id.
    pub fn set_holder_node(&mut self, id: u128) {
        self.holder_node_lo = id as u64;
        self.holder_node_hi = (id >> 64) as u64;
    }

    /// The status, decoded.
    pub fn status(&self) -> Result<Status, DecodeError> {
        Status::try_from(self.status)
    }
}
