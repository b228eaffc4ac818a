//! End-effector poses and small angle helpers shared by every solver.

use std::f64::consts::{PI, TAU};

use nalgebra::{Matrix3, Rotation3, Vector3};

/// A rigid pose: a position and a rotation whose columns are the approach (x),
/// normal (y) and orientation (z) vectors of Player's limb interface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// Position in metres.
    pub position: Vector3<f64>,
    /// Rotation from the end-effector frame to the reference frame.
    pub rotation: Rotation3<f64>,
}

/// Why a frame could not be built from Player's approach and orientation vectors.
#[derive(Clone, Copy, Debug, PartialEq, thiserror::Error)]
pub enum FrameError {
    /// A component was NaN or infinite.
    #[error("pose contains a NaN or infinite value")]
    NonFinite,
    /// The approach vector has (almost) zero length (< 1e-12).
    #[error("approach vector has zero length")]
    ZeroApproach,
    /// The orientation vector has (almost) zero length (< 1e-12).
    #[error("orientation vector has zero length")]
    ZeroOrientation,
    /// The approach and orientation vectors are not perpendicular within the
    /// tolerance: `deviation` is |90° − angle(a, o)| in radians.
    #[error("approach and orientation are {deviation} rad away from perpendicular")]
    NotPerpendicular {
        /// |π/2 − angle between approach and orientation|, radians.
        deviation: f64,
    },
}

/// `v` scaled to unit length without overflow or underflow: divided by its largest
/// component first, so `(1e308, 1e308, 0)` gives `(0.707, 0.707, 0)` where `v / v.norm()`
/// gives zero (the norm overflows to infinity). `None` for the zero vector and for a
/// vector with a NaN or infinite component.
pub fn unit_direction(v: &Vector3<f64>) -> Option<Vector3<f64>> {
    if !all_finite(v) {
        return None;
    }
    let m = v.amax();
    if m == 0.0 {
        return None;
    }
    let s = v / m;
    Some(s / s.norm())
}

impl Pose {
    /// A pose from a position and a rotation.
    pub fn new(position: Vector3<f64>, rotation: Rotation3<f64>) -> Self {
        Self { position, rotation }
    }

    /// The identity pose (origin, no rotation).
    pub fn identity() -> Self {
        Self::new(Vector3::zeros(), Rotation3::identity())
    }

    /// Builds a pose from Player's position, approach and orientation vectors.
    ///
    /// Both vectors are normalised. The orientation vector is made exactly
    /// perpendicular to the approach (Gram–Schmidt; the approach is kept exactly) if it
    /// is within `tolerance` radians of perpendicular; otherwise the request is
    /// inconsistent and [`FrameError::NotPerpendicular`] is returned. The normal is
    /// `o × a`.
    pub fn from_approach_orientation(
        position: Vector3<f64>,
        approach: Vector3<f64>,
        orientation: Vector3<f64>,
        tolerance: f64,
    ) -> Result<Self, FrameError> {
        if !(all_finite(&position)
            && all_finite(&approach)
            && all_finite(&orientation)
            && tolerance.is_finite())
        {
            return Err(FrameError::NonFinite);
        }
        // The norm of a finite vector may overflow (1e308, 1e308, -1e308): such a vector
        // is long, not zero, and its direction comes from [`unit_direction`], which scales
        // before it normalises (dividing by an infinite norm would give a zero vector).
        if approach.norm() < 1e-12 {
            return Err(FrameError::ZeroApproach);
        }
        if orientation.norm() < 1e-12 {
            return Err(FrameError::ZeroOrientation);
        }
        let a = unit_direction(&approach).ok_or(FrameError::ZeroApproach)?;
        let o = unit_direction(&orientation).ok_or(FrameError::ZeroOrientation)?;
        let cos = a.dot(&o).clamp(-1.0, 1.0);
        let deviation = cos.abs().asin();
        if deviation > tolerance.max(0.0) {
            return Err(FrameError::NotPerpendicular { deviation });
        }
        let o_perp = o - a * cos;
        let o = o_perp / o_perp.norm();
        let n = o.cross(&a);
        let m = Matrix3::from_columns(&[a, n, o]);
        Ok(Self::new(position, Rotation3::from_matrix_unchecked(m)))
    }

    /// The approach vector `a` (first column; x axis of the end-effector frame).
    pub fn approach(&self) -> Vector3<f64> {
        self.rotation.matrix().column(0).into_owned()
    }

    /// The normal vector `n = o × a` (second column; y axis).
    pub fn normal(&self) -> Vector3<f64> {
        self.rotation.matrix().column(1).into_owned()
    }

    /// The orientation vector `o` (third column; z axis, "up" from the gripper).
    pub fn orientation(&self) -> Vector3<f64> {
        self.rotation.matrix().column(2).into_owned()
    }

    /// True when every component is finite.
    pub fn is_finite(&self) -> bool {
        all_finite(&self.position) && self.rotation.matrix().iter().all(|v| v.is_finite())
    }

    /// Euclidean distance between the two positions, metres.
    pub fn position_error(&self, other: &Pose) -> f64 {
        (self.position - other.position).norm()
    }

