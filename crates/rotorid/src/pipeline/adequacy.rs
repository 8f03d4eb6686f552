//! Does the model explain the record? (docs/method.md section 6.4.) Its residuals go
//! through the whiteness and level tests of [`crate::residual`]. An inadequate model's
//! standard errors (which assume white residuals of a correct model) do not hold, and the
//! pipeline withholds its values; a channel adequate only by the size of its residuals
//! gets a note ([`Finding::SmallResidual`]).
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

use crate::model::{InitialState, RotorParams};
use crate::parameter::{ModelKind, Parameter};
use crate::refine::{model_response, Discretisation, RefineOptions, SpeedData};

use super::diagnostic::{Diagnostic, Direction, Finding};
use super::error::PipelineError;
use super::identification::Identification;
use super::knowledge::Knowledge;
use super::record::Record;

pub use crate::residual::{
    channel, AdequacyBasis, ChannelAdequacy, ADEQUACY_P_MIN, LJUNG_BOX_LAGS, NOISE_RATIO_MAX,
    RESIDUAL_FLOOR, SMALL_RESIDUAL_MAX,
};
use crate::residual::{dominant_frequency, noise_of, residual_tests, SPECTRUM_SAMPLES};

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
        residual_tests(y, &r, noise)
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
        let rec = Record::from_response(&r).expect("valid record");
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
}
