//! Modes free of the sweep's bias: a modal model ([`ModalDescription`]) fitted to the
//! order-tracked 1X vectors of a run-up or coast-down by weighted least squares on the
//! transient response itself ([`synchronous`]), not on the steady-state formula
//! (docs/transient.md section 6).
//!
//! Each sensor's compensated 1X vector at point r (a revolution or a speed bin) is
//! modelled as
//!
//! ```text
//! V_p(r) = sum_j a_pj W_j(r; k_j, c_j) + b_p
//! ```
//!
//! W_j the synchronous response of mode j to a unit unbalance along the measured speed
//! history (k_j = w_j^2, c_j = 2 zeta_j w_j), a_pj the complex share of mode j at sensor p
//! (the mode's unbalance times its shape there) and b_p a constant vector (runout the
//! slow-roll vector did not remove). The a and b enter linearly: for each th = (k, c) they
//! are the weighted least-squares solution (weights 1 / std of each vector), and th
//! minimises what is left (variable projection: Golub & Pereyra, SIAM J. Numer. Anal. 10,
//! 1973; the Jacobian of Kaufman, BIT 15, 1975) by Gauss-Newton with Levenberg-Marquardt
//! damping, from the criticals' speeds and damping ratios.
//!
//! - The number of modes is the data's: fits of 1 .. n modes (n the distinct criticals,
//!   at most [`ModeSettings::max_modes`]), the one of least BIC = N ln(S / N) + p ln N
//!   chosen (S the weighted residual sum, N the real data, p all unknowns; Schwarz,
//!   Ann. Stat. 6, 1978).
//! - Standard deviations from the Gauss-Newton covariance of th with the linear
//!   unknowns eliminated, s^2 (J^T J)^-1, s^2 = S / (N - p) if above 1 (or when the
//!   vectors' stds are unknown), else 1: the fit's scatter is believed when it exceeds the
//!   vectors' own noise. w, zeta and the log decrement delta = 2 pi zeta / sqrt(1 - zeta^2)
//!   follow by the delta method.
//! - Adequacy: the residual level against the vectors' noise (sqrt(S / (N - p)), about 1
//!   for a correct model) and the whiteness of each sensor's normalised residuals
//!   (Ljung-Box over 20 lags, as the identification's adequacy test); the fit is
//!   adequate when the level is at most 1.5 and every p-value at least 1e-3.
//! - Only the points whose speed lies within [`ModeSettings::window`] of the guesses
//!   take part (a long stretch far from every resonance adds cost, no information).
//!
//! Without times (a Bode table) the same fit runs on steady states: its modes carry the
//! sweep's bias as the half-power figures do ([`FitBasis::SteadyState`]).

use std::f64::consts::TAU;

use nalgebra::{Complex, DMatrix, DVector};
use serde::Serialize;

use super::critical::Critical;
use super::error::{same_length, TransientError};
use super::order::C64;
use super::synchronous::{synchronous, Sweep};
use crate::model::description::{ModalDescription, Mode};
use crate::model::{rad_per_s_to_rpm, OutOfRange};
use crate::residual::{ljung_box, ADEQUACY_P_MIN, NOISE_RATIO_MAX};

/// Settings of [`fit_modes`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ModeSettings {
    /// The most modes tried (default 4).
    pub max_modes: usize,
    /// Runge-Kutta steps per point of the transient response (default 16).
    pub substeps: usize,
    /// Most Levenberg-Marquardt trials per fit (default 100).
    pub max_iterations: usize,
    /// The speeds fitted, as factors of the lowest and highest guess (default 0.5, 1.5).
    pub window: (f64, f64),
}

impl Default for ModeSettings {
    fn default() -> Self {
        Self {
            max_modes: 4,
            substeps: 16,
            max_iterations: 100,
            window: (0.5, 1.5),
        }
    }
}

/// Where a fit starts: a resonance's speed and damping ratio.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ModeGuess {
    /// Speed \[rev/min\].
    pub rpm: f64,
    /// Damping ratio \[-\].
    pub damping_ratio: f64,
    /// How clearly the data show it (the critical's significance, to rank guesses).
    pub weight: f64,
}

/// Distinct criticals within this fraction of each other's speed are one mode's.
pub const SAME_MODE: f64 = 0.03;
/// The damping ratio a guess takes when its critical has none.
pub const DEFAULT_DAMPING_RATIO: f64 = 0.05;

