//! The result of an identification: one serde-serialisable structure, the export contract
//! of every caller (`rotorid identify --summary SUMMARY.json` writes it as JSON; the
//! Python package's `to_dict()` returns it). docs/summary.md documents every field.
//!
//! Values are already masked where the data do not determine them (`value: null`,
//! `determined: false`; the raw number stays in `estimate`). JSON has no infinity: an
//! infinite standard error or bound is `null`.

use serde::{Deserialize, Serialize};

use crate::identify::algebraic::Quadrature;
use crate::model::RotorParams;
use crate::parameter::{ModelKind, Parameter};

use super::diagnostic::{Diagnostic, Directions};
use super::method::MethodName;
use super::record::SpeedSource;
use super::session::SampleEstimate;

pub use crate::IDENTIFICATION_SCHEMA;

/// The record as the pipeline saw it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RecordInfo {
    /// Samples identified.
    pub samples: u64,
    /// First and last time stamps \[s\].
    pub t_first_s: f64,
    /// Last time stamp \[s\].
    pub t_last_s: f64,
    /// The sampling period the identifiers used \[s\]: least squares over the stamps.
    pub dt_s: f64,
    /// Time of sample 0 on the fitted grid \[s\].
    pub t0_s: f64,
    /// Stamps the grid was fitted over (all of them for a whole record; a stream fits
    /// its first ones, see [`super::Session`]); 0 when dt was given.
    pub grid_fitted_over: u64,
    /// Largest distance of a stamp from the grid \[s\].
    pub max_time_deviation_s: f64,
    /// Where the speed came from.
    pub speed: SpeedSource,
}

/// One identified parameter.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParameterResult {
    /// Which parameter.
    pub parameter: Parameter,
    /// Its SI unit.
    pub unit: String,
    /// The value \[unit\], `None` where the data do not determine it (see `determined`).
    pub value: Option<f64>,
    /// The method's number even where not determined (`None` when NaN or infinite).
    pub estimate: Option<f64>,
    /// Its standard error \[unit\] (`None`: infinite, or the method gives none).
    pub std_error: Option<f64>,
    /// std_error / |estimate|.
    pub relative_std_error: Option<f64>,
    /// refine: the standard error from the autocorrelation-robust sandwich covariance
    /// \[unit\], which does not assume a correct model (docs/method.md section 5.5).
    #[serde(default)]
    pub robust_std_error: Option<f64>,
    /// The Cramer-Rao bound on its standard deviation \[unit\], where computed (see
    /// `refine.crb_at`).
    pub crb: Option<f64>,
    /// The true value, when the caller gave it.
    pub truth: Option<f64>,
    /// Signed (value - truth) / truth.
    pub relative_error: Option<f64>,
    /// False when the value is withheld: ill-conditioned, never well conditioned, not
    /// identifiable, or a standard error above the value.
    pub determined: bool,
    /// The instant the value belongs to \[s\] (input time).
    pub t_s: Option<f64>,
    /// algebraic: the earliest t after which every well-conditioned estimate stays
    /// within `tol` of the final value \[s\].
    pub identification_time_s: Option<f64>,
}

impl ParameterResult {
    /// An empty result for `p`.
    pub fn new(p: Parameter) -> Self {
        Self {
            parameter: p,
            unit: p.unit().to_owned(),
            value: None,
            estimate: None,
            std_error: None,
            relative_std_error: None,
            robust_std_error: None,
            crb: None,
            truth: None,
            relative_error: None,
            determined: false,
            t_s: None,
            identification_time_s: None,
        }
    }
}

/// Every parameter of the model used (estimated, else known), by name, in the model's
/// order, SI units (kg, N s/m, N/m, N s^2/m, kg m, rad): for the Jeffcott model m, cx, kx,
/// cz, kz, a, mud, alpha; for the cross-coupled model m, cxx, cxz, czx, czz, kxx, kxz, kzx,
/// kzz, a, mud, alpha. Serialised as a JSON object of those names.
#[derive(Debug, Clone, PartialEq)]
pub struct RotorSummary {
    model: ModelKind,
    values: Vec<(Parameter, f64)>,
}

impl RotorSummary {
    /// The values of `p`, in its model.
    pub fn of(p: &RotorParams) -> Self {
        let model = p.model();
        Self {
            model,
            values: model
                .parameters()
                .iter()
                .map(|&q| (q, p.get(q).unwrap_or(f64::NAN)))
                .collect(),
        }
    }

    /// The model whose parameters these are.
    pub fn model(&self) -> ModelKind {
        self.model
    }

    /// The value of `p` (either model's name of a direct coefficient), if the model has it.
    pub fn get(&self, p: Parameter) -> Option<f64> {
        let q = self.model.own(p.physical())?;
        self.values.iter().find(|(r, _)| *r == q).map(|(_, v)| *v)
    }

