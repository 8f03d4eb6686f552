//! `rotorid analyze` of a finite-element rotor: `rotorid analyze --scenario
//! fe.toml --out DIR` (the scenario's values, no uncertainty) or `rotorid analyze
//! SUMMARY.json --scenario fe.toml --out DIR` (a finite-element identification's values on
//! its scenario's matrices, with standard deviations from its covariance;
//! [`crate::io::fe_summary`]). The computation is `rotorid::analysis::fe_analysis`.
//!
//! `analysis.json` keeps the 2-DOF layout where it applies (the parent module's doc), with
//! `model` = `"finite_element"`:
//!
//! ```json
//! {
//!   "format_version": 1, "generator": "rotorid analyze 0.1.0", "source": "s.json",
//!   "scenario": "fe.toml", "model": "finite_element", "modes": 6,
//!   "rotor": {"bearings": [{"node": 0, "kxx": .., "kxy": .., "kyx": .., "kyy": ..,
//!                           "cxx": .., "cxy": .., "cyx": .., "cyy": ..}],
//!             "unbalances": [{"node": 3, "mud": .., "alpha": ..}]},        // SI: N/m, N s/m, kg m, rad
//!   "rotor_std": {same layout, standard deviations: 0 known, null undetermined} | null,
//!   "speed_range_rpm": {"start": 0, "stop": 6000, "step": 10},
//!   "critical_speeds": [{"rpm": .., "whirl": "forward", "std_rpm": .., "mode": 0,
//!                        "frequency_hz": .., "damping_ratio": .., "log_dec": .., "log_dec_std": ..}],
//!   "campbell": {"rpm": [...], "modes": [{"whirl": .., "frequency_hz": [...], "log_dec": [...],
//!                "damping_ratio": [...], "whirl_by_speed": [...]}, ...]},   // one per followed mode
//!   "stability": {... as for the 2-DOF models; mode indices are the followed modes'},
//!   "unbalances": [{"unbalance": "unbalance0", "node": 3, "mud_kg_m": .., "mud_std_kg_m": ..,
//!                   "angle_deg": .., "angle_std_deg": .., "correction_angle_deg": ..}],
//!   "figures": ["campbell.png", "campbell.svg"]
//! }
//! ```
//!
//! Modes are followed across speeds from the lowest `--modes` at the first speed
//! (`rotorid::analysis` finite_element module): `mode` j is the j-th lowest at the start of
//! the range. The whirl is that of the node with the largest orbit, in the matrices' frame
//! (forward: from +x towards +y, the shaft's rotation). Angles are from +x towards +y at
//! phi = 0, in [0, 360); the correction (a mass at the same m_u d) goes 180 deg opposite.
//! No unbalance response, Bode or polar plot, and no report.html yet for a finite-element
//! rotor: `--probe` and `--unit` (the amplitude unit of those figures) are refused by name
//! rather than ignored.

use anyhow::{bail, Context as _};
use rotorid::analysis::{
    fe_analysis, fe_stability_margin, fe_unbalances, FeAnalysis, FeCovariance, StabilityMargin,
};
use rotorid::model::finite_element::{Bearing, FeParameter, FiniteElementRotor};
use rotorid::model::{rad_per_s_to_rpm, rpm_to_rad_per_s};
use rotorid::SpeedProfile;
use serde::Serialize;

use super::{
    critical_json, instability_text, mode_json, print_critical_speeds, print_margin,
    print_stability, stability_json, whirl_name, write_analysis_json, AnalyzeArgs, CampbellJson,
    CriticalJson, RpmGrid, StabilityJson, ANALYSIS_FORMAT_VERSION,
};
use crate::io::fe_summary::{is_finite_element_summary, IdentifiedFe};
use crate::io::finite_element::finite_element_of;
use crate::io::{LoadScenario as _, ScenarioSpec, SimulationOverrides};
use crate::plot::campbell::{with_std, CampbellMode, CampbellPlot, CriticalMark};
use crate::plot::canvas::save_drawing;
use crate::plot::DEFAULT_SIZE;

