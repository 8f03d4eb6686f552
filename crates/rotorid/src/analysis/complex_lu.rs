//! LU factorization with partial pivoting of a dense complex square matrix, P A = L U,
//! with solves of A x = b and of A^T x = b (no conjugation) from the one factorization.
//!
//! The finite-element analysis factors Q(lambda) = lambda^2 M + lambda C + K at every
//! Newton step of every eigenvalue it polishes, for both null vectors (inverse iteration
//! on Q and on Q^T): this is its inner loop. Column-major storage, rank-one updates down
//! contiguous columns, the buffer reused from one factorization to the next (no
//! allocation per step). The pivot is the entry of largest |re| + |im| in the column, as
//! nalgebra's `LU` chooses it.

use nalgebra::{Complex, DVector};

type C64 = Complex<f64>;

const ZERO: C64 = Complex::new(0.0, 0.0);

/// The factors of one matrix (module doc).
#[derive(Debug, Clone)]
pub(crate) struct ComplexLu {
    n: usize,
    /// L (unit diagonal, below) and U (on and above), column-major.
    a: Vec<C64>,
    /// Row k was swapped with row piv\[k\] at step k.
    piv: Vec<usize>,
    /// True when a pivot is exactly zero (A singular in floating point).
    singular: bool,
}

impl ComplexLu {
    /// A workspace for n x n matrices.
    pub(crate) fn new(n: usize) -> Self {
        Self {
            n,
            a: vec![ZERO; n * n],
            piv: vec![0; n],
            singular: false,
        }
    }

    /// Factors the matrix whose entry (i, j) is `entry(i, j)`.
    pub(crate) fn factor(&mut self, entry: impl Fn(usize, usize) -> C64) {
        let n = self.n;
        for j in 0..n {
            for i in 0..n {
                self.a[i + j * n] = entry(i, j);
            }
        }
        self.singular = false;
        for k in 0..n {
            let col = &self.a[k * n..(k + 1) * n];
            let mut p = k;
            let mut best = col[k].l1_norm();
            for (i, v) in col.iter().enumerate().skip(k + 1) {
                let m = v.l1_norm();
                if m > best {
                    best = m;
                    p = i;
                }
            }
            self.piv[k] = p;
            if p != k {
                for j in 0..n {
                    self.a.swap(k + j * n, p + j * n);
                }
            }
            let d = self.a[k + k * n];
            if d == ZERO {
                self.singular = true;
                continue;
            }
            let inv = d.inv();
            for v in &mut self.a[k * n + k + 1..(k + 1) * n] {
                *v *= inv;
            }
            // the trailing columns: a_j -= a_kj l_k below the diagonal
            let (left, right) = self.a.split_at_mut((k + 1) * n);
            let l = &left[k * n + k + 1..(k + 1) * n];
            for cj in right.chunks_exact_mut(n) {
                let akj = cj[k];
                if akj == ZERO {
                    continue;
                }
                for (x, &lik) in cj[k + 1..].iter_mut().zip(l) {
                    *x -= lik * akj;
                }
            }
        }
    }

    /// x with A x = b; `None` when A is singular.
    pub(crate) fn solve(&self, b: &DVector<C64>) -> Option<DVector<C64>> {
        if self.singular {
            return None;
        }
        let n = self.n;
        let mut x = b.clone();
        for k in 0..n {
            x.swap_rows(k, self.piv[k]);
        }
        // L y = P b (unit diagonal)
        for k in 0..n {
            let xk = x[k];
            if xk != ZERO {
                let col = &self.a[k * n..(k + 1) * n];
                for i in k + 1..n {
                    x[i] -= col[i] * xk;
                }
            }
        }
        // U x = y
        for k in (0..n).rev() {
            let col = &self.a[k * n..(k + 1) * n];
            x[k] /= col[k];
            let xk = x[k];
            for i in 0..k {
                x[i] -= col[i] * xk;
            }
        }
        Some(x)
    }

    /// x with A^T x = b (no conjugation): U^T L^T P x = b; `None` when A is singular.
    pub(crate) fn solve_transposed(&self, b: &DVector<C64>) -> Option<DVector<C64>> {
        if self.singular {
            return None;
        }
        let n = self.n;
        let mut x = b.clone();
        // U^T y = b: down the columns of U
        for k in 0..n {
            let col = &self.a[k * n..(k + 1) * n];
            let s: C64 = col[..k].iter().zip(x.iter()).map(|(u, y)| u * y).sum();
            x[k] = (x[k] - s) / col[k];
        }
        // L^T z = y (unit diagonal)
        for k in (0..n).rev() {
            let col = &self.a[k * n..(k + 1) * n];
            let s: C64 = col[k + 1..]
                .iter()
                .zip(x.iter().skip(k + 1))
                .map(|(l, z)| l * z)
                .sum();
            x[k] -= s;
        }
        // x = P^T z: the swaps undone in reverse order
        for k in (0..n).rev() {
            x.swap_rows(k, self.piv[k]);
        }
        Some(x)
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::DMatrix;

    use super::*;

    fn matrix(n: usize, seed: u64) -> DMatrix<C64> {
        // entries of widely different sizes, so that pivoting matters
        DMatrix::from_fn(n, n, |i, j| {
            let t = (i * 31 + j * 17) as f64 + seed as f64;
            let s = if (i + 2 * j) % 5 == 0 { 1e-6 } else { 1.0 };
            Complex::new(s * (0.7 * t).sin(), s * (1.3 * t).cos())
        })
    }

    #[test]
    fn solves_match_nalgebra_and_the_residuals_are_rounding() {
        for (n, seed) in [(1, 0), (2, 3), (7, 1), (44, 5)] {
            let a = matrix(n, seed);
            let b = DVector::from_fn(n, |i, _| Complex::new(1.0 + i as f64, 0.5 - i as f64));
            let mut lu = ComplexLu::new(n);
            lu.factor(|i, j| a[(i, j)]);
            let x = lu.solve(&b).unwrap();
            let y = lu.solve_transposed(&b).unwrap();
            let x_ref = a.clone().lu().solve(&b).unwrap();
            // the same pivots as nalgebra's LU of A: the same x to rounding
            let tol = 1e-10 * x_ref.norm();
            assert!((&x - &x_ref).norm() <= tol, "n {n}: {x} vs {x_ref}");
            // A^T y = b (nalgebra's LU of A^T pivots otherwise: compared by residual, which
            // is rounding for a backward-stable solve whatever the condition number)
            let rx = (&a * &x - &b).norm() / (a.norm() * x.norm());
            let ry = (a.transpose() * &y - &b).norm() / (a.norm() * y.norm());
            assert!(
                rx <= 1e-13 && ry <= 1e-13,
                "n {n}: residuals {rx:e}, {ry:e}"
            );
        }
    }

    #[test]
    fn a_singular_matrix_has_no_solution() {
        let mut a = matrix(5, 2);
        a.row_mut(3).fill(ZERO);
        let mut lu = ComplexLu::new(5);
        lu.factor(|i, j| a[(i, j)]);
        let b = DVector::from_element(5, Complex::new(1.0, 0.0));
        assert!(lu.solve(&b).is_none());
        assert!(lu.solve_transposed(&b).is_none());
    }
}
