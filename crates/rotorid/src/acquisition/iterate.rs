//! Conditioning and identification, iterated until the rotor guess settles
//! (docs/acquisition.md section 6).
//!
//! The model-assisted steps of [`condition`] (the slow-roll record's own response removed
//! from the runout, the transient's mean removed from the DC) are only as good as the
//! rotor guess they use; the identification of the conditioned record is in turn biased
//! by what a wrong guess left in it. So: condition with the first guess (the scenario's
//! complete `[rotor]`, or none), identify; condition again with that estimate
//! ([`ModelGuess::from_identification`]: the estimate and refine's fitted initial state),
//! identify again; and so on while an estimate moves, between two passes, by more than
//! [`SETTLED_STD_ERRORS`] of its standard error (a method without standard errors, the
//! algebraic one: by more than [`SETTLED_RELATIVE`] of its value), at most [`MAX_PASSES`]
//! passes. The result is the last pass's conditioned record and identification, with
//! [`Passes`] in the report, a note saying what was done and, when the guess did not
//! settle, the finding [`AcquisitionFinding::NotSettled`].
//!
//! Each pass shrinks the bias the previous guess left (measured on a 600 rpm + 10 rad/s^2
//! run-up without a first guess: m off by 1.6e-3, then 2e-4, 3e-5; docs/acquisition.md
//! section 9), so a run without a first guess takes about five passes, one with the
//! true rotor two.

use serde::Serialize;

use crate::parameter::Parameter;
use crate::pipeline::{identify, Identification, Knowledge, Method, PipelineError, Record, Speed};

use super::{
    condition, Acquisition, AcquisitionError, AcquisitionFinding, Conditioned, GuessSource,
    ModelGuess, RawRecord,
};

/// Most passes (each a conditioning and an identification).
pub const MAX_PASSES: usize = 8;
/// The guess has settled when no estimate moved by more than this many of its standard
/// errors between the last two passes.
pub const SETTLED_STD_ERRORS: f64 = 0.1;
/// The same, relative to the value, for estimates without standard errors (algebraic).
pub const SETTLED_RELATIVE: f64 = 1e-6;

/// How a change between two passes is measured.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ChangeBasis {
    /// In standard errors of the newer estimate.
    StdErrors,
    /// Relative to the newer estimate (some estimate had no standard error).
    Relative,
}

/// What the iteration did (module doc).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Passes {
    /// Passes made (each a conditioning and an identification).
    pub passes: usize,
    /// The largest change of an estimate between the last two passes (in `basis`);
    /// `None` after one pass.
    pub last_change: Option<f64>,
    /// The estimate that changed most.
    pub parameter: Option<Parameter>,
    /// How `last_change` is measured.
    pub basis: ChangeBasis,
    /// Whether the guess settled (last change within [`SETTLED_STD_ERRORS`] or
    /// [`SETTLED_RELATIVE`]).
    pub settled: bool,
    /// Where the first pass's guess came from (`None`: no guess).
    pub first_guess: Option<GuessSource>,
}

/// The last pass (module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct Iterated {
    /// The record conditioned with the last guess; its report holds [`Passes`].
    pub conditioned: Conditioned,
    /// The identification of that record.
    pub identification: Identification,
}