    /// Every (parameter, value), in the model's order.
    pub fn values(&self) -> &[(Parameter, f64)] {
        &self.values
    }

    /// The rotor parameters (the unbalance as m_u = mud, d = 1 m).
    pub fn params(&self) -> RotorParams {
        let mut p = RotorParams {
            m: f64::NAN,
            cx: f64::NAN,
            cz: f64::NAN,
            kx: f64::NAN,
            kz: f64::NAN,
            a: f64::NAN,
            unbalance: crate::model::Unbalance {
                m_u: 0.0,
                d: 1.0,
                alpha: 0.0,
            },
            coupling: (self.model == ModelKind::CrossCoupled).then(Default::default),
        };
        for &(q, v) in &self.values {
            p.set(q, v);
        }
        p
    }
}

impl Serialize for RotorSummary {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut map = s.serialize_map(Some(self.values.len()))?;
        for (p, v) in &self.values {
            map.serialize_entry(p.name(), v)?;
        }
        map.end()
    }
}

impl<'de> Deserialize<'de> for RotorSummary {
    /// An object of one model's parameter names (the model is the one whose names appear:
    /// cross-coupled when any of cxx .. kzz is there).
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let map = std::collections::BTreeMap::<String, f64>::deserialize(d)?;
        let mut values = Vec::new();
        for (name, v) in &map {
            let p: Parameter = name.parse().map_err(D::Error::custom)?;
            values.push((p, *v));
        }
        let model = if values
            .iter()
            .any(|(p, _)| ModelKind::Jeffcott.own(*p) != Some(*p))
        {
            ModelKind::CrossCoupled
        } else {
            ModelKind::Jeffcott
        };
        let mut ordered = Vec::new();
        for &q in model.parameters() {
            match values.iter().find(|(p, _)| *p == q) {
                Some(&pv) => ordered.push(pv),
                None => {
                    return Err(D::Error::custom(format!(
                        "rotor: the {} model's parameter {q} is missing",
                        model.name()
                    )))
                }
            }
        }
        if ordered.len() != values.len() {
            return Err(D::Error::custom(format!(
                "rotor: parameters of another model than {}",
                model.name()
            )));
        }
        Ok(Self {
            model,
            values: ordered,
        })
    }
}

/// How the pipeline chose the model (`--model auto`, docs/method.md section 6.6).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelSelection {
    /// The rule: among the candidates whose residuals pass the adequacy test, the lowest
    /// Bayesian information criterion; when none passes, the lowest criterion (its values
    /// withheld as inadequate).
    pub criterion: String,
    /// Every model fitted, simplest first.
    pub candidates: Vec<ModelCandidate>,
    /// The model taken.
    pub chosen: ModelKind,
    /// Why, in words.
    pub reason: String,
}

/// One model fitted during the selection.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelCandidate {
    /// The model.
    pub model: ModelKind,
    /// Quantities estimated: parameters, initial state and the two noise levels.
    pub estimated: u64,
    /// The maximised Gaussian log-likelihood of x and z (dimensionless).
    pub log_likelihood: f64,
    /// BIC = -2 ln L + (estimated) ln(2 N), N samples per channel (dimensionless; lower
    /// is better).
    pub bic: f64,
    /// Whether the residuals pass the adequacy test (`None`: not computed).
    pub adequate: Option<bool>,
    /// Residual level over the data's noise level, x and z (about 1 for a correct model).
    pub noise_ratio: Directions<f64>,
    /// The fit converged.
    pub converged: bool,
    /// The unknowns are identifiable from the record.
    pub identifiable: bool,
}

/// A covariance matrix over named quantities (`None` = not finite).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Covariance {
    /// Row and column names: the model's parameters estimated (m, cx, kx, cz, kz, a or
    /// m, cxx, kxx, czz, kzz, a, then cxz, czx, kxz, kzx), mud_cos_alpha, mud_sin_alpha,
    /// x0, z0, vx0, vz0 (those estimated).
    pub names: Vec<String>,
    /// Row-major entries in the product of the two names' units.
    pub matrix: Vec<Vec<Option<f64>>>,
}

/// Where a noise level comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum NoiseSource {
    /// White noise from the data's fourth differences (modulating).
    FourthDifferences,
    /// sqrt(sum r^2 / N) of the fit's residuals (refine).
    Residuals,
}

/// The white-noise level per channel.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Noise {
    /// On x \[m\].
    pub sigma_x_m: f64,
    /// On z \[m\].
    pub sigma_z_m: f64,
    /// How it was estimated.
    pub source: NoiseSource,
}

