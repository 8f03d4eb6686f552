//! `rotorid plot INPUT.csv --out FILE.png|FILE.svg [--scenario table1|FILE.toml]
//! [--from S --to S]`: draw a CSV written by `rotorid simulate` or `rotorid identify`.
//!
//! The kind is chosen from the header (names compared as the readers in [`crate::io`]
//! compare them: trimmed, lower-case, a unit suffix `[m]` or `(m)` dropped):
//!
//! - an estimates column (`m_x` ... `k_z`, `rcond_x`, `rcond_z`): identify output
//!   (`t,m_x,c_x,k_x,m_z,c_z,k_z,rcond_x,rcond_z`) -> three stacked panels m, c, k against
//!   time, both directions solid; with `--scenario`, the true values dashed. Ill-conditioned
//!   instants are empty in that file and show as gaps. y is scaled to what is visible and
//!   kept within +-50 % of a reference: the true value, else the median of the last quarter
//!   of the window's estimates.
//! - otherwise `t` with `x` or `z`: simulate output (`t,x,z[,phi,phi_dot,phi_ddot]`) ->
//!   x(t) and z(t), and the orbit z against x (equal scales), side by side; displacements
//!   in the SI prefix that suits their size (nm, um, ...).
//!
//! `--from`/`--to` restrict the time window [s]. The files are read with the validating
//! readers of [`crate::io`] (line and column in every error).

use std::io::Read;
use std::path::{Path, PathBuf};

use anyhow::{bail, Context};

use crate::io::columns::{csv_reader, next_record, normalise};
use crate::io::{
    open_input, EstimateRow, EstimatesReader, ResponseReader, ScenarioSpec, Truth,
    DEFAULT_TIME_TOLERANCE, ESTIMATES_HEADER,
};
use crate::plot::scale::si_prefix;
use crate::plot::{palette, save, Figure, ImageFormat, Panel, Series};

/// Auto-scaled estimates never extend beyond reference * (1 -+ this).
const Y_BAND: f64 = 0.5;

/// Arguments of `rotorid plot`.
#[derive(Debug, clap::Args)]
pub struct PlotArgs {
    /// A response CSV from `rotorid simulate` (t,x,z,...) or an estimates CSV from
    /// `rotorid identify` (t,m_x,...,rcond_z); `-` reads stdin.
    #[arg(value_name = "INPUT.csv")]
    pub input: String,
    /// The image to write: FILE.png or FILE.svg.
    #[arg(long, value_name = "FILE.png|FILE.svg")]
    pub out: PathBuf,
    /// Draw the true m, c, k of this scenario (dashed) on an estimates plot: `table1` or
    /// a scenario TOML file.
    #[arg(long, value_name = "table1|FILE.toml")]
    pub scenario: Option<String>,
    /// Start of the time window [s].
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub from: Option<f64>,
    /// End of the time window [s].
    #[arg(long, value_name = "S", allow_negative_numbers = true)]
    pub to: Option<f64>,
}

/// What a CSV holds, from its header.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CsvKind {
    /// `rotorid simulate` output.
    Response,
    /// `rotorid identify` output.
    Estimates,
}

/// Run `rotorid plot`.
pub fn run(args: PlotArgs) -> anyhow::Result<()> {
    ImageFormat::from_path(&args.out)?;
    for (flag, v) in [("--from", args.from), ("--to", args.to)] {
        if let Some(v) = v {
            if !v.is_finite() {
                bail!("{flag} {v} is out of range: must be a finite time (s)");
            }
        }
    }
    if let (Some(a), Some(b)) = (args.from, args.to) {
        if a >= b {
            bail!("--from {a} must be earlier than --to {b} (s)");
        }
    }
    let (name, mut input) = open_input(&args.input)?;
    let mut bytes = Vec::new();
    input
        .read_to_end(&mut bytes)
        .with_context(|| format!("cannot read {name}"))?;
    let kind = detect(&name, &bytes)?;
    let truth = match &args.scenario {
        Some(s) => Some(ScenarioSpec::load(s)?.identification()?.truth),
        None => None,
    };
    let title = Path::new(&name)
        .file_name()
        .map_or_else(|| name.clone(), |f| f.to_string_lossy().into_owned());
    let window = (args.from, args.to);
    let figure = match kind {
        CsvKind::Response => {
            if truth.is_some() {
                eprintln!("note: --scenario only adds true values to an estimates plot; {name} is a response");
            }
            let (t, x, z) = read_response(&name, &bytes)?;
            response_figure(&title, &t, &x, &z, window)?
        }
        CsvKind::Estimates => {
            let rows = read_estimates(&name, &bytes)?;
            estimates_figure(&title, &rows, truth.as_ref(), window)?
        }
    };
    save(&figure, &args.out)
}

