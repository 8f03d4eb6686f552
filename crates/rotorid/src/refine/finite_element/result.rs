//! The result of a finite-element fit (module doc of `super`).

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use super::evaluate::{normal_equations, Evaluation};
use super::{full_initial, FeInitial, FeProblem, FeRefineError, FeRefineOptions, Fit};
use crate::model::finite_element::{Dof, FeParameter, FiniteElementRotor};
use crate::refine::CONDITION_LIMIT;
use crate::residual::ChannelAdequacy;
use crate::simulate::finite_element::FeInitialState;

/// One estimated parameter of a finite-element rotor.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FeFittedValue {
    /// Its name (`bearing0.kxx`, `unbalance1.alpha`).
    pub parameter: String,
    /// SI unit of `value` and the errors (N/m, N s/m, kg m, rad).
    pub unit: &'static str,
    /// The estimate \[unit\].
    pub value: f64,
    /// Standard error \[unit\] from the Fisher information at the estimate with the
    /// channels' estimated noise (+infinity when the data do not determine it).
    pub std_error: f64,
    /// std_error / |value| (None for an angle).
    pub relative_std_error: Option<f64>,
    /// Where the fit started \[unit\].
    pub start: f64,
    /// The Cramer-Rao bound at the truth \[unit\], when a simulation study attaches it.
    pub crb: Option<f64>,
    /// The shift the reduction causes at the estimate, in standard errors (the full
    /// model's response minus the reduced one, projected on this parameter), when measured.
    pub reduction_bias_std: Option<f64>,
}

/// A channel's fitted constant offset: data = model response + offset + noise.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FeOffset {
    /// The channel (`<node>.<dof>`).
    pub channel: String,
    /// The offset \[m or rad, the channel's unit\].
    pub value: f64,
    /// Its standard error \[same unit\] (+infinity when not determined).
    pub std_error: f64,
}

/// A diagnostic of a finite-element fit.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum FeWarning {
    /// The Fisher information is (nearly) singular: the data cannot separate the named
    /// unknowns (those with the largest share of its weakest direction).
    NotIdentifiable {
        /// Condition number of the unit-diagonal Fisher information.
        condition_number: f64,
        /// The unknowns involved.
        unknowns: Vec<String>,
    },
    /// The fit stopped before its step fell below the tolerance.
    NotConverged {
        /// Levenberg-Marquardt trials made.
        trials: usize,
    },
    /// A channel's residuals fail the adequacy tests: the model misses something there.
    ModelInadequate {
        /// The channel (`<node>.<dof>`).
        channel: String,
        /// Ljung-Box p-value.
        ljung_box_p: f64,
        /// Residual level over the data's own noise level.
        noise_ratio: f64,
    },
    /// The reduction moves an estimate by more than half its standard error: use more
    /// modes.
    ReductionBias {
        /// The parameter.
        parameter: String,
        /// Its bias in standard errors.
        bias_std: f64,
    },
}

/// The reduction used by the fit and what it cost.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FeReduction {
    /// Modes in the basis.
    pub modes: usize,
    /// Static shapes in the basis.
    pub statics: usize,
    /// Basis size r (reduced coordinates).
    pub size: usize,
    /// Degrees of freedom of the full model.
    pub full: usize,
    /// RMS over the channels of (full - reduced response) / RMS of the response at the
    /// estimate (None when not measured).
    pub relative_error: Option<f64>,
    /// The largest |bias| in standard errors over the parameters (None when not measured).
    pub max_bias_std: Option<f64>,
}

/// The result of [`refine_fe`](super::refine_fe).
#[derive(Debug, Clone)]
pub struct FeRefined {
    /// The estimated parameters, in the order of the unknowns.
    pub parameters: Vec<FeFittedValue>,
    /// The rotor with the estimates in (the known values kept).
    pub rotor: FiniteElementRotor,
    /// How the initial state was treated.
    pub initial: FeInitial,
    /// The fitted initial state in full coordinates (None at rest).
    pub initial_state: Option<FeInitialState>,
    /// Each channel's fitted constant offset, when estimated
    /// ([`FeRefineOptions::offsets`](super::FeRefineOptions::offsets)).
    pub offsets: Option<Vec<FeOffset>>,
    /// The channels, with the noise standard deviation estimated from the residuals \[m or
    /// rad\].
    pub noise: Vec<(Dof, f64)>,
    /// Samples per channel.
    pub samples: usize,
    /// Levenberg-Marquardt trials.
    pub iterations: usize,
    /// The step fell below the tolerance.
    pub converged: bool,
    /// The Fisher information is well conditioned.
    pub identifiable: bool,
    /// Condition number of the unit-diagonal Fisher information of the parameters.
    pub condition_number: f64,
    /// Covariance of the parameters (unknowns only, their order) \[unit_i unit_j\].
    pub covariance: DMatrix<f64>,
    /// The channels' residual tests.
    pub adequacy: Vec<(Dof, ChannelAdequacy)>,
    /// Every channel adequate.
    pub model_adequate: bool,
    /// The reduction.
    pub reduction: FeReduction,
    /// Diagnostics, worst first.
    pub warnings: Vec<FeWarning>,
    /// The model response at the estimate (channels x samples).
    pub model_response: Vec<Vec<f64>>,
}

