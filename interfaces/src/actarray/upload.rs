//! The driver's side of a joint trajectory's upload ([`TrajectoryUpload`]): the
//! `TRAJ_CHUNK`s of one client assembled into a [`JointTrajectory`] at its `TRAJ`, and
//! the checks of a chunk and a header as they are decoded.

use super::trajectory::CHUNK;
use super::wire::{ActArrayTrajChunkCmd, ActArrayTrajCmd};
use super::{JointTrajectory, MAX_TRAJ_POINTS, TrajectoryError, traj_field, traj_has};
use crate::common::MAX_ACTUATORS;

/// The driver's side of an upload: takes the `TRAJ_CHUNK`s of one client and, at its
/// `TRAJ`, the trajectory they make. One upload per device at a time: a chunk of another
/// client starts over (the first client's `TRAJ` is then refused as incomplete). Holds its
/// trajectory inline (~50 kB, allocated once).
#[derive(Debug)]
pub struct TrajectoryUpload {
    owner: u64,
    traj: Box<JointTrajectory>,
    times: u64,
    fields: [[u64; MAX_ACTUATORS]; 3],
    tolerances: u8,
}

impl Default for TrajectoryUpload {
    fn default() -> Self {
        Self::new()
    }
}

impl TrajectoryUpload {
    /// Empty.
    pub fn new() -> Self {
        TrajectoryUpload {
            owner: 0,
            traj: JointTrajectory::boxed(),
            times: 0,
            fields: [[0; MAX_ACTUATORS]; 3],
            tolerances: 0,
        }
    }

    fn clear(&mut self, owner: u64) {
        self.owner = owner;
        self.times = 0;
        self.fields = [[0; MAX_ACTUATORS]; 3];
        self.tolerances = 0;
    }

    /// Stores one chunk of client `client` (validated when it was decoded).
    pub fn chunk(&mut self, client: u64, c: &ActArrayTrajChunkCmd) {
        if client != self.owner {
            self.clear(client);
        }
        let (first, count, column) = (c.first as usize, c.count as usize, c.column as usize);
        let values = &c.values[..count];
        let mask = ((1u128 << count) - 1) as u64;
        let t = &mut *self.traj;
        match c.field {
            traj_field::TIME => {
                t.times[first..first + count].copy_from_slice(values);
                self.times |= mask << first;
            }
            traj_field::POSITION | traj_field::VELOCITY | traj_field::ACCELERATION => {
                let (k, table) = match c.field {
                    traj_field::POSITION => (0, &mut t.positions),
                    traj_field::VELOCITY => (1, &mut t.velocities),
                    _ => (2, &mut t.accelerations),
                };
                for (i, &v) in values.iter().enumerate() {
                    table[first + i][column] = v;
                }
                self.fields[k][column] |= mask << first;
            }
            traj_field::PATH_TOLERANCE => {
                t.path_tolerance[..count].copy_from_slice(values);
                self.tolerances |= 1;
            }
            _ => {
                t.goal_tolerance[..count].copy_from_slice(values);
                self.tolerances |= 2;
            }
        }
    }

    /// The trajectory the chunks of `client` make with this header, validated; the upload
    /// starts over either way.
    pub fn finish(
        &mut self,
        client: u64,
        h: &ActArrayTrajCmd,
    ) -> Result<&JointTrajectory, TrajectoryError> {
        let done = self.assemble(client, h);
        self.clear(0);
        done?;
        Ok(&self.traj)
    }

