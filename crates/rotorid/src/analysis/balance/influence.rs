//! Influence coefficients by least squares over every calibration run.
//!
//! For one sensor at one speed (a "key"), run r with added unbalances T_rp \[kg m\] on
//! planes p gives the 1X vector
//!
//! ```text
//! V_r = A + sum_p H_p T_rp + e_r
//! ```
//!
//! with A the vector as found and H_p the influence coefficient of plane p
//! \[sensor unit / (kg m)\]. The 1 + P complex unknowns are fitted to all the runs with a
//! vector of that key, in real form (Re and Im of each equation, Re and Im of each
//! unknown), so that a vector's own 2x2 covariance Sigma_r can weight it: the rows of run r
//! are whitened by L_r^-1 (Sigma_r = L_r L_r^T) when every run of the key has one. The
//! solve is an SVD of the whitened, column-scaled design (the unbalances are ~1e-5 kg m
//! and the constant column 1): a smallest singular value below 1e-10 of the largest means
//! the runs do not separate the planes ([`BalanceError::Undetermined`]).
//!
//! The fit is a linear map of the measured vectors, beta = L v. Their covariance is
//!
//! - the given Sigma_r, scaled by chi^2 / dof (the Birge ratio) when the residuals are
//!   larger than that noise explains: chi^2 = sum of the whitened squared residuals above
//!   its 95 % quantile for dof degrees of freedom (the stated noise is then too small, and
//!   the scatter between runs wins);
//! - without a given noise, s^2 I with s^2 = RSS / dof per real component (dof = 2 n -
//!   2 (1 + P) for n runs): the residuals' own estimate;
//! - unknown (no standard deviation) with neither: n = 1 + P runs fit exactly.
//!
//! and the covariance of the coefficients is L Cov(v) L^T. Reference: Goodman, "A
//! least-squares method for computing balance corrections", J. Eng. Ind. 86, 1964; the
//! weighted form and the Birge ratio: e.g. Bevington & Robinson, *Data reduction and error
//! analysis*, 3rd ed., 2003, ch. 7.

use nalgebra::{Complex, DMatrix, DVector, Matrix2};

use super::data::Assembled;
use super::error::BalanceError;
use crate::analysis::modes::C64;

/// Smallest singular value accepted, relative to the largest, of the scaled design.
const RANK_TOLERANCE: f64 = 1e-10;

/// Where the noise of a key's vectors comes from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum NoiseSource {
    /// The vectors' own standard deviations, multiplied by `scale` >= 1 (the square root
    /// of chi^2 / dof when the residuals are significantly larger than they explain, else
    /// 1).
    Given {
        /// Factor on the standard deviations.
        scale: f64,
    },
    /// The fit's residuals (no standard deviation given for every vector).
    Residuals,
    /// Neither: the runs fit exactly and no standard deviation is given.
    None,
}

/// The fit of one key.
#[derive(Debug, Clone)]
pub struct KeyFit {
    /// The calibration runs used (indices into the run list).
    pub runs: Vec<usize>,
    /// The vector as found, A \[sensor unit\].
    pub as_found: C64,
    /// The influence coefficient of each plane \[sensor unit / (kg m)\].
    pub h: Vec<C64>,
    /// Covariance of (Re A, Im A, Re H_1, Im H_1, ...), when known.
    pub covariance: Option<DMatrix<f64>>,
    /// Real degrees of freedom of the residuals, 2 n - 2 (1 + P).
    pub dof: usize,
    /// RMS of the residual vectors' magnitudes \[sensor unit\].
    pub residual_rms: f64,
    /// Where the noise comes from.
    pub noise: NoiseSource,
    /// The linear map from the runs' vectors (Re, Im of each, in `runs` order) to the
    /// unknowns, (2 + 2P) x 2n.
    pub(crate) map: DMatrix<f64>,
    /// The covariance of each run's vector used for the standard deviations, when known.
    pub(crate) run_covariance: Option<Vec<Matrix2<f64>>>,
}

/// The real 2x2 matrix of multiplication by `t`: (Re(t h), Im(t h)) = M (Re h, Im h).
fn mul_matrix(t: C64) -> Matrix2<f64> {
    Matrix2::new(t.re, -t.im, t.im, t.re)
}

/// The 95 % quantile of the chi-square distribution with `dof` degrees of freedom, by the
/// Wilson-Hilferty approximation (within 1 % of the exact quantile for dof >= 2, 3 % at 1).
pub(crate) fn chi2_quantile_95(dof: usize) -> f64 {
    let k = dof as f64;
    let c = 2.0 / (9.0 * k);
    k * (1.0 - c + 1.644_853_6 * c.sqrt()).powi(3)
}

