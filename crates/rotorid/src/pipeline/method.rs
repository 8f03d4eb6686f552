//! Which identifier the pipeline runs, with its settings (docs/method.md sections 3-5).

use serde::{Deserialize, Serialize};

use crate::identify::algebraic::{
    AlgebraicConfig, Quadrature, SpeedModel, DEFAULT_ALGEBRAIC_RCOND_MIN, DEFAULT_TOLERANCE,
};
use crate::identify::modulating::ModulatingConfig;
use crate::model::{check, RotorParams};
use crate::parameter::ModelKind;
use crate::refine::{RefineOptions, Unknowns};

use super::error::PipelineError;

/// The method's name, as reported.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MethodName {
    /// The paper's algebraic identifier.
    Algebraic,
    /// Modulating functions and least squares over windows.
    Modulating,
    /// Maximum-likelihood output-error refinement.
    Refine,
}

impl MethodName {
    /// `algebraic`, `modulating` or `refine`.
    pub fn as_str(self) -> &'static str {
        match self {
            MethodName::Algebraic => "algebraic",
            MethodName::Modulating => "modulating",
            MethodName::Refine => "refine",
        }
    }
}

/// The rotor model an identification uses (docs/method.md sections 1.6 and 6.6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ModelChoice {
    /// The paper's Jeffcott rotor.
    Jeffcott,
    /// The rotor on cross-coupled bearings.
    CrossCoupled,
    /// Refine: fit every candidate model, keep those whose residuals pass the adequacy
    /// test and take the simplest by the Bayesian information criterion (the summary's
    /// `model_selection` says what was compared and why).
    Auto,
}

impl ModelChoice {
    /// `jeffcott`, `cross_coupled` or `auto`.
    pub fn name(self) -> &'static str {
        match self {
            ModelChoice::Jeffcott => "jeffcott",
            ModelChoice::CrossCoupled => "cross_coupled",
            ModelChoice::Auto => "auto",
        }
    }

    /// The one model, when not `Auto`.
    pub fn fixed(self) -> Option<ModelKind> {
        match self {
            ModelChoice::Jeffcott => Some(ModelKind::Jeffcott),
            ModelChoice::CrossCoupled => Some(ModelKind::CrossCoupled),
            ModelChoice::Auto => None,
        }
    }
}

impl From<ModelKind> for ModelChoice {
    fn from(m: ModelKind) -> Self {
        match m {
            ModelKind::Jeffcott => ModelChoice::Jeffcott,
            ModelKind::CrossCoupled => ModelChoice::CrossCoupled,
        }
    }
}

impl std::str::FromStr for ModelChoice {
    type Err = crate::parameter::UnknownModel;
    /// `jeffcott`, `cross_coupled` or `auto`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s == "auto" {
            return Ok(ModelChoice::Auto);
        }
        s.parse::<ModelKind>()
            .map(ModelChoice::from)
            .map_err(|_| crate::parameter::UnknownModel { name: s.to_owned() })
    }
}

/// Settings of the algebraic identifier as the pipeline runs it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AlgebraicSettings {
    /// The running quadrature (default: Adams-Moulton order 5).
    pub quadrature: Quadrature,
    /// Instants whose scaled 3x3 system has rcond below this are flagged (dimensionless,
    /// [0, 1]; default [`DEFAULT_ALGEBRAIC_RCOND_MIN`]).
    pub rcond_min: f64,
    /// Relative band of the identification time (dimensionless, >= 0; default 0.01).
    pub tol: f64,
    /// Restart period of the overlapping windows \[s\] (docs/method.md section 3.9):
    /// every estimate then comes from integrals between half and one period old, so a
    /// record of any length stays well conditioned. `None` (default): the paper's single
    /// identifier over the whole record. Finite and at least 4 dt; rounded to an even
    /// number of samples.
    #[serde(default)]
    pub restart_s: Option<f64>,
    /// The rotor model: per direction m and that row's coefficients; `None` (default):
    /// the knowledge's ([`super::Knowledge::model`], the scenario's).
    #[serde(default)]
    pub model: Option<ModelKind>,
}

impl Default for AlgebraicSettings {
    fn default() -> Self {
        Self {
            quadrature: Quadrature::default(),
            rcond_min: DEFAULT_ALGEBRAIC_RCOND_MIN,
            tol: DEFAULT_TOLERANCE,
            restart_s: None,
            model: None,
        }
    }
}

