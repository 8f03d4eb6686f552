//! `rotorid analyze (SUMMARY.json | --scenario S.toml) --out DIR [--rpm 0:6000:10]
//! [--operating-rpm RPM]`:
//! from identified (or stated) rotor parameters to the numbers an engineer decides on,
//! with the uncertainty of the identification carried through (`rotorid::analysis`).
//!
//! A finite-element rotor: `rotorid analyze --scenario fe.toml --out DIR` or
//! `rotorid analyze SUMMARY.json --scenario fe.toml --out DIR [--modes N]` (a summary with
//! `model` = `"finite_element"` needs its scenario for the matrices); its `analysis.json`
//! keeps the layout below where it applies, with `model` = `"finite_element"`, `rotor` by
//! bearings and unbalances, `campbell.modes` one per followed mode and `unbalances` per
//! plane: the full layout is in the doc of the `finite_element` submodule
//! (`analyze/finite_element.rs`).
//!
//! Writes into DIR (created if missing):
//!
//! - `analysis.json`: critical speeds with standard deviations, the Campbell diagram's
//!   modes, stability, and the unbalance response per probe (layout below);
//! - `campbell.png/.svg`, `bode.png/.svg`, `polar.png/.svg`;
//! - `report.html`: one self-contained page with the tables and the figures.
//!
//! ```json
//! {
//!   "format_version": 1, "generator": "rotorid analyze 0.1.0", "source": "s.json",
//!   "model": "jeffcott",                          // or "cross_coupled"
//!   "rotor": {"m": .., "cx": .., "kx": .., "cz": .., "kz": .., "a": .., "mud": .., "alpha": ..},
//!            // cross_coupled: m, cxx, cxz, czx, czz, kxx, kxz, kzx, kzz, a, mud, alpha
//!   "rotor_std": {"m": .., ...} | null,          // null entries: undetermined
//!   "speed_range_rpm": {"start": 0, "stop": 6000, "step": 10},
//!   "critical_speeds": [{"rpm": 2519.9, "whirl": "backward", "std_rpm": 0.3, "mode": 0,
//!                        "frequency_hz": 42.0, "damping_ratio": .., "log_dec": ..,
//!                        "log_dec_std": ..}],
//!   "campbell": {"rpm": [...], "modes": [{"whirl": "backward", "frequency_hz": [...],
//!                "log_dec": [...], "damping_ratio": [...], "whirl_by_speed": [...]}]},
//!   "stability": {"stable": true, "min_log_dec": .., "min_log_dec_rpm": .., "min_log_dec_mode": 1,
//!                 "min_damping_ratio": .., "threshold_rpm": null, "threshold_rpm_std": null,
//!                 "threshold_mode": null, "threshold_whirl": null, "unstable_at_start": false,
//!                 "stable_from_rpm": null, "stable_from_rpm_std": null,
//!                 "operating": {"rpm": 1200, "source": "given", "mode": 1, "whirl": "forward",
//!                               "frequency_hz": .., "damping_ratio": .., "log_dec": ..,
//!                               "log_dec_std": .., "stable": true} | null},
//!   "unbalance_response": {"rpm": [...], "amplitude_unit": "um pk-pk", "band_sigmas": 2,
//!                "channels": [{"name": "x", "probe_deg": 90, "amplitude_um_pp": [...],
//!                "std_amplitude_um_pp": [...], "phase_lag_deg": [...], "std_phase_lag_deg": [...],
//!                "peak": {"rpm": .., "amplitude_um_pp": ..}}]},
//!   "figures": ["campbell.png", ...]
//! }
//! ```
//!
//! Units as engineers read them (ROSS, API 684): speeds in rpm, frequencies in Hz,
//! amplitudes in um peak-to-peak (mil with `--unit mil` in the figures), phase as lag in
//! degrees in [0, 360). Frequencies are damped natural frequencies; a critical speed is
//! where one meets the running speed. The unbalance response is computed on the `--rpm`
//! grid refined around each critical speed (the resonances are sharper than 10 rpm), so
//! its `rpm` array is not the Campbell diagram's. Standard deviations are linearised from
//! the summary's covariance (null without one, or where a parameter is undetermined).
//!
//! Stability (`rotorid::analysis` stability module, docs/analysis.md section 4): the
//! threshold is the lowest speed of the range at which the least damped mode's logarithmic
//! decrement turns negative (`threshold_rpm`, null when stable over the whole range; the
//! first speed of the range with `unstable_at_start` when already unstable there), with
//! its standard deviation by the implicit function theorem, the mode and its whirl;
//! `stable_from_rpm`, after an instability, where the rotor is stable again to the end of
//! the range. `operating` is the stability margin, the least damped mode's logarithmic
//! decrement with its standard deviation, at `--operating-rpm` (source `given`) or at the
//! constant speed of a `--scenario` (source `scenario`); null otherwise.

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context};
use rotorid::analysis::{
    campbell, critical_speeds, stability_margin, stability_with_covariance, unbalance_response,
    Campbell, CovarianceParameter, CriticalSpeed, Mode, ParameterCovariance, Probe, Stability,
    StabilityMargin, UnbalanceResponse, Whirl,
};
use rotorid::model::{rad_per_s_to_rpm, rpm_to_rad_per_s, CrossCoupling, SpeedProfile};
use rotorid::parameter::ModelKind;
use rotorid::{RotorParams, Unbalance};
use serde::Serialize;

use crate::io::identified::IdentifiedRotor;
use crate::io::{FileMode, LoadScenario as _, Output, ScenarioSpec};
use crate::plot::bode::{unwrap_deg, BodeChannel, BodePlot, BAND_SIGMAS};
use crate::plot::campbell::{with_std, CampbellMode, CampbellPlot, CriticalMark};
use crate::plot::canvas::save_drawing;
use crate::plot::polar::{PolarChannel, PolarPlot};
use crate::plot::{palette, Rgb, DEFAULT_SIZE};
use crate::report::analysis::{render_report, ReportFigure};

