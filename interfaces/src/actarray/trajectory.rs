//! Joint trajectories ([`JointTrajectory`]): control_msgs' FollowJointTrajectory goal as a
//! fixed-capacity value, its validation (one rule, for clients and drivers), its upload as
//! commands ([`JointTrajectory::commands`]) and its assembly on the driver's side
//! ([`TrajectoryUpload`]).
//!
//! # Why an upload of chunks, and why 64 points
//!
//! Every command of a device travels in one [`ActArrayCmdMsg`] (296 bytes), and a driver
//! keeps [`CMD_BUFFER`](crate::protocol) (256) of them per client slot for 66 slots: a
//! trajectory of 64 points of 32 joints with velocities and accelerations is ~50 kB, and
//! carried whole in that envelope it would cost every command of every client that much
//! shared memory (~850 MB per device). So a trajectory goes as a series of ordinary
//! commands: `TRAJ_CHUNK`s of up to 32 values of one field (times, or one joint's
//! positions, velocities or accelerations, or the tolerances), then one `TRAJ` with the
//! header that runs it. Each chunk has an outcome (and no result of its own,
//! [`Message::is_piece`](crate::Message::is_piece)). The largest upload (64 points, 32
//! joints, three fields) is 2 + 2 + 32·3·2 = 198 chunks: below the 256 outcomes a client may
//! miss between two looks (`OUTCOME_BUFFER`), so one upload does not overwrite another
//! client's outcome; a 6-joint arm's 64 positions go in 2 + 2 + 6·2 = 16. 64 points also
//! give each field of a joint a
//! `u64` bit mask of what arrived. At the Pioneer's servo pace (a full 6-joint update every
//! ~12 ms) 64 points at one every 50-100 ms are 3-6 s of motion; a longer path is several
//! trajectories, each replacing the last from its start time.

use thiserror::Error;

use super::wire::{ActArrayTrajChunkCmd, ActArrayTrajCmd};

use super::{ActArrayCommand, traj_field, traj_has};
use crate::common::{MAX_ACTUATORS, Status};

/// The most points of one trajectory (see the module's documentation for why).
pub const MAX_TRAJ_POINTS: usize = 64;

/// Values of one chunk.
pub(super) const CHUNK: usize = 32;

/// Why a joint trajectory is not acceptable (nothing runs).
#[derive(Debug, Clone, Copy, PartialEq, Error)]
pub enum TrajectoryError {
    /// No joints, or more than 32.
    #[error("a trajectory names 1 to {MAX_ACTUATORS} joints, not {0}")]
    JointCount(usize),
    /// A joint index beyond the array capacity.
    #[error("joint {0} is not a valid joint index (0 to 31)")]
    BadJoint(i64),
    /// A joint named twice.
    #[error("joint {0} is named twice")]
    DuplicateJoint(u8),
    /// No points, or more than [`MAX_TRAJ_POINTS`].
    #[error("a trajectory has 1 to {MAX_TRAJ_POINTS} points, not {0}")]
    PointCount(usize),
    /// A point's value list has the wrong length.
    #[error("point {point}: {field} has {got} values, the trajectory names {expected} joints")]
    ValueCount {
        /// The point.
        point: usize,
        /// Which values.
        field: &'static str,
        /// How many were given.
        got: usize,
        /// How many joints the trajectory names.
        expected: usize,
    },
    /// Velocities (or accelerations) given for some points but not all.
    #[error("point {point}: {field} must be given for every point or none")]
    Partial {
        /// The first point that differs from point 0.
        point: usize,
        /// Which values.
        field: &'static str,
    },
    /// Accelerations without velocities (quintic needs both).
    #[error("accelerations need velocities too")]
    AccelerationsWithoutVelocities,
    /// A value is NaN or infinite.
    #[error("point {point}: {field} is not finite")]
    NotFinite {
        /// The point (0 for tolerances and the goal time tolerance).
        point: usize,
        /// Which value.
        field: &'static str,
    },
    /// A point's time is negative or not after the previous one.
    #[error("point {point}: time {time} s is not after the previous point's {previous} s")]
    TimeNotIncreasing {
        /// The point.
        point: usize,
        /// Its time from start, s.
        time: f64,
        /// The previous point's (0 for the first).
        previous: f64,
    },
    /// A tolerance is negative (0 = not enforced).
    #[error("{field} of column {column} is {value}: a tolerance is 0 (not enforced) or positive")]
    BadTolerance {
        /// Path or goal tolerance.
        field: &'static str,
        /// The joint column.
        column: usize,
        /// The value.
        value: f64,
    },
    /// The last point's time is 0: the trajectory has no duration to move in.
    #[error("the last point's time is 0 s: a trajectory needs time to move")]
    NoDuration,
    /// The last point has a velocity that is not zero (the joints would not stop there).
    #[error("the last point's velocity of column {column} is {velocity}, not 0")]
    FinalVelocity {
        /// The joint column.
        column: usize,
        /// The velocity.
        velocity: f64,
    },
    /// An upload's `TRAJ` came before some of the values it names (or from another
    /// client, or after a chunk of another client replaced the upload).
    #[error("the upload is incomplete: {field} of point {point} (column {column}) never arrived")]
    Incomplete {
        /// The field.
        field: &'static str,
        /// The first missing point.
        point: usize,
        /// The joint column.
        column: usize,
    },
}

