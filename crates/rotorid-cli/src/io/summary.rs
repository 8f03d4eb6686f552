//! The identification summary (`rotorid identify --summary SUMMARY.json`): the export
//! contract for scripts and for `rotorid plot` / `rotorid paper`. Field names and meanings
//! are stable; new fields may be added (readers should ignore unknown fields). JSON has no
//! infinity: every number documented as possibly infinite is written as `null` then.
//!
//! ```json
//! {
//!   "format_version": 1,
//!   "input": "response.csv",          // file name as given ("-" for stdin)
//!   "scenario": "table1",             // built-in name or scenario file path
//!   "method": "algebraic",            // "algebraic" | "modulating" | "refine"
//!   "quadrature": "am5" | null,       // running quadrature rule of the algebraic identifier
//!   "tol": 0.01 | null,               // relative band for identification_time_s
//!   "rcond_min": 1e-5,                // conditioning threshold (dimensionless)
//!   "samples": 10001,                 // data rows read
//!   "dt_s": 0.0001, "t_first_s": 0, "t_last_s": 1,
//!   "final": {"m_x": 14.29, "c_x": 10, "k_x": 1195000, "m_z": .., "c_z": .., "k_z": ..},
//!   "final_time_s": {"x": 1, "z": 1},
//!   "identification_time_s": {"m_x": 0.016, ...},
//!   "truth": {"m_x": 14.29, ...} | null,
//!   "relative_error": {"m_x": 1e-9, ...} | null,
//!   "flagged": {"x": 12, "z": 9},
//!   "rows_written": 10001,
//!   // modulating and refine (null for algebraic):
//!   "sigma_x": 1.1e-9, "sigma_z": 1.2e-9,       // noise standard deviations [m]
//!   "warnings": ["..."],
//!   "modulating": {"window_s": 0.02, "hop_s": 0.0025, "windows": 113,
//!                  "rcond": {"x": 0.13, "z": 0.14}} | null,
//!   "std_error": {"m_x": 3.4e-3, ...},           // modulating: per final value
//!   "relative_std_error": {"m_x": 2.3e-4, ...},
//!   "std_error_basis": "...",
//!   // refine only (null otherwise):
//!   "unknowns": ["m", "cx", "kx", "cz", "kz"],
//!   "start": {"source": "modulating", "t_s": 0.3, "values": {"m": .., ...}, "note": null},
//!   "estimate": {"m": 14.2901, "cx": 10.03, "kx": 1195010, "cz": .., "kz": ..},
//!   "std_error": {"m": 6.1e-4, ...},
//!   "relative_std_error": {"m": 4.3e-5, ...},
//!   "crb": {"m": 5.9e-4, ...},
//!   "crb_at": "truth",
//!   "std_error_basis": "...",
//!   "initial_state": {"x0": 1e-10, "z0": .., "vx0": .., "vz0": ..},
//!   "initial_state_std_error": {"x0": 2e-11, ...},
//!   "identifiable": true, "converged": true, "iterations": 7,
//!   "condition_number": 3.2e4,
//!   "discretisation": "exact (...)"
//! }
//! ```
//!
//! Fields of every method:
//!
//! - `quadrature`: the algebraic identifier's rule: method algebraic; refine when its start
//!   came from the algebraic identifier; null otherwise.
//! - `tol`: algebraic only (null otherwise), like `identification_time_s`.
//! - `rcond_min`: the conditioning threshold of the identifier that produced `final`
//!   (algebraic: scaled 3x3 system; modulating: equilibrated normal matrix) or, for refine,
//!   of the one that gave its start.
//! - `final`: algebraic: the estimate at the last well-conditioned instant of each
//!   direction (`final_time_s` says when); modulating: the least squares over all completed
//!   windows (`final_time_s`: end of the last window); refine: the fitted m (in both m_x
//!   and m_z), cx, kx, cz, kz (`final_time_s`: the last sample). Null if the direction was
//!   never well conditioned (algebraic, modulating) or the parameter was not estimated
//!   (refine: known, see `unknowns`).
//! - `identification_time_s`: algebraic only: per parameter, the earliest t after which
//!   every well-conditioned estimate stays within `tol` (relative) of its final value:
//!   `|theta(t') - theta_final| <= tol |theta_final|` for all well-conditioned t' >= t.
//!   null if there is no final value, and for the batch methods. Times are the input's t
//!   (not shifted to start at 0).
//! - `truth`: the scenario's m, cx, cz, kx, kz (m for both m_x and m_z), null without any;
//!   a parameter the scenario does not state is null.
//! - `relative_error`: signed `(final - truth) / truth` per parameter (null where either is
//!   unknown or truth is 0); null without any truth.
//! - `flagged`: algebraic: instants whose system was not well conditioned (rcond <
//!   rcond_min or singular), per direction; their estimates are not written and never count
//!   as converged. modulating and refine: 1 when the direction's final estimate is withheld
//!   from the estimates CSV (modulating: ill-conditioned; refine: some parameter of the
//!   direction not determined, see below), else 0.
//!
//! Batch methods:
//!
//! - `sigma_x`, `sigma_z` [m]: modulating: the white-noise level estimated from the data's
//!   fourth differences (used to compensate the least squares' noise bias); refine: the
//!   maximum-likelihood estimate sqrt(sum r^2 / N) from the fit's residuals.
//! - `warnings`: one sentence each, worst first; empty when there is nothing to say.
//! - `modulating`: the modulating identifier's window length, hop, completed windows and
//!   rcond per direction (method modulating, or refine started from it).
//! - `std_error`, `relative_std_error`, `std_error_basis` for method modulating: per final
//!   value m_x .. k_z [its unit], the identifier's first-order (sandwich) standard error
//!   for white noise of the estimated sigma (null where the direction is withheld); `crb`
//!   and the other refine fields are null.
//! - `unknowns`: what refine estimated, from m, cx, kx, cz, kz, a, unbalance; the initial
//!   state is always estimated too.
//! - `start`: where refine started: `source` is `"modulating"` (the modulating estimate over
//!   the whole record, m = mean of m_x and m_z), `"algebraic"` (the algebraic identifier's
//!   estimate at the last well-conditioned instant up to 0.05 s after the first sample;
//!   `t_s` is that instant) or `"scenario"` (the scenario's m, cx, kx, cz, kz, when neither
//!   identifier gave a physical estimate); `values` holds every starting rotor parameter
//!   (m kg, cx, cz N s/m, kx, kz N/m, a N s^2/m, mud kg m, alpha rad), estimated or known;
//!   `note` says why an earlier source was not used (null when the first one was).
//! - `estimate`: the fitted parameters, named m [kg], cx, cz [N s/m], kx, kz [N/m],
//!   a [N s^2/m], mud (= m_u d) [kg m], alpha [rad], only those estimated.
//! - `std_error` (refine): per estimated parameter [its unit], the asymptotic maximum-likelihood
//!   standard error: sqrt of the diagonal of the inverse Fisher information at the estimate
//!   with the estimated noise (`std_error_basis` says it in words). null = infinite: the data
//!   carry no information on that parameter.
//! - `relative_std_error`: std_error / |estimate| (null when infinite; alpha: null).
//! - `crb`: per estimated parameter [its unit], the Cramer-Rao bound on its standard
//!   deviation for this experiment (same samples, speed and unknowns) with the estimated
//!   sigma_x, sigma_z, evaluated where `crb_at` says: `"truth"` (the scenario's rotor and
//!   initial state: the scenario states m, cx, kx, cz, kz and the record starts at t = 0),
//!   `"truth_parameters"` (the scenario's rotor with the fitted initial state: the record
//!   starts later, or the scenario's initial state is not available) or `"estimate"` (the
//!   fitted rotor and initial state: no complete truth; then it equals `std_error` up to
//!   the no-transient adjustment described in the warnings). null = infinite.
//! - `initial_state`: the fitted state at the first sample, x0, z0 [m], vx0, vz0 [m/s];
//!   `initial_state_std_error` its standard errors (null = infinite).
//! - `identifiable`: false when any warning says the data cannot separate or determine the
//!   unknowns; the numbers are then reported but must not be relied on.
//! - `converged`, `iterations`: the Levenberg-Marquardt iteration's outcome and model passes.
//! - `condition_number`: of the Fisher information scaled to unit diagonal (null when
//!   infinite).
//! - `discretisation`: the discrete model the fit used.

