//! Generic serial chains: a limb described joint by joint the way Player's actarray
//! geometry describes it (type, origin offset, rest orientation, axis, limits, speed),
//! loaded from TOML, with forward kinematics and a numeric inverse
//! (Levenberg–Marquardt on the damped least-squares step, joint limits by projection
//! and an active set, restarts from the nearest of a set of configurations made at
//! load, then deterministic random ones).
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
//! Loading allocates (names, the joint list, the atlas of restart seeds). FK, the
//! Jacobian and [`Chain::ik`] do
//! not: they work on fixed-size stack arrays of [`MAX_JOINTS`] entries.

use std::ops::{Deref, DerefMut};

use nalgebra::{Matrix3, Rotation3, SMatrix, Unit, Vector3};
use rand::rngs::SmallRng;
use rand::{Rng as _, RngCore as _, SeedableRng};
use serde::Deserialize;

use crate::pose::{Pose, all_finite};

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
    /// Per joint: its rest orientation and axis in their cheapest form, for the walk.
    turns: Vec<(Turn, Axis)>,
    /// Restart seeds of [`Chain::ik`]: deterministic configurations and their tool
    /// poses, made at load.
    atlas: Vec<(JointVec, Pose)>,
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
    /// Restarts after the attempt from the seed (40): atlas seeds near the target
    /// first, then random configurations (see [`Chain::ik`]).
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
    /// Restarts used (atlas or random).
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
mod dls;
use dls::Gram;
mod file;
use file::{ARM6_TOML, ARM7_TOML, PIONEER5_TOML};
mod ik;
use ik::sample_range;
mod nearest;
pub use nearest::{NearestOptions, NearestSolution};
mod trig;
mod turn;
use turn::{Axis, Turn};

type Jacobian = SMatrix<f64, 6, MAX_JOINTS>;
impl Chain {
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
        Ok(self.walk(q, |i, p, r| {
            frames[i] = Pose::new(*p, Rotation3::from_matrix_unchecked(*r));
        }))
    }

    /// Walks the chain; `visit(i, position, rotation)` with joint i's frame after its
    /// motion. Returns the tool pose.
    #[inline]
    fn walk(&self, q: &[f64], mut visit: impl FnMut(usize, &Vector3<f64>, &Matrix3<f64>)) -> Pose {
        let (mut sin, mut cos) = ([0.0; MAX_JOINTS], [1.0; MAX_JOINTS]);
        trig::sin_cos_all(q, &mut sin, &mut cos);
        let mut r = *self.base.rotation.matrix();
        let mut p = self.base.position;
        for (i, ((j, (rest, axis)), v)) in self.joints.iter().zip(&self.turns).zip(q).enumerate() {
            p += r * j.origin;
            rest.apply(&mut r);
            match j.kind {
                JointKind::Rotary => axis.turn(&mut r, sin[i], cos[i]),
                JointKind::Linear => p += axis.in_frame(&r) * *v,
            }
            visit(i, &p, &r);
        }
        p += r * self.tool.position;
        r *= self.tool.rotation.matrix();
        Pose::new(p, Rotation3::from_matrix_unchecked(r))
    }
}
