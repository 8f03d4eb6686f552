//! `rotorid balance`: correction masses, with their uncertainty (`rotorid::analysis::balance`;
//! method, conventions and formats in docs/balancing.md).
//!
//! Influence coefficients of several planes, sensors and speeds (multi-plane):
//!
//! - `rotorid balance --vectors vectors.csv --masses masses.csv --current RUN [--speeds
//!   1000,1200] [--planes A,B] [--method ls|minmax] [--limit SENSOR=VALUE ...] [--weight
//!   SENSOR=W ...] [--holes PLANE=N[@OFFSET_DEG] ...] [--radius PLANE=R ...] [--mass-set
//!   KG,KG] --out balance.json`: the influence coefficients fitted over every calibration
//!   run, the correction of run RUN by least squares or min-max, its standard deviations,
//!   the predicted residual, the condition number, the split into holes; a report on
//!   stderr, `balance.json` written atomically. `--raw RUN=FILE --scenario S.toml` adds
//!   the 1X vectors of raw records (as `rotorid onex` computes them).
//! - `--plan`: trial masses that change the response by `--fraction` (default 0.3) at the
//!   most sensitive sensor, from the influence estimate of `--masses` or, without one,
//!   from an identification summary (`rotorid balance SUMMARY.json --plan --speeds RPM
//!   --radius R`).
//!
//! Single plane (the forms `rotorid balance` had first, printed on stdout):
//!
//! - `rotorid balance SUMMARY.json --radius R [--rpm RPM]`: from the identified unbalance
//!   (m_u d, alpha) and its covariance: the mass at radius R that cancels it, its standard
//!   deviations, and the predicted residual (the estimate's error: the 1X amplitude is
//!   reduced by |U| / sqrt(var u_c + var u_s); with `--rpm`, the 1X amplitudes before and
//!   after at that speed).
//! - `rotorid balance --reference RUN1.csv --trial RUN2.csv --trial-mass M
//!   --trial-angle DEG --radius R [--trial-radius RT] [--rpm RPM] [--scenario S.toml]`:
//!   single-plane influence coefficients from the 1X vectors of x and z in a reference
//!   run and in a run with a known trial mass (least squares over both directions: the
//!   one-plane case of the multi-plane computation), for users who trust measurements
//!   more than models. The runs are response CSVs (`t,x,z,phi,phi_dot,phi_ddot`, as
//!   `rotorid simulate` writes them); without phi columns the shaft angle comes from the
//!   scenario's speed profile. With `--rpm`, only the samples within 1 % of that speed are
//!   used (a run-up); otherwise the whole record, which must then be at one speed.
//!
//!   Both print the correction and write it with `--out FILE.json`:
//!
//!   ```json
//!   {"method": "identified_unbalance" | "influence_coefficients",
//!    "mass_kg": 1.0e-4, "angle_deg": 225.0, "std_mass_kg": 9.7e-9, "std_angle_deg": 0.0048,
//!    "radius_m": 0.15, "angle_reference": "...", ...}
//!   ```
//!
//! Angles (alpha_deg, --trial-angle, masses, holes, the corrections) are shaft angles
//! measured from the keyphasor mark (phi = 0) in the direction of rotation.

use std::f64::consts::TAU;
use std::path::{Path, PathBuf};

use anyhow::{anyhow, bail, Context};
use rotorid::analysis::{
    balance_from_runs, balance_from_unbalance, one_x, response_per_unbalance, Probe, RunVectors,
    TrialMass,
};
use rotorid::model::{rad_per_s_to_rpm, rpm_to_rad_per_s};
use rotorid::SpeedProfile;
use serde::Serialize;

use crate::io::{open_input, FileMode, LoadScenario as _, Output, ResponseReader, ScenarioSpec};

use super::analyze::load_rotor;

mod multi;

/// The half-width of the speed band `--rpm` selects, relative to the speed.
const SPEED_BAND: f64 = 0.01;

/// Runs whose mean speeds differ by more than this (relative) are not at one speed.
const SAME_SPEED: f64 = 0.01;

/// Where every angle is measured from.
const ANGLE_REFERENCE: &str = "shaft angle in the frame of alpha_deg: from the keyphasor reference (phi = 0) in the direction of rotation";