/// One guess per resonance of `criticals` (of every sensor): those within
/// [`SAME_MODE`] of one another merged into the most significant; most significant
/// first.
pub fn guesses(criticals: &[Critical]) -> Vec<ModeGuess> {
    let mut all: Vec<ModeGuess> = criticals
        .iter()
        .map(|c| ModeGuess {
            rpm: c.rpm,
            damping_ratio: c
                .damping_ratio
                .filter(|z| z.is_finite() && *z > 0.0 && *z < 1.0)
                .unwrap_or(DEFAULT_DAMPING_RATIO),
            weight: c.significance,
        })
        .collect();
    all.sort_by(|a, b| b.weight.total_cmp(&a.weight));
    let mut out: Vec<ModeGuess> = Vec::new();
    for g in all {
        if out
            .iter()
            .all(|o| (o.rpm - g.rpm).abs() > SAME_MODE * o.rpm.max(g.rpm))
        {
            out.push(g);
        }
    }
    out
}

/// One sensor's data for the fit.
#[derive(Debug, Clone, Copy)]
pub struct SensorSeries<'a> {
    /// Its compensated 1X vector per point \[m\].
    pub vectors: &'a [C64],
    /// The standard deviation of each of re and im per point \[m\]; NaN when unknown (all
    /// then weigh the same and the scatter of the fit is the noise).
    pub std: &'a [f64],
}

/// Whether the fit's model carries the sweep.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FitBasis {
    /// The transient response along the measured speed history: free of the sweep's
    /// bias.
    Transient,
    /// Steady states (a table without times): biased like the half-power figures.
    SteadyState,
}

/// A fitted mode.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct FittedMode {
    /// Undamped natural speed \[rev/min\].
    pub rpm: f64,
    /// Its standard deviation \[rev/min\].
    pub rpm_std: f64,
    /// Damping ratio \[-\].
    pub damping_ratio: f64,
    /// Its standard deviation \[-\].
    pub damping_ratio_std: f64,
    /// Logarithmic decrement 2 pi zeta / sqrt(1 - zeta^2) \[-\] (None at zeta >= 1).
    pub log_decrement: Option<f64>,
    /// Its standard deviation \[-\].
    pub log_decrement_std: Option<f64>,
}

/// One candidate number of modes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Candidate {
    /// Its modes.
    pub modes: usize,
    /// Its BIC (lower is better; NaN when the fit failed).
    pub bic: f64,
    /// sqrt(S / (N - p)) \[-\].
    pub noise_ratio: f64,
    /// Whether its iteration converged.
    pub converged: bool,
}

/// The result of [`fit_modes`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModeFit {
    /// The chosen modes, in order of speed.
    pub modes: Vec<FittedMode>,
    /// Transient or steady-state model.
    pub basis: FitBasis,
    /// Every number of modes tried.
    pub candidates: Vec<Candidate>,
    /// The points fitted (indices into the sweep).
    #[serde(skip)]
    pub points: std::ops::Range<usize>,
    /// The speeds fitted \[rev/min\].
    pub window_rpm: (f64, f64),
    /// Real data N.
    pub data: usize,
    /// Unknowns p (the modes' k, c; each sensor's shares and constant, re and im).
    pub unknowns: usize,
    /// sqrt(S / (N - p)): the residual's level against the vectors' noise (about 1 when
    /// the model explains them; NaN when their stds are unknown).
    pub noise_ratio: f64,
    /// Per sensor, the smaller Ljung-Box p-value of its residuals' re and im.
    pub ljung_box_p: Vec<f64>,
    /// False when the residuals show what the model misses (module doc).
    pub adequate: bool,
    /// Whether the chosen fit's iteration converged.
    pub converged: bool,
    /// Levenberg-Marquardt trials of the chosen fit.
    pub iterations: usize,
    /// Per sensor, the fitted model's 1X vector at each point of `points` \[m\].
    #[serde(skip)]
    pub model: Vec<Vec<C64>>,
}

/// One evaluated th.
struct Eval {
    /// The weighted residual, re then im per sensor.
    residual: Vec<f64>,
    /// d residual / d th (variable projection), one column per parameter.
    jacobian: Option<DMatrix<f64>>,
    /// Per sensor, the model's vectors.
    model: Vec<Vec<C64>>,
    cost: f64,
}

struct Problem {
    sweep: Sweep,
    /// Per sensor: its vectors and their weights.
    sensors: Vec<(Vec<C64>, Vec<f64>)>,
    substeps: usize,
}

