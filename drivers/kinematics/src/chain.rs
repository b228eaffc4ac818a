//! Generic serial chains: a limb described joint by joint the way Player's actarray
//! geometry describes it (type, origin offset, rest orientation, axis, limits, speed),
//! loaded from TOML, with forward kinematics and a numeric inverse
//! (Levenberg–Marquardt on the damped least-squares step, joint limits by projection
//! and an active set, deterministic random restarts).
//!
//! # Chain file format (TOML)
//!
//! ```toml
//! name = "arm6"
//! description = "optional text"
//! [base]                  # pose of the chain root in the robot frame (optional)
//! xyz = [0.0, 0.0, 0.0]   # metres
//! rpy = [0.0, 0.0, 0.0]   # roll, pitch, yaw (rad): R = Rz(yaw)·Ry(pitch)·Rx(roll)
//! [[joints]]              # one table per joint, root to tip (1..=16 joints)
//! name = "shoulder_pan"
//! type = "rotary"         # or "linear"
//! xyz = [0.0, 0.0, 0.089] # origin offset from the previous joint frame, m
//! rpy = [0.0, 0.0, 0.0]   # rest orientation relative to the previous frame, rad
//! axis = [0.0, 0.0, 1.0]  # joint axis in this joint's frame (normalised on load)
//! min = -3.14             # limits, rad or m
//! max = 3.14
//! max_speed = 3.15        # rad/s or m/s
//! home = 0.0              # optional; defaults to 0 clamped into the limits
//! [tool]                  # tool centre point in the last joint frame (optional)
//! xyz = [0.0, 0.0, 0.1]
//! rpy = [0.0, 0.0, 0.0]
//! [gripper]               # optional parallel gripper
//! stroke = 0.085          # total opening, m
//! max_speed = 0.1         # finger speed, m/s
//! max_force = 140.0       # optional, N
//! ```
//!
//! Frame i is `frame(i−1) · Trans(xyz_i) · Rot(rpy_i) · Motion_i(q_i)`, where the motion
//! is a rotation about `axis_i` (rotary) or a translation along it (linear). The tool
//! frame follows the last joint. FK poses are in the frame the `base` is given in.
//!
//! # Allocation
//!
//! Loading allocates (names, the joint list). FK, the Jacobian and [`Chain::ik`] do
//! not: they work on fixed-size stack arrays of [`MAX_JOINTS`] entries.

use std::ops::{Deref, DerefMut};
use std::path::Path;

use nalgebra::{Rotation3, SMatrix, Unit, Vector3, Vector6};
use rand::rngs::SmallRng;
use rand::{Rng as _, RngCore as _, SeedableRng};
use serde::Deserialize;

use super::pose::{Pose, all_finite};

/// Most joints a chain may have.
pub const MAX_JOINTS: usize = 16;

/// Kind of joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum JointKind {
    /// Revolute: the variable is an angle (rad) about the axis.
    Rotary,
    /// Prismatic: the variable is a displacement (m) along the axis.
    Linear,
}

/// One joint's geometry and limits.
#[derive(Clone, Debug, PartialEq)]
pub struct JointSpec {
    /// Name from the file.
    pub name: String,
    /// Rotary or linear.
    pub kind: JointKind,
    /// Offset of this joint's frame from the previous one, in the previous frame, m.
    pub origin: Vector3<f64>,
    /// Rest orientation of this joint's frame relative to the previous one.
    pub rest: Rotation3<f64>,
    /// Unit joint axis in this joint's frame.
    pub axis: Unit<Vector3<f64>>,
    /// Lower limit, rad or m.
    pub min: f64,
    /// Upper limit, rad or m.
    pub max: f64,
    /// Largest speed, rad/s or m/s (> 0).
    pub max_speed: f64,
    /// Home position, inside the limits.
    pub home: f64,
}