mod finite_element;

/// Version of the `analysis.json` layout.
pub const ANALYSIS_FORMAT_VERSION: u32 = 1;

/// The most speeds `--rpm` may ask for.
const MAX_SPEEDS: f64 = 1e5;

/// Points of the response grid added around each critical speed (see [`response_grid`]).
const REFINE_POINTS: usize = 360;

/// They reach this many decay rates either side of the critical speed.
const REFINE_SPAN: f64 = 60.0;

const ANALYZE_HELP: &str = "\
Input: an identification summary (its `rotor` and `covariance` fields; standard deviations
are propagated from the covariance) or a scenario (its rotor; no uncertainty). A
finite-element rotor: its scenario (rotor.model = \"finite_element\"), or the summary of its
identification with that scenario (SUMMARY.json --scenario fe.toml); --modes N follows its
lowest N modes (default 6); the whirl is in the matrices' frame (forward from +x towards +y).

Conventions: the shaft turns from +z (up) toward +x (horizontal), the sense in which the
unbalance force turns; forward whirl is whirl in that sense. Probe angles are measured from
+z (vertical) in the direction of rotation: x is at 90 deg, z at 0 deg. Phase lag is the
shaft angle from the keyphasor reference (phi = 0) to the positive peak of the signal.

Examples:
  rotorid analyze summary.json --out analysis
  rotorid analyze --scenario table1 --out analysis --rpm 0:4000:5 --probe 45
  rotorid analyze fe_summary.json --scenario fe.toml --out analysis --rpm 0:12000:20 --modes 4";

/// Arguments of `rotorid analyze`.
#[derive(Debug, clap::Args)]
#[command(after_long_help = ANALYZE_HELP)]
pub struct AnalyzeArgs {
    /// An identification summary written by `rotorid identify --summary` (its `rotor` and
    /// `covariance` fields are read).
    #[arg(value_name = "SUMMARY.json", required_unless_present = "scenario")]
    pub summary: Option<PathBuf>,

    /// Analyse the rotor of a scenario instead: `table1` or a TOML scenario file (every
    /// rotor key needed; no uncertainty). With a finite-element summary: the scenario it
    /// was identified with (its matrices; the summary's identified values replace its own).
    #[arg(long, value_name = "table1|FILE.toml")]
    pub scenario: Option<String>,

    /// Finite-element rotor: how many of its lowest modes the Campbell diagram, critical
    /// speeds and stability follow (1 ..= its degrees of freedom; default 6 or all when it
    /// has fewer).
    #[arg(long, value_name = "N")]
    pub modes: Option<usize>,

    /// Output directory (created if missing).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,

    /// Speed grid START:STOP:STEP in rpm.
    #[arg(long, value_name = "START:STOP:STEP", default_value = "0:6000:10", value_parser = parse_rpm_grid)]
    pub rpm: RpmGrid,

    /// An extra probe for the unbalance response, at this angle in degrees from +z
    /// (vertical) in the direction of rotation (repeatable; x and z are always shown).
    #[arg(long = "probe", value_name = "DEG", allow_hyphen_values = true)]
    pub probes: Vec<f64>,

    /// The operating speed in rpm: the stability margin (least damped mode's logarithmic
    /// decrement with its standard deviation) is reported there. Default: a scenario's
    /// constant speed; none for a summary.
    #[arg(long, value_name = "RPM", value_parser = parse_operating_rpm)]
    pub operating_rpm: Option<f64>,

    /// Amplitude unit of the figures: um or mil peak-to-peak (analysis.json is in um);
    /// default um. Refused for a finite-element rotor, whose analysis has no amplitude
    /// figure yet.
    #[arg(long, value_enum, value_name = "UNIT")]
    pub unit: Option<AmplitudeUnit>,
}

/// `--unit` values.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum AmplitudeUnit {
    /// Micrometres peak-to-peak.
    Um,
    /// Mils (thousandths of an inch) peak-to-peak.
    Mil,
}

impl AmplitudeUnit {
    /// Peak-to-peak in this unit per metre of peak amplitude.
    fn per_metre_peak(self) -> f64 {
        match self {
            AmplitudeUnit::Um => 2.0e6,
            AmplitudeUnit::Mil => 2.0 / 25.4e-6,
        }
    }

    /// As written on the command line.
    fn name(self) -> &'static str {
        match self {
            AmplitudeUnit::Um => "um",
            AmplitudeUnit::Mil => "mil",
        }
    }

    fn label(self) -> &'static str {
        match self {
            AmplitudeUnit::Um => "\u{b5}m pk-pk",
            AmplitudeUnit::Mil => "mil pk-pk",
        }
    }
}

/// The `--rpm` grid.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RpmGrid {
    /// First speed \[rpm\].
    pub start: f64,
    /// Last speed \[rpm\].
    pub stop: f64,
    /// Spacing \[rpm\].
    pub step: f64,
}

impl RpmGrid {
    /// The speeds start, start + step, ... up to stop (included, within rounding) \[rpm\].
    pub fn speeds_rpm(&self) -> Vec<f64> {
        let n = ((self.stop - self.start) / self.step * (1.0 + 1e-12)).floor() as usize;
        let mut v: Vec<f64> = (0..=n).map(|i| self.start + i as f64 * self.step).collect();
        if let Some(last) = v.last_mut() {
            if (self.stop - *last).abs() <= 1e-9 * self.step {
                *last = self.stop;
            }
        }
        v
    }

    /// The same speeds \[rad/s\].
    pub fn speeds_rad_per_s(&self) -> Vec<f64> {
        self.speeds_rpm()
            .into_iter()
            .map(rpm_to_rad_per_s)
            .collect()
    }
}