/// The algebraic identifier's figures.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AlgebraicDetail {
    /// The running quadrature.
    pub quadrature: Quadrature,
    /// Conditioning threshold of the scaled 3x3 systems.
    pub rcond_min: f64,
    /// Relative band of the identification times.
    pub tol: f64,
    /// Restart period of the overlapping windows \[s\] (`None`: one identifier over the
    /// whole record).
    #[serde(default)]
    pub restart_s: Option<f64>,
    /// Windows started (1 without restarts).
    #[serde(default)]
    pub windows: u64,
    /// Ill-conditioned instants per direction (their estimates are withheld).
    pub flagged: Directions<u64>,
    /// The instant of each direction's final estimate \[s\].
    pub final_time_s: Directions<Option<f64>>,
    /// rcond of the last sample per direction.
    pub last_rcond: Directions<f64>,
}

/// The modulating identifier's figures.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModulatingDetail {
    /// Window length \[s\].
    pub window_s: f64,
    /// Hop between window starts \[s\].
    pub hop_s: f64,
    /// Completed windows.
    pub windows: u64,
    /// Conditioning threshold of the equilibrated normal matrix.
    pub rcond_min: f64,
    /// Its reciprocal condition number per direction (0 when singular).
    pub rcond: Directions<f64>,
    /// The end of the last window \[s\] (grid time).
    pub t_s: f64,
    /// Where the Cramer-Rao bound of `parameters[].crb` was evaluated (method modulating;
    /// `None` when it was not computed): the bound of the model with one mass, a lower
    /// bound for m_x and m_z (docs/method.md section 4.6).
    #[serde(default)]
    pub crb_at: Option<CrbAt>,
    /// Whether the noise bias was compensated.
    pub compensated: bool,
    /// How its standard errors are computed.
    pub std_error_basis: String,
}

/// Where the refinement started.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StartSource {
    /// The modulating estimate over the whole record.
    Modulating,
    /// The algebraic estimate early in the record.
    Algebraic,
    /// The nominal values.
    Nominal,
    /// Values the caller gave.
    Given,
    /// The estimate of a smaller model nested in this one (`--model auto`: the Jeffcott
    /// fit, with the cross-coupled coefficients at 0 or their nominal values).
    NestedModel,
}

/// The refinement's start.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Start {
    /// Where it came from.
    pub source: StartSource,
    /// The instant of the starting estimate \[s\] (algebraic: input time; modulating: the
    /// end of its last window on the grid); `None` for nominal and given values.
    pub t_s: Option<f64>,
    /// Every starting rotor parameter, estimated or known.
    pub values: RotorSummary,
    /// Why earlier sources were not used (`None` when the first was).
    pub note: Option<String>,
}

/// Where the Cramer-Rao bound was evaluated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CrbAt {
    /// At the true rotor and initial state.
    Truth,
    /// At the true rotor with the fitted initial state.
    TruthParameters,
    /// At the estimate.
    Estimate,
}

/// An initial-state component.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StateResult {
    /// x0, z0 \[m\] or vx0, vz0 \[m/s\].
    pub name: String,
    /// Its unit.
    pub unit: String,
    /// The fitted value.
    pub value: f64,
    /// Its standard error (`None`: infinite).
    pub std_error: Option<f64>,
}

/// The refinement's figures.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RefineDetail {
    /// What was estimated (besides the initial state).
    pub unknowns: Vec<Parameter>,
    /// The start.
    pub start: Start,
    /// The fitted state at the first sample.
    pub initial_state: Vec<StateResult>,
    /// The Levenberg-Marquardt iteration stopped on its tolerance.
    pub converged: bool,
    /// Model passes.
    pub iterations: u64,
    /// False when the data cannot separate or determine the unknowns.
    pub identifiable: bool,
    /// Condition number of the Fisher information scaled to unit diagonal (`None`:
    /// infinite).
    pub condition_number: Option<f64>,
    /// Rank of the Fisher information: how many independent combinations of the unknowns
    /// (initial state included) the record informs.
    #[serde(default)]
    pub fisher_rank: Option<u64>,
    /// The discrete model of the fit.
    pub discretisation: String,
    /// How the standard errors are computed.
    pub std_error_basis: String,
    /// Where the Cramer-Rao bound was evaluated (`None` when not computed).
    pub crb_at: Option<CrbAt>,
    /// The sandwich covariance's Bartlett bandwidth \[samples\] (`None`: not computed).
    #[serde(default)]
    pub hac_bandwidth: Option<u64>,
    /// Pooled lag-1 autocorrelation of the noise-weighted residuals (about 0 for a
    /// correct model).
    #[serde(default)]
    pub residual_lag1_autocorrelation: Option<f64>,
}

