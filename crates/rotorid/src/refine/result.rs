//! What a fit reports: estimates with standard errors, the noise level, convergence and
//! identifiability diagnostics. Serialisable (serde) for machine-readable summaries; note
//! that serde_json writes an infinite standard error (an unidentifiable parameter) as `null`.
//!
//! Reported parameters are m, cx, kx, cz, kz, a and, for the unbalance, m_u d and alpha,
//! whose standard errors follow from the internal (u_c, u_s) by the delta method:
//!
//! ```text
//! m_u d = hypot(u_c, u_s):   grad = (u_c, u_s) / m_u d
//! alpha = atan2(u_s, u_c):   grad = (-u_s, u_c) / (m_u d)^2
//! var   = grad^T Cov(u_c, u_s) grad
//! ```

use std::fmt;

use serde::Serialize;

use crate::model::{InitialState, RotorParams};
use crate::parameter::Sign;

use super::fisher::Fisher;
use super::unknowns::{Columns, Kind, Theta};

/// Above this condition number of the scaled Fisher information (unit diagonal) the
/// unknowns are so strongly correlated that the computed standard errors lose their
/// accuracy (rounding ~ 1e-16 x condition number); typical well-posed fits are at 1e3-1e5.
pub const CONDITION_LIMIT: f64 = 1.0e10;
/// Above this standard error \[rad\] the unbalance angle is reported as undetermined.
pub const ALPHA_STD_LIMIT: f64 = 1.0;

/// One estimated quantity.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FittedValue {
    /// Name: m, cx, kx, cz, kz, a, mud, alpha, x0, z0, vx0, vz0.
    pub name: &'static str,
    /// SI unit of `value` and `std_error` (kg, N s/m, N/m, N s^2/m, kg m, rad, m, m/s).
    pub unit: &'static str,
    /// The estimate \[unit\].
    pub value: f64,
    /// Standard error \[unit\]: sqrt of the diagonal of the inverse Fisher information at
    /// the estimate with the estimated sigma_x, sigma_z (the asymptotic standard error of
    /// the maximum-likelihood estimate, i.e. the Cramer-Rao bound evaluated at the
    /// estimate). +infinity when the data carry no information on it.
    pub std_error: f64,
    /// std_error / |value| (+infinity at value 0); `None` for alpha and the initial state.
    pub relative_std_error: Option<f64>,
    /// Standard error \[unit\] from the autocorrelation-robust sandwich covariance
    /// ([`Refined::robust`]), which does not assume a correct model; `None` when it was not
    /// computed (unidentifiable unknowns).
    pub robust_std_error: Option<f64>,
    /// Starting value of the fit \[unit\].
    pub start: f64,
    /// For a coefficient whose true value may be zero or negative (a cross-coupled one):
    /// the size \[unit\] its standard error must not exceed for it to count as determined,
    /// from the direct coefficients (sqrt(kx kz) for kxz, kzx; the larger of sqrt(cx cz)
    /// and 1 % of the critical damping 2 sqrt(m sqrt(kx kz)) for cxz, czx). `None` for the
    /// others, whose standard error is compared with their value.
    pub scale: Option<f64>,
    /// The Cramer-Rao bound at the true parameters and true noise \[unit\], when attached
    /// with [`Refined::attach_crb`] (simulation studies), else `None`.
    pub crb: Option<f64>,
}

/// A diagnostic the user should read before trusting the numbers.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Warning {
    /// The data carry no information on these parameters (alone or in combination): the
    /// Fisher information is singular along them; their values are arbitrary.
    NotIdentifiable {
        /// Names of the parameters concerned.
        parameters: Vec<&'static str>,
        /// The record holds no significant free transient at constant speed: only the
        /// steady-state response informs the fit (its message says what record would).
        steady_state_only: bool,
    },
    /// The unknowns are so strongly correlated that the data barely separate them and the
    /// standard errors are numerically unreliable.
    IllConditioned {
        /// Condition number of the scaled Fisher information.
        condition_number: f64,
        /// The limit it exceeds ([`CONDITION_LIMIT`]).
        limit: f64,
        /// The unknowns in the least informed direction (the near-null space), largest
        /// share first.
        parameters: Vec<&'static str>,
    },
    /// The standard error exceeds the value itself (or 1 rad for alpha; or, for a
    /// cross-coupled coefficient, its scale [`FittedValue::scale`]).
    PoorlyDetermined {
        /// The parameter.
        parameter: &'static str,
        /// Its standard error over its absolute value (for alpha: its standard error, rad;
        /// for a cross-coupled coefficient: over its scale).
        relative_std_error: f64,
    },
    /// The iteration limit was reached before the step fell below the tolerance.
    NotConverged {
        /// Model passes made.
        iterations: usize,
        /// Length of the last Gauss-Newton step in standard errors.
        last_step: f64,
    },
    /// Constant speed, initial state estimated, and the fitted free transient is not
    /// significant (its initial-state offset from the steady state is below 10 standard
    /// errors): the standard errors are those of the steady-state response alone, which
    /// fixes only amplitude and phase per channel.
    NoSignificantTransient {
        /// The offset's Mahalanobis length in standard errors.
        significance: f64,
    },
    /// An estimate outside the physical range of the model (c < 0, k <= 0 or m <= 0).
    Unphysical {
        /// The parameter.
        parameter: &'static str,
        /// Its estimate.
        value: f64,
    },
}

