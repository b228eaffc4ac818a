//! Pioneer forward kinematics, with the sign of Player's FK corrected (see the crate
//! docs): the rotation product `Rz(θ1)·Ry(−(θ2+θ3))·Rx(θ4)·Ry(−θ5)`, with a variant
//! from precomputed sines and cosines that the IK uses to score its candidates.

use nalgebra::{Matrix3, Rotation3, Vector3};

use super::{PioneerGeometry, Theta};
use crate::pose::Pose;

/// Error of [`PioneerGeometry::fk`].
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum PioneerFkError {
    /// A joint angle was NaN or infinite.
    #[error("joint angle is NaN or infinite")]
    NonFinite,
}

/// Sines and cosines of θ1, θ2, θ2+θ3, θ4, θ5.
#[derive(Clone, Copy)]
pub(super) struct Trig {
    pub(super) s1: f64,
    pub(super) c1: f64,
    pub(super) s2: f64,
    pub(super) c2: f64,
    pub(super) s23: f64,
    pub(super) c23: f64,
    pub(super) s4: f64,
    pub(super) c4: f64,
    pub(super) s5: f64,
    pub(super) c5: f64,
}

impl PioneerGeometry {
    /// Forward kinematics relative to the arm base, with the corrected sign
    /// (`a_y = s1c23c5 − c1s4s5 − s1s23c4s5`): R = Rz(θ1)·Ry(−(θ2+θ3))·Rx(θ4)·Ry(−θ5),
    /// p = L5·a + (c1ρ, s1ρ, L2s2 + L4s23) with ρ = L1 + L2c2 + L4c23.
    pub fn fk(&self, theta: &Theta) -> Result<Pose, PioneerFkError> {
        if !theta.iter().all(|t| t.is_finite()) {
            return Err(PioneerFkError::NonFinite);
        }
        Ok(self.fk_raw(theta))
    }

    /// [`fk`](Self::fk) in the robot frame (base offset added).
    pub fn fk_robot(&self, theta: &Theta) -> Result<Pose, PioneerFkError> {
        self.fk(theta).map(|p| self.base_to_robot(&p))
    }
    pub(super) fn fk_raw(&self, t: &Theta) -> Pose {
        let (s1, c1) = t[0].sin_cos();
        let (s2, c2) = t[1].sin_cos();
        let (s23, c23) = (t[1] + t[2]).sin_cos();
        let (s4, c4) = t[3].sin_cos();
        let (s5, c5) = t[4].sin_cos();
        self.fk_trig(&Trig {
            s1,
            c1,
            s2,
            c2,
            s23,
            c23,
            s4,
            c4,
            s5,
            c5,
        })
    }

    /// FK from the sines and cosines (the IK reuses the ones it already has).
    pub(super) fn fk_trig(&self, t: &Trig) -> Pose {
        let Trig {
            s1,
            c1,
            s2,
            c2,
            s23,
            c23,
            s4,
            c4,
            s5,
            c5,
        } = *t;
        let n = Vector3::new(-s1 * c4 - c1 * s23 * s4, c1 * c4 - s1 * s23 * s4, c23 * s4);
        let o = Vector3::new(
            -c1 * c23 * s5 + s1 * s4 * c5 - c1 * s23 * c4 * c5,
            -s1 * c23 * s5 - c1 * s4 * c5 - s1 * s23 * c4 * c5,
            -s23 * s5 + c23 * c4 * c5,
        );
        let a = Vector3::new(
            c1 * c23 * c5 + s1 * s4 * s5 - c1 * s23 * c4 * s5,
            s1 * c23 * c5 - c1 * s4 * s5 - s1 * s23 * c4 * s5,
            s23 * c5 + c23 * c4 * s5,
        );
        let rho = self.l1 + self.l2 * c2 + self.l4 * c23;
        let p = a * self.l5 + Vector3::new(c1 * rho, s1 * rho, self.l2 * s2 + self.l4 * s23);
        Pose::new(
            p,
            Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[a, n, o])),
        )
    }
}