const BALANCE_HELP: &str = "\
Angles: masses, holes, --trial-angle and the corrections' angles are shaft angles measured
from the keyphasor mark (phi = 0, the frame of alpha_deg) in the direction of rotation.
Place each correction mass at its angle on the rotor, at its radius.

Multi-plane (influence coefficients): vectors.csv has run,speed_rpm,sensor,re,im (or
amp,phase_deg with --phase lag|lead), re + i im meaning the 1X component is
Re((re + i im) e^{i phi}); masses.csv has run,plane,mass_kg,radius_m,angle_deg for the
calibration runs (mass 0 for the run as found). The coefficients are fitted over every
calibration run; run RUN (--current) is balanced by least squares or min-max; the report
goes to stderr and balance.json (--out) holds corrections, residual and influence with
their standard deviations (docs/balancing.md, field by field).

From an identification summary, the correction cancels the identified unbalance; its
standard deviations and the predicted residual come from the summary's covariance.
From two runs (influence coefficients), the correction is the least-squares fit over the
x and z 1X vectors; remove the trial mass before adding the correction.

Examples:
  rotorid balance --vectors vectors.csv --masses masses.csv --current asfound \\
      --holes disk1=12 --holes disk2=8@22.5 --out balance.json
  rotorid balance --vectors vectors.csv --masses masses.csv --current asfound \\
      --method minmax --limit B1X=25 --out balance.json
  rotorid balance --plan --vectors vectors.csv --masses old_masses.csv --current now
  rotorid balance summary.json --plan --speeds 3000 --radius 0.15
  rotorid balance summary.json --radius 0.15 --rpm 3000
  rotorid balance --reference run1.csv --trial run2.csv --trial-mass 0.0002 --trial-angle 200 \\
      --radius 0.15 --out balance.json";

/// Arguments of `rotorid balance`.
#[derive(Debug, clap::Args)]
#[command(after_long_help = BALANCE_HELP)]
pub struct BalanceArgs {
    /// An identification summary (its `rotor` and `covariance`): balance the identified
    /// unbalance, or (--plan) plan a trial mass from the identified rotor.
    #[arg(value_name = "SUMMARY.json", conflicts_with_all = ["reference", "trial", "scenario", "vectors", "raw"])]
    pub summary: Option<PathBuf>,

    /// Multi-plane: the 1X vectors (run,speed_rpm,sensor,re,im[,unit,re_std,im_std|std]
    /// or amp,phase_deg instead of re,im).
    #[arg(long, value_name = "vectors.csv")]
    pub vectors: Option<String>,

    /// Multi-plane: a run's 1X vectors from its raw record (probes and keyphasor, the
    /// --scenario's [acquisition]), as `rotorid onex` computes them. Repeat per run.
    #[arg(long, value_name = "RUN=FILE", requires = "scenario")]
    pub raw: Vec<String>,

    /// Multi-plane: the masses of the calibration runs (run,plane,mass_kg,radius_m,angle_deg).
    #[arg(long, value_name = "masses.csv")]
    pub masses: Option<String>,

    /// Multi-plane: the run to balance (a run of the vectors).
    #[arg(long, value_name = "RUN")]
    pub current: Option<String>,

    /// Only the vectors within 1 % of these speeds [rev/min] (--plan with a summary: the
    /// speeds to plan at).
    #[arg(long, value_name = "RPM,RPM", value_delimiter = ',')]
    pub speeds: Option<Vec<f64>>,

    /// The planes to correct (default: every plane of the masses).
    #[arg(long, value_name = "PLANE,PLANE", value_delimiter = ',')]
    pub planes: Option<Vec<String>>,

    /// ls: least squares over every sensor and speed; minmax: the smallest largest
    /// residual, within the --limit values.
    #[arg(long, value_enum, default_value_t = MethodArg::Ls)]
    pub method: MethodArg,

    /// Largest residual allowed at a sensor [its unit], every speed. Repeat per sensor.
    #[arg(long, value_name = "SENSOR=VALUE")]
    pub limit: Vec<String>,

    /// A sensor's weight in the correction (default 1): its residuals count W times.
    /// Repeat per sensor.
    #[arg(long, value_name = "SENSOR=W")]
    pub weight: Vec<String>,

    /// A plane's holes: N equally spaced, the first at OFFSET_DEG (default 0), or a list
    /// of angles [deg] (PLANE=0,40,80,...). The correction is split into them. Repeat per
    /// plane.
    #[arg(long, value_name = "PLANE=N[@OFFSET_DEG]")]
    pub holes: Vec<String>,

