//! Paths of the tool, checked before anything moves (issue 28, item 3): a straight line of
//! the tool point ([`line()`]: the position interpolated, the orientation kept or
//! interpolated) and a point-to-point move ([`ptp`]: the joints interpolated). Each is
//! sampled; every sample must be reachable (the inverse kinematics within the limits,
//! without a jump of the joints between samples) and clear of the [`Scene`] (the floor and
//! the obstacle boxes); the first sample that is not is answered as a [`BadSample`]: where
//! (the tool point, the fraction of the path) and why. The samples of a good path are the
//! joint configurations a driver then runs, through its trajectory executor.
//!
//! The same [`Scene::contact`] is what a simulated arm stops at while it moves: one rule
//! for "collides", checked before a path and while any motion runs.
//!
//! Points, not link volumes: the origin of every joint frame after the first (the first
//! sits on the base) and the tool point.

use nalgebra::Vector3;

use crate::Pose;
use crate::chain::{
    Chain, ChainIkError, IkTarget, JointKind, JointVec, MAX_JOINTS, NumericIkOptions,
};
use crate::fit_angle_to_limits;

/// An obstacle: a box, axis-aligned in the chain's base frame (m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Box3 {
    /// The corner with the smallest x, y, z.
    pub min: [f64; 3],
    /// The corner with the largest x, y, z.
    pub max: [f64; 3],
}

impl Box3 {
    /// True when `p` lies strictly inside.
    pub fn contains(&self, p: [f64; 3]) -> bool {
        (0..3).all(|k| p[k] > self.min[k] && p[k] < self.max[k])
    }
}

/// What the arm can collide with (default: nothing).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Scene {
    /// The floor's height (m); `None`: no floor.
    pub floor: Option<f64>,
    /// The obstacles.
    pub boxes: Vec<Box3>,
}

/// What the arm touched.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Contact {
    /// The floor.
    Floor,
    /// Obstacle `i` of [`Scene::boxes`].
    Obstacle(usize),
}

impl core::fmt::Display for Contact {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Contact::Floor => f.write_str("the floor"),
            Contact::Obstacle(i) => write!(f, "obstacle {i}"),
        }
    }
}

impl Scene {
    /// True when there is nothing to collide with.
    pub fn is_empty(&self) -> bool {
        self.floor.is_none() && self.boxes.is_empty()
    }

    /// The first contact of `chain` at `q` (a joint frame after the first, or the tool
    /// point) with the floor or an obstacle; `None` when clear (or `q` is not a
    /// configuration of the chain).
    pub fn contact(&self, chain: &Chain, q: &[f64]) -> Option<Contact> {
        if self.is_empty() {
            return None;
        }
        let n = chain.dof();
        let mut frames = [Pose::identity(); MAX_JOINTS];
        let tool = chain.fk_frames(q, &mut frames[..n]).ok()?;
        let points = frames[1..n]
            .iter()
            .chain(core::iter::once(&tool))
            .map(|f| [f.position.x, f.position.y, f.position.z]);
        for p in points {
            if self.floor.is_some_and(|z| p[2] < z) {
                return Some(Contact::Floor);
            }
            if let Some(i) = self.boxes.iter().position(|b| b.contains(p)) {
                return Some(Contact::Obstacle(i));
            }
        }
        None
    }
}

/// Each rotary joint of `q` turned by whole turns to the angle nearest `seed` within its
/// limits; `None` when `q` is not within the limits after that.
pub fn nearest_turns(chain: &Chain, q: JointVec, seed: &[f64]) -> Option<JointVec> {
    let mut q = q;
    for ((v, j), s) in q.iter_mut().zip(chain.joints()).zip(seed) {
        if j.kind == JointKind::Rotary
            && let Some(w) = fit_angle_to_limits(*v, j.min, j.max, *s, 0.0)
        {
            *v = w;
        }
    }
    chain.within_limits(&q).then_some(q)
}

/// The tool's orientation along a [`line()`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Orientation {
    /// Kept as it is at the start (the goal's orientation is not used): VECMOVE's.
    Keep,
    /// Turned evenly (spherical interpolation) from the start's to the goal's.
    Interpolate,
}