use serde::de::{MapAccess, Visitor};
use serde::ser::SerializeMap;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use super::number::format_sig;
use super::params::{ParameterSet, PARAMETER_NAMES, PARAMETER_UNITS};

/// Version of the summary format (incremented on incompatible changes).
pub const SUMMARY_FORMAT_VERSION: u32 = 1;

/// One value per direction.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Directions<T> {
    /// x direction (horizontal).
    pub x: T,
    /// z direction (vertical).
    pub z: T,
}

/// Values by name, serialised as a JSON object whose keys keep this order.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Named<T>(pub Vec<(String, T)>);

impl<T> Named<T> {
    /// The value called `name`.
    pub fn get(&self, name: &str) -> Option<&T> {
        self.0.iter().find(|(n, _)| n == name).map(|(_, v)| v)
    }
}

impl<T> FromIterator<(String, T)> for Named<T> {
    fn from_iter<I: IntoIterator<Item = (String, T)>>(iter: I) -> Self {
        Self(iter.into_iter().collect())
    }
}

impl<T: Serialize> Serialize for Named<T> {
    fn serialize<S: Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        let mut m = s.serialize_map(Some(self.0.len()))?;
        for (k, v) in &self.0 {
            m.serialize_entry(k, v)?;
        }
        m.end()
    }
}