impl fmt::Display for Warning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Warning::NotIdentifiable {
                parameters,
                steady_state_only,
            } => {
                write!(
                    f,
                    "not identifiable from this record: {} (the data carry no information on them; values are arbitrary)",
                    parameters.join(", ")
                )?;
                if *steady_state_only {
                    write!(
                        f,
                        ": a steady-state unbalance response at one speed gives two real equations per direction (the amplitude and phase of x and of z), which cannot separate mass, damping and stiffness, nor direct from cross-coupled bearing coefficients; a record with a start-up transient, a run-up or a coast-down can"
                    )?;
                }
                Ok(())
            }
            Warning::IllConditioned {
                condition_number,
                limit,
                parameters,
            } => {
                write!(
                    f,
                    "the unknowns are nearly inseparable: Fisher information condition number {condition_number:.3e} > {limit:.0e}"
                )?;
                if !parameters.is_empty() {
                    write!(
                        f,
                        "; the record hardly tells apart {}",
                        parameters.join(", ")
                    )?;
                }
                Ok(())
            }
            Warning::PoorlyDetermined {
                parameter,
                relative_std_error,
            } => {
                if *parameter == "alpha" {
                    write!(f, "alpha is undetermined: standard error {relative_std_error:.3} rad")
                } else if matches!(*parameter, "cxz" | "czx" | "kxz" | "kzx") {
                    write!(
                        f,
                        "{parameter} is undetermined: standard error is {relative_std_error:.3e} times the size of the direct coefficients it couples"
                    )
                } else {
                    write!(
                        f,
                        "{parameter} is undetermined: standard error is {relative_std_error:.3e} times its value"
                    )
                }
            }
            Warning::NotConverged {
                iterations,
                last_step,
            } => write!(
                f,
                "not converged after {iterations} iterations (last step {last_step:.3e} standard errors)"
            ),
            Warning::NoSignificantTransient { significance } => write!(
                f,
                "the record holds no significant free transient ({significance:.2} standard errors): only the steady-state response informs the fit, uncertainties are computed from it alone"
            ),
            Warning::Unphysical { parameter, value } => {
                write!(f, "{parameter} = {value:e} is outside the model's physical range")
            }
        }
    }
}

/// The result of [`refine`](super::refine).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Refined {
    /// The estimated model parameters, in the order m, cx, kx, cz, kz, a, mud, alpha
    /// (only those selected as unknown).
    pub parameters: Vec<FittedValue>,
    /// The estimated initial state x0, z0 \[m\], vx0, vz0 \[m/s\] (empty when it was known).
    pub initial_state: Vec<FittedValue>,
    /// All rotor parameters: the estimates and the known values. The unbalance keeps the
    /// starting radius d (if > 0; else d = 1 m) with m_u = (m_u d) / d.
    pub rotor: RotorParams,
    /// The initial state used by the final model (estimated or known).
    pub initial: InitialState,
    /// Estimated noise standard deviation on x \[m\]: sqrt(sum r_x^2 / N).
    pub sigma_x: f64,
    /// Estimated noise standard deviation on z \[m\]: sqrt(sum r_z^2 / N).
    pub sigma_z: f64,
    /// Samples per channel used.
    pub samples: usize,
    /// Model passes (each one Levenberg-Marquardt trial) after the starting point.
    pub iterations: usize,
    /// True when the last Gauss-Newton step was below the tolerance (in standard errors)
    /// or at the rounding floor.
    pub converged: bool,
    /// False when any warning says the data cannot separate the unknowns.
    pub identifiable: bool,
    /// Condition number of the Fisher information scaled to unit diagonal.
    pub condition_number: f64,
    /// Rank of the Fisher information: the directions of the unknowns the record informs
    /// (the number of unknowns when all are identifiable).
    pub fisher_rank: usize,
    /// Diagnostics, worst first.
    pub warnings: Vec<Warning>,
    /// The discrete model used.
    pub discretisation: String,
    /// How `std_error` was computed.
    pub std_error_basis: &'static str,
    /// Covariance of the internal parameters (unbalance as mud_cos_alpha, mud_sin_alpha),
    /// names in `covariance_names`, row-major; NaN/inf rows for unidentifiable ones.
    pub covariance: Vec<Vec<f64>>,
    /// Names of the rows/columns of `covariance`.
    pub covariance_names: Vec<&'static str>,
    /// The sandwich covariance beside the Fisher one (docs/method.md section 5.5).
    pub robust: Option<RobustCovariance>,
}

