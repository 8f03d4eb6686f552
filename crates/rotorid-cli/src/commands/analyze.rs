//! `rotorid analyze (SUMMARY.json | --scenario S.toml) --out DIR [--rpm 0:6000:10]`:
//! from identified (or stated) rotor parameters to the numbers an engineer decides on,
//! with the uncertainty of the identification carried through (`rotorid::analysis`).
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
//!   "rotor": {"m": .., "cx": .., "kx": .., "cz": .., "kz": .., "a": .., "mud": .., "alpha": ..},
//!   "rotor_std": {"m": .., ...} | null,          // null entries: undetermined
//!   "speed_range_rpm": {"start": 0, "stop": 6000, "step": 10},
//!   "critical_speeds": [{"rpm": 2519.9, "whirl": "backward", "std_rpm": 0.3, "mode": 0,
//!                        "frequency_hz": 42.0, "damping_ratio": .., "log_dec": ..}],
//!   "campbell": {"rpm": [...], "modes": [{"whirl": "backward", "frequency_hz": [...],
//!                "log_dec": [...], "damping_ratio": [...], "whirl_by_speed": [...]}]},
//!   "stability": {"stable": true, "min_log_dec": .., "min_log_dec_rpm": .., "min_log_dec_mode": 1,
//!                 "min_damping_ratio": .., "threshold_rpm": null},
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

use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context};
use rotorid::analysis::{
    campbell, critical_speeds, stability, unbalance_response, Campbell, CovarianceParameter,
    CriticalSpeed, ParameterCovariance, Probe, Stability, UnbalanceResponse, Whirl,
};
use rotorid::model::{rad_per_s_to_rpm, rpm_to_rad_per_s};
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
are propagated from the covariance) or a scenario (its rotor; no uncertainty).

Conventions: the shaft turns from +z (up) toward +x (horizontal), the sense in which the
unbalance force turns; forward whirl is whirl in that sense. Probe angles are measured from
+z (vertical) in the direction of rotation: x is at 90 deg, z at 0 deg. Phase lag is the
shaft angle from the keyphasor reference (phi = 0) to the positive peak of the signal.

Examples:
  rotorid analyze summary.json --out analysis
  rotorid analyze --scenario table1 --out analysis --rpm 0:4000:5 --probe 45";

/// Arguments of `rotorid analyze`.
#[derive(Debug, clap::Args)]
#[command(after_long_help = ANALYZE_HELP)]
pub struct AnalyzeArgs {
    /// An identification summary written by `rotorid identify --summary` (its `rotor` and
    /// `covariance` fields are read).
    #[arg(
        value_name = "SUMMARY.json",
        required_unless_present = "scenario",
        conflicts_with = "scenario"
    )]
    pub summary: Option<PathBuf>,

    /// Analyse the rotor of a scenario instead: `table1` or a TOML scenario file (every
    /// rotor key needed; no uncertainty).
    #[arg(long, value_name = "table1|FILE.toml")]
    pub scenario: Option<String>,

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

    /// Amplitude unit of the figures: um or mil peak-to-peak (analysis.json is in um).
    #[arg(long, value_enum, default_value_t = AmplitudeUnit::Um)]
    pub unit: AmplitudeUnit,
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