    fn assemble(&mut self, client: u64, h: &ActArrayTrajCmd) -> Result<(), TrajectoryError> {
        let (n, p) = (h.joint_count as usize, h.point_count as usize);
        if n == 0 || n > MAX_ACTUATORS {
            return Err(TrajectoryError::JointCount(n));
        }
        if p == 0 || p > MAX_TRAJ_POINTS {
            return Err(TrajectoryError::PointCount(p));
        }
        let want = if p == 64 { u64::MAX } else { (1u64 << p) - 1 };
        let missing = |have: u64, field: &'static str, column: usize| {
            if have & want == want {
                Ok(())
            } else {
                Err(TrajectoryError::Incomplete {
                    field,
                    point: (!have & want).trailing_zeros() as usize,
                    column,
                })
            }
        };
        let owner = if client == self.owner { u64::MAX } else { 0 };
        missing(self.times & owner, "time", 0)?;
        for (k, field, needed) in [
            (0, "position", true),
            (1, "velocity", h.fields & traj_has::VELOCITIES != 0),
            (2, "acceleration", h.fields & traj_has::ACCELERATIONS != 0),
        ] {
            if needed {
                for (column, &have) in self.fields[k][..n].iter().enumerate() {
                    missing(have & owner, field, column)?;
                }
            }
        }
        for (bit, field) in [(1, "path tolerance"), (2, "goal tolerance")] {
            if self.tolerances & bit == 0 || owner == 0 {
                return Err(TrajectoryError::Incomplete {
                    field,
                    point: 0,
                    column: 0,
                });
            }
        }
        let t = &mut *self.traj;
        let joints: [u16; MAX_ACTUATORS] = core::array::from_fn(|i| h.joints[i].into());
        t.set_joints(&joints[..n])?;
        t.point_count = p as u8;
        t.has = h.fields;
        t.goal_time_tolerance = h.goal_time_tolerance;
        t.start_ns = h.start_ns;
        for row in t.velocities[..p].iter_mut() {
            if h.fields & traj_has::VELOCITIES == 0 {
                row.fill(0.0);
            }
        }
        for row in t.accelerations[..p].iter_mut() {
            if h.fields & traj_has::ACCELERATIONS == 0 {
                row.fill(0.0);
            }
        }
        t.validate()
    }
}

/// Checks a chunk as it is decoded: a known field, a column and a point range within the
/// capacity, finite values.
pub(super) fn check_chunk(c: &ActArrayTrajChunkCmd) -> Result<(), crate::error::ValueError> {
    use crate::error::ValueError;
    let count = c.count as usize;
    let points = match c.field {
        traj_field::TIME
        | traj_field::POSITION
        | traj_field::VELOCITY
        | traj_field::ACCELERATION => true,
        traj_field::PATH_TOLERANCE | traj_field::GOAL_TOLERANCE => false,
        _ => {
            return Err(ValueError::TooMany {
                field: "trajectory chunk field code",
                count: c.field.into(),
                max: traj_field::GOAL_TOLERANCE.into(),
            });
        }
    };
    if count > CHUNK {
        return Err(ValueError::TooMany {
            field: "trajectory chunk values",
            count,
            max: CHUNK,
        });
    }
    if c.column as usize >= MAX_ACTUATORS {
        return Err(ValueError::BadJoint {
            joint: c.column.into(),
            max: MAX_ACTUATORS,
        });
    }
    let end = c.first as usize + count;
    if points && end > MAX_TRAJ_POINTS {
        return Err(ValueError::TooMany {
            field: "trajectory points",
            count: end,
            max: MAX_TRAJ_POINTS,
        });
    }
    if !points && c.first != 0 {
        return Err(ValueError::TooMany {
            field: "tolerance chunk's first",
            count: c.first.into(),
            max: 0,
        });
    }
    if c.values[..count].iter().any(|v| !v.is_finite()) {
        return Err(ValueError::NotFinite {
            field: "trajectory values",
        });
    }
    Ok(())
}

/// Checks a `TRAJ` header as it is decoded: counts within the capacity, known field bits,
/// a finite goal time tolerance.
pub(super) fn check_header(h: &ActArrayTrajCmd) -> Result<(), crate::error::ValueError> {
    use crate::error::ValueError;
    if h.joint_count as usize > MAX_ACTUATORS {
        return Err(ValueError::TooMany {
            field: "trajectory joints",
            count: h.joint_count as usize,
            max: MAX_ACTUATORS,
        });
    }
    if h.point_count as usize > MAX_TRAJ_POINTS {
        return Err(ValueError::TooMany {
            field: "trajectory points",
            count: h.point_count as usize,
            max: MAX_TRAJ_POINTS,
        });
    }
    if h.fields & !(traj_has::VELOCITIES | traj_has::ACCELERATIONS) != 0 {
        return Err(ValueError::TooMany {
            field: "trajectory field bits",
            count: h.fields as usize,
            max: (traj_has::VELOCITIES | traj_has::ACCELERATIONS) as usize,
        });
    }
    if let Some(&j) = h.joints[..h.joint_count as usize]
        .iter()
        .find(|&&j| j as usize >= MAX_ACTUATORS)
    {
        return Err(ValueError::BadJoint {
            joint: j.into(),
            max: MAX_ACTUATORS,
        });
    }
    if !h.goal_time_tolerance.is_finite() {
        return Err(ValueError::NotFinite {
            field: "goal time tolerance",
        });
    }
    Ok(())
}