/// Parse `START:STOP:STEP` (rpm): finite, 0 <= START < STOP, STEP > 0, at most 1e5 speeds.
pub fn parse_rpm_grid(s: &str) -> Result<RpmGrid, String> {
    let parts: Vec<&str> = s.split(':').collect();
    let usage = "expected START:STOP:STEP in rpm, e.g. 0:6000:10";
    if parts.len() != 3 {
        return Err(format!("`{s}`: {usage}"));
    }
    let mut v = [0.0; 3];
    for (slot, (p, name)) in v
        .iter_mut()
        .zip(parts.iter().zip(["START", "STOP", "STEP"]))
    {
        *slot = p
            .trim()
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| format!("`{s}`: {name} = `{p}` is not a finite number; {usage}"))?;
    }
    let [start, stop, step] = v;
    if start < 0.0 {
        return Err(format!("`{s}`: START = {start} must be >= 0 (rpm)"));
    }
    if stop <= start {
        return Err(format!(
            "`{s}`: STOP = {stop} must be above START = {start} (rpm)"
        ));
    }
    if step <= 0.0 {
        return Err(format!("`{s}`: STEP = {step} must be > 0 (rpm)"));
    }
    if (stop - start) / step > MAX_SPEEDS {
        return Err(format!(
            "`{s}`: {} speeds exceed the limit of {MAX_SPEEDS:e}; use a larger STEP",
            ((stop - start) / step).floor() + 1.0
        ));
    }
    Ok(RpmGrid { start, stop, step })
}

/// Parse `--operating-rpm`: a finite speed >= 0 (rpm).
pub fn parse_operating_rpm(s: &str) -> Result<f64, String> {
    s.trim()
        .parse::<f64>()
        .ok()
        .filter(|v| v.is_finite() && *v >= 0.0)
        .ok_or_else(|| format!("`{s}` is not a speed: expected a finite number >= 0 (rpm)"))
}

/// The rotor to analyse: from a summary (with its covariance) or a scenario; and a
/// description of where it came from.
pub fn load_rotor(
    summary: Option<&Path>,
    scenario: Option<&str>,
    who: &str,
) -> anyhow::Result<(IdentifiedRotor, String)> {
    load_rotor_and_speed(summary, scenario, who).map(|(r, s, _)| (r, s))
}

/// [`load_rotor`], and the scenario's constant speed \[rad/s\] when it has one.
fn load_rotor_and_speed(
    summary: Option<&Path>,
    scenario: Option<&str>,
    who: &str,
) -> anyhow::Result<(IdentifiedRotor, String, Option<f64>)> {
    match (summary, scenario) {
        (Some(p), _) => Ok((IdentifiedRotor::read(p)?, p.display().to_string(), None)),
        (None, Some(s)) => {
            let spec = ScenarioSpec::load(s)?;
            let id = spec.identification()?;
            let t = id.truth;
            let need = |v: Option<f64>, key: &str, unit: &str| {
                v.ok_or_else(|| {
                    anyhow!(
                        "{}: missing key rotor.{key} ({unit}); {who} needs every rotor parameter",
                        spec.origin()
                    )
                })
            };
            let coupling = match id.model {
                ModelKind::Jeffcott => None,
                ModelKind::CrossCoupled => Some(CrossCoupling {
                    cxz: need(t.cxz, "cxz", "N s/m")?,
                    czx: need(t.czx, "czx", "N s/m")?,
                    kxz: need(t.kxz, "kxz", "N/m")?,
                    kzx: need(t.kzx, "kzx", "N/m")?,
                }),
            };
            let cross = coupling.is_some();
            let name = |j: &'static str, c: &'static str| if cross { c } else { j };
            let params = RotorParams {
                coupling,
                m: need(t.m, "m", "kg")?,
                cx: need(t.cx, name("cx", "cxx"), "N s/m")?,
                cz: need(t.cz, name("cz", "czz"), "N s/m")?,
                kx: need(t.kx, name("kx", "kxx"), "N/m")?,
                kz: need(t.kz, name("kz", "kzz"), "N/m")?,
                a: id.a,
                unbalance: Unbalance {
                    m_u: id.m_u,
                    d: id.d,
                    alpha: id.alpha,
                },
            };
            let speed = match id.speed {
                Some(SpeedProfile::Constant { omega, .. }) => Some(omega),
                _ => None,
            };
            Ok((
                IdentifiedRotor {
                    params,
                    covariance: None,
                },
                format!("scenario {}", spec.origin()),
                speed,
            ))
        }
        (None, None) => bail!("give an identification summary SUMMARY.json or --scenario"),
    }
}

/// The response grid \[rad/s\]: `grid` with `REFINE_POINTS` more around each critical
/// speed W_c, spaced as W = W_c + s tan(theta) with theta uniform over
/// +-atan(`REFINE_SPAN`) and s = |Re lambda| (the mode's decay rate, about the resonance's
/// half-power half-width). Near a resonance the response's phase is about theta, so the
/// points fall evenly along the polar plot's loop and resolve the Bode plot's peak, which
/// the `--rpm` grid would miss (half-widths of a few rpm).
pub fn response_grid(grid: &[f64], critical: &[CriticalSpeed]) -> Vec<f64> {
    let (lo, hi) = (grid[0], grid[grid.len() - 1]);
    let mut v = grid.to_vec();
    for c in critical {
        let s = c.at.eigenvalue.re.abs().max(1e-6 * c.speed);
        let t_max = REFINE_SPAN.atan();
        for i in 0..=REFINE_POINTS {
            let t = -t_max + 2.0 * t_max * i as f64 / REFINE_POINTS as f64;
            let w = c.speed + s * t.tan();
            if w >= lo && w <= hi {
                v.push(w);
            }
        }
    }
    v.sort_by(f64::total_cmp);
    v.dedup_by(|a, b| (*a - *b).abs() <= 1e-9 * b.abs().max(1e-9));
    v
}

