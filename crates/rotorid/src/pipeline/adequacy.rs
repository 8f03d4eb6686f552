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
//! [`NOISE_RATIO_MAX`], unless its residuals are small against the signal
//! ([`AdequacyBasis`]): below [`RESIDUAL_FLOOR`] of its RMS they are the model's own
//! numerical accuracy and are not tested; below [`SMALL_RESIDUAL_MAX`] a channel that
//! fails the tests is adequate to that precision, with a note ([`Finding::SmallResidual`]):
//! a record almost without noise, on which the tests compare the model with the record's
//! own numerical error. An inadequate model's standard errors (which assume white
//! residuals of a correct model) do not hold, and the pipeline withholds its values.
//!
//! The modulating and algebraic identifiers ask the same question of their own model
//! ([`judge`], docs/method.md section 6.4): eq. (1) refitted by maximum likelihood from
//! their estimate ([`of_model`]), its residuals through the same tests. Not the response of
//! their estimate itself: the modulating estimate is within its standard errors but far
//! less precise than the data in the natural frequencies, which fix the phase of the free
//! response over the record, so its own residuals fail the tests on correct models (table1
//! at 40 dB: Ljung-Box p down to 1e-40); the refit's verdict is the model's. The refit
//! fits and tests every `stride`-th sample, about [`REFIT_SAMPLES`] of them, with
//! [`REFIT_SAMPLES_PER_PERIOD`] at least per period of the fastest frequency: at constant
//! speed the discrete model is exact at any sampling, white noise stays white, and the
//! verdict costs a few per cent of the identification (docs/performance.md, "The adequacy
//! verdict").

use serde::{Deserialize, Serialize};

use crate::identify::modulating::noise_estimate::DifferenceNoise;
use crate::model::{InitialState, RotorParams};
use crate::parameter::{ModelKind, Parameter};
use crate::refine::{model_response, Discretisation, RefineOptions, SpeedData};

use super::diagnostic::{Diagnostic, Direction, Finding};
use super::error::PipelineError;
use super::identification::Identification;
use super::knowledge::Knowledge;
use super::record::Record;

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

/// Both channels' adequacy.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Adequacy {
    /// False when either channel is inadequate.
    pub model_adequate: bool,
    /// x (horizontal).
    pub x: ChannelAdequacy,
    /// z (vertical).
    pub z: ChannelAdequacy,
    /// How the model was refitted for the test (modulating and algebraic; `None` for
    /// refine, which tests its own fit).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub refit: Option<Refit>,
}

/// The refit the modulating and algebraic methods are judged by
/// ([`adequacy_of`](super::adequacy_of)).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Refit {
    /// Every `stride`-th sample of the record was fitted and tested.
    pub stride: u64,
    /// Samples fitted and tested.
    pub samples: u64,
    /// Samples of the record judged (the first this many).
    pub of_samples: u64,
    /// Model passes with sensitivities the fit took.
    pub passes: u64,
    /// Whether the fit's last step was below its tolerance.
    pub converged: bool,
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
            refit: None,
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

    /// One note ([`Finding::SmallResidual`]) per channel judged adequate by the size of
    /// its residuals alone ([`AdequacyBasis::SmallResidual`]), x first.
    pub(crate) fn notes(&self) -> Vec<Diagnostic> {
        [(Direction::X, &self.x), (Direction::Z, &self.z)]
            .into_iter()
            .filter(|(_, c)| c.basis == AdequacyBasis::SmallResidual)
            .map(|(direction, c)| {
                Diagnostic::note(Finding::SmallResidual {
                    direction,
                    relative_residual: c.relative_residual,
                    residual_sigma_m: c.residual_sigma_m,
                    noise_sigma_m: c.noise_sigma_m,
                })
            })
            .collect()
    }
}

/// Step tolerance of the fit [`of_model`] makes (and of its continuation's windows), in
/// standard errors: the residual's energy there is within one noise variance of the
/// optimum's, over all the samples fitted.
const REFIT_TOLERANCE: f64 = 1.0;