/// Modes followed when `--modes` is not given (fewer when the rotor has fewer).
const DEFAULT_MODES: usize = 6;

/// A finite-element rotor to analyse.
pub(super) struct FeInput {
    rotor: FiniteElementRotor,
    covariance: Option<FeCovariance>,
    /// The summary, or the scenario when analysing the scenario's values.
    source: String,
    scenario: String,
    /// The scenario's constant speed \[rad/s\], if it has one.
    scenario_speed: Option<f64>,
}

/// The finite-element rotor `args` name, if they name one: a finite-element summary (which
/// needs `--scenario`) or a finite-element scenario alone; `None` for a 2-DOF input.
pub(super) fn input(args: &AnalyzeArgs) -> anyhow::Result<Option<FeInput>> {
    let spec = match (&args.summary, &args.scenario) {
        (Some(summary), None) => {
            if is_finite_element_summary(summary)? {
                bail!(
                    "{} is a finite-element summary (model \"finite_element\"): give the \
                     scenario it was identified with, --scenario fe.toml, whose matrices it needs",
                    summary.display()
                );
            }
            return Ok(None);
        }
        (Some(summary), Some(s)) => {
            if !is_finite_element_summary(summary)? {
                return Ok(None);
            }
            ScenarioSpec::load(s)?
        }
        (None, Some(s)) => {
            let spec = ScenarioSpec::load(s)?;
            if spec.finite_element().is_none() {
                return Ok(None);
            }
            spec
        }
        (None, None) => return Ok(None),
    };
    if let Some(unit) = args.unit {
        bail!(
            "--unit {}: the analysis of a finite-element rotor has no amplitude figure or \
             amplitude to convert (Campbell diagram, critical speeds, stability and unbalances \
             only; see rotorid predict for responses): drop --unit",
            unit.name()
        );
    }
    if !args.probes.is_empty() {
        bail!(
            "--probe: the unbalance response of a finite-element rotor is not computed by \
             analyze yet (its probes are degrees of freedom: see rotorid predict)"
        );
    }
    let rotor = finite_element_of(&spec)?;
    let scenario_speed = match spec.fe_simulation(&SimulationOverrides::default()) {
        Ok((SpeedProfile::Constant { omega, .. }, _)) => Some(omega),
        _ => None,
    };
    let scenario = spec.origin().to_owned();
    Ok(Some(match &args.summary {
        Some(summary) => {
            let id = IdentifiedFe::read(summary, rotor)?;
            FeInput {
                rotor: id.rotor,
                covariance: id.covariance,
                source: summary.display().to_string(),
                scenario,
                scenario_speed,
            }
        }
        None => FeInput {
            rotor,
            covariance: None,
            source: format!("scenario {scenario}"),
            scenario,
            scenario_speed,
        },
    }))
}

#[derive(Serialize)]
struct BearingJson<T> {
    node: u32,
    kxx: T,
    kxy: T,
    kyx: T,
    kyy: T,
    cxx: T,
    cxy: T,
    cyx: T,
    cyy: T,
}

#[derive(Serialize)]
struct FeUnbalanceJson<T> {
    node: u32,
    mud: T,
    alpha: T,
}

#[derive(Serialize)]
struct FeRotorJson<T> {
    bearings: Vec<BearingJson<T>>,
    unbalances: Vec<FeUnbalanceJson<T>>,
}

#[derive(Serialize)]
struct UnbalanceJson {
    unbalance: String,
    node: u32,
    mud_kg_m: f64,
    mud_std_kg_m: Option<f64>,
    angle_deg: f64,
    angle_std_deg: Option<f64>,
    correction_angle_deg: f64,
}