#[derive(Serialize)]
struct RotorJson {
    m: f64,
    cx: f64,
    kx: f64,
    cz: f64,
    kz: f64,
    a: f64,
    mud: f64,
    alpha: f64,
}

/// The cross-coupled model's rotor, keyed as the summary keys it.
#[derive(Serialize)]
struct CrossRotorJson<T> {
    m: T,
    cxx: T,
    cxz: T,
    czx: T,
    czz: T,
    kxx: T,
    kxz: T,
    kzx: T,
    kzz: T,
    a: T,
    mud: T,
    alpha: T,
}

/// The rotor (or its standard deviations) in the model's own names.
#[derive(Serialize)]
#[serde(untagged)]
enum ModelRotorJson<J, C> {
    Jeffcott(J),
    Cross(C),
}

#[derive(Serialize)]
struct RotorStdJson {
    m: Option<f64>,
    cx: Option<f64>,
    kx: Option<f64>,
    cz: Option<f64>,
    kz: Option<f64>,
    a: Option<f64>,
    mud: Option<f64>,
    alpha: Option<f64>,
}

#[derive(Serialize)]
struct CriticalJson {
    rpm: f64,
    whirl: Option<Whirl>,
    std_rpm: Option<f64>,
    mode: usize,
    frequency_hz: f64,
    damping_ratio: f64,
    log_dec: Option<f64>,
    log_dec_std: Option<f64>,
}

#[derive(Serialize)]
struct ModeJson {
    whirl: Option<Whirl>,
    frequency_hz: Vec<f64>,
    log_dec: Vec<Option<f64>>,
    damping_ratio: Vec<f64>,
    whirl_by_speed: Vec<Option<Whirl>>,
}

#[derive(Serialize)]
struct CampbellJson {
    rpm: Vec<f64>,
    modes: Vec<ModeJson>,
}

#[derive(Serialize)]
struct StabilityJson {
    stable: bool,
    min_log_dec: Option<f64>,
    min_log_dec_rpm: Option<f64>,
    min_log_dec_mode: Option<usize>,
    min_damping_ratio: f64,
    threshold_rpm: Option<f64>,
    threshold_rpm_std: Option<f64>,
    threshold_mode: Option<usize>,
    threshold_whirl: Option<Whirl>,
    unstable_at_start: bool,
    stable_from_rpm: Option<f64>,
    stable_from_rpm_std: Option<f64>,
    operating: Option<OperatingJson>,
}

/// The stability margin at the operating speed.
#[derive(Serialize)]
struct OperatingJson {
    rpm: f64,
    source: &'static str,
    mode: usize,
    whirl: Option<Whirl>,
    frequency_hz: f64,
    damping_ratio: f64,
    log_dec: Option<f64>,
    log_dec_std: Option<f64>,
    stable: bool,
}

#[derive(Serialize)]
struct PeakJson {
    rpm: f64,
    amplitude_um_pp: f64,
}

#[derive(Serialize)]
struct ChannelJson {
    name: String,
    probe_deg: f64,
    amplitude_um_pp: Vec<Option<f64>>,
    std_amplitude_um_pp: Vec<Option<f64>>,
    phase_lag_deg: Vec<Option<f64>>,
    std_phase_lag_deg: Vec<Option<f64>>,
    peak: Option<PeakJson>,
}

#[derive(Serialize)]
struct ResponseJson {
    rpm: Vec<f64>,
    amplitude_unit: &'static str,
    band_sigmas: f64,
    channels: Vec<ChannelJson>,
}

#[derive(Serialize)]
struct AnalysisJson {
    format_version: u32,
    generator: String,
    source: String,
    model: &'static str,
    rotor: ModelRotorJson<RotorJson, CrossRotorJson<f64>>,
    rotor_std: Option<ModelRotorJson<RotorStdJson, CrossRotorJson<Option<f64>>>>,
    speed_range_rpm: RpmGrid,
    critical_speeds: Vec<CriticalJson>,
    campbell: CampbellJson,
    stability: StabilityJson,
    unbalance_response: ResponseJson,
    figures: Vec<String>,
}