    /// The weights available for the splits [kg], comma-separated (default: any mass).
    #[arg(long, value_name = "KG,KG", value_delimiter = ',')]
    pub mass_set: Option<Vec<f64>>,

    /// Most weights of the mass set stacked in one hole.
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub per_hole: usize,

    /// Radius at which the correction mass is placed [m]: R for every plane (and the
    /// single-plane forms), or PLANE=R (repeat per plane). Multi-plane default: the radius
    /// of the plane's calibration masses.
    #[arg(long, value_name = "R|PLANE=R")]
    pub radius: Vec<String>,

    /// The phase convention of amp,phase_deg vectors: lag (re + i im = amp e^{-i phase},
    /// as most data collectors report it) or lead (amp e^{+i phase}).
    #[arg(long, value_enum)]
    pub phase: Option<PhaseArg>,

    /// The unit of the vectors when vectors.csv has no unit column or header unit.
    #[arg(long, value_name = "UNIT")]
    pub unit: Option<String>,

    /// Plan trial masses instead of a correction.
    #[arg(long)]
    pub plan: bool,

    /// With --plan: the fraction by which a trial changes the response at the most
    /// sensitive sensor.
    #[arg(long, value_name = "F", default_value_t = rotorid::analysis::balance::DEFAULT_FRACTION)]
    pub fraction: f64,

    /// Reference run: a response CSV (t,x,z[,phi,phi_dot,phi_ddot]) without trial mass.
    #[arg(long, value_name = "RUN1.csv", requires_all = ["trial", "trial_mass", "trial_angle"], conflicts_with_all = ["vectors", "raw", "masses", "plan"])]
    pub reference: Option<String>,

    /// Trial run: the same, with the trial mass added.
    #[arg(long, value_name = "RUN2.csv", requires = "reference")]
    pub trial: Option<String>,

    /// Trial mass [kg].
    #[arg(long, value_name = "KG", requires = "reference")]
    pub trial_mass: Option<f64>,

    /// Trial mass angle [deg]: shaft angle from the keyphasor reference in the direction
    /// of rotation (the frame of alpha_deg).
    #[arg(
        long,
        value_name = "DEG",
        allow_hyphen_values = true,
        requires = "reference"
    )]
    pub trial_angle: Option<f64>,

    /// Trial mass radius [m] (default: --radius).
    #[arg(long, value_name = "M", requires = "reference")]
    pub trial_radius: Option<f64>,

    /// Single plane: speed [rpm]: with runs, use only the samples within 1 % of it; with a
    /// summary, also report the 1X amplitudes before and after the correction at this
    /// speed.
    #[arg(long, value_name = "RPM")]
    pub rpm: Option<f64>,

    /// Scenario (table1 or FILE.toml): its speed profile gives the shaft angle of runs
    /// without phi columns; its [acquisition] reads --raw records.
    #[arg(long, value_name = "table1|FILE.toml")]
    pub scenario: Option<String>,

    /// Write the result as JSON to this file (written whole or not at all).
    #[arg(long, value_name = "FILE.json")]
    pub out: Option<PathBuf>,
}

/// `--method`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum MethodArg {
    /// Least squares.
    Ls,
    /// Min-max.
    Minmax,
}

/// `--phase`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum PhaseArg {
    /// re + i im = amp e^{-i phase}.
    Lag,
    /// re + i im = amp e^{+i phase}.
    Lead,
}

#[derive(Serialize)]
struct Directions {
    x: f64,
    z: f64,
}

#[derive(Serialize)]
struct UnbalanceJson {
    mud_kg_m: f64,
    alpha_deg: f64,
    std_mud_kg_m: Option<f64>,
    std_alpha_deg: Option<f64>,
}

#[derive(Serialize)]
struct AtSpeedJson {
    rpm: f64,
    before_um_pp: Directions,
    after_um_pp: Option<Directions>,
}

#[derive(Serialize)]
struct TrialJson {
    mass_kg: f64,
    angle_deg: f64,
    radius_m: f64,
}

#[derive(Serialize)]
struct InfluenceJson {
    amplitude_um_pp_per_g_mm: f64,
    phase_lag_deg: f64,
}