impl<'de, T: Deserialize<'de>> Deserialize<'de> for Named<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V<T>(std::marker::PhantomData<T>);
        impl<'de, T: Deserialize<'de>> Visitor<'de> for V<T> {
            type Value = Named<T>;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an object of named values")
            }
            fn visit_map<A: MapAccess<'de>>(self, mut a: A) -> Result<Self::Value, A::Error> {
                let mut out = Vec::new();
                while let Some((k, v)) = a.next_entry::<String, T>()? {
                    out.push((k, v));
                }
                Ok(Named(out))
            }
        }
        d.deserialize_map(V(std::marker::PhantomData))
    }
}

/// Where the refinement started (see the module doc, `start`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StartSummary {
    /// `modulating`, `algebraic` or `scenario`.
    pub source: String,
    /// The instant of the starting estimate [s] (input time); null for `scenario`.
    pub t_s: Option<f64>,
    /// Every starting rotor parameter (m, cx, kx, cz, kz, a, mud, alpha; SI units).
    pub values: Named<f64>,
    /// Why an earlier source was not used (null when the first one was).
    pub note: Option<String>,
}

/// The modulating identifier's figures (see the module doc, `modulating`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModulatingSummary {
    /// Window length L [s].
    pub window_s: f64,
    /// Hop between window starts [s].
    pub hop_s: f64,
    /// Completed windows.
    pub windows: u64,
    /// Reciprocal condition number of the equilibrated normal matrix per direction
    /// (dimensionless, [0, 1]; 0 when singular).
    pub rcond: Directions<f64>,
}