/// The autocorrelation-robust (HAC) sandwich covariance of a fit: F^-1 B F^-1 with the
/// Bartlett-weighted outer products of the scores (docs/method.md section 5.5).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RobustCovariance {
    /// Bartlett bandwidth L \[samples\] (Andrews' AR(1) rule; 0 for white residuals).
    pub bandwidth: usize,
    /// Pooled lag-1 autocorrelation of the noise-weighted residuals.
    pub residual_lag1_autocorrelation: f64,
    /// The covariance, in the order of [`Refined::covariance_names`].
    pub covariance: Vec<Vec<f64>>,
}

/// The basis of every reported standard error.
pub const STD_ERROR_BASIS: &str =
    "inverse Fisher information at the estimate with the estimated noise (asymptotic ML standard error = Cramer-Rao bound evaluated at the estimate)";

impl Refined {
    /// The estimate called `name` (a parameter or an initial-state component).
    pub fn get(&self, name: &str) -> Option<&FittedValue> {
        self.parameters
            .iter()
            .chain(self.initial_state.iter())
            .find(|e| e.name == name)
    }

    /// Fill each estimate's `crb` from a bound computed at the truth (simulation studies).
    pub fn attach_crb(&mut self, crb: &Crb) {
        for e in self
            .parameters
            .iter_mut()
            .chain(self.initial_state.iter_mut())
        {
            e.crb = crb.get(e.name).map(|b| b.std_dev);
        }
    }
}

/// One Cramer-Rao bound.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Bound {
    /// Parameter name (as in [`FittedValue::name`]).
    pub name: &'static str,
    /// SI unit of `value` and `std_dev`.
    pub unit: &'static str,
    /// The true value \[unit\].
    pub value: f64,
    /// Lower bound on the standard deviation of any unbiased estimator \[unit\]
    /// (+infinity when not identifiable).
    pub std_dev: f64,
    /// std_dev / |value|; `None` for alpha and the initial state.
    pub relative: Option<f64>,
}

/// The Cramer-Rao bound of an experiment (see [`crb`](super::crb())).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Crb {
    /// Bounds on the model parameters (order as in [`Refined::parameters`]).
    pub parameters: Vec<Bound>,
    /// Bounds on the initial state, when it is unknown.
    pub initial_state: Vec<Bound>,
    /// Noise standard deviation on x used \[m\].
    pub sigma_x: f64,
    /// Noise standard deviation on z used \[m\].
    pub sigma_z: f64,
    /// Condition number of the scaled Fisher information.
    pub condition_number: f64,
    /// False when some unknown has no information (infinite bound) or the condition
    /// number exceeds [`CONDITION_LIMIT`].
    pub identifiable: bool,
    /// The discrete model used.
    pub discretisation: String,
}

impl Crb {
    /// The bound called `name`.
    pub fn get(&self, name: &str) -> Option<&Bound> {
        self.parameters
            .iter()
            .chain(self.initial_state.iter())
            .find(|b| b.name == name)
    }

    /// Its relative value std_dev / |value|.
    pub fn relative(&self, name: &str) -> Option<f64> {
        self.get(name).and_then(|b| b.relative)
    }
}

/// A reported quantity before it is dressed as a [`FittedValue`] or a [`Bound`].
pub(crate) struct Row {
    pub name: &'static str,
    pub unit: &'static str,
    pub value: f64,
    pub std: f64,
    pub initial: bool,
    pub relative: Option<f64>,
    /// [`FittedValue::scale`].
    pub scale: Option<f64>,
    /// Outside the physical range of its parameter (m, a direct stiffness <= 0; a direct
    /// damping < 0).
    pub unphysical: bool,
}

/// The scale of a cross-coupled coefficient ([`FittedValue::scale`]) at `t`.
fn cross_scale(k: Kind, t: &Theta) -> Option<f64> {
    let stiffness = (t.kx * t.kz).abs().sqrt();
    match k {
        Kind::Kxz | Kind::Kzx => Some(stiffness),
        Kind::Cxz | Kind::Czx => {
            let critical = 2.0 * (t.m.abs() * stiffness).sqrt();
            Some((t.cx * t.cz).abs().sqrt().max(0.01 * critical))
        }
        _ => None,
    }
}

fn relative(std: f64, value: f64) -> f64 {
    if value == 0.0 {
        f64::INFINITY
    } else {
        std / value.abs()
    }
}