/// Samples the refit of the modulating and algebraic verdicts aims at: it fits and tests
/// every `stride`-th sample of the record, `stride` = samples / this (rounded down), as
/// far as [`REFIT_SAMPLES_PER_PERIOD`] allows. The test's power on N samples: a sinusoid
/// in the residuals holding a share f of their variance gives a Ljung-Box statistic of
/// about 10 N f^2 (its autocorrelation f cos(w k dt) over 20 lags), past the 1e-3 level
/// (45.3) from f = 0.094 at N = 512, where all 10,001 samples of a 1 s record flagged
/// f = 0.021; the wrong models of the 100-seed studies leave f = 0.3 (a foundation) and
/// 0.9 (a cubic support) at 40 dB.
pub const REFIT_SAMPLES: usize = 512;
/// Fewest samples per period of the fastest frequency (the start's natural frequency
/// with its gyroscopic shift, the speed) the refit's samples keep.
pub const REFIT_SAMPLES_PER_PERIOD: f64 = 8.0;

/// The fastest frequency of the refit of `start` to `rec` \[rad/s\]: the start's undamped
/// natural frequency with its gyroscopic shift, or the record's largest speed.
fn fastest_frequency(rec: &crate::refine::Record, start: &RotorParams) -> f64 {
    let n = rec.x.len();
    let w_speed = match rec.speed {
        SpeedData::Profile(p) => {
            let t_end = n.saturating_sub(1) as f64 * rec.dt;
            p.at(0.0).omega.abs().max(p.at(t_end).omega.abs())
        }
        SpeedData::Samples { omega, .. } => omega.iter().fold(0.0f64, |a, &w| a.max(w.abs())),
    };
    let c = start.cross();
    let k = (start.kx.abs() + c.kxz.abs()).max(c.kzx.abs() + start.kz.abs());
    let w_n = (k / start.m).sqrt() + start.a.abs() * w_speed / (2.0 * start.m);
    w_n.max(w_speed)
}

/// The stride of the refit of `start` to `rec` (module doc): samples / [`REFIT_SAMPLES`],
/// at most what keeps [`REFIT_SAMPLES_PER_PERIOD`] samples per period of the fastest
/// frequency, at least 1.
fn stride(rec: &crate::refine::Record, start: &RotorParams) -> usize {
    let w = fastest_frequency(rec, start);
    let by_frequency = std::f64::consts::TAU / (REFIT_SAMPLES_PER_PERIOD * w * rec.dt);
    let by_length = (rec.x.len() / REFIT_SAMPLES) as f64;
    let s = by_length.min(by_frequency);
    if s.is_finite() && s >= 1.0 {
        s as usize
    } else {
        1
    }
}

/// The model error the refit's RK4 integration (a record whose speed changes) may leave,
/// relative to the larger of the record's noise and [`RESIDUAL_FLOOR`], both relative to
/// the signal: 5 % of the noise adds 0.25 % to the residual's variance, which neither
/// test can see.
pub const REFIT_MODEL_ERROR: f64 = 0.05;
/// The loosest RK4 frequency error the refit takes: (w h)^4 / 120 = 1e-4 keeps w h = 0.33,
/// far inside RK4's stability interval (2.8).
const REFIT_FREQ_TOL_MAX: f64 = 1e-4;

/// The bound on the relative frequency error of the refit's RK4 sub-steps (module doc):
/// RK4's phase error grows as w T (w h)^4 / 120 over a record of T seconds at the fastest
/// frequency w, and is held at [`REFIT_MODEL_ERROR`] of the quieter channel's noise
/// relative to its signal (`noise` \[m\], x and z); never tighter than refine's own
/// (`FREQ_TOL`, 1e-9: a record without noise is integrated as refine integrates it).
fn rk4_freq_tol(full: &crate::refine::Record, start: &RotorParams, noise: [f64; 2]) -> f64 {
    let rms = |y: &[f64]| {
        let n = y.len().max(1) as f64;
        let mean = y.iter().sum::<f64>() / n;
        (y.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n).sqrt()
    };
    let relative = [(full.x, noise[0]), (full.z, noise[1])]
        .into_iter()
        .map(|(y, s)| s / rms(y))
        .filter(|r| r.is_finite())
        .fold(f64::INFINITY, f64::min);
    let eps = REFIT_MODEL_ERROR * relative.max(RESIDUAL_FLOOR);
    let span = full.x.len().saturating_sub(1) as f64 * full.dt;
    let tol = eps / (fastest_frequency(full, start) * span);
    if tol.is_finite() {
        tol.clamp(crate::refine::FREQ_TOL, REFIT_FREQ_TOL_MAX)
    } else {
        crate::refine::FREQ_TOL
    }
}

