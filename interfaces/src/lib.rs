#![doc = include_str!("../README.md")]
#![warn(missing_docs)]

pub mod actarray;
pub mod codegen;
pub mod common;
pub mod control;
pub mod describe;
pub mod diagnostics;
pub mod error;
pub mod gripper;
pub mod interface;
pub mod limb;
pub mod limb_outcome;
pub mod manifest;
pub mod message;
pub mod protocol;
pub mod ranger;
pub mod reference;
pub mod wire;

pub use common::{
    Bbox3, CmdOutcome, MAX_ACTUATORS, MsgMeta, Orientation3, Pose3, ReplyMeta, StateHeader, Status,
    Vec3, device_flag,
};
pub use describe::Describe;
pub use error::{DecodeError, ValueError};
pub use interface::{
    ActArray, Gripper, HasHeader, Interface, InterfaceKind, InterfaceVisitor, Limb, Ranger,
    WireBytes,
};
pub use manifest::Manifest;
pub use message::{Envelope, Message, ReplyBody, ReplyEnvelope};
pub use wire::{WireField, WireStruct};

/// The layout version carried in every type name.
///
/// Version 2 added the `outcome` and `lease` channels ([`control::OutcomeMsg`],
/// [`control::LeaseReq`], [`control::LeaseReply`]), the statuses `PREEMPTED`, `LEASED` and
/// `ADJUSTED`, the limb state's `orientation_adjustment` and the limb's REACH request.
/// Version 3 added the `ranger` interface ([`ranger::RangerData`] and its envelopes), and
/// the motion results on the `outcome` channel ([`control::OutcomeMsg::result`],
/// [`control::MotionResult`]); every type name carries the version.
/// Version 4 added the actarray's joint trajectories (`TRAJ_CHUNK`, `TRAJ`, `TRAJ_SCALE`:
/// [`actarray::ActArrayTrajChunkCmd`], [`actarray::ActArrayTrajCmd`],
/// [`actarray::ActArrayTrajScaleCmd`]) and their feedback in the state
/// ([`actarray::TrajFeedback`]), the statuses `INVALID_GOAL`, `OLD_TIMESTAMP` and
/// `TOO_FAST`, and the results `PATH_TOLERANCE_VIOLATED` and `GOAL_TOLERANCE_VIOLATED`.
/// It also added the gripper's GOAL command ([`gripper::GripperGoalCmd`], a wider
/// [`gripper::GripperCmdMsg`]) and the statuses `OBJECT_PRESENT`, `GAP_NOT_SETTABLE`,
/// `EFFORT_NOT_SETTABLE` and `SPEED_NOT_SETTABLE`, and the limb's paths (LINE, PTP:
/// [`limb::LimbPathCmd`], a wider [`limb::LimbCmdMsg`]; the limb state's path fields) with
/// the statuses `PATH_COLLIDES` and `PATH_JUMPS`.
/// Version 5 added the `told` channel: each client's own outcomes, on a stream of its own
/// ([`protocol::TOLD_BUFFER`]); the `outcome` channel is for those who watch every outcome.
/// Version 6 added [`control::OutcomeMsg::also_outcome`]: a command whose result is decided
/// when the driver carries it out gets one sample, its result and its outcome at once.
pub const LAYOUT_VERSION: u32 = 6;

/// Everything a driver or client author needs, in one `use`.
pub mod prelude {
    pub use crate::actarray::{
        ActArrayCmdMsg, ActArrayCommand, ActArrayData, ActArrayGeom, ActArrayReply,
        ActArrayReplyMsg, ActArrayReqMsg, ActArrayRequest, ActArrayTrajChunkCmd, ActArrayTrajCmd,
        ActuatorFlags, ActuatorGeom, ActuatorKind, ActuatorState, JointSel, JointTrajectory,
        JointValues, MAX_TRAJ_POINTS, TrajFeedback, TrajectoryError, TrajectoryUpload,
    };
    pub use crate::common::{
        Bbox3, CmdOutcome, MAX_ACTUATORS, MsgMeta, Orientation3, Pose3, ReplyMeta, StateHeader,
        Status, Vec3, device_flag,
    };
    pub use crate::control::{LeaseReply, LeaseReq, MotionResult, OutcomeMsg, lease_op};
    pub use crate::describe::Describe;
    pub use crate::diagnostics::DriverStats;
    pub use crate::error::{DecodeError, ValueError};
    pub use crate::gripper::{
        GripperCmdMsg, GripperCommand, GripperData, GripperGeom, GripperReply, GripperReplyMsg,
        GripperReqMsg, GripperRequest, GripperState,
    };
    pub use crate::interface::{
        ActArray, Gripper, HasHeader, Interface, InterfaceKind, InterfaceVisitor, Limb, Ranger,
    };
    pub use crate::limb::{
        LimbCmdMsg, LimbCommand, LimbData, LimbGeom, LimbReach, LimbReply, LimbReplyMsg,
        LimbReqMsg, LimbRequest, LimbState,
    };
    pub use crate::message::{Envelope, Message, ReplyBody, ReplyEnvelope};
    pub use crate::ranger::{
        MAX_RANGES, RangerCmdMsg, RangerCommand, RangerData, RangerGeom, RangerReply,
        RangerReplyMsg, RangerReqMsg, RangerRequest,
    };
}