/// Everything computed, before it is written.
struct Results {
    params: RotorParams,
    covariance: Option<ParameterCovariance>,
    campbell: Campbell,
    critical: Vec<CriticalSpeed>,
    stability: Stability,
    /// The margin at the operating speed, and where that speed came from.
    operating: Option<(StabilityMargin, &'static str)>,
    response: UnbalanceResponse,
    names: Vec<String>,
}

fn rotor_std(
    p: &RotorParams,
    c: &ParameterCovariance,
) -> ModelRotorJson<RotorStdJson, CrossRotorJson<Option<f64>>> {
    let j = jeffcott_std(p, c);
    if p.coupling.is_none() {
        return ModelRotorJson::Jeffcott(j);
    }
    let one = |q: CovarianceParameter| c.std(q);
    ModelRotorJson::Cross(CrossRotorJson {
        m: j.m,
        cxx: j.cx,
        cxz: one(CovarianceParameter::Cxz),
        czx: one(CovarianceParameter::Czx),
        czz: j.cz,
        kxx: j.kx,
        kxz: one(CovarianceParameter::Kxz),
        kzx: one(CovarianceParameter::Kzx),
        kzz: j.kz,
        a: j.a,
        mud: j.mud,
        alpha: j.alpha,
    })
}

fn jeffcott_std(p: &RotorParams, c: &ParameterCovariance) -> RotorStdJson {
    let (mud, alpha) = (p.unbalance.mud(), p.unbalance.alpha);
    let (s, co) = alpha.sin_cos();
    let one = |q: CovarianceParameter| c.std(q);
    RotorStdJson {
        m: one(CovarianceParameter::M),
        cx: one(CovarianceParameter::Cx),
        kx: one(CovarianceParameter::Kx),
        cz: one(CovarianceParameter::Cz),
        kz: one(CovarianceParameter::Kz),
        a: one(CovarianceParameter::A),
        mud: c.std_of_linear(&[
            (CovarianceParameter::MudCosAlpha, co),
            (CovarianceParameter::MudSinAlpha, s),
        ]),
        alpha: (mud > 0.0)
            .then(|| {
                c.std_of_linear(&[
                    (CovarianceParameter::MudCosAlpha, -s / mud),
                    (CovarianceParameter::MudSinAlpha, co / mud),
                ])
            })
            .flatten(),
    }
}

/// The probes: x, z and the extra ones, with their names.
fn probes(extra: &[f64]) -> anyhow::Result<(Vec<Probe>, Vec<String>)> {
    let mut p = vec![Probe::X, Probe::Z];
    let mut names = vec!["x".to_string(), "z".to_string()];
    for &deg in extra {
        if !deg.is_finite() {
            bail!("--probe {deg} is out of range: must be a finite angle (deg)");
        }
        p.push(Probe {
            angle: deg.to_radians(),
        });
        names.push(format!("probe {deg} deg"));
    }
    Ok((p, names))
}

fn compute(
    args: &AnalyzeArgs,
    rotor: IdentifiedRotor,
    scenario_speed: Option<f64>,
) -> anyhow::Result<Results> {
    let speeds = args.rpm.speeds_rad_per_s();
    let p = rotor.params;
    let cov = rotor.covariance.as_ref();
    let camp = campbell(&p, &speeds)?;
    let critical = if speeds.len() >= 2 {
        critical_speeds(&p, cov, &speeds)?
    } else {
        Vec::new()
    };
    let stab = stability_with_covariance(&p, cov, &speeds)?;
    let operating = match (args.operating_rpm, scenario_speed) {
        (Some(rpm), _) => Some((rpm_to_rad_per_s(rpm), "given")),
        (None, Some(w)) => Some((w, "scenario")),
        (None, None) => None,
    };
    let operating = operating
        .map(|(w, src)| stability_margin(&p, cov, w).map(|m| (m, src)))
        .transpose()?;
    let (pr, names) = probes(&args.probes)?;
    let response = unbalance_response(&p, cov, &response_grid(&speeds, &critical), &pr)?;
    Ok(Results {
        params: p,
        covariance: rotor.covariance,
        campbell: camp,
        critical,
        stability: stab,
        operating,
        response,
        names,
    })
}

fn whirl_name(w: Option<Whirl>) -> &'static str {
    w.map_or("no whirl direction", Whirl::name)
}

/// `v` with 4 (`digits`) decimals and its standard deviation when there is one.
fn with_std_fixed(v: f64, std: Option<f64>, digits: usize) -> String {
    match std {
        Some(s) => format!("{v:.digits$} \u{b1} {s:.digits$}"),
        None => format!("{v:.digits$}"),
    }
}

/// The instability in words: where it starts (with its standard deviation), the mode
/// (`mode_name` of its index: "lower", "mode 3") and whirl that grow, where the rotor is
/// stable again, and what causes it.
fn instability_text(st: &Stability, mode_name: &dyn Fn(usize) -> String, cross: bool) -> String {
    let Some(t) = st.threshold else {
        return "stable over the range".to_string();
    };
    let whirl = st
        .threshold_whirl
        .map_or("a".to_string(), |w| format!("the {}", w.name()));
    let mode = mode_name(st.threshold_mode.unwrap_or(0));
    let mut s = if st.unstable_at_start {
        format!(
            "UNSTABLE from the start of the range ({:.1} rpm): {whirl} whirl ({mode}) mode's log decrement is negative",
            rad_per_s_to_rpm(t)
        )
    } else {
        format!(
            "UNSTABLE above the threshold speed {}: {whirl} whirl ({mode}) mode's log decrement turns negative there",
            with_std(rad_per_s_to_rpm(t), st.threshold_std_rpm(), "rpm")
        )
    };
    if let Some(w) = st.stable_from {
        s.push_str(&format!(
            "; stable again from {}",
            with_std(
                rad_per_s_to_rpm(w),
                st.stable_from_std.map(rad_per_s_to_rpm),
                "rpm"
            )
        ));
    }
    s.push_str(if cross {
        " (the bearings' cross-coupled coefficients feed that whirl faster than the damping dissipates it)"
    } else {
        " (the Jeffcott rotor is stable whenever cx, cz > 0: check the identified damping)"
    });
    s
}