/// A parallel gripper at the tool.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GripperSpec {
    /// Total opening (finger travel), m.
    pub stroke: f64,
    /// Finger speed, m/s.
    pub max_speed: f64,
    /// Largest grip force, N, if known.
    pub max_force: Option<f64>,
}

/// A serial chain (see the module docs for the file format).
#[derive(Clone, Debug, PartialEq)]
pub struct Chain {
    name: String,
    description: String,
    base: Pose,
    joints: Vec<JointSpec>,
    tool: Pose,
    gripper: Option<GripperSpec>,
    reach: f64,
}

/// Why a chain could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum ChainLoadError {
    /// The file could not be read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The path.
        path: String,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The text is not valid TOML or does not match the format.
    #[error("chain file: {0}")]
    Parse(#[from] toml::de::Error),
    /// A value is out of range (`joint` names the joint, if any).
    #[error("invalid chain{}: {reason}", joint.as_ref().map(|j| format!(" (joint {j})")).unwrap_or_default())]
    Invalid {
        /// The joint concerned, if any.
        joint: Option<String>,
        /// What is wrong.
        reason: &'static str,
    },
}

/// Error of [`Chain::fk`] and the other per-configuration helpers.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum ChainFkError {
    /// The configuration has the wrong number of joints.
    #[error("expected {expected} joint values, got {got}")]
    WrongJointCount {
        /// The chain's joint count.
        expected: usize,
        /// The slice length given.
        got: usize,
    },
    /// A joint value is NaN or infinite.
    #[error("joint value is NaN or infinite")]
    NonFinite,
}

/// Why [`Chain::ik`] failed. Both [`ChainIkError::OutOfReach`] and
/// [`ChainIkError::NotConverged`] mean "the limb is out of reach" to a driver
/// ([`ChainIkError::is_out_of_reach`]).
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum ChainIkError {
    /// The seed has the wrong number of joints.
    #[error("expected {expected} joint values, got {got}")]
    WrongJointCount {
        /// The chain's joint count.
        expected: usize,
        /// The slice length given.
        got: usize,
    },
    /// The target or the seed contains NaN or an infinite value.
    #[error("input contains NaN or an infinite value")]
    NonFinite,
    /// A tolerance, weight or count in the options is invalid.
    #[error("invalid IK options")]
    InvalidOptions,
    /// The target is provably out of reach: its `distance` from the first joint's
    /// origin exceeds the chain's `reach` bound (sum of the link offsets and linear
    /// travel after the first joint).
    #[error("out of reach: {distance} m from the first joint, reach bound {reach} m")]
    OutOfReach {
        /// Distance from the first joint's origin, m.
        distance: f64,
        /// The reach bound, m.
        reach: f64,
    },
    /// No configuration inside the limits met the tolerances after every restart: the
    /// target is outside the reachable set within the limits, or the solver failed.
    /// The residuals are those of `best`, the configuration with the lowest cost.
    #[error("did not converge: residual {position_error} m, {orientation_error} rad")]
    NotConverged {
        /// Position residual of `best`, m.
        position_error: f64,
        /// Orientation residual of `best`, rad (0 for position targets).
        orientation_error: f64,
        /// The best configuration found (inside the limits).
        best: JointVec,
    },
}

impl ChainIkError {
    /// True for [`ChainIkError::OutOfReach`] and [`ChainIkError::NotConverged`].
    pub fn is_out_of_reach(&self) -> bool {
        matches!(self, Self::OutOfReach { .. } | Self::NotConverged { .. })
    }
}

/// A joint configuration of up to [`MAX_JOINTS`] values, on the stack. Dereferences
/// to a slice of its length.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointVec {
    len: usize,
    values: [f64; MAX_JOINTS],
}

impl JointVec {
    /// `n` zeros; `None` if `n > MAX_JOINTS`.
    pub fn zeros(n: usize) -> Option<Self> {
        (n <= MAX_JOINTS).then_some(Self {
            len: n,
            values: [0.0; MAX_JOINTS],
        })
    }

