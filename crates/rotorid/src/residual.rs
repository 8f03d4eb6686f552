//! Are a model's residuals only the data's noise? The tests behind every adequacy verdict
//! (docs/method.md section 6.4). A maximum-likelihood fit of the wrong model (a nonlinear
//! support, an unmodelled mode) still converges and still reports small standard errors,
//! which are then wrong. Its residuals r = y - y(theta) show it:
//!
//! - whiteness: the Ljung-Box statistic over h lags of the residual autocorrelation
//!   rho_k = sum r_t r_(t-k) / sum r_t^2,
//!   `Q = n (n + 2) sum_(k=1..h) rho_k^2 / (n - k)`, chi-square with h degrees of freedom
//!   for white residuals (Ljung & Box, Biometrika 65, 1978); its p-value ([`ljung_box`]);
//! - level: the residual's standard deviation against the white-noise level estimated
//!   from the data's fourth differences, independently of any model (it sees only the
//!   noise); a correct model leaves residuals at the noise level (ratio ~1);
//! - the normalised fit 1 - |r| / |y - mean y| and, when inadequate, the residual's
//!   dominant frequency (a hint of the unmodelled mode or the nonlinearity's harmonic).
//!
//! A channel is inadequate when p < [`ADEQUACY_P_MIN`] or the level ratio exceeds
//! [`NOISE_RATIO_MAX`], unless its residuals are small against the signal
//! ([`AdequacyBasis`]): below [`RESIDUAL_FLOOR`] of its RMS they are the model's own
//! numerical accuracy and are not tested; below [`SMALL_RESIDUAL_MAX`] a channel that
//! fails the tests is adequate to that precision: a record almost without noise, on which
//! the tests compare the model with the record's own numerical error.
//!
//! Used by the pipeline's verdicts (`pipeline::adequacy`), the finite-element fit and the
//! transient's mode fit.

use serde::{Deserialize, Serialize};

use crate::identify::modulating::noise_estimate::DifferenceNoise;

/// Lags of the Ljung-Box test.
pub const LJUNG_BOX_LAGS: usize = 20;
/// Below this p-value the residuals are not white (two channels: ~0.2 % false alarms).
pub const ADEQUACY_P_MIN: f64 = 1e-3;
/// Above this ratio of the residual's level to the data's noise level the model leaves
/// signal unexplained.
pub const NOISE_RATIO_MAX: f64 = 1.5;
/// Residuals below this fraction of the signal's RMS are at the discretised model's own
/// accuracy (RK4 on measured speed: ~5e-8; exact discretisation: ~1e-12), not evidence of
/// a wrong model: such fits (noise-free data, SNR above 120 dB) are not tested.
pub const RESIDUAL_FLOOR: f64 = 1e-6;
/// A channel that fails the tests with residuals below this fraction of the signal's RMS
/// is adequate to the record's precision, with a note ([`AdequacyBasis::SmallResidual`]):
/// a record almost without noise (a simulation, a file's rounding as its only noise)
/// judged against a noise level of 1e-13 of the signal would withhold every value over
/// an integrator's period error of 3e-5. Any noise within 80 dB of the signal keeps the
/// residuals of any fit above this, so the tests decide every noisy record as before.
pub const SMALL_RESIDUAL_MAX: f64 = 1e-4;

/// What decided a channel's verdict (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum AdequacyBasis {
    /// The whiteness and level tests against the data's noise.
    #[default]
    Noise,
    /// Residuals below [`RESIDUAL_FLOOR`] of the signal: the model's own numerical
    /// accuracy; adequate, not tested.
    NumericalFloor,
    /// The tests fail, but the residuals are below [`SMALL_RESIDUAL_MAX`] of the signal
    /// (a record almost without noise): adequate to that precision, with a note.
    SmallResidual,
}

/// Residual samples scanned for the dominant frequency.
pub(crate) const SPECTRUM_SAMPLES: usize = 8192;

