//! What every interface shares: 3D geometry, the state header, command and request
//! metadata, and the status codes that say why something was refused.

use crate::error::DecodeError;
use crate::manifest::{Constant, ConstantGroup};
#[allow(unused_imports)]
use crate::wire::{ZeroCopySend, wire_struct};

/// The maximum number of actuators in one actuator array.
pub const MAX_ACTUATORS: usize = 32;

wire_struct! {
    /// A point or vector in 3D (Player's `point_3d`), metres or unitless.
    pub struct Vec3 : "limber.v6.Vec3", size = 24, align = 8 {
        /// x (forward in the robot frame).
        pub x: f64,
        /// y (left).
        pub y: f64,
        /// z (up).
        pub z: f64,
    }
}

wire_struct! {
    /// Roll, pitch and yaw in radians (Player's `orientation_3d`).
    pub struct Orientation3 : "limber.v6.Orientation3", size = 24, align = 8 {
        /// Rotation about x.
        pub roll: f64,
        /// Rotation about y.
        pub pitch: f64,
        /// Rotation about z.
        pub yaw: f64,
    }
}

wire_struct! {
    /// A 3D pose (Player's `pose3d`): position in metres, orientation in radians.
    pub struct Pose3 : "limber.v6.Pose3", size = 48, align = 8 {
        /// Position.
        pub position: Vec3,
        /// Orientation.
        pub orientation: Orientation3,
    }
}

wire_struct! {
    /// A box size in metres (Player's `bbox3d`).
    pub struct Bbox3 : "limber.v6.Bbox3", size = 24, align = 8 {
        /// Width (along y).
        pub width: f64,
        /// Length (along x).
        pub length: f64,
        /// Height (along z).
        pub height: f64,
    }
}

wire_struct! {
    /// The outcome of the last command a driver applied, carried in every state sample so
    /// the sender of a command sees whether (and why not) it was carried out.
    pub struct CmdOutcome : "limber.v6.CmdOutcome", size = 24, align = 8 {
        /// The client that sent it (0: no command applied yet).
        pub client_id: u64,
        /// That client's sequence number of the command.
        pub cmd_seq: u64,
        /// The command kind (the interface's `*_CMD` code).
        pub kind: u32,
        /// A `STATUS` code: 0 = carried out, otherwise why it was refused.
        pub status: u32,
    }
}

wire_struct! {
    /// The header of every state sample.
    pub struct StateHeader : "limber.v6.StateHeader", size = 48, align = 8 {
        /// Sample sequence number, +1 per published sample of this device.
        pub seq: u64,
        /// `CLOCK_MONOTONIC` time in ns at which the state was acquired (e.g. when the
        /// robot's packet arrived), not when it was published.
        pub stamp_ns: u64,
        /// The last command applied (or refused).
        pub last_cmd: CmdOutcome,
        /// `DEVICE_FLAG` bits (link up, calibrated, ...).
        pub flags: u32,
        /// Commands lost because the driver's command queue overflowed (since start).
        pub cmd_overflows: u32,
    }
}

wire_struct! {
    /// Metadata in front of every command and every request.
    pub struct MsgMeta : "limber.v6.MsgMeta", size = 32, align = 8 {
        /// The sending client (unique per client in a domain; never 0).
        pub client_id: u64,
        /// The client's sequence number, +1 per message it sends on this channel.
        pub seq: u64,
        /// `CLOCK_MONOTONIC` ns when the client sent it (for latency accounting).
        pub stamp_ns: u64,
        /// The message kind (the interface's `*_CMD` or `*_REQ` code).
        pub kind: u32,
        /// Number of valid bytes in the body that follows.
        pub body_len: u32,
    }
}

wire_struct! {
    /// Metadata in front of every reply.
    pub struct ReplyMeta : "limber.v6.ReplyMeta", size = 32, align = 8 {
        /// The client whose request this answers.
        pub client_id: u64,
        /// The request's sequence number.
        pub seq: u64,
        /// `CLOCK_MONOTONIC` ns when the driver answered.
        pub stamp_ns: u64,
        /// The request kind (echoed).
        pub kind: u32,
        /// `STATUS_OK` for an ACK; any other `STATUS` code is a NACK with that reason.
        pub status: u32,
    }
}

