//! Which identifier the pipeline runs, with its settings (docs/method.md sections 3-5).

use serde::{Deserialize, Serialize};

use crate::identify::algebraic::{
    AlgebraicConfig, Quadrature, SpeedModel, DEFAULT_ALGEBRAIC_RCOND_MIN, DEFAULT_TOLERANCE,
};
use crate::identify::modulating::ModulatingConfig;
use crate::model::{check, RotorParams};
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
}

impl Default for AlgebraicSettings {
    fn default() -> Self {
        Self {
            quadrature: Quadrature::default(),
            rcond_min: DEFAULT_ALGEBRAIC_RCOND_MIN,
            tol: DEFAULT_TOLERANCE,
            restart_s: None,
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
    /// The unknowns (default m, cx, kx, cz, kz and the initial state).
    pub unknowns: Unknowns,
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
