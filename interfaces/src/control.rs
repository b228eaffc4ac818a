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
    /// cuts short the motion it started. The motion's result is one more sample
    /// (`result` set) when it ends; a command whose result is decided when the driver
    /// carries it out with `STATUS_OK` (it drives nothing that runs on, or it is a stop)
    /// gets a single sample, its result with `also_outcome` set.
    pub struct OutcomeMsg : "limber.v6.OutcomeMsg", size = 616, align = 8 {
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
        /// 0: this sample is the command's outcome (applied or refused). Otherwise a
        /// `RESULT` code: the motion the command started has ended, and how (one such
        /// sample per command carried out; `status` then says why, e.g. `LINK_DOWN` for
        /// an aborted motion, and `other_client` names the command that preempted it; with
        /// `also_outcome`, the command's outcome too).
        pub result: u32,
        /// The parts (joints) the command drove: the valid entries of `position` and
        /// `error` (at most 32).
        pub parts: u32,
        /// The largest |error| of the parts, in their unit (rad or m); NaN if not known.
        pub max_error: f64,
        /// The device's tolerance for "reached" (the loosest of the parts'), same unit.
        pub tolerance: f64,
        /// Each part's final position (part i = bit i of what the command drove: joint i
        /// of an actuator array, of a limb; 0 for a gripper); NaN if not known.
        pub position: [f64; 32],
        /// Each part's final error against the command's goal (position − goal); NaN if
        /// not known (a motion preempted before its goal was set, a SPEED).
        pub error: [f64; 32],
        /// 1: this result sample is also the command's outcome, carried out with
        /// `STATUS_OK` (its result was decided when the driver carried it out, and no
        /// outcome sample of its own came or comes before it); 0 otherwise.
        pub also_outcome: u32,
        /// Zero.
        pub _pad: u32,
    }
}

/// How a motion ended: [`OutcomeMsg::result`] (0 = not a result but the command's
/// outcome).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum MotionResult {
    /// Every part reached its goal, within the device's tolerance (a command that starts
    /// no motion running on by itself is reached when carried out).
    Reached = 1,
    /// A part stopped short of its goal and does not move on (blocked, or no progress).
    Stalled = 2,
    /// A STOP (or the deadman, when the lease's holder died) stopped it.
    Stopped = 3,
    /// Another command (of this client or another) took over its parts.
    Preempted = 4,
    /// The device gave up: link lost, powered off, brakes, collision (`status` says which).
    Aborted = 5,
    /// The device's own time limit for the motion passed before it ended.
    TimedOut = 6,
    /// A joint of a trajectory left its path tolerance: the device holds where it is
    /// (control_msgs' PATH_TOLERANCE_VIOLATED).
    PathToleranceViolated = 7,
    /// A trajectory's joints were not within their goal tolerance when its last point's
    /// time plus the goal time tolerance had passed: the device holds where it is
    /// (control_msgs' GOAL_TOLERANCE_VIOLATED).
    GoalToleranceViolated = 8,
}

impl MotionResult {
    /// Every result, in code order.
    pub const ALL: [MotionResult; 8] = [
        MotionResult::Reached,
        MotionResult::Stalled,
        MotionResult::Stopped,
        MotionResult::Preempted,
        MotionResult::Aborted,
        MotionResult::TimedOut,
        MotionResult::PathToleranceViolated,
        MotionResult::GoalToleranceViolated,
    ];

    /// The wire code.
    pub const fn code(self) -> u32 {
        self as u32
    }