/// Why a command or request was refused, or `Ok`. Carried as a `u32` on the wire.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[repr(u32)]
pub enum Status {
    /// Carried out (ACK).
    Ok = 0,
    /// The driver cannot do this (e.g. brakes on an arm without brakes).
    Unsupported = 1,
    /// The joint index does not exist on this device.
    UnknownJoint = 2,
    /// A value was NaN or infinite.
    NotFinite = 3,
    /// A value lies outside the joint's limits, or every way of reaching a pose needs a
    /// joint beyond its limits.
    BeyondLimits = 4,
    /// The position lies beyond the limb's reach.
    OutOfReach = 5,
    /// The device has not reported its calibration yet.
    NotCalibrated = 6,
    /// The link to the hardware is down.
    LinkDown = 7,
    /// The device is busy with something that cannot be interrupted.
    Busy = 8,
    /// The hardware did not answer in time.
    Timeout = 9,
    /// An argument is malformed (bad count, zero-length vector, parallel approach and
    /// orientation vectors, unknown kind, ...).
    InvalidArgument = 10,
    /// The arm is powered off: a motion command would not move it.
    PoweredOff = 11,
    /// The position is within reach but no configuration of the limb's joints holds the
    /// requested orientation (e.g. a 5-joint arm asked for a full 6-DOF pose).
    UnreachableOrientation = 12,
    /// Carried out, with a value clamped to the device's limit (e.g. a speed above the
    /// joint's maximum runs at the maximum). Counts as carried out
    /// ([`Status::is_carried_out`]).
    Clamped = 13,
    /// The motion this command started was cut short by another client's command (a new
    /// motion of the same joints, or a stop) before it finished: it did not complete.
    Preempted = 14,
    /// Another client holds the device (a control lease): commands and requests that
    /// change the device are refused until it releases it or its lease ends.
    Leased = 15,
    /// Carried out, with the orientation adjusted to the nearest one the limb's joints can
    /// hold (a 5-joint arm asked for a full pose; the limb state's
    /// `orientation_adjustment` says by how much). Counts as carried out
    /// ([`Status::is_carried_out`]).
    Adjusted = 16,
    /// The brakes are on: a motion of a braked joint (or of the limb) would not move it.
    Braked = 17,
    /// The gripper's store is full: STORE cannot take one more object.
    StoreFull = 18,
    /// Nothing is between the gripper's fingers: STORE has nothing to store.
    NothingToStore = 19,
    /// The gripper's store is empty: RETRIEVE has nothing to give back.
    NothingStored = 20,
    /// A joint trajectory is malformed or incomplete (no points, times not increasing,
    /// counts that do not match, a point never uploaded, a final velocity not zero):
    /// control_msgs' INVALID_GOAL.
    InvalidGoal = 21,
    /// A joint trajectory's start time lies further in the past than the device accepts,
    /// or every point of it is already past: control_msgs' OLD_HEADER_TIMESTAMP.
    OldTimestamp = 22,
    /// A joint trajectory asks a joint to move faster than the device can (the driver's
    /// log names the joint, the segment and the speeds): an invalid goal.
    TooFast = 23,
    /// A gripper motion ended with an object between the fingers (the break beams see
    /// it): the cause a gripper goal's result carries, `STALLED` when the fingers stopped
    /// on it short of the goal.
    ObjectPresent = 30,
    /// This gripper only opens fully or closes fully: a goal gap between the two is
    /// refused (the Pioneer's paddles).
    GapNotSettable = 31,
    /// This gripper has no effort (force) setting: a goal with a maximum effort is refused.
    EffortNotSettable = 32,
    /// This gripper moves at one speed: a goal with a speed is refused.
    SpeedNotSettable = 33,
    /// The path (LINE, PTP) would bring the arm into the floor or an obstacle: refused
    /// before it started (the limb state's `refused_at` says where).
    PathCollides = 34,
    /// The joints would jump on the way (the line passes a singularity or leaves the
    /// configuration it started in): refused before it started (`refused_at` says where).
    PathJumps = 35,
}

