//! `--method modulating`: the modulating-function identifier
//! (`rotorid::identify::modulating`, method.md section 6) over a response CSV. Per
//! direction, every window [t_j, t_j + L] and test function psi_i give one row of
//!
//! ```text
//! m int psi'' x - cx int psi' x + kx int psi x = -a int psi' w z + mud int psi f_x
//! m int psi'' z - cz int psi' z + kz int psi z =  a int psi' w x + a int psi w' x + mud int psi f_z
//! ```
//!
//! solved by noise-bias-compensated least squares over all completed windows. The
//! identifier is streaming (memory independent of the record length); this command writes
//! one row, at the last sample's time, with the estimate from every completed window.

use std::io::Read;

use rotorid::identify::modulating::{
    ModulatingConfig, ModulatingError, ModulatingEstimate, ModulatingIdentifier,
};
use rotorid::identify::Measurement;

use super::algebraic::too_few_rows;
use super::speed::SpeedSource;
use super::{base_summary, kept_values, truth_set, write_single_row, Context, IdentifyMethod};
use crate::io::params::PARAMETER_NAMES;
use crate::io::summary::{relative_errors, ModulatingSummary};
use crate::io::{CsvError, Directions, EstimateRow, Output, ResponseReader, SharedWriter, Summary};

/// The identifier's configuration: the library's defaults with `--window` and the
/// modulating `--rcond-min`.
pub(crate) fn config(ctx: &Context) -> ModulatingConfig {
    ModulatingConfig {
        rcond_min: ctx.settings.rcond_min_modulating,
        ..ModulatingConfig::with_window(ctx.settings.window_s)
    }
}

/// The estimate once every sample is in, or the error for a record shorter than one window.
pub(crate) fn finish(
    id: &ModulatingIdentifier,
    dt: f64,
) -> Result<ModulatingEstimate, ModulatingError> {
    if id.windows() == 0 {
        return Err(ModulatingError::RecordShorterThanWindow {
            samples: id.samples() as usize,
            needed: id.window_samples(),
            window_s: id.window_s(),
            dt,
        });
    }
    Ok(id.estimate())
}

/// Read, identify and write one row; return the summary.
pub(crate) fn run<R: Read>(
    ctx: &Context,
    input: R,
    out: SharedWriter<Output>,
) -> anyhow::Result<Summary> {
    let (args, name) = (ctx.args, ctx.name);
    let mut reader = ResponseReader::new(name, input, args.time_tolerance)?;
    let speed = SpeedSource::new(ctx, reader.has_phi())?;
    let mut head = Vec::with_capacity(2);
    while head.len() < 2 {
        match reader.next_row()? {
            Some(r) => head.push(r),
            None => {
                return Err(too_few_rows(name, reader.rows(), 2, "two give dt").into());
            }
        }
    }
    let dt = reader.dt().expect("set once two rows are read");
    let cfg = config(ctx);
    let mut id = ModulatingIdentifier::new(ctx.view.known(), dt, cfg)
        .map_err(|e| anyhow::anyhow!("--window: {e}; choose a longer --window"))?;
    let t_first = head[0].t;
    let mut t_last = t_first;
    let mut n = 0u64;
    let mut push = |row: crate::io::ResponseRow| -> anyhow::Result<()> {
        let m = Measurement {
            t: t_first + n as f64 * dt,
            x: row.x,
            z: row.z,
            speed: speed.at(&row),
        };
        id.push(&m)
            .map_err(|e| CsvError::line(name, row.line, e.to_string()))?;
        n += 1;
        t_last = row.t;
        Ok(())
    };
    for row in head {
        push(row)?;
    }
    while let Some(row) = reader.next_row()? {
        push(row)?;
    }
    drop(reader);
    let est = finish(&id, dt).map_err(|e| CsvError::file(name, format!("{e} (--window)")))?;

    let rcond_min = ctx.settings.rcond_min_modulating;
    let ok = est.well_conditioned(rcond_min);
    let values = kept_values(est.x.theta(), est.z.theta(), ok);
    write_single_row(
        out,
        &args.out,
        &EstimateRow {
            t: t_last,
            values,
            rcond_x: est.x.rcond,
            rcond_z: est.z.rcond,
        },
    )?;

    let truth = truth_set(&ctx.view.truth);
    let mut s = base_summary(ctx, IdentifyMethod::Modulating);
    s.samples = n;
    s.dt_s = Some(dt);
    s.t_first_s = Some(t_first);
    s.t_last_s = Some(t_last);
    s.final_values = values;
    let when = |ok: bool| ok.then_some(est.t);
    s.final_time_s = Directions {
        x: when(ok[0]),
        z: when(ok[1]),
    };
    s.relative_error = truth.map(|t| relative_errors(&values, &t));
    s.truth = truth;
    s.flagged = Directions {
        x: u64::from(!ok[0]),
        z: u64::from(!ok[1]),
    };
    s.rows_written = 1;
    s.sigma_x = Some(est.sigma_x);
    s.sigma_z = Some(est.sigma_z);
    s.warnings = Some(warnings(&est, rcond_min));
    s.modulating = Some(summary_of(&est));
    let okv = [ok[0], ok[0], ok[0], ok[1], ok[1], ok[1]];
    let std = est.std_errors();
    let val = est.values();
    s.std_error = Some(
        PARAMETER_NAMES
            .iter()
            .enumerate()
            .map(|(i, n)| {
                (
                    (*n).to_owned(),
                    (okv[i] && std[i].is_finite()).then_some(std[i]),
                )
            })
            .collect(),
    );
    s.relative_std_error = Some(
        PARAMETER_NAMES
            .iter()
            .enumerate()
            .map(|(i, n)| {
                let r = std[i] / val[i].abs();
                ((*n).to_owned(), (okv[i] && r.is_finite()).then_some(r))
            })
            .collect(),
    );
    s.std_error_basis = Some(MODULATING_STD_ERROR_BASIS.to_owned());
    Ok(s)
}

/// How the modulating identifier's standard errors are computed.
pub(crate) const MODULATING_STD_ERROR_BASIS: &str =
    "first-order sandwich covariance of the least squares, with the correlations of \
     overlapping windows, for white noise of the estimated sigma_x, sigma_z";

/// The modulating figures for the summary.
pub(crate) fn summary_of(est: &ModulatingEstimate) -> ModulatingSummary {
    ModulatingSummary {
        window_s: est.window_s,
        hop_s: est.hop_s,
        windows: est.windows,
        rcond: Directions {
            x: est.x.rcond,
            z: est.z.rcond,
        },
    }
}

/// One sentence per ill-conditioned direction.
fn warnings(est: &ModulatingEstimate, rcond_min: f64) -> Vec<String> {
    [("x", est.x), ("z", est.z)]
        .iter()
        .filter(|(_, d)| !d.well_conditioned(rcond_min))
        .map(|(n, d)| {
            if d.rcond > 0.0 {
                format!(
                    "the {n} direction is ill-conditioned (rcond {:.2e} < --rcond-min {rcond_min:e}): \
                     its m, c, k are withheld",
                    d.rcond
                )
            } else {
                format!(
                    "the {n} direction is singular (the least squares has no unique solution, or \
                     the noise compensation exceeds the information in the data): its m, c, k are \
                     withheld"
                )
            }
        })
        .collect()
}
