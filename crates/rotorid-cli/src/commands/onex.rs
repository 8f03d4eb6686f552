//! `rotorid onex RAW... --scenario S.toml [--speeds 1000,1200] --out vectors.csv`: the 1X
//! vector of each probe in raw records (two probes in volts and a keyphasor, the scenario's
//! `[acquisition]` table, docs/acquisition.md), as the rows of `vectors.csv`
//! (`run,speed_rpm,sensor,re,im,unit,re_std,im_std`, docs/balancing.md) that
//! `rotorid balance --vectors` reads.
//!
//! Each record is conditioned as `rotorid condition` does (keyphasor to shaft angle,
//! slow-roll runout removed, the probes combined into x, z); each probe's displacement
//! towards it, x cos theta + z sin theta (its angle theta from +x towards +z), is reduced
//! to its 1X vector by synchronous averaging over whole revolutions
//! (`rotorid::analysis::synchronous_average`): the mean of the revolutions' vectors, with
//! standard deviations from their scatter. The vectors are in m, peak, in the shaft-angle
//! frame of the scenario (phi = `[acquisition.keyphasor] angle_deg` at the keyphasor
//! event: with the default 0, angles from the keyphasor mark). Without `--speeds` a record
//! must be at one speed (within 2 %); with it, each speed takes the longest stretch of
//! samples within 1 % of it.

use std::io::Write as _;
use std::path::Path;

use anyhow::{bail, Context as _};
use rotorid::acquisition::Acquisition;
use rotorid::analysis::synchronous_average;
use rotorid::model::{rad_per_s_to_rpm, rpm_to_rad_per_s};

use crate::io::number::format_f64;
use crate::io::tables;
use crate::io::LoadScenario as _;
use crate::io::{FileMode, Output, ScenarioSpec};

/// Half-width of the speed band `--speeds` selects, relative to the speed.
const SPEED_BAND: f64 = 0.01;
/// Largest relative speed spread of a record without `--speeds`.
const ONE_SPEED: f64 = 0.02;

/// The header `rotorid onex` writes.
pub const ONEX_HEADER: &str = "run,speed_rpm,sensor,re,im,unit,re_std,im_std";

const ONEX_HELP: &str = "\
Each probe's 1X vector V means its displacement towards it has the 1X component
Re(V e^{i phi}), phi the shaft angle from the keyphasor mark in the direction of rotation
(the scenario's frame: phi = [acquisition.keyphasor] angle_deg at the keyphasor event).
re, im and their standard deviations are in m (peak); the standard deviations come from
the scatter of the revolutions' own vectors.

Examples:
  rotorid onex asfound.csv trial1.csv trial2.csv --scenario rig.toml --out vectors.csv
  rotorid onex runup.tdms --scenario rig.toml --run asfound --speeds 1800,3000 --out -";

/// Arguments of `rotorid onex`.
#[derive(Debug, clap::Args)]
#[command(after_long_help = ONEX_HELP)]
pub struct OnexArgs {
    /// Raw records (.csv, .mat, .tdms, .uff, .npy/.npz, .parquet), one run each, with the
    /// columns the scenario's [acquisition] names.
    #[arg(value_name = "RAW", required = true)]
    pub inputs: Vec<String>,

    /// The scenario TOML with an [acquisition] table.
    #[arg(long, value_name = "FILE.toml")]
    pub scenario: String,

    /// The run's name (one record only; default: each file's name without its extension).
    #[arg(long, value_name = "NAME")]
    pub run: Option<String>,

    /// Speeds [rev/min], comma-separated: a vector at each, from the longest stretch of
    /// samples within 1 % of it.
    #[arg(long, value_name = "RPM,RPM", value_delimiter = ',')]
    pub speeds: Option<Vec<f64>>,

    /// The CSV to write, or `-` for stdout.
    #[arg(long, short, value_name = "vectors.csv|-", default_value = "-")]
    pub out: String,

    /// Write no header line (to append to a file with one).
    #[arg(long)]
    pub no_header: bool,
}

/// One row of `vectors.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct OnexRow {
    /// Run.
    pub run: String,
    /// Mean speed \[rev/min\].
    pub speed_rpm: f64,
    /// Probe column.
    pub sensor: String,
    /// Re V \[m\].
    pub re: f64,
    /// Im V \[m\].
    pub im: f64,
    /// Standard deviations of re and im \[m\].
    pub std: (f64, f64),
}

/// The run name of `path`: its file name without the extension.
pub fn run_name(path: &str) -> String {
    Path::new(path)
        .file_stem()
        .map_or_else(|| path.to_owned(), |s| s.to_string_lossy().into_owned())
}

/// The longest run of consecutive indices where `keep` holds.
fn longest_stretch(n: usize, keep: impl Fn(usize) -> bool) -> std::ops::Range<usize> {
    let (mut best, mut start) = (0..0, None);
    for i in 0..=n {
        match (i < n && keep(i), start) {
            (true, None) => start = Some(i),
            (false, Some(s)) => {
                if i - s > best.len() {
                    best = s..i;
                }
                start = None;
            }
            _ => {}
        }
    }
    best
}