impl Status {
    /// Every status, in code order.
    pub const ALL: [Status; 30] = [
        Status::Ok,
        Status::Unsupported,
        Status::UnknownJoint,
        Status::NotFinite,
        Status::BeyondLimits,
        Status::OutOfReach,
        Status::NotCalibrated,
        Status::LinkDown,
        Status::Busy,
        Status::Timeout,
        Status::InvalidArgument,
        Status::PoweredOff,
        Status::UnreachableOrientation,
        Status::Clamped,
        Status::Preempted,
        Status::Leased,
        Status::Adjusted,
        Status::Braked,
        Status::StoreFull,
        Status::NothingToStore,
        Status::NothingStored,
        Status::InvalidGoal,
        Status::OldTimestamp,
        Status::TooFast,
        Status::ObjectPresent,
        Status::GapNotSettable,
        Status::EffortNotSettable,
        Status::SpeedNotSettable,
        Status::PathCollides,
        Status::PathJumps,
    ];

    /// The wire code.
    pub const fn code(self) -> u32 {
        self as u32
    }

    /// Its name as limber.h spells it without the prefix (`OK`, `OUT_OF_REACH`, ...), from
    /// the layout manifest: the same in every language.
    pub fn name(self) -> &'static str {
        STATUS_GROUP
            .constants
            .iter()
            .find(|c| c.value == i64::from(self.code()))
            .map_or("UNKNOWN", |c| c.name)
    }

    /// True for `Ok` only (carried out exactly as asked); see also
    /// [`Status::is_carried_out`].
    pub const fn is_ok(self) -> bool {
        matches!(self, Status::Ok)
    }

    /// True when the command was carried out: `Ok`, `Clamped` (carried out with a value
    /// clamped to the device's limit) or `Adjusted` (carried out with the orientation
    /// adjusted to one the joints can hold). Everything else is a refusal.
    pub const fn is_carried_out(self) -> bool {
        matches!(self, Status::Ok | Status::Clamped | Status::Adjusted)
    }

    /// A short human-readable reason.
    pub const fn describe(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::Unsupported => "unsupported by this device",
            Status::UnknownJoint => "unknown joint",
            Status::NotFinite => "value not finite",
            Status::BeyondLimits => "beyond the joint limits",
            Status::OutOfReach => "out of reach",
            Status::NotCalibrated => "not calibrated yet",
            Status::LinkDown => "link to the hardware is down",
            Status::Busy => "device busy",
            Status::Timeout => "hardware timeout",
            Status::InvalidArgument => "invalid argument",
            Status::PoweredOff => "powered off",
            Status::UnreachableOrientation => "orientation not attainable by this limb's joints",
            Status::Clamped => "ok, clamped to the limit",
            Status::Preempted => "preempted by another client",
            Status::Leased => "held by another client",
            Status::Adjusted => "ok, orientation adjusted",
            Status::Braked => "brakes on",
            Status::StoreFull => "the gripper's store is full",
            Status::NothingToStore => "nothing between the fingers to store",
            Status::NothingStored => "nothing stored to retrieve",
            Status::InvalidGoal => "invalid trajectory",
            Status::OldTimestamp => "the trajectory's start time is too old",
            Status::TooFast => "the trajectory is faster than the joints can move",
            Status::ObjectPresent => "an object is between the fingers",
            Status::GapNotSettable => "this gripper only opens or closes fully",
            Status::EffortNotSettable => "this gripper has no effort setting",
            Status::SpeedNotSettable => "this gripper has no speed setting",
            Status::PathCollides => "the path would hit the floor or an obstacle",
            Status::PathJumps => "the joints would jump on the way (a singularity)",
        }
    }
}

impl core::fmt::Display for Status {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.describe())
    }
}

impl TryFrom<u32> for Status {
    type Error = DecodeError;
    fn try_from(code: u32) -> Result<Self, DecodeError> {
        Status::ALL
            .iter()
            .find(|s| s.code() == code)
            .copied()
            .ok_or(DecodeError::UnknownCode {
                field: "status",
                value: code as i64,
            })
    }
}

