//! `rotorid balance --vectors ... --masses ... --current RUN` and `--plan`: read the two
//! CSVs (and raw records), call `rotorid::analysis::balance`, print the report on stderr
//! and write `balance.json` (module doc of the parent).

use anyhow::{anyhow, bail, Context as _};
use rotorid::analysis::balance::{
    balance, plan_from_influence, plan_from_model, BalanceMethod, BalanceOptions, Holes, MassInput,
    MassSet, MultiPlaneBalance, TrialPlan, VectorInput,
};
use rotorid_io::csv::{read_masses, read_vectors, Phase};

use super::{write_json, BalanceArgs, MethodArg, PhaseArg};
use crate::commands::analyze::load_rotor;
use crate::commands::onex::{acquisition_of, vectors_of_raw};
use crate::io::LoadScenario as _;
use crate::io::{open_input, ScenarioSpec};

/// `NAME=VALUE` split at the last `=`, both sides trimmed and non-empty.
fn name_value<'a>(flag: &str, text: &'a str, form: &str) -> anyhow::Result<(&'a str, &'a str)> {
    match text.rsplit_once('=') {
        Some((n, v)) if !n.trim().is_empty() && !v.trim().is_empty() => Ok((n.trim(), v.trim())),
        _ => bail!("{flag} {text:?}: expected {form}"),
    }
}

/// A number of `flag`, finite.
fn number(flag: &str, text: &str, what: &str) -> anyhow::Result<f64> {
    let v: f64 = text
        .parse()
        .map_err(|_| anyhow!("{flag}: {text:?} is not a number: expected {what}"))?;
    if !v.is_finite() {
        bail!("{flag}: {v} is not finite: expected {what}");
    }
    Ok(v)
}

/// `SENSOR=VALUE` pairs.
fn pairs(flag: &str, items: &[String], what: &str) -> anyhow::Result<Vec<(String, f64)>> {
    items
        .iter()
        .map(|t| {
            let (n, v) = name_value(flag, t, &format!("NAME={what}"))?;
            Ok((n.to_owned(), number(flag, v, what)?))
        })
        .collect()
}

/// `--holes PLANE=N[@OFFSET_DEG]` or `PLANE=A1,A2,...` (degrees).
fn holes(items: &[String]) -> anyhow::Result<Vec<(String, Holes)>> {
    let form = "PLANE=N[@OFFSET_DEG] (N equally spaced holes, the first at OFFSET_DEG) or PLANE=A1,A2,... (hole angles in deg)";
    items
        .iter()
        .map(|t| {
            let (plane, spec) = match t.split_once('=') {
                Some((p, s)) if !p.trim().is_empty() && !s.trim().is_empty() => (p.trim(), s.trim()),
                _ => bail!("--holes {t:?}: expected {form}"),
            };
            let h = if spec.contains(',') {
                let angles = spec
                    .split(',')
                    .map(|a| number("--holes", a.trim(), "an angle in deg").map(f64::to_radians))
                    .collect::<anyhow::Result<Vec<f64>>>()?;
                Holes::Angles(angles)
            } else {
                let (n, off) = match spec.split_once('@') {
                    Some((n, o)) => (n.trim(), number("--holes", o.trim(), "an offset in deg")?),
                    None => (spec, 0.0),
                };
                let count: usize = n.parse().map_err(|_| {
                    anyhow!("--holes {t:?}: {n:?} is not a number of holes: expected {form}")
                })?;
                if count < 2 {
                    bail!("--holes {t:?}: {count} hole(s): equally spaced holes must be at least 2 (give one angle as PLANE=A,A... or a list)");
                }
                Holes::Equal {
                    count,
                    offset: off.to_radians(),
                }
            };
            Ok((plane.to_owned(), h))
        })
        .collect()
}

/// The options of the library from the flags.
fn options(args: &BalanceArgs, current: String) -> anyhow::Result<BalanceOptions> {
    let mut radius = Vec::new();
    let mut default_radius = None;
    for r in &args.radius {
        match r.rsplit_once('=') {
            Some(_) => {
                let (n, v) = name_value("--radius", r, "PLANE=R or R [m]")?;
                radius.push((n.to_owned(), number("--radius", v, "a radius [m]")?));
            }
            None => {
                if default_radius.is_some() {
                    bail!("--radius {r:?}: a radius for every plane is given twice");
                }
                default_radius = Some(number("--radius", r.trim(), "a radius [m]")?);
            }
        }
    }
    let mass_set = args.mass_set.as_ref().map(|m| MassSet {
        masses: m.clone(),
        per_hole: args.per_hole,
    });
    Ok(BalanceOptions {
        current,
        speeds_rpm: args.speeds.clone(),
        planes: args.planes.clone(),
        method: match args.method {
            MethodArg::Ls => BalanceMethod::LeastSquares,
            MethodArg::Minmax => BalanceMethod::MinMax,
        },
        weights: pairs("--weight", &args.weight, "a weight > 0")?,
        limits: pairs("--limit", &args.limit, "a limit [the sensor's unit]")?,
        radius,
        default_radius,
        holes: holes(&args.holes)?,
        mass_set,
    })
}