/// How finely a path is sampled and checked.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PathOptions {
    /// The largest distance of the tool between two samples of a line, m.
    pub step: f64,
    /// The largest turn of the tool between two samples of a line, rad.
    pub turn_step: f64,
    /// The largest change of a joint between two samples of a point-to-point move, rad
    /// (or m).
    pub joint_step: f64,
    /// The largest change of a joint between two samples of a line that is still one
    /// motion (more: the inverse kinematics switched branches, the arm would swing).
    pub max_jump: f64,
    /// The most samples a path may have (the trajectory's points): a longer path is
    /// sampled more coarsely, never beyond it.
    pub max_samples: usize,
    /// The inverse kinematics' options.
    pub ik: NumericIkOptions,
}

impl Default for PathOptions {
    fn default() -> Self {
        PathOptions {
            step: 0.005,
            turn_step: 0.05,
            joint_step: 0.05,
            max_jump: 0.5,
            max_samples: 64,
            ik: NumericIkOptions::default(),
        }
    }
}

/// Why a sample of a path is bad.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum PathFault {
    /// No configuration of the joints puts the tool there (with that orientation).
    #[error("out of reach")]
    OutOfReach,
    /// The position is reachable, the orientation there is not.
    #[error("the orientation there is not attainable")]
    UnreachableOrientation,
    /// The only configurations lie beyond a joint's limits.
    #[error("beyond the joint limits")]
    BeyondLimits,
    /// The joints would jump between two samples (joint `joint` by `jump`): the line
    /// passes a singularity or leaves the branch it started on.
    #[error("joint {joint} would jump by {jump:.3} between two samples")]
    Jump {
        /// The joint.
        joint: usize,
        /// By how much, rad or m.
        jump: f64,
    },
    /// The arm would touch the floor or an obstacle.
    #[error("it would hit {0}")]
    Collision(Contact),
    /// The input is not usable (not finite, wrong joint count, a path too fine for
    /// `max_samples`).
    #[error("invalid path")]
    Invalid,
}

/// The first bad sample of a path: where, and why.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error(
    "refused at {:.0}% of the path, the tool at ({:.3}, {:.3}, {:.3}): {why}",
    fraction * 100.0, point.x, point.y, point.z
)]
pub struct BadSample {
    /// How far along the path, 0 (start) to 1 (goal).
    pub fraction: f64,
    /// The tool point there (the line's point; for a point-to-point move, where the
    /// interpolated joints put the tool), m.
    pub point: Vector3<f64>,
    /// Why.
    pub why: PathFault,
}

/// A path's samples: joint configurations from the first after the start to the goal.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Samples {
    /// The configurations (`q[k]` at fraction `(k + 1) / len`).
    pub q: Vec<JointVec>,
    /// The tool's distance between two samples (the line's), m; 0 for a point-to-point
    /// move.
    pub spacing: f64,
}

fn bad(fraction: f64, point: Vector3<f64>, why: PathFault) -> BadSample {
    BadSample {
        fraction,
        point,
        why,
    }
}

fn ik_fault(e: &ChainIkError, ik: &NumericIkOptions) -> PathFault {
    match *e {
        ChainIkError::NotConverged {
            position_error,
            orientation_error,
            ..
        } if position_error <= ik.position_tolerance
            && orientation_error > ik.orientation_tolerance =>
        {
            PathFault::UnreachableOrientation
        }
        ChainIkError::OutOfReach { .. } | ChainIkError::NotConverged { .. } => {
            PathFault::OutOfReach
        }
        _ => PathFault::Invalid,
    }
}

/// The largest |a − b| of two configurations, and its joint.
fn largest_change(a: &[f64], b: &[f64]) -> (usize, f64) {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .enumerate()
        .fold((0, 0.0), |m, (j, d)| if d > m.1 { (j, d) } else { m })
}