impl TrajectoryError {
    /// The status a driver answers for it.
    pub const fn status(&self) -> Status {
        match self {
            TrajectoryError::BadJoint(_) => Status::UnknownJoint,
            TrajectoryError::NotFinite { .. } => Status::NotFinite,
            _ => Status::InvalidGoal,
        }
    }
}

/// A joint trajectory: the joints it drives, up to [`MAX_TRAJ_POINTS`] points
/// (time from start, positions, optional velocities and accelerations), per-joint path and
/// goal tolerances, a goal time tolerance and a start time. The interpolation follows from
/// what the points give: positions only = linear, with velocities = cubic, with
/// accelerations too = quintic.
///
/// About 50 kB: keep one in a `Box` or a long-lived struct, not on a small stack.
#[derive(Clone)]
pub struct JointTrajectory {
    pub(super) joints: [u8; MAX_ACTUATORS],
    pub(super) joint_count: u8,
    pub(super) point_count: u8,
    pub(super) has: u32,
    pub(super) times: [f64; MAX_TRAJ_POINTS],
    pub(super) positions: [[f64; MAX_ACTUATORS]; MAX_TRAJ_POINTS],
    pub(super) velocities: [[f64; MAX_ACTUATORS]; MAX_TRAJ_POINTS],
    pub(super) accelerations: [[f64; MAX_ACTUATORS]; MAX_TRAJ_POINTS],
    pub(super) path_tolerance: [f64; MAX_ACTUATORS],
    pub(super) goal_tolerance: [f64; MAX_ACTUATORS],
    pub(super) goal_time_tolerance: f64,
    pub(super) start_ns: u64,
}

impl PartialEq for JointTrajectory {
    /// Equal when every valid value is (what lies beyond the counts is not compared).
    fn eq(&self, other: &Self) -> bool {
        let p = self.len();
        self.joints() == other.joints()
            && p == other.len()
            && self.has == other.has
            && self.times[..p] == other.times[..p]
            && (0..p).all(|i| {
                self.positions(i) == other.positions(i)
                    && self.velocities(i) == other.velocities(i)
                    && self.accelerations(i) == other.accelerations(i)
            })
            && self.path_tolerance() == other.path_tolerance()
            && self.goal_tolerance() == other.goal_tolerance()
            && self.goal_time_tolerance == other.goal_time_tolerance
            && self.start_ns == other.start_ns
    }
}