/// The summary of one `identify` run (see the module doc for every field).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Summary {
    /// [`SUMMARY_FORMAT_VERSION`].
    pub format_version: u32,
    /// The input file as given (`-` for stdin).
    pub input: String,
    /// The scenario: `table1` or the scenario file path.
    pub scenario: String,
    /// The identification method: `algebraic`, `modulating` or `refine`.
    pub method: String,
    /// The algebraic identifier's running quadrature rule, when it was used.
    pub quadrature: Option<String>,
    /// Relative tolerance defining the identification time (dimensionless; algebraic).
    pub tol: Option<f64>,
    /// Conditioning threshold: estimates with rcond below it are flagged (dimensionless).
    pub rcond_min: f64,
    /// Data rows read.
    pub samples: u64,
    /// Sampling period [s] (t_2 - t_1), null with fewer than two rows.
    pub dt_s: Option<f64>,
    /// Time of the first sample [s].
    pub t_first_s: Option<f64>,
    /// Time of the last sample [s].
    pub t_last_s: Option<f64>,
    /// The final estimate (kg, N s/m, N/m).
    #[serde(rename = "final")]
    pub final_values: ParameterSet<Option<f64>>,
    /// The instant of the final estimate of each direction [s].
    pub final_time_s: Directions<Option<f64>>,
    /// Identification time per parameter [s] (algebraic; see the module doc).
    pub identification_time_s: ParameterSet<Option<f64>>,
    /// True values from the scenario, if any.
    pub truth: Option<ParameterSet<Option<f64>>>,
    /// Signed relative error of the final values against the truth.
    pub relative_error: Option<ParameterSet<Option<f64>>>,
    /// Ill-conditioned instants (algebraic) or withheld final estimates (batch methods).
    pub flagged: Directions<u64>,
    /// Rows written to the estimates CSV.
    pub rows_written: u64,
    /// Noise standard deviation on x [m] (batch methods).
    #[serde(default)]
    pub sigma_x: Option<f64>,
    /// Noise standard deviation on z [m] (batch methods).
    #[serde(default)]
    pub sigma_z: Option<f64>,
    /// Diagnostics, one sentence each (batch methods).
    #[serde(default)]
    pub warnings: Option<Vec<String>>,
    /// The modulating identifier's figures, when it was used.
    #[serde(default)]
    pub modulating: Option<ModulatingSummary>,
    /// The quantities refine estimated.
    #[serde(default)]
    pub unknowns: Option<Vec<String>>,
    /// Where refine started.
    #[serde(default)]
    pub start: Option<StartSummary>,
    /// The fitted parameters (SI units, see the module doc).
    #[serde(default)]
    pub estimate: Option<Named<f64>>,
    /// Their standard errors (None = infinite).
    #[serde(default)]
    pub std_error: Option<Named<Option<f64>>>,
    /// std_error / |estimate| (None = infinite or not defined).
    #[serde(default)]
    pub relative_std_error: Option<Named<Option<f64>>>,
    /// Cramer-Rao bounds on their standard deviations (None = infinite).
    #[serde(default)]
    pub crb: Option<Named<Option<f64>>>,
    /// Where the bound was evaluated: `truth`, `truth_parameters` or `estimate`.
    #[serde(default)]
    pub crb_at: Option<String>,
    /// How `std_error` was computed, in words.
    #[serde(default)]
    pub std_error_basis: Option<String>,
    /// The fitted initial state x0, z0 [m], vx0, vz0 [m/s] at the first sample.
    #[serde(default)]
    pub initial_state: Option<Named<f64>>,
    /// Its standard errors (None = infinite).
    #[serde(default)]
    pub initial_state_std_error: Option<Named<Option<f64>>>,
    /// False when the data cannot separate or determine the unknowns.
    #[serde(default)]
    pub identifiable: Option<bool>,
    /// True when the fit's last step was below its tolerance.
    #[serde(default)]
    pub converged: Option<bool>,
    /// Model passes of the fit.
    #[serde(default)]
    pub iterations: Option<u64>,
    /// Condition number of the scaled Fisher information (None = infinite).
    #[serde(default)]
    pub condition_number: Option<f64>,
    /// The discrete model of the fit.
    #[serde(default)]
    pub discretisation: Option<String>,
}

impl Summary {
    /// A summary with the run's identity and every result field empty (null, 0).
    pub fn new(input: String, scenario: String, method: String, rcond_min: f64) -> Self {
        Self {
            format_version: SUMMARY_FORMAT_VERSION,
            input,
            scenario,
            method,
            quadrature: None,
            tol: None,
            rcond_min,
            samples: 0,
            dt_s: None,
            t_first_s: None,
            t_last_s: None,
            final_values: ParameterSet::default(),
            final_time_s: Directions::default(),
            identification_time_s: ParameterSet::default(),
            truth: None,
            relative_error: None,
            flagged: Directions::default(),
            rows_written: 0,
            sigma_x: None,
            sigma_z: None,
            warnings: None,
            modulating: None,
            unknowns: None,
            start: None,
            estimate: None,
            std_error: None,
            relative_std_error: None,
            crb: None,
            crb_at: None,
            std_error_basis: None,
            initial_state: None,
            initial_state_std_error: None,
            identifiable: None,
            converged: None,
            iterations: None,
            condition_number: None,
            discretisation: None,
        }
    }
}