/// Bits of [`StateHeader::flags`].
pub mod device_flag {
    /// The driver's link to the hardware is up.
    pub const LINK_UP: u32 = 1;
    /// The device's calibration is known (e.g. the Pioneer's ARMINFO arrived).
    pub const CALIBRATED: u32 = 2;
    /// The device is simulated or emulated, not hardware.
    pub const SIMULATED: u32 = 4;
    /// The hardware reported this device as absent (e.g. no arm fitted).
    pub const ABSENT: u32 = 8;
    /// A client holds the device with a control lease (see the `lease` channel).
    pub const LEASED: u32 = 16;
    /// Every defined bit.
    pub const ALL: u32 = LINK_UP | CALIBRATED | SIMULATED | ABSENT | LEASED;
}

pub(crate) const STATUS_GROUP: ConstantGroup = ConstantGroup {
    name: "STATUS",
    doc: "Status / reply codes: 0 = ok (ACK), anything else says why a command or request was refused",
    constants: &[
        Constant {
            name: "OK",
            value: 0,
            doc: "carried out (ACK)",
        },
        Constant {
            name: "UNSUPPORTED",
            value: 1,
            doc: "the driver cannot do this",
        },
        Constant {
            name: "UNKNOWN_JOINT",
            value: 2,
            doc: "the joint index does not exist",
        },
        Constant {
            name: "NOT_FINITE",
            value: 3,
            doc: "a value was NaN or infinite",
        },
        Constant {
            name: "BEYOND_LIMITS",
            value: 4,
            doc: "a value (or every solution for a pose) lies outside the joint limits",
        },
        Constant {
            name: "OUT_OF_REACH",
            value: 5,
            doc: "the position lies beyond the limb's reach",
        },
        Constant {
            name: "NOT_CALIBRATED",
            value: 6,
            doc: "calibration not known yet",
        },
        Constant {
            name: "LINK_DOWN",
            value: 7,
            doc: "the link to the hardware is down",
        },
        Constant {
            name: "BUSY",
            value: 8,
            doc: "device busy",
        },
        Constant {
            name: "TIMEOUT",
            value: 9,
            doc: "the hardware did not answer in time",
        },
        Constant {
            name: "INVALID_ARGUMENT",
            value: 10,
            doc: "malformed argument (e.g. parallel approach and orientation)",
        },
        Constant {
            name: "POWERED_OFF",
            value: 11,
            doc: "the arm is powered off",
        },
        Constant {
            name: "UNREACHABLE_ORIENTATION",
            value: 12,
            doc: "the orientation is not attainable by the limb's joints",
        },
        Constant {
            name: "CLAMPED",
            value: 13,
            doc: "carried out, a value clamped to the limit",
        },
        Constant {
            name: "PREEMPTED",
            value: 14,
            doc: "the motion was cut short by another client's command",
        },
        Constant {
            name: "LEASED",
            value: 15,
            doc: "another client holds the device",
        },
        Constant {
            name: "ADJUSTED",
            value: 16,
            doc: "carried out, the orientation adjusted to one the limb's joints can hold",
        },
        Constant {
            name: "BRAKED",
            value: 17,
            doc: "the brakes are on: release them before moving",
        },
        Constant {
            name: "STORE_FULL",
            value: 18,
            doc: "the gripper's store is full",
        },
        Constant {
            name: "NOTHING_TO_STORE",
            value: 19,
            doc: "nothing between the gripper's fingers to store",
        },
        Constant {
            name: "NOTHING_STORED",
            value: 20,
            doc: "the gripper's store is empty",
        },
        Constant {
            name: "INVALID_GOAL",
            value: 21,
            doc: "a joint trajectory is malformed or incomplete",
        },
        Constant {
            name: "OLD_TIMESTAMP",
            value: 22,
            doc: "a joint trajectory's start time is too far in the past",
        },
        Constant {
            name: "TOO_FAST",
            value: 23,
            doc: "a joint trajectory is faster than the joints can move",
        },
        Constant {
            name: "OBJECT_PRESENT",
            value: 30,
            doc: "a gripper motion ended with an object between the fingers (the break beams)",
        },
        Constant {
            name: "GAP_NOT_SETTABLE",
            value: 31,
            doc: "the gripper only opens or closes fully: no goal gap in between",
        },
        Constant {
            name: "EFFORT_NOT_SETTABLE",
            value: 32,
            doc: "the gripper has no effort setting",
        },
        Constant {
            name: "SPEED_NOT_SETTABLE",
            value: 33,
            doc: "the gripper has no speed setting",
        },
        Constant {
            name: "PATH_COLLIDES",
            value: 34,
            doc: "the path would hit the floor or an obstacle (the limb state's refused_at says where)",
        },
        Constant {
            name: "PATH_JUMPS",
            value: 35,
            doc: "the joints would jump on the way (the limb state's refused_at says where)",
        },
    ],
};