/// The adequacy figures of one channel (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ChannelAdequacy {
    /// Ljung-Box statistic over [`LJUNG_BOX_LAGS`] lags.
    pub ljung_box_q: f64,
    /// Its p-value (chi-square, LJUNG_BOX_LAGS degrees of freedom).
    pub ljung_box_p: f64,
    /// Lag-1 autocorrelation of the residuals (about 0 when white).
    pub lag1_autocorrelation: f64,
    /// Residual standard deviation \[m\].
    pub residual_sigma_m: f64,
    /// White-noise level of the data from its fourth differences \[m\].
    pub noise_sigma_m: f64,
    /// residual_sigma / noise_sigma (about 1 for a correct model).
    pub noise_ratio: f64,
    /// 1 - |r| / |y - mean y| (1 = perfect).
    pub normalised_fit: f64,
    /// The residual's dominant frequency \[Hz\], computed when the channel is inadequate.
    pub dominant_frequency_hz: Option<f64>,
    /// False when the residuals show what the model misses.
    pub adequate: bool,
    /// The data's RMS about its mean \[m\].
    #[serde(default)]
    pub signal_rms_m: f64,
    /// residual_sigma_m / signal_rms_m.
    #[serde(default)]
    pub relative_residual: f64,
    /// What decided `adequate`.
    #[serde(default)]
    pub basis: AdequacyBasis,
    /// Residual samples the tests used.
    #[serde(default)]
    pub samples: u64,
}

/// The white-noise level of `y` from its fourth differences \[m\].
pub(crate) fn noise_of(y: &[f64]) -> f64 {
    let mut d = DifferenceNoise::default();
    y.iter().for_each(|&v| d.push(v));
    d.sigma()
}

/// The adequacy of `model` for the data `y` sampled every `dt` \[s\].
pub fn channel(y: &[f64], model: &[f64], dt: f64) -> ChannelAdequacy {
    let n = y.len().min(model.len());
    let r: Vec<f64> = (0..n).map(|i| y[i] - model[i]).collect();
    let mut c = residual_tests(&y[..n], &r, noise_of(&y[..n]));
    if !c.adequate {
        c.dominant_frequency_hz = Some(dominant_frequency(&r, dt));
    }
    c
}

/// The Ljung-Box test of a residual series (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LjungBox {
    /// The statistic Q over min([`LJUNG_BOX_LAGS`], n / 4) lags.
    pub q: f64,
    /// Its p-value (chi-square with that many degrees of freedom); 1 without lags.
    pub p: f64,
    /// The lag-1 autocorrelation (0 without lags).
    pub lag1: f64,
}

/// The Ljung-Box test of `r` about its mean (module doc).
pub fn ljung_box(r: &[f64]) -> LjungBox {
    let n = r.len();
    let mean = r.iter().sum::<f64>() / n.max(1) as f64;
    let c: Vec<f64> = r.iter().map(|v| v - mean).collect();
    let c0: f64 = c.iter().map(|v| v * v).sum();
    let lags = LJUNG_BOX_LAGS.min(n / 4);
    let rho = |k: usize| -> f64 {
        if c0 <= 0.0 {
            return 0.0;
        }
        c[k..].iter().zip(&c).map(|(a, b)| a * b).sum::<f64>() / c0
    };
    let nf = n as f64;
    let q: f64 = (1..=lags)
        .map(|k| {
            let p = rho(k);
            p * p / (nf - k as f64)
        })
        .sum::<f64>()
        * nf
        * (nf + 2.0);
    let p = if lags == 0 {
        1.0
    } else {
        gamma_q(lags as f64 / 2.0, q / 2.0)
    };
    LjungBox {
        q,
        p,
        lag1: if lags > 0 { rho(1) } else { 0.0 },
    }
}

