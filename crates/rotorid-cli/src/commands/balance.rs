//! `rotorid balance`: the correction mass for single-plane balancing, two ways
//! (`rotorid::analysis`, balance module):
//!
//! - `rotorid balance SUMMARY.json --radius R [--rpm RPM]`: from the identified unbalance
//!   (m_u d, alpha) and its covariance: the mass at radius R that cancels it, its standard
//!   deviations, and the predicted residual (the estimate's error: the 1X amplitude is
//!   reduced by |U| / sqrt(var u_c + var u_s); with `--rpm`, the 1X amplitudes before and
//!   after at that speed).
//! - `rotorid balance --reference RUN1.csv --trial RUN2.csv --trial-mass M
//!   --trial-angle DEG --radius R [--trial-radius RT] [--rpm RPM] [--scenario S.toml]`:
//!   single-plane influence coefficients from the 1X vectors of x and z in a reference
//!   run and in a run with a known trial mass (least squares over both directions), for
//!   users who trust measurements more than models. The runs are response CSVs
//!   (`t,x,z,phi,phi_dot,phi_ddot`, as `rotorid simulate` writes them); without phi
//!   columns the shaft angle comes from the scenario's speed profile. With `--rpm`, only
//!   the samples within 1 % of that speed are used (a run-up); otherwise the whole record,
//!   which must then be at one speed.
//!
//! Prints the correction and writes it with `--out FILE.json`:
//!
//! ```json
//! {"method": "identified_unbalance" | "influence_coefficients",
//!  "mass_kg": 1.0e-4, "angle_deg": 225.0, "std_mass_kg": 9.7e-9, "std_angle_deg": 0.0048,
//!  "radius_m": 0.15, "angle_reference": "...", ...}
//! ```
//!
//! Angles (alpha_deg, --trial-angle, the correction's angle) are shaft angles in the frame
//! of `alpha_deg`: measured from the keyphasor reference (phi = 0) in the direction of
//! rotation.

use std::f64::consts::TAU;
use std::path::PathBuf;

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

/// The half-width of the speed band `--rpm` selects, relative to the speed.
const SPEED_BAND: f64 = 0.01;

/// Runs whose mean speeds differ by more than this (relative) are not at one speed.
const SAME_SPEED: f64 = 0.01;

/// Where every angle is measured from.
const ANGLE_REFERENCE: &str = "shaft angle in the frame of alpha_deg: from the keyphasor reference (phi = 0) in the direction of rotation";

const BALANCE_HELP: &str = "\
Angles: --trial-angle and the correction's angle are shaft angles in the frame of alpha_deg,
measured from the keyphasor reference (phi = 0) in the direction of rotation. Place the
correction mass at that angle on the rotor, at --radius.

From an identification summary, the correction cancels the identified unbalance; its
standard deviations and the predicted residual come from the summary's covariance.
From two runs (influence coefficients), the correction is the least-squares fit over the
x and z 1X vectors; remove the trial mass before adding the correction.

Examples:
  rotorid balance summary.json --radius 0.15 --rpm 3000
  rotorid balance --reference run1.csv --trial run2.csv --trial-mass 0.0002 --trial-angle 200 \\
      --radius 0.15 --out balance.json";

/// Arguments of `rotorid balance`.
#[derive(Debug, clap::Args)]
#[command(after_long_help = BALANCE_HELP)]
pub struct BalanceArgs {
    /// An identification summary (its `rotor` and `covariance`): balance the identified
    /// unbalance.
    #[arg(value_name = "SUMMARY.json", conflicts_with_all = ["reference", "trial", "scenario"])]
    pub summary: Option<PathBuf>,

    /// Reference run: a response CSV (t,x,z[,phi,phi_dot,phi_ddot]) without trial mass.
    #[arg(long, value_name = "RUN1.csv", requires_all = ["trial", "trial_mass", "trial_angle"])]
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

    /// Radius at which the correction mass is placed [m].
    #[arg(long, value_name = "M")]
    pub radius: f64,

    /// Speed [rpm]: with runs, use only the samples within 1 % of it; with a summary,
    /// also report the 1X amplitudes before and after the correction at this speed.
    #[arg(long, value_name = "RPM")]
    pub rpm: Option<f64>,

    /// Scenario (table1 or FILE.toml) whose speed profile gives the shaft angle of runs
    /// without phi columns.
    #[arg(long, value_name = "table1|FILE.toml")]
    pub scenario: Option<String>,

    /// Also write the result as JSON to this file.
    #[arg(long, value_name = "FILE.json")]
    pub out: Option<PathBuf>,
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
    if !(args.radius.is_finite() && args.radius > 0.0) {
        bail!(
            "--radius {} is out of range: must be finite and > 0 (m)",
            args.radius
        );
    }
    if let Some(r) = args.rpm {
        if !(r.is_finite() && r > 0.0) {
            bail!("--rpm {r} is out of range: must be finite and > 0 (rev/min)");
        }
    }
    let result = match (&args.summary, &args.reference) {
        (Some(_), _) => from_summary(&args)?,
        (None, Some(_)) => from_runs(&args)?,
        (None, None) => bail!(
            "give an identification summary (rotorid balance SUMMARY.json --radius R) or two runs \
             (--reference RUN1.csv --trial RUN2.csv --trial-mass KG --trial-angle DEG --radius R)"
        ),
    };
    // the file first: a reader of stdout that goes away ends the run at the print
    if let Some(path) = &args.out {
        let mut out = Output::create(&path.display().to_string(), FileMode::Atomic)?;
        serde_json::to_writer_pretty(&mut out, &result)
            .with_context(|| format!("cannot write {}", path.display()))?;
        std::io::Write::write_all(&mut out, b"\n")?;
        out.commit()?;
    }
    print(&result)
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

fn from_summary(args: &BalanceArgs) -> anyhow::Result<BalanceJson> {
    let (rotor, source) = load_rotor(args.summary.as_deref(), None, "balance")?;
    let p = rotor.params;
    let cov = rotor.covariance.as_ref();
    let b = balance_from_unbalance(&p, cov, args.radius).with_context(|| source.clone())?;
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

fn from_runs(args: &BalanceArgs) -> anyhow::Result<BalanceJson> {
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
        radius: args.trial_radius.unwrap_or(args.radius),
        angle: angle.to_radians(),
    };
    let b = balance_from_runs(&v0, &v1, &trial, args.radius)?.ok_or_else(|| {
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