impl Problem {
    fn data(&self) -> usize {
        2 * self.sensors.iter().map(|s| s.0.len()).sum::<usize>()
    }

    fn evaluate(&self, theta: &DVector<f64>, jac: bool) -> Result<Eval, TransientError> {
        let modes: Vec<Mode> = ModalDescription::modes(theta)
            .into_iter()
            .map(|m| m.ok_or_else(|| TransientError::ModelResponse("a mode's k <= 0".into())))
            .collect::<Result<_, _>>()?;
        let desc = ModalDescription::new(&modes)?;
        let syn = synchronous(&desc, theta, &self.sweep, self.substeps, jac)?;
        let n = modes.len();
        let np = theta.len();
        let points = self.sweep.len();
        let mut residual = Vec::with_capacity(self.data());
        let mut jac_cols: Vec<Vec<f64>> = vec![Vec::with_capacity(self.data()); np];
        let mut model = Vec::new();
        // A mode's vector at a sensor is a P + conj(a) Q (P its mean response, Q the mean
        // of its conjugate times e^{-2 i psi}, [`Synchronous`]): with a = ar + i ai, real
        // coefficients ar, ai of the columns P + Q and i (P - Q); the constant's of 1 and
        // i. Rows: each point's re, then each point's im, weighted.
        let column = |m: usize, part: usize, p: &[Vec<C64>], q: &[Vec<C64>], r: usize| {
            let (pv, qv) = (p[r][m], q[r][m]);
            if part == 0 {
                pv + qv
            } else {
                (pv - qv) * Complex::new(0.0, 1.0)
            }
        };
        let cols = 2 * (n + 1);
        for (d, w) in &self.sensors {
            let basis: Vec<Vec<C64>> = (0..cols)
                .map(|c| {
                    (0..points)
                        .map(|r| {
                            let v = if c < 2 * n {
                                column(c / 2, c % 2, &syn.response, &syn.conjugate, r)
                            } else if c == 2 * n {
                                Complex::new(1.0, 0.0)
                            } else {
                                Complex::new(0.0, 1.0)
                            };
                            v * w[r]
                        })
                        .collect()
                })
                .collect();
            let b = DMatrix::<f64>::from_fn(2 * points, cols, |i, c| {
                let v = basis[c][i % points];
                if i < points {
                    v.re
                } else {
                    v.im
                }
            });
            let y = DVector::<f64>::from_fn(2 * points, |i, _| {
                let v = d[i % points] * w[i % points];
                if i < points {
                    v.re
                } else {
                    v.im
                }
            });
            let qr = b.clone().qr();
            let (q, rr) = (qr.q(), qr.r());
            let dependent = {
                let diag: Vec<f64> = (0..rr.ncols()).map(|i| rr[(i, i)].abs()).collect();
                let top = diag.iter().copied().fold(0.0, f64::max);
                diag.iter().any(|&d| d.is_nan() || d <= 1e-12 * top)
            };
            let coef = (!dependent)
                .then(|| rr.solve_upper_triangular(&(q.transpose() * &y)))
                .flatten()
                .ok_or_else(|| {
                    TransientError::ModelResponse(
                        "the modes' responses are linearly dependent (two modes at one speed?)"
                            .into(),
                    )
                })?;
            let fitted = &b * &coef;
            model.push(
                (0..points)
                    .map(|k| Complex::new(fitted[k], fitted[k + points]) / w[k])
                    .collect(),
            );
            residual.extend((&y - &fitted).iter());
            if jac {
                for (j, col) in jac_cols.iter_mut().enumerate() {
                    let m = j / 2;
                    // d(B c)/d th_j: only mode m's two columns depend on it
                    let dv: Vec<C64> = (0..points)
                        .map(|r| {
                            (column(m, 0, &syn.sensitivity[j], &syn.conjugate_sensitivity[j], r)
                                * coef[2 * m]
                                + column(
                                    m,
                                    1,
                                    &syn.sensitivity[j],
                                    &syn.conjugate_sensitivity[j],
                                    r,
                                ) * coef[2 * m + 1])
                                * w[r]
                        })
                        .collect();
                    let v = DVector::<f64>::from_fn(2 * points, |i, _| {
                        let z = dv[i % points];
                        if i < points {
                            z.re
                        } else {
                            z.im
                        }
                    });
                    let proj = &v - &q * (q.transpose() * &v);
                    col.extend(proj.iter().map(|z| -z));
                }
            }
        }
        let cost = residual.iter().map(|v| v * v).sum();
        let jacobian = jac.then(|| DMatrix::from_fn(residual.len(), np, |r, c| jac_cols[c][r]));
        Ok(Eval {
            residual,
            jacobian,
            model,
            cost,
        })
    }
}

