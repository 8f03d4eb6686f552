//! `--method refine`: maximum-likelihood (output-error) fit of eq. (1) to the whole record
//! (`rotorid::refine`; method.md section 7). With white noise of unknown sigma_x, sigma_z
//! the fit minimises
//!
//! ```text
//! L(theta) = N/2 ln S_x(theta) + N/2 ln S_z(theta),   S_x = sum_k (x_k - x(t_k; theta))^2
//! ```
//!
//! over the unknowns (m, cx, kx, cz, kz by default; optionally a and the unbalance) and the
//! initial state at the first sample; standard errors are sqrt(diag F^-1) with the Fisher
//! information F at the estimate, and the Cramer-Rao bound F^-1 is evaluated at the
//! scenario's truth when it is known (else at the estimate).
//!
//! Batch: the record is held in memory (module `record`), the start comes from module
//! `start`, and one row is written, at the last sample's time, holding the parameters the
//! record determines (finite standard error no larger than the value, no inseparable
//! unknowns); the summary holds everything, with the warnings.

use std::io::Read;

use rotorid::refine::{crb, refine, Record, RefineOptions, Refined, SpeedData, Unknowns, Warning};
use rotorid::{InitialState, RotorParams, Unbalance};

use super::algebraic::too_few_rows;
use super::record::RecordData;
use super::speed::{shifted, SpeedSource};
use super::start::{self, ScenarioValues, Source, Start, MCK};
use super::{
    base_summary, modulating, truth_set, write_single_row, Context, IdentifyMethod, UnknownName,
};
use crate::io::summary::{relative_errors, Named, StartSummary};
use crate::io::{
    CsvError, Directions, EstimateRow, Output, ParameterSet, ResponseReader, SharedWriter,
    SimulationOverrides, Summary,
};

/// Fewest rows refine accepts: its algebraic fallback start needs 4 (module `algebraic`).
const MIN_ROWS: u64 = super::algebraic::MIN_ROWS;

/// The unknowns `--unknowns` selects (default m, cx, kx, cz, kz); the initial state is
/// always estimated.
pub(crate) fn unknowns_of(names: Option<&[UnknownName]>) -> Unknowns {
    let Some(names) = names else {
        return Unknowns::default();
    };
    let has = |n: UnknownName| names.contains(&n);
    Unknowns {
        m: has(UnknownName::M),
        cx: has(UnknownName::Cx),
        kx: has(UnknownName::Kx),
        cz: has(UnknownName::Cz),
        kz: has(UnknownName::Kz),
        a: has(UnknownName::A),
        unbalance: has(UnknownName::Unbalance),
        initial_state: true,
    }
}

/// The names of the selected unknowns, in the order m, cx, kx, cz, kz, a, unbalance.
fn unknown_names(u: &Unknowns) -> Vec<String> {
    [
        (u.m, "m"),
        (u.cx, "cx"),
        (u.kx, "kx"),
        (u.cz, "cz"),
        (u.kz, "kz"),
        (u.a, "a"),
        (u.unbalance, "unbalance"),
    ]
    .iter()
    .filter(|(on, _)| *on)
    .map(|(_, n)| (*n).to_owned())
    .collect()
}

/// The scenario's values; every known one among m, cx, kx, cz, kz must be stated.
fn scenario_values(ctx: &Context, u: &Unknowns) -> anyhow::Result<ScenarioValues> {
    let v = &ctx.view;
    let t = &v.truth;
    let mck = [t.m, t.cx, t.kx, t.cz, t.kz];
    let unknown = start::unknown_mck(u);
    let missing: Vec<&str> = (0..5)
        .filter(|&i| !unknown[i] && mck[i].is_none())
        .map(|i| MCK[i])
        .collect();
    if !missing.is_empty() {
        anyhow::bail!(
            "--unknowns leaves {} known, but the scenario {} does not state rotor.{}: give the \
             known values in the scenario or add them to --unknowns",
            missing.join(", "),
            ctx.spec.origin(),
            missing.join(", rotor.")
        );
    }
    Ok(ScenarioValues {
        mck,
        a: v.a,
        unbalance: Unbalance {
            m_u: v.m_u,
            d: v.d,
            alpha: v.alpha,
        },
    })
}