/// Signed relative error `(value - truth) / truth`, `None` where either is unknown or the
/// truth is zero.
pub fn relative_errors(
    values: &ParameterSet<Option<f64>>,
    truth: &ParameterSet<Option<f64>>,
) -> ParameterSet<Option<f64>> {
    let v = values.to_array();
    let t = truth.to_array();
    ParameterSet::from_array(std::array::from_fn(|i| match (v[i], t[i]) {
        (Some(v), Some(t)) if t != 0.0 => Some((v - t) / t),
        _ => None,
    }))
}

/// The lines to print on stderr whatever `--quiet` says: a prominent line when the fit is
/// not identifiable, then `warning: ...` per warning.
pub fn warning_lines(s: &Summary) -> Vec<String> {
    let mut out = Vec::new();
    if s.identifiable == Some(false) {
        out.push(
            "warning: NOT IDENTIFIABLE: this record does not determine every unknown (see \
             the warnings below); such values are reported with their huge or infinite \
             standard errors, must not be relied on, and are left empty in the estimates CSV"
                .to_owned(),
        );
    }
    for w in s.warnings.iter().flatten() {
        out.push(format!("warning: {w}"));
    }
    out
}

/// A few lines for a person: per parameter the final value, the truth and relative error
/// when known, and (algebraic) the identification time or (refine) the standard error and
/// Cramer-Rao bound; then the warnings.
pub fn human_report(s: &Summary) -> String {
    let mut out = match s.method.as_str() {
        "refine" => refine_report(s),
        "modulating" => modulating_report(s),
        _ => algebraic_report(s),
    };
    for w in warning_lines(s) {
        out.push('\n');
        out.push_str(&w);
    }
    out
}

fn algebraic_report(s: &Summary) -> String {
    use std::fmt::Write as _;
    let mut out = String::new();
    let tol = s.tol.map_or("-".to_owned(), |t| t.to_string());
    let _ = writeln!(
        out,
        "identified {} samples of {} ({} quadrature, tol {tol}):",
        s.samples,
        s.input,
        s.quadrature.as_deref().unwrap_or("-"),
    );
    let time = s.identification_time_s.to_array();
    for (i, time) in time.iter().enumerate() {
        value_and_error(&mut out, s, i);
        match time {
            Some(t) => {
                let _ = write!(out, "  within {tol} from t = {t:.4} s");
            }
            None => {
                let _ = write!(out, "  never settled");
            }
        }
        out.push('\n');
    }
    let _ = write!(
        out,
        "  ill-conditioned instants (rcond < {:e}): x {}, z {}",
        s.rcond_min, s.flagged.x, s.flagged.z
    );
    out
}

/// `  m_x  =  14.2900000 kg      true 14.29  error +1.0e-9` (no newline).
fn value_and_error(out: &mut String, s: &Summary, i: usize) {
    use std::fmt::Write as _;
    let fin = s.final_values.to_array();
    let truth = s.truth.map(|t| t.to_array());
    let err = s.relative_error.map(|e| e.to_array());
    let _ = write!(out, "  {:<4} = ", PARAMETER_NAMES[i]);
    match fin[i] {
        Some(v) => {
            let _ = write!(out, "{:>16} {:<6}", format_sig(v, 9), PARAMETER_UNITS[i]);
        }
        None => {
            let _ = write!(out, "{:>16} {:<6}", "none", "");
        }
    }
    if let (Some(t), Some(e)) = (truth.and_then(|t| t[i]), err.and_then(|e| e[i])) {
        let _ = write!(out, "  true {t:<12} error {e:+.2e}");
    }
}