/// Why the iteration stopped without a result.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum IterationError {
    /// The conditioning refused the input.
    #[error(transparent)]
    Acquisition(#[from] AcquisitionError),
    /// The identification refused the conditioned record.
    #[error(transparent)]
    Pipeline(#[from] PipelineError),
}

/// The largest change of an estimate of `new` from `old`, the estimate, and how it is
/// measured: in standard errors of `new` when every estimate has one, else relative.
pub fn change(old: &Identification, new: &Identification) -> (f64, Option<Parameter>, ChangeBasis) {
    let estimate = |r: &crate::pipeline::ParameterResult| r.estimate.or(r.value);
    // (in standard errors, relative, parameter)
    let mut moves = Vec::new();
    for r in &new.parameters {
        let before = old.parameter(r.parameter).and_then(estimate);
        let (Some(v), Some(before)) = (estimate(r), before) else {
            continue;
        };
        let d = (v - before).abs();
        let se = r.std_error.filter(|s| s.is_finite() && *s > 0.0);
        moves.push((se.map(|s| d / s), d / v.abs(), r.parameter));
    }
    let basis = if moves.iter().all(|m| m.0.is_some()) {
        ChangeBasis::StdErrors
    } else {
        ChangeBasis::Relative
    };
    let mut worst = (0.0_f64, None);
    for (in_se, relative, p) in moves {
        let c = match basis {
            ChangeBasis::StdErrors => in_se.unwrap_or(f64::NAN),
            ChangeBasis::Relative => relative,
        };
        // a NaN change (an estimate at 0) counts as unsettled, and stays the worst
        if !worst.0.is_nan() && (c.is_nan() || c > worst.0) {
            worst = (c, Some(p));
        }
    }
    (worst.0, worst.1, basis)
}

/// The conditioned record `c` as the pipeline's record (stamps within `time_tolerance` dt
/// of their grid, besides their rounding).
fn record_of(c: &Conditioned, time_tolerance: f64) -> Result<Record, PipelineError> {
    Record::new(
        c.t.clone(),
        c.x.clone(),
        c.z.clone(),
        Speed::Samples {
            phi: c.phi.clone(),
            omega: c.phi_dot.clone(),
            omega_dot: c.phi_ddot.clone(),
        },
        time_tolerance,
    )
}

/// Condition `raw` and identify it by `method`, iterated (module doc): `first` is the
/// first pass's rotor guess, `knowledge` what the identification knows, `time_tolerance`
/// the stamps' allowed deviation from their grid, relative to dt.
pub fn condition_iterated(
    raw: &RawRecord,
    acq: &Acquisition,
    slow_roll: Option<&RawRecord>,
    first: Option<&ModelGuess>,
    knowledge: &Knowledge,
    method: &Method,
    time_tolerance: f64,
) -> Result<Iterated, IterationError> {
    let mut conditioned = condition(raw, acq, slow_roll, first)?;
    let mut ident = identify(&record_of(&conditioned, time_tolerance)?, knowledge, method)?;
    let mut passes = Passes {
        passes: 1,
        last_change: None,
        parameter: None,
        basis: ChangeBasis::StdErrors,
        settled: false,
        first_guess: first.map(|g| g.source),
    };
    let mut unusable = false;
    while passes.passes < MAX_PASSES {
        let Some(guess) = ModelGuess::from_identification(&ident, knowledge) else {
            unusable = true;
            break;
        };
        let c = condition(raw, acq, slow_roll, Some(&guess))?;
        let id = identify(&record_of(&c, time_tolerance)?, knowledge, method)?;
        let (moved, parameter, basis) = change(&ident, &id);
        passes.passes += 1;
        passes.last_change = Some(moved);
        passes.parameter = parameter;
        passes.basis = basis;
        conditioned = c;
        ident = id;
        let limit = match basis {
            ChangeBasis::StdErrors => SETTLED_STD_ERRORS,
            ChangeBasis::Relative => SETTLED_RELATIVE,
        };
        if moved <= limit {
            passes.settled = true;
            break;
        }
    }
    let report = &mut conditioned.report;
    let first_words = match passes.first_guess {
        Some(GuessSource::Scenario) => "the scenario's [rotor]",
        Some(GuessSource::Identification) => "an identification",
        Some(GuessSource::Given) => "the given rotor",
        None => "no rotor guess",
    };
    let unit = |b: ChangeBasis| match b {
        ChangeBasis::StdErrors => "standard errors",
        ChangeBasis::Relative => "(relative)",
    };
    if unusable {
        report.notes.push(format!(
            "pass {}'s estimates do not make a rotor the model accepts (m, kx, kz > 0) and \
             the scenario has no nominal values to stand in: the record stays conditioned \
             with the guess before",
            passes.passes
        ));
    }
    match (passes.last_change, passes.parameter) {
        (Some(c), Some(p)) => report.notes.push(format!(
            "conditioned and identified in {} passes (pass 1 with {first_words}, each next \
             with the estimate before it); in the last, {} moved by {c:.2e} {} ({}settled: \
             the limit is {:e})",
            passes.passes,
            p.name(),
            unit(passes.basis),
            if passes.settled { "" } else { "not " },
            match passes.basis {
                ChangeBasis::StdErrors => SETTLED_STD_ERRORS,
                ChangeBasis::Relative => SETTLED_RELATIVE,
            }
        )),
        _ => report.notes.push(format!(
            "conditioned and identified in {} pass with {first_words}",
            passes.passes
        )),
    }
    if !passes.settled && !unusable {
        report.findings.push(AcquisitionFinding::NotSettled {
            passes: passes.passes,
            last_change: passes.last_change.unwrap_or(f64::NAN),
            parameter: passes.parameter.map(|p| p.name().to_owned()),
            relative: passes.basis == ChangeBasis::Relative,
        });
    }
    report.passes = Some(passes);
    Ok(Iterated {
        conditioned,
        identification: ident,
    })
}