    /// Angle of the rotation taking one frame to the other, radians, in [0, π].
    pub fn orientation_error(&self, other: &Pose) -> f64 {
        angle_between_rotations(&self.rotation, &other.rotation)
    }

    /// The same pose with its position shifted by `offset`.
    pub fn translated(&self, offset: &Vector3<f64>) -> Pose {
        Pose::new(self.position + offset, self.rotation)
    }
}

/// The angle (radians, [0, π]) of `a⁻¹·b`, computed as `2·asin(‖A−B‖_F / √8)`, which
/// stays accurate for tiny angles (unlike `acos((trace−1)/2)`).
pub fn angle_between_rotations(a: &Rotation3<f64>, b: &Rotation3<f64>) -> f64 {
    let f = (a.matrix() - b.matrix()).norm();
    if !f.is_finite() {
        return f64::INFINITY;
    }
    2.0 * (f / 8f64.sqrt()).min(1.0).asin()
}

/// Chooses, among `angle + 2πk`, the representative inside `[min − tol, max + tol]`
/// that is nearest to `near`, clamped into `[min, max]`. `None` if no representative
/// fits or an input is not finite. Used so a revolute joint whose limits span more than
/// 2π can use its extra turn, and so a solution sitting on a limit up to round-off is
/// accepted.
pub fn fit_angle_to_limits(angle: f64, min: f64, max: f64, near: f64, tol: f64) -> Option<f64> {
    if !(angle.is_finite() && min.is_finite() && max.is_finite() && near.is_finite()) {
        return None;
    }
    if angle >= min - tol && angle <= max + tol && (max - min) + 2.0 * tol < TAU {
        // Only one representative fits.
        return Some(angle.clamp(min, max));
    }
    let kmin = ((min - tol - angle) / TAU).ceil();
    let kmax = ((max + tol - angle) / TAU).floor();
    if kmin > kmax {
        return None;
    }
    let k = ((near - angle) / TAU).round().clamp(kmin, kmax);
    let v = angle + TAU * k;
    if v < min - tol || v > max + tol {
        return None;
    }
    Some(v.clamp(min, max))
}

/// Wraps an angle into (−π, π].
pub(crate) fn wrap_pi(x: f64) -> f64 {
    let mut v = x - TAU * (x / TAU).round();
    if v <= -PI {
        v += TAU;
    }
    v
}

pub(crate) fn all_finite(v: &Vector3<f64>) -> bool {
    v.iter().all(|x| x.is_finite())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fit_angle_prefers_nearest_turn() {
        let v = fit_angle_to_limits(0.5, -7.0, 7.0, 6.0, 1e-9).unwrap();
        assert!((v - (0.5 + TAU)).abs() < 1e-12);
        assert!(fit_angle_to_limits(3.0, -1.0, 1.0, 0.0, 1e-9).is_none());
        assert_eq!(
            fit_angle_to_limits(1.0 + 1e-12, -1.0, 1.0, 0.0, 1e-9),
            Some(1.0)
        );
        assert!(fit_angle_to_limits(f64::NAN, -1.0, 1.0, 0.0, 1e-9).is_none());
    }

    #[test]
    fn small_angles_are_accurate() {
        let a = Rotation3::identity();
        let b = Rotation3::from_axis_angle(&Vector3::z_axis(), 1e-10);
        let e = angle_between_rotations(&a, &b);
        assert!((e - 1e-10).abs() < 1e-20);
        assert!((wrap_pi(3.0 * PI) - PI).abs() < 1e-12);
    }

    #[test]
    fn frame_from_vectors() {
        let p = Pose::from_approach_orientation(
            Vector3::zeros(),
            Vector3::new(2.0, 0.0, 0.0),
            Vector3::new(0.0, 0.0, 3.0),
            1e-6,
        )
        .unwrap();
        assert!((p.normal() - Vector3::y()).norm() < 1e-15);
        let e = Pose::from_approach_orientation(
            Vector3::zeros(),
            Vector3::x(),
            Vector3::new(1.0, 0.0, 1.0),
            1e-6,
        );
        assert!(matches!(e, Err(FrameError::NotPerpendicular { .. })));
    }

    /// A finite vector whose norm overflows is a long vector with a direction, not a
    /// zero or non-finite one: the frame is the one of the unit vectors.
    #[test]
    fn frame_from_vectors_whose_norm_overflows() {
        let big = Pose::from_approach_orientation(
            Vector3::zeros(),
            Vector3::new(1e308, 1e308, -1e308),
            Vector3::new(f64::MAX, 0.0, f64::MAX),
            1e-6,
        )
        .unwrap();
        let unit = Pose::from_approach_orientation(
            Vector3::zeros(),
            Vector3::new(1.0, 1.0, -1.0),
            Vector3::new(1.0, 0.0, 1.0),
            1e-6,
        )
        .unwrap();
        assert!(big.is_finite());
        assert!((big.approach() - unit.approach()).norm() < 1e-15, "{big:?}");
        assert!(
            (big.orientation() - unit.orientation()).norm() < 1e-15,
            "{big:?}"
        );
    }
}