fn modulating_report(s: &Summary) -> String {
    use std::fmt::Write as _;
    let mut out = String::new();
    let _ = write!(
        out,
        "identified {} samples of {} by modulating functions",
        s.samples, s.input
    );
    if let Some(m) = &s.modulating {
        let _ = write!(
            out,
            " ({} windows of {} s, hop {} s)",
            m.windows,
            format_sig(m.window_s, 4),
            format_sig(m.hop_s, 4)
        );
    }
    out.push_str(":\n");
    let std = s.std_error.as_ref();
    for (i, name) in PARAMETER_NAMES.iter().enumerate() {
        value_and_error(&mut out, s, i);
        if let Some(e) = std.and_then(|n| n.get(name).copied().flatten()) {
            let _ = write!(out, "  +- {e:.2e}");
        }
        out.push('\n');
    }
    if let Some(m) = &s.modulating {
        let _ = writeln!(
            out,
            "  rcond x {:.2e}, z {:.2e} (threshold {:e})",
            m.rcond.x, m.rcond.z, s.rcond_min
        );
    }
    let _ = write!(
        out,
        "  noise (4th differences): sigma_x = {} m, sigma_z = {} m",
        opt_e(s.sigma_x),
        opt_e(s.sigma_z)
    );
    out
}

/// `1.23e-9`, or `inf` for `None`.
fn opt_e(v: Option<f64>) -> String {
    v.map_or_else(|| "inf".to_owned(), |v| format!("{v:.3e}"))
}

/// The unit of a refined quantity.
fn unit_of(name: &str) -> &'static str {
    match name {
        "m" => "kg",
        "cx" | "cz" => "N s/m",
        "kx" | "kz" => "N/m",
        "a" => "N s^2/m",
        "mud" => "kg m",
        "alpha" => "rad",
        "x0" | "z0" => "m",
        "vx0" | "vz0" => "m/s",
        _ => "",
    }
}

/// The truth of a refined quantity, when the summary has it.
fn truth_of(s: &Summary, name: &str) -> Option<f64> {
    let t = s.truth?;
    match name {
        "m" => t.m_x,
        "cx" => t.c_x,
        "kx" => t.k_x,
        "cz" => t.c_z,
        "kz" => t.k_z,
        _ => None,
    }
}