/// Run `rotorid analyze`.
pub fn run(args: AnalyzeArgs) -> anyhow::Result<()> {
    if let Some(fe) = finite_element::input(&args)? {
        return finite_element::run(&args, fe);
    }
    if let (Some(summary), Some(scenario)) = (&args.summary, &args.scenario) {
        bail!(
            "--scenario {scenario}: a scenario goes with a finite-element summary only (for its \
             matrices); {} is a 2-DOF summary, analysed from its own rotor: drop --scenario",
            summary.display()
        );
    }
    if let Some(n) = args.modes {
        bail!(
            "--modes {n}: the number of modes applies to a finite-element rotor; the 2-DOF \
             models have two"
        );
    }
    let (rotor, source, scenario_speed) =
        load_rotor_and_speed(args.summary.as_deref(), args.scenario.as_deref(), "analyze")?;
    let r = compute(&args, rotor, scenario_speed)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create output directory {}", args.out.display()))?;

    let marks: Vec<CriticalMark> = r
        .critical
        .iter()
        .map(|c| CriticalMark {
            rpm: c.rpm(),
            std_rpm: c.std_rpm(),
            whirl: c.whirl(),
        })
        .collect();
    let figures = write_figures(&args, &r, &source, &marks)?;
    let json = analysis_json(&args, &r, &source, &figures);
    write_analysis_json(&args.out, &json)?;
    let html = render_report(&json, &args.out, &report_figures())?;
    let report = args.out.join("report.html");
    std::fs::write(&report, html).with_context(|| format!("cannot write {}", report.display()))?;

    // the numbers that matter, on stdout
    let uncertainty = if r.covariance.is_some() {
        "with standard deviations from the covariance"
    } else {
        "no covariance: no standard deviations"
    };
    outln!("rotor from {source} ({uncertainty})")?;
    print_critical_speeds(args.rpm, &r.critical, |_| String::new())?;
    let two = |m: usize| ["lower", "higher"][m.min(1)].to_owned();
    print_stability(
        &r.stability,
        &|m| format!("{} mode", two(m)),
        &instability_text(&r.stability, &two, r.params.coupling.is_some()),
    )?;
    if let Some((m, src)) = &r.operating {
        let which = format!("{} mode, {}", two(m.mode), whirl_name(m.at.whirl));
        print_margin(m, src, &which)?;
    }
    outln!(
        "wrote {}: analysis.json, {}, report.html",
        args.out.display(),
        figures.join(", ")
    )?;
    Ok(())
}

/// `json` as `dir/analysis.json` (pretty, written atomically).
fn write_analysis_json(dir: &Path, json: &impl Serialize) -> anyhow::Result<()> {
    let path = dir.join("analysis.json");
    let mut out = Output::create(&path.display().to_string(), FileMode::Atomic)?;
    serde_json::to_writer_pretty(&mut out, json)
        .with_context(|| format!("cannot write {}", path.display()))?;
    std::io::Write::write_all(&mut out, b"\n")?;
    out.commit()?;
    Ok(())
}

/// The critical speeds over the grid `g` on stdout, `extra` after each one's whirl.
fn print_critical_speeds(
    g: RpmGrid,
    critical: &[CriticalSpeed],
    extra: impl Fn(&CriticalSpeed) -> String,
) -> anyhow::Result<()> {
    outln!("critical speeds ({}-{} rpm):", g.start, g.stop)?;
    if critical.is_empty() {
        outln!("  none")?;
    }
    for (n, c) in critical.iter().enumerate() {
        outln!(
            "  {}: {}  {}{}  (log dec {})",
            n + 1,
            with_std(c.rpm(), c.std_rpm(), "rpm"),
            whirl_name(c.whirl()),
            extra(c),
            c.at.log_dec
                .map_or("-".into(), |d| with_std_fixed(d, c.log_dec_std, 4))
        )?;
    }
    Ok(())
}

/// Stability over the range on stdout (`mode_name` names a mode by its index; `unstable`
/// is [`instability_text`]), and on stderr as a warning when unstable.
fn print_stability(
    st: &Stability,
    mode_name: &dyn Fn(usize) -> String,
    unstable: &str,
) -> anyhow::Result<()> {
    match (st.threshold, st.min_log_dec) {
        (None, Some(d)) => outln!(
            "stability: stable over the range; minimum log decrement {d:.4} ({} at {:.0} rpm)",
            mode_name(st.min_log_dec_mode.unwrap_or(0)),
            rad_per_s_to_rpm(st.min_log_dec_speed.unwrap_or(0.0))
        )?,
        (None, None) => outln!("stability: stable over the range")?,
        (Some(_), _) => {
            outln!("stability: {unstable}")?;
            eprintln!("warning: {unstable}");
        }
    }
    Ok(())
}

/// The stability margin at the operating speed on stdout (`which` names the least damped
/// mode and its whirl), with a warning on stderr when that mode grows.
fn print_margin(m: &StabilityMargin, src: &str, which: &str) -> anyhow::Result<()> {
    let rpm = rad_per_s_to_rpm(m.speed);
    let from = if src == "given" {
        "--operating-rpm"
    } else {
        "the scenario's speed"
    };
    let d = m
        .log_dec()
        .map_or("- (the mode does not oscillate)".into(), |d| {
            with_std_fixed(d, m.log_dec_std, 4)
        });
    outln!(
        "stability margin at {rpm:.1} rpm ({from}): log decrement {d} of the least damped mode ({which})"
    )?;
    if m.is_unstable() {
        eprintln!(
            "warning: the rotor is UNSTABLE at the operating speed {rpm:.1} rpm: the {} mode's log decrement is {d}",
            whirl_name(m.at.whirl)
        );
    }
    Ok(())
}

/// One channel's response as plotted and written.
struct ChannelSeries {
    /// Amplitude per speed \[unit pk-pk\]; NaN where unbounded.
    amplitude: Vec<f64>,
    /// Its standard deviation \[unit pk-pk\].
    std_amplitude: Vec<Option<f64>>,
    /// Phase lag per speed \[deg\] in \[0, 360); NaN where undefined.
    lag_deg: Vec<f64>,
    /// Its standard deviation \[deg\].
    std_lag_deg: Vec<Option<f64>>,
}

/// The response's series of channel `i`, amplitudes in the unit of `per_m` (per metre
/// of peak amplitude).
fn channel_series(r: &Results, i: usize, per_m: f64) -> ChannelSeries {
    let pts = &r.response.channels[i].points;
    ChannelSeries {
        amplitude: pts
            .iter()
            .map(|v| v.map_or(f64::NAN, |v| v.amplitude * per_m))
            .collect(),
        std_amplitude: pts
            .iter()
            .map(|v| v.and_then(|v| v.std_amplitude).map(|s| s * per_m))
            .collect(),
        lag_deg: pts
            .iter()
            .map(|v| {
                v.and_then(|v| v.phase_lag)
                    .map_or(f64::NAN, f64::to_degrees)
            })
            .collect(),
        std_lag_deg: pts
            .iter()
            .map(|v| v.and_then(|v| v.std_phase_lag).map(f64::to_degrees))
            .collect(),
    }
}