impl core::fmt::Debug for JointTrajectory {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("JointTrajectory")
            .field("joints", &self.joints())
            .field("points", &self.len())
            .field("interpolation", &self.interpolation())
            .field("duration", &self.duration())
            .field("start_ns", &self.start_ns)
            .finish_non_exhaustive()
    }
}

/// The interpolation between points.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interpolation {
    /// Positions only: straight lines (the velocity jumps at each point).
    Linear,
    /// Positions and velocities: cubic polynomials.
    Cubic,
    /// Positions, velocities and accelerations: quintic polynomials.
    Quintic,
}

impl JointTrajectory {
    /// An empty trajectory of these actarray joints (each column of a point is one of
    /// them, in this order), starting when it arrives, tolerances not enforced, the goal
    /// time tolerance the device's default.
    pub fn new(joints: &[u16]) -> Result<Box<Self>, TrajectoryError> {
        let mut t = Self::boxed();
        t.set_joints(joints)?;
        Ok(t)
    }

    /// Every field zero, on the heap.
    pub(super) fn boxed() -> Box<Self> {
        Box::new(JointTrajectory {
            joints: [0; MAX_ACTUATORS],
            joint_count: 0,
            point_count: 0,
            has: 0,
            times: [0.0; MAX_TRAJ_POINTS],
            positions: [[0.0; MAX_ACTUATORS]; MAX_TRAJ_POINTS],
            velocities: [[0.0; MAX_ACTUATORS]; MAX_TRAJ_POINTS],
            accelerations: [[0.0; MAX_ACTUATORS]; MAX_TRAJ_POINTS],
            path_tolerance: [0.0; MAX_ACTUATORS],
            goal_tolerance: [0.0; MAX_ACTUATORS],
            goal_time_tolerance: 0.0,
            start_ns: 0,
        })
    }

    pub(super) fn set_joints(&mut self, joints: &[u16]) -> Result<(), TrajectoryError> {
        if joints.is_empty() || joints.len() > MAX_ACTUATORS {
            return Err(TrajectoryError::JointCount(joints.len()));
        }
        for (i, &j) in joints.iter().enumerate() {
            if j as usize >= MAX_ACTUATORS {
                return Err(TrajectoryError::BadJoint(j.into()));
            }
            if joints[..i].contains(&j) {
                return Err(TrajectoryError::DuplicateJoint(j as u8));
            }
            self.joints[i] = j as u8;
        }
        self.joint_count = joints.len() as u8;
        Ok(())
    }

    /// Appends a point reached `time` s after the start: one position per joint, and
    /// optionally velocities and accelerations (every point the same fields). Checked here
    /// and again as a whole by [`JointTrajectory::validate`].
    pub fn push(
        &mut self,
        time: f64,
        positions: &[f64],
        velocities: Option<&[f64]>,
        accelerations: Option<&[f64]>,
    ) -> Result<(), TrajectoryError> {
        let i = self.point_count as usize;
        if i >= MAX_TRAJ_POINTS {
            return Err(TrajectoryError::PointCount(i + 1));
        }
        let n = self.joint_count as usize;
        let has = (u32::from(velocities.is_some()) * traj_has::VELOCITIES)
            | (u32::from(accelerations.is_some()) * traj_has::ACCELERATIONS);
        if i > 0 && has != self.has {
            let field = if (has ^ self.has) & traj_has::VELOCITIES != 0 {
                "velocities"
            } else {
                "accelerations"
            };
            return Err(TrajectoryError::Partial { point: i, field });
        }
        for (field, values) in [
            ("positions", Some(positions)),
            ("velocities", velocities),
            ("accelerations", accelerations),
        ] {
            if let Some(v) = values
                && v.len() != n
            {
                return Err(TrajectoryError::ValueCount {
                    point: i,
                    field,
                    got: v.len(),
                    expected: n,
                });
            }
        }
        self.has = has;
        self.times[i] = time;
        self.positions[i][..n].copy_from_slice(positions);
        if let Some(v) = velocities {
            self.velocities[i][..n].copy_from_slice(v);
        }
        if let Some(a) = accelerations {
            self.accelerations[i][..n].copy_from_slice(a);
        }
        self.point_count += 1;
        let checked = self.check_point(i);
        if checked.is_err() {
            self.point_count -= 1;
        }
        checked
    }