fn refine_report(s: &Summary) -> String {
    use std::fmt::Write as _;
    let mut out = String::new();
    let span = match (s.t_first_s, s.t_last_s) {
        (Some(a), Some(b)) => format!(", t = {} .. {} s", format_sig(a, 6), format_sig(b, 6)),
        _ => String::new(),
    };
    let start = s.start.as_ref().map_or("-".to_owned(), |st| match st.t_s {
        Some(t) if st.source == "algebraic" => {
            format!("algebraic estimate at t = {} s", format_sig(t, 4))
        }
        _ if st.source == "scenario" => "the scenario's values".to_owned(),
        _ => format!("{} estimate", st.source),
    });
    let _ = writeln!(
        out,
        "refined {} samples of {}{span} by maximum likelihood (start: {start}):",
        s.samples, s.input
    );
    let _ = writeln!(
        out,
        "  {:<6} {:>16} {:<8} {:>12} {:>11} {:>12} {:>14} {:>10}",
        "", "value", "", "+- std err", "rel. std", "CRB", "true", "err/std"
    );
    let empty = Named::default();
    let est = s.estimate.as_ref().unwrap_or(&empty);
    for (name, v) in &est.0 {
        let std = s
            .std_error
            .as_ref()
            .and_then(|n| n.get(name).copied().flatten());
        let rel = s
            .relative_std_error
            .as_ref()
            .and_then(|n| n.get(name).copied().flatten());
        let crb = s.crb.as_ref().and_then(|n| n.get(name).copied().flatten());
        let truth = truth_of(s, name);
        let _ = write!(
            out,
            "  {:<6} {:>16} {:<8} {:>12} {:>11} {:>12}",
            name,
            format_sig(*v, 9),
            unit_of(name),
            format!(
                "+- {}",
                std.map_or("inf".to_owned(), |e| format!("{e:.2e}"))
            ),
            rel.map_or("-".to_owned(), |r| format!("{r:.2e}")),
            crb.map_or("inf".to_owned(), |c| format!("{c:.2e}")),
        );
        if let Some(t) = truth {
            let z = std.map_or("-".to_owned(), |e| format!("{:+.2}", (v - t) / e));
            let _ = write!(out, " {:>14} {:>10}", format_sig(t, 7), z);
        }
        out.push('\n');
    }
    if let (Some(ic), Some(ise)) = (&s.initial_state, &s.initial_state_std_error) {
        let parts: Vec<String> =
            ic.0.iter()
                .map(|(n, v)| {
                    let e = ise.get(n).copied().flatten();
                    format!("{n} = {:.3e} +- {} {}", v, opt_e(e), unit_of(n))
                })
                .collect();
        let _ = writeln!(out, "  initial state: {}", parts.join(", "));
    }
    let _ = writeln!(
        out,
        "  noise (residuals): sigma_x = {} m, sigma_z = {} m",
        opt_e(s.sigma_x),
        opt_e(s.sigma_z)
    );
    let at = match s.crb_at.as_deref() {
        Some("truth") => "the scenario's rotor and initial state (the truth)",
        Some("truth_parameters") => "the scenario's rotor with the fitted initial state",
        Some("estimate") => "the estimate (the scenario states no complete truth)",
        _ => "-",
    };
    let _ = writeln!(
        out,
        "  CRB: Cramer-Rao bound on the standard deviation at {at}, with the fitted noise"
    );
    if let Some(note) = s.start.as_ref().and_then(|st| st.note.as_deref()) {
        let _ = writeln!(out, "  start: {note}");
    }
    let _ = write!(
        out,
        "  {} after {} model passes; {}; Fisher condition number {}",
        if s.converged == Some(true) {
            "converged"
        } else {
            "NOT converged"
        },
        s.iterations.unwrap_or(0),
        if s.identifiable == Some(true) {
            "identifiable"
        } else {
            "NOT identifiable"
        },
        opt_e(s.condition_number)
    );
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn named_values_keep_their_order_and_write_infinity_as_null() {
        let n: Named<Option<f64>> = [
            ("m".to_owned(), Some(1.5)),
            ("cx".to_owned(), None),
            ("a".to_owned(), Some(2.0)),
        ]
        .into_iter()
        .collect();
        let text = serde_json::to_string(&n).unwrap();
        assert_eq!(text, r#"{"m":1.5,"cx":null,"a":2.0}"#);
        let back: Named<Option<f64>> = serde_json::from_str(&text).unwrap();
        assert_eq!(back, n);
        assert_eq!(back.get("a"), Some(&Some(2.0)));
    }

    #[test]
    fn a_new_summary_has_every_batch_field_null() {
        let s = Summary::new("-".into(), "table1".into(), "algebraic".into(), 1e-5);
        let v = serde_json::to_value(&s).unwrap();
        for key in [
            "quadrature",
            "tol",
            "sigma_x",
            "sigma_z",
            "warnings",
            "modulating",
            "unknowns",
            "start",
            "estimate",
            "std_error",
            "relative_std_error",
            "crb",
            "crb_at",
            "std_error_basis",
            "initial_state",
            "initial_state_std_error",
            "identifiable",
            "converged",
            "iterations",
            "condition_number",
            "discretisation",
        ] {
            assert!(v[key].is_null(), "{key}: {}", v[key]);
        }
        let back: Summary = serde_json::from_value(v).unwrap();
        assert_eq!(back, s);
    }

    #[test]
    fn not_identifiable_is_said_first_and_every_warning_on_its_own_line() {
        let mut s = Summary::new("-".into(), "table1".into(), "refine".into(), 1e-12);
        s.identifiable = Some(false);
        s.warnings = Some(vec!["m is undetermined".into(), "x".into()]);
        let lines = warning_lines(&s);
        assert_eq!(lines.len(), 3);
        assert!(lines[0].starts_with("warning: NOT IDENTIFIABLE"));
        assert_eq!(lines[1], "warning: m is undetermined");
        let report = human_report(&s);
        assert!(report.contains("\nwarning: x"));
    }
}