impl AlgebraicSettings {
    /// The restart period in samples of `dt` \[s\]: `restart_s / dt` rounded to an even
    /// number (module `identify::algebraic::windows`); `None` without restarts.
    pub fn restart_samples(&self, dt: f64) -> Result<Option<u64>, PipelineError> {
        let Some(p) = self.restart_s else {
            return Ok(None);
        };
        let min = crate::identify::algebraic::MIN_RESTART_SAMPLES as f64 * dt;
        check(
            "restart_s",
            p,
            "finite and at least 4 sampling periods (s)",
            |v| v >= min * (1.0 - 1e-9) && v / dt < 1e15,
        )?;
        let half = (p / dt / 2.0).round().max(2.0);
        Ok(Some(2 * half as u64))
    }

    /// The identifier's configuration (general speed model: phi, w, w' per sample).
    pub fn config(&self) -> Result<AlgebraicConfig, PipelineError> {
        check("tol", self.tol, "finite and >= 0 (relative)", |v| v >= 0.0)?;
        Ok(AlgebraicConfig::new(
            self.quadrature,
            self.rcond_min,
            SpeedModel::General,
        )?)
    }
}

/// Settings of the modulating-function identifier.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub struct ModulatingSettings {
    /// Window, test functions, hop, noise compensation, rcond_min.
    pub config: ModulatingConfig,
    /// The rotor model: per direction m and that row's coefficients; `None` (default):
    /// the knowledge's ([`super::Knowledge::model`], the scenario's).
    #[serde(default)]
    pub model: Option<ModelKind>,
}

/// Where the refinement starts.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub enum StartPolicy {
    /// The modulating estimate over the whole record, else the algebraic estimate early in
    /// the record, else the nominal values (docs/method.md section 5.2).
    #[default]
    Auto,
    /// These values.
    Given(RotorParams),
}

/// Settings of the refinement.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub struct RefineSettings {
    /// The model: one, or `Auto` (chosen by the pipeline); `None` (default): the
    /// knowledge's ([`super::Knowledge::model`], the scenario's). A given start
    /// ([`StartPolicy::Given`]) needs a fixed model.
    #[serde(default)]
    pub model: Option<ModelChoice>,
    /// The unknowns; `None` (default): the model's default, m and its bearing
    /// coefficients ([`ModelKind::default_unknowns`]) and the initial state. With `Auto`,
    /// given unknowns are the cross-coupled candidate's (the four cross terms added when
    /// none is among them) and, without their cross terms, the Jeffcott candidate's.
    pub unknowns: Option<Unknowns>,
    /// The start.
    pub start: StartPolicy,
    /// The fit's own options (iterations, tolerance, discretisation); its `unknowns`
    /// field is replaced by `unknowns` above.
    pub options: RefineOptions,
    /// The algebraic identifier that may give the start.
    pub algebraic: AlgebraicSettings,
    /// The modulating identifier that may give the start.
    pub modulating: ModulatingSettings,
}

/// An identification method and its settings.
// The refine variant carries the settings of both identifiers that may start it; a
// Method is made once per identification, and boxing it would cost `Copy`.
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Method {
    /// The paper's algebraic identifier: an estimate per sample, streaming.
    Algebraic(AlgebraicSettings),
    /// Modulating functions, least squares over windows: one estimate, streaming.
    Modulating(ModulatingSettings),
    /// Maximum likelihood on the whole record, with standard errors and the Cramer-Rao
    /// bound.
    Refine(RefineSettings),
}

impl Method {
    /// Its name.
    pub fn name(&self) -> MethodName {
        match self {
            Method::Algebraic(_) => MethodName::Algebraic,
            Method::Modulating(_) => MethodName::Modulating,
            Method::Refine(_) => MethodName::Refine,
        }
    }

    /// The algebraic method with its defaults.
    pub fn algebraic() -> Self {
        Method::Algebraic(AlgebraicSettings::default())
    }

    /// The modulating method with its defaults.
    pub fn modulating() -> Self {
        Method::Modulating(ModulatingSettings::default())
    }

    /// The refinement with its defaults.
    pub fn refine() -> Self {
        Method::Refine(RefineSettings::default())
    }
}
