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
}
