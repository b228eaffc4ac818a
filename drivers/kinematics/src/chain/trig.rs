//! Sine and cosine of all the joint angles of a walk at once.
//!
//! The frame walk needs both for every joint, and the numeric IK walks the chain once
//! per iteration, so the library call (`sin_cos`, one at a time, with branches for
//! every range) was a sixth of its time. Here the angle is reduced by the nearest
//! multiple of π/2 (π/2 split in three parts, the first two short enough that their
//! products with the multiple are exact) and both functions are Taylor polynomials
//! on [−π/4, π/4], carried far enough that the truncation (< 1e-19) stays far below
//! the rounding: within two units in the last place of the library's values. The
//! loop over the joints has no branch, so the joints' polynomials overlap. Angles
//! beyond [`LIMIT`] (or not finite) go to the library.

use super::MAX_JOINTS;

/// π/2 to 33 significant bits: its product with a multiple below 2^20 is exact.
const PIO2_HI: f64 = 1.570_796_326_734_125_6;
/// The next 33 bits of π/2.
const PIO2_MID: f64 = 6.077_100_506_303_966e-11;
/// The rest of π/2, rounded.
const PIO2_LO: f64 = 2.022_266_248_795_950_6e-21;

/// Largest |angle| reduced here (multiples of π/2 below 2^17).
const LIMIT: f64 = 1.0e5;

/// 1.5·2^52: adding and subtracting it rounds a value below 2^51 to an integer.
const ROUND: f64 = 6_755_399_441_055_744.0;

/// sin r = r − r³/3! + r⁵/5! − … + r¹⁷/17!: the coefficients of (sin r − r)/r³ in
/// powers of r².
const SIN: [f64; 8] = [
    -1.0 / 6.0,
    1.0 / 120.0,
    -1.0 / 5_040.0,
    1.0 / 362_880.0,
    -1.0 / 39_916_800.0,
    1.0 / 6_227_020_800.0,
    -1.0 / 1_307_674_368_000.0,
    1.0 / 355_687_428_096_000.0,
];

/// cos r = 1 − r²/2! + r⁴/4! − … + r¹⁶/16!: the coefficients of (cos r − 1)/r² in
/// powers of r².
const COS: [f64; 8] = [
    -0.5,
    1.0 / 24.0,
    -1.0 / 720.0,
    1.0 / 40_320.0,
    -1.0 / 3_628_800.0,
    1.0 / 479_001_600.0,
    -1.0 / 87_178_291_200.0,
    1.0 / 20_922_789_888_000.0,
];

/// The polynomial with coefficients `c` (lowest power first) at `z`, by Horner.
#[inline(always)]
fn horner(c: &[f64; 8], z: f64) -> f64 {
    c.iter().rev().fold(0.0, |acc, c| acc * z + c)
}

/// (sin, cos) of every value of `q` into `s` and `c` (entries beyond `q.len()` are
/// left alone).
pub(super) fn sin_cos_all(q: &[f64], s: &mut [f64; MAX_JOINTS], c: &mut [f64; MAX_JOINTS]) {
    let out = s.iter_mut().zip(c.iter_mut());
    if q.iter().all(|v| v.abs() <= LIMIT) {
        for (v, (s, c)) in q.iter().zip(out) {
            (*s, *c) = sin_cos(*v);
        }
    } else {
        for (v, (s, c)) in q.iter().zip(out) {
            (*s, *c) = v.sin_cos();
        }
    }
}

/// (sin x, cos x) for |x| ≤ [`LIMIT`].
#[inline(always)]
fn sin_cos(x: f64) -> (f64, f64) {
    let k = (x * std::f64::consts::FRAC_2_PI + ROUND) - ROUND;
    // x − kπ/2: the first difference is exact (the two are within a factor of two of
    // each other, or k is 0), the products with HI and MID are exact.
    let r = ((x - k * PIO2_HI) - k * PIO2_MID) - k * PIO2_LO;
    let z = r * r;
    // sin r = r + r·z·SIN(z), cos r = 1 + z·COS(z).
    let (ps, pc) = (z * horner(&SIN, z), z * horner(&COS, z));
    let (sr, cr) = (r + r * ps, 1.0 + pc);
    // The quadrant: sin(r + π/2) = cos r, cos(r + π/2) = −sin r; a half turn negates
    // both.
    let quadrant = k as i64;
    let (s, c) = if quadrant & 1 == 0 {
        (sr, cr)
    } else {
        (cr, -sr)
    };
    let sign = if quadrant & 2 == 0 { 1.0 } else { -1.0 };
    (s * sign, c * sign)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Within two units in the last place of the library (absolute, relative to 1)
    /// over the range of joint angles and beyond, at quarter turns, and the library's
    /// values beyond the limit and for NaN.
    #[test]
    fn sin_cos_all_matches_the_library() {
        let ulp = f64::EPSILON;
        let mut worst = 0.0f64;
        // Error in units of 2^-52 relative to the value, or absolute where the value
        // is below 2^-52.
        let check = |x: f64, got: f64, want: f64, worst: &mut f64| {
            let e = (got - want).abs() / (ulp * want.abs().max(ulp));
            *worst = worst.max(e);
            assert!(e <= 2.0, "{x}: {got} against {want}");
        };
        let mut xs = Vec::new();
        for i in -200_000..=200_000 {
            xs.push(f64::from(i) * 1e-4 * std::f64::consts::PI);
        }
        for k in -40..=40 {
            let q = f64::from(k) * std::f64::consts::FRAC_PI_2;
            xs.extend([q, q.next_up(), q.next_down(), q + 1e-9, q - 1e-9]);
        }
        xs.extend([
            0.0,
            -0.0,
            1e-300,
            -1e-300,
            1e-8,
            std::f64::consts::FRAC_PI_4,
            0.855_469,
        ]);
        xs.extend([LIMIT, -LIMIT, 12_345.678, -99_999.9]);
        for chunk in xs.chunks(MAX_JOINTS) {
            let (mut s, mut c) = ([0.0; MAX_JOINTS], [0.0; MAX_JOINTS]);
            sin_cos_all(chunk, &mut s, &mut c);
            for (i, x) in chunk.iter().enumerate() {
                check(*x, s[i], x.sin(), &mut worst);
                check(*x, c[i], x.cos(), &mut worst);
            }
        }
        println!("worst error: {worst:.2} ulp");
        for x in [LIMIT * 1.5, 1e300, f64::INFINITY, f64::NAN] {
            let (mut s, mut c) = ([0.0; MAX_JOINTS], [0.0; MAX_JOINTS]);
            sin_cos_all(&[0.3, x], &mut s, &mut c);
            assert_eq!(s[1].to_bits(), x.sin().to_bits());
            assert_eq!(c[1].to_bits(), x.cos().to_bits());
            assert_eq!((s[0], c[0]), 0.3f64.sin_cos());
        }
    }
}
