//! SUMMARY.json of a finite-element identification (docs/summary.md, "finite_element"):
//! the same top-level layout as the 2-DOF models' (`schema`, `method`, `model`, `input`,
//! `scenario`, `record`, `parameters`, `rotor`, `covariance`, `noise`, `diagnostics`),
//! with the finite-element rotor's bearings and unbalances, the initial state, the
//! reduction and each channel's adequacy.

use serde::Serialize;

use super::{FeInitial, FeOffset, FeReduction, FeRefined, FeWarning};
use crate::model::finite_element::{Bearing, FeUnbalance};
use crate::residual::ChannelAdequacy;
use crate::IDENTIFICATION_SCHEMA;

/// The summary (module doc). Non-finite numbers are written as null.
#[derive(Debug, Clone, Serialize)]
pub struct FeSummary {
    /// [`IDENTIFICATION_SCHEMA`].
    pub schema: u32,
    /// "refine".
    pub method: &'static str,
    /// "finite_element".
    pub model: &'static str,
    /// The data file, as given.
    pub input: Option<String>,
    /// The scenario file, as given.
    pub scenario: Option<String>,
    /// The record.
    pub record: FeRecordSummary,
    /// How the initial state was treated.
    pub initial: FeInitial,
    /// The fitted initial state (full coordinates), null at rest.
    pub initial_state: Option<FeInitialStateSummary>,
    /// Each channel's fitted constant offset \[m or rad\] with its standard error (null:
    /// infinite), when estimated (a record conditioned from raw probes); absent otherwise.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub offsets: Option<Vec<FeOffset>>,
    /// One entry per unknown, in the order of the unknowns.
    pub parameters: Vec<FeParameterSummary>,
    /// Every bearing and unbalance with the identified values in.
    pub rotor: FeRotorSummary,
    /// Covariance of the unknowns (their order) \[unit_i unit_j\]; null entries infinite.
    pub covariance: FeCovariance,
    /// Noise per channel.
    pub noise: FeNoise,
    /// The reduction and its bias.
    pub reduction: FeReduction,
    /// Each channel's residual tests.
    pub adequacy: FeAdequacy,
    /// Diagnostics, worst first.
    pub diagnostics: Vec<FeWarning>,
    /// The step fell below the tolerance.
    pub converged: bool,
    /// The Fisher information is well conditioned.
    pub identifiable: bool,
    /// Levenberg-Marquardt trials.
    pub iterations: usize,
    /// Condition number of the unit-diagonal Fisher information of the parameters (null:
    /// infinite).
    pub condition_number: Option<f64>,
}

/// The record's shape.
#[derive(Debug, Clone, Serialize)]
pub struct FeRecordSummary {
    /// Samples per channel.
    pub samples: usize,
    /// First time stamp \[s\].
    pub t_first_s: f64,
    /// Last time stamp \[s\].
    pub t_last_s: f64,
    /// Sampling period \[s\].
    pub dt_s: f64,
    /// The measured degrees of freedom.
    pub channels: Vec<String>,
    /// Where the speed came from ("profile": the scenario's \[speed\]).
    pub speed: &'static str,
}

/// The initial state in full coordinates.
#[derive(Debug, Clone, Serialize)]
pub struct FeInitialStateSummary {
    /// Every degree of freedom of the matrices.
    pub dofs: Vec<String>,
    /// q(0) \[m or rad\].
    pub q: Vec<f64>,
    /// q'(0) \[m/s or rad/s\].
    pub v: Vec<f64>,
}

/// One estimated parameter.
#[derive(Debug, Clone, Serialize)]
pub struct FeParameterSummary {
    /// `bearing<i>.<coefficient>`, `unbalance<j>.mud`, `unbalance<j>.alpha`.
    pub parameter: String,
    /// Its SI unit.
    pub unit: &'static str,
    /// The estimate \[unit\] (null when not determined).
    pub value: Option<f64>,
    /// The estimate \[unit\] even when not determined.
    pub estimate: Option<f64>,
    /// Standard error \[unit\] (null: infinite).
    pub std_error: Option<f64>,
    /// std_error / |value| (null for angles or infinite).
    pub relative_std_error: Option<f64>,
    /// Cramer-Rao bound at the truth \[unit\], when the truth is known.
    pub crb: Option<f64>,
    /// The truth \[unit\], when the scenario states it.
    pub truth: Option<f64>,
    /// (value - truth) / truth.
    pub relative_error: Option<f64>,
    /// Finite standard error below |value| (angles: below 1 rad), the unknowns identifiable
    /// and every channel adequate (else `value` is withheld, as for the 2-DOF models).
    pub determined: bool,
    /// Where the fit started \[unit\].
    pub start: f64,
    /// The reduction's bias in standard errors.
    pub reduction_bias_std: Option<f64>,
}

