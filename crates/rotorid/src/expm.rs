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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn absurd_matrices_give_nan_not_a_panic() {
        let big = SMatrix::<f64, 6, 6>::from_element(1e300);
        assert!(exp6(&big).iter().all(|v| v.is_nan()));
        let nan = SMatrix::<f64, 12, 12>::from_element(f64::NAN);
        assert!(exp12(&nan).iter().all(|v| v.is_nan()));
        let small = SMatrix::<f64, 6, 6>::identity() * 0.5;
        assert!((exp6(&small)[(0, 0)] - 0.5f64.exp()).abs() < 1e-15);
    }
}