    /// Per-joint path tolerances (one per joint column; 0 = not enforced).
    pub fn set_path_tolerance(&mut self, tolerances: &[f64]) -> Result<(), TrajectoryError> {
        self.set_tolerance("path tolerance", tolerances, true)
    }

    /// Per-joint goal tolerances (one per joint column; 0 = not enforced).
    pub fn set_goal_tolerance(&mut self, tolerances: &[f64]) -> Result<(), TrajectoryError> {
        self.set_tolerance("goal tolerance", tolerances, false)
    }

    fn set_tolerance(
        &mut self,
        field: &'static str,
        tolerances: &[f64],
        path: bool,
    ) -> Result<(), TrajectoryError> {
        let n = self.joint_count as usize;
        if tolerances.len() != n {
            return Err(TrajectoryError::ValueCount {
                point: 0,
                field,
                got: tolerances.len(),
                expected: n,
            });
        }
        check_tolerance(field, tolerances)?;
        let dst = if path {
            &mut self.path_tolerance
        } else {
            &mut self.goal_tolerance
        };
        dst[..n].copy_from_slice(tolerances);
        Ok(())
    }

    /// The time after the last point's within which the joints must come within their goal
    /// tolerance, s (0: the device's default).
    pub fn set_goal_time_tolerance(&mut self, seconds: f64) -> Result<(), TrajectoryError> {
        if !seconds.is_finite() {
            return Err(TrajectoryError::NotFinite {
                point: 0,
                field: "goal time tolerance",
            });
        }
        if seconds < 0.0 {
            return Err(TrajectoryError::BadTolerance {
                field: "goal time tolerance",
                column: 0,
                value: seconds,
            });
        }
        self.goal_time_tolerance = seconds;
        Ok(())
    }

    /// The `CLOCK_MONOTONIC` time (ns) the point times count from; 0 = when it arrives.
    pub fn set_start_ns(&mut self, start_ns: u64) {
        self.start_ns = start_ns;
    }

    /// The actarray joints, one per column.
    pub fn joints(&self) -> &[u8] {
        &self.joints[..self.joint_count as usize]
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.point_count as usize
    }

    /// True without points.
    pub fn is_empty(&self) -> bool {
        self.point_count == 0
    }

    /// Point `i`'s time from start, s.
    pub fn time(&self, i: usize) -> f64 {
        self.times[i]
    }

    /// Point `i`'s positions (one per column).
    pub fn positions(&self, i: usize) -> &[f64] {
        &self.positions[i][..self.joint_count as usize]
    }

    /// Point `i`'s velocities (zeros when the trajectory gives none).
    pub fn velocities(&self, i: usize) -> &[f64] {
        &self.velocities[i][..self.joint_count as usize]
    }

    /// Point `i`'s accelerations (zeros when the trajectory gives none).
    pub fn accelerations(&self, i: usize) -> &[f64] {
        &self.accelerations[i][..self.joint_count as usize]
    }

    /// The interpolation its points call for.
    pub fn interpolation(&self) -> Interpolation {
        if self.has & traj_has::ACCELERATIONS != 0 {
            Interpolation::Quintic
        } else if self.has & traj_has::VELOCITIES != 0 {
            Interpolation::Cubic
        } else {
            Interpolation::Linear
        }
    }

    /// Per-column path tolerances (0 = not enforced).
    pub fn path_tolerance(&self) -> &[f64] {
        &self.path_tolerance[..self.joint_count as usize]
    }