const CHANNEL_COLOURS: [Rgb; 6] = [
    palette::BLUE,
    palette::VERMILLION,
    Rgb(0, 158, 115),
    Rgb(204, 121, 167),
    Rgb(230, 159, 0),
    palette::GREY,
];

fn channel_label(name: &str) -> String {
    match name {
        "x" => "x (horizontal, 90\u{b0})".to_string(),
        "z" => "z (vertical, 0\u{b0})".to_string(),
        other => other.replace(" deg", "\u{b0}"),
    }
}

fn write_figures(
    args: &AnalyzeArgs,
    r: &Results,
    source: &str,
    marks: &[CriticalMark],
) -> anyhow::Result<Vec<String>> {
    // titles name the file, not its whole path
    let name = args
        .summary
        .as_deref()
        .and_then(Path::file_name)
        .map_or_else(|| source.to_string(), |f| f.to_string_lossy().into_owned());
    let source = name.as_str();
    let camp_rpm: Vec<f64> = r
        .campbell
        .speeds
        .iter()
        .map(|&w| rad_per_s_to_rpm(w))
        .collect();
    let campbell_plot = CampbellPlot {
        title: format!("Campbell diagram \u{2014} {source}"),
        rpm: camp_rpm,
        modes: (0..2)
            .map(|i| CampbellMode {
                frequency_hz: r.campbell.mode(i).map(|m| m.frequency_hz()).collect(),
                log_dec: r.campbell.mode(i).map(|m| m.log_dec).collect(),
                whirl: r.campbell.mode(i).map(|m| m.whirl).collect(),
            })
            .collect(),
        critical: marks.to_vec(),
    };
    let per_m = args.unit.unwrap_or(AmplitudeUnit::Um).per_metre_peak();
    let rpm: Vec<f64> = r
        .response
        .speeds
        .iter()
        .map(|&w| rad_per_s_to_rpm(w))
        .collect();
    let mut bode_channels = Vec::new();
    let mut polar_channels = Vec::new();
    for (i, name) in r.names.iter().enumerate() {
        let s = channel_series(r, i, per_m);
        let color = CHANNEL_COLOURS[i % CHANNEL_COLOURS.len()];
        polar_channels.push(PolarChannel {
            label: channel_label(name),
            color,
            amplitude: s.amplitude.clone(),
            phase_lag_deg: s.lag_deg.clone(),
        });
        bode_channels.push(BodeChannel {
            label: channel_label(name),
            color,
            amplitude: s.amplitude,
            std_amplitude: s.std_amplitude,
            phase_lag_deg: unwrap_deg(&s.lag_deg),
            std_phase_lag_deg: s.std_lag_deg,
        });
    }
    let unit = args.unit.unwrap_or(AmplitudeUnit::Um).label().to_string();
    let bode = BodePlot {
        title: format!("Unbalance response (Bode) \u{2014} {source}"),
        rpm: rpm.clone(),
        unit: unit.clone(),
        channels: bode_channels,
        critical: marks.to_vec(),
    };
    let polar = PolarPlot {
        title: format!("Unbalance response (polar) \u{2014} {source}"),
        rpm,
        unit,
        channels: polar_channels,
        critical: marks.to_vec(),
    };
    let mut written = Vec::new();
    for ext in ["png", "svg"] {
        let name = format!("campbell.{ext}");
        save_drawing(&campbell_plot, DEFAULT_SIZE, &args.out.join(&name))?;
        written.push(name);
        let name = format!("bode.{ext}");
        save_drawing(&bode, (1400, 1000), &args.out.join(&name))?;
        written.push(name);
        let name = format!("polar.{ext}");
        save_drawing(&polar, (1400, 1000), &args.out.join(&name))?;
        written.push(name);
    }
    written.sort();
    Ok(written)
}

fn analysis_json(
    args: &AnalyzeArgs,
    r: &Results,
    source: &str,
    figures: &[String],
) -> AnalysisJson {
    let p = &r.params;
    let um = AmplitudeUnit::Um.per_metre_peak();
    let opt = |v: f64| v.is_finite().then_some(v);
    let channels = r
        .names
        .iter()
        .enumerate()
        .map(|(i, name)| {
            let ch = &r.response.channels[i];
            let s = channel_series(r, i, um);
            let peak = s
                .amplitude
                .iter()
                .enumerate()
                .filter(|(_, a)| a.is_finite())
                .max_by(|a, b| a.1.total_cmp(b.1))
                .map(|(k, &a)| PeakJson {
                    rpm: rad_per_s_to_rpm(r.response.speeds[k]),
                    amplitude_um_pp: a,
                });
            ChannelJson {
                name: name.clone(),
                probe_deg: ch.probe.angle.to_degrees(),
                amplitude_um_pp: s.amplitude.iter().map(|&a| opt(a)).collect(),
                std_amplitude_um_pp: s.std_amplitude,
                phase_lag_deg: s.lag_deg.iter().map(|&l| opt(l)).collect(),
                std_phase_lag_deg: s.std_lag_deg,
                peak,
            }
        })
        .collect();
    AnalysisJson {
        format_version: ANALYSIS_FORMAT_VERSION,
        generator: format!("rotorid analyze {}", env!("CARGO_PKG_VERSION")),
        source: source.to_string(),
        model: p.model().name(),
        rotor: match p.coupling {
            None => ModelRotorJson::Jeffcott(RotorJson {
                m: p.m,
                cx: p.cx,
                kx: p.kx,
                cz: p.cz,
                kz: p.kz,
                a: p.a,
                mud: p.unbalance.mud(),
                alpha: p.unbalance.alpha,
            }),
            Some(x) => ModelRotorJson::Cross(CrossRotorJson {
                m: p.m,
                cxx: p.cx,
                cxz: x.cxz,
                czx: x.czx,
                czz: p.cz,
                kxx: p.kx,
                kxz: x.kxz,
                kzx: x.kzx,
                kzz: p.kz,
                a: p.a,
                mud: p.unbalance.mud(),
                alpha: p.unbalance.alpha,
            }),
        },
        rotor_std: r.covariance.as_ref().map(|c| rotor_std(p, c)),
        speed_range_rpm: args.rpm,
        critical_speeds: r.critical.iter().map(critical_json).collect(),
        campbell: CampbellJson {
            rpm: r
                .campbell
                .speeds
                .iter()
                .map(|&w| rad_per_s_to_rpm(w))
                .collect(),
            modes: (0..2)
                .map(|i| mode_json(r.campbell.mode(i), r.campbell.whirl(i)))
                .collect(),
        },
        stability: stability_json(&r.stability, r.operating.as_ref()),
        unbalance_response: ResponseJson {
            rpm: r
                .response
                .speeds
                .iter()
                .map(|&w| rad_per_s_to_rpm(w))
                .collect(),
            amplitude_unit: "um pk-pk",
            band_sigmas: BAND_SIGMAS,
            channels,
        },
        figures: figures.to_vec(),
    }
}