    /// A copy of `q`; `None` if it is longer than [`MAX_JOINTS`].
    pub fn from_slice(q: &[f64]) -> Option<Self> {
        let mut v = Self::zeros(q.len())?;
        v.values[..q.len()].copy_from_slice(q);
        Some(v)
    }

    /// The values.
    pub fn as_slice(&self) -> &[f64] {
        &self.values[..self.len]
    }

    /// The values, mutable.
    pub fn as_mut_slice(&mut self) -> &mut [f64] {
        &mut self.values[..self.len]
    }
}

impl Deref for JointVec {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        self.as_slice()
    }
}

impl DerefMut for JointVec {
    fn deref_mut(&mut self) -> &mut [f64] {
        self.as_mut_slice()
    }
}

/// What [`Chain::ik`] should reach.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum IkTarget {
    /// Tool position only (orientation free).
    Position(Vector3<f64>),
    /// Tool position and orientation.
    Pose(Pose),
}

/// Options of [`Chain::ik`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NumericIkOptions {
    /// Accepted position residual, m (1e-6).
    pub position_tolerance: f64,
    /// Accepted orientation residual, rad (1e-6), for pose targets.
    pub orientation_tolerance: f64,
    /// Weight of orientation against position in the least-squares cost, m/rad (0.5).
    pub orientation_weight: f64,
    /// Iterations per attempt (100).
    pub max_iterations: u32,
    /// Random restarts after the attempt from the seed (40).
    pub max_restarts: u32,
    /// Seed of the deterministic restart generator (same inputs, same answer).
    pub seed: u64,
}

impl Default for NumericIkOptions {
    fn default() -> Self {
        Self {
            position_tolerance: 1e-6,
            orientation_tolerance: 1e-6,
            orientation_weight: 0.5,
            max_iterations: 100,
            max_restarts: 40,
            seed: 0x5EED_1DEA_u64,
        }
    }
}

/// A solution of [`Chain::ik`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ChainSolution {
    /// The joint values, inside the limits.
    pub q: JointVec,
    /// Position residual, m.
    pub position_error: f64,
    /// Orientation residual, rad (0 for position targets).
    pub orientation_error: f64,
    /// Iterations used in total.
    pub iterations: u32,
    /// Random restarts used.
    pub restarts: u32,
}

/// A small deterministic generator (rand's `SmallRng`, seeded) for restarts, tests and
/// benchmarks: the same seed gives the same sequence.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DeterministicRng(SmallRng);

impl DeterministicRng {
    /// A generator from a seed.
    pub fn new(seed: u64) -> Self {
        Self(SmallRng::seed_from_u64(seed))
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0.next_u64()
    }

    /// Uniform in [0, 1).
    pub fn next_f64(&mut self) -> f64 {
        self.0.random()
    }

    /// Uniform in [lo, hi).
    pub fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.next_f64()
    }
}

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

const ARM6_TOML: &str = include_str!("../chains/arm6.toml");
const ARM7_TOML: &str = include_str!("../chains/arm7.toml");
const PIONEER5_TOML: &str = include_str!("../chains/pioneer5.toml");

