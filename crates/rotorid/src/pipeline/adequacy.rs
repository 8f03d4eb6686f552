//! Does the model explain the record? (docs/method.md section 6.4.) A maximum-likelihood
//! fit of the wrong model (a nonlinear support, an unmodelled mode) still converges and
//! still reports small standard errors, which are then wrong. Its residuals r = y - y(theta)
//! show it:
//!
//! - whiteness: the Ljung-Box statistic over h lags of the residual autocorrelation
//!   rho_k = sum r_t r_(t-k) / sum r_t^2,
//!   `Q = n (n + 2) sum_(k=1..h) rho_k^2 / (n - k)`, chi-square with h degrees of freedom
//!   for white residuals (Ljung & Box, Biometrika 65, 1978); its p-value;
//! - level: the residual's standard deviation against the white-noise level estimated
//!   from the data's fourth differences, independently of any model (it sees only the
//!   noise); a correct model leaves residuals at the noise level (ratio ~1);
//! - the normalised fit 1 - |r| / |y - mean y| and, when inadequate, the residual's
//!   dominant frequency (a hint of the unmodelled mode or the nonlinearity's harmonic).
//!
//! A channel is inadequate when p < [`ADEQUACY_P_MIN`] or the level ratio exceeds
//! [`NOISE_RATIO_MAX`], unless its residuals are below [`RESIDUAL_FLOOR`] of the signal
//! (the model's numerical accuracy). Then the refinement's standard errors (which assume white residuals
//! of a correct model) do not hold, and the pipeline withholds its values.
//!
//! The modulating and algebraic identifiers ask the same question of their own model
//! ([`judge`], docs/method.md section 6.4): eq. (1) refitted by maximum likelihood from
//! their estimate ([`of_model`]), its residuals through the same tests. Not the response of
//! their estimate itself: the modulating estimate is within its standard errors but far
//! less precise than the data in the natural frequencies, which fix the phase of the free
//! response over the record, so its own residuals fail the tests on correct models (table1
//! at 40 dB: Ljung-Box p down to 1e-40); the refit's verdict is the model's.

use serde::{Deserialize, Serialize};

use crate::identify::modulating::noise_estimate::DifferenceNoise;
use crate::model::{InitialState, RotorParams};
use crate::refine::{model_response, refine, Discretisation, RefineOptions};

use super::diagnostic::{Diagnostic, Direction, Finding};
use super::error::PipelineError;
use super::identification::Identification;
use super::knowledge::Knowledge;
use super::record::Record;
use crate::parameter::Parameter;

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
/// Residual samples scanned for the dominant frequency.
const SPECTRUM_SAMPLES: usize = 8192;

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
}

/// Both channels' adequacy.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Adequacy {
    /// False when either channel is inadequate.
    pub model_adequate: bool,
    /// x (horizontal).
    pub x: ChannelAdequacy,
    /// z (vertical).
    pub z: ChannelAdequacy,
}

impl Adequacy {
    /// Both channels' figures of `model` (x, z) against the record `rec`.
    pub(crate) fn of_response(rec: &Record, model_x: &[f64], model_z: &[f64]) -> Self {
        let dt = rec.grid().dt;
        let x = channel(rec.x(), model_x, dt);
        let z = channel(rec.z(), model_z, dt);
        Self {
            model_adequate: x.adequate && z.adequate,
            x,
            z,
        }
    }

    /// One [`Finding::ModelInadequate`] per inadequate channel, x first.
    pub(crate) fn findings(&self) -> Vec<Diagnostic> {
        [(Direction::X, &self.x), (Direction::Z, &self.z)]
            .into_iter()
            .filter(|(_, c)| !c.adequate)
            .map(|(direction, c)| {
                Diagnostic::new(Finding::ModelInadequate {
                    direction,
                    ljung_box_p: c.ljung_box_p,
                    lag1_autocorrelation: c.lag1_autocorrelation,
                    noise_ratio: c.noise_ratio,
                    dominant_frequency_hz: c.dominant_frequency_hz,
                })
            })
            .collect()
    }
}

/// Step tolerance of the fit [`of_model`] makes, in standard errors: the residual's energy
/// there is within 0.01 noise variances of the optimum's.
const REFIT_TOLERANCE: f64 = 0.1;

/// The adequacy of eq. (1) for the record `rec` (module doc): the maximum-likelihood fit
/// of m, cx, kx, cz, kz and the initial state (a and the unbalance as in `start`) from
/// `start`, to [`REFIT_TOLERANCE`], its residuals through the tests (as the refinement
/// tests its own fit, converged or not).
pub(crate) fn of_model(rec: &Record, start: &RotorParams) -> Result<Adequacy, PipelineError> {
    let record = rec.for_refine();
    let options = RefineOptions {
        tolerance: REFIT_TOLERANCE,
        unknowns: crate::refine::Unknowns::for_model(start.model()),
        ..RefineOptions::default()
    };
    let fit = refine(&record, start, &InitialState::default(), &options)?;
    let model = model_response(
        &fit.rotor,
        &fit.initial,
        &record.experiment(),
        Discretisation::Auto,
    )?;
    Ok(Adequacy::of_response(rec, &model.x, &model.z))
}

