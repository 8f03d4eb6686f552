//! `rotorid predict SUMMARY.json --scenario S.toml --dofs 3.x,3.y --out pred.csv`: the
//! identified finite-element rotor's response at degrees of freedom no probe
//! watches, with a standard-deviation band from the identification's covariance.
//!
//! The rotor is the scenario's with the summary's identified values
//! ([`crate::io::fe_summary`]); it is simulated on the scenario's `[speed]` and
//! `[sampling]` as `rotorid simulate` simulates a finite-element scenario: the full model,
//! exact discretisation at constant speed, the fourth-order Magnus integrator otherwise;
//! from rest, or from the summary's `initial_state` when `initial` is `"estimated"`.
//!
//! Output columns: `t` \[s\], then each requested degree of freedom `<node>.<dof>` \[m for
//! x, y; rad for rx, ry\], then `<node>.<dof>_std` for each (same unit): the standard
//! deviation sqrt(diag(J Sigma J^T)) of the predicted response, Sigma the summary's
//! covariance over the unknowns, J the sensitivity of the response to them at each sample:
//! central differences of the simulation for the bearing coefficients (step 1e-5 of the
//! coefficient, or of the bearing's larger direct coefficient of the same kind when it is
//! smaller, e.g. a cross term of 0), exact for the unbalances (the response is linear in
//! the unbalance load: d/d mud is the response from rest to the unbalance alone at unit
//! m_u d, d/d alpha the response to it turned by 90 degrees). The initial state's own
//! uncertainty is not in the summary's covariance and not in the band. Standard deviations
//! are empty without a covariance, or where an undetermined parameter (a `null` variance)
//! moves the response; both are said on stderr.
//!
//! Header names carry no unit suffix: SI, as every rotorid CSV without a suffix
//! (docs/formats.md); numbers in shortest round-trip form. `.parquet`, `.mat` and `.npz`
//! outputs get the same columns with their units.

use std::path::PathBuf;

use anyhow::{anyhow, bail};
use rotorid::model::finite_element::{Dof, FeParameter, FeSystem, FeUnbalance, FiniteElementRotor};
use rotorid::simulate::finite_element::{simulate_fe, FeInitialState, FeMethod};
use rotorid::{Sampling, SpeedProfile};

use crate::io::fe_summary::{is_finite_element_summary, IdentifiedFe};
use crate::io::finite_element::finite_element_of;
use crate::io::LoadScenario as _;
use crate::io::{check_distinct_files, is_broken_pipe, ScenarioSpec, SimulationOverrides};

/// Relative step of the central differences over bearing coefficients (module doc).
const STEP: f64 = 1e-5;

const PREDICT_HELP: &str = "\
Output: CSV with the header t,<dof>...,<dof>_std..., SI units: t [s]; x, y [m]; rx, ry [rad];
each _std column the standard deviation of its degree of freedom's prediction, propagated
from the summary's covariance (central differences over the bearing coefficients, step 1e-5
relative; exact over the unbalances). Empty std cells: no covariance, or an undetermined
parameter moves the response (said on stderr).

Example:
  rotorid predict summary.json --scenario fe.toml --dofs 3.x,3.y,7.x,7.y --out pred.csv";

/// Arguments of `rotorid predict`.
#[derive(Debug, clap::Args)]
#[command(after_long_help = PREDICT_HELP)]
pub struct PredictArgs {
    /// The summary of a finite-element identification (`rotorid identify --summary`): its
    /// `parameters`, `covariance` and `initial_state`.
    #[arg(value_name = "SUMMARY.json")]
    pub summary: PathBuf,

    /// The finite-element scenario the summary was identified with: its matrices, bearings,
    /// unbalances, [speed] and [sampling] (the identified values replace its own).
    #[arg(long, value_name = "FILE.toml")]
    pub scenario: Option<String>,

    /// The degrees of freedom to predict, comma-separated `<node>.<dof>` (dof x, y, rx, ry).
    #[arg(long, value_name = "DOF,DOF,...")]
    pub dofs: String,

    /// Output CSV file, or `-` for stdout (`.parquet`, `.mat`, `.npz`: that format).
    #[arg(long, short, value_name = "FILE.csv|-|FILE.parquet|FILE.mat|FILE.npz")]
    pub out: String,

    /// Do not print what was simulated on stderr.
    #[arg(long, short)]
    pub quiet: bool,
}