#[derive(Serialize)]
struct BalanceJson {
    method: &'static str,
    mass_kg: f64,
    angle_deg: f64,
    std_mass_kg: Option<f64>,
    std_angle_deg: Option<f64>,
    radius_m: f64,
    angle_reference: &'static str,
    /// Model: the identified unbalance.
    #[serde(skip_serializing_if = "Option::is_none")]
    unbalance: Option<UnbalanceJson>,
    /// Model: predicted residual unbalance sqrt(var u_c + var u_s) [kg m].
    #[serde(skip_serializing_if = "Option::is_none")]
    residual_unbalance_kg_m: Option<f64>,
    /// Predicted reduction of the 1X amplitude (model: every speed and probe).
    #[serde(skip_serializing_if = "Option::is_none")]
    predicted_reduction: Option<f64>,
    /// 1X amplitudes before and (predicted) after the correction.
    #[serde(skip_serializing_if = "Option::is_none")]
    at_speed: Option<AtSpeedJson>,
    /// Influence coefficients: the trial mass.
    #[serde(skip_serializing_if = "Option::is_none")]
    trial: Option<TrialJson>,
    /// Influence coefficients per direction.
    #[serde(skip_serializing_if = "Option::is_none")]
    influence: Option<[InfluenceJson; 2]>,
}

/// The angle \[rad\] as degrees in \[0, 360).
fn degrees(a: f64) -> f64 {
    let d = a.to_degrees().rem_euclid(360.0);
    if d >= 360.0 {
        0.0
    } else {
        d
    }
}

/// Run `rotorid balance`.
pub fn run(args: BalanceArgs) -> anyhow::Result<()> {
    if args.vectors.is_some() || !args.raw.is_empty() || args.masses.is_some() || args.plan {
        return multi::run(&args);
    }
    let radius = single_radius(&args.radius)?;
    if let Some(r) = args.rpm {
        if !(r.is_finite() && r > 0.0) {
            bail!("--rpm {r} is out of range: must be finite and > 0 (rev/min)");
        }
    }
    let result = match (&args.summary, &args.reference) {
        (Some(_), _) => from_summary(&args, radius.context(RADIUS_NEEDED)?)?,
        (None, Some(_)) => from_runs(&args, radius.context(RADIUS_NEEDED)?)?,
        (None, None) => bail!(
            "give an identification summary (rotorid balance SUMMARY.json --radius R), two runs \
             (--reference RUN1.csv --trial RUN2.csv --trial-mass KG --trial-angle DEG --radius R), \
             or 1X vectors and calibration masses (--vectors vectors.csv --masses masses.csv \
             --current RUN)"
        ),
    };
    // the file first: a reader of stdout that goes away ends the run at the print
    if let Some(path) = &args.out {
        write_json(path, &result)?;
    }
    print(&result)
}

const RADIUS_NEEDED: &str =
    "give --radius R: the radius at which the correction mass is placed [m]";

/// The radius of the single-plane forms: one bare number, when given.
fn single_radius(radius: &[String]) -> anyhow::Result<Option<f64>> {
    match radius {
        [] => Ok(None),
        [one] => {
            let r: f64 = one.trim().parse().map_err(|_| {
                anyhow!(
                    "--radius {one:?} is not a number: the single-plane forms take one radius [m]"
                )
            })?;
            if !(r.is_finite() && r > 0.0) {
                bail!("--radius {r} is out of range: must be finite and > 0 (m)");
            }
            Ok(Some(r))
        }
        _ => bail!(
            "--radius is given {} times: the single-plane forms take one radius [m]",
            radius.len()
        ),
    }
}

/// Write `value` as pretty JSON to `path`, whole or not at all.
pub(crate) fn write_json(path: &Path, value: &impl Serialize) -> anyhow::Result<()> {
    let mut out = Output::create(&path.display().to_string(), FileMode::Atomic)?;
    serde_json::to_writer_pretty(&mut out, value)
        .with_context(|| format!("cannot write {}", path.display()))?;
    std::io::Write::write_all(&mut out, b"\n")?;
    out.commit()
}

