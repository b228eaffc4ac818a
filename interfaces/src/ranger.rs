//! `ranger`: a range sensor such as a planar laser scanner (Player's `ranger` interface 62,
//! which replaced `laser` 6).
//!
//! State: [`RangerData`], one scan: the ranges with the angle of each (the first at
//! `min_angle`, then every `angular_res`, counter-clockwise, in the sensor's frame), the
//! sensor's minimum and maximum range and range resolution, and optional intensities.
//! No commands (a sensor is read, not driven: [`RangerCommand`] has no value). Request
//! ([`RangerRequest`]): GET_GEOM, answered with [`RangerGeom`] (the sensor's pose on the
//! robot, its size and its configuration) in [`RangerReplyMsg`].

use crate::common::{Bbox3, MsgMeta, Pose3, ReplyMeta, StateHeader, Status};
use crate::error::{DecodeError, ValueError};
use crate::manifest::{Constant, ConstantGroup};
use crate::message::{self, Message, ReplyBody, envelope, reply_envelope};
#[allow(unused_imports)]
use crate::wire::{ZeroCopySend, wire_struct};

/// The most ranges in one scan (a SICK LMS200 at 0.5° over 180° gives 361).
pub const MAX_RANGES: usize = 361;

/// Request kinds (Player's `PLAYER_RANGER_REQ_*`).
pub mod req {
    /// Get the geometry.
    pub const GET_GEOM: u32 = 1;
}

wire_struct! {
    /// One scan (channel `data`). Range `i` was measured along the bearing
    /// `min_angle + i * angular_res` (rad, counter-clockwise from the sensor's x axis).
    pub struct RangerData : "limber.v6.RangerData", size = 5888, align = 8 {
        /// Common header.
        pub header: StateHeader,
        /// Bearing of the first range, rad.
        pub min_angle: f64,
        /// Bearing of the last range, rad.
        pub max_angle: f64,
        /// Angle between two ranges, rad.
        pub angular_res: f64,
        /// Shortest range the sensor measures, m.
        pub min_range: f64,
        /// Longest range the sensor measures, m (a beam that hits nothing reads this).
        pub max_range: f64,
        /// Range resolution, m.
        pub range_res: f64,
        /// Scans per second, Hz.
        pub frequency: f64,
        /// Valid entries of `ranges`.
        pub ranges_count: u32,
        /// Valid entries of `intensities` (0: the sensor gives none).
        pub intensities_count: u32,
        /// The ranges, m.
        pub ranges: [f64; 361],
        /// The intensities (sensor-specific units), when `intensities_count` > 0.
        pub intensities: [f64; 361],
    }
}

wire_struct! {
    /// The command envelope (channel `cmd`). A ranger has no command: every kind is
    /// refused as unknown.
    pub struct RangerCmdMsg : "limber.v6.RangerCmdMsg", size = 40, align = 8 {
        /// Sender, sequence, time, kind, body length.
        pub meta: MsgMeta,
        /// Reserved, zero.
        pub body: [u8; 8],
    }
}

wire_struct! {
    /// The request envelope (channel `req`). GET_GEOM has an empty body.
    pub struct RangerReqMsg : "limber.v6.RangerReqMsg", size = 40, align = 8 {
        /// Sender, sequence, time, kind, body length (0).
        pub meta: MsgMeta,
        /// Reserved, zero.
        pub body: [u8; 8],
    }
}

wire_struct! {
    /// The ranger's geometry and configuration (the GET_GEOM reply).
    pub struct RangerGeom : "limber.v6.RangerGeom", size = 136, align = 8 {
        /// Pose of the sensor in the robot frame (its x axis is bearing 0).
        pub pose: Pose3,
        /// The sensor's size, m.
        pub size: Bbox3,
        /// Bearing of the first range, rad.
        pub min_angle: f64,
        /// Bearing of the last range, rad.
        pub max_angle: f64,
        /// Angle between two ranges, rad.
        pub angular_res: f64,
        /// Shortest range, m.
        pub min_range: f64,
        /// Longest range, m.
        pub max_range: f64,
        /// Range resolution, m.
        pub range_res: f64,
        /// Scans per second, Hz.
        pub frequency: f64,
        /// Ranges in a scan.
        pub ranges_count: u32,
        /// Reserved, zero.
        pub _pad: u32,
    }
}

wire_struct! {
    /// The reply envelope (channel `req`).
    pub struct RangerReplyMsg : "limber.v6.RangerReplyMsg", size = 168, align = 8 {
        /// Client, sequence, time, kind, status.
        pub meta: ReplyMeta,
        /// `RangerGeom` for GET_GEOM.
        pub body: [u8; 136],
    }
}

envelope!(RangerCmdMsg);
envelope!(RangerReqMsg);
reply_envelope!(RangerReplyMsg);

/// A typed ranger command: there is none (a ranger is read, not commanded), so no value
/// of this type exists and every command on the wire is refused as unknown.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RangerCommand {}

impl Message for RangerCommand {
    type Raw = RangerCmdMsg;
    const CHANNEL: &'static str = "ranger command";

    fn kind(&self) -> u32 {
        match *self {}
    }

    fn write(&self, _: &mut RangerCmdMsg) {
        match *self {}
    }

    fn read(raw: &RangerCmdMsg) -> Result<Self, DecodeError> {
        Err(DecodeError::UnknownKind {
            channel: Self::CHANNEL,
            kind: raw.meta.kind,
        })
    }
}