/// Read, fit and write one row; return the summary.
pub(crate) fn run<R: Read>(
    ctx: &Context,
    input: R,
    out: SharedWriter<Output>,
) -> anyhow::Result<Summary> {
    let (args, name) = (ctx.args, ctx.name);
    let unknowns = unknowns_of(args.unknowns.as_deref());
    let sc = scenario_values(ctx, &unknowns)?;
    let reader = ResponseReader::new(name, input, args.time_tolerance)?;
    let source = SpeedSource::new(ctx, reader.has_phi())?;
    let rec = RecordData::read(reader)?;
    if (rec.len() as u64) < MIN_ROWS {
        let why = "the algebraic identifier that may give the start needs them";
        return Err(too_few_rows(name, rec.len() as u64, MIN_ROWS, why).into());
    }
    let dt = rec.dt.expect("two rows give dt");
    let (t_first, t_last) = (rec.t[0], rec.t[rec.len() - 1]);
    let start = start::find(ctx, &rec, source.profile(), &unknowns, &sc)?;
    let speed = match (&rec.speed, source.profile()) {
        (Some(cols), _) => cols.speed_data(&rec.t),
        (None, Some(p)) => SpeedData::Profile(shifted(p, t_first)),
        (None, None) => unreachable!("SpeedSource::new requires one of them"),
    };
    let record = Record {
        dt,
        x: &rec.x,
        z: &rec.z,
        speed,
    };
    let options = RefineOptions {
        unknowns,
        ..RefineOptions::default()
    };
    let fit = refine(&record, &start.params, &InitialState::default(), &options)
        .map_err(|e| CsvError::file(name, format!("the refinement cannot run: {e}")))?;
    let mut warnings: Vec<String> = fit.warnings.iter().map(Warning::to_string).collect();
    let bound = match bound(ctx, &record, &fit, &unknowns, &sc, t_first) {
        Ok(b) => Some(b),
        Err(e) => {
            warnings.push(format!("the Cramer-Rao bound was not computed: {e}"));
            None
        }
    };

    let inseparable = fit.warnings.iter().any(|w| {
        matches!(
            w,
            Warning::NotIdentifiable { .. } | Warning::IllConditioned { .. }
        )
    });
    let determined = |n: &str| -> Option<f64> {
        let e = fit.get(n)?;
        let rel_ok = e.relative_std_error.is_some_and(|r| r <= 1.0);
        (e.std_error.is_finite() && rel_ok && !inseparable).then_some(e.value)
    };
    let values = ParameterSet {
        m_x: determined("m"),
        c_x: determined("cx"),
        k_x: determined("kx"),
        m_z: determined("m"),
        c_z: determined("cz"),
        k_z: determined("kz"),
    };
    let withheld = |dir: [&str; 3]| {
        u64::from(
            dir.iter()
                .any(|n| fit.get(n).is_some() && determined(n).is_none()),
        )
    };
    let flagged = Directions {
        x: withheld(["m", "cx", "kx"]),
        z: withheld(["m", "cz", "kz"]),
    };
    let rcond = if fit.condition_number.is_finite() && fit.condition_number > 0.0 {
        1.0 / fit.condition_number
    } else {
        0.0
    };
    write_single_row(
        out,
        &args.out,
        &EstimateRow {
            t: t_last,
            values,
            rcond_x: rcond,
            rcond_z: rcond,
        },
    )?;

    let finite = |v: f64| v.is_finite().then_some(v);
    let truth = truth_set(&ctx.view.truth);
    let mut s = base_summary(ctx, IdentifyMethod::Refine);
    s.samples = rec.len() as u64;
    s.dt_s = Some(dt);
    s.t_first_s = Some(t_first);
    s.t_last_s = Some(t_last);
    s.final_values = values;
    s.final_time_s = Directions {
        x: (values.m_x.is_some() || values.c_x.is_some() || values.k_x.is_some()).then_some(t_last),
        z: (values.m_z.is_some() || values.c_z.is_some() || values.k_z.is_some()).then_some(t_last),
    };
    s.relative_error = truth.map(|t| relative_errors(&values, &t));
    s.truth = truth;
    s.flagged = flagged;
    s.rows_written = 1;
    s.sigma_x = Some(fit.sigma_x);
    s.sigma_z = Some(fit.sigma_z);
    s.unknowns = Some(unknown_names(&unknowns));
    s.estimate = Some(
        fit.parameters
            .iter()
            .map(|e| (e.name.to_owned(), e.value))
            .collect(),
    );
    s.std_error = Some(
        fit.parameters
            .iter()
            .map(|e| (e.name.to_owned(), finite(e.std_error)))
            .collect(),
    );
    s.relative_std_error = Some(
        fit.parameters
            .iter()
            .map(|e| (e.name.to_owned(), e.relative_std_error.and_then(finite)))
            .collect(),
    );
    if let Some((c, at)) = &bound {
        s.crb = Some(c.clone());
        s.crb_at = Some((*at).to_owned());
    }
    s.std_error_basis = Some(fit.std_error_basis.to_owned());
    s.initial_state = Some(
        fit.initial_state
            .iter()
            .map(|e| (e.name.to_owned(), e.value))
            .collect(),
    );
    s.initial_state_std_error = Some(
        fit.initial_state
            .iter()
            .map(|e| (e.name.to_owned(), finite(e.std_error)))
            .collect(),
    );
    s.identifiable = Some(fit.identifiable);
    s.converged = Some(fit.converged);
    s.iterations = Some(fit.iterations as u64);
    s.condition_number = finite(fit.condition_number);
    s.discretisation = Some(fit.discretisation.clone());
    s.warnings = Some(warnings);
    s.start = Some(start_summary(&start));
    match &start.source {
        Source::Modulating { estimate, .. } => {
            s.modulating = Some(modulating::summary_of(estimate));
        }
        Source::Algebraic { .. } => {
            s.quadrature = Some(ctx.settings.quadrature.to_string());
            s.rcond_min = ctx.settings.rcond_min_algebraic;
        }
        Source::Scenario => {}
    }
    Ok(s)
}