/// The rotor to analyse: from a summary (with its covariance) or a scenario; and a
/// description of where it came from.
pub fn load_rotor(
    summary: Option<&Path>,
    scenario: Option<&str>,
    who: &str,
) -> anyhow::Result<(IdentifiedRotor, String)> {
    match (summary, scenario) {
        (Some(p), _) => Ok((IdentifiedRotor::read(p)?, p.display().to_string())),
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
            let params = RotorParams {
                coupling: None,
                m: need(t.m, "m", "kg")?,
                cx: need(t.cx, "cx", "N s/m")?,
                cz: need(t.cz, "cz", "N s/m")?,
                kx: need(t.kx, "kx", "N/m")?,
                kz: need(t.kz, "kz", "N/m")?,
                a: id.a,
                unbalance: Unbalance {
                    m_u: id.m_u,
                    d: id.d,
                    alpha: id.alpha,
                },
            };
            Ok((
                IdentifiedRotor {
                    params,
                    covariance: None,
                },
                format!("scenario {}", spec.origin()),
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
    rotor: RotorJson,
    rotor_std: Option<RotorStdJson>,
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
    response: UnbalanceResponse,
    names: Vec<String>,
}

fn rotor_std(p: &RotorParams, c: &ParameterCovariance) -> RotorStdJson {
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

fn compute(args: &AnalyzeArgs, rotor: IdentifiedRotor) -> anyhow::Result<Results> {
    let speeds: Vec<f64> = args
        .rpm
        .speeds_rpm()
        .into_iter()
        .map(rpm_to_rad_per_s)
        .collect();
    let p = rotor.params;
    let cov = rotor.covariance.as_ref();
    let camp = campbell(&p, &speeds)?;
    let critical = if speeds.len() >= 2 {
        critical_speeds(&p, cov, &speeds)?
    } else {
        Vec::new()
    };
    let stab = stability(&p, &speeds)?;
    let (pr, names) = probes(&args.probes)?;
    let response = unbalance_response(&p, cov, &response_grid(&speeds, &critical), &pr)?;
    Ok(Results {
        params: p,
        covariance: rotor.covariance,
        campbell: camp,
        critical,
        stability: stab,
        response,
        names,
    })
}

fn whirl_name(w: Option<Whirl>) -> &'static str {
    w.map_or("no whirl direction", Whirl::name)
}

/// Run `rotorid analyze`.
pub fn run(args: AnalyzeArgs) -> anyhow::Result<()> {
    let (rotor, source) = load_rotor(args.summary.as_deref(), args.scenario.as_deref(), "analyze")?;
    let r = compute(&args, rotor)?;
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
    let path = args.out.join("analysis.json");
    let mut out = Output::create(&path.display().to_string(), FileMode::Atomic)?;
    serde_json::to_writer_pretty(&mut out, &json)
        .with_context(|| format!("cannot write {}", path.display()))?;
    std::io::Write::write_all(&mut out, b"\n")?;
    out.commit()?;
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
    let g = args.rpm;
    outln!("critical speeds ({}-{} rpm):", g.start, g.stop)?;
    if r.critical.is_empty() {
        outln!("  none")?;
    }
    for (n, c) in r.critical.iter().enumerate() {
        outln!(
            "  {}: {}  {}  (log dec {})",
            n + 1,
            with_std(c.rpm(), c.std_rpm(), "rpm"),
            whirl_name(c.whirl()),
            c.at.log_dec.map_or("-".into(), |d| format!("{d:.4}"))
        )?;
    }
    match (r.stability.threshold, r.stability.min_log_dec) {
        (None, Some(d)) => outln!(
            "stability: stable over the range; minimum log decrement {d:.4} ({} mode at {:.0} rpm)",
            ["lower", "higher"][r.stability.min_log_dec_mode.unwrap_or(0).min(1)],
            rad_per_s_to_rpm(r.stability.min_log_dec_speed.unwrap_or(0.0))
        )?,
        (None, None) => outln!("stability: stable over the range")?,
        (Some(t), _) => outln!(
            "stability: UNSTABLE from {:.1} rpm (a mode's log decrement is negative; the model is stable whenever cx, cz > 0)",
            rad_per_s_to_rpm(t)
        )?,
    }
    outln!(
        "wrote {}: analysis.json, {}, report.html",
        args.out.display(),
        figures.join(", ")
    )?;
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
    let per_m = args.unit.per_metre_peak();
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
    let unit = args.unit.label().to_string();
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
        rotor: RotorJson {
            m: p.m,
            cx: p.cx,
            kx: p.kx,
            cz: p.cz,
            kz: p.kz,
            a: p.a,
            mud: p.unbalance.mud(),
            alpha: p.unbalance.alpha,
        },
        rotor_std: r.covariance.as_ref().map(|c| rotor_std(p, c)),
        speed_range_rpm: args.rpm,
        critical_speeds: r
            .critical
            .iter()
            .map(|c| CriticalJson {
                rpm: c.rpm(),
                whirl: c.whirl(),
                std_rpm: c.std_rpm(),
                mode: c.mode,
                frequency_hz: c.at.frequency_hz(),
                damping_ratio: c.at.damping_ratio,
                log_dec: c.at.log_dec,
            })
            .collect(),
        campbell: CampbellJson {
            rpm: r
                .campbell
                .speeds
                .iter()
                .map(|&w| rad_per_s_to_rpm(w))
                .collect(),
            modes: (0..2)
                .map(|i| ModeJson {
                    whirl: r.campbell.whirl(i),
                    frequency_hz: r.campbell.mode(i).map(|m| m.frequency_hz()).collect(),
                    log_dec: r.campbell.mode(i).map(|m| m.log_dec).collect(),
                    damping_ratio: r.campbell.mode(i).map(|m| m.damping_ratio).collect(),
                    whirl_by_speed: r.campbell.mode(i).map(|m| m.whirl).collect(),
                })
                .collect(),
        },
        stability: StabilityJson {
            stable: r.stability.is_stable(),
            min_log_dec: r.stability.min_log_dec,
            min_log_dec_rpm: r.stability.min_log_dec_speed.map(rad_per_s_to_rpm),
            min_log_dec_mode: r.stability.min_log_dec_mode,
            min_damping_ratio: r.stability.min_damping_ratio,
            threshold_rpm: r.stability.threshold.map(rad_per_s_to_rpm),
        },
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