/// Judge the modulating (or algebraic) identification `ident` of `rec` by its own fit
/// (module doc): when every value is determined, the adequacy of its rotor (m the mean of
/// m_x and m_z; a and the unbalance from `k`) goes into `ident.adequacy`, and an
/// inadequate model withholds every value behind one [`Finding::ModelInadequate`] per
/// channel, first among the diagnostics, as for the refinement. Not judged (`adequacy`
/// stays `None`) when a value is withheld already or the model response cannot be
/// computed.
pub(crate) fn judge(ident: &mut Identification, rec: &Record, k: &Knowledge) {
    let Some(r) = ident.rotor.as_ref().map(|r| r.params()) else {
        return;
    };
    let value = |p: Parameter| ident.parameter(p).and_then(|v| v.value);
    // the per-direction model's own free dynamics: each direction's c/m and k/m kept
    let (mx, mz) = match (value(Parameter::MX), value(Parameter::MZ)) {
        (Some(mx), Some(mz)) => (mx, mz),
        _ => (r.m, r.m),
    };
    let rotor = RotorParams {
        cx: r.cx * r.m / mx,
        kx: r.kx * r.m / mx,
        cz: r.cz * r.m / mz,
        kz: r.kz * r.m / mz,
        a: k.a,
        unbalance: k.unbalance,
        // a row's cross terms scale with that row's mass, as its direct ones
        coupling: r.coupling.map(|c| crate::model::CrossCoupling {
            cxz: c.cxz * r.m / mx,
            kxz: c.kxz * r.m / mx,
            czx: c.czx * r.m / mz,
            kzx: c.kzx * r.m / mz,
        }),
        ..r
    };
    let Ok(a) = of_model(rec, &rotor) else {
        return;
    };
    ident.adequacy = Some(a);
    if !a.model_adequate {
        super::withhold_all(ident);
        for d in a.findings() {
            ident.diagnostics.insert(0, d);
        }
    }
}

/// The adequacy of `model` for the data `y` sampled every `dt` \[s\].
pub fn channel(y: &[f64], model: &[f64], dt: f64) -> ChannelAdequacy {
    let n = y.len().min(model.len());
    let r: Vec<f64> = (0..n).map(|i| y[i] - model[i]).collect();
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
    let residual_sigma = (r.iter().map(|v| v * v).sum::<f64>() / nf).sqrt();
    let mut d = DifferenceNoise::default();
    y.iter().take(n).for_each(|&v| d.push(v));
    let noise = d.sigma();
    let ratio = residual_sigma / noise;
    let ym = y.iter().take(n).sum::<f64>() / nf;
    let spread = y
        .iter()
        .take(n)
        .map(|v| (v - ym) * (v - ym))
        .sum::<f64>()
        .sqrt();
    let fit = 1.0 - (residual_sigma * nf.sqrt()) / spread;
    let signal_rms = spread / nf.sqrt();
    let at_floor = residual_sigma <= RESIDUAL_FLOOR * signal_rms;
    let adequate = at_floor || !(p < ADEQUACY_P_MIN || ratio > NOISE_RATIO_MAX);
    ChannelAdequacy {
        ljung_box_q: q,
        ljung_box_p: p,
        lag1_autocorrelation: if lags > 0 { rho(1) } else { 0.0 },
        residual_sigma_m: residual_sigma,
        noise_sigma_m: noise,
        noise_ratio: ratio,
        normalised_fit: fit,
        dominant_frequency_hz: (!adequate).then(|| dominant_frequency(&c, dt)),
        adequate,
    }
}

/// The frequency \[Hz\] of the largest DFT bin (Goertzel) of the first
/// [`SPECTRUM_SAMPLES`] of `r`.
fn dominant_frequency(r: &[f64], dt: f64) -> f64 {
    let r = &r[..r.len().min(SPECTRUM_SAMPLES)];
    let n = r.len();
    let mut best = (0.0, 0usize);
    for k in 1..n / 2 {
        let w = std::f64::consts::TAU * k as f64 / n as f64;
        let coeff = 2.0 * w.cos();
        let (mut s1, mut s2) = (0.0, 0.0);
        for &v in r {
            let s = v + coeff * s1 - s2;
            s2 = s1;
            s1 = s;
        }
        let power = s1 * s1 + s2 * s2 - coeff * s1 * s2;
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
}