/// The inverse of the lower Cholesky factor of `s`, or `None` when `s` is not positive
/// definite (a zero standard deviation).
fn whitening(s: &Matrix2<f64>) -> Option<Matrix2<f64>> {
    let c = s.cholesky()?;
    let l = c.l();
    let inv = l.try_inverse()?;
    inv.iter().all(|v| v.is_finite()).then_some(inv)
}

/// Fit key `key` of `a` (module doc).
pub(crate) fn fit_key(a: &Assembled, key: usize) -> Result<KeyFit, BalanceError> {
    let np = a.planes.len();
    let m = 2 * (1 + np);
    let (sensor, speed_rpm) = a.key(key);
    let used: Vec<(usize, usize)> = a
        .calibration
        .iter()
        .enumerate()
        .filter(|&(_, &r)| a.vector[key][r].is_some())
        .map(|(c, &r)| (c, r))
        .collect();
    let n = used.len();
    if n < 1 + np {
        return Err(BalanceError::TooFewRuns {
            sensor: sensor.to_owned(),
            speed_rpm,
            runs: n,
            planes: np,
            needed: 1 + np,
        });
    }
    let obs: Vec<(C64, Option<Matrix2<f64>>)> = used
        .iter()
        .map(|&(_, r)| a.vector[key][r].expect("filtered above"))
        .collect();
    // whitening of each run, when every run has a usable covariance
    let white: Option<Vec<Matrix2<f64>>> = obs
        .iter()
        .map(|(_, c)| c.as_ref().and_then(whitening))
        .collect();
    let mut x = DMatrix::<f64>::zeros(2 * n, m);
    let mut v = DVector::<f64>::zeros(2 * n);
    for (i, &(c, _)) in used.iter().enumerate() {
        let mut block = DMatrix::<f64>::zeros(2, m);
        block
            .fixed_view_mut::<2, 2>(0, 0)
            .copy_from(&Matrix2::identity());
        for p in 0..np {
            block
                .fixed_view_mut::<2, 2>(0, 2 + 2 * p)
                .copy_from(&mul_matrix(a.trial[c][p]));
        }
        x.view_mut((2 * i, 0), (2, m)).copy_from(&block);
        v[2 * i] = obs[i].0.re;
        v[2 * i + 1] = obs[i].0.im;
    }
    // whitening operator (block diagonal), identity without given noise
    let mut w = DMatrix::<f64>::identity(2 * n, 2 * n);
    if let Some(ws) = &white {
        for (i, wi) in ws.iter().enumerate() {
            w.fixed_view_mut::<2, 2>(2 * i, 2 * i).copy_from(wi);
        }
    }
    let xw = &w * &x;
    let scale = DVector::from_iterator(
        m,
        xw.column_iter().map(|c| {
            let s = c.norm();
            if s > 0.0 {
                1.0 / s
            } else {
                1.0
            }
        }),
    );
    let xs = &xw * DMatrix::from_diagonal(&scale);
    let svd = xs.clone().svd(true, true);
    let (u, vt) = (
        svd.u.as_ref().expect("asked for"),
        svd.v_t.as_ref().expect("asked for"),
    );
    let smax = svd.singular_values.max();
    let smin = svd.singular_values.min();
    if !(smax > 0.0 && smin > RANK_TOLERANCE * smax) {
        return Err(BalanceError::Undetermined {
            sensor: sensor.to_owned(),
            speed_rpm,
            runs: super::data::list(used.iter().map(|&(_, r)| format!("{:?}", a.runs[r]))),
        });
    }
    let sinv = DMatrix::from_diagonal(&svd.singular_values.map(|s| 1.0 / s));
    // beta = D V S^-1 U^T W v
    let map = DMatrix::from_diagonal(&scale) * vt.transpose() * sinv * u.transpose() * &w;
    let beta = &map * &v;
    let resid = &v - &x * &beta;
    let dof = 2 * n - m;
    let rss: f64 = resid.iter().map(|e| e * e).sum();
    let residual_rms = (rss / n as f64).sqrt();
    let (noise, run_covariance) = match &white {
        Some(_) => {
            let chi2 = (&w * &resid).norm_squared();
            let f = if dof > 0 && chi2 > chi2_quantile_95(dof) {
                chi2 / dof as f64
            } else {
                1.0
            };
            let covs = obs
                .iter()
                .map(|(_, c)| c.expect("checked: every run has one") * f)
                .collect();
            (NoiseSource::Given { scale: f.sqrt() }, Some(covs))
        }
        None if dof > 0 => {
            let s2 = rss / dof as f64;
            (
                NoiseSource::Residuals,
                Some(vec![Matrix2::identity() * s2; n]),
            )
        }
        None => (NoiseSource::None, None),
    };
    let covariance = run_covariance.as_ref().map(|covs| {
        let mut s = DMatrix::<f64>::zeros(2 * n, 2 * n);
        for (i, c) in covs.iter().enumerate() {
            s.fixed_view_mut::<2, 2>(2 * i, 2 * i).copy_from(c);
        }
        &map * s * map.transpose()
    });
    let as_found = Complex::new(beta[0], beta[1]);
    let h = (0..np)
        .map(|p| Complex::new(beta[2 + 2 * p], beta[3 + 2 * p]))
        .collect();
    Ok(KeyFit {
        runs: used.iter().map(|&(_, r)| r).collect(),
        as_found,
        h,
        covariance,
        dof,
        residual_rms,
        noise,
        map,
        run_covariance,
    })
}