/// Every `stride`-th sample of a record's channels and speed samples.
struct Strided {
    x: Vec<f64>,
    z: Vec<f64>,
    speed: Option<[Vec<f64>; 3]>,
}

impl Strided {
    fn of(rec: &crate::refine::Record, stride: usize) -> Self {
        let every = |v: &[f64]| v.iter().step_by(stride).copied().collect::<Vec<f64>>();
        Self {
            x: every(rec.x),
            z: every(rec.z),
            speed: match rec.speed {
                SpeedData::Samples {
                    phi,
                    omega,
                    omega_dot,
                } => Some([every(phi), every(omega), every(omega_dot)]),
                SpeedData::Profile(_) => None,
            },
        }
    }

    fn record<'a>(
        &'a self,
        rec: &crate::refine::Record<'a>,
        stride: usize,
    ) -> crate::refine::Record<'a> {
        crate::refine::Record {
            dt: rec.dt * stride as f64,
            x: &self.x,
            z: &self.z,
            speed: match &self.speed {
                Some([phi, omega, omega_dot]) => SpeedData::Samples {
                    phi,
                    omega,
                    omega_dot,
                },
                None => rec.speed,
            },
        }
    }
}

/// The white-noise level of `y` from its fourth differences \[m\].
fn noise_of(y: &[f64]) -> f64 {
    let mut d = DifferenceNoise::default();
    y.iter().for_each(|&v| d.push(v));
    d.sigma()
}

/// The adequacy of eq. (1) for the record `rec` (module doc): the maximum-likelihood fit
/// of m, cx, kx, cz, kz and the initial state (a and the unbalance as in `start`) from
/// `start`, to [`REFIT_TOLERANCE`], over every `stride`-th sample ([`REFIT_SAMPLES`]),
/// its residuals there through the tests against the noise level of all samples.
pub(crate) fn of_model(rec: &Record, start: &RotorParams) -> Result<Adequacy, PipelineError> {
    of_model_within(rec, start, None)
}

/// [`of_model`] with the RK4 frequency-error bound `freq_tol` instead of the one the
/// record's noise allows ([`rk4_freq_tol`]; tests compare the two).
fn of_model_within(
    rec: &Record,
    start: &RotorParams,
    freq_tol: Option<f64>,
) -> Result<Adequacy, PipelineError> {
    let full = rec.for_refine();
    let stride = stride(&full, start);
    let strided = (stride > 1).then(|| Strided::of(&full, stride));
    let record = match &strided {
        Some(s) => s.record(&full, stride),
        None => full,
    };
    let options = RefineOptions {
        tolerance: REFIT_TOLERANCE,
        unknowns: crate::refine::Unknowns::for_model(start.model()),
        ..RefineOptions::default()
    };
    let noise = [noise_of(full.x), noise_of(full.z)];
    let how = crate::refine::Continuation {
        stride,
        window_tolerance: REFIT_TOLERANCE,
        balanced: true,
        rk4_freq_tol: freq_tol.unwrap_or_else(|| rk4_freq_tol(&full, start, noise)),
    };
    let fit = crate::refine::fit(&record, start, &InitialState::default(), &options, &how)?;
    let judge = |y: &[f64], model: &[f64], noise: f64| {
        let r: Vec<f64> = y.iter().zip(model).map(|(a, b)| a - b).collect();
        tests(y, &r, noise)
    };
    let mut x = judge(record.x, &fit.x, noise[0]);
    let mut z = judge(record.z, &fit.z, noise[1]);
    if !(x.adequate && z.adequate) {
        hint(&full, &fit, [&mut x, &mut z])?;
    }
    Ok(Adequacy {
        model_adequate: x.adequate && z.adequate,
        x,
        z,
        refit: Some(Refit {
            stride: stride as u64,
            samples: record.x.len() as u64,
            of_samples: full.x.len() as u64,
            passes: fit.passes as u64,
            converged: fit.converged,
        }),
    })
}