/// The vectors of `--vectors` and `--raw`.
fn read_all_vectors(args: &BalanceArgs) -> anyhow::Result<Vec<VectorInput>> {
    let mut vectors = Vec::new();
    if let Some(path) = &args.vectors {
        let (name, input) = open_input(path)?;
        let phase = args.phase.map(|p| match p {
            PhaseArg::Lag => Phase::Lag,
            PhaseArg::Lead => Phase::Lead,
        });
        for r in read_vectors(&name, input, phase, args.unit.as_deref())? {
            vectors.push(VectorInput::new(
                &r.run,
                r.speed_rpm,
                &r.sensor,
                &r.unit,
                r.re,
                r.im,
                r.std,
            ));
        }
    }
    if !args.raw.is_empty() {
        let scenario = args
            .scenario
            .as_deref()
            .context("--raw needs --scenario with an [acquisition] table")?;
        let spec = ScenarioSpec::load(scenario)?;
        let acq = acquisition_of(&spec)?;
        for item in &args.raw {
            let (run, file) = name_value("--raw", item, "RUN=FILE")?;
            for r in vectors_of_raw(file, &spec, acq, run, args.speeds.as_deref())? {
                vectors.push(VectorInput::new(
                    &r.run,
                    r.speed_rpm,
                    &r.sensor,
                    "m",
                    r.re,
                    r.im,
                    Some(r.std),
                ));
            }
        }
    }
    Ok(vectors)
}

fn read_all_masses(path: &str) -> anyhow::Result<Vec<MassInput>> {
    let (name, input) = open_input(path)?;
    Ok(read_masses(&name, input)?
        .into_iter()
        .map(|m| MassInput {
            run: m.run,
            plane: m.plane,
            mass: m.mass_kg,
            radius: m.radius_m,
            angle: m.angle_deg.to_radians(),
        })
        .collect())
}

/// Run the multi-plane forms.
pub fn run(args: &BalanceArgs) -> anyhow::Result<()> {
    if args.plan && args.masses.is_none() {
        return plan_model(args);
    }
    if args.vectors.is_none() && args.raw.is_empty() {
        bail!("multi-plane balancing needs 1X vectors: give --vectors vectors.csv (or --raw RUN=FILE with --scenario)");
    }
    let masses_path = args.masses.as_deref().context(
        "multi-plane balancing needs the calibration runs' masses: give --masses masses.csv (run,plane,mass_kg,radius_m,angle_deg)",
    )?;
    let current = args
        .current
        .clone()
        .context("give --current RUN: the run to balance (or to plan trials for)")?;
    let vectors = read_all_vectors(args)?;
    let masses = read_all_masses(masses_path)?;
    let opts = options(args, current)?;
    if args.plan {
        let plan = plan_from_influence(&vectors, &masses, &opts, args.fraction)?;
        if let Some(path) = &args.out {
            write_json(path, &plan.report())?;
        }
        print_plan(&plan);
        return Ok(());
    }
    let b = balance(&vectors, &masses, &opts)?;
    if let Some(path) = &args.out {
        write_json(path, &b.report())?;
    }
    print_balance(&b);
    Ok(())
}

/// `--plan` from an identification summary.
fn plan_model(args: &BalanceArgs) -> anyhow::Result<()> {
    let Some(summary) = &args.summary else {
        bail!("--plan needs an influence estimate (--vectors and --masses of earlier calibration runs, and --current RUN) or an identified rotor (rotorid balance SUMMARY.json --plan --speeds RPM --radius R)");
    };
    let speeds = args
        .speeds
        .as_deref()
        .context("--plan from a summary needs --speeds: the speeds to plan at [rev/min]")?;
    let radius = match args.radius.as_slice() {
        [r] if !r.contains('=') => number("--radius", r.trim(), "a radius [m]")?,
        [r] => {
            let (_, v) = name_value("--radius", r, "PLANE=R or R [m]")?;
            number("--radius", v, "a radius [m]")?
        }
        _ => bail!("--plan from a summary needs one --radius R: the radius of the trial mass [m]"),
    };
    let plane = match args.planes.as_deref() {
        None => "disk".to_owned(),
        Some([p]) => p.clone(),
        Some(p) => bail!(
            "--planes: the identified rotor has one plane (its disk), {} given",
            p.len()
        ),
    };
    let (rotor, source) = load_rotor(Some(summary.as_path()), None, "balance")?;
    let hl = holes(&args.holes)?;
    let set = args.mass_set.as_ref().map(|m| MassSet {
        masses: m.clone(),
        per_hole: args.per_hole,
    });
    let h = match hl.as_slice() {
        [] => None,
        [(n, h)] if *n == plane => Some((h, set.as_ref())),
        [(n, _)] => bail!("--holes names plane {n:?}, but the plane is {plane:?} (--planes)"),
        _ => bail!("--holes: the identified rotor has one plane"),
    };
    let plan = plan_from_model(&rotor.params, speeds, &plane, radius, args.fraction, h)
        .with_context(|| source.clone())?;
    if let Some(path) = &args.out {
        write_json(path, &plan.report())?;
    }
    print_plan(&plan);
    Ok(())
}