/// A typed ranger request.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RangerRequest {
    /// Get the geometry and configuration.
    GetGeom,
}

impl Message for RangerRequest {
    type Raw = RangerReqMsg;
    const CHANNEL: &'static str = "ranger request";

    fn is_read_only(&self) -> bool {
        true
    }

    fn kind(&self) -> u32 {
        req::GET_GEOM
    }

    fn write(&self, raw: &mut RangerReqMsg) {
        raw.body.fill(0);
        raw.meta.kind = self.kind();
        raw.meta.body_len = 0;
    }

    fn read(raw: &RangerReqMsg) -> Result<Self, DecodeError> {
        match raw.meta.kind {
            req::GET_GEOM => {
                message::empty(Self::CHANNEL, req::GET_GEOM, raw.meta.body_len)?;
                Ok(RangerRequest::GetGeom)
            }
            k => Err(DecodeError::UnknownKind {
                channel: Self::CHANNEL,
                kind: k,
            }),
        }
    }
}

/// The payload of a ranger ACK.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum RangerReply {
    /// The geometry (GET_GEOM).
    Geom(RangerGeom),
}

impl ReplyBody for RangerReply {
    type Raw = RangerReplyMsg;

    fn write(kind: u32, reply: Result<&Self, Status>, raw: &mut RangerReplyMsg) {
        raw.meta.kind = kind;
        match reply {
            Ok(RangerReply::Geom(g)) => {
                raw.meta.status = Status::Ok.code();
                message::put(&mut raw.body, g);
            }
            Err(s) => {
                raw.meta.status = s.code();
                raw.body.fill(0);
            }
        }
    }

    fn read(raw: &RangerReplyMsg) -> Result<Result<Self, Status>, DecodeError> {
        let status = message::reply_status(&raw.meta)?;
        if !status.is_ok() {
            return Ok(Err(status));
        }
        match raw.meta.kind {
            req::GET_GEOM => {
                let g: RangerGeom = message::get(
                    "ranger reply",
                    req::GET_GEOM,
                    &raw.body,
                    core::mem::size_of::<RangerGeom>() as u32,
                )?;
                let numbers = [
                    g.min_angle,
                    g.max_angle,
                    g.angular_res,
                    g.min_range,
                    g.max_range,
                    g.range_res,
                    g.frequency,
                ];
                if !(g.pose.is_finite() && g.size.is_finite())
                    || numbers.iter().any(|v| !v.is_finite())
                {
                    return Err(DecodeError::not_finite("ranger geometry"));
                }
                Ok(Ok(RangerReply::Geom(g)))
            }
            k => Err(DecodeError::UnknownKind {
                channel: "ranger reply",
                kind: k,
            }),
        }
    }
}

impl RangerData {
    /// The valid ranges (cut to `ranges_count`, at most [`MAX_RANGES`]).
    pub fn ranges(&self) -> &[f64] {
        &self.ranges[..(self.ranges_count as usize).min(MAX_RANGES)]
    }

    /// The valid intensities (empty when the sensor gives none).
    pub fn intensities(&self) -> &[f64] {
        &self.intensities[..(self.intensities_count as usize).min(MAX_RANGES)]
    }

    /// The bearing of range `i`, rad, in the sensor's frame (Player's
    /// `GetMinAngle() + GetScanRes() * i`).
    pub fn bearing(&self, i: usize) -> f64 {
        self.min_angle + self.angular_res * i as f64
    }

    /// The point range `i` hit, (x, y) in the sensor's frame, m (Player's `GetPoint`).
    pub fn point(&self, i: usize) -> Option<[f64; 2]> {
        let r = *self.ranges().get(i)?;
        let b = self.bearing(i);
        Some([r * b.cos(), r * b.sin()])
    }

    /// Checks the counts and that the angles and range limits are finite.
    pub fn validate(&self) -> Result<(), DecodeError> {
        if self.ranges_count as usize > MAX_RANGES {
            return Err(ValueError::TooMany {
                field: "ranges_count",
                count: self.ranges_count as usize,
                max: MAX_RANGES,
            }
            .into());
        }
        if self.intensities_count as usize > MAX_RANGES {
            return Err(ValueError::TooMany {
                field: "intensities_count",
                count: self.intensities_count as usize,
                max: MAX_RANGES,
            }
            .into());
        }
        let numbers = [
            self.min_angle,
            self.max_angle,
            self.angular_res,
            self.min_range,
            self.max_range,
            self.range_res,
            self.frequency,
        ];
        if numbers.iter().any(|v| !v.is_finite()) {
            return Err(DecodeError::not_finite("ranger scan"));
        }
        Ok(())
    }
}

pub(crate) const GROUPS: &[ConstantGroup] = &[
    ConstantGroup {
        name: "RANGER_REQ",
        doc: "ranger request kinds (MsgMeta.kind on the req channel); a ranger has no command",
        constants: &[Constant {
            name: "GET_GEOM",
            value: 1,
            doc: "empty; reply RangerGeom",
        }],
    },
    ConstantGroup {
        name: "RANGER_LIMITS",
        doc: "capacity of RangerData's arrays",
        constants: &[Constant {
            name: "MAX_RANGES",
            value: MAX_RANGES as i64,
            doc: "ranges (and intensities) in one scan",
        }],
    },
];