/// The dominant frequency of each inadequate channel of `channels` (x, z), from the
/// residuals of `fit` over the first [`SPECTRUM_SAMPLES`] of the record `full` at its own
/// rate (the refit's samples alias what lies above their Nyquist frequency).
fn hint(
    full: &crate::refine::Record,
    fit: &crate::refine::Fit,
    channels: [&mut ChannelAdequacy; 2],
) -> Result<(), PipelineError> {
    let m = SPECTRUM_SAMPLES.min(full.x.len());
    let speed = match full.speed {
        SpeedData::Samples {
            phi,
            omega,
            omega_dot,
        } => SpeedData::Samples {
            phi: &phi[..m],
            omega: &omega[..m],
            omega_dot: &omega_dot[..m],
        },
        p => p,
    };
    let head = crate::refine::Experiment {
        dt: full.dt,
        samples: m,
        speed,
    };
    let model = model_response(&fit.rotor, &fit.initial, &head, Discretisation::Auto)?;
    for (c, (y, model)) in channels
        .into_iter()
        .zip([(full.x, &model.x), (full.z, &model.z)])
    {
        if !c.adequate {
            let r: Vec<f64> = y.iter().zip(model).map(|(a, b)| a - b).collect();
            c.dominant_frequency_hz = Some(dominant_frequency(&r, full.dt));
        }
    }
    Ok(())
}

/// The start of the refit from per-direction values of `model` (in the order of
/// [`ModelKind::per_direction`]): m the mean of m_x and m_z, each direction's
/// coefficients over its m kept (the per-direction model's own free dynamics), a and the
/// unbalance from `k`; `None` unless every value is finite, m and the direct stiffnesses
/// positive (a negative damping is raised to 0 by the fit, as for refine's start).
pub(crate) fn start_from(k: &Knowledge, model: ModelKind, values: &[f64]) -> Option<RotorParams> {
    let per = model.per_direction();
    let usable = |p: Parameter, v: f64| {
        v.is_finite() && (p.sign() != crate::parameter::Sign::Positive || v > 0.0)
    };
    if values.len() != per.len() || per.iter().zip(values).any(|(&p, &v)| !usable(p, v)) {
        return None;
    }
    let half = per.len() / 2;
    let (mx, mz) = (values[0], values[half]);
    let m = 0.5 * (mx + mz);
    let mut p = RotorParams {
        m,
        cx: f64::NAN,
        kx: f64::NAN,
        cz: f64::NAN,
        kz: f64::NAN,
        a: k.a,
        unbalance: k.unbalance,
        coupling: (model == ModelKind::CrossCoupled).then(Default::default),
    };
    for (i, (&q, &v)) in per.iter().zip(values).enumerate() {
        if i % half != 0 {
            // a row's cross terms scale with that row's mass, as its direct ones
            let row_m = if i < half { mx } else { mz };
            p.set(q, v * m / row_m);
        }
    }
    Some(p)
}

/// Judge the modulating (or algebraic) identification `ident` of `rec` by its own fit
/// (module doc) when every value is determined: [`judge_from`] the start of its values
/// ([`start_from`]). Not judged (`adequacy` stays `None`) when a value is withheld
/// already.
pub(crate) fn judge(ident: &mut Identification, rec: &Record, k: &Knowledge) {
    let values: Option<Vec<f64>> = ident
        .model
        .per_direction()
        .iter()
        .map(|&p| ident.value(p))
        .collect();
    if let Some(start) = values.and_then(|v| start_from(k, ident.model, &v)) {
        judge_from(ident, rec, &start);
    }
}

/// Judge `ident` by the refit of eq. (1) from `start` ([`of_model`]): its adequacy goes
/// into `ident.adequacy`; an inadequate model withholds every value behind one
/// [`Finding::ModelInadequate`] per channel, first among the diagnostics, as for the
/// refinement; a channel adequate by its residual's size alone adds its note. Not judged
/// when the model response cannot be computed.
pub(crate) fn judge_from(ident: &mut Identification, rec: &Record, start: &RotorParams) {
    let Ok(a) = of_model(rec, start) else {
        return;
    };
    ident.adequacy = Some(a);
    if !a.model_adequate {
        super::withhold_all(ident);
        for d in a.findings() {
            ident.diagnostics.insert(0, d);
        }
    }
    ident.diagnostics.extend(a.notes());
}