    /// Per-column goal tolerances (0 = not enforced).
    pub fn goal_tolerance(&self) -> &[f64] {
        &self.goal_tolerance[..self.joint_count as usize]
    }

    /// The goal time tolerance, s (0: the device's default).
    pub fn goal_time_tolerance(&self) -> f64 {
        self.goal_time_tolerance
    }

    /// The start time, `CLOCK_MONOTONIC` ns (0 = when it arrives).
    pub fn start_ns(&self) -> u64 {
        self.start_ns
    }

    /// The last point's time from start, s.
    pub fn duration(&self) -> f64 {
        self.point_count
            .checked_sub(1)
            .map_or(0.0, |i| self.times[i as usize])
    }

    fn check_point(&self, i: usize) -> Result<(), TrajectoryError> {
        let n = self.joint_count as usize;
        let t = self.times[i];
        if !t.is_finite() {
            return Err(TrajectoryError::NotFinite {
                point: i,
                field: "time",
            });
        }
        let previous = if i == 0 { 0.0 } else { self.times[i - 1] };
        if t < 0.0 || (i > 0 && t <= previous) {
            return Err(TrajectoryError::TimeNotIncreasing {
                point: i,
                time: t,
                previous,
            });
        }
        for (field, v) in [
            ("positions", &self.positions[i][..n]),
            ("velocities", &self.velocities[i][..n]),
            ("accelerations", &self.accelerations[i][..n]),
        ] {
            if v.iter().any(|x| !x.is_finite()) {
                return Err(TrajectoryError::NotFinite { point: i, field });
            }
        }
        Ok(())
    }

    fn check_tolerances(&self) -> Result<(), TrajectoryError> {
        let n = self.joint_count as usize;
        for (field, v) in [
            ("path tolerance", &self.path_tolerance[..n]),
            ("goal tolerance", &self.goal_tolerance[..n]),
        ] {
            check_tolerance(field, v)?;
        }
        Ok(())
    }

    /// Checks the whole trajectory: joints, points, every value finite, times strictly
    /// increasing from 0, tolerances, a final velocity of zero.
    pub fn validate(&self) -> Result<(), TrajectoryError> {
        let n = self.joint_count as usize;
        if n == 0 || n > MAX_ACTUATORS {
            return Err(TrajectoryError::JointCount(n));
        }
        for (i, &j) in self.joints().iter().enumerate() {
            if j as usize >= MAX_ACTUATORS {
                return Err(TrajectoryError::BadJoint(j.into()));
            }
            if self.joints[..i].contains(&j) {
                return Err(TrajectoryError::DuplicateJoint(j));
            }
        }
        let p = self.point_count as usize;
        if p == 0 || p > MAX_TRAJ_POINTS {
            return Err(TrajectoryError::PointCount(p));
        }
        if self.has & !(traj_has::VELOCITIES | traj_has::ACCELERATIONS) != 0 {
            return Err(TrajectoryError::Partial {
                point: 0,
                field: "fields",
            });
        }
        if self.has == traj_has::ACCELERATIONS {
            return Err(TrajectoryError::AccelerationsWithoutVelocities);
        }
        for i in 0..p {
            self.check_point(i)?;
        }
        self.check_tolerances()?;
        if !self.goal_time_tolerance.is_finite() {
            return Err(TrajectoryError::NotFinite {
                point: 0,
                field: "goal time tolerance",
            });
        }
        if self.goal_time_tolerance < 0.0 {
            return Err(TrajectoryError::BadTolerance {
                field: "goal time tolerance",
                column: 0,
                value: self.goal_time_tolerance,
            });
        }
        if self.times[p - 1] <= 0.0 {
            return Err(TrajectoryError::NoDuration);
        }
        for (column, &velocity) in self.velocities[p - 1][..n].iter().enumerate() {
            if velocity != 0.0 {
                return Err(TrajectoryError::FinalVelocity { column, velocity });
            }
        }
        Ok(())
    }

