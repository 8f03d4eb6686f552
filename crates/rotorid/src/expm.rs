//! The matrix exponential without panics: nalgebra's `exp` (scaling and squaring with a
//! Pade approximant, Higham 2005) forms A^6 before scaling, so a matrix of 1-norm above
//! ~1e50 (or with NaN or infinite entries) overflows and its internal solve panics. The
//! rotor's matrices A dt have norms ~1e-2 .. 1e2; only absurd inputs (a speed of 1e300
//! rad/s, a stiffness of 1e300 N/m) come near the limit, and they get NaN instead, which the
//! callers report as non-finite results.

use nalgebra::SMatrix;

/// Largest 1-norm handed to nalgebra's exponential (A^6 stays below 1e180).
const MAX_NORM: f64 = 1e30;

macro_rules! checked_exp {
    ($name:ident, $n:literal) => {
        /// exp(`m`), or all NaN when `m` is not finite or too large (module doc).
        pub(crate) fn $name(m: &SMatrix<f64, $n, $n>) -> SMatrix<f64, $n, $n> {
            let norm = (0..$n)
                .map(|c| m.column(c).iter().map(|v| v.abs()).sum::<f64>())
                .fold(0.0, f64::max);
            if norm.is_finite() && norm <= MAX_NORM {
                m.exp()
            } else {
                SMatrix::from_element(f64::NAN)
            }
        }
    };
}

checked_exp!(exp6, 6);
checked_exp!(exp12, 12);

/// exp(`m`) for a square dynamic matrix, after balancing it (a diagonal similarity by
/// powers of 2, Parlett & Reinsch 1969, so that each row and column have comparable norms:
/// nalgebra's error bound is relative to the whole matrix's norm, and a rotor's state
/// matrix mixes entries ~1 with entries ~1e6 in SI units); all NaN when not finite or too
/// large (module doc).
pub(crate) fn exp_balanced(m: &nalgebra::DMatrix<f64>) -> nalgebra::DMatrix<f64> {
    let d = balancing(m);
    let n = m.nrows();
    let scaled = nalgebra::DMatrix::from_fn(n, n, |i, j| m[(i, j)] * d[j] / d[i]);
    let norm = (0..n)
        .map(|c| scaled.column(c).iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    if !(norm.is_finite() && norm <= MAX_NORM) {
        return nalgebra::DMatrix::from_element(n, n, f64::NAN);
    }
    let e = scaled.exp();
    nalgebra::DMatrix::from_fn(n, n, |i, j| e[(i, j)] * d[i] / d[j])
}

/// The diagonal D (powers of 2) with D^-1 A D balanced: Parlett & Reinsch's iteration on
/// the 1-norms of the off-diagonal parts of each row and column.
pub(crate) fn balancing(a: &nalgebra::DMatrix<f64>) -> Vec<f64> {
    let n = a.nrows();
    let mut d = vec![1.0f64; n];
    if !a.iter().all(|v| v.is_finite()) {
        return d;
    }
    for _ in 0..100 {
        let mut converged = true;
        for i in 0..n {
            // column i and row i of D^-1 A D, off the diagonal
            let (mut c, mut r) = (0.0, 0.0);
            for j in 0..n {
                if j != i {
                    c += (a[(j, i)] * d[i] / d[j]).abs();
                    r += (a[(i, j)] * d[j] / d[i]).abs();
                }
            }
            if c == 0.0 || r == 0.0 {
                continue;
            }
            let mut f = 1.0;
            let s = c + r;
            while c < r / 2.0 {
                c *= 2.0;
                r /= 2.0;
                f *= 2.0;
            }
            while c >= r * 2.0 {
                c /= 2.0;
                r *= 2.0;
                f /= 2.0;
            }
            if (c + r) < 0.95 * s {
                converged = false;
                d[i] *= f;
            }
        }
        if converged {
            break;
        }
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn absurd_matrices_give_nan_not_a_panic() {
        let big = SMatrix::<f64, 6, 6>::from_element(1e300);
        assert!(exp6(&big).iter().all(|v| v.is_nan()));
        let nan = SMatrix::<f64, 12, 12>::from_element(f64::NAN);
        assert!(exp12(&nan).iter().all(|v| v.is_nan()));
        let dynamic = nalgebra::DMatrix::<f64>::from_element(3, 3, f64::INFINITY);
        assert!(exp_balanced(&dynamic).iter().all(|v| v.is_nan()));
        let small = SMatrix::<f64, 6, 6>::identity() * 0.5;
        assert!((exp6(&small)[(0, 0)] - 0.5f64.exp()).abs() < 1e-15);
    }
}

#[cfg(test)]
mod balanced_tests {
    use super::*;
    use nalgebra::DMatrix;

    #[test]
    fn balanced_exponential_of_a_badly_scaled_oscillator_is_accurate_entrywise() {
        // x'' = -w^2 x in SI-like scaling: A = [[0, 1], [-w^2, 0]], w = 3000 rad/s
        let w: f64 = 3000.0;
        let h = 1e-4;
        let a = DMatrix::from_row_slice(2, 2, &[0.0, h, -w * w * h, 0.0]);
        let e = exp_balanced(&a);
        let (s, c) = (w * h).sin_cos();
        let exact = [c, s / w, -w * s, c];
        for (k, ex) in exact.iter().enumerate() {
            let got = e[(k / 2, k % 2)];
            assert!((got - ex).abs() < 4e-15 * ex.abs(), "{k}: {got} vs {ex}");
        }
        let d = balancing(&a);
        assert!((d[1] / d[0] - w).abs() < w, "{d:?}");
    }
}