fn deg(z: rotorid::analysis::balance::Split) -> String {
    z.masses
        .iter()
        .map(|m| {
            let w = if m.weights.is_empty() {
                String::new()
            } else {
                format!(
                    " = {}",
                    m.weights
                        .iter()
                        .map(|w| format!("{:.4} g", w * 1e3))
                        .collect::<Vec<_>>()
                        .join(" + ")
                )
            };
            format!(
                "{:.4} g in hole {} ({:.1} deg){w}",
                m.mass * 1e3,
                m.hole + 1,
                m.angle.to_degrees()
            )
        })
        .collect::<Vec<_>>()
        .join(" + ")
}

/// `v` with 2 significant digits.
fn sig(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (1 - v.abs().log10().floor() as i32).max(0) as usize;
    format!("{v:.digits$}")
}

fn opt(v: Option<f64>, f: impl Fn(f64) -> String) -> String {
    v.map_or_else(|| "unknown".into(), f)
}

fn print_balance(b: &MultiPlaneBalance) {
    let speeds: Vec<String> = b.speeds_rpm.iter().map(|s| format!("{s}")).collect();
    eprintln!(
        "balance of run {:?} by {} over {} sensor(s) at {} rpm; {} plane(s), calibration runs {}",
        b.current,
        match b.method {
            BalanceMethod::LeastSquares => "least squares",
            BalanceMethod::MinMax => "min-max",
        },
        b.sensors.len(),
        speeds.join(", "),
        b.planes.len(),
        b.calibration_runs
            .iter()
            .map(|r| format!("{r:?}"))
            .collect::<Vec<_>>()
            .join(", ")
    );
    eprintln!(
        "condition number of the influence matrix: {:.2}",
        b.condition_number
    );
    eprintln!("corrections (angles from the keyphasor mark in the direction of rotation):");
    for c in &b.corrections {
        let k = &c.correction;
        eprintln!(
            "  {:<10} {:.4} g (std {}) at {:.2} deg (std {}), radius {} m",
            c.plane,
            k.mass * 1e3,
            opt(k.std_mass, |s| format!("{} g", sig(s * 1e3))),
            rotorid::analysis::balance::angle_deg(c.unbalance),
            opt(k.std_angle, |s| format!("{} deg", sig(s.to_degrees()))),
            k.radius
        );
        if let Some(s) = &c.split {
            eprintln!(
                "  {:<10} split: {} (leaves {:.3e} kg m)",
                "",
                deg(s.clone()),
                s.residual.norm()
            );
        }
    }
    eprintln!("predicted 1X after the correction (amplitude, the sensor's unit):");
    eprintln!(
        "  {:<10} {:>9} {:>12} {:>12} {:>10}",
        "sensor", "rpm", "before", "after", "std"
    );
    for r in &b.residual {
        let s = &b.sensors[r.sensor];
        let std = r
            .covariance
            .map(|c| (c[(0, 0)] + c[(1, 1)]).max(0.0).sqrt());
        let split = r.after_split.map_or(String::new(), |z| {
            format!("  (with the split masses {:.4})", z.norm())
        });
        eprintln!(
            "  {:<10} {:>9} {:>12.4} {:>12.4} {:>10} {}{split}",
            s.name,
            r.speed_rpm,
            r.before.norm(),
            r.after.norm(),
            opt(std, sig),
            s.unit
        );
    }
    for w in &b.warnings {
        eprintln!("warning: {w}");
    }
    for n in &b.notes {
        eprintln!("note: {n}");
    }
}

fn print_plan(p: &TrialPlan) {
    eprintln!(
        "trial masses changing the 1X response by {:.0} % at the most sensitive sensor (from the {} estimate; angles from the keyphasor mark in the direction of rotation):",
        100.0 * p.fraction,
        if p.source == "model" { "identified rotor's" } else { "influence" }
    );
    for t in &p.trials {
        eprintln!(
            "  {:<10} {:.4} g at {:.2} deg, radius {} m: at {} {} rpm the 1X changes by {:.4} of {:.4} {}",
            t.plane,
            t.mass * 1e3,
            t.angle.to_degrees(),
            t.radius,
            t.sensor,
            t.speed_rpm,
            t.change.norm(),
            t.current.norm(),
            t.unit
        );
        if let Some(s) = &t.split {
            eprintln!("  {:<10} split: {}", "", deg(s.clone()));
        }
    }
    for n in &p.notes {
        eprintln!("note: {n}");
    }
}