    /// Its name as limber.h spells it without the prefix (`REACHED`, ...).
    pub fn name(self) -> &'static str {
        RESULT_GROUP
            .constants
            .iter()
            .find(|c| c.value == i64::from(self.code()))
            .map_or("UNKNOWN", |c| c.name)
    }

    /// A short sentence.
    pub const fn describe(self) -> &'static str {
        match self {
            MotionResult::Reached => "reached the goal within the tolerance",
            MotionResult::Stalled => "stalled short of the goal",
            MotionResult::Stopped => "stopped",
            MotionResult::Preempted => "preempted by another command",
            MotionResult::Aborted => "aborted",
            MotionResult::TimedOut => "timed out",
            MotionResult::PathToleranceViolated => "aborted: a joint left its path tolerance",
            MotionResult::GoalToleranceViolated => "aborted: not within the goal tolerance in time",
        }
    }

    /// Which of two results of parts of one command the command ends with: the first
    /// that is not `Reached` (a command reached only when every part did).
    pub const fn combine(self, other: MotionResult) -> MotionResult {
        match self {
            MotionResult::Reached => other,
            s => s,
        }
    }
}

impl core::fmt::Display for MotionResult {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.describe())
    }
}

impl TryFrom<u32> for MotionResult {
    type Error = DecodeError;
    fn try_from(code: u32) -> Result<Self, DecodeError> {
        MotionResult::ALL
            .iter()
            .find(|s| s.code() == code)
            .copied()
            .ok_or(DecodeError::UnknownCode {
                field: "result",
                value: code as i64,
            })
    }
}

pub(crate) const RESULT_GROUP: ConstantGroup = ConstantGroup {
    name: "RESULT",
    doc: "OutcomeMsg.result codes: how a motion ended (0: the sample is the command's outcome)",
    constants: &[
        Constant {
            name: "REACHED",
            value: 1,
            doc: "every part reached its goal within the tolerance",
        },
        Constant {
            name: "STALLED",
            value: 2,
            doc: "a part stopped short of its goal",
        },
        Constant {
            name: "STOPPED",
            value: 3,
            doc: "a STOP (or the deadman) stopped it",
        },
        Constant {
            name: "PREEMPTED",
            value: 4,
            doc: "another command took over its parts",
        },
        Constant {
            name: "ABORTED",
            value: 5,
            doc: "link lost, powered off, brakes, collision (status says which)",
        },
        Constant {
            name: "TIMED_OUT",
            value: 6,
            doc: "the device's time limit for the motion passed",
        },
        Constant {
            name: "PATH_TOLERANCE_VIOLATED",
            value: 7,
            doc: "a trajectory's joint left its path tolerance; the device holds",
        },
        Constant {
            name: "GOAL_TOLERANCE_VIOLATED",
            value: 8,
            doc: "a trajectory's joints were not within the goal tolerance in time; the device holds",
        },
    ],
};

wire_struct! {
    /// A request on a device's `lease` channel (`op` is a `LEASE_OP` code).
    pub struct LeaseReq : "limber.v6.LeaseReq", size = 80, align = 8 {
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
    pub struct LeaseReply : "limber.v6.LeaseReply", size = 80, align = 8 {
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

    /// The motion's result in one sentence (empty when the sample is only the command's
    /// outcome): how it ended, why, and the largest final error against the tolerance.
    pub fn result_sentence(&self) -> String {
        let Ok(Some(r)) = self.motion_result() else {
            return String::new();
        };
        let mut s = String::from(r.describe());
        match self.status() {
            Ok(Status::Ok | Status::Preempted) | Err(_) => {}
            Ok(cause) => s = format!("{s} ({cause})"),
        }
        if r == MotionResult::Preempted && self.other_client != 0 {
            s = format!("{s} (client {:#x})", self.other_client);
        }
        if self.max_error.is_nan() {
            s.push_str("; final error not known");
        } else {
            s = format!(
                "{s}; largest final error {:.4} (tolerance {:.4})",
                self.max_error, self.tolerance
            );
        }
        s
    }

    /// Whether this sample is the command's outcome: a sample without a result, or a
    /// result that is also the outcome ([`OutcomeMsg::also_outcome`]).
    pub fn is_outcome(&self) -> bool {
        self.result == 0 || self.also_outcome != 0
    }

    /// The motion's result, decoded: `None` when the sample is only the command's outcome.
    pub fn motion_result(&self) -> Result<Option<MotionResult>, DecodeError> {
        match self.result {
            0 => Ok(None),
            c => MotionResult::try_from(c).map(Some),
        }
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