/// The tests of the residuals `r` of the data `y` (same length) against the white-noise
/// level `noise` \[m\] (module doc), without the dominant frequency.
pub(crate) fn residual_tests(y: &[f64], r: &[f64], noise: f64) -> ChannelAdequacy {
    let n = r.len();
    let nf = n as f64;
    let LjungBox { q, p, lag1 } = ljung_box(r);
    let residual_sigma = (r.iter().map(|v| v * v).sum::<f64>() / nf).sqrt();
    let ratio = residual_sigma / noise;
    let ym = y.iter().sum::<f64>() / nf;
    let spread = y.iter().map(|v| (v - ym) * (v - ym)).sum::<f64>().sqrt();
    let fit = 1.0 - (residual_sigma * nf.sqrt()) / spread;
    let signal_rms = spread / nf.sqrt();
    let relative = residual_sigma / signal_rms;
    let passes = !(p < ADEQUACY_P_MIN || ratio > NOISE_RATIO_MAX);
    let basis = if residual_sigma <= RESIDUAL_FLOOR * signal_rms {
        AdequacyBasis::NumericalFloor
    } else if !passes && residual_sigma <= SMALL_RESIDUAL_MAX * signal_rms {
        AdequacyBasis::SmallResidual
    } else {
        AdequacyBasis::Noise
    };
    let adequate = passes || basis != AdequacyBasis::Noise;
    ChannelAdequacy {
        ljung_box_q: q,
        ljung_box_p: p,
        lag1_autocorrelation: lag1,
        residual_sigma_m: residual_sigma,
        noise_sigma_m: noise,
        noise_ratio: ratio,
        normalised_fit: fit,
        dominant_frequency_hz: None,
        adequate,
        signal_rms_m: signal_rms,
        relative_residual: relative,
        basis,
        samples: n as u64,
    }
}

/// The frequency \[Hz\] of the largest DFT bin (k = 1 .. n/2 - 1) of the first
/// [`SPECTRUM_SAMPLES`] of `r`, mean removed (one real FFT).
pub(crate) fn dominant_frequency(r: &[f64], dt: f64) -> f64 {
    let r = &r[..r.len().min(SPECTRUM_SAMPLES)];
    let n = r.len();
    if n < 4 {
        return 0.0;
    }
    let mean = r.iter().sum::<f64>() / n as f64;
    let mut input: Vec<f64> = r.iter().map(|v| v - mean).collect();
    let fft = realfft::RealFftPlanner::<f64>::new().plan_fft_forward(n);
    let mut spectrum = fft.make_output_vec();
    if fft.process(&mut input, &mut spectrum).is_err() {
        return f64::NAN;
    }
    let mut best = (0.0, 0usize);
    for (k, v) in spectrum.iter().enumerate().take(n / 2).skip(1) {
        let power = v.norm_sqr();
        if power > best.0 {
            best = (power, k);
        }
    }
    best.1 as f64 / (n as f64 * dt)
}

/// The regularised upper incomplete gamma function Q(a, x) = Gamma(a, x) / Gamma(a)
/// (series for x < a + 1, continued fraction otherwise; Numerical Recipes 6.2).
pub(crate) fn gamma_q(a: f64, x: f64) -> f64 {
    if x <= 0.0 {
        return 1.0;
    }
    let ln_front = a * x.ln() - x - ln_gamma(a);
    if x < a + 1.0 {
        let (mut sum, mut term, mut ap) = (1.0 / a, 1.0 / a, a);
        for _ in 0..1000 {
            ap += 1.0;
            term *= x / ap;
            sum += term;
            if term.abs() < sum.abs() * 1e-16 {
                break;
            }
        }
        (1.0 - sum * ln_front.exp()).clamp(0.0, 1.0)
    } else {
        let tiny = 1e-300;
        let mut b = x + 1.0 - a;
        let mut c = 1.0 / tiny;
        let mut d = 1.0 / b;
        let mut h = d;
        for i in 1..1000 {
            let an = -(i as f64) * (i as f64 - a);
            b += 2.0;
            d = an * d + b;
            if d.abs() < tiny {
                d = tiny;
            }
            c = b + an / c;
            if c.abs() < tiny {
                c = tiny;
            }
            d = 1.0 / d;
            let del = d * c;
            h *= del;
            if (del - 1.0).abs() < 1e-16 {
                break;
            }
        }
        (ln_front.exp() * h).clamp(0.0, 1.0)
    }
}