/// A straight line of the tool point from where `start` (the joints now) puts it to
/// `goal`'s position, the orientation kept or turned to `goal`'s: sampled at most
/// `options.step` apart (and `turn_step`, when it turns; coarser when that would take more
/// than `max_samples`), each sample solved from the one before (so the joints move
/// continuously), within the limits, without a jump, and clear of `scene`. The samples,
/// or the first bad one.
pub fn line(
    chain: &Chain,
    scene: &Scene,
    start: &[f64],
    goal: &Pose,
    orientation: Orientation,
    options: &PathOptions,
) -> Result<Samples, BadSample> {
    let from = chain
        .fk(start)
        .map_err(|_| bad(0.0, Vector3::zeros(), PathFault::Invalid))?;
    if !goal.is_finite() || options.max_samples == 0 {
        return Err(bad(0.0, from.position, PathFault::Invalid));
    }
    let travel = goal.position - from.position;
    let length = travel.norm();
    let turn = match orientation {
        Orientation::Keep => 0.0,
        Orientation::Interpolate => crate::angle_between_rotations(&from.rotation, &goal.rotation),
    };
    let by_length = (length / options.step.max(1e-9)).ceil();
    let by_turn = (turn / options.turn_step.max(1e-9)).ceil();
    let count = by_length
        .max(by_turn)
        .max(1.0)
        .min(options.max_samples as f64) as usize;
    let mut seed =
        JointVec::from_slice(start).ok_or_else(|| bad(0.0, from.position, PathFault::Invalid))?;
    let mut out = Vec::with_capacity(count);
    for k in 1..=count {
        let s = k as f64 / count as f64;
        let point = from.position + travel * s;
        let rotation = match orientation {
            Orientation::Keep => from.rotation,
            Orientation::Interpolate => from.rotation.slerp(&goal.rotation, s),
        };
        let target = IkTarget::Pose(Pose::new(point, rotation));
        let sol = chain
            .ik(&target, &seed, &options.ik)
            .map_err(|e| bad(s, point, ik_fault(&e, &options.ik)))?;
        let q = nearest_turns(chain, sol.q, &seed)
            .ok_or_else(|| bad(s, point, PathFault::BeyondLimits))?;
        let (joint, jump) = largest_change(&q, &seed);
        if jump > options.max_jump {
            return Err(bad(s, point, PathFault::Jump { joint, jump }));
        }
        if let Some(c) = scene.contact(chain, &q) {
            return Err(bad(s, point, PathFault::Collision(c)));
        }
        out.push(q);
        seed = q;
    }
    Ok(Samples {
        q: out,
        spacing: length / count as f64,
    })
}

/// A point-to-point move from `start` to `goal` (joint configurations): the joints
/// interpolated linearly, sampled at most `options.joint_step` apart (coarser when that
/// would take more than `max_samples`); `goal` within the limits (every sample then is),
/// every sample clear of `scene`. The samples, or the first bad one.
pub fn ptp(
    chain: &Chain,
    scene: &Scene,
    start: &[f64],
    goal: &[f64],
    options: &PathOptions,
) -> Result<Samples, BadSample> {
    let tool = |q: &[f64]| chain.fk(q).map(|p| p.position);
    let from = tool(start).map_err(|_| bad(0.0, Vector3::zeros(), PathFault::Invalid))?;
    let to = tool(goal).map_err(|_| bad(1.0, from, PathFault::Invalid))?;
    if options.max_samples == 0 {
        return Err(bad(0.0, from, PathFault::Invalid));
    }
    if !chain.within_limits(goal) {
        return Err(bad(1.0, to, PathFault::BeyondLimits));
    }
    let (_, widest) = largest_change(start, goal);
    let count = (widest / options.joint_step.max(1e-9))
        .ceil()
        .max(1.0)
        .min(options.max_samples as f64) as usize;
    let mut out = Vec::with_capacity(count);
    for k in 1..=count {
        let s = k as f64 / count as f64;
        let mut q = JointVec::from_slice(start).ok_or_else(|| bad(s, from, PathFault::Invalid))?;
        for (v, (a, b)) in q.iter_mut().zip(start.iter().zip(goal)) {
            *v = a + (b - a) * s;
        }
        let point = tool(&q).map_err(|_| bad(s, from, PathFault::Invalid))?;
        if let Some(c) = scene.contact(chain, &q) {
            return Err(bad(s, point, PathFault::Collision(c)));
        }
        out.push(q);
    }
    Ok(Samples {
        q: out,
        spacing: 0.0,
    })
}
