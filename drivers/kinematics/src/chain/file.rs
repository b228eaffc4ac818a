//! Chain files: the TOML description of a chain, parsed and validated into a [`Chain`].

use std::path::Path;

use nalgebra::{Rotation3, Unit, Vector3};
use serde::Deserialize;

use super::*;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ChainFile {
    name: String,
    #[serde(default)]
    description: String,
    #[serde(default)]
    base: FrameFile,
    joints: Vec<JointFile>,
    #[serde(default)]
    tool: FrameFile,
    gripper: Option<GripperFile>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct FrameFile {
    #[serde(default)]
    xyz: [f64; 3],
    #[serde(default)]
    rpy: [f64; 3],
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JointFile {
    name: String,
    #[serde(rename = "type")]
    kind: JointKind,
    #[serde(default)]
    xyz: [f64; 3],
    #[serde(default)]
    rpy: [f64; 3],
    axis: [f64; 3],
    min: f64,
    max: f64,
    max_speed: f64,
    home: Option<f64>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct GripperFile {
    stroke: f64,
    max_speed: f64,
    max_force: Option<f64>,
}

fn frame(f: &FrameFile) -> Option<Pose> {
    let p = Vector3::from(f.xyz);
    if !(all_finite(&p) && f.rpy.iter().all(|v| v.is_finite())) {
        return None;
    }
    Some(Pose::new(
        p,
        Rotation3::from_euler_angles(f.rpy[0], f.rpy[1], f.rpy[2]),
    ))
}

pub(super) const ARM6_TOML: &str = include_str!("../../chains/arm6.toml");
pub(super) const ARM7_TOML: &str = include_str!("../../chains/arm7.toml");
pub(super) const PIONEER5_TOML: &str = include_str!("../../chains/pioneer5.toml");

impl Chain {
    /// Parses and validates a chain from TOML text.
    pub fn from_toml_str(text: &str) -> Result<Chain, ChainLoadError> {
        let file: ChainFile = toml::from_str(text)?;
        let invalid = |joint: Option<&str>, reason| ChainLoadError::Invalid {
            joint: joint.map(str::to_owned),
            reason,
        };
        if file.joints.is_empty() {
            return Err(invalid(None, "a chain needs at least one joint"));
        }
        if file.joints.len() > MAX_JOINTS {
            return Err(invalid(None, "more than MAX_JOINTS (16) joints"));
        }
        let base = frame(&file.base).ok_or_else(|| invalid(None, "base pose is not finite"))?;
        let tool = frame(&file.tool).ok_or_else(|| invalid(None, "tool pose is not finite"))?;
        let mut joints = Vec::with_capacity(file.joints.len());
        for j in &file.joints {
            let name = Some(j.name.as_str());
            let f = frame(&FrameFile {
                xyz: j.xyz,
                rpy: j.rpy,
            })
            .ok_or_else(|| invalid(name, "origin is not finite"))?;
            let axis = Vector3::from(j.axis);
            if !all_finite(&axis) || axis.norm() < 1e-9 {
                return Err(invalid(name, "axis must be finite and non-zero"));
            }
            if !(j.min.is_finite() && j.max.is_finite() && j.min <= j.max) {
                return Err(invalid(name, "limits must be finite with min <= max"));
            }
            if !(j.max_speed.is_finite() && j.max_speed > 0.0) {
                return Err(invalid(name, "max_speed must be finite and > 0"));
            }
            let home = j.home.unwrap_or(0.0_f64.clamp(j.min, j.max));
            if !(home.is_finite() && home >= j.min && home <= j.max) {
                return Err(invalid(name, "home must lie inside the limits"));
            }
            joints.push(JointSpec {
                name: j.name.clone(),
                kind: j.kind,
                origin: f.position,
                rest: f.rotation,
                axis: Unit::new_normalize(axis),
                min: j.min,
                max: j.max,
                max_speed: j.max_speed,
                home,
            });
        }
        let gripper = match file.gripper {
            None => None,
            Some(g) => {
                let pos = |v: f64| v.is_finite() && v > 0.0;
                if !(pos(g.stroke) && pos(g.max_speed) && g.max_force.is_none_or(pos)) {
                    return Err(invalid(None, "gripper stroke, speed and force must be > 0"));
                }
                Some(GripperSpec {
                    stroke: g.stroke,
                    max_speed: g.max_speed,
                    max_force: g.max_force,
                })
            }
        };
        let reach = joints.iter().skip(1).map(|j| j.origin.norm()).sum::<f64>()
            + tool.position.norm()
            + joints
                .iter()
                .filter(|j| j.kind == JointKind::Linear)
                .map(|j| j.min.abs().max(j.max.abs()))
                .sum::<f64>();
        let turns = joints
            .iter()
            .map(|j| (Turn::of(&j.rest), Axis::of(&j.axis)))
            .collect();
        let mut chain = Chain {
            name: file.name,
            description: file.description,
            base,
            joints,
            tool,
            gripper,
            reach,
            turns,
            atlas: Vec::new(),
        };
        chain.atlas = chain.make_atlas();
        Ok(chain)
    }

    /// Reads, parses and validates a chain file.
    pub fn from_file(path: impl AsRef<Path>) -> Result<Chain, ChainLoadError> {
        let path = path.as_ref();
        let text = std::fs::read_to_string(path).map_err(|source| ChainLoadError::Io {
            path: path.display().to_string(),
            source,
        })?;
        Self::from_toml_str(&text)
    }
}