#[derive(Serialize)]
struct FeAnalysisJson {
    format_version: u32,
    generator: String,
    source: String,
    scenario: String,
    model: &'static str,
    modes: usize,
    rotor: FeRotorJson<f64>,
    rotor_std: Option<FeRotorJson<Option<f64>>>,
    speed_range_rpm: RpmGrid,
    critical_speeds: Vec<CriticalJson>,
    campbell: CampbellJson,
    stability: StabilityJson,
    unbalances: Vec<UnbalanceJson>,
    figures: Vec<String>,
}

/// The rotor's values (`get` = the value) or standard deviations, in the summary's layout.
fn rotor_json<T>(r: &FiniteElementRotor, get: impl Fn(FeParameter) -> T) -> FeRotorJson<T> {
    use rotorid::model::finite_element::BearingCoefficient as B;
    let b = |index: usize, b: &Bearing| {
        let c = |coefficient| get(FeParameter::Bearing { index, coefficient });
        BearingJson {
            node: b.node,
            kxx: c(B::Kxx),
            kxy: c(B::Kxy),
            kyx: c(B::Kyx),
            kyy: c(B::Kyy),
            cxx: c(B::Cxx),
            cxy: c(B::Cxy),
            cyx: c(B::Cyx),
            cyy: c(B::Cyy),
        }
    };
    FeRotorJson {
        bearings: r
            .bearings
            .iter()
            .enumerate()
            .map(|(i, x)| b(i, x))
            .collect(),
        unbalances: r
            .unbalances
            .iter()
            .enumerate()
            .map(|(index, u)| FeUnbalanceJson {
                node: u.node,
                mud: get(FeParameter::Mud { index }),
                alpha: get(FeParameter::Alpha { index }),
            })
            .collect(),
    }
}

/// An angle \[rad\] in degrees in [0, 360).
fn degrees(a: f64) -> f64 {
    let d = a.to_degrees().rem_euclid(360.0);
    if d >= 360.0 {
        0.0
    } else {
        d
    }
}