/// The kind of CSV `bytes` holds, from its header line (module doc).
pub fn detect(name: &str, bytes: &[u8]) -> anyhow::Result<CsvKind> {
    let mut csv = csv_reader(bytes);
    let mut rec = csv::ByteRecord::new();
    if next_record(name, &mut csv, &mut rec)?.is_none() {
        bail!("{name}: the file is empty: expected a CSV header (t,x,z,... or t,m_x,...,rcond_z)");
    }
    let names: Vec<String> = rec.iter().map(normalise).collect();
    let has = |n: &str| names.iter().any(|h| h == n);
    if ESTIMATES_HEADER[1..].iter().any(|n| has(n)) {
        Ok(CsvKind::Estimates)
    } else if has("t") && (has("x") || has("z")) {
        Ok(CsvKind::Response)
    } else {
        bail!(
            "{name} line 1: unknown header `{}`: expected a response CSV from `rotorid simulate` \
             (t,x,z[,phi,phi_dot,phi_ddot]) or an estimates CSV from `rotorid identify` ({})",
            names.join(","),
            ESTIMATES_HEADER.join(",")
        )
    }
}

fn read_response(name: &str, bytes: &[u8]) -> anyhow::Result<(Vec<f64>, Vec<f64>, Vec<f64>)> {
    let mut r = ResponseReader::new(name, bytes, DEFAULT_TIME_TOLERANCE)?;
    let (mut t, mut x, mut z) = (Vec::new(), Vec::new(), Vec::new());
    while let Some(row) = r.next_row()? {
        t.push(row.t);
        x.push(row.x);
        z.push(row.z);
    }
    if t.is_empty() {
        bail!("{name}: the file has a header but no data rows");
    }
    Ok((t, x, z))
}

fn read_estimates(name: &str, bytes: &[u8]) -> anyhow::Result<Vec<EstimateRow>> {
    let mut r = EstimatesReader::new(name, bytes)?;
    let mut rows = Vec::new();
    while let Some(row) = r.next_row()? {
        rows.push(row);
    }
    if rows.is_empty() {
        bail!("{name}: the file has a header but no data rows");
    }
    Ok(rows)
}

/// The time window: the flags, else the data's extent; an error if no sample is inside.
fn window(t: &[f64], (from, to): (Option<f64>, Option<f64>)) -> anyhow::Result<(f64, f64)> {
    let t0 = from.unwrap_or(t[0]);
    let t1 = to.unwrap_or(t[t.len() - 1]);
    if !t.iter().any(|&v| v >= t0 && v <= t1) {
        bail!(
            "no sample in the window {t0} s to {t1} s: the file spans {} s to {} s",
            t[0],
            t[t.len() - 1]
        );
    }
    if t1 > t0 {
        Ok((t0, t1))
    } else {
        // a single sample: show a little around it
        Ok((t0 - 0.5, t1 + 0.5))
    }
}

/// x(t), z(t) and the orbit, side by side.
pub fn response_figure(
    title: &str,
    t: &[f64],
    x: &[f64],
    z: &[f64],
    window_flags: (Option<f64>, Option<f64>),
) -> anyhow::Result<Figure> {
    let (t0, t1) = window(t, window_flags)?;
    let inside: Vec<usize> = (0..t.len()).filter(|&i| t[i] >= t0 && t[i] <= t1).collect();
    let peak = inside
        .iter()
        .fold(0.0f64, |m, &i| m.max(x[i].abs()).max(z[i].abs()));
    let (f, prefix) = si_prefix(peak);
    let unit = format!("{prefix}m");
    let scaled = |v: &[f64]| v.iter().map(|y| y * f).collect::<Vec<f64>>();
    let time = Panel::new(
        "(a) displacement against time",
        "time t (s)",
        format!("displacement ({unit})"),
    )
    .with_series(vec![
        Series::solid("x (horizontal)", t.to_vec(), scaled(x), palette::BLUE),
        Series::solid("z (vertical)", t.to_vec(), scaled(z), palette::VERMILLION),
    ])
    .with_x_range(t0, t1);
    let ox: Vec<f64> = inside.iter().map(|&i| x[i] * f).collect();
    let oz: Vec<f64> = inside.iter().map(|&i| z[i] * f).collect();
    let orbit = Panel::new(
        format!("(b) orbit, t = {t0}-{t1} s"),
        format!("horizontal x ({unit})"),
        format!("vertical z ({unit})"),
    )
    .with_series(vec![Series::solid("", ox, oz, palette::BLUE).with_width(1)])
    .with_equal_aspect();
    Ok(Figure::new(format!("{title}: response"), vec![time, orbit])
        .side_by_side()
        .with_size(1600, 800))
}