impl FeRefined {
    /// The fitted value of `name`.
    pub fn get(&self, name: &str) -> Option<&FeFittedValue> {
        self.parameters.iter().find(|p| p.parameter == name)
    }

    /// Attach the Cramer-Rao bounds `crb` (order of the parameters).
    pub fn attach_crb(&mut self, crb: &[f64]) {
        for (p, b) in self.parameters.iter_mut().zip(crb) {
            p.crb = Some(*b);
        }
    }
}

/// Inverse of a symmetric positive definite matrix (None when not).
pub(crate) fn inverse(a: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    // scale to unit diagonal for accuracy
    let n = a.nrows();
    let d: Vec<f64> = (0..n).map(|i| a[(i, i)].max(0.0).sqrt()).collect();
    if d.iter()
        .any(|v| v.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater))
    {
        return None;
    }
    let s = DMatrix::from_fn(n, n, |i, j| a[(i, j)] / (d[i] * d[j]));
    let inv = s.cholesky()?.inverse();
    Some(DMatrix::from_fn(n, n, |i, j| inv[(i, j)] / (d[i] * d[j])))
}

/// Condition number of the unit-diagonal matrix and its weakest eigenvector.
fn conditioning(a: &DMatrix<f64>) -> (f64, DVector<f64>) {
    let n = a.nrows();
    let d: Vec<f64> = (0..n).map(|i| a[(i, i)].max(0.0).sqrt()).collect();
    if d.iter()
        .any(|v| v.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater))
    {
        let i = d
            .iter()
            .position(|v| v.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater))
            .unwrap_or(0);
        let mut e = DVector::zeros(n);
        e[i] = 1.0;
        return (f64::INFINITY, e);
    }
    let s = DMatrix::from_fn(n, n, |i, j| a[(i, j)] / (d[i] * d[j]));
    let eig = s.symmetric_eigen();
    let (mut lo, mut hi, mut at) = (f64::INFINITY, 0.0_f64, 0);
    for (i, &l) in eig.eigenvalues.iter().enumerate() {
        if l < lo {
            lo = l;
            at = i;
        }
        hi = hi.max(l);
    }
    let cond = if lo > 0.0 { hi / lo } else { f64::INFINITY };
    (cond, eig.eigenvectors.column(at).into_owned())
}