/// Run `rotorid analyze` on a finite-element rotor.
pub(super) fn run(args: &AnalyzeArgs, fe: FeInput) -> anyhow::Result<()> {
    let n = fe.rotor.matrices.n();
    let modes = match args.modes {
        Some(m) if m == 0 || m > n => {
            bail!("--modes {m} is out of range: must be 1 ..= {n} (the rotor's degrees of freedom)")
        }
        Some(m) => m,
        None => DEFAULT_MODES.min(n),
    };
    let speeds = args.rpm.speeds_rad_per_s();
    let cov = fe.covariance.as_ref();
    let a = fe_analysis(&fe.rotor, cov, &speeds, modes)?;
    let operating = match (args.operating_rpm, fe.scenario_speed) {
        (Some(rpm), _) => Some((rpm_to_rad_per_s(rpm), "given")),
        (None, Some(w)) => Some((w, "scenario")),
        (None, None) => None,
    };
    let operating: Option<(StabilityMargin, &'static str)> = operating
        .map(|(w, src)| fe_stability_margin(&fe.rotor, cov, w, modes).map(|m| (m, src)))
        .transpose()?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create output directory {}", args.out.display()))?;
    let figures = write_campbell(args, &a, &fe.source)?;
    let unbalances = fe_unbalances(&fe.rotor, cov);
    let json = FeAnalysisJson {
        format_version: ANALYSIS_FORMAT_VERSION,
        generator: format!("rotorid analyze {}", env!("CARGO_PKG_VERSION")),
        source: fe.source.clone(),
        scenario: fe.scenario.clone(),
        model: "finite_element",
        modes,
        rotor: rotor_json(&fe.rotor, |p| p.get(&fe.rotor).unwrap_or(f64::NAN)),
        rotor_std: cov.map(|c| rotor_json(&fe.rotor, |p| c.std(p))),
        speed_range_rpm: args.rpm,
        critical_speeds: a.critical.iter().map(critical_json).collect(),
        campbell: CampbellJson {
            rpm: speeds.iter().map(|&w| rad_per_s_to_rpm(w)).collect(),
            modes: (0..a.campbell.count())
                .map(|j| mode_json(a.campbell.mode(j), a.campbell.whirl(j)))
                .collect(),
        },
        stability: stability_json(&a.stability, operating.as_ref()),
        unbalances: unbalances
            .iter()
            .map(|u| UnbalanceJson {
                unbalance: format!("unbalance{}", u.index),
                node: u.node,
                mud_kg_m: u.mud,
                mud_std_kg_m: u.mud_std,
                angle_deg: degrees(u.alpha),
                angle_std_deg: u.alpha_std.map(f64::to_degrees),
                correction_angle_deg: degrees(u.alpha + std::f64::consts::PI),
            })
            .collect(),
        figures: figures.clone(),
    };
    write_analysis_json(&args.out, &json)?;

    let uncertainty = if cov.is_some() {
        "with standard deviations from the covariance"
    } else {
        "no covariance: no standard deviations"
    };
    outln!(
        "finite-element rotor from {} on {} ({} degrees of freedom, lowest {modes} modes \
         followed; {uncertainty})",
        fe.source,
        fe.scenario,
        n
    )?;
    print_critical_speeds(args.rpm, &a.critical, |c| format!("  mode {}", c.mode))?;
    let name = |j: usize| format!("mode {j}");
    print_stability(
        &a.stability,
        &name,
        &instability_text(&a.stability, &name, true),
    )?;
    if let Some((m, src)) = &operating {
        let which = format!(
            "mode {} of the lowest {modes}, {}",
            m.mode,
            whirl_name(m.at.whirl)
        );
        print_margin(m, src, &which)?;
    }
    for u in &unbalances {
        let deg = |s: Option<f64>| s.map(f64::to_degrees);
        outln!(
            "unbalance{} at node {}: m_u d = {} kg m at {} (from +x towards +y; correct with \
             the same m_u d at {:.2} deg)",
            u.index,
            u.node,
            with_sig(u.mud, u.mud_std),
            with_std(degrees(u.alpha), deg(u.alpha_std), "deg"),
            degrees(u.alpha + std::f64::consts::PI)
        )?;
    }
    outln!(
        "wrote {}: analysis.json, {} (no unbalance response or report.html for a \
         finite-element rotor yet)",
        args.out.display(),
        figures.join(", ")
    )?;
    Ok(())
}

/// `v` (4 significant digits) with its standard deviation.
fn with_sig(v: f64, std: Option<f64>) -> String {
    match std {
        Some(s) => format!("{v:.4e} \u{b1} {s:.2e}"),
        None => format!("{v:.4e}"),
    }
}

fn write_campbell(args: &AnalyzeArgs, a: &FeAnalysis, source: &str) -> anyhow::Result<Vec<String>> {
    let name = std::path::Path::new(source)
        .file_name()
        .map_or_else(|| source.to_owned(), |f| f.to_string_lossy().into_owned());
    let c = &a.campbell;
    let plot = CampbellPlot {
        title: format!("Campbell diagram \u{2014} {name}"),
        rpm: c.speeds.iter().map(|&w| rad_per_s_to_rpm(w)).collect(),
        modes: (0..c.count())
            .map(|j| CampbellMode {
                frequency_hz: c.mode(j).map(|m| m.frequency_hz()).collect(),
                log_dec: c.mode(j).map(|m| m.log_dec).collect(),
                whirl: c.mode(j).map(|m| m.whirl).collect(),
            })
            .collect(),
        critical: a
            .critical
            .iter()
            .map(|c| CriticalMark {
                rpm: c.rpm(),
                std_rpm: c.std_rpm(),
                whirl: c.whirl(),
            })
            .collect(),
    };
    let mut written = Vec::new();
    for ext in ["png", "svg"] {
        let name = format!("campbell.{ext}");
        save_drawing(&plot, DEFAULT_SIZE, &args.out.join(&name))?;
        written.push(name);
    }
    Ok(written)
}