/// The degrees of freedom `list` names, each one of `rotor`'s (errors name the bad one and
/// list the allowed).
fn parse_dofs(list: &str, rotor: &FiniteElementRotor) -> anyhow::Result<Vec<Dof>> {
    let allowed = || {
        rotor
            .matrices
            .dofs()
            .iter()
            .map(|d| d.to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    let mut out: Vec<Dof> = Vec::new();
    for name in list.split(',').map(str::trim) {
        let dof = name
            .parse::<Dof>()
            .ok()
            .filter(|d| rotor.matrices.index(*d).is_some())
            .ok_or_else(|| {
                anyhow!(
                    "--dofs: {name:?} is not a degree of freedom of the rotor: allowed {}",
                    allowed()
                )
            })?;
        if out.contains(&dof) {
            bail!("--dofs: {name} is given twice");
        }
        out.push(dof);
    }
    Ok(out)
}

/// The central-difference step of bearing coefficient `p` at `rotor` (module doc).
fn step(p: FeParameter, rotor: &FiniteElementRotor) -> f64 {
    let v = p.get(rotor).unwrap_or(0.0);
    let scale = match p {
        FeParameter::Bearing { index, coefficient } => {
            let b = &rotor.bearings[index];
            if coefficient.is_stiffness() {
                b.kxx.abs().max(b.kyy.abs())
            } else {
                b.cxx.abs().max(b.cyy.abs())
            }
        }
        _ => 0.0,
    };
    let h = STEP * v.abs().max(scale);
    if h > 0.0 {
        h
    } else {
        STEP
    }
}

/// What is simulated: the scenario's speed and sampling, the method, the output dofs.
struct Run<'a> {
    speed: SpeedProfile,
    sampling: Sampling,
    method: FeMethod,
    dofs: &'a [Dof],
}

impl Run<'_> {
    /// The response of `rotor` at the dofs from `initial` (None: rest): one column per dof.
    fn response(
        &self,
        rotor: &FiniteElementRotor,
        initial: Option<&FeInitialState>,
    ) -> anyhow::Result<(Vec<f64>, Vec<Vec<f64>>)> {
        let r = simulate_fe(
            &FeSystem::full(rotor),
            &self.speed,
            &self.sampling,
            initial,
            Some(self.dofs),
            self.method,
        )?;
        Ok((r.t, r.q))
    }

    /// d response / d `p` at `rotor` (module doc): per dof, per sample.
    fn sensitivity(
        &self,
        p: FeParameter,
        rotor: &FiniteElementRotor,
        initial: Option<&FeInitialState>,
    ) -> anyhow::Result<Vec<Vec<f64>>> {
        match p {
            FeParameter::Bearing { .. } => {
                let v = p.get(rotor).unwrap_or(0.0);
                let h = step(p, rotor);
                let at = |x: f64| {
                    let mut r = rotor.clone();
                    p.set(&mut r, x);
                    self.response(&r, initial).map(|r| r.1)
                };
                let (up, dn) = (at(v + h)?, at(v - h)?);
                Ok(up
                    .iter()
                    .zip(&dn)
                    .map(|(u, d)| u.iter().zip(d).map(|(a, b)| (a - b) / (2.0 * h)).collect())
                    .collect())
            }
            FeParameter::Mud { index } | FeParameter::Alpha { index } => {
                // linear in the load: the unbalance alone, from rest
                let mut r = rotor.clone();
                for u in &mut r.unbalances {
                    u.mud = 0.0;
                }
                let u = rotor.unbalances[index];
                r.unbalances[index] = if matches!(p, FeParameter::Mud { .. }) {
                    FeUnbalance { mud: 1.0, ..u }
                } else {
                    FeUnbalance {
                        alpha: u.alpha + std::f64::consts::FRAC_PI_2,
                        ..u
                    }
                };
                self.response(&r, None).map(|r| r.1)
            }
        }
    }
}