fn print(r: &BalanceJson) -> anyhow::Result<()> {
    let std = match (r.std_mass_kg, r.std_angle_deg) {
        (Some(m), Some(a)) => format!(" (std {m:.2e} kg, {a:.3} deg)"),
        (Some(m), None) => format!(" (std {m:.2e} kg)"),
        _ => String::new(),
    };
    outln!(
        "correction: {:.4e} kg ({:.4} g) at {:.2} deg, radius {} m{std}",
        r.mass_kg,
        r.mass_kg * 1e3,
        r.angle_deg,
        r.radius_m
    )?;
    outln!("angles: {ANGLE_REFERENCE}")?;
    if let (Some(u), Some(red)) = (r.residual_unbalance_kg_m, r.predicted_reduction) {
        outln!("predicted residual unbalance {u:.3e} kg m: 1X amplitude reduced {red:.0}x")?;
    }
    if let Some(s) = &r.at_speed {
        match &s.after_um_pp {
            Some(a) => {
                outln!(
                "at {:.1} rpm: 1X x {:.4} -> {:.4} um pk-pk, z {:.4} -> {:.4} um pk-pk (predicted)",
                s.rpm, s.before_um_pp.x, a.x, s.before_um_pp.z, a.z
            )?
            }
            None => outln!(
                "at {:.1} rpm: 1X x {:.4}, z {:.4} um pk-pk before the correction",
                s.rpm,
                s.before_um_pp.x,
                s.before_um_pp.z
            )?,
        }
    }
    Ok(())
}

fn from_summary(args: &BalanceArgs, radius: f64) -> anyhow::Result<BalanceJson> {
    let (rotor, source) = load_rotor(args.summary.as_deref(), None, "balance")?;
    let p = rotor.params;
    let cov = rotor.covariance.as_ref();
    let b = balance_from_unbalance(&p, cov, radius).with_context(|| source.clone())?;
    // the unbalance itself: the correction at a radius of 1 m carries m_u d and its std
    let u = balance_from_unbalance(&p, cov, 1.0)?.correction;
    let at_speed = match args.rpm {
        None => None,
        Some(rpm) => {
            let w = rpm_to_rad_per_s(rpm);
            let mud = p.unbalance.mud();
            let amp = |probe: Probe, u: f64| -> anyhow::Result<f64> {
                let h = response_per_unbalance(&p, w, probe)?.ok_or_else(|| {
                    anyhow!("no bounded response at {rpm} rpm (undamped resonance)")
                })?;
                Ok(2e6 * h.norm() * u)
            };
            Some(AtSpeedJson {
                rpm,
                before_um_pp: Directions {
                    x: amp(Probe::X, mud)?,
                    z: amp(Probe::Z, mud)?,
                },
                after_um_pp: match b.residual_unbalance {
                    Some(r) => Some(Directions {
                        x: amp(Probe::X, r)?,
                        z: amp(Probe::Z, r)?,
                    }),
                    None => None,
                },
            })
        }
    };
    let c = b.correction;
    Ok(BalanceJson {
        method: "identified_unbalance",
        mass_kg: c.mass,
        angle_deg: degrees(c.angle),
        std_mass_kg: c.std_mass,
        std_angle_deg: c.std_angle.map(f64::to_degrees),
        radius_m: c.radius,
        angle_reference: ANGLE_REFERENCE,
        unbalance: Some(UnbalanceJson {
            mud_kg_m: p.unbalance.mud(),
            alpha_deg: degrees(p.unbalance.alpha),
            std_mud_kg_m: u.std_mass,
            std_alpha_deg: u.std_angle.map(f64::to_degrees),
        }),
        residual_unbalance_kg_m: b.residual_unbalance,
        predicted_reduction: b.reduction,
        at_speed,
        trial: None,
        influence: None,
    })
}