fn critical_json(c: &CriticalSpeed) -> CriticalJson {
    CriticalJson {
        rpm: c.rpm(),
        whirl: c.whirl(),
        std_rpm: c.std_rpm(),
        mode: c.mode,
        frequency_hz: c.at.frequency_hz(),
        damping_ratio: c.at.damping_ratio,
        log_dec: c.at.log_dec,
        log_dec_std: c.log_dec_std,
    }
}

fn mode_json<'a>(modes: impl Iterator<Item = &'a Mode>, whirl: Option<Whirl>) -> ModeJson {
    let modes: Vec<&Mode> = modes.collect();
    ModeJson {
        whirl,
        frequency_hz: modes.iter().map(|m| m.frequency_hz()).collect(),
        log_dec: modes.iter().map(|m| m.log_dec).collect(),
        damping_ratio: modes.iter().map(|m| m.damping_ratio).collect(),
        whirl_by_speed: modes.iter().map(|m| m.whirl).collect(),
    }
}

fn stability_json(
    st: &Stability,
    operating: Option<&(StabilityMargin, &'static str)>,
) -> StabilityJson {
    StabilityJson {
        stable: st.is_stable(),
        min_log_dec: st.min_log_dec,
        min_log_dec_rpm: st.min_log_dec_speed.map(rad_per_s_to_rpm),
        min_log_dec_mode: st.min_log_dec_mode,
        min_damping_ratio: st.min_damping_ratio,
        threshold_rpm: st.threshold_rpm(),
        threshold_rpm_std: st.threshold_std_rpm(),
        threshold_mode: st.threshold_mode,
        threshold_whirl: st.threshold_whirl,
        unstable_at_start: st.unstable_at_start,
        stable_from_rpm: st.stable_from.map(rad_per_s_to_rpm),
        stable_from_rpm_std: st.stable_from_std.map(rad_per_s_to_rpm),
        operating: operating.map(|(m, src)| OperatingJson {
            rpm: rad_per_s_to_rpm(m.speed),
            source: src,
            mode: m.mode,
            whirl: m.at.whirl,
            frequency_hz: m.at.frequency_hz(),
            damping_ratio: m.at.damping_ratio,
            log_dec: m.at.log_dec,
            log_dec_std: m.log_dec_std,
            stable: !m.is_unstable(),
        }),
    }
}

/// The figures of the report, in page order, with captions.
pub fn report_figures() -> Vec<ReportFigure> {
    vec![
        ReportFigure {
            stem: "campbell",
            caption: "Campbell diagram: damped natural frequencies against running speed; \
                      triangles up forward whirl, down backward whirl, colour the logarithmic \
                      decrement; circles the critical speeds (a mode meeting 1X)."
                .to_string(),
        },
        ReportFigure {
            stem: "bode",
            caption: format!(
                "Unbalance response: 1X amplitude (peak-to-peak, log scale) and phase lag \
                 against running speed; shaded +-{BAND_SIGMAS:.0} standard deviations \
                 propagated from the covariance; dashed lines the critical speeds."
            ),
        },
        ReportFigure {
            stem: "polar",
            caption: "Polar plot of the 1X vectors over the speed range: radius the amplitude, \
                      angle the phase lag (0 deg at the top, increasing against rotation)."
                .to_string(),
        },
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rpm_grids_parse_and_reject_nonsense() {
        let g = parse_rpm_grid("0:6000:10").unwrap();
        let s = g.speeds_rpm();
        assert_eq!((s.len(), s[0], s[600]), (601, 0.0, 6000.0));
        let g = parse_rpm_grid("100:1000:300").unwrap();
        assert_eq!(g.speeds_rpm(), [100.0, 400.0, 700.0, 1000.0]);
        let g = parse_rpm_grid("0:1:0.1").unwrap();
        assert_eq!(g.speeds_rpm().len(), 11);
        for (bad, why) in [
            ("0:6000", "expected START:STOP:STEP"),
            ("0:x:10", "STOP = `x` is not a finite number"),
            ("-5:10:1", "START = -5 must be >= 0"),
            ("10:10:1", "STOP = 10 must be above START"),
            ("0:10:0", "STEP = 0 must be > 0"),
            ("0:1e9:1", "exceed the limit"),
            ("0:inf:1", "not a finite number"),
        ] {
            let e = parse_rpm_grid(bad).unwrap_err();
            assert!(e.contains(why), "{bad}: {e}");
        }
    }
}
