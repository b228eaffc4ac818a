//! The three interfaces as types, so the services layer can be written once for all of
//! them: each names its state struct, its command, request and reply envelopes and their
//! typed views.

use core::fmt::Debug;

use iceoryx2_bb_elementary_traits::zero_copy_send::ZeroCopySend;

use crate::actarray::{
    ActArrayCmdMsg, ActArrayCommand, ActArrayData, ActArrayReply, ActArrayReplyMsg, ActArrayReqMsg,
    ActArrayRequest,
};
use crate::common::StateHeader;
use crate::gripper::{
    GripperCmdMsg, GripperCommand, GripperData, GripperReply, GripperReplyMsg, GripperReqMsg,
    GripperRequest,
};
use crate::limb::{
    LimbCmdMsg, LimbCommand, LimbData, LimbReply, LimbReplyMsg, LimbReqMsg, LimbRequest,
};
use crate::message::{Envelope, Message, ReplyBody, ReplyEnvelope};
use crate::wire::WireStruct;

/// The byte view of a wire struct: its fixed layout as bytes, both ways (what a bridge
/// carries over a network).
pub trait WireBytes:
    zerocopy::IntoBytes + zerocopy::FromBytes + zerocopy::Immutable + WireStruct
{
}
impl<T: zerocopy::IntoBytes + zerocopy::FromBytes + zerocopy::Immutable + WireStruct> WireBytes
    for T
{
}

/// Which interface a device offers.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum InterfaceKind {
    /// `actarray`.
    ActArray,
    /// `limb`.
    Limb,
    /// `gripper`.
    Gripper,
}

impl InterfaceKind {
    /// Every interface.
    pub const ALL: [InterfaceKind; 3] = [
        InterfaceKind::ActArray,
        InterfaceKind::Limb,
        InterfaceKind::Gripper,
    ];

    /// The name used in service names (`actarray`, `limb`, `gripper`).
    pub const fn name(self) -> &'static str {
        match self {
            InterfaceKind::ActArray => "actarray",
            InterfaceKind::Limb => "limb",
            InterfaceKind::Gripper => "gripper",
        }
    }

    /// The name with its indefinite article, for messages ("an actarray", "a limb").
    pub const fn with_article(self) -> &'static str {
        match self {
            InterfaceKind::ActArray => "an actarray",
            InterfaceKind::Limb => "a limb",
            InterfaceKind::Gripper => "a gripper",
        }
    }

    /// Player's interface code (53, 54, 3).
    pub const fn player_code(self) -> u16 {
        match self {
            InterfaceKind::ActArray => 53,
            InterfaceKind::Limb => 54,
            InterfaceKind::Gripper => 3,
        }
    }

    /// Parses a name as used in service names.
    pub fn from_name(s: &str) -> Option<Self> {
        InterfaceKind::ALL.into_iter().find(|k| k.name() == s)
    }
}

impl core::fmt::Display for InterfaceKind {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.write_str(self.name())
    }
}

/// Implemented by a payload type with a state header.
pub trait HasHeader {
    /// The header.
    fn header(&self) -> &StateHeader;
    /// The header, mutable.
    fn header_mut(&mut self) -> &mut StateHeader;
}

/// An interface: its state and the envelopes and typed views of its channels.
pub trait Interface: 'static {
    /// Which one.
    const KIND: InterfaceKind;
    /// The state (channel `data`).
    type Data: HasHeader + Default + Copy + Debug + ZeroCopySend + Send + WireBytes + 'static;
    /// The command envelope (channel `cmd`).
    type CmdMsg: Envelope + Debug + ZeroCopySend + WireBytes;
    /// The typed command.
    type Command: Message<Raw = Self::CmdMsg> + Debug;
    /// The request envelope (channel `req`).
    type ReqMsg: Envelope + Debug + ZeroCopySend + WireBytes;
    /// The typed request.
    type Request: Message<Raw = Self::ReqMsg> + Debug;
    /// The reply envelope (channel `req`).
    type ReplyMsg: ReplyEnvelope + Debug + ZeroCopySend + WireBytes;
    /// The typed payload of an ACK.
    type Reply: ReplyBody<Raw = Self::ReplyMsg> + Debug;
}

macro_rules! has_header {
    ($t:ty) => {
        impl HasHeader for $t {
            fn header(&self) -> &StateHeader {
                &self.header
            }
            fn header_mut(&mut self) -> &mut StateHeader {
                &mut self.header
            }
        }
    };
}
has_header!(ActArrayData);
has_header!(LimbData);
has_header!(GripperData);

/// The actuator-array interface.
#[derive(Debug, Clone, Copy)]
pub struct ActArray;
/// The limb interface.
#[derive(Debug, Clone, Copy)]
pub struct Limb;
/// The gripper interface.
#[derive(Debug, Clone, Copy)]
pub struct Gripper;

impl Interface for ActArray {
    const KIND: InterfaceKind = InterfaceKind::ActArray;
    type Data = ActArrayData;
    type CmdMsg = ActArrayCmdMsg;
    type Command = ActArrayCommand;
    type ReqMsg = ActArrayReqMsg;
    type Request = ActArrayRequest;
    type ReplyMsg = ActArrayReplyMsg;
    type Reply = ActArrayReply;
}

impl Interface for Limb {
    const KIND: InterfaceKind = InterfaceKind::Limb;
    type Data = LimbData;
    type CmdMsg = LimbCmdMsg;
    type Command = LimbCommand;
    type ReqMsg = LimbReqMsg;
    type Request = LimbRequest;
    type ReplyMsg = LimbReplyMsg;
    type Reply = LimbReply;
}

impl Interface for Gripper {
    const KIND: InterfaceKind = InterfaceKind::Gripper;
    type Data = GripperData;
    type CmdMsg = GripperCmdMsg;
    type Command = GripperCommand;
    type ReqMsg = GripperReqMsg;
    type Request = GripperRequest;
    type ReplyMsg = GripperReplyMsg;
    type Reply = GripperReply;
}