/// The rotor's bearings and unbalances.
#[derive(Debug, Clone, Serialize)]
pub struct FeRotorSummary {
    /// Each bearing: `node` and the eight coefficients `kxx`, `kxy`, `kyx`, `kyy` \[N/m\],
    /// `cxx`, `cxy`, `cyx`, `cyy` \[N s/m\], in that order.
    pub bearings: Vec<Bearing>,
    /// Each unbalance: `node`, `mud` \[kg m\], `alpha` \[rad\] (from +x towards +y at
    /// phi = 0).
    pub unbalances: Vec<FeUnbalance>,
}

/// Covariance with names.
#[derive(Debug, Clone, Serialize)]
pub struct FeCovariance {
    /// Row/column names.
    pub names: Vec<String>,
    /// Row-major; null entries are infinite or undefined.
    pub matrix: Vec<Vec<Option<f64>>>,
}

/// Noise per channel.
#[derive(Debug, Clone, Serialize)]
pub struct FeNoise {
    /// Standard deviation per channel \[m or rad\].
    pub sigma_m: std::collections::BTreeMap<String, f64>,
    /// "residuals".
    pub source: &'static str,
}

/// Adequacy per channel.
#[derive(Debug, Clone, Serialize)]
pub struct FeAdequacy {
    /// Every channel adequate.
    pub model_adequate: bool,
    /// Per channel.
    pub channels: std::collections::BTreeMap<String, ChannelAdequacy>,
}

fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

impl FeSummary {
    /// The summary of `fit` of a record sampled at `t` (first and last stamps \[s\]),
    /// with the truth (`truth(name)`) when known.
    pub fn new(
        fit: &FeRefined,
        t: (f64, f64),
        dt: f64,
        truth: &dyn Fn(&str) -> Option<f64>,
    ) -> Self {
        let parameters = fit
            .parameters
            .iter()
            .map(|p| {
                let angle = p.unit == "rad";
                let determined = fit.identifiable
                    && fit.model_adequate
                    && p.std_error.is_finite()
                    && if angle {
                        p.std_error < 1.0
                    } else {
                        p.std_error < p.value.abs()
                    };
                let tr = truth(&p.parameter);
                FeParameterSummary {
                    parameter: p.parameter.clone(),
                    unit: p.unit,
                    value: determined.then_some(p.value),
                    estimate: finite(p.value),
                    std_error: finite(p.std_error),
                    relative_std_error: p.relative_std_error.and_then(finite),
                    crb: p.crb.and_then(finite),
                    truth: tr,
                    relative_error: tr.filter(|t| *t != 0.0).map(|t| (p.value - t) / t),
                    determined,
                    start: p.start,
                    reduction_bias_std: p.reduction_bias_std.and_then(finite),
                }
            })
            .collect();
        let r = &fit.rotor;
        Self {
            schema: IDENTIFICATION_SCHEMA,
            method: "refine",
            model: "finite_element",
            input: None,
            scenario: None,
            record: FeRecordSummary {
                samples: fit.samples,
                t_first_s: t.0,
                t_last_s: t.1,
                dt_s: dt,
                channels: fit.noise.iter().map(|(d, _)| d.to_string()).collect(),
                speed: "profile",
            },
            initial: fit.initial,
            initial_state: fit.initial_state.as_ref().map(|s| FeInitialStateSummary {
                dofs: r.matrices.dofs().iter().map(|d| d.to_string()).collect(),
                q: s.q.iter().copied().collect(),
                v: s.v.iter().copied().collect(),
            }),
            offsets: fit.offsets.clone(),
            parameters,
            rotor: FeRotorSummary {
                bearings: r.bearings.clone(),
                unbalances: r.unbalances.clone(),
            },
            covariance: FeCovariance {
                names: fit.parameters.iter().map(|p| p.parameter.clone()).collect(),
                matrix: (0..fit.covariance.nrows())
                    .map(|i| {
                        (0..fit.covariance.ncols())
                            .map(|j| finite(fit.covariance[(i, j)]))
                            .collect()
                    })
                    .collect(),
            },
            noise: FeNoise {
                sigma_m: fit.noise.iter().map(|(d, s)| (d.to_string(), *s)).collect(),
                source: "residuals",
            },
            reduction: fit.reduction.clone(),
            adequacy: FeAdequacy {
                model_adequate: fit.model_adequate,
                channels: fit
                    .adequacy
                    .iter()
                    .map(|(d, a)| (d.to_string(), *a))
                    .collect(),
            },
            diagnostics: fit.warnings.clone(),
            converged: fit.converged,
            identifiable: fit.identifiable,
            iterations: fit.iterations,
            condition_number: finite(fit.condition_number),
        }
    }
}