/// The result of an identification (module doc).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Identification {
    /// [`IDENTIFICATION_SCHEMA`].
    pub schema: u32,
    /// The method.
    pub method: MethodName,
    /// The rotor model the values belong to (schema 2 files: jeffcott).
    #[serde(default)]
    pub model: ModelKind,
    /// How the model was chosen, when the pipeline chose it (`--model auto`).
    #[serde(default)]
    pub model_selection: Option<ModelSelection>,
    /// The input's name, when the caller gives one.
    pub input: Option<String>,
    /// The scenario's name, when the caller gives one.
    pub scenario: Option<String>,
    /// The record.
    pub record: RecordInfo,
    /// The identified parameters: algebraic and modulating: m_x, cx, kx, m_z, cz, kz
    /// (cross-coupled model: m_x, cxx, cxz, kxx, kxz, m_z, czx, czz, kzx, kzz); refine:
    /// its unknowns among the model's parameters, in the model's order.
    pub parameters: Vec<ParameterResult>,
    /// Every parameter of the model (estimated, else known), when all its mass, damping
    /// and stiffness values are determined (algebraic and modulating: m is the mean of
    /// m_x and m_z).
    pub rotor: Option<RotorSummary>,
    /// refine: covariance of its internal unknowns (`mud_cos_alpha`, `mud_sin_alpha` for
    /// the unbalance).
    pub covariance: Option<Covariance>,
    /// The noise level, when the method estimates it.
    pub noise: Option<Noise>,
    /// refine: whether the model explains the record (residual tests per channel).
    pub adequacy: Option<super::adequacy::Adequacy>,
    /// What to read before trusting the numbers, worst first.
    pub diagnostics: Vec<Diagnostic>,
    /// The algebraic identifier's figures (method algebraic).
    pub algebraic: Option<AlgebraicDetail>,
    /// The modulating identifier's figures (method modulating, or refine started from it).
    pub modulating: Option<ModulatingDetail>,
    /// The refinement's figures.
    pub refine: Option<RefineDetail>,
    /// algebraic, from [`super::identify`]: the estimate at every sample (not serialised).
    #[serde(skip)]
    pub estimates: Vec<SampleEstimate>,
}

impl Identification {
    /// The result for `p`, if it was identified.
    pub fn parameter(&self, p: Parameter) -> Option<&ParameterResult> {
        self.parameters.iter().find(|r| r.parameter == p)
    }

    /// The determined value of `p`.
    pub fn value(&self, p: Parameter) -> Option<f64> {
        self.parameter(p).and_then(|r| r.value)
    }

    /// The messages of the warnings, worst first.
    pub fn warnings(&self) -> Vec<String> {
        self.diagnostics.iter().map(|d| d.message.clone()).collect()
    }

    /// The one estimate of a batch method (modulating, refine) as a row of per-direction
    /// values of its model ([`ModelKind::per_direction`]: Jeffcott m_x, cx, kx, m_z, cz,
    /// kz; refine: m in both m_x and m_z), `None` where not determined or not estimated,
    /// at the last sample; rcond per direction (modulating: of its normal matrix; refine:
    /// 1 / condition number of the scaled Fisher information, 0 when singular). `None` for
    /// the algebraic method, whose estimates are per sample.
    pub fn final_estimate(&self) -> Option<FinalEstimate> {
        let t_s = self.record.t_last_s;
        let per_direction = self.model.per_direction();
        if let Some(m) = &self.modulating {
            if self.method == MethodName::Modulating {
                return Some(FinalEstimate {
                    t_s,
                    model: self.model,
                    values: per_direction.iter().map(|&p| self.value(p)).collect(),
                    rcond: m.rcond,
                });
            }
        }
        let r = self.refine.as_ref()?;
        let rcond = r
            .condition_number
            .filter(|c| *c > 0.0)
            .map_or(0.0, |c| 1.0 / c);
        Some(FinalEstimate {
            t_s,
            model: self.model,
            values: per_direction
                .iter()
                .map(|&p| self.value(p.physical()))
                .collect(),
            rcond: Directions { x: rcond, z: rcond },
        })
    }

    /// refine: false when the data cannot determine the unknowns.
    pub fn identifiable(&self) -> bool {
        self.refine.as_ref().is_none_or(|r| r.identifiable)
    }
}

/// The one estimate of a batch method (see [`Identification::final_estimate`]).
#[derive(Debug, Clone, PartialEq)]
pub struct FinalEstimate {
    /// The last sample's time \[s\].
    pub t_s: f64,
    /// The model whose parameters the values are.
    pub model: ModelKind,
    /// The values of `model.per_direction()` (Jeffcott: m_x \[kg\], cx \[N s/m\], kx
    /// \[N/m\], m_z, cz, kz); `None` where not determined.
    pub values: Vec<Option<f64>>,
    /// Reciprocal condition number per direction (dimensionless, [0, 1]).
    pub rcond: Directions<f64>,
}

/// `v` when finite.
pub(crate) fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}
