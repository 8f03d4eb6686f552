//! Least squares over the stacked window equations of one direction, with compensation of
//! the bias that noise in the regressors causes (errors in variables).
//!
//! Every window j and test function i give one row r = (phi_r, y_r), phi_r in R^P (P = 3
//! for the Jeffcott rows, 5 for the cross-coupled rows of module `cross`),
//! `phi_r . theta_s = y_r` with theta_s the scaled unknowns (module docs of [`super`]).
//! The rows are accumulated into the (P+1)x(P+1) Gram G = sum_r (phi_r, y_r)(phi_r, y_r)^T
//! (its y-y entry is never needed), so memory does not grow with the record.
//!
//! Noise. With white noise of standard deviation sigma on the displacement in the
//! regressors, phi_r = phi_r0 + sum_k g_r(k) n_k, g_r(k) = (psi_i'', -psi_i', psi_i)(u_k)
//! (u-derivatives, [`super::test_functions`]), so
//!
//! ```text
//! E[ sum_r phi_r phi_r^T ] = sum_r phi_r0 phi_r0^T + sigma^2 W N0,
//! N0 = sum_i sum_k g_i(k) g_i(k)^T            (one window; every window has the same shape)
//! ```
//!
//! with W the number of windows. Plain least squares is therefore biased by O(sigma^2)
//! (towards zero in the psi'' column, i.e. m, mostly). The right-hand side y holds the
//! *other* direction's displacement (coupling) and known forcing, whose noise is
//! independent of the regressors' noise, so E[sum_r phi_r y_r] needs no correction. The
//! compensated estimate (Söderström, "Errors-in-variables methods in system
//! identification", Automatica 43, 2007, bias-compensated least squares) is
//!
//! ```text
//! H = G[0..3, 0..3] - sigma^2 W N0,     b = G[0..3, 3],     theta_s = H^-1 b.
//! ```
//!
//! (The cross-coupled rows hold the other channel in their regressors too, and their
//! right-hand side shares noise with them: module `cross` subtracts the expected noise
//! part from b as well, `solve`'s second argument.)
//!
//! H is equilibrated to unit diagonal (D = diag(G_ii)^1/2, Hs = D^-1 H D^-1) before it is
//! factored; the conditioning figure is rcond = lambda_min(Hs) / lambda_max(Hs), the
//! reciprocal 2-norm condition number of the equilibrated normal matrix (the square of
//! that of the equilibrated design matrix). rcond <= 0 (compensation made H indefinite:
//! noise too large for the information in the data) or a non-finite value gives the
//! singular answer (NaN), not an error.

use nalgebra::{Cholesky, Const, SMatrix, SVector};

/// The Gram of the rows (phi, y) of one direction, phi in R^P: sum phi phi^T, sum phi y
/// (sum y^2 is never needed).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Gram<const P: usize> {
    hh: [[f64; P]; P],
    hy: [f64; P],
    rows: u64,
}

impl<const P: usize> Default for Gram<P> {
    fn default() -> Self {
        Self {
            hh: [[0.0; P]; P],
            hy: [0.0; P],
            rows: 0,
        }
    }
}

/// A solution of the compensated normal equations.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Solution<const P: usize> {
    /// theta_s (NaN when singular).
    pub theta: [f64; P],
    /// Reciprocal 2-norm condition number of the equilibrated normal matrix (0 when
    /// singular).
    pub rcond: f64,
    /// H^-1, the inverse of the compensated normal matrix (NaN when singular).
    pub h_inv: [[f64; P]; P],
}

impl<const P: usize> Solution<P> {
    const SINGULAR: Self = Self {
        theta: [f64::NAN; P],
        rcond: 0.0,
        h_inv: [[f64::NAN; P]; P],
    };
}

/// The extreme eigenvalues (lowest, highest) of a symmetric matrix (nalgebra's symmetric
/// eigenvalue solver needs a concrete size).
pub(crate) trait ExtremeEigenvalues {
    fn extreme_eigenvalues(&self) -> (f64, f64);
}

impl ExtremeEigenvalues for SMatrix<f64, 3, 3> {
    fn extreme_eigenvalues(&self) -> (f64, f64) {
        let eig = self.symmetric_eigenvalues();
        (eig.min(), eig.max())
    }
}

impl ExtremeEigenvalues for SMatrix<f64, 5, 5> {
    fn extreme_eigenvalues(&self) -> (f64, f64) {
        let eig = self.symmetric_eigenvalues();
        (eig.min(), eig.max())
    }
}

