//! The damped least-squares step `Δq = Jᵀ(JJᵀ + λI)⁻¹e` of the numeric IK, in two
//! parts: the 6×6 matrix `JJᵀ` (its [`Gram`]), which depends on the Jacobian only,
//! so an iteration whose step was refused (same Jacobian, larger λ) reuses it; and
//! the damped solve, an LDLᵀ factorisation (no square roots: a division per column
//! is all that waits on the column before) with its loops unrolled at compile time.
//! Stack arrays only, no allocation.

use nalgebra::Vector6;

use super::{Jacobian, MAX_JOINTS};

/// A joint step of up to [`MAX_JOINTS`] values.
pub(super) type Step = nalgebra::SMatrix<f64, MAX_JOINTS, 1>;

/// `JJᵀ` over a Jacobian's first `n` columns (symmetric, both triangles stored).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Gram([[f64; 6]; 6]);

impl Gram {
    /// `JJᵀ` over the first `n` columns of `jac`.
    #[inline]
    pub(super) fn of(jac: &Jacobian, n: usize) -> Gram {
        let mut a = [[0.0f64; 6]; 6];
        // Column-major storage: each chunk is one column of six values.
        for col in jac.as_slice().chunks_exact(6).take(n) {
            add_outer(&mut a, col);
        }
        Gram(a)
    }

    /// `JJᵀ` over the first `n` columns of `jac` but those whose bits are set in
    /// `frozen` (as if they were zero).
    #[inline]
    pub(super) fn without(jac: &Jacobian, n: usize, frozen: u32) -> Gram {
        let mut a = [[0.0f64; 6]; 6];
        for (_, col) in columns(jac, n, frozen) {
            add_outer(&mut a, col);
        }
        Gram(a)
    }

    /// `Jᵀ (JJᵀ + λI)⁻¹ e` over the first `n` columns of `jac` but the `frozen` ones
    /// (the Jacobian and columns this is the Gram matrix of; the frozen joints' steps
    /// are 0), `None` if `JJᵀ + λI` is not positive definite (to round-off) or the
    /// step is not finite.
    #[inline]
    pub(super) fn step(
        &self,
        jac: &Jacobian,
        e: &Vector6<f64>,
        lambda: f64,
        n: usize,
        frozen: u32,
    ) -> Option<Step> {
        let mut f = Ldl {
            w: self.0,
            inv: [0.0; 6],
        };
        for (k, row) in f.w.iter_mut().enumerate() {
            row[k] += lambda;
        }
        let ok = f.column::<0>()
            & f.column::<1>()
            & f.column::<2>()
            & f.column::<3>()
            & f.column::<4>()
            & f.column::<5>();
        if !ok {
            return None;
        }
        let x = f.solve(e);
        let mut dq = Step::zeros();
        for (i, col) in columns(jac, n, frozen) {
            dq[i] = col.iter().zip(&x).map(|(c, x)| c * x).sum();
        }
        dq.iter().all(|v| v.is_finite()).then_some(dq)
    }
}

/// `a ← a + col·colᵀ`.
#[inline(always)]
fn add_outer(a: &mut [[f64; 6]; 6], col: &[f64]) {
    for (row, x) in a.iter_mut().zip(col) {
        for (cell, y) in row.iter_mut().zip(col) {
            *cell += x * y;
        }
    }
}

/// The first `n` columns of `jac` but the `frozen` ones, with their indices.
#[inline(always)]
fn columns(jac: &Jacobian, n: usize, frozen: u32) -> impl Iterator<Item = (usize, &[f64])> {
    jac.as_slice()
        .chunks_exact(6)
        .take(n)
        .enumerate()
        .filter(move |(i, _)| frozen & (1 << i) == 0)
}

/// `JJᵀ + λI` being factorised as `L·D·Lᵀ` in place: below the diagonal of `w`, row
/// i column j holds `L[i][j]` once column j is done (and `L[i][j]·D[j]` while the
/// later columns need it, kept above the diagonal as `w[j][i]`); `inv` holds `1/D`.
struct Ldl {
    w: [[f64; 6]; 6],
    inv: [f64; 6],
}