/// The names of the columns in the least informed direction of `fi` (the internal names:
/// the unbalance as mud_cos_alpha, mud_sin_alpha).
pub(crate) fn weakest_names(fi: &Fisher, cols: &Columns) -> Vec<&'static str> {
    fi.weakest(WEAK_SHARE)
        .into_iter()
        .map(|j| cols.kinds()[j].name_in(cols.model))
        .collect()
}

/// Squared weight in the least informed direction above which an unknown is named in an
/// ill-conditioning warning (the weights of a unit vector sum to 1).
const WEAK_SHARE: f64 = 0.1;

/// The reported quantities at `t` with covariance from `fi` (column order `cols`).
pub(crate) fn rows(t: &Theta, cols: &Columns, fi: &Fisher) -> Vec<Row> {
    let n = cols.n;
    let mut out = Vec::new();
    for (j, &k) in cols.kinds().iter().enumerate() {
        match k {
            Kind::Uc => {
                let js = cols.position(Kind::Us).expect("u_s accompanies u_c");
                let (uc, us) = (t.uc, t.us);
                let mud = t.mud();
                let (vcc, vss, vcs) = (fi.cov[j * n + j], fi.cov[js * n + js], fi.cov[j * n + js]);
                let bad = fi.unidentifiable[j] || fi.unidentifiable[js];
                let (s_mud, s_alpha) = if bad {
                    (f64::INFINITY, f64::INFINITY)
                } else if mud > 0.0 {
                    let (a, b) = (uc / mud, us / mud);
                    let v_mud = a * a * vcc + 2.0 * a * b * vcs + b * b * vss;
                    let (c, d) = (-us / (mud * mud), uc / (mud * mud));
                    let v_alpha = c * c * vcc + 2.0 * c * d * vcs + d * d * vss;
                    (v_mud.max(0.0).sqrt(), v_alpha.max(0.0).sqrt())
                } else {
                    (vcc.max(vss).sqrt(), f64::INFINITY)
                };
                out.push(Row {
                    name: "mud",
                    unit: "kg m",
                    value: mud,
                    std: s_mud,
                    initial: false,
                    relative: Some(relative(s_mud, mud)),
                    scale: None,
                    unphysical: false,
                });
                out.push(Row {
                    name: "alpha",
                    unit: "rad",
                    value: us.atan2(uc),
                    std: s_alpha,
                    initial: false,
                    relative: None,
                    scale: None,
                    unphysical: false,
                });
            }
            Kind::Us => {}
            _ => {
                let initial = k.initial_index().is_some();
                let v = t.get(k);
                let s = fi.std(j);
                let unphysical = match k.parameter(cols.model).map(|p| p.sign()) {
                    Some(Sign::Positive) => v <= 0.0,
                    Some(Sign::NonNegative) => v < 0.0,
                    _ => false,
                };
                out.push(Row {
                    name: k.name_in(cols.model),
                    unit: k.unit(),
                    value: v,
                    std: s,
                    initial,
                    relative: if initial { None } else { Some(relative(s, v)) },
                    scale: cross_scale(k, t),
                    unphysical,
                });
            }
        }
    }
    out
}

/// Identifiability warnings for `rows` (NotIdentifiable, IllConditioned with the unknowns
/// of the least informed direction `weakest`, PoorlyDetermined).
pub(crate) fn identifiability_warnings(
    rows: &[Row],
    condition_number: f64,
    weakest: Vec<&'static str>,
) -> Vec<Warning> {
    let mut w = Vec::new();
    let unid: Vec<&'static str> = rows
        .iter()
        .filter(|r| r.std.is_infinite())
        .map(|r| r.name)
        .collect();
    let any_unid = !unid.is_empty();
    if any_unid {
        w.push(Warning::NotIdentifiable {
            parameters: unid,
            steady_state_only: false,
        });
    }
    if condition_number > CONDITION_LIMIT && !any_unid {
        w.push(Warning::IllConditioned {
            condition_number,
            limit: CONDITION_LIMIT,
            parameters: weakest,
        });
    }
    for r in rows.iter().filter(|r| r.std.is_finite() && !r.initial) {
        if r.name == "alpha" {
            if r.std > ALPHA_STD_LIMIT {
                w.push(Warning::PoorlyDetermined {
                    parameter: r.name,
                    relative_std_error: r.std,
                });
            }
        } else if let Some(scale) = r.scale {
            if r.std > scale || scale.is_nan() {
                w.push(Warning::PoorlyDetermined {
                    parameter: r.name,
                    relative_std_error: r.std / scale,
                });
            }
        } else if let Some(rel) = r.relative {
            if rel > 1.0 {
                w.push(Warning::PoorlyDetermined {
                    parameter: r.name,
                    relative_std_error: rel,
                });
            }
        }
    }
    w
}
