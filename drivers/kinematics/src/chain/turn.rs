//! The frame walk's rotations, prepared at load: most joints of real arms turn about a
//! coordinate axis of their frame and most rest orientations are quarter turns about
//! one, and a rotation about a coordinate axis, applied on the right of a frame, only
//! mixes two of its columns (12 products instead of a 3×3 product and the Rodrigues
//! matrix).

use nalgebra::{Matrix3, Rotation3, Unit, Vector3};

/// A fixed rotation applied on the right of a frame (`r ← r·R`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Turn {
    /// No rotation.
    Identity,
    /// About a coordinate axis: columns `a` and `b` (the other two axes, in cyclic
    /// order) turn by the angle whose cosine and sine are `c` and `s`.
    Coordinate { a: usize, b: usize, c: f64, s: f64 },
    /// Any other rotation.
    General(Rotation3<f64>),
}

impl Turn {
    /// The same rotation as `m`, in its cheapest form (exact: taken only when `m` has
    /// exact zeros and one where a rotation about a coordinate axis has them).
    pub(super) fn of(m: &Rotation3<f64>) -> Turn {
        let m = m.matrix();
        if *m == Matrix3::identity() {
            return Turn::Identity;
        }
        for k in 0..3 {
            let (a, b) = others(k);
            let fixed = m[(k, k)] == 1.0
                && m[(k, a)] == 0.0
                && m[(k, b)] == 0.0
                && m[(a, k)] == 0.0
                && m[(b, k)] == 0.0;
            let (c, s) = (m[(a, a)], m[(b, a)]);
            if fixed && m[(b, b)] == c && m[(a, b)] == -s {
                return Turn::Coordinate { a, b, c, s };
            }
        }
        Turn::General(Rotation3::from_matrix_unchecked(*m))
    }

    /// `r ← r·R`.
    #[inline]
    pub(super) fn apply(&self, r: &mut Matrix3<f64>) {
        match *self {
            Turn::Identity => {}
            Turn::Coordinate { a, b, c, s } => mix(r, a, b, c, s),
            Turn::General(m) => *r *= m.matrix(),
        }
    }
}

/// A rotary joint's axis: a coordinate axis (`sign` ±1) or any unit vector.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Axis {
    /// ±e_k: the turn mixes columns `a` and `b` (the other two axes, in cyclic order).
    Coordinate {
        k: usize,
        a: usize,
        b: usize,
        sign: f64,
    },
    /// Any other unit axis.
    General(Unit<Vector3<f64>>),
}

impl Axis {
    /// The cheapest form of `axis` (exact: a coordinate axis only when two components
    /// are exactly zero and the third is exactly ±1).
    pub(super) fn of(axis: &Unit<Vector3<f64>>) -> Axis {
        for k in 0..3 {
            let (a, b) = others(k);
            if axis[a] == 0.0 && axis[b] == 0.0 && axis[k].abs() == 1.0 {
                return Axis::Coordinate {
                    k,
                    a,
                    b,
                    sign: axis[k],
                };
            }
        }
        Axis::General(*axis)
    }

    /// `r ← r·Rot(axis, angle)`, given the angle's sine `s` and cosine `c`.
    #[inline]
    pub(super) fn turn(&self, r: &mut Matrix3<f64>, s: f64, c: f64) {
        match *self {
            Axis::Coordinate { a, b, sign, .. } => mix(r, a, b, c, sign * s),
            Axis::General(axis) => {
                // Rodrigues: c·I + s·[u]ₓ + (1 − c)·u·uᵀ.
                let u = axis.into_inner();
                let m =
                    Matrix3::identity() * c + u.cross_matrix() * s + u * u.transpose() * (1.0 - c);
                *r *= m;
            }
        }
    }

    /// The axis in the frame whose rotation is `r` (`r·axis`).
    #[inline]
    pub(super) fn in_frame(&self, r: &Matrix3<f64>) -> Vector3<f64> {
        match *self {
            Axis::Coordinate { k, sign, .. } => r.column(k) * sign,
            Axis::General(axis) => r * axis.into_inner(),
        }
    }
}

/// The two other coordinate axes after `k`, in cyclic order.
fn others(k: usize) -> (usize, usize) {
    ((k + 1) % 3, (k + 2) % 3)
}

/// Columns `a`, `b` of `r` turned by the angle with cosine `c` and sine `s`: the
/// product of `r` with a rotation about the third axis.
#[inline(always)]
fn mix(r: &mut Matrix3<f64>, a: usize, b: usize, c: f64, s: f64) {
    let ca = r.column(a).into_owned();
    let cb = r.column(b).into_owned();
    r.set_column(a, &(ca * c + cb * s));
    r.set_column(b, &(cb * c - ca * s));
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every form gives the product it replaces, to round-off.
    #[test]
    fn turns_equal_the_matrix_products() {
        let r = Rotation3::from_euler_angles(0.3, -1.1, 2.0);
        let close = |x: &Matrix3<f64>, y: &Matrix3<f64>| (x - y).amax() < 1e-14;
        for rpy in [
            [0.0, 0.0, 0.0],
            [std::f64::consts::FRAC_PI_2, 0.0, 0.0],
            [0.0, -std::f64::consts::FRAC_PI_2, 0.0],
            [0.0, 0.0, 0.7],
            [0.2, 0.3, 0.4],
        ] {
            let rest = Rotation3::from_euler_angles(rpy[0], rpy[1], rpy[2]);
            let mut m = *r.matrix();
            Turn::of(&rest).apply(&mut m);
            assert!(close(&m, (r * rest).matrix()), "{rpy:?}");
        }
        assert_eq!(
            Turn::of(&Rotation3::from_euler_angles(0.0, 0.5, 0.0)),
            Turn::Coordinate {
                a: 2,
                b: 0,
                c: 0.5f64.cos(),
                s: 0.5f64.sin()
            }
        );
        for v in [
            Vector3::x(),
            -Vector3::y(),
            Vector3::z(),
            Vector3::new(0.3, -0.2, 0.9),
        ] {
            let axis = Unit::new_normalize(v);
            let mut m = *r.matrix();
            let (s, c) = 0.83f64.sin_cos();
            Axis::of(&axis).turn(&mut m, s, c);
            let want = r * Rotation3::from_axis_angle(&axis, 0.83);
            assert!(close(&m, want.matrix()), "{v:?}");
            let d = Axis::of(&axis).in_frame(r.matrix()) - r * axis.into_inner();
            assert!(d.amax() < 1e-15);
        }
    }
}