/// m, c, k against time, both directions, the truth dashed when known.
pub fn estimates_figure(
    title: &str,
    rows: &[EstimateRow],
    truth: Option<&Truth>,
    window_flags: (Option<f64>, Option<f64>),
) -> anyhow::Result<Figure> {
    let t: Vec<f64> = rows.iter().map(|r| r.t).collect();
    let (t0, t1) = window(&t, window_flags)?;
    let column = |i: usize| -> Vec<f64> {
        rows.iter()
            .map(|r| r.values.to_array()[i].unwrap_or(f64::NAN))
            .collect()
    };
    let specs = [
        (
            "m",
            "mass m (kg)",
            0,
            3,
            truth.and_then(|tr| tr.m),
            truth.and_then(|tr| tr.m),
        ),
        (
            "c",
            "damping c (N s/m)",
            1,
            4,
            truth.and_then(|tr| tr.cx),
            truth.and_then(|tr| tr.cz),
        ),
        (
            "k",
            "stiffness k (N/m)",
            2,
            5,
            truth.and_then(|tr| tr.kx),
            truth.and_then(|tr| tr.kz),
        ),
    ];
    let mut panels = Vec::new();
    for (sym, label, ix, iz, tx, tz) in specs {
        let (vx, vz) = (column(ix), column(iz));
        let (lx, lz) = if sym == "m" {
            ("m from x".to_string(), "m from z".to_string())
        } else {
            (format!("{sym}x"), format!("{sym}z"))
        };
        let mut series = vec![
            Series::solid(lx, t.clone(), vx.clone(), palette::BLUE),
            Series::solid(lz, t.clone(), vz.clone(), palette::VERMILLION),
        ];
        match (tx, tz) {
            (Some(a), Some(b)) if a == b => {
                let l = if sym == "m" {
                    "true m".to_string()
                } else {
                    format!("true {sym}x = {sym}z")
                };
                series.push(Series::level(l, t0, t1, a, palette::BLACK));
            }
            _ => {
                if let Some(a) = tx {
                    series.push(Series::level(
                        format!("true {sym}x"),
                        t0,
                        t1,
                        a,
                        palette::BLACK,
                    ));
                }
                if let Some(b) = tz {
                    series.push(Series::level(
                        format!("true {sym}z"),
                        t0,
                        t1,
                        b,
                        palette::GREY,
                    ));
                }
            }
        }
        let mut panel = Panel::new("", "time t (s)", label)
            .with_series(series)
            .with_x_range(t0, t1);
        let refs: Vec<f64> = [tx, tz].into_iter().flatten().collect();
        let refs = if refs.is_empty() {
            [late_median(&t, &vx, t0, t1), late_median(&t, &vz, t0, t1)]
                .into_iter()
                .flatten()
                .collect()
        } else {
            refs
        };
        if !refs.is_empty() {
            let lo = refs.iter().fold(f64::INFINITY, |m, v| m.min(*v));
            let hi = refs.iter().fold(f64::NEG_INFINITY, |m, v| m.max(*v));
            panel = panel
                .with_y_limits(lo - Y_BAND * lo.abs(), hi + Y_BAND * hi.abs())
                .with_min_y_span(1e-3 * lo.abs().max(hi.abs()));
        }
        panels.push(panel);
    }
    let what = if truth.is_some() {
        "identified m, c, k (solid) and true values (dashed)"
    } else {
        "identified m, c, k"
    };
    Ok(Figure::new(format!("{title}: {what}"), panels).with_size(1400, 1200))
}

/// Median of the finite values of `v` in the last quarter of the window `t0..t1`.
fn late_median(t: &[f64], v: &[f64], t0: f64, t1: f64) -> Option<f64> {
    let from = t1 - 0.25 * (t1 - t0);
    let mut late: Vec<f64> = t
        .iter()
        .zip(v)
        .filter(|(&ti, vi)| ti >= from && ti <= t1 && vi.is_finite())
        .map(|(_, &vi)| vi)
        .collect();
    if late.is_empty() {
        return None;
    }
    late.sort_by(f64::total_cmp);
    Some(late[late.len() / 2])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn headers_pick_the_kind() {
        assert_eq!(
            detect("a.csv", b"t,x,z,phi,phi_dot,phi_ddot\n0,0,0,0,0,0\n").unwrap(),
            CsvKind::Response
        );
        assert_eq!(
            detect("a.csv", b"T [s], X [m], Z [m]\n").unwrap(),
            CsvKind::Response
        );
        assert_eq!(
            detect("a.csv", ESTIMATES_HEADER.join(",").as_bytes()).unwrap(),
            CsvKind::Estimates
        );
        let e = detect("a.csv", b"time,speed\n1,2\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("a.csv line 1: unknown header `time,speed`"),
            "{e}"
        );
        assert!(detect("a.csv", b"")
            .unwrap_err()
            .to_string()
            .contains("empty"));
    }

    #[test]
    fn late_median_ignores_gaps_and_early_transients() {
        let t: Vec<f64> = (0..100).map(f64::from).collect();
        let mut v: Vec<f64> = t
            .iter()
            .map(|x| if *x < 50.0 { 1e6 } else { 14.29 })
            .collect();
        v[90] = f64::NAN;
        assert_eq!(late_median(&t, &v, 0.0, 99.0), Some(14.29));
    }
}