/// The 1X vectors of the probes of raw record `path` for run `run` (module doc).
pub fn vectors_of_raw(
    path: &str,
    spec: &ScenarioSpec,
    acq: &Acquisition,
    run: &str,
    speeds: Option<&[f64]>,
) -> anyhow::Result<Vec<OnexRow>> {
    let table = tables::read(path)?;
    let raw = tables::raw_record(&table, acq)?;
    let slow = tables::slow_roll(spec, acq)?;
    let c = tables::condition_for(&raw, acq, slow.as_ref(), spec, &spec.knowledge()?, None)
        .with_context(|| format!("{path}: conditioning the raw record"))?;
    tables::print_report(&c);
    let n = c.t.len();
    let ranges: Vec<(std::ops::Range<usize>, String)> = match speeds {
        Some(list) => list
            .iter()
            .map(|&rpm| {
                if !(rpm.is_finite() && rpm > 0.0) {
                    bail!("--speeds {rpm} is out of range: must be finite and > 0 (rev/min)");
                }
                let w = rpm_to_rad_per_s(rpm);
                let r = longest_stretch(n, |i| (c.phi_dot[i] - w).abs() <= SPEED_BAND * w);
                Ok((r, format!(" within 1 % of {rpm} rpm")))
            })
            .collect::<anyhow::Result<_>>()?,
        None => {
            let (lo, hi) = c
                .phi_dot
                .iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &w| {
                    (a.min(w), b.max(w))
                });
            if lo.is_nan() || lo <= 0.0 || hi > lo * (1.0 + ONE_SPEED) {
                bail!(
                    "{path}: the shaft turns at {:.1} to {:.1} rpm: a 1X vector needs one speed (within 2 %); give --speeds to pick speeds out of a run-up",
                    rad_per_s_to_rpm(lo),
                    rad_per_s_to_rpm(hi)
                );
            }
            vec![(0..n, String::new())]
        }
    };
    let mut rows = Vec::new();
    for (range, within) in ranges {
        let phi = &c.phi[range.clone()];
        let speed_rpm = rad_per_s_to_rpm(
            c.phi_dot[range.clone()].iter().sum::<f64>() / range.len().max(1) as f64,
        );
        for p in &acq.probes {
            let (cs, sn) = (p.angle.cos(), p.angle.sin());
            let d: Vec<f64> = range.clone().map(|i| c.x[i] * cs + c.z[i] * sn).collect();
            let v = synchronous_average(&d, phi)?.ok_or_else(|| {
                anyhow::anyhow!(
                    "{path}: {} samples{within}: at least 2 whole revolutions are needed for a 1X vector with its noise",
                    range.len()
                )
            })?;
            rows.push(OnexRow {
                run: run.to_owned(),
                speed_rpm,
                sensor: p.column.clone(),
                re: v.vector.re,
                im: v.vector.im,
                std: (
                    v.covariance[(0, 0)].max(0.0).sqrt(),
                    v.covariance[(1, 1)].max(0.0).sqrt(),
                ),
            });
        }
    }
    Ok(rows)
}

/// The scenario's `[acquisition]`, or the error of a scenario without one.
pub fn acquisition_of(spec: &ScenarioSpec) -> anyhow::Result<&Acquisition> {
    spec.acquisition().ok_or_else(|| {
        anyhow::anyhow!(
            "{}: has no [acquisition] table: it names the probe and keyphasor columns (see docs/acquisition.md)",
            spec.origin()
        )
    })
}

/// Run `rotorid onex`.
pub fn run(args: OnexArgs) -> anyhow::Result<()> {
    if args.run.is_some() && args.inputs.len() > 1 {
        bail!(
            "--run names one run, but {} records are given: each is named by its file name",
            args.inputs.len()
        );
    }
    let spec = ScenarioSpec::load(&args.scenario)?;
    let acq = acquisition_of(&spec)?;
    let mut rows = Vec::new();
    for input in &args.inputs {
        let run = args.run.clone().unwrap_or_else(|| run_name(input));
        rows.extend(vectors_of_raw(
            input,
            &spec,
            acq,
            &run,
            args.speeds.as_deref(),
        )?);
    }
    let mut out = Output::create(&args.out, FileMode::Atomic)?;
    let name = out.name().to_owned();
    let mut text = String::new();
    if !args.no_header {
        text.push_str(ONEX_HEADER);
        text.push('\n');
    }
    for r in &rows {
        text.push_str(&format!(
            "{},{},{},{},{},m,{},{}\n",
            csv_text(&r.run),
            format_f64(r.speed_rpm),
            csv_text(&r.sensor),
            format_f64(r.re),
            format_f64(r.im),
            format_f64(r.std.0),
            format_f64(r.std.1)
        ));
    }
    out.write_all(text.as_bytes())
        .with_context(|| format!("cannot write {name}"))?;
    out.commit()
}

/// A text field for CSV: quoted when it holds a comma, quote or line end.
pub(crate) fn csv_text(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_owned()
    }
}
