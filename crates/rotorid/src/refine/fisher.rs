//! The Fisher information of the output-error problem and what is read from it.
//!
//! For white Gaussian noise of standard deviation sigma_x on x and sigma_z on z,
//!
//! ```text
//! F = J_x^T J_x / sigma_x^2 + J_z^T J_z / sigma_z^2,       Cov(theta_hat) >= F^-1   (Cramer-Rao)
//! ```
//!
//! (S. M. Kay, *Fundamentals of Statistical Signal Processing: Estimation Theory*, 1993,
//! ch. 3). F is scaled to unit diagonal, Fs = D^-1 F D^-1 with D = diag(sqrt(F_ii)), and
//! decomposed Fs = V diag(l) V^T. Directions with l_j <= NULL_TOL * l_max carry no
//! information: a parameter with weight sum_(null j) V_ij^2 > NULL_WEIGHT in them is not
//! identifiable (its standard error is +infinity). Elsewhere
//!
//! ```text
//! Cov = D^-1 [ sum_(j not null) v_j v_j^T / l_j ] D^-1
//! ```
//!
//! The same decomposition gives the Levenberg-Marquardt step (Marquardt's scaling:
//! damping mu on the unit diagonal of Fs), delta = D^-1 sum_j v_j (v_j^T D^-1 g) / (l_j + mu).

use nalgebra::{DMatrix, SymmetricEigen};

/// Relative eigenvalue below which a direction of the scaled Fisher information is null.
pub(crate) const NULL_TOL: f64 = 1e-13;
/// A parameter with more than this squared weight in the null directions is unidentifiable.
/// Exact null directions give weights down to ~1e-6 for weakly informed parameters (c when
/// m, c, k, a and the unbalance are all unknown: the equation is homogeneous in them), while
/// parameters outside the null space sit at the rounding level (~1e-30).
pub(crate) const NULL_WEIGHT: f64 = 1e-16;

/// Eigen-analysis of one Fisher information matrix.
#[derive(Debug, Clone)]
pub(crate) struct Fisher {
    n: usize,
    scale: Vec<f64>,
    informed: Vec<usize>,
    vals: Vec<f64>,
    vecs: DMatrix<f64>,
    null: Vec<bool>,
    /// l_max / l_min of the scaled information (+inf when singular or when a parameter
    /// has no information at all).
    pub condition_number: f64,
    /// Per column: true when the data carry no information on it (alone or in combination).
    pub unidentifiable: Vec<bool>,
    /// Covariance F^-1 (n x n, row-major); rows and columns of unidentifiable parameters
    /// are +infinity on the diagonal and NaN elsewhere.
    pub cov: Vec<f64>,
}

impl Fisher {
    /// Analyse the symmetric n x n matrix `f` (row-major).
    pub(crate) fn new(f: &[f64], n: usize) -> Self {
        let scale: Vec<f64> = (0..n)
            .map(|i| {
                let d = f[i * n + i];
                if d.is_finite() && d > 0.0 {
                    d.sqrt()
                } else {
                    0.0
                }
            })
            .collect();
        let informed: Vec<usize> = (0..n).filter(|&i| scale[i] > 0.0).collect();
        let m = informed.len();
        let fs = DMatrix::from_fn(m, m, |a, b| {
            let (i, j) = (informed[a], informed[b]);
            f[i * n + j] / (scale[i] * scale[j])
        });
        let (vals, vecs) = if m > 0 {
            let e = SymmetricEigen::new(fs);
            (
                e.eigenvalues.iter().copied().collect::<Vec<_>>(),
                e.eigenvectors,
            )
        } else {
            (Vec::new(), DMatrix::zeros(0, 0))
        };
        let l_max = vals.iter().fold(0.0f64, |a, &l| a.max(l));
        let l_min = vals.iter().fold(f64::INFINITY, |a, &l| a.min(l));
        let null: Vec<bool> = vals
            .iter()
            .map(|&l| l.is_nan() || l <= NULL_TOL * l_max)
            .collect();
        let mut unidentifiable = vec![true; n];
        for (a, &i) in informed.iter().enumerate() {
            let w: f64 = (0..m)
                .filter(|&j| null[j])
                .map(|j| vecs[(a, j)].powi(2))
                .sum();
            unidentifiable[i] = w > NULL_WEIGHT;
        }
        let condition_number = if m < n || m == 0 || l_min <= 0.0 {
            f64::INFINITY
        } else {
            l_max / l_min
        };
        let mut cov = vec![f64::NAN; n * n];
        for (a, &i) in informed.iter().enumerate() {
            for (b, &j) in informed.iter().enumerate() {
                if unidentifiable[i] || unidentifiable[j] {
                    continue;
                }
                let s: f64 = (0..m)
                    .filter(|&k| !null[k])
                    .map(|k| vecs[(a, k)] * vecs[(b, k)] / vals[k])
                    .sum();
                cov[i * n + j] = s / (scale[i] * scale[j]);
            }
        }
        for i in 0..n {
            if unidentifiable[i] {
                cov[i * n + i] = f64::INFINITY;
            }
        }
        Self {
            n,
            scale,
            informed,
            vals,
            vecs,
            null,
            condition_number,
            unidentifiable,
            cov,
        }
    }