struct Fit {
    theta: DVector<f64>,
    eval: Eval,
    converged: bool,
    iterations: usize,
}

/// Largest relative change of a mode's k in one step (a step beyond it is damped).
const MAX_K_CHANGE: f64 = 0.3;

fn levenberg_marquardt(
    problem: &Problem,
    start: DVector<f64>,
    max_iterations: usize,
) -> Result<Fit, TransientError> {
    let mut theta = start;
    let mut cur = problem.evaluate(&theta, true)?;
    let mut mu = 1e-4;
    let mut iterations = 0;
    let mut converged = false;
    while iterations < max_iterations {
        let j = cur.jacobian.as_ref().expect("asked for");
        let r = DVector::from_column_slice(&cur.residual);
        let a = j.transpose() * j;
        let g = j.transpose() * &r;
        let d: Vec<f64> = (0..a.nrows())
            .map(|i| a[(i, i)].sqrt().max(f64::MIN_POSITIVE))
            .collect();
        let mut accepted = false;
        while mu < 1e12 && iterations < max_iterations {
            let scaled = DMatrix::from_fn(a.nrows(), a.ncols(), |i, k| {
                a[(i, k)] / (d[i] * d[k]) + if i == k { mu } else { 0.0 }
            });
            let rhs = DVector::from_fn(a.nrows(), |i, _| -g[i] / d[i]);
            let Some(y) = scaled.cholesky().map(|c| c.solve(&rhs)) else {
                mu *= 10.0;
                continue;
            };
            let delta = DVector::from_fn(y.len(), |i, _| y[i] / d[i]);
            let trial = &theta + &delta;
            let in_region = trial
                .as_slice()
                .chunks(2)
                .zip(theta.as_slice().chunks(2))
                .all(|(t, o)| {
                    t[0] > 0.0 && t[1] >= 0.0 && ((t[0] - o[0]) / o[0]).abs() <= MAX_K_CHANGE
                });
            if !in_region {
                mu *= 10.0;
                continue;
            }
            iterations += 1;
            match problem.evaluate(&trial, true) {
                Ok(e) if e.cost < cur.cost => {
                    // the undamped step's length in standard errors
                    let s2 = (cur.cost / problem.data() as f64).max(f64::MIN_POSITIVE);
                    let length = (delta.dot(&(&a * &delta)) / s2).sqrt();
                    theta = trial;
                    cur = e;
                    mu = (mu / 10.0).max(1e-12);
                    accepted = true;
                    if length < 1e-4 {
                        converged = true;
                    }
                    break;
                }
                _ => mu *= 10.0,
            }
        }
        if converged || !accepted {
            // a rejected step at full damping: at the minimum (to rounding)
            converged = converged || mu >= 1e12;
            break;
        }
    }
    Ok(Fit {
        theta,
        eval: cur,
        converged,
        iterations,
    })
}