type Jacobian = SMatrix<f64, 6, MAX_JOINTS>;

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
        Ok(Chain {
            name: file.name,
            description: file.description,
            base,
            joints,
            tool,
            gripper,
            reach,
        })
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

    /// The default limb: a 6-joint UR5-like arm (0.85 m reach) with a parallel
    /// gripper, embedded from `drivers/kinematics/chains/arm6.toml`.
    pub fn default_6dof() -> Chain {
        Self::from_toml_str(ARM6_TOML).expect("embedded arm6.toml is valid")
    }

    /// A 7-joint Panda-like arm with a parallel gripper, embedded from
    /// `drivers/kinematics/chains/arm7.toml`.
    pub fn default_7dof() -> Chain {
        Self::from_toml_str(ARM7_TOML).expect("embedded arm7.toml is valid")
    }

    /// The Pioneer 5-DOF arm as a generic chain (kinematic θ convention, relative to
    /// the arm base), embedded from `drivers/kinematics/chains/pioneer5.toml`.
    pub fn pioneer5() -> Chain {
        Self::from_toml_str(PIONEER5_TOML).expect("embedded pioneer5.toml is valid")
    }

    /// The chain's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The chain's description (may be empty).
    pub fn description(&self) -> &str {
        &self.description
    }

    /// Number of joints.
    pub fn dof(&self) -> usize {
        self.joints.len()
    }

    /// The joints, root to tip.
    pub fn joints(&self) -> &[JointSpec] {
        &self.joints
    }

    /// The chain root's pose in the robot frame.
    pub fn base(&self) -> &Pose {
        &self.base
    }

    /// The tool centre point in the last joint's frame.
    pub fn tool(&self) -> &Pose {
        &self.tool
    }

    /// The gripper, if the file describes one.
    pub fn gripper(&self) -> Option<&GripperSpec> {
        self.gripper.as_ref()
    }

    /// Upper bound on the distance from the first joint's origin to the tool, m.
    pub fn reach_bound(&self) -> f64 {
        self.reach
    }

    /// The home configuration.
    pub fn home(&self) -> JointVec {
        let mut q = JointVec::zeros(self.dof()).unwrap_or(JointVec {
            len: 0,
            values: [0.0; MAX_JOINTS],
        });
        for (v, j) in q.iter_mut().zip(&self.joints) {
            *v = j.home;
        }
        q
    }

    /// True when `q` has the right length and every value lies inside its limits.
    pub fn within_limits(&self, q: &[f64]) -> bool {
        q.len() == self.dof()
            && q.iter()
                .zip(&self.joints)
                .all(|(v, j)| *v >= j.min && *v <= j.max)
    }

    /// Clamps each value of `q` into its joint's limits (extra values are left alone).
    pub fn clamp_to_limits(&self, q: &mut [f64]) {
        for (v, j) in q.iter_mut().zip(&self.joints) {
            *v = v.clamp(j.min, j.max);
        }
    }

    /// A configuration drawn uniformly inside the limits (rotary joints whose range
    /// exceeds [−π, π] are drawn in [−π, π]).
    pub fn random_configuration(&self, rng: &mut DeterministicRng) -> JointVec {
        let mut q = self.home();
        for (v, j) in q.iter_mut().zip(&self.joints) {
            let (lo, hi) = sample_range(j);
            *v = rng.uniform(lo, hi);
        }
        q
    }

    /// Shortest time, s, to move every joint from `from` to `to` at its `max_speed`
    /// (the slowest joint decides; a synchronised move takes this long).
    pub fn min_travel_time(&self, from: &[f64], to: &[f64]) -> Result<f64, ChainFkError> {
        self.check_q(from)?;
        self.check_q(to)?;
        Ok(self
            .joints
            .iter()
            .zip(from.iter().zip(to))
            .map(|(j, (a, b))| (b - a).abs() / j.max_speed)
            .fold(0.0, f64::max))
    }

    fn check_q(&self, q: &[f64]) -> Result<(), ChainFkError> {
        if q.len() != self.dof() {
            return Err(ChainFkError::WrongJointCount {
                expected: self.dof(),
                got: q.len(),
            });
        }
        if !q.iter().all(|v| v.is_finite()) {
            return Err(ChainFkError::NonFinite);
        }
        Ok(())
    }

    /// Forward kinematics: the tool pose for `q` (in the frame the base is given in).
    pub fn fk(&self, q: &[f64]) -> Result<Pose, ChainFkError> {
        self.check_q(q)?;
        Ok(self.walk(q, |_, _, _| {}))
    }

    /// The frame of every joint after its motion (`frames[i]` for joint i), for
    /// drawing or collision checks; `frames` must hold at least `dof()` poses (extra
    /// entries are left alone). Returns the tool pose.
    pub fn fk_frames(&self, q: &[f64], frames: &mut [Pose]) -> Result<Pose, ChainFkError> {
        self.check_q(q)?;
        if frames.len() < self.dof() {
            return Err(ChainFkError::WrongJointCount {
                expected: self.dof(),
                got: frames.len(),
            });
        }
        Ok(self.walk(q, |i, _, after| frames[i] = *after))
    }

    /// Walks the chain; `visit(i, joint_frame_before_motion, frame_after_motion)`.
    fn walk(&self, q: &[f64], mut visit: impl FnMut(usize, &Pose, &Pose)) -> Pose {
        let mut r = self.base.rotation;
        let mut p = self.base.position;
        for (i, (j, v)) in self.joints.iter().zip(q).enumerate() {
            p += r * j.origin;
            r *= j.rest;
            let before = Pose::new(p, r);
            match j.kind {
                JointKind::Rotary => r *= Rotation3::from_axis_angle(&j.axis, *v),
                JointKind::Linear => p += r * (j.axis.into_inner() * *v),
            }
            visit(i, &before, &Pose::new(p, r));
        }
        p += r * self.tool.position;
        r *= self.tool.rotation;
        Pose::new(p, r)
    }

    /// Tool pose and the geometric Jacobian (rows: linear velocity, then angular
    /// velocity scaled by `w`; columns past `dof()` are zero).
    fn fk_jacobian(&self, q: &[f64], w: f64, jac: &mut Jacobian) -> Pose {
        let mut axes = [Vector3::zeros(); MAX_JOINTS];
        let mut points = [Vector3::zeros(); MAX_JOINTS];
        let tip = self.walk(q, |i, before, _| {
            axes[i] = before.rotation * self.joints[i].axis.into_inner();
            points[i] = before.position;
        });
        jac.fill(0.0);
        for (i, j) in self.joints.iter().enumerate() {
            let z = axes[i];
            let (lin, ang) = match j.kind {
                JointKind::Rotary => (z.cross(&(tip.position - points[i])), z * w),
                JointKind::Linear => (z, Vector3::zeros()),
            };
            jac.fixed_view_mut::<3, 1>(0, i).copy_from(&lin);
            jac.fixed_view_mut::<3, 1>(3, i).copy_from(&ang);
        }
        tip
    }

    /// Numeric IK: joint values inside the limits that bring the tool to `target`.
    /// The first attempt starts at `seed` (clamped into the limits), then up to
    /// `max_restarts` attempts start at deterministic random configurations. Each
    /// attempt is Levenberg–Marquardt on the damped least-squares step
    /// `Δq = Jᵀ(JJᵀ + λI)⁻¹e` with λ adapted to the cost, the step limited to 0.5 rad
    /// (or m) per joint, abandoned when the cost falls by less than 10 % in 10
    /// iterations, joints pushing against a limit frozen for that step, and the
    /// result clamped into the limits. No allocation.
    // The error carries the best configuration on the stack (136 bytes) so that a
    // failed solve does not allocate either.
    #[allow(clippy::result_large_err)]
    pub fn ik(
        &self,
        target: &IkTarget,
        seed: &[f64],
        options: &NumericIkOptions,
    ) -> Result<ChainSolution, ChainIkError> {
        let n = self.dof();
        if seed.len() != n {
            return Err(ChainIkError::WrongJointCount {
                expected: n,
                got: seed.len(),
            });
        }
        let (target_p, target_r) = match target {
            IkTarget::Position(p) => (*p, None),
            IkTarget::Pose(pose) => (pose.position, Some(pose.rotation)),
        };
        let finite_target = all_finite(&target_p)
            && target_r.is_none_or(|r| r.matrix().iter().all(|v| v.is_finite()));
        if !finite_target || !seed.iter().all(|v| v.is_finite()) {
            return Err(ChainIkError::NonFinite);
        }
        let pos = |v: f64| v.is_finite() && v > 0.0;
        if !(pos(options.position_tolerance)
            && pos(options.orientation_tolerance)
            && pos(options.orientation_weight)
            && options.max_iterations > 0)
        {
            return Err(ChainIkError::InvalidOptions);
        }
        // Reach bound from the first joint's origin, which no joint moves.
        let j0 = &self.joints[0];
        let first = self.base.position + self.base.rotation * j0.origin;
        let d = target_p - first;
        let distance = d.x.hypot(d.y).hypot(d.z);
        if distance > self.reach + options.position_tolerance {
            return Err(ChainIkError::OutOfReach {
                distance,
                reach: self.reach,
            });
        }

        let w = if target_r.is_some() {
            options.orientation_weight
        } else {
            0.0
        };
        let residual = |pose: &Pose| -> Vector6<f64> {
            let dp = target_p - pose.position;
            let dw = match target_r {
                Some(r) => (r * pose.rotation.inverse()).scaled_axis() * w,
                None => Vector3::zeros(),
            };
            Vector6::new(dp.x, dp.y, dp.z, dw.x, dw.y, dw.z)
        };
        let errors = |pose: &Pose| -> (f64, f64) {
            let pe = (target_p - pose.position).norm();
            let oe = match target_r {
                Some(r) => super::pose::angle_between_rotations(&r, &pose.rotation),
                None => 0.0,
            };
            (pe, oe)
        };
        let converged = |(pe, oe): (f64, f64)| {
            pe <= options.position_tolerance && oe <= options.orientation_tolerance
        };

        let mut rng = DeterministicRng::new(options.seed);
        let mut q = JointVec::from_slice(seed).ok_or(ChainIkError::WrongJointCount {
            expected: n,
            got: seed.len(),
        })?;
        self.clamp_to_limits(&mut q);
        let mut jac = Jacobian::zeros();
        let mut jac_new = Jacobian::zeros();
        let mut best_q = q;
        let mut best_cost = f64::INFINITY;
        let mut iterations = 0u32;
        for attempt in 0..=options.max_restarts {
            if attempt > 0 {
                q = self.random_configuration(&mut rng);
            }
            let mut pose = self.fk_jacobian(&q, w, &mut jac);
            let mut e = residual(&pose);
            let mut cost = e.norm_squared();
            let mut lambda = 1e-3;
            let mut checkpoint = cost;
            for it in 0..=options.max_iterations {
                // Stalled (less than 10 % progress in 10 iterations): restart.
                if it > 0 && it % 10 == 0 {
                    if cost > 0.9 * checkpoint {
                        break;
                    }
                    checkpoint = cost;
                }
                if !cost.is_finite() {
                    break;
                }
                if cost < best_cost {
                    best_cost = cost;
                    best_q = q;
                }
                let errs = errors(&pose);
                if converged(errs) {
                    return Ok(ChainSolution {
                        q,
                        position_error: errs.0,
                        orientation_error: errs.1,
                        iterations,
                        restarts: attempt,
                    });
                }
                if it == options.max_iterations {
                    break;
                }
                iterations += 1;
                let Some(mut dq) = dls_step(&jac, &e, lambda, n) else {
                    lambda *= 10.0;
                    continue;
                };
                // Freeze joints that sit on a limit and would be pushed beyond it.
                let mut frozen = false;
                let mut jf = jac;
                for (i, j) in self.joints.iter().enumerate() {
                    let out = (q[i] <= j.min && dq[i] < 0.0) || (q[i] >= j.max && dq[i] > 0.0);
                    if out {
                        jf.column_mut(i).fill(0.0);
                        frozen = true;
                    }
                }
                if frozen {
                    match dls_step(&jf, &e, lambda, n) {
                        Some(d) => dq = d,
                        None => {
                            lambda *= 10.0;
                            continue;
                        }
                    }
                }
                let biggest = dq.iter().take(n).fold(0.0_f64, |m, v| m.max(v.abs()));
                let scale = if biggest > 0.5 { 0.5 / biggest } else { 1.0 };
                let mut q_new = q;
                for (i, v) in q_new.iter_mut().enumerate() {
                    *v += dq[i] * scale;
                }
                self.clamp_to_limits(&mut q_new);
                let pose_new = self.fk_jacobian(&q_new, w, &mut jac_new);
                let e_new = residual(&pose_new);
                let cost_new = e_new.norm_squared();
                if cost_new < cost {
                    q = q_new;
                    pose = pose_new;
                    e = e_new;
                    cost = cost_new;
                    std::mem::swap(&mut jac, &mut jac_new);
                    lambda = (lambda * 0.3).max(1e-12);
                } else {
                    lambda *= 5.0;
                    if lambda > 1e6 {
                        break;
                    }
                }
            }
            if cost < best_cost {
                best_cost = cost;
                best_q = q;
            }
        }
        let pose = self.walk(&best_q, |_, _, _| {});
        let (position_error, orientation_error) = errors(&pose);
        if converged((position_error, orientation_error)) {
            return Ok(ChainSolution {
                q: best_q,
                position_error,
                orientation_error,
                iterations,
                restarts: options.max_restarts,
            });
        }
        Err(ChainIkError::NotConverged {
            position_error,
            orientation_error,
            best: best_q,
        })
    }
}

