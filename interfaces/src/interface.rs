//! The interfaces as types, so the services layer can be written once for all of
//! them: each names its state struct, its command, request and reply envelopes and their
//! typed views.

use core::fmt::Debug;

use iceoryx2_bb_elementary_traits::zero_copy_send::ZeroCopySend;

use crate::actarray::{
    ActArrayCmdMsg, ActArrayCommand, ActArrayData, ActArrayGeom, ActArrayReply, ActArrayReplyMsg,
    ActArrayReqMsg, ActArrayRequest,
};
use crate::common::StateHeader;
use crate::describe::Describe;
use crate::gripper::{
    GripperCmdMsg, GripperCommand, GripperData, GripperGeom, GripperReply, GripperReplyMsg,
    GripperReqMsg, GripperRequest,
};
use crate::limb::{
    LimbCmdMsg, LimbCommand, LimbData, LimbGeom, LimbReply, LimbReplyMsg, LimbReqMsg, LimbRequest,
};
use crate::message::{Envelope, Message, ReplyBody, ReplyEnvelope};
use crate::ranger::{
    RangerCmdMsg, RangerCommand, RangerData, RangerGeom, RangerReply, RangerReplyMsg, RangerReqMsg,
    RangerRequest,
};
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
    /// `ranger`.
    Ranger,
}

impl InterfaceKind {
    /// Every interface.
    pub const ALL: [InterfaceKind; 4] = [
        InterfaceKind::ActArray,
        InterfaceKind::Limb,
        InterfaceKind::Gripper,
        InterfaceKind::Ranger,
    ];

    /// The name used in service names (`actarray`, `limb`, `gripper`, `ranger`).
    pub const fn name(self) -> &'static str {
        match self {
            InterfaceKind::ActArray => "actarray",
            InterfaceKind::Limb => "limb",
            InterfaceKind::Gripper => "gripper",
            InterfaceKind::Ranger => "ranger",
        }
    }

    /// The name with its indefinite article, for messages ("an actarray", "a limb").
    pub const fn with_article(self) -> &'static str {
        match self {
            InterfaceKind::ActArray => "an actarray",
            InterfaceKind::Limb => "a limb",
            InterfaceKind::Gripper => "a gripper",
            InterfaceKind::Ranger => "a ranger",
        }
    }

    /// Player's interface code (53, 54, 3, 62).
    pub const fn player_code(self) -> u16 {
        match self {
            InterfaceKind::ActArray => 53,
            InterfaceKind::Limb => 54,
            InterfaceKind::Gripper => 3,
            InterfaceKind::Ranger => 62,
        }
    }

    /// Parses a name as used in service names.
    pub fn from_name(s: &str) -> Option<Self> {
        InterfaceKind::ALL.into_iter().find(|k| k.name() == s)
    }

    /// Calls `visitor` with this kind's [`Interface`] type: the one place in limber where
    /// the kind is matched. Every generic consumer (a client of any device, the bridge, the
    /// CLI's `echo`, the C API) writes its per-interface code once, generic over
    /// `I: Interface`, and reaches it through here; a new interface is one arm below.
    pub fn visit<V: InterfaceVisitor>(self, visitor: V) -> V::Output {
        match self {
            InterfaceKind::ActArray => visitor.visit::<ActArray>(),
            InterfaceKind::Limb => visitor.visit::<Limb>(),
            InterfaceKind::Gripper => visitor.visit::<Gripper>(),
            InterfaceKind::Ranger => visitor.visit::<Ranger>(),
        }
    }
}

/// Code generic over the interface, called through [`InterfaceKind::visit`].
pub trait InterfaceVisitor {
    /// What the visit returns.
    type Output;
    /// The visit, with the interface as a type.
    fn visit<I: Interface>(self) -> Self::Output;
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
    type Data: HasHeader
        + Describe
        + Default
        + Copy
        + Debug
        + ZeroCopySend
        + Send
        + WireBytes
        + 'static;
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
    /// The device's geometry: the reply to [`Interface::GEOMETRY`].
    type Geom: Copy + Debug + WireBytes + 'static;
    /// The request that asks for the geometry.
    const GEOMETRY: Self::Request;
    /// The geometry in a reply (`None`: the reply is of another request).
    fn geometry_of(reply: Self::Reply) -> Option<Self::Geom>;
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
has_header!(RangerData);

/// The actuator-array interface.
#[derive(Debug, Clone, Copy)]
pub struct ActArray;
/// The limb interface.
#[derive(Debug, Clone, Copy)]
pub struct Limb;
/// The gripper interface.
#[derive(Debug, Clone, Copy)]
pub struct Gripper;
/// The ranger interface (a laser scanner).
#[derive(Debug, Clone, Copy)]
pub struct Ranger;

impl Interface for ActArray {
    const KIND: InterfaceKind = InterfaceKind::ActArray;
    type Data = ActArrayData;
    type CmdMsg = ActArrayCmdMsg;
    type Command = ActArrayCommand;
    type ReqMsg = ActArrayReqMsg;
    type Request = ActArrayRequest;
    type ReplyMsg = ActArrayReplyMsg;
    type Reply = ActArrayReply;
    type Geom = ActArrayGeom;
    const GEOMETRY: ActArrayRequest = ActArrayRequest::GetGeom;
    fn geometry_of(reply: ActArrayReply) -> Option<ActArrayGeom> {
        match reply {
            ActArrayReply::Geom(g) => Some(g),
            ActArrayReply::Done => None,
        }
    }
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
    type Geom = LimbGeom;
    const GEOMETRY: LimbRequest = LimbRequest::Geom;
    fn geometry_of(reply: LimbReply) -> Option<LimbGeom> {
        match reply {
            LimbReply::Geom(g) => Some(g),
            LimbReply::Done | LimbReply::Reach(_) => None,
        }
    }
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
    type Geom = GripperGeom;
    const GEOMETRY: GripperRequest = GripperRequest::GetGeom;
    fn geometry_of(reply: GripperReply) -> Option<GripperGeom> {
        match reply {
            GripperReply::Geom(g) => Some(g),
        }
    }
}

impl Interface for Ranger {
    const KIND: InterfaceKind = InterfaceKind::Ranger;
    type Data = RangerData;
    type CmdMsg = RangerCmdMsg;
    type Command = RangerCommand;
    type ReqMsg = RangerReqMsg;
    type Request = RangerRequest;
    type ReplyMsg = RangerReplyMsg;
    type Reply = RangerReply;
    type Geom = RangerGeom;
    const GEOMETRY: RangerRequest = RangerRequest::GetGeom;
    fn geometry_of(reply: RangerReply) -> Option<RangerGeom> {
        match reply {
            RangerReply::Geom(g) => Some(g),
        }
    }
}