impl Ldl {
    /// Factorises column `J` (the columns before it done). False when the pivot is
    /// not positive and finite.
    #[inline(always)]
    #[allow(clippy::needless_range_loop)]
    fn column<const J: usize>(&mut self) -> bool {
        let w = &mut self.w;
        // D[J] = A[J][J] − Σ L[J][k]·(L[J][k]·D[k]).
        let mut d = w[J][J];
        for k in 0..J {
            d -= w[J][k] * w[k][J];
        }
        let ok = d > 0.0 && d.is_finite();
        let inv = 1.0 / d;
        self.inv[J] = inv;
        for i in J + 1..6 {
            // L[i][J]·D[J] = A[i][J] − Σ L[i][k]·(L[J][k]·D[k]).
            let mut v = w[i][J];
            for k in 0..J {
                v -= w[i][k] * w[k][J];
            }
            w[J][i] = v;
            w[i][J] = v * inv;
        }
        ok
    }

    /// `(L·D·Lᵀ)⁻¹ e`.
    #[inline(always)]
    #[allow(clippy::needless_range_loop)]
    fn solve(&self, e: &Vector6<f64>) -> [f64; 6] {
        let w = &self.w;
        let mut y = [0.0f64; 6];
        for i in 0..6 {
            let mut v = e[i];
            for k in 0..i {
                v -= w[i][k] * y[k];
            }
            y[i] = v;
        }
        for i in 0..6 {
            y[i] *= self.inv[i];
        }
        for i in (0..6).rev() {
            let mut v = y[i];
            for k in i + 1..6 {
                v -= w[k][i] * y[k];
            }
            y[i] = v;
        }
        y
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::{DMatrix, DVector};

    use super::*;
    use crate::chain::DeterministicRng;

    /// The step equals the textbook formula computed with nalgebra's dynamic
    /// matrices and LU, for ranks from 1 to 6, several λ and column counts; frozen
    /// columns count as zero columns; a matrix that is not positive definite gives
    /// `None`.
    #[test]
    fn step_equals_the_formula() {
        let mut rng = DeterministicRng::new(3);
        for n in [1, 3, 5, 6, 7, 9, MAX_JOINTS] {
            for lambda in [1e-12, 1e-3, 0.3, 50.0] {
                for rank in 1..=6usize.min(n) {
                    // J = U·V with U 6×rank, V rank×n: rank-deficient below 6.
                    let u = DMatrix::from_fn(6, rank, |_, _| rng.uniform(-1.0, 1.0));
                    let v = DMatrix::from_fn(rank, n, |_, _| rng.uniform(-1.0, 1.0));
                    let j = &u * &v;
                    let mut jac = Jacobian::zeros();
                    jac.columns_mut(0, n).copy_from(&j);
                    // Columns past n must not count.
                    if n < MAX_JOINTS {
                        jac.column_mut(n).fill(7.0);
                    }
                    let e = Vector6::from_fn(|_, _| rng.uniform(-1.0, 1.0));
                    let dq = Gram::of(&jac, n).step(&jac, &e, lambda, n, 0).unwrap();
                    let a = &j * j.transpose() + DMatrix::identity(6, 6) * lambda;
                    let y = a
                        .lu()
                        .solve(&DVector::from_column_slice(e.as_slice()))
                        .unwrap();
                    let want = j.transpose() * y;
                    // Relative to the size of the step and of the conditioning.
                    let scale = want.amax().max(1.0);
                    for i in 0..n {
                        assert!(
                            (dq[i] - want[i]).abs() <= 1e-9 * scale / lambda.min(1.0).sqrt(),
                            "n {n} λ {lambda} rank {rank}: {} {}",
                            dq[i],
                            want[i]
                        );
                    }
                    assert!(dq.iter().skip(n).all(|v| *v == 0.0));
                    // Frozen columns count as zero columns, to the bit.
                    let frozen = 0b101u32 & ((1 << n) - 1);
                    let mut zeroed = jac;
                    for i in (0..n).filter(|i| frozen & (1 << i) != 0) {
                        zeroed.column_mut(i).fill(0.0);
                    }
                    assert_eq!(
                        Gram::without(&jac, n, frozen).step(&jac, &e, lambda, n, frozen),
                        Gram::of(&zeroed, n).step(&zeroed, &e, lambda, n, 0)
                    );
                }
            }
        }
        let jac = Jacobian::zeros();
        let e = Vector6::repeat(1.0);
        assert!(Gram::of(&jac, 6).step(&jac, &e, 0.0, 6, 0).is_none());
        assert!(Gram::of(&jac, 6).step(&jac, &e, -1.0, 6, 0).is_none());
        assert!(Gram::of(&jac, 6).step(&jac, &e, f64::NAN, 6, 0).is_none());
        assert!(Gram::of(&jac, 6).step(&jac, &e, 1.0, 6, 0).is_some());
    }
}