/// `Jᵀ (J Jᵀ + λ I)⁻¹ e` over the first `n` columns, `None` if the 6×6 system is not
/// positive definite. Plain loops and a hand-written Cholesky: small, allocation-free
/// and fast even in unoptimised builds.
#[allow(clippy::needless_range_loop)]
fn dls_step(
    jac: &Jacobian,
    e: &Vector6<f64>,
    lambda: f64,
    n: usize,
) -> Option<SMatrix<f64, MAX_JOINTS, 1>> {
    let mut a = [[0.0f64; 6]; 6];
    for (r, row) in a.iter_mut().enumerate() {
        for (c, cell) in row.iter_mut().enumerate().take(r + 1) {
            let mut sum = 0.0;
            for i in 0..n {
                sum += jac[(r, i)] * jac[(c, i)];
            }
            *cell = sum;
        }
        row[r] += lambda;
    }
    // Cholesky A = L·Lᵀ in place (lower triangle).
    for j in 0..6 {
        let mut d = a[j][j];
        for k in 0..j {
            d -= a[j][k] * a[j][k];
        }
        if !(d > 0.0 && d.is_finite()) {
            return None;
        }
        let d = d.sqrt();
        a[j][j] = d;
        for i in j + 1..6 {
            let mut v = a[i][j];
            for k in 0..j {
                v -= a[i][k] * a[j][k];
            }
            a[i][j] = v / d;
        }
    }
    let mut y = [0.0f64; 6];
    for i in 0..6 {
        let mut v = e[i];
        for k in 0..i {
            v -= a[i][k] * y[k];
        }
        y[i] = v / a[i][i];
    }
    for i in (0..6).rev() {
        let mut v = y[i];
        for k in i + 1..6 {
            v -= a[k][i] * y[k];
        }
        y[i] = v / a[i][i];
    }
    let mut dq = SMatrix::<f64, MAX_JOINTS, 1>::zeros();
    for i in 0..n {
        let mut v = 0.0;
        for (r, yr) in y.iter().enumerate() {
            v += jac[(r, i)] * yr;
        }
        dq[i] = v;
    }
    dq.iter().all(|v| v.is_finite()).then_some(dq)
}

fn sample_range(j: &JointSpec) -> (f64, f64) {
    use std::f64::consts::PI;
    if j.kind == JointKind::Rotary {
        let lo = j.min.max(-PI);
        let hi = j.max.min(PI);
        if lo < hi {
            return (lo, hi);
        }
    }
    (j.min, j.max)
}