/// The modes of the sensors' 1X vectors along `sweep` (module doc), started from
/// `guesses` (most significant first, as [`guesses`] gives them).
///
/// Errors on unusable input (lengths, non-finite values, no guess, too few points for
/// the unknowns); a fit that does not converge is returned with `converged == false`.
pub fn fit_modes(
    sweep: &Sweep,
    sensors: &[SensorSeries],
    guesses: &[ModeGuess],
    settings: &ModeSettings,
) -> Result<ModeFit, TransientError> {
    sweep.validate()?;
    if guesses.is_empty() {
        return Err(TransientError::TooFew {
            what: "resonances to start a mode fit from".into(),
            found: 0,
            needed: 1,
        });
    }
    if sensors.is_empty() {
        return Err(TransientError::TooFew {
            what: "sensors for a mode fit".into(),
            found: 0,
            needed: 1,
        });
    }
    for s in sensors {
        same_length("vectors", s.vectors.len(), "speed", sweep.len())?;
        same_length("std", s.std.len(), "speed", sweep.len())?;
    }
    for g in guesses {
        if !(g.rpm.is_finite() && g.rpm > 0.0) {
            return Err(OutOfRange {
                field: "mode guess rpm",
                value: g.rpm,
                allowed: "finite and > 0 rev/min",
            }
            .into());
        }
    }
    let (lo_f, hi_f) = settings.window;
    let max_modes = settings.max_modes.clamp(1, guesses.len());
    let lo = guesses.iter().map(|g| g.rpm).fold(f64::INFINITY, f64::min) * lo_f;
    let hi = guesses.iter().map(|g| g.rpm).fold(0.0, f64::max) * hi_f;
    let rpm: Vec<f64> = sweep.speed().iter().map(|&w| rad_per_s_to_rpm(w)).collect();
    let inside = |r: f64| r >= lo && r <= hi;
    let first = rpm.iter().position(|&r| inside(r));
    let last = rpm.iter().rposition(|&r| inside(r));
    let (Some(first), Some(last)) = (first, last) else {
        return Err(TransientError::TooFew {
            what: format!("points between {lo:.0} and {hi:.0} rpm for a mode fit"),
            found: 0,
            needed: 1,
        });
    };
    let points = first..last + 1;
    let known = sensors.iter().all(|s| {
        s.std[points.clone()]
            .iter()
            .all(|v| v.is_finite() && *v > 0.0)
    });
    let problem = Problem {
        sweep: sweep.slice(points.clone()),
        sensors: sensors
            .iter()
            .map(|s| {
                let w = s.std[points.clone()]
                    .iter()
                    .map(|&v| if known { 1.0 / v } else { 1.0 })
                    .collect();
                (s.vectors[points.clone()].to_vec(), w)
            })
            .collect(),
        substeps: settings.substeps.max(1),
    };
    let n_data = problem.data();
    let mut candidates = Vec::new();
    let mut best: Option<(f64, usize, Fit)> = None;
    for n in 1..=max_modes {
        let unknowns = 2 * n + 2 * (n + 1) * sensors.len();
        if n_data <= unknowns + 1 {
            break;
        }
        let mut start: Vec<ModeGuess> = guesses[..n].to_vec();
        start.sort_by(|a, b| a.rpm.total_cmp(&b.rpm));
        let modes: Vec<Mode> = start
            .iter()
            .map(|g| Mode {
                omega: g.rpm * TAU / 60.0,
                zeta: g.damping_ratio,
            })
            .collect();
        let theta0 = ModalDescription::theta(&modes);
        match levenberg_marquardt(&problem, theta0, settings.max_iterations) {
            Ok(fit) => {
                let nf = n_data as f64;
                let bic = nf * (fit.eval.cost / nf).max(f64::MIN_POSITIVE).ln()
                    + unknowns as f64 * nf.ln();
                let noise_ratio = (fit.eval.cost / (n_data - unknowns) as f64).sqrt();
                candidates.push(Candidate {
                    modes: n,
                    bic,
                    noise_ratio: if known { noise_ratio } else { f64::NAN },
                    converged: fit.converged,
                });
                if best.as_ref().is_none_or(|b| bic < b.0) {
                    best = Some((bic, unknowns, fit));
                }
            }
            Err(_) => candidates.push(Candidate {
                modes: n,
                bic: f64::NAN,
                noise_ratio: f64::NAN,
                converged: false,
            }),
        }
    }
    let Some((_, unknowns, fit)) = best else {
        return Err(TransientError::TooFew {
            what: format!("points between {lo:.0} and {hi:.0} rpm for a one-mode fit"),
            found: points.len(),
            needed: 3 + 2 * sensors.len(),
        });
    };
    let dof = (n_data - unknowns) as f64;
    let s2 = fit.eval.cost / dof;
    let scale = if known { s2.max(1.0) } else { s2 };
    let j = fit.eval.jacobian.as_ref().expect("evaluated with it");
    let info = j.transpose() * j;
    let cov = info
        .clone()
        .try_inverse()
        .map(|c| c * scale)
        .unwrap_or_else(|| DMatrix::from_element(info.nrows(), info.ncols(), f64::INFINITY));
    let mut modes: Vec<FittedMode> = fit
        .theta
        .as_slice()
        .chunks(2)
        .enumerate()
        .map(|(m, kc)| {
            let (k, c) = (kc[0], kc[1]);
            let (vk, vc, ckc) = (
                cov[(2 * m, 2 * m)],
                cov[(2 * m + 1, 2 * m + 1)],
                cov[(2 * m, 2 * m + 1)],
            );
            let w = k.sqrt();
            let zeta = c / (2.0 * w);
            let dw_dk = 1.0 / (2.0 * w);
            let (dz_dk, dz_dc) = (-c / (4.0 * k * w), 1.0 / (2.0 * w));
            let w_std = dw_dk * vk.max(0.0).sqrt();
            let z_var = dz_dk * dz_dk * vk + 2.0 * dz_dk * dz_dc * ckc + dz_dc * dz_dc * vc;
            let z_std = z_var.max(0.0).sqrt();
            let (dec, dec_std) = if zeta < 1.0 {
                let root = (1.0 - zeta * zeta).sqrt();
                (
                    Some(TAU * zeta / root),
                    Some(TAU / (root * root * root) * z_std),
                )
            } else {
                (None, None)
            };
            FittedMode {
                rpm: rad_per_s_to_rpm(w),
                rpm_std: rad_per_s_to_rpm(w_std),
                damping_ratio: zeta,
                damping_ratio_std: z_std,
                log_decrement: dec,
                log_decrement_std: dec_std,
            }
        })
        .collect();
    modes.sort_by(|a, b| a.rpm.total_cmp(&b.rpm));
    let per_sensor = 2 * points.len();
    let ljung_box_p: Vec<f64> = fit
        .eval
        .residual
        .chunks(per_sensor)
        .map(|r| {
            let (re, im) = r.split_at(points.len());
            ljung_box(re).p.min(ljung_box(im).p)
        })
        .collect();
    let noise_ratio = if known { s2.sqrt() } else { f64::NAN };
    let adequate = (!known || noise_ratio <= NOISE_RATIO_MAX)
        && ljung_box_p.iter().all(|&p| p >= ADEQUACY_P_MIN);
    let basis = match sweep {
        Sweep::Transient { .. } => FitBasis::Transient,
        Sweep::Steady { .. } => FitBasis::SteadyState,
    };
    Ok(ModeFit {
        modes,
        basis,
        candidates,
        window_rpm: rpm[points.clone()]
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &r| {
                (a.min(r), b.max(r))
            }),
        points,
        data: n_data,
        unknowns,
        noise_ratio,
        ljung_box_p,
        adequate,
        converged: fit.converged,
        iterations: fit.iterations,
        model: fit.eval.model,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::transient::order::{track, OrderSettings};
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    /// Two probes at 45 and 135 deg of a rotor with two modes, one horizontal (w1) and one
    /// vertical (w2), sampled at `fs` on psi = w0 t + a t^2 / 2, integrated in the fixed
    /// frame (x'' + 2 z w x' + w^2 x = e w^2 cos(phi) + e a sin... from the real unbalance
    /// force) by RK4 at the sample step: independent of `synchronous`.
    fn rig(
        modes: [(f64, f64); 2],
        w0: f64,
        a: f64,
        dur: f64,
        fs: f64,
        noise: f64,
        seed: u64,
    ) -> (Vec<f64>, Vec<f64>, [Vec<f64>; 2]) {
        let n = (dur * fs) as usize;
        let h = 1.0 / fs;
        let e = 1e-5; // unbalance eccentricity [m]
                      // force per unit mass of the unbalance: x: e (w^2 cos phi + w' sin phi), z: e (w^2 sin phi - w' cos phi)
        let force = |t: f64| {
            let (w, phi) = (w0 + a * t, w0 * t + 0.5 * a * t * t);
            [
                e * (w * w * phi.cos() + a * phi.sin()),
                e * (w * w * phi.sin() - a * phi.cos()),
            ]
        };
        let rhs = |t: f64, y: [f64; 4]| {
            let f = force(t);
            let [(w1, z1), (w2, z2)] = modes;
            [
                y[2],
                y[3],
                f[0] - 2.0 * z1 * w1 * y[2] - w1 * w1 * y[0],
                f[1] - 2.0 * z2 * w2 * y[3] - w2 * w2 * y[1],
            ]
        };
        let add = |y: [f64; 4], k: [f64; 4], s: f64| {
            std::array::from_fn::<f64, 4, _>(|i| y[i] + s * k[i])
        };
        // start on the quasi-static response (the speed is far below both modes)
        let mut y = [0.0; 4];
        for (i, (w, z)) in modes.iter().enumerate() {
            let f = Complex::new(w0 * w0, -a) * e;
            let r = f / Complex::new(w * w - w0 * w0, 2.0 * z * w * w0);
            y[i] = if i == 0 {
                r.re
            } else {
                (r * Complex::new(0.0, -1.0)).re
            };
        }
        let mut rng = rand::rngs::StdRng::seed_from_u64(seed);
        let noise_d = Normal::new(0.0, noise).unwrap();
        let (mut t_out, mut psi, mut p1, mut p2) = (vec![], vec![], vec![], vec![]);
        let (c, s) = (
            std::f64::consts::FRAC_1_SQRT_2,
            std::f64::consts::FRAC_1_SQRT_2,
        );
        for i in 0..n {
            let t = i as f64 * h;
            t_out.push(t);
            psi.push(w0 * t + 0.5 * a * t * t);
            // probe at 45 deg: x cos + z sin; at 135 deg: -x cos + z sin
            p1.push(c * y[0] + s * y[1] + noise_d.sample(&mut rng));
            p2.push(-c * y[0] + s * y[1] + noise_d.sample(&mut rng));
            let k1 = rhs(t, y);
            let k2 = rhs(t + h / 2.0, add(y, k1, h / 2.0));
            let k3 = rhs(t + h / 2.0, add(y, k2, h / 2.0));
            let k4 = rhs(t + h, add(y, k3, h));
            y = std::array::from_fn(|j| {
                y[j] + h / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j])
            });
        }
        (t_out, psi, [p1, p2])
    }

    struct Tracks {
        sweep: Sweep,
        vectors: [Vec<C64>; 2],
        std: [Vec<f64>; 2],
    }

    fn tracks(t: &[f64], psi: &[f64], probes: &[Vec<f64>; 2]) -> Tracks {
        let settings = OrderSettings {
            orders: vec![1],
            harmonics: 4,
        };
        let tr: Vec<_> = probes
            .iter()
            .map(|p| track(t, psi, p, &settings).unwrap())
            .collect();
        let revs = &tr[0].revolutions;
        Tracks {
            sweep: Sweep::Transient {
                intervals: revs.iter().map(|r| (r.t_start, r.t_end)).collect(),
                speed: revs.iter().map(|r| r.speed).collect(),
            },
            vectors: std::array::from_fn(|k| {
                tr[k].revolutions.iter().map(|r| r.vectors[0]).collect()
            }),
            std: std::array::from_fn(|k| tr[k].revolutions.iter().map(|r| r.std[0]).collect()),
        }
    }

    fn fit(t: &Tracks, sweep: &Sweep, guesses: &[ModeGuess]) -> ModeFit {
        let sensors: Vec<SensorSeries> = (0..2)
            .map(|k| SensorSeries {
                vectors: &t.vectors[k],
                std: &t.std[k],
            })
            .collect();
        fit_modes(sweep, &sensors, guesses, &ModeSettings::default()).unwrap()
    }

    fn guess(rpm: f64, damping_ratio: f64, weight: f64) -> ModeGuess {
        ModeGuess {
            rpm,
            damping_ratio,
            weight,
        }
    }

    #[test]
    fn a_fast_run_up_gives_the_modes_without_the_sweep_bias() {
        // modes at 300 and 380 rad/s (2865, 3629 rpm), zeta 0.02 and 0.03, run up from
        // 150 rad/s at 40 rad/s^2: the apparent peaks lie about 1 % above the modes
        let modes = [(300.0, 0.02), (380.0, 0.03)];
        let (t, psi, probes) = rig(modes, 150.0, 40.0, 8.0, 4096.0, 2e-6, 7);
        let tr = tracks(&t, &psi, &probes);
        // guesses as the criticals would give them: 2 % high, damping 50 % off
        let g = [
            guess(2865.0 * 1.02, 0.03, 10.0),
            guess(3629.0 * 1.02, 0.02, 8.0),
        ];
        let f = fit(&tr, &tr.sweep, &g);
        assert_eq!(f.basis, FitBasis::Transient);
        assert_eq!(f.modes.len(), 2, "{:?}", f.candidates);
        assert!(
            f.converged && f.adequate,
            "{:?} {:?} {} {:?}",
            f.modes,
            f.candidates,
            f.noise_ratio,
            f.ljung_box_p
        );
        for (m, (w, z)) in f.modes.iter().zip(modes) {
            let rpm = rad_per_s_to_rpm(w);
            let e_rpm = (m.rpm - rpm) / rpm;
            let e_z = (m.damping_ratio - z) / z;
            assert!(e_rpm.abs() < 1e-3, "speed off by {e_rpm:e}: {m:?}");
            assert!(e_z.abs() < 0.05, "damping ratio off by {e_z:e}: {m:?}");
            // the stds are the scatter's: the errors within 4 of them
            assert!((m.rpm - rpm).abs() < 4.0 * m.rpm_std, "{m:?}");
            assert!(
                (m.damping_ratio - z).abs() < 4.0 * m.damping_ratio_std,
                "{m:?}"
            );
            let dec = TAU * z / (1.0 - z * z).sqrt();
            assert!((m.log_decrement.unwrap() - dec).abs() < 4.0 * m.log_decrement_std.unwrap());
        }
        // the steady-state formula fitted to the same vectors carries the sweep's lag
        let steady = Sweep::Steady {
            speed: tr.sweep.speed().to_vec(),
        };
        let s = fit(&tr, &steady, &g);
        assert_eq!(s.basis, FitBasis::SteadyState);
        let bias = (s.modes[0].rpm - rad_per_s_to_rpm(300.0)) / rad_per_s_to_rpm(300.0);
        let err = (f.modes[0].rpm - rad_per_s_to_rpm(300.0)) / rad_per_s_to_rpm(300.0);
        assert!(
            bias > 10.0 * err.abs() && bias > 2e-3,
            "steady bias {bias:e}, transient {err:e}"
        );
    }

    #[test]
    fn bic_keeps_one_mode_when_the_data_have_one() {
        // an isotropic rotor: one mode at 300 rad/s; a spurious second guess offered
        let modes = [(300.0, 0.03), (300.0, 0.03)];
        let (t, psi, probes) = rig(modes, 150.0, 30.0, 8.0, 4096.0, 2e-6, 11);
        let tr = tracks(&t, &psi, &probes);
        let g = [guess(2900.0, 0.03, 10.0), guess(3300.0, 0.05, 3.0)];
        let f = fit(&tr, &tr.sweep, &g);
        assert_eq!(f.candidates.len(), 2);
        assert_eq!(f.modes.len(), 1, "{:?}", f.candidates);
        let e = (f.modes[0].rpm - rad_per_s_to_rpm(300.0)) / rad_per_s_to_rpm(300.0);
        assert!(e.abs() < 1e-3, "{:?}", f.modes);
    }

    #[test]
    fn guesses_merge_the_criticals_of_one_mode() {
        let crit = |rpm: f64, significance: f64| Critical {
            rpm,
            rpm_std: 1.0,
            amplitude: 1e-5,
            amplitude_std: 1e-7,
            phase_lag_deg: 90.0,
            n1_rpm: None,
            n1_std: None,
            n2_rpm: None,
            n2_std: None,
            amplification_factor: None,
            amplification_factor_std: None,
            damping_ratio: Some(0.02),
            damping_ratio_std: None,
            significance,
        };
        let g = guesses(&[crit(3000.0, 5.0), crit(3050.0, 9.0), crit(4000.0, 7.0)]);
        assert_eq!(g.len(), 2);
        assert_eq!((g[0].rpm, g[1].rpm), (3050.0, 4000.0));
        assert_eq!(g[0].damping_ratio, 0.02);
    }

    #[test]
    fn unusable_input_is_refused_by_name() {
        let sweep = Sweep::Steady {
            speed: vec![100.0, 200.0, 300.0],
        };
        let v = vec![C64::new(1.0, 0.0); 3];
        let s = vec![1.0; 2];
        let sensors = [SensorSeries {
            vectors: &v,
            std: &s,
        }];
        let e = fit_modes(
            &sweep,
            &sensors,
            &[guess(1900.0, 0.05, 1.0)],
            &ModeSettings::default(),
        )
        .unwrap_err();
        assert!(
            e.to_string().contains("std has 2 values but speed has 3"),
            "{e}"
        );
        let s = vec![1.0; 3];
        let sensors = [SensorSeries {
            vectors: &v,
            std: &s,
        }];
        let e = fit_modes(&sweep, &sensors, &[], &ModeSettings::default()).unwrap_err();
        assert!(
            e.to_string().contains("resonances to start a mode fit"),
            "{e}"
        );
        let e = fit_modes(
            &sweep,
            &sensors,
            &[guess(f64::NAN, 0.05, 1.0)],
            &ModeSettings::default(),
        )
        .unwrap_err();
        assert!(e.to_string().contains("rpm"), "{e}");
    }
}