/// ln Gamma(x), x > 0 (Lanczos, g = 7, n = 9; ~1e-15 relative).
fn ln_gamma(x: f64) -> f64 {
    const G: [f64; 9] = [
        0.999_999_999_999_809_9,
        676.520_368_121_885_1,
        -1_259.139_216_722_402_8,
        771.323_428_777_653_1,
        -176.615_029_162_140_6,
        12.507_343_278_686_905,
        -0.138_571_095_265_720_12,
        9.984_369_578_019_572e-6,
        1.505_632_735_149_311_6e-7,
    ];
    if x < 0.5 {
        let pi = std::f64::consts::PI;
        return (pi / (pi * x).sin()).ln() - ln_gamma(1.0 - x);
    }
    let x = x - 1.0;
    let mut a = G[0];
    let t = x + 7.5;
    for (i, g) in G.iter().enumerate().skip(1) {
        a += g / (x + i as f64);
    }
    0.5 * (std::f64::consts::TAU).ln() + (x + 0.5) * t.ln() - t + a.ln()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gamma_q_matches_closed_forms() {
        // Q(1, x) = exp(-x); Q(h/2, x/2) for h = 2 is the chi-square(2) tail exp(-x/2)
        for x in [0.1, 1.0, 5.0, 30.0] {
            assert!((gamma_q(1.0, x) - (-x).exp()).abs() < 1e-13 * (1.0 + (-x).exp()));
        }
        // chi-square(20) at its 99.9 % quantile 45.3147: tail 1e-3
        assert!((gamma_q(10.0, 45.3147 / 2.0) - 1e-3).abs() < 1e-6);
        // ln Gamma(10) = ln 362880
        assert!((ln_gamma(10.0) - 362_880f64.ln()).abs() < 1e-12);
    }

    #[test]
    fn white_residuals_pass_and_a_missed_sinusoid_fails() {
        // deterministic white-ish noise (xorshift, uniform)
        let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
        let mut noise = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            ((s >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 3.46e-9
        };
        let dt = 1e-4;
        let truth: Vec<f64> = (0..10_000)
            .map(|i| 1e-6 * (125.0 * i as f64 * dt).sin())
            .collect();
        let y: Vec<f64> = truth.iter().map(|v| v + noise()).collect();
        let ok = channel(&y, &truth, dt);
        assert!(ok.adequate, "{ok:?}");
        assert!((ok.noise_ratio - 1.0).abs() < 0.1, "{ok:?}");
        // a model that misses a 3X component of 2 % of the signal
        let model: Vec<f64> = truth
            .iter()
            .enumerate()
            .map(|(i, v)| v - 2e-8 * (375.0 * i as f64 * dt).sin())
            .collect();
        let bad = channel(&y, &model, dt);
        assert!(!bad.adequate, "{bad:?}");
        let f = bad.dominant_frequency_hz.unwrap();
        assert!((f - 375.0 / std::f64::consts::TAU).abs() < 2.0, "{f} Hz");
    }

    #[test]
    fn the_dominant_frequency_is_the_largest_bin() {
        // two sinusoids on exact bins of 8192 samples at 1 kHz: 50 and 125 Hz, the latter
        // larger
        let dt = 1e-3;
        let n = 8192;
        let bin = |f: f64| (f * n as f64 * dt).round() / (n as f64 * dt);
        let r: Vec<f64> = (0..n)
            .map(|i| {
                let t = i as f64 * dt;
                0.5 * (std::f64::consts::TAU * bin(50.0) * t).sin()
                    + (std::f64::consts::TAU * bin(125.0) * t).cos()
                    + 3.0
            })
            .collect();
        assert_eq!(dominant_frequency(&r, dt), bin(125.0));
    }
}
