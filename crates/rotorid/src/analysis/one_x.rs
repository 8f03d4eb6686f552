//! The 1X (synchronous) vector of a measured signal against the shaft angle, by linear
//! least squares on a constant and the first harmonic of the shaft angle phi_k:
//!
//! ```text
//! s_k = c + a cos(phi_k) + b sin(phi_k) + e_k  =  c + Re( V e^{i phi_k} ) + e_k,    V = a - i b
//! ```
//!
//! (the same 1X vector as the response module: amplitude |V| peak, phase lag
//! beta = -arg V from the keyphasor phi = 0 to the positive peak). The constant absorbs a
//! probe's gap offset. The standard errors are those of least squares for white
//! residuals, Cov(c, a, b) = sigma^2 (A^T A)^-1 with sigma^2 = RSS / (n - 3); residuals
//! that are not white (a free transient, other harmonics) make them optimistic.
//!
//! The vector is the average 1X content of the samples given: pass samples at one
//! (nearly) constant speed. It is undefined (`None`) when the normal matrix is singular to
//! rounding, e.g. when the shaft does not turn.
//! Reference: order tracking by least squares, e.g. R. B. Randall, *Vibration-based
//! condition monitoring*, Wiley, 2011, sec. 3.6.

use nalgebra::{Complex, Matrix2, Matrix3, SymmetricEigen, Vector3};

use super::error::{check_finite, AnalysisError};
use super::modes::C64;
use super::response::phase_lag;

/// The normal matrix scaled to unit diagonal must have a smallest eigenvalue above this
/// (its condition number below ~1e10), else the vector is undefined.
const MIN_EIGENVALUE: f64 = 1e-10;

/// The 1X vector of a signal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OneX {
    /// V \[signal unit\]: the 1X part of the signal is Re(V e^{i phi}).
    pub vector: C64,
    /// |V| \[signal unit\], peak (zero-to-peak).
    pub amplitude: f64,
    /// Phase lag beta = -arg V \[rad\] in \[0, 2 pi).
    pub phase_lag: f64,
    /// The constant c \[signal unit\].
    pub offset: f64,
    /// Covariance of (Re V, Im V) \[signal unit^2\] (module doc).
    pub covariance: Matrix2<f64>,
    /// RMS of the residuals e_k \[signal unit\].
    pub residual_rms: f64,
    /// Number of samples used.
    pub samples: usize,
}

/// The 1X vector of `signal` against the shaft angle `phi` \[rad\] (same length, at least
/// 4 samples, all finite; phi wrapped or not). `Ok(None)` when the samples do not
/// determine it (module doc).
pub fn one_x(signal: &[f64], phi: &[f64]) -> Result<Option<OneX>, AnalysisError> {
    let n = signal.len();
    if phi.len() != n {
        return Err(AnalysisError::LengthMismatch {
            field: "phi",
            len: phi.len(),
            other: "signal",
            expected: n,
        });
    }
    if n < 4 {
        return Err(AnalysisError::TooFew {
            field: "signal",
            len: n,
            needed: 4,
        });
    }
    check_finite("signal", signal)?;
    check_finite("phi", phi)?;
    // scale the signal so its squares stay well inside the range of f64
    let scale = signal.iter().fold(0.0f64, |m, s| m.max(s.abs()));
    let scale = if scale > 0.0 { scale } else { 1.0 };
    let mut ata = Matrix3::zeros();
    let mut atb = Vector3::zeros();
    for (&s, &p) in signal.iter().zip(phi) {
        let (sn, cs) = p.sin_cos();
        let row = Vector3::new(1.0, cs, sn);
        ata += row * row.transpose();
        atb += row * (s / scale);
    }
    let d = ata.diagonal().map(|v| 1.0 / v.sqrt());
    let scaled = Matrix3::from_fn(|i, j| ata[(i, j)] * d[i] * d[j]);
    let eig = SymmetricEigen::new(scaled);
    let smallest = eig.eigenvalues.min();
    if smallest.is_nan() || smallest <= MIN_EIGENVALUE {
        return Ok(None);
    }
    let inv_scaled = eig.eigenvectors
        * Matrix3::from_diagonal(&eig.eigenvalues.map(|l| 1.0 / l))
        * eig.eigenvectors.transpose();
    let inv = Matrix3::from_fn(|i, j| inv_scaled[(i, j)] * d[i] * d[j]);
    let theta = inv * atb;
    let rss: f64 = signal
        .iter()
        .zip(phi)
        .map(|(&s, &p)| {
            let (sn, cs) = p.sin_cos();
            let e = s / scale - (theta[0] + theta[1] * cs + theta[2] * sn);
            e * e
        })
        .sum();
    let sigma2 = rss / (n - 3) as f64;
    let (c, a, b) = (theta[0] * scale, theta[1] * scale, theta[2] * scale);
    let v = Complex::new(a, -b);
    let s2 = sigma2 * scale * scale;
    // (Re V, Im V) = (a, -b)
    let covariance = Matrix2::new(
        s2 * inv[(1, 1)],
        -s2 * inv[(1, 2)],
        -s2 * inv[(2, 1)],
        s2 * inv[(2, 2)],
    );
    Ok(Some(OneX {
        vector: v,
        amplitude: v.norm(),
        phase_lag: phase_lag(v),
        offset: c,
        covariance,
        residual_rms: (rss / n as f64).sqrt() * scale,
        samples: n,
    }))
}