/// The adequacy of `model` for the data `y` sampled every `dt` \[s\].
pub fn channel(y: &[f64], model: &[f64], dt: f64) -> ChannelAdequacy {
    let n = y.len().min(model.len());
    let r: Vec<f64> = (0..n).map(|i| y[i] - model[i]).collect();
    let mut c = tests(&y[..n], &r, noise_of(&y[..n]));
    if !c.adequate {
        c.dominant_frequency_hz = Some(dominant_frequency(&r, dt));
    }
    c
}

/// The tests of the residuals `r` of the data `y` (same length) against the white-noise
/// level `noise` \[m\] (module doc), without the dominant frequency.
fn tests(y: &[f64], r: &[f64], noise: f64) -> ChannelAdequacy {
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
        lag1_autocorrelation: if lags > 0 { rho(1) } else { 0.0 },
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
fn dominant_frequency(r: &[f64], dt: f64) -> f64 {
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

    /// A run-up at 40 dB: the verdict's RK4 sub-steps, chosen from the noise
    /// ([`rk4_freq_tol`]), are far looser than refine's, and its verdict is the one
    /// refine's own integration (`FREQ_TOL`) gives: the same residuals to 1e-3, the same
    /// Ljung-Box statistic to 1 %.
    #[test]
    fn the_verdicts_looser_rk4_on_a_run_up_gives_refines_verdict() {
        use crate::simulate::{add_noise, simulate, Method};
        let s = crate::Scenario::table1_ramp(600.0).expect("valid ramp");
        let mut r = simulate(&s, Method::Exact).expect("simulated");
        add_noise(&mut r, 40.0, 3).expect("valid noise");
        let rec = Record::new(
            r.t,
            r.x,
            r.z,
            super::super::Speed::Samples {
                phi: r.phi,
                omega: r.phi_dot,
                omega_dot: r.phi_ddot,
            },
            1e-6,
        )
        .expect("valid record");
        let start = s.rotor.params();
        let full = rec.for_refine();
        let tol = rk4_freq_tol(&full, &start, [noise_of(full.x), noise_of(full.z)]);
        assert!(tol > 100.0 * crate::refine::FREQ_TOL, "tolerance {tol}");
        let loose = of_model(&rec, &start).expect("judged");
        let tight = of_model_within(&rec, &start, Some(crate::refine::FREQ_TOL)).expect("judged");
        for (a, b) in [(&loose.x, &tight.x), (&loose.z, &tight.z)] {
            assert!(
                (a.residual_sigma_m / b.residual_sigma_m - 1.0).abs() < 1e-3,
                "residual {} vs {}",
                a.residual_sigma_m,
                b.residual_sigma_m
            );
            assert!(
                (a.ljung_box_q - b.ljung_box_q).abs() < 0.01 * b.ljung_box_q,
                "Q {} vs {}",
                a.ljung_box_q,
                b.ljung_box_q
            );
            assert!(a.adequate && b.adequate);
        }
    }

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
    fn noise_free_residuals_are_judged_by_their_size() {
        // noise-free data (the fourth differences see only rounding): a model off by a
        // 3X component of `size` of the signal's RMS
        let dt = 1e-4;
        let y: Vec<f64> = (0..10_000)
            .map(|i| 1e-6 * (125.0 * i as f64 * dt).sin())
            .collect();
        for (size, basis, adequate) in [
            (1e-7, AdequacyBasis::NumericalFloor, true),
            (1e-5, AdequacyBasis::SmallResidual, true),
            (3e-4, AdequacyBasis::Noise, false),
        ] {
            let model: Vec<f64> = y
                .iter()
                .enumerate()
                .map(|(i, v)| v - size * 1e-6 * (375.0 * i as f64 * dt).sin())
                .collect();
            let c = channel(&y, &model, dt);
            assert_eq!((c.basis, c.adequate), (basis, adequate), "{size}: {c:?}");
            assert!(
                (c.relative_residual / size - 1.0).abs() < 0.05,
                "{size}: {}",
                c.relative_residual
            );
            assert!(
                c.noise_ratio > 10.0,
                "{size}: the tests alone reject: {c:?}"
            );
            let a = Adequacy {
                model_adequate: c.adequate,
                x: c,
                z: c,
                refit: None,
            };
            let notes = a.notes();
            assert_eq!(
                notes.len(),
                if basis == AdequacyBasis::SmallResidual {
                    2
                } else {
                    0
                }
            );
            assert_eq!(a.findings().len(), if adequate { 0 } else { 2 });
        }
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
