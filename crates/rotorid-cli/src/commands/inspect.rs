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
        let (lo, hi, nan) = extremes(&c.data);
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

/// The least and greatest values of `data` other than NaN (infinities when there are none)
/// and the number of NaN, in one pass written so that it vectorises (a NaN fails both
/// comparisons, so it never replaces an extreme).
fn extremes(data: &[f64]) -> (f64, f64, usize) {
    const L: usize = 8;
    let mut lo = [f64::INFINITY; L];
    let mut hi = [f64::NEG_INFINITY; L];
    let mut nan = [0usize; L];
    let mut chunks = data.chunks_exact(L);
    for c in &mut chunks {
        for l in 0..L {
            let v = c[l];
            lo[l] = if v < lo[l] { v } else { lo[l] };
            hi[l] = if v > hi[l] { v } else { hi[l] };
            nan[l] += usize::from(v.is_nan());
        }
    }
    for (l, &v) in chunks.remainder().iter().enumerate() {
        lo[l] = if v < lo[l] { v } else { lo[l] };
        hi[l] = if v > hi[l] { v } else { hi[l] };
        nan[l] += usize::from(v.is_nan());
    }
    (
        lo.into_iter().fold(f64::INFINITY, f64::min),
        hi.into_iter().fold(f64::NEG_INFINITY, f64::max),
        nan.into_iter().sum(),
    )
}

#[cfg(test)]
mod tests {
    use super::extremes;

    /// Against the plain filter-and-fold, on lengths around the lane count, with NaN and
    /// infinities in every position.
    #[test]
    fn extremes_are_those_of_a_plain_fold() {
        let plain = |d: &[f64]| {
            let (lo, hi) = d
                .iter()
                .filter(|v| !v.is_nan())
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
                    (lo.min(v), hi.max(v))
                });
            (lo, hi, d.iter().filter(|v| v.is_nan()).count())
        };
        let pool = [
            1.5,
            -2.0,
            f64::NAN,
            7.25,
            f64::INFINITY,
            -1e300,
            f64::NEG_INFINITY,
            3.0,
        ];
        for n in 0..40 {
            for shift in 0..pool.len() {
                let d: Vec<f64> = (0..n)
                    .map(|i| pool[(i * 5 + shift) % pool.len()] * (i as f64 + 1.0))
                    .collect();
                let (a, b) = (extremes(&d), plain(&d));
                assert_eq!(
                    (a.0.to_bits(), a.1.to_bits(), a.2),
                    (b.0.to_bits(), b.1.to_bits(), b.2),
                    "{d:?}"
                );
            }
        }
        let nans = [f64::NAN; 11];
        assert_eq!(extremes(&nans).2, 11);
        assert!(extremes(&nans).0.is_infinite() && extremes(&nans).1.is_infinite());
    }
}