/// The 1X vector of `signal` by synchronous averaging over whole revolutions of `phi`
/// \[rad\] (increasing): the 1X vector of each whole revolution (the least squares above,
/// over that revolution's samples, at least 4), averaged over the revolutions,
///
/// ```text
/// V = (1 / n) sum_j V_j,     Cov(Re V, Im V) = S / n,   S the sample covariance of the V_j
/// ```
///
/// so the noise estimate is the vectors' own scatter from revolution to revolution: it
/// counts non-synchronous content (a transient, noise of any colour, speed jitter) as it
/// actually varies the 1X vector, where the whole-record least squares of [`one_x`]
/// assumes white residuals. Needs at least 2 whole revolutions; `Ok(None)` with fewer,
/// or when a revolution does not determine its vector. `residual_rms` and `offset` are
/// the means over the revolutions; `samples` counts the samples in whole revolutions.
pub fn synchronous_average(signal: &[f64], phi: &[f64]) -> Result<Option<OneX>, AnalysisError> {
    let n = signal.len();
    if phi.len() != n {
        return Err(AnalysisError::LengthMismatch {
            field: "phi",
            len: phi.len(),
            other: "signal",
            expected: n,
        });
    }
    check_finite("signal", signal)?;
    check_finite("phi", phi)?;
    let Some(&first) = phi.first() else {
        return Ok(None);
    };
    // revolution boundaries: the first sample at or past each multiple of 2 pi after phi_0
    let tau = std::f64::consts::TAU;
    let start = (first / tau).ceil();
    let mut edges = Vec::new();
    let mut next = start * tau;
    for (i, &p) in phi.iter().enumerate() {
        if p >= next {
            edges.push(i);
            next += tau;
            while p >= next {
                next += tau;
            }
        }
    }
    let mut vectors = Vec::new();
    let (mut offset, mut rms, mut used) = (0.0, 0.0, 0);
    for w in edges.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b - a < 4 || phi[b] - phi[a] > 1.5 * tau {
            continue;
        }
        match one_x(&signal[a..b], &phi[a..b])? {
            Some(v) => {
                vectors.push(v.vector);
                offset += v.offset;
                rms += v.residual_rms * v.residual_rms;
                used += b - a;
            }
            None => return Ok(None),
        }
    }
    let k = vectors.len();
    if k < 2 {
        return Ok(None);
    }
    let kf = k as f64;
    let mean = vectors.iter().sum::<C64>() / kf;
    let mut s = Matrix2::zeros();
    for v in &vectors {
        let d = v - mean;
        s += Matrix2::new(d.re * d.re, d.re * d.im, d.im * d.re, d.im * d.im);
    }
    let covariance = s / ((kf - 1.0) * kf);
    Ok(Some(OneX {
        vector: mean,
        amplitude: mean.norm(),
        phase_lag: phase_lag(mean),
        offset: offset / kf,
        covariance,
        residual_rms: (rms / kf).sqrt(),
        samples: used,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recovers_amplitude_lag_and_offset_exactly() {
        let phi: Vec<f64> = (0..500).map(|k| 0.0371 * k as f64 + 0.2).collect();
        let (amp, lag, off) = (2.5e-7, 4.0, -3e-8);
        let s: Vec<f64> = phi.iter().map(|p| off + amp * (p - lag).cos()).collect();
        let v = one_x(&s, &phi).unwrap().unwrap();
        assert!((v.amplitude - amp).abs() < 1e-12 * amp);
        assert!((v.phase_lag - lag).abs() < 1e-11);
        assert!((v.offset - off).abs() < 1e-12 * amp);
        assert!(v.residual_rms < 1e-12 * amp);
    }

    #[test]
    fn a_shaft_that_does_not_turn_gives_no_vector_and_bad_input_is_named() {
        let phi = vec![1.0; 100];
        let s: Vec<f64> = (0..100).map(|k| k as f64).collect();
        assert_eq!(one_x(&s, &phi).unwrap(), None);
        let e = one_x(&s, &phi[..10]).unwrap_err();
        assert!(matches!(e, AnalysisError::LengthMismatch { .. }), "{e}");
        let mut bad = s.clone();
        bad[3] = f64::NAN;
        let e = one_x(&bad, &phi).unwrap_err();
        assert_eq!(
            e.to_string(),
            "signal[3] = NaN is not finite: every sample must be a finite number"
        );
    }

    #[test]
    fn synchronous_averaging_recovers_the_vector_and_its_scatter() {
        use rand::SeedableRng;
        use rand_distr::{Distribution, Normal};
        // 1X of 2e-6 at lag 1.1 rad in white noise 1e-7, 50 revolutions of 64 samples, 200
        // seeds: the stated covariance covers the error as a 95 % ellipse should
        let (amp, lag) = (2e-6, 1.1);
        let truth = Complex::from_polar(amp, -lag);
        let phi: Vec<f64> = (0..64 * 50 + 7)
            .map(|k| 0.3 + std::f64::consts::TAU * k as f64 / 64.0)
            .collect();
        let mahalanobis = |v: &OneX| {
            let d = v.vector - truth;
            let inv = v.covariance.try_inverse().unwrap();
            d.re * (inv[(0, 0)] * d.re + inv[(0, 1)] * d.im)
                + d.im * (inv[(1, 0)] * d.re + inv[(1, 1)] * d.im)
        };
        let seeds = 200;
        let mut inside = 0;
        for seed in 0..seeds {
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
            let noise = Normal::new(0.0, 1e-7).unwrap();
            let s: Vec<f64> = phi
                .iter()
                .map(|p| amp * (p - lag).cos() + noise.sample(&mut rng))
                .collect();
            let v = synchronous_average(&s, &phi).unwrap().unwrap();
            // chi^2 with 2 degrees of freedom: 95 % below 5.99
            if mahalanobis(&v) < 5.99 {
                inside += 1;
            }
        }
        let cover = inside as f64 / seeds as f64;
        assert!((0.90..=0.99).contains(&cover), "coverage {cover}");
        // a non-synchronous tone (0.37 X, 3e-7) moves the vectors of single revolutions:
        // it is in the scatter, and the mean's error stays within the stated ellipse
        let s: Vec<f64> = phi
            .iter()
            .map(|p| amp * (p - lag).cos() + 3e-7 * (0.37 * p).cos())
            .collect();
        let v = synchronous_average(&s, &phi).unwrap().unwrap();
        assert!(mahalanobis(&v) < 13.8, "{}", mahalanobis(&v));
        assert!(v.covariance[(0, 0)] > 0.0);
        // fewer than two whole revolutions: no vector
        let phi: Vec<f64> = (0..80).map(|k| 0.1 * k as f64).collect();
        let s: Vec<f64> = phi.iter().map(|p| p.cos()).collect();
        assert_eq!(synchronous_average(&s, &phi).unwrap(), None);
    }
}
