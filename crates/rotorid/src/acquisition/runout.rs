//! Runout: the part of a probe's reading that follows the shaft angle without being a
//! motion of the shaft centre (docs/acquisition.md section 5).
//!
//! A probe reads `d_i(t) = x cos t_i + z sin t_i + r_i(phi(t))`, with r_i the mechanical and
//! electrical runout of the track it faces, a 2 pi-periodic function of the shaft angle.
//! At slow roll (speed W_s) the shaft's own motion is the model's steady response to the
//! unbalance, small but not zero (~ (W_s / W)^2 of the running 1X), so
//!
//! ```text
//! r_i(phi) ~ sum_(h=1..H) ( a_ih cos(h phi) + b_ih sin(h phi) )
//!          = least squares fit over the slow-roll samples of  d_i^s(t) - d_i^pred(t)
//! d_i^pred = Re( (Q_x(W) cos t_i + Q_z(W) sin t_i) e^(i (phi + alpha)) ),  D(W) Q = m_u d W^2 (-i, 1)
//! ```
//!
//! (the closed-form steady state of docs/method.md section 2.4, evaluated at each sample's
//! measured speed) with a constant term in the fit that is discarded (the gap). The fit
//! uses the samples between the first and last keyphasor events (whole revolutions), so
//! it is the angle-domain average of the revolutions, smoothed to H harmonics. The running
//! record then has r_i(phi(t)) subtracted at its own phi. References: A. Muszynska,
//! *Rotordynamics*, CRC 2005, sec. 2.4 (slow-roll compensation); API 670 (runout limits).

use serde::Serialize;

use crate::model::{Rotor, RotorParams};
use crate::simulate::steady_state;

use super::probes::toward;

/// Fourier coefficients of a 2 pi-periodic function of the shaft angle, harmonics 1..H.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Harmonics {
    /// The constant term of the fit (not part of the function) \[m\].
    pub mean: f64,
    /// a_h, h = 1..H: coefficients of cos(h phi) \[m\].
    pub cos: Vec<f64>,
    /// b_h, h = 1..H: coefficients of sin(h phi) \[m\].
    pub sin: Vec<f64>,
}

impl Harmonics {
    /// sum_h a_h cos(h phi) + b_h sin(h phi) \[m\] (without the mean).
    pub fn eval(&self, phi: f64) -> f64 {
        let (s1, c1) = phi.sin_cos();
        let (mut s, mut c) = (s1, c1);
        let mut v = 0.0;
        for (a, b) in self.cos.iter().zip(&self.sin) {
            v += a * c + b * s;
            let (sn, cn) = (s * c1 + c * s1, c * c1 - s * s1);
            s = sn;
            c = cn;
        }
        v
    }

    /// Amplitude sqrt(a_h^2 + b_h^2) of harmonic `h` (1-based) \[m\].
    pub fn amplitude(&self, h: usize) -> f64 {
        self.cos[h - 1].hypot(self.sin[h - 1])
    }

    /// Peak-to-peak of the function over one revolution (sampled at 720 angles) \[m\].
    pub fn peak_to_peak(&self) -> f64 {
        let v: Vec<f64> = (0..720)
            .map(|k| self.eval(k as f64 * std::f64::consts::PI / 360.0))
            .collect();
        v.iter().cloned().fold(f64::NEG_INFINITY, f64::max)
            - v.iter().cloned().fold(f64::INFINITY, f64::min)
    }
}

/// cos(h phi), sin(h phi) for h = 1..H into `row` as (c1, s1, c2, s2, ...).
pub(crate) fn harmonic_row(phi: f64, h: usize, row: &mut [f64]) {
    let (s1, c1) = phi.sin_cos();
    let (mut s, mut c) = (s1, c1);
    for k in 0..h {
        row[2 * k] = c;
        row[2 * k + 1] = s;
        let (sn, cn) = (s * c1 + c * s1, c * c1 - s * s1);
        s = sn;
        c = cn;
    }
}

