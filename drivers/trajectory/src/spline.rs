//! One joint's motion between two knots: linear, cubic (Hermite) or quintic polynomials,
//! chosen by what the trajectory gives.

use limber_interfaces::actarray::Interpolation;

/// A joint's state at a knot: position, velocity, acceleration.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Knot {
    /// Position, rad or m.
    pub p: f64,
    /// Velocity.
    pub v: f64,
    /// Acceleration.
    pub a: f64,
}

/// Position, velocity and acceleration `tau` s after knot `k0` on the way to `k1`, reached
/// `span` s after `k0` (`span > 0`; `tau` is clamped to `0..=span`).
pub fn sample(kind: Interpolation, k0: Knot, k1: Knot, span: f64, tau: f64) -> Knot {
    let t = tau.clamp(0.0, span);
    let h = k1.p - k0.p;
    match kind {
        Interpolation::Linear => Knot {
            p: k0.p + h * t / span,
            v: h / span,
            a: 0.0,
        },
        Interpolation::Cubic => {
            let (s2, s3) = (span * span, span * span * span);
            let c2 = (3.0 * h - (2.0 * k0.v + k1.v) * span) / s2;
            let c3 = (-2.0 * h + (k0.v + k1.v) * span) / s3;
            Knot {
                p: k0.p + t * (k0.v + t * (c2 + t * c3)),
                v: k0.v + t * (2.0 * c2 + 3.0 * c3 * t),
                a: 2.0 * c2 + 6.0 * c3 * t,
            }
        }
        Interpolation::Quintic => {
            let s2 = span * span;
            let s3 = s2 * span;
            let c2 = k0.a / 2.0;
            let c3 = (20.0 * h - (8.0 * k1.v + 12.0 * k0.v) * span - (3.0 * k0.a - k1.a) * s2)
                / (2.0 * s3);
            let c4 =
                (-30.0 * h + (14.0 * k1.v + 16.0 * k0.v) * span + (3.0 * k0.a - 2.0 * k1.a) * s2)
                    / (2.0 * s3 * span);
            let c5 = (12.0 * h - 6.0 * (k1.v + k0.v) * span + (k1.a - k0.a) * s2) / (2.0 * s3 * s2);
            Knot {
                p: k0.p + t * (k0.v + t * (c2 + t * (c3 + t * (c4 + t * c5)))),
                v: k0.v + t * (2.0 * c2 + t * (3.0 * c3 + t * (4.0 * c4 + t * 5.0 * c5))),
                a: 2.0 * c2 + t * (6.0 * c3 + t * (12.0 * c4 + t * 20.0 * c5)),
            }
        }
    }
}

/// Samples of a segment checked for limits and speed (besides its ends).
pub const CHECK_SAMPLES: usize = 32;

/// The largest |velocity| and the lowest and highest position of a segment, sampled.
pub fn extremes(kind: Interpolation, k0: Knot, k1: Knot, span: f64) -> (f64, f64, f64) {
    let mut vmax: f64 = 0.0;
    let (mut lo, mut hi) = (k0.p.min(k1.p), k0.p.max(k1.p));
    for i in 0..=CHECK_SAMPLES {
        let s = sample(kind, k0, k1, span, span * i as f64 / CHECK_SAMPLES as f64);
        vmax = vmax.max(s.v.abs());
        lo = lo.min(s.p);
        hi = hi.max(s.p);
    }
    (vmax, lo, hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9
    }

    #[test]
    fn every_kind_meets_its_knots() {
        let k0 = Knot {
            p: 0.3,
            v: -0.2,
            a: 0.5,
        };
        let k1 = Knot {
            p: -1.1,
            v: 0.4,
            a: -0.7,
        };
        let span = 1.7;
        for kind in [
            Interpolation::Linear,
            Interpolation::Cubic,
            Interpolation::Quintic,
        ] {
            let s0 = sample(kind, k0, k1, span, 0.0);
            let s1 = sample(kind, k0, k1, span, span);
            assert!(close(s0.p, k0.p) && close(s1.p, k1.p), "{kind:?}");
            if kind != Interpolation::Linear {
                assert!(close(s0.v, k0.v) && close(s1.v, k1.v), "{kind:?}");
            }
            if kind == Interpolation::Quintic {
                assert!(close(s0.a, k0.a) && close(s1.a, k1.a), "{kind:?}");
            }
            // The velocity is the derivative of the position.
            let (t, d) = (0.6, 1e-6);
            let fd = (sample(kind, k0, k1, span, t + d).p - sample(kind, k0, k1, span, t - d).p)
                / (2.0 * d);
            assert!(
                (fd - sample(kind, k0, k1, span, t).v).abs() < 1e-5,
                "{kind:?}"
            );
        }
    }
}
