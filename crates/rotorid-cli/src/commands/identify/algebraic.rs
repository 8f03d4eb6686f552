//! `--method algebraic`: the paper's algebraic identifier (eqs. 7-8; method.md section 5)
//! over a response CSV, streaming.
//!
//! Per direction, at every sample, solve `A(t) theta = b(t)` for theta = (m, c, k), with
//! A, b built from running iterated integrals of the measured x(t), z(t) and the known
//! a, m_u d, alpha (`rotorid::identify::algebraic::AlgebraicIdentifier`).
//!
//! Data flow, all in bounded memory whatever the input length:
//!
//! ```text
//! INPUT.csv|stdin -> FlushBeforeRead -> ResponseReader (validates, line/column errors)
//!   -> AlgebraicIdentifier::push -> ConvergenceTracker (final value, identification time)
//!   -> every N-th estimate -> EstimatesWriter -> ESTIMATES.csv|stdout
//! ```
//!
//! The output is flushed whenever the input runs dry (so a live pipe sees every estimate
//! as soon as its sample arrived) and only ever holds whole rows. The sampling period is
//! dt = t_2 - t_1 of the first two rows; rows that deviate from the uniform grid by more
//! than `--time-tolerance` (relative to dt) are rejected; the identifier integrates on the
//! nominal grid t_1 + n dt (its tau), and the estimates carry the input's own t.

use std::io::Read;

use anyhow::Context as _;
use rotorid::identify::algebraic::{
    AlgebraicConfig, AlgebraicEstimate, AlgebraicIdentifier, ConvergenceTracker, SpeedModel,
};
use rotorid::identify::Measurement;

use super::speed::SpeedSource;
use super::{base_summary, kept_values, truth_set, Context, IdentifyMethod};
use crate::io::summary::relative_errors;
use crate::io::{
    CsvError, Directions, EstimateRow, EstimatesWriter, Output, ParameterSet, ResponseReader,
    ResponseRow, SharedWriter, Summary,
};

/// Fewest data rows the algebraic identifier accepts: two give the sampling period, and the
/// 3x3 system A(t) is singular or nearly so until the 4th sample (tau = 3 dt), the first
/// instant that can be well conditioned with every quadrature rule (A is singular at
/// tau = 0 and its entries are integrals over fewer intervals than the 3 unknowns need
/// before that).
pub const MIN_ROWS: u64 = 4;

/// Read, identify and write; return the summary.
pub(crate) fn run<R: Read>(
    ctx: &Context,
    input: R,
    out: SharedWriter<Output>,
) -> anyhow::Result<Summary> {
    let (args, set, name) = (ctx.args, &ctx.settings, ctx.name);
    let mut reader = ResponseReader::new(name, input, args.time_tolerance)?;
    let speed = SpeedSource::new(ctx, reader.has_phi())?;
    // Buffer the first MIN_ROWS rows: they give dt (t_2 - t_1), which the identifier needs
    // before its first sample, and a too-short input fails before anything is written.
    let mut head = Vec::with_capacity(MIN_ROWS as usize);
    while head.len() < MIN_ROWS as usize {
        match reader.next_row()? {
            Some(r) => head.push(r),
            None => return Err(too_few_rows(name, reader.rows(), MIN_ROWS, WHY).into()),
        }
    }
    let dt = reader.dt().expect("set once two rows are read");
    let out_name = args.out.clone();
    let write_err = move || format!("cannot write {out_name}");
    let mut writer = EstimatesWriter::new(out).with_context(write_err.clone())?;
    let rcond_min = set.rcond_min_algebraic;
    let config = AlgebraicConfig::new(set.quadrature, rcond_min, SpeedModel::General)?;
    let mut id = AlgebraicIdentifier::new(ctx.view.known(), dt, config)?;
    let mut tracker = ConvergenceTracker::new(set.tol, rcond_min)?;
    let t_first = head[0].t;
    let mut state = RunState::default();

    let mut step = |row: ResponseRow, state: &mut RunState| -> anyhow::Result<()> {
        let n = state.samples;
        let m = Measurement {
            // The identifier's grid: uniform by construction (jitter was checked above).
            t: t_first + n as f64 * dt,
            x: row.x,
            z: row.z,
            speed: speed.at(&row),
        };
        let mut est: AlgebraicEstimate = id
            .push(&m)
            .map_err(|e| CsvError::line(name, row.line, e.to_string()))?;
        est.t = row.t;
        tracker.push(&est);
        let ok = est.well_conditioned(rcond_min);
        state.flagged.x += u64::from(!ok[0]);
        state.flagged.z += u64::from(!ok[1]);
        if n % set.every == 0 {
            writer
                .write(&row_of(&est, ok))
                .with_context(write_err.clone())?;
            state.written += 1;
        }
        state.samples += 1;
        state.t_last = row.t;
        Ok(())
    };
    for row in head {
        step(row, &mut state)?;
    }
    while let Some(row) = reader.next_row()? {
        step(row, &mut state)?;
    }
    drop(reader);

    let results = tracker.results();
    let final_values = ParameterSet::from_array(results.map(|r| r.final_value));
    let truth = truth_set(&ctx.view.truth);
    let mut s = base_summary(ctx, IdentifyMethod::Algebraic);
    s.quadrature = Some(set.quadrature.to_string());
    s.tol = Some(set.tol);
    s.samples = state.samples;
    s.dt_s = Some(dt);
    s.t_first_s = Some(t_first);
    s.t_last_s = Some(state.t_last);
    s.final_values = final_values;
    s.final_time_s = Directions {
        x: results[0].final_t,
        z: results[3].final_t,
    };
    s.identification_time_s = ParameterSet::from_array(results.map(|r| r.identification_time));
    s.relative_error = truth.map(|t| relative_errors(&final_values, &t));
    s.truth = truth;
    s.flagged = state.flagged;
    s.rows_written = state.written;
    Ok(s)
}

/// Why the algebraic identifier needs [`MIN_ROWS`] rows.
const WHY: &str = "the 4th sample is the first at which the 3x3 system can be well conditioned";

#[derive(Default)]
struct RunState {
    samples: u64,
    written: u64,
    t_last: f64,
    flagged: Directions<u64>,
}

/// The error for an input with only `rows` data rows where `needed` are required (`why`).
pub(crate) fn too_few_rows(name: &str, rows: u64, needed: u64, why: &str) -> CsvError {
    CsvError::file(
        name,
        format!(
            "{rows} data row{} after the header: the identifier needs at least {needed} \
             ({why})",
            if rows == 1 { "" } else { "s" }
        ),
    )
}

/// The CSV row of an estimate: m, c, k only where the direction is well conditioned.
fn row_of(e: &AlgebraicEstimate, ok: [bool; 2]) -> EstimateRow {
    EstimateRow {
        t: e.t,
        values: kept_values(e.x.theta(), e.z.theta(), ok),
        rcond_x: e.x.rcond,
        rcond_z: e.z.rcond,
    }
}