/// Solve the symmetric positive (semi)definite system `a x = b` (p x p, row-major) with
/// Jacobi scaling; columns without information get 0.
pub(crate) fn solve_normal(a: &[f64], b: &[f64], p: usize) -> Vec<f64> {
    let d: Vec<f64> = (0..p)
        .map(|i| {
            let v = a[i * p + i];
            if v > 0.0 {
                1.0 / v.sqrt()
            } else {
                0.0
            }
        })
        .collect();
    let m = nalgebra::DMatrix::from_fn(p, p, |i, j| a[i * p + j] * d[i] * d[j]);
    let r = nalgebra::DVector::from_fn(p, |i, _| b[i] * d[i]);
    let y = match m.clone().cholesky() {
        Some(ch) => ch.solve(&r),
        None => m
            .svd(true, true)
            .solve(&r, 1e-12)
            .unwrap_or_else(|_| nalgebra::DVector::zeros(p)),
    };
    (0..p).map(|i| y[i] * d[i]).collect()
}

/// Least-squares fit of `c + sum_(h=1..H) a_h cos(h phi) + b_h sin(h phi)` to `d` over the
/// samples `range`.
pub fn fit_harmonics(
    phi: &[f64],
    d: &[f64],
    harmonics: usize,
    range: std::ops::Range<usize>,
) -> Harmonics {
    let p = 2 * harmonics + 1;
    let mut a = vec![0.0; p * p];
    let mut b = vec![0.0; p];
    let mut row = vec![0.0; p];
    for i in range {
        row[0] = 1.0;
        harmonic_row(phi[i], harmonics, &mut row[1..]);
        for r in 0..p {
            b[r] += row[r] * d[i];
            for c in r..p {
                a[r * p + c] += row[r] * row[c];
            }
        }
    }
    for r in 0..p {
        for c in 0..r {
            a[r * p + c] = a[c * p + r];
        }
    }
    let x = solve_normal(&a, &b, p);
    Harmonics {
        mean: x[0],
        cos: (0..harmonics).map(|k| x[1 + 2 * k]).collect(),
        sin: (0..harmonics).map(|k| x[2 + 2 * k]).collect(),
    }
}

/// The model's steady response at each sample's speed, seen by probes at `angles` \[rad\]:
/// `d_i^pred(t) = Re((Q_x(w) cos t_i + Q_z(w) sin t_i) e^(i (phi + alpha)))` \[m\] (module
/// doc), for the rotor `rotor` (validated here).
pub fn predicted_slow_roll(
    rotor: &RotorParams,
    phi: &[f64],
    omega: &[f64],
    angles: [f64; 2],
) -> Result<[Vec<f64>; 2], crate::model::ModelError> {
    let r = Rotor::new(*rotor)?;
    let mut out = [Vec::with_capacity(phi.len()), Vec::with_capacity(phi.len())];
    let mut cache: Option<(f64, nalgebra::Vector2<nalgebra::Complex<f64>>)> = None;
    for (&p, &w) in phi.iter().zip(omega) {
        let q = match cache {
            Some((wc, q)) if (wc - w).abs() <= 1e-9 * w.abs() => q,
            _ => {
                let q = steady_state(&r, w).q;
                cache = Some((w, q));
                q
            }
        };
        let (s, c) = (p + r.unbalance().alpha).sin_cos();
        let x = q[0].re * c - q[0].im * s;
        let z = q[1].re * c - q[1].im * s;
        for (k, &a) in angles.iter().enumerate() {
            out[k].push(toward(a, x, z));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn harmonic_fit_recovers_coefficients_and_eval_matches() {
        let phi: Vec<f64> = (0..5000).map(|i| 0.37 + i as f64 * 0.0031).collect();
        let f = |p: f64| {
            0.2 + 2e-6 * (p + 0.3).cos() + 1e-6 * (2.0 * p - 1.0).sin() - 5e-7 * (3.0 * p).cos()
        };
        let d: Vec<f64> = phi.iter().map(|&p| f(p)).collect();
        let h = fit_harmonics(&phi, &d, 4, 0..phi.len());
        assert!((h.mean - 0.2).abs() < 1e-12);
        assert!((h.amplitude(1) - 2e-6).abs() < 1e-15);
        assert!((h.amplitude(2) - 1e-6).abs() < 1e-15);
        assert!((h.amplitude(3) - 5e-7).abs() < 1e-15);
        assert!(h.amplitude(4) < 1e-15);
        for &p in &[0.0, 1.0, 4.0] {
            assert!((h.eval(p) + 0.2 - f(p)).abs() < 1e-15);
        }
    }
}