/// One run's 1X vectors and its mean speed \[rad/s\].
fn run_vectors(
    file: &str,
    speed: Option<&SpeedProfile>,
    rpm: Option<f64>,
) -> anyhow::Result<(RunVectors, f64)> {
    let (name, input) = open_input(file)?;
    let mut r = ResponseReader::new(&name, input)?;
    r.print_conversions();
    if !r.has_phi() && speed.is_none() {
        bail!(
            "{name} has no phi, phi_dot, phi_ddot columns: give --scenario with a [speed] section \
             for the shaft angle"
        );
    }
    let (mut x, mut z, mut phi, mut w) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    while let Some(row) = r.next_row()? {
        let s = match (row.speed, speed) {
            (Some(s), _) => s,
            (None, Some(p)) => p.at(row.t),
            (None, None) => unreachable!("checked above"),
        };
        if let Some(rpm) = rpm {
            let target = rpm_to_rad_per_s(rpm);
            if (s.omega - target).abs() > SPEED_BAND * target {
                continue;
            }
        }
        x.push(row.x);
        z.push(row.z);
        phi.push(s.phi);
        w.push(s.omega);
    }
    let within = rpm.map_or(String::new(), |r| format!(" within 1 % of {r} rpm"));
    if x.len() < 4 {
        bail!("{name}: {} samples{within}: at least 4 are needed", x.len());
    }
    let (lo, hi) = phi
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &p| {
            (a.min(p), b.max(p))
        });
    if hi - lo < TAU && rpm.is_some() {
        bail!(
            "{name}: the shaft turns {:.2} revolutions{within}: at least one is needed for a 1X vector",
            (hi - lo) / TAU
        );
    }
    let vx = one_x(&x, &phi)?.ok_or_else(|| {
        anyhow!("{name}: the samples{within} do not determine a 1X vector (does the shaft turn?)")
    })?;
    let vz = one_x(&z, &phi)?.ok_or_else(|| {
        anyhow!("{name}: the samples{within} do not determine a 1X vector (does the shaft turn?)")
    })?;
    let mean = w.iter().sum::<f64>() / w.len() as f64;
    Ok((RunVectors { x: vx, z: vz }, mean))
}

fn from_runs(args: &BalanceArgs, radius: f64) -> anyhow::Result<BalanceJson> {
    let (Some(reference), Some(trial_file), Some(mass), Some(angle)) = (
        args.reference.as_deref(),
        args.trial.as_deref(),
        args.trial_mass,
        args.trial_angle,
    ) else {
        bail!("influence coefficients need --reference, --trial, --trial-mass and --trial-angle");
    };
    let speed = match &args.scenario {
        Some(s) => ScenarioSpec::load(s)?.identification()?.speed,
        None => None,
    };
    let (v0, w0) = run_vectors(reference, speed.as_ref(), args.rpm)?;
    let (v1, w1) = run_vectors(trial_file, speed.as_ref(), args.rpm)?;
    if (w0 - w1).abs() > SAME_SPEED * w0.abs().max(w1.abs()) {
        bail!(
            "the reference run turns at {:.1} rpm on average, the trial run at {:.1} rpm: \
             influence coefficients need both at one speed (select it with --rpm)",
            rad_per_s_to_rpm(w0),
            rad_per_s_to_rpm(w1)
        );
    }
    let trial = TrialMass {
        mass,
        radius: args.trial_radius.unwrap_or(radius),
        angle: angle.to_radians(),
    };
    let b = balance_from_runs(&v0, &v1, &trial, radius)?.ok_or_else(|| {
        anyhow!(
            "the trial mass changed neither 1X vector: no influence coefficient (use a larger trial mass)"
        )
    })?;
    let c = b.correction;
    let before = b.before.map(|v| 2e6 * v.norm());
    let after = b.residual.map(|v| 2e6 * v.norm());
    let influence = b.influence.map(|h| InfluenceJson {
        // [m / (kg m)] peak -> um pk-pk per g mm (1 g mm = 1e-6 kg m)
        amplitude_um_pp_per_g_mm: 2.0 * h.norm(),
        phase_lag_deg: degrees(-h.arg()),
    });
    Ok(BalanceJson {
        method: "influence_coefficients",
        mass_kg: c.mass,
        angle_deg: degrees(c.angle),
        std_mass_kg: c.std_mass,
        std_angle_deg: c.std_angle.map(f64::to_degrees),
        radius_m: c.radius,
        angle_reference: ANGLE_REFERENCE,
        unbalance: None,
        residual_unbalance_kg_m: None,
        predicted_reduction: None,
        at_speed: Some(AtSpeedJson {
            rpm: rad_per_s_to_rpm(0.5 * (w0 + w1)),
            before_um_pp: Directions {
                x: before[0],
                z: before[1],
            },
            after_um_pp: Some(Directions {
                x: after[0],
                z: after[1],
            }),
        }),
        trial: Some(TrialJson {
            mass_kg: trial.mass,
            angle_deg: angle,
            radius_m: trial.radius,
        }),
        influence: Some(influence),
    })
}