    /// The commands that upload it and run it, in order: the tolerances, the times, each
    /// column's positions (then velocities, accelerations), and last the `TRAJ` that runs
    /// it (whose ticket is the trajectory's). Validates first.
    pub fn commands(&self) -> Result<Vec<ActArrayCommand>, TrajectoryError> {
        self.validate()?;
        let n = self.joint_count as usize;
        let p = self.point_count as usize;
        let mut out = Vec::new();
        let mut chunk = |field: u16, column: usize, first: usize, values: &[f64]| {
            let mut c = ActArrayTrajChunkCmd {
                field,
                column: column as u16,
                first: first as u16,
                count: values.len() as u16,
                ..Default::default()
            };
            c.values[..values.len()].copy_from_slice(values);
            out.push(ActArrayCommand::TrajChunk(c));
        };
        chunk(traj_field::PATH_TOLERANCE, 0, 0, &self.path_tolerance[..n]);
        chunk(traj_field::GOAL_TOLERANCE, 0, 0, &self.goal_tolerance[..n]);
        for first in (0..p).step_by(CHUNK) {
            let end = (first + CHUNK).min(p);
            chunk(traj_field::TIME, 0, first, &self.times[first..end]);
        }
        let mut column_values = [0.0; MAX_TRAJ_POINTS];
        for (field, has, table) in [
            (traj_field::POSITION, true, &self.positions),
            (
                traj_field::VELOCITY,
                self.has & traj_has::VELOCITIES != 0,
                &self.velocities,
            ),
            (
                traj_field::ACCELERATION,
                self.has & traj_has::ACCELERATIONS != 0,
                &self.accelerations,
            ),
        ] {
            if !has {
                continue;
            }
            for column in 0..n {
                for (v, row) in column_values[..p].iter_mut().zip(&table[..p]) {
                    *v = row[column];
                }
                for first in (0..p).step_by(CHUNK) {
                    let end = (first + CHUNK).min(p);
                    chunk(field, column, first, &column_values[first..end]);
                }
            }
        }
        let mut header = ActArrayTrajCmd {
            start_ns: self.start_ns,
            goal_time_tolerance: self.goal_time_tolerance,
            joint_count: n as u32,
            point_count: p as u32,
            fields: self.has,
            ..Default::default()
        };
        header.joints[..n].copy_from_slice(&self.joints[..n]);
        out.push(ActArrayCommand::Traj(header));
        Ok(out)
    }
}