/// Standard errors, adequacy, reduction bias and warnings at the fit's estimate.
pub(crate) fn finish(
    problem: &FeProblem,
    y: &[&[f64]],
    mut fit: Fit,
    trials: usize,
    converged: bool,
    options: &FeRefineOptions,
) -> Result<super::FeRefined, FeRefineError> {
    let eval: Evaluation = match fit.eval.take() {
        Some(e) if e.k == 1 && e.y[0].len() == problem.samples() => e,
        _ => problem.evaluate(
            &fit.rotor,
            fit.basis.matrix(),
            &fit.x0,
            (1, problem.samples()),
            true,
        )?,
    };
    let weights = eval.residual_weights(y, 1);
    let (a, _) = normal_equations(&eval, None, &weights);
    let np = problem.unknowns().len();
    let (cond_all, weak) = conditioning(&a);
    let cov_all = inverse(&a);
    // the parameters' block: their marginal covariance
    let covariance = match &cov_all {
        Some(c) if cond_all < CONDITION_LIMIT => c.view((0, 0), (np, np)).into_owned(),
        _ => DMatrix::from_element(np, np, f64::INFINITY),
    };
    let (cond, _) = if np > 0 {
        let ap = a.view((0, 0), (np, np)).into_owned();
        conditioning(&ap)
    } else {
        (1.0, DVector::zeros(0))
    };
    let identifiable = cond_all < CONDITION_LIMIT && cov_all.is_some();
    let mut warnings = Vec::new();
    if !identifiable {
        let mut names: Vec<(f64, String)> = weak
            .iter()
            .enumerate()
            .filter(|(_, v)| v.abs() > 0.1)
            .map(|(i, v)| {
                let name = if i < np {
                    problem.unknowns()[i].to_string()
                } else if i < np + problem.states() {
                    format!("initial state {}", i - np)
                } else {
                    format!("offset of {}", problem.outputs()[i - np - problem.states()])
                };
                (-v.abs(), name)
            })
            .collect();
        names.sort_by(|a, b| a.0.total_cmp(&b.0));
        warnings.push(FeWarning::NotIdentifiable {
            condition_number: cond_all,
            unknowns: names.into_iter().map(|(_, n)| n).collect(),
        });
    }
    if !converged {
        warnings.push(FeWarning::NotConverged { trials });
    }
    let dt = problem.dt();
    let adequacy: Vec<(Dof, ChannelAdequacy)> = problem
        .outputs()
        .iter()
        .enumerate()
        .map(|(c, d)| (*d, crate::residual::channel(y[c], &eval.y[c], dt)))
        .collect();
    for (d, a) in &adequacy {
        if !a.adequate {
            warnings.push(FeWarning::ModelInadequate {
                channel: d.to_string(),
                ljung_box_p: a.ljung_box_p,
                noise_ratio: a.noise_ratio,
            });
        }
    }
    let std: Vec<f64> = (0..np)
        .map(|i| {
            let v = covariance[(i, i)];
            if v.is_finite() && v >= 0.0 {
                v.sqrt()
            } else {
                f64::INFINITY
            }
        })
        .collect();
    // the reduction's bias: full minus reduced response at the estimate
    let mut bias = vec![None; np];
    let mut relative_error = None;
    let mut max_bias = None;
    if options.reduction_bias {
        let full = crate::model::finite_element::FeSystem::full(&fit.rotor);
        let init = (problem.states() > 0).then(|| full_initial(fit.basis.matrix(), &fit.x0));
        let mut yf = problem.simulate(&full, (1, problem.samples()), init.as_ref())?;
        if problem.offsets() {
            for (c, yc) in yf.iter_mut().enumerate() {
                let o = fit.x0[problem.states() + c];
                yc.iter_mut().for_each(|v| *v += o);
            }
        }
        let (mut num, mut den) = (0.0, 0.0);
        let mut shift = Evaluation {
            y: Vec::new(),
            jac: Vec::new(),
            k: 1,
            units: Vec::new(),
        };
        // delta y as the "data" of a normal-equation right-hand side: J^T W (yf - y)
        shift.y.clone_from(&eval.y);
        for (m, f) in eval.y.iter().zip(&yf) {
            for (a, b) in m.iter().zip(f) {
                num += (b - a) * (b - a);
                den += a * a;
            }
        }
        relative_error = Some(if den > 0.0 { (num / den).sqrt() } else { 0.0 });
        let yf_refs: Vec<&[f64]> = yf.iter().map(|c| c.as_slice()).collect();
        shift.jac.clone_from(&eval.jac);
        let (_, g) = normal_equations(&shift, Some((&yf_refs, 1)), &weights);
        if let Some(c) = &cov_all {
            let d = c * g;
            let mut worst: f64 = 0.0;
            for i in 0..np {
                if std[i].is_finite() && std[i] > 0.0 {
                    let b = d[i] / std[i];
                    bias[i] = Some(b);
                    worst = worst.max(b.abs());
                    if b.abs() > 0.5 {
                        warnings.push(FeWarning::ReductionBias {
                            parameter: problem.unknowns()[i].to_string(),
                            bias_std: b,
                        });
                    }
                }
            }
            max_bias = Some(worst);
        }
    }
    let start = fit.start_values().to_vec();
    let parameters = problem
        .unknowns()
        .iter()
        .enumerate()
        .map(|(i, p)| {
            let value = p.get(&fit.rotor).unwrap_or(f64::NAN);
            FeFittedValue {
                parameter: p.to_string(),
                unit: p.unit(),
                value,
                std_error: std[i],
                relative_std_error: match p {
                    FeParameter::Alpha { .. } => None,
                    _ => Some(if value != 0.0 {
                        std[i] / value.abs()
                    } else {
                        f64::INFINITY
                    }),
                },
                start: start[i],
                crb: None,
                reduction_bias_std: bias[i],
            }
        })
        .collect();
    let noise = problem
        .outputs()
        .iter()
        .zip(&weights)
        .map(|(d, w)| (*d, 1.0 / w.sqrt()))
        .collect();
    let model_adequate = adequacy.iter().all(|(_, a)| a.adequate);
    let initial_state = (problem.states() > 0).then(|| full_initial(fit.basis.matrix(), &fit.x0));
    // the channels' offsets with their standard errors (marginal, from the full covariance)
    let offsets = problem.offsets().then(|| {
        let at = np + problem.states();
        problem
            .outputs()
            .iter()
            .enumerate()
            .map(|(c, d)| {
                let v = cov_all
                    .as_ref()
                    .filter(|_| identifiable)
                    .map_or(f64::INFINITY, |m| m[(at + c, at + c)]);
                FeOffset {
                    channel: d.to_string(),
                    value: fit.x0[at - np + c],
                    std_error: if v.is_finite() && v >= 0.0 {
                        v.sqrt()
                    } else {
                        f64::INFINITY
                    },
                }
            })
            .collect()
    });
    Ok(super::FeRefined {
        parameters,
        initial: problem.initial(),
        initial_state,
        offsets,
        noise,
        samples: problem.samples(),
        iterations: trials,
        converged,
        identifiable,
        condition_number: cond,
        covariance,
        adequacy,
        model_adequate,
        reduction: FeReduction {
            modes: fit.basis.modes(),
            statics: fit.basis.statics(),
            size: fit.basis.len(),
            full: fit.rotor.matrices.n(),
            relative_error,
            max_bias_std: max_bias,
        },
        warnings,
        model_response: eval.y,
        rotor: fit.rotor,
    })
}
