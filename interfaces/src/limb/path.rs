//! The limb's paths (limber's, issue 28): LINE, a straight line of the tool to a position
//! with a speed limit, its orientation kept or turned evenly to a given one (VECMOVE
//! generalised), and PTP, a point-to-point move (the joints interpolated) to a position
//! with the orientation kept or given. Both are checked whole before anything moves: a
//! path that leaves the reachable space or hits the world is refused, and the limb's state
//! says where ([`LimbData::refused_at`](super::LimbData::refused_at)).

use crate::common::Vec3;
use crate::error::{DecodeError, ValueError};
use crate::manifest::{Constant, ConstantGroup};
#[allow(unused_imports)]
use crate::wire::{ZeroCopySend, wire_struct};

wire_struct! {
    /// CMD LINE and CMD PTP: the goal and how to get there.
    pub struct LimbPathCmd : "limber.v6.LimbPathCmd", size = 88, align = 8 {
        /// Goal position of the tool, robot coordinates, m.
        pub position: Vec3,
        /// Goal approach vector (`LIMB_PATH_ORIENT_GIVEN`; ignored with `KEEP`).
        pub approach: Vec3,
        /// Goal orientation vector (`LIMB_PATH_ORIENT_GIVEN`; ignored with `KEEP`).
        pub orientation: Vec3,
        /// LINE: the tool's speed limit, m/s. PTP: the fastest joint's, rad/s (m/s for a
        /// linear joint). 0: the limb's own (its SPEED setting, else the joints'
        /// configured speeds).
        pub speed: f64,
        /// `LIMB_PATH_ORIENT` value.
        pub orient: u32,
        /// Reserved, zero.
        pub _pad: u32,
    }
}

/// [`LimbPathCmd::orient`] values.
pub mod path_orient {
    /// The tool keeps the orientation it has at the start.
    pub const KEEP: u32 = 0;
    /// The tool ends with the given approach and orientation (LINE: turned evenly along
    /// the way).
    pub const GIVEN: u32 = 1;
}

/// The tool's orientation along a path.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PathOrientation {
    /// Kept as it is at the start.
    Keep,
    /// The goal's (non-zero vectors).
    Given {
        /// Approach vector.
        approach: Vec3,
        /// Orientation vector.
        orientation: Vec3,
    },
}

/// A LINE's or a PTP's goal, validated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LimbPath {
    /// Goal position, m (finite).
    pub position: Vec3,
    /// The orientation.
    pub orientation: PathOrientation,
    /// The speed limit (finite, not negative; 0: the limb's own).
    pub speed: f64,
}

impl LimbPath {
    /// A path's goal, validated: a finite position, non-zero approach and orientation
    /// vectors when given, a finite speed not negative.
    pub fn new(
        position: Vec3,
        orientation: Option<(Vec3, Vec3)>,
        speed: f64,
    ) -> Result<Self, ValueError> {
        let position = super::point("position", position)?;
        let orientation = match orientation {
            None => PathOrientation::Keep,
            Some((a, o)) => PathOrientation::Given {
                approach: super::direction("approach", a)?,
                orientation: super::direction("orientation", o)?,
            },
        };
        if !speed.is_finite() {
            return Err(ValueError::NotFinite { field: "speed" });
        }
        if speed < 0.0 {
            return Err(ValueError::Negative { field: "speed" });
        }
        Ok(LimbPath {
            position,
            orientation,
            speed,
        })
    }

    pub(super) fn to_wire(self) -> LimbPathCmd {
        let (orient, approach, orientation) = match self.orientation {
            PathOrientation::Keep => (path_orient::KEEP, Vec3::default(), Vec3::default()),
            PathOrientation::Given {
                approach,
                orientation,
            } => (path_orient::GIVEN, approach, orientation),
        };
        LimbPathCmd {
            position: self.position,
            approach,
            orientation,
            speed: self.speed,
            orient,
            _pad: 0,
        }
    }

    pub(super) fn from_wire(c: &LimbPathCmd) -> Result<Self, DecodeError> {
        let given = match c.orient {
            path_orient::KEEP => None,
            path_orient::GIVEN => Some((c.approach, c.orientation)),
            v => {
                return Err(DecodeError::UnknownCode {
                    field: "path orientation",
                    value: v.into(),
                });
            }
        };
        Ok(LimbPath::new(c.position, given, c.speed)?)
    }
}

pub(crate) const PATH_ORIENT_GROUP: ConstantGroup = ConstantGroup {
    name: "LIMB_PATH_ORIENT",
    doc: "LimbPathCmd.orient values",
    constants: &[
        Constant {
            name: "KEEP",
            value: 0,
            doc: "the tool keeps its orientation",
        },
        Constant {
            name: "GIVEN",
            value: 1,
            doc: "the tool ends with the given approach and orientation (LINE: turned evenly)",
        },
    ],
};