/// Tolerances are finite and 0 (not enforced) or positive.
fn check_tolerance(field: &'static str, values: &[f64]) -> Result<(), TrajectoryError> {
    for (column, &value) in values.iter().enumerate() {
        if !value.is_finite() {
            return Err(TrajectoryError::NotFinite { point: 0, field });
        }
        if value < 0.0 {
            return Err(TrajectoryError::BadTolerance {
                field,
                column,
                value,
            });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::TrajectoryUpload;
    use super::*;
    use crate::message::Message;

    fn sample(n: usize, p: usize, vel: bool) -> Box<JointTrajectory> {
        let joints: Vec<u16> = (0..n as u16).collect();
        let mut t = JointTrajectory::new(&joints).unwrap();
        for i in 0..p {
            let pos: Vec<f64> = (0..n).map(|j| (i * 10 + j) as f64 * 0.01).collect();
            let v = vec![if i + 1 == p { 0.0 } else { 0.1 }; n];
            t.push((i + 1) as f64 * 0.1, &pos, vel.then_some(&v[..]), None)
                .unwrap();
        }
        t.set_path_tolerance(&vec![0.1; n]).unwrap();
        t.set_goal_tolerance(&vec![0.01; n]).unwrap();
        t.set_goal_time_tolerance(0.5).unwrap();
        t
    }

    fn upload(t: &JointTrajectory, client: u64, up: &mut TrajectoryUpload) -> JointTrajectory {
        let cmds = t.commands().unwrap();
        let mut raw = Default::default();
        for c in &cmds {
            c.write(&mut raw);
            let back = ActArrayCommand::read(&raw).unwrap();
            match back {
                ActArrayCommand::TrajChunk(c) => up.chunk(client, &c),
                ActArrayCommand::Traj(h) => return up.finish(client, &h).unwrap().clone(),
                other => panic!("unexpected {other:?}"),
            }
        }
        panic!("no TRAJ")
    }

    #[test]
    fn upload_round_trips_at_capacity() {
        let mut up = TrajectoryUpload::new();
        for (n, p, vel) in [(1, 1, false), (6, 64, true), (32, 64, true), (5, 33, false)] {
            let t = sample(n, p, vel);
            let cmds = t.commands().unwrap();
            assert!(cmds.len() <= 256, "{} commands", cmds.len());
            assert!(upload(&t, 7, &mut up) == *t, "{n} joints, {p} points");
        }
    }

    #[test]
    fn an_incomplete_or_foreign_upload_is_refused() {
        let t = sample(3, 40, false);
        let cmds = t.commands().unwrap();
        let mut up = TrajectoryUpload::new();
        // One position chunk missing.
        for c in cmds.iter().filter(|c| {
            !matches!(c, ActArrayCommand::TrajChunk(c) if c.field == traj_field::POSITION && c.column == 1 && c.first == 32)
        }) {
            match c {
                ActArrayCommand::TrajChunk(c) => up.chunk(1, c),
                ActArrayCommand::Traj(h) => {
                    let e = up.finish(1, h).unwrap_err();
                    assert_eq!(
                        e,
                        TrajectoryError::Incomplete {
                            field: "position",
                            point: 32,
                            column: 1
                        }
                    );
                    assert_eq!(e.status(), Status::InvalidGoal);
                }
                _ => unreachable!(),
            }
        }
        // Another client's TRAJ does not run this client's chunks.
        for c in &cmds {
            match c {
                ActArrayCommand::TrajChunk(c) => up.chunk(1, c),
                ActArrayCommand::Traj(h) => assert!(up.finish(2, h).is_err()),
                _ => unreachable!(),
            }
        }
    }

    #[test]
    fn bad_trajectories_are_refused_with_the_reason() {
        assert_eq!(
            JointTrajectory::new(&[0, 0]).unwrap_err(),
            TrajectoryError::DuplicateJoint(0)
        );
        assert_eq!(
            JointTrajectory::new(&[40]).unwrap_err().status(),
            Status::UnknownJoint
        );
        let mut t = JointTrajectory::new(&[0, 1]).unwrap();
        t.push(1.0, &[0.0, 0.0], None, None).unwrap();
        let e = t.push(1.0, &[0.1, 0.1], None, None).unwrap_err();
        assert!(matches!(
            e,
            TrajectoryError::TimeNotIncreasing { point: 1, .. }
        ));
        let mut t = JointTrajectory::new(&[0, 1]).unwrap();
        assert_eq!(
            t.push(1.0, &[f64::NAN, 0.0], None, None)
                .unwrap_err()
                .status(),
            Status::NotFinite
        );
        let mut t = JointTrajectory::new(&[0]).unwrap();
        t.push(1.0, &[0.0], Some(&[0.5]), None).unwrap();
        assert!(matches!(
            t.validate().unwrap_err(),
            TrajectoryError::FinalVelocity { column: 0, .. }
        ));
        let mut t = JointTrajectory::new(&[0]).unwrap();
        t.push(0.0, &[0.1], None, None).unwrap();
        assert_eq!(t.validate().unwrap_err(), TrajectoryError::NoDuration);
        let t = JointTrajectory::new(&[0]).unwrap();
        assert_eq!(t.validate().unwrap_err(), TrajectoryError::PointCount(0));
        assert!(t.commands().is_err());
    }
}