/// The start for the summary.
fn start_summary(st: &Start) -> StartSummary {
    let p = &st.params;
    let u = &p.unbalance;
    let values: Named<f64> = [
        ("m", p.m),
        ("cx", p.cx),
        ("kx", p.kx),
        ("cz", p.cz),
        ("kz", p.kz),
        ("a", p.a),
        ("mud", u.m_u * u.d),
        ("alpha", u.alpha),
    ]
    .into_iter()
    .map(|(n, v)| (n.to_owned(), v))
    .collect();
    StartSummary {
        source: st.source.name().to_owned(),
        t_s: st.source.t(),
        values,
        note: st.note.clone(),
    }
}

/// The Cramer-Rao bound per estimated parameter (None = infinite) and where it was
/// evaluated: `truth` (the scenario's rotor and initial state), `truth_parameters` (its
/// rotor, the fitted initial state) or `estimate`; always with the fitted sigma_x, sigma_z.
fn bound(
    ctx: &Context,
    record: &Record,
    fit: &Refined,
    unknowns: &Unknowns,
    sc: &ScenarioValues,
    t_first: f64,
) -> anyhow::Result<(Named<Option<f64>>, &'static str)> {
    let truth: Option<RotorParams> = match sc.mck {
        [Some(m), Some(cx), Some(kx), Some(cz), Some(kz)] => Some(RotorParams {
            m,
            cx,
            kx,
            cz,
            kz,
            a: sc.a,
            unbalance: sc.unbalance,
        }),
        _ => None,
    };
    let (rotor, initial, at) = match truth {
        Some(r) => match scenario_initial_state(ctx, record, t_first) {
            Some(ic) => (r, ic, "truth"),
            None => (r, fit.initial, "truth_parameters"),
        },
        None => (fit.rotor, fit.initial, "estimate"),
    };
    let b = crb(
        &rotor,
        &initial,
        &record.experiment(),
        unknowns,
        fit.sigma_x,
        fit.sigma_z,
    )?;
    let named = fit
        .parameters
        .iter()
        .map(|e| {
            let v = b.get(e.name).map(|b| b.std_dev).filter(|v| v.is_finite());
            (e.name.to_owned(), v)
        })
        .collect();
    Ok((named, at))
}

/// The scenario's initial state (its `[initial]`, at rest by default) when the record
/// starts at the scenario's t = 0; `None` when it starts later (the state there is not
/// the scenario's) or the scenario does not describe a complete simulation.
fn scenario_initial_state(ctx: &Context, record: &Record, t_first: f64) -> Option<InitialState> {
    if t_first != 0.0 {
        return None;
    }
    let duration = (record.x.len().saturating_sub(1) as f64 * record.dt).max(record.dt);
    let ov = SimulationOverrides {
        dt: Some(record.dt),
        duration: Some(duration),
        ..SimulationOverrides::default()
    };
    ctx.spec.simulation(&ov).ok().map(|s| s.initial)
}