    /// The rank of the information: informed directions that are not null.
    pub(crate) fn rank(&self) -> usize {
        self.null.iter().filter(|&&n| !n).count()
    }

    /// The columns that take part in the least informed direction (the eigenvector of the
    /// smallest eigenvalue of the scaled information, null or not): those whose squared
    /// weight in it exceeds `share`, largest first. These are the unknowns the record
    /// hardly tells apart.
    pub(crate) fn weakest(&self, share: f64) -> Vec<usize> {
        let m = self.informed.len();
        let Some(k) = (0..m).min_by(|&a, &b| self.vals[a].total_cmp(&self.vals[b])) else {
            return Vec::new();
        };
        let mut w: Vec<(usize, f64)> = (0..m)
            .map(|a| (self.informed[a], self.vecs[(a, k)].powi(2)))
            .filter(|&(_, v)| v > share)
            .collect();
        w.sort_by(|a, b| b.1.total_cmp(&a.1));
        w.into_iter().map(|(i, _)| i).collect()
    }

    /// Standard deviation sqrt(Cov_ii) (+inf when unidentifiable).
    pub(crate) fn std(&self, i: usize) -> f64 {
        self.cov[i * self.n + i].sqrt()
    }

    /// The damped Gauss-Newton step for the gradient g = J^T W r, damping `mu` >= 0 on the
    /// unit diagonal of the scaled information; zero along null directions. Also returns
    /// the step's length in standard errors, sqrt(delta^T F delta).
    pub(crate) fn step(&self, g: &[f64], mu: f64) -> (Vec<f64>, f64) {
        let m = self.informed.len();
        let gs: Vec<f64> = self
            .informed
            .iter()
            .map(|&i| g[i] / self.scale[i])
            .collect();
        let mut ds = vec![0.0; m];
        let mut len2 = 0.0;
        for k in 0..m {
            if self.null[k] {
                continue;
            }
            let proj: f64 = (0..m).map(|a| self.vecs[(a, k)] * gs[a]).sum();
            let c = proj / (self.vals[k] + mu);
            len2 += self.vals[k] * c * c;
            for (a, d) in ds.iter_mut().enumerate() {
                *d += self.vecs[(a, k)] * c;
            }
        }
        let mut delta = vec![0.0; self.n];
        for (a, &i) in self.informed.iter().enumerate() {
            delta[i] = ds[a] / self.scale[i];
        }
        (delta, len2.sqrt())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inverse_of_a_regular_matrix() {
        // F = [[4, 1], [1, 3]] -> F^-1 = [[3, -1], [-1, 4]] / 11
        let f = [4.0, 1.0, 1.0, 3.0];
        let a = Fisher::new(&f, 2);
        let want = [3.0 / 11.0, -1.0 / 11.0, -1.0 / 11.0, 4.0 / 11.0];
        for (c, w) in a.cov.iter().zip(want) {
            assert!((c - w).abs() < 1e-15);
        }
        let (d, len) = a.step(&[1.0, 2.0], 0.0);
        assert!((d[0] - (3.0 - 2.0) / 11.0).abs() < 1e-15);
        assert!((d[1] - (-1.0 + 8.0) / 11.0).abs() < 1e-15);
        // len^2 = d^T F d = g^T F^-1 g
        assert!((len * len - (d[0] + 2.0 * d[1])).abs() < 1e-14);
        assert!(!a.unidentifiable.iter().any(|&u| u));
    }

    #[test]
    fn a_combination_without_information_is_flagged() {
        // theta_0 and theta_1 enter only as their sum; theta_2 is free.
        let f = [1.0, 1.0, 0.0, 1.0, 1.0, 0.0, 0.0, 0.0, 2.0];
        let a = Fisher::new(&f, 3);
        assert_eq!(a.unidentifiable, vec![true, true, false]);
        assert!(a.std(0).is_infinite() && a.std(1).is_infinite());
        assert!((a.std(2) - 0.5f64.sqrt()).abs() < 1e-15);
        assert!(a.condition_number.is_infinite());
        // no step along the null direction (1, -1)
        let (d, _) = a.step(&[1.0, 1.0, 0.0], 0.0);
        assert!((d[0] - d[1]).abs() < 1e-15);
    }

    #[test]
    fn the_weakest_direction_names_the_correlated_pair() {
        // theta_0 and theta_1 nearly equal in effect (correlation 0.999999), theta_2 apart
        let c = 0.999_999;
        let f = [1.0, c, 0.0, c, 1.0, 0.0, 0.0, 0.0, 3.0];
        let a = Fisher::new(&f, 3);
        assert_eq!(a.rank(), 3);
        let mut w = a.weakest(0.1);
        w.sort();
        assert_eq!(w, vec![0, 1]);
        assert!((a.condition_number - (1.0 + c) / (1.0 - c)).abs() < 1e-3 * a.condition_number);
        let sing = Fisher::new(&[1.0, 1.0, 1.0, 1.0], 2);
        assert_eq!(sing.rank(), 1);
    }

    #[test]
    fn a_parameter_without_any_information_is_flagged() {
        let f = [2.0, 0.0, 0.0, 0.0];
        let a = Fisher::new(&f, 2);
        assert_eq!(a.unidentifiable, vec![false, true]);
        assert_eq!(a.step(&[1.0, 5.0], 0.0).0[1], 0.0);
    }
}