/// The layout manifest of the whole contract: every wire struct (dependencies first) and
/// every constant group.
pub fn manifest() -> Manifest {
    use crate::wire::WireStruct as _;
    use actarray::*;
    use common::*;
    use gripper::*;
    use limb::*;
    let structs = vec![
        Vec3::LAYOUT,
        Orientation3::LAYOUT,
        Pose3::LAYOUT,
        Bbox3::LAYOUT,
        CmdOutcome::LAYOUT,
        StateHeader::LAYOUT,
        MsgMeta::LAYOUT,
        ReplyMeta::LAYOUT,
        // actarray
        ActuatorState::LAYOUT,
        TrajFeedback::LAYOUT,
        ActArrayData::LAYOUT,
        ActArrayPositionCmd::LAYOUT,
        ActArrayMultiPositionCmd::LAYOUT,
        ActArraySpeedCmd::LAYOUT,
        ActArrayMultiSpeedCmd::LAYOUT,
        ActArrayHomeCmd::LAYOUT,
        ActArrayCurrentCmd::LAYOUT,
        ActArrayMultiCurrentCmd::LAYOUT,
        ActArrayTrajChunkCmd::LAYOUT,
        ActArrayTrajCmd::LAYOUT,
        ActArrayTrajScaleCmd::LAYOUT,
        ActArrayCmdMsg::LAYOUT,
        ActArrayPowerReq::LAYOUT,
        ActArrayBrakesReq::LAYOUT,
        ActArraySpeedReq::LAYOUT,
        ActArrayAccelReq::LAYOUT,
        ActArrayReqMsg::LAYOUT,
        ActuatorGeom::LAYOUT,
        ActArrayGeom::LAYOUT,
        ActArrayReplyMsg::LAYOUT,
        // limb
        LimbData::LAYOUT,
        LimbSetPoseCmd::LAYOUT,
        LimbSetPositionCmd::LAYOUT,
        LimbVecMoveCmd::LAYOUT,
        limb::LimbPathCmd::LAYOUT,
        LimbCmdMsg::LAYOUT,
        LimbPowerReq::LAYOUT,
        LimbBrakesReq::LAYOUT,
        LimbSpeedReq::LAYOUT,
        LimbReachReq::LAYOUT,
        LimbReqMsg::LAYOUT,
        LimbGeom::LAYOUT,
        LimbReach::LAYOUT,
        LimbReplyMsg::LAYOUT,
        // gripper
        GripperData::LAYOUT,
        gripper::GripperGoalCmd::LAYOUT,
        GripperCmdMsg::LAYOUT,
        GripperReqMsg::LAYOUT,
        GripperGeom::LAYOUT,
        GripperReplyMsg::LAYOUT,
        // ranger
        ranger::RangerData::LAYOUT,
        ranger::RangerCmdMsg::LAYOUT,
        ranger::RangerReqMsg::LAYOUT,
        ranger::RangerGeom::LAYOUT,
        ranger::RangerReplyMsg::LAYOUT,
        // diagnostics
        diagnostics::DriverStats::LAYOUT,
        // control (layout version 2)
        control::OutcomeMsg::LAYOUT,
        control::LeaseReq::LAYOUT,
        control::LeaseReply::LAYOUT,
    ];
    let mut constants = vec![
        common::LIMITS_GROUP,
        common::STATUS_GROUP,
        common::DEVICE_FLAG_GROUP,
    ];
    constants.extend_from_slice(actarray::GROUPS);
    constants.extend_from_slice(limb::GROUPS);
    constants.extend_from_slice(gripper::GROUPS);
    constants.extend_from_slice(ranger::GROUPS);
    constants.extend_from_slice(diagnostics::GROUPS);
    constants.push(control::LEASE_OP_GROUP);
    constants.push(control::RESULT_GROUP);
    constants.extend_from_slice(&[
        protocol::NAME_GROUP,
        protocol::WAKE_GROUP,
        protocol::NOTIFY_GROUP,
        protocol::QOS_GROUP,
    ]);
    let status_texts = Status::ALL
        .iter()
        .map(|s| manifest::StatusText {
            code: s.code(),
            text: s.describe(),
        })
        .collect();
    Manifest {
        layout_version: LAYOUT_VERSION,
        structs,
        constants,
        status_texts,
    }
}
