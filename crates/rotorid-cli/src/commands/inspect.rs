//! `rotorid inspect FILE`: the channels of a record in any format rotorid reads, with
//! their length, unit, sample rate and range, so a user can pick `--columns`.

use std::fmt::Write as _;

use crate::io::tables;

/// Arguments of `rotorid inspect`.
#[derive(Debug, clap::Args)]
pub struct InspectArgs {
    /// A .csv, .mat, .tdms, .uff/.unv/.58, .npy, .npz or .parquet file.
    #[arg(value_name = "FILE")]
    pub file: String,
}

/// Run `rotorid inspect`: one line per channel on stdout.
pub fn run(args: InspectArgs) -> anyhow::Result<()> {
    let table = tables::read(&args.file)?;
    let mut out = String::new();
    // (writing to a String cannot fail)
    let _ = writeln!(
        out,
        "{}: {} channel{}",
        table.file,
        table.channels.len(),
        if table.channels.len() == 1 { "" } else { "s" }
    );
    let _ = writeln!(
        out,
        "  {:<28} {:>10} {:<8} {:>14} {:>14} {:>14}",
        "channel", "samples", "unit", "rate [Hz]", "min", "max"
    );
    // the sample rate: a channel's own time axis, else the time channel t or time
    let time = ["t", "time"].iter().find_map(|n| table.channel(n));
    let rate_of_time = time.and_then(|t| {
        let n = t.data.len();
        (n >= 2).then(|| (n - 1) as f64 / (t.data[n - 1] - t.data[0]))
    });
    for c in &table.channels {
        let rate = c.axis.map(|a| 1.0 / a.increment).or(rate_of_time);
        let (lo, hi) = c
            .data
            .iter()
            .filter(|v| !v.is_nan())
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            });
        let nan = c.data.iter().filter(|v| v.is_nan()).count();
        let _ = writeln!(
            out,
            "  {:<28} {:>10} {:<8} {:>14} {:>14} {:>14}{}",
            c.name,
            c.data.len(),
            c.unit.as_deref().unwrap_or("-"),
            rate.filter(|r| r.is_finite())
                .map_or("-".to_owned(), |r| format!("{r:.6}")),
            if lo.is_finite() {
                format!("{lo:.6e}")
            } else {
                "-".to_owned()
            },
            if hi.is_finite() {
                format!("{hi:.6e}")
            } else {
                "-".to_owned()
            },
            if nan > 0 {
                format!("  ({nan} NaN)")
            } else {
                String::new()
            }
        );
    }
    out!("{out}")?;
    Ok(())
}