pub(crate) const DEVICE_FLAG_GROUP: ConstantGroup = ConstantGroup {
    name: "DEVICE_FLAG",
    doc: "Bits of StateHeader.flags",
    constants: &[
        Constant {
            name: "LINK_UP",
            value: 1,
            doc: "link to the hardware up",
        },
        Constant {
            name: "CALIBRATED",
            value: 2,
            doc: "calibration known",
        },
        Constant {
            name: "SIMULATED",
            value: 4,
            doc: "simulated or emulated device",
        },
        Constant {
            name: "ABSENT",
            value: 8,
            doc: "hardware reports the device absent",
        },
        Constant {
            name: "LEASED",
            value: 16,
            doc: "a client holds the device with a control lease",
        },
    ],
};

pub(crate) const LIMITS_GROUP: ConstantGroup = ConstantGroup {
    name: "LIMITS",
    doc: "Capacities of the fixed-size arrays",
    constants: &[Constant {
        name: "MAX_ACTUATORS",
        value: MAX_ACTUATORS as i64,
        doc: "actuators in one actuator array",
    }],
};

impl Vec3 {
    /// A vector from its components.
    pub const fn new(x: f64, y: f64, z: f64) -> Self {
        Vec3 { x, y, z }
    }

    /// True when every component is finite.
    pub fn is_finite(&self) -> bool {
        self.x.is_finite() && self.y.is_finite() && self.z.is_finite()
    }

    /// Euclidean length.
    pub fn norm(&self) -> f64 {
        (self.x * self.x + self.y * self.y + self.z * self.z).sqrt()
    }

    /// Components as an array.
    pub const fn to_array(self) -> [f64; 3] {
        [self.x, self.y, self.z]
    }
}

impl From<[f64; 3]> for Vec3 {
    fn from(a: [f64; 3]) -> Self {
        Vec3::new(a[0], a[1], a[2])
    }
}

impl Orientation3 {
    /// True when every component is finite.
    pub fn is_finite(&self) -> bool {
        self.roll.is_finite() && self.pitch.is_finite() && self.yaw.is_finite()
    }
}

impl Pose3 {
    /// True when every component is finite.
    pub fn is_finite(&self) -> bool {
        self.position.is_finite() && self.orientation.is_finite()
    }
}

impl Bbox3 {
    /// True when every component is finite.
    pub fn is_finite(&self) -> bool {
        self.width.is_finite() && self.length.is_finite() && self.height.is_finite()
    }
}

impl StateHeader {
    /// The status of the last applied command, decoded.
    pub fn last_status(&self) -> Result<Status, DecodeError> {
        Status::try_from(self.last_cmd.status)
    }

    /// True when the `LINK_UP` flag is set.
    pub fn link_up(&self) -> bool {
        self.flags & device_flag::LINK_UP != 0
    }
}

/// Checks that a value is finite, naming the field in the error.
pub(crate) fn finite(field: &'static str, v: f64) -> Result<f64, DecodeError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(DecodeError::not_finite(field))
    }
}

/// Checks that a vector is finite, naming the field in the error.
pub(crate) fn finite_vec(field: &'static str, v: Vec3) -> Result<Vec3, DecodeError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(DecodeError::not_finite(field))
    }
}