impl<const P: usize> Gram<P>
where
    SMatrix<f64, P, P>: ExtremeEigenvalues,
{
    /// Add one row (phi, y).
    #[inline]
    pub(crate) fn add(&mut self, phi: &[f64; P], y: f64) {
        for i in 0..P {
            for j in i..P {
                self.hh[i][j] += phi[i] * phi[j];
            }
            self.hy[i] += phi[i] * y;
        }
        self.rows += 1;
    }

    /// Solve with the noise terms `noise_h` (= E[noise part of sum phi phi^T]) subtracted
    /// from the regressor block and `noise_b` (= E[noise part of sum phi y]) from the
    /// right-hand side (zeros for plain least squares).
    pub(crate) fn solve(&self, noise_h: &[[f64; P]; P], noise_b: &[f64; P]) -> Solution<P> {
        let g = |i: usize, j: usize| if i <= j { self.hh[i][j] } else { self.hh[j][i] };
        let d: [f64; P] = std::array::from_fn(|i| g(i, i).sqrt());
        if self.rows < P as u64 || d.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
            return Solution::SINGULAR;
        }
        let hs = SMatrix::<f64, P, P>::from_fn(|i, j| (g(i, j) - noise_h[i][j]) / (d[i] * d[j]));
        let bs = SVector::<f64, P>::from_fn(|i, _| (self.hy[i] - noise_b[i]) / d[i]);
        if !hs.iter().chain(bs.iter()).all(|v| v.is_finite()) {
            return Solution::SINGULAR;
        }
        let (lo, hi) = hs.extreme_eigenvalues();
        if !(lo > 0.0 && hi > 0.0) {
            return Solution::SINGULAR;
        }
        let Some(chol) = Cholesky::<f64, Const<P>>::new(hs) else {
            return Solution::SINGULAR;
        };
        let ts = chol.solve(&bs);
        let theta: [f64; P] = std::array::from_fn(|i| ts[i] / d[i]);
        // H^-1 = D^-1 Hs^-1 D^-1
        let hs_inv = chol.inverse();
        let h_inv: [[f64; P]; P] =
            std::array::from_fn(|i| std::array::from_fn(|j| hs_inv[(i, j)] / (d[i] * d[j])));
        if theta.iter().all(|v| v.is_finite()) {
            Solution {
                theta,
                rcond: lo / hi,
                h_inv,
            }
        } else {
            Solution::SINGULAR
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exact_rows_give_the_exact_solution_at_any_scale() {
        let theta = [14.29e-3, -2.5, 1.195e6];
        let mut g = Gram::<3>::default();
        for i in 0..20 {
            let fi = i as f64;
            let phi = [
                1e3 * (0.3 * fi).sin(),
                7.0 * (1.1 * fi).cos(),
                1e-3 * (0.1 + fi),
            ];
            let y = phi[0] * theta[0] + phi[1] * theta[1] + phi[2] * theta[2];
            g.add(&phi, y);
        }
        let s = g.solve(&[[0.0; 3]; 3], &[0.0; 3]);
        for (got, want) in s.theta.iter().zip(theta) {
            assert!((got - want).abs() < 1e-12 * want.abs(), "{s:?}");
        }
        assert!(s.rcond > 1e-4 && s.rcond <= 1.0);
    }

    #[test]
    fn too_few_or_dependent_rows_are_singular_not_a_panic() {
        let mut g = Gram::<3>::default();
        g.add(&[1.0, 2.0, 3.0], 4.0);
        g.add(&[2.0, 4.0, 6.0], 8.0);
        assert_eq!(g.solve(&[[0.0; 3]; 3], &[0.0; 3]).rcond, 0.0);
        g.add(&[3.0, 6.0, 9.0], 12.0);
        let s = g.solve(&[[0.0; 3]; 3], &[0.0; 3]);
        assert_eq!(s.rcond, 0.0);
        assert!(s.theta[0].is_nan());
    }

    #[test]
    fn compensation_removes_the_errors_in_variables_bias() {
        // one regressor column measured with noise of known variance: y = 2 phi0.
        // sum (phi0 + e)^2 = sum phi0^2 + n s^2 in expectation; subtracting n s^2 restores 2.
        let mut g = Gram::<3>::default();
        let n = 4000;
        let s2 = 0.25;
        let mut noise = 0.0;
        for k in 0..n {
            let p0 = ((k as f64) * 0.37).sin();
            // deterministic "noise" with mean square s2, uncorrelated with p0 on average
            let e = if (k / 3) % 2 == 0 { 0.5 } else { -0.5 };
            noise += e * e;
            let other = [((k as f64) * 1.3).cos(), ((k as f64) * 0.011).cos()];
            g.add(
                &[p0 + e, other[0], other[1]],
                2.0 * p0 + 0.1 * other[0] + other[1],
            );
        }
        assert!((noise / n as f64 - s2).abs() < 1e-12);
        let plain = g.solve(&[[0.0; 3]; 3], &[0.0; 3]).theta[0];
        let comp = g
            .solve(&[[noise, 0.0, 0.0], [0.0; 3], [0.0; 3]], &[0.0; 3])
            .theta[0];
        assert!((plain - 2.0).abs() > 0.5, "plain {plain}");
        assert!((comp - 2.0).abs() < 0.05, "compensated {comp}");
    }
}