/// Run `rotorid predict`.
pub fn run(args: PredictArgs) -> anyhow::Result<()> {
    let summary = args.summary.display().to_string();
    let Some(scenario) = args.scenario.as_deref() else {
        bail!(
            "--scenario is needed: {summary} gives the identified values, the scenario the \
             finite-element rotor's matrices, [speed] and [sampling] (rotorid predict \
             SUMMARY.json --scenario fe.toml --dofs 3.x,3.y --out pred.csv)"
        );
    };
    check_distinct_files(
        &[("--scenario", scenario), ("SUMMARY.json", &summary)],
        &[("--out", &args.out)],
    )?;
    if !is_finite_element_summary(&args.summary)? {
        bail!(
            "{summary}: field `model` is not \"finite_element\": rotorid predict takes the \
             summary of a finite-element identification"
        );
    }
    let spec = ScenarioSpec::load(scenario)?;
    let id = IdentifiedFe::read(&args.summary, finite_element_of(&spec)?)?;
    let dofs = parse_dofs(&args.dofs, &id.rotor)?;
    let (speed, sampling) = spec.fe_simulation(&SimulationOverrides::default())?;
    let method = match speed {
        SpeedProfile::Constant { .. } => FeMethod::Exact,
        _ => FeMethod::Magnus,
    };
    let run = Run {
        speed,
        sampling,
        method,
        dofs: &dofs,
    };
    let (t, q) = run.response(&id.rotor, id.initial.as_ref())?;
    let std = band(&args, &run, &id, &summary)?;
    if !args.quiet {
        eprintln!(
            "predicted the identified finite-element rotor of {summary} on {} ({} samples, {} \
             by {method}, from {}) at {}",
            spec.origin(),
            t.len(),
            match run.speed {
                SpeedProfile::Constant { .. } => "constant speed",
                _ => "the speed profile",
            },
            if id.initial.is_some() {
                "the estimated initial state"
            } else {
                "rest"
            },
            args.dofs
        );
    }
    let unit = |d: &Dof| d.kind.unit().to_owned();
    let mut channels = vec![rotorid_io::Channel {
        name: "t".to_owned(),
        unit: Some("s".to_owned()),
        data: t,
        axis: None,
    }];
    for (d, col) in dofs.iter().zip(q) {
        channels.push(rotorid_io::Channel {
            name: d.to_string(),
            unit: Some(unit(d)),
            data: col,
            axis: None,
        });
    }
    for (j, d) in dofs.iter().enumerate() {
        channels.push(rotorid_io::Channel {
            name: format!("{d}_std"),
            unit: Some(unit(d)),
            data: std
                .as_ref()
                .map_or_else(|| vec![f64::NAN; channels[0].data.len()], |s| s[j].clone()),
            axis: None,
        });
    }
    let table = rotorid_io::Table {
        file: args.out.clone(),
        notes: Vec::new(),
        channels,
    };
    match crate::commands::simulate::write_any(&args.out, &table) {
        Err(e) if args.out == "-" && is_broken_pipe(&e) => Ok(()),
        r => r,
    }
}

/// The standard deviation of each dof's prediction at each sample (module doc); `None`
/// (with a warning) without a covariance or when an undetermined parameter enters.
fn band(
    args: &PredictArgs,
    run: &Run<'_>,
    id: &IdentifiedFe,
    summary: &str,
) -> anyhow::Result<Option<Vec<Vec<f64>>>> {
    let Some(cov) = &id.covariance else {
        eprintln!(
            "warning: {summary} has no covariance (null): the _std columns are empty, the \
             prediction's uncertainty is unknown"
        );
        return Ok(None);
    };
    let params = cov.parameters();
    if let Some(i) = (0..params.len()).find(|&i| cov.is_undetermined(i)) {
        eprintln!(
            "warning: {} is undetermined in {summary} (a null variance): the _std columns are \
             empty, the prediction's uncertainty is unbounded",
            params[i]
        );
        return Ok(None);
    }
    if id.initial.is_some() && !args.quiet {
        eprintln!(
            "note: the band holds the uncertainty of the identified parameters, not that of \
             the estimated initial state (the summary's covariance is over the parameters)"
        );
    }
    let jac: Vec<Vec<Vec<f64>>> = params
        .iter()
        .map(|&p| run.sensitivity(p, &id.rotor, id.initial.as_ref()))
        .collect::<anyhow::Result<_>>()?;
    let m = cov.matrix();
    let n = params.len();
    let out = (0..run.dofs.len())
        .map(|d| {
            let samples = jac.first().map_or(0, |j| j[d].len());
            (0..samples)
                .map(|s| {
                    let mut v = 0.0;
                    for i in 0..n {
                        let gi = jac[i][d][s];
                        if gi == 0.0 {
                            continue;
                        }
                        for k in 0..n {
                            v += gi * m[i][k] * jac[k][d][s];
                        }
                    }
                    v.max(0.0).sqrt()
                })
                .collect()
        })
        .collect();
    Ok(Some(out))
}
