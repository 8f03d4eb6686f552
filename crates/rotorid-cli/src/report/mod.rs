//! The report of `rotorid paper`: the paper's experiments in two settings, their numbers
//! (`results.json`), a markdown summary (`report.md`) and one self-contained web page
//! (`report.html`, figures embedded as base64 PNG).
//!
//! - [`experiment`]: the speed cases and settings, simulate + identify.
//! - [`results`]: estimate at 0.3 s, relative error, identification time (1 %) per
//!   parameter and direction, beside the paper's reported times.
//! - [`figures`]: the paper's figures 2-9 (window 0.1-0.23 s and whole record).
//! - [`tables`], [`markdown`], [`html`]: the documents; [`format`]: their numbers.
//! - [`analysis`]: the page of `rotorid analyze` (critical speeds, stability, response).

pub mod analysis;
pub mod experiment;
pub mod figures;
pub mod format;
pub mod html;
pub mod markdown;
pub mod results;
pub mod tables;

use rotorid::{RotorParams, SpeedProfile};
use serde::Serialize;

use results::{Attribution, ResponseComparison, Row};

/// Version of the `results.json` layout.
pub const FORMAT_VERSION: u32 = 1;

/// Everything `results.json` holds.
#[derive(Debug, Clone, Serialize)]
pub struct Report {
    /// Layout version ([`FORMAT_VERSION`]).
    pub format_version: u32,
    /// `rotorid paper` and the version.
    pub generator: String,
    /// The rotor and sampling.
    pub scenario: ScenarioInfo,
    /// Relative band of the identification time (dimensionless).
    pub tolerance: f64,
    /// Instant the estimates are read at [s].
    pub estimate_time: f64,
    /// Conditioning threshold of the identifier (dimensionless).
    pub rcond_min: f64,
    /// The two settings.
    pub settings: Vec<SettingInfo>,
    /// The two speed cases.
    pub cases: Vec<CaseInfo>,
    /// One row per case, setting, parameter and direction (2 x 2 x 6).
    pub rows: Vec<Row>,
    /// Newmark against exact response, per case.
    pub responses: Vec<ResponseComparison>,
    /// Every combination of data (Newmark, exact) and rule (trapezoid, default), per case.
    pub attribution: Vec<Attribution>,
    /// The figures written.
    pub figures: Vec<FigureInfo>,
}

/// The simulated rotor and grid.
#[derive(Debug, Clone, Serialize)]
pub struct ScenarioInfo {
    /// `table1` (the paper's Table 1).
    pub name: &'static str,
    /// Its parameters (SI: kg, N s/m, N/m, N s^2/m, kg, m, rad).
    pub rotor: RotorParams,
    /// Sampling period [s].
    pub dt: f64,
    /// Record length [s].
    pub duration: f64,
    /// Initial displacement and velocity (zero, as in the paper).
    pub initial_state: &'static str,
}

impl ScenarioInfo {
    /// The sentence both documents open with: the rotor's parameters, the sampling and the
    /// initial state, in the units they are quoted in (kg, N s/m, N/m, N s^2/m, m, degrees,
    /// ms, s). `name` is the scenario name as the document shows it (the markdown wraps it
    /// in backticks).
    pub fn description(&self, name: &str) -> String {
        let r = &self.rotor;
        format!(
            "Rotor {} (the paper's Table 1): m = {} kg, cx = {} N s/m, cz = {} N s/m, \
             kx = {} N/m, kz = {} N/m, a = {} N s\u{b2}/m, m_u = {} kg, d = {} m, alpha = {}\u{b0}. \
             Sampling period {} ms, record 0-{} s, {} initial state, phi(0) = 0.",
            name,
            r.m,
            r.cx,
            r.cz,
            r.kx,
            r.kz,
            r.a,
            r.unbalance.m_u,
            r.unbalance.d,
            r.unbalance.alpha.to_degrees(),
            self.dt * 1e3,
            self.duration,
            self.initial_state,
        )
    }
}

/// One setting.
#[derive(Debug, Clone, Serialize)]
pub struct SettingInfo {
    /// `paper` or `ours`.
    pub name: &'static str,
    /// `newmark` or `exact`.
    pub simulation: String,
    /// `trapezoid` or the default rule's name.
    pub quadrature: &'static str,
    /// Human description.
    pub description: String,
}

/// One speed case.
#[derive(Debug, Clone, Serialize)]
pub struct CaseInfo {
    /// `constant` or `ramp`.
    pub name: &'static str,
    /// Human description.
    pub description: &'static str,
    /// The speed profile (rad/s, rad/s^2, rad).
    pub speed: SpeedProfile,
    /// The paper's figure numbers: response, m, c, k.
    pub paper_figures: [u32; 4],
}

/// One figure written (two files).
#[derive(Debug, Clone, Serialize)]
pub struct FigureInfo {
    /// File stem, e.g. `fig3` or `fig3_full`.
    pub stem: String,
    /// The paper's figure number.
    pub number: u32,
    /// Whole record (true) or the paper's window (false).
    pub full: bool,
    /// Caption.
    pub caption: String,
    /// PNG file name.
    pub png: String,
    /// SVG file name.
    pub svg: String,
}