impl KeyFit {
    /// Standard deviations of Re H_p and Im H_p, when known.
    pub fn h_std(&self, p: usize) -> Option<(f64, f64)> {
        self.covariance.as_ref().map(|c| {
            (
                c[(2 + 2 * p, 2 + 2 * p)].max(0.0).sqrt(),
                c[(3 + 2 * p, 3 + 2 * p)].max(0.0).sqrt(),
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::data::{assemble, MassInput, VectorInput};
    use super::*;

    #[test]
    fn the_chi_square_quantile_is_close_to_the_tables() {
        // 95 % quantiles: 1 -> 3.841, 2 -> 5.991, 4 -> 9.488, 10 -> 18.307, 30 -> 43.773
        for (k, q) in [
            (1, 3.841),
            (2, 5.991),
            (4, 9.488),
            (10, 18.307),
            (30, 43.773),
        ] {
            let tol = if k == 1 { 0.03 } else { 0.01 };
            assert!(
                (chi2_quantile_95(k) / q - 1.0).abs() < tol,
                "{k}: {}",
                chi2_quantile_95(k)
            );
        }
    }

    #[test]
    fn the_fit_is_the_complex_least_squares_solution() {
        // 2 planes, 5 runs, one sensor at one speed, inconsistent data: the real-form fit
        // equals the complex normal equations (X^H X) beta = X^H v solved independently
        let t = [
            [Complex::new(0.0, 0.0), Complex::new(0.0, 0.0)],
            [Complex::from_polar(2e-5, 0.3), Complex::new(0.0, 0.0)],
            [Complex::new(0.0, 0.0), Complex::from_polar(3e-5, 2.0)],
            [
                Complex::from_polar(1e-5, 4.0),
                Complex::from_polar(1e-5, 1.0),
            ],
            [
                Complex::from_polar(2e-5, 5.0),
                Complex::from_polar(2e-5, 3.0),
            ],
        ];
        let obs = [
            Complex::new(10.0, -3.0),
            Complex::new(14.0, 1.0),
            Complex::new(6.5, -9.0),
            Complex::new(11.0, -1.5),
            Complex::new(9.0, 2.0),
        ];
        let mut vectors = Vec::new();
        let mut masses = Vec::new();
        for (r, (tr, v)) in t.iter().zip(&obs).enumerate() {
            let run = format!("r{r}");
            vectors.push(VectorInput::new(&run, 1000.0, "s", "um", v.re, v.im, None));
            for (p, u) in tr.iter().enumerate() {
                masses.push(MassInput {
                    run: run.clone(),
                    plane: format!("p{p}"),
                    mass: u.norm() / 0.1,
                    radius: 0.1,
                    angle: u.arg(),
                });
            }
        }
        let a = assemble(&vectors, &masses, None).unwrap();
        let f = fit_key(&a, 0).unwrap();
        let x = DMatrix::<C64>::from_fn(5, 3, |i, j| {
            if j == 0 {
                Complex::new(1.0, 0.0)
            } else {
                t[i][j - 1]
            }
        });
        let y = DVector::from_column_slice(&obs);
        let xh = x.adjoint();
        let beta = (&xh * &x).try_inverse().unwrap() * (&xh * &y);
        assert!((f.as_found - beta[0]).norm() < 1e-9 * beta[0].norm());
        for p in 0..2 {
            assert!((f.h[p] - beta[1 + p]).norm() < 1e-9 * beta[1 + p].norm());
        }
        assert_eq!(f.dof, 4);
        assert_eq!(f.noise, NoiseSource::Residuals);
        // circular noise: Cov(beta) = s^2 (X^H X)^-1 in complex form, half of it on each
        // of Re and Im
        let resid = &y - &x * &beta;
        let s2c = resid.norm_squared() / (5 - 3) as f64;
        let g = (&xh * &x).try_inverse().unwrap();
        let c = f.covariance.as_ref().unwrap();
        for j in 0..3 {
            let want = 0.5 * s2c * g[(j, j)].re;
            assert!((c[(2 * j, 2 * j)] / want - 1.0).abs() < 1e-9);
            assert!((c[(2 * j + 1, 2 * j + 1)] / want - 1.0).abs() < 1e-9);
        }
    }
}
