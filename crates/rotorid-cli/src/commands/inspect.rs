//! `rotorid inspect FILE`: the channels of a record in any format rotorid reads, with
//! their length, unit, sample rate and range, so a user can pick `--columns`; or, for a
//! scenario `.toml` of a finite-element rotor, the rotor its matrices file and `[rotor]`
//! make (degrees of freedom, bearings, unbalances), so a user sees it loads.

use std::fmt::Write as _;

use crate::io::tables;

/// Arguments of `rotorid inspect`.
#[derive(Debug, clap::Args)]
pub struct InspectArgs {
    /// A .csv, .mat, .tdms, .uff/.unv/.58, .npy, .npz or .parquet file; or a scenario .toml
    /// of a finite-element rotor.
    #[arg(value_name = "FILE")]
    pub file: String,

    /// A finite-element scenario: FILE is read as the response file of its rotor
    /// (docs/formats.md: t, the measured <node>.<dof> columns, phi, phi_dot, phi_ddot or
    /// the scenario's [speed]) with every check identification makes, and summarised.
    #[arg(long, value_name = "FE.toml")]
    pub scenario: Option<String>,
}

/// What `inspect` prints of one channel.
struct Summary {
    name: String,
    samples: usize,
    unit: Option<String>,
    /// From the channel's own time axis \[Hz\].
    axis_rate: Option<f64>,
    lo: f64,
    hi: f64,
    nan: usize,
    /// The first and last samples (the rate of a time channel).
    ends: Option<(f64, f64)>,
}

impl Summary {
    fn new(name: &str, unit: Option<&str>, axis: Option<rotorid_io::TimeAxis>) -> Self {
        Self {
            name: name.to_owned(),
            samples: 0,
            unit: unit.map(str::to_owned),
            axis_rate: axis.map(|a| 1.0 / a.increment),
            lo: f64::INFINITY,
            hi: f64::NEG_INFINITY,
            nan: 0,
            ends: None,
        }
    }

    /// Take the next samples of the channel.
    fn add(&mut self, data: &[f64]) {
        let (lo, hi, nan) = extremes(data);
        self.lo = self.lo.min(lo);
        self.hi = self.hi.max(hi);
        self.nan += nan;
        self.samples += data.len();
        if let (Some(&first), Some(&last)) = (data.first(), data.last()) {
            self.ends = Some((self.ends.map_or(first, |e| e.0), last));
        }
    }
}

/// Run `rotorid inspect`: one line per channel on stdout. A TDMS or Parquet file is read a
/// block of rows at a time (`rotorid_io::stream`), so a recording of any length can be
/// inspected; the others are read whole.
pub fn run(args: InspectArgs) -> anyhow::Result<()> {
    let toml = std::path::Path::new(&args.file)
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("toml"));
    if let Some(scenario) = &args.scenario {
        return fe_response(&args.file, scenario);
    }
    if toml {
        return finite_element(&args.file);
    }
    let (file, channels) = match rotorid_io::open_blocks(&args.file)? {
        Some(reader) => streamed(&args.file, reader)?,
        None => {
            let table = tables::read(&args.file)?;
            let channels = table
                .channels
                .iter()
                .map(|c| {
                    let mut s = Summary::new(&c.name, c.unit.as_deref(), c.axis);
                    s.add(&c.data);
                    s
                })
                .collect();
            (table.file, channels)
        }
    };
    let mut out = String::new();
    // (writing to a String cannot fail)
    let _ = writeln!(
        out,
        "{}: {} channel{}",
        file,
        channels.len(),
        if channels.len() == 1 { "" } else { "s" }
    );
    let _ = writeln!(
        out,
        "  {:<28} {:>10} {:<8} {:>14} {:>14} {:>14}",
        "channel", "samples", "unit", "rate [Hz]", "min", "max"
    );
    // the sample rate: a channel's own time axis, else the time channel t or time (found
    // as Table::channel finds it)
    let time = ["t", "time"]
        .iter()
        .find_map(|n| rotorid_io::table::index_named(&channels, |c| &c.name, n))
        .map(|i| &channels[i]);
    let rate_of_time = time.and_then(|t| {
        let (first, last) = t.ends?;
        (t.samples >= 2).then(|| (t.samples - 1) as f64 / (last - first))
    });
    for c in &channels {
        let rate = c.axis_rate.or(rate_of_time);
        let _ = writeln!(
            out,
            "  {:<28} {:>10} {:<8} {:>14} {:>14} {:>14}{}",
            c.name,
            c.samples,
            c.unit.as_deref().unwrap_or("-"),
            rate.filter(|r| r.is_finite())
                .map_or("-".to_owned(), |r| format!("{r:.6}")),
            if c.lo.is_finite() {
                format!("{:.6e}", c.lo)
            } else {
                "-".to_owned()
            },
            if c.hi.is_finite() {
                format!("{:.6e}", c.hi)
            } else {
                "-".to_owned()
            },
            if c.nan > 0 {
                format!("  ({} NaN)", c.nan)
            } else {
                String::new()
            }
        );
    }
    out!("{out}")?;
    Ok(())
}

/// Rows a block of `inspect` holds per channel (512 KiB of `f64`).
const BLOCK_ROWS: usize = 1 << 16;

/// The summaries of every channel of the file at `path`, which `reader` reads a block of
/// rows at a time (`rotorid_io::stream`). The channels are summed up side by side, as the
/// whole read decodes them: each thread (at most two) takes the next channel not yet taken
/// and reads it to its end through a reader of its own (the first thread through `reader`),
/// so no thread waits for another at every block. Of several channels that cannot be read,
/// the first in file order is the one reported. The reader's notes go to stderr as
/// `tables::read` prints them.
fn streamed(
    path: &str,
    reader: Box<dyn rotorid_io::RowBlocks>,
) -> anyhow::Result<(String, Vec<Summary>)> {
    tables::print_notes(reader.file(), reader.notes());
    let file = reader.file().to_owned();
    let infos = reader.channels().to_vec();
    let threads = std::thread::available_parallelism()
        .map_or(1, std::num::NonZeroUsize::get)
        .clamp(1, 2)
        .min(infos.len().max(1));
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results: Vec<std::sync::Mutex<Option<anyhow::Result<Summary>>>> =
        infos.iter().map(|_| std::sync::Mutex::new(None)).collect();
    let work = |mut r: Box<dyn rotorid_io::RowBlocks>| loop {
        let k = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let Some(info) = infos.get(k) else {
            return;
        };
        let mut s = Summary::new(&info.name, info.unit.as_deref(), info.axis);
        let read = rotorid_io::stream::for_each_block_of(&mut *r, &[k], BLOCK_ROWS, |_, rows| {
            s.add(&rows[0])
        });
        *results[k].lock().unwrap_or_else(|p| p.into_inner()) =
            Some(read.map(|()| s).map_err(Into::into));
    };
    std::thread::scope(|scope| -> anyhow::Result<()> {
        let mut readers = vec![reader];
        for _ in 1..threads {
            // (a format that streams opens again; should it not, one thread does it all)
            if let Some(r) = rotorid_io::open_blocks(path)? {
                readers.push(r);
            }
        }
        for r in readers {
            scope.spawn(|| work(r));
        }
        Ok(())
    })?;
    let mut channels = Vec::with_capacity(infos.len());
    for (r, info) in results.into_iter().zip(&infos) {
        let r = r.into_inner().unwrap_or_else(|p| p.into_inner());
        channels.push(
            r.ok_or_else(|| anyhow::anyhow!("{file}: channel {:?} was not read", info.name))??,
        );
    }
    Ok((file, channels))
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

/// `rotorid inspect FILE --scenario fe.toml`: FILE read as the response file of the
/// scenario's finite-element rotor (`crate::io::fe_response::read_fe_response`), one line
/// for the record and one per measured degree of freedom.
fn fe_response(path: &str, scenario: &str) -> anyhow::Result<()> {
    use crate::io::LoadScenario as _;
    let spec = crate::io::ScenarioSpec::load(scenario)?;
    let rotor = crate::io::finite_element::finite_element_of(&spec)?;
    let r = crate::io::fe_response::read_fe_response(
        path,
        &rotor,
        spec.speed_profile(),
        rotorid::pipeline::DEFAULT_TIME_TOLERANCE,
    )?;
    let n = r.len();
    let grid = rotorid::pipeline::TimeGrid::fit(&r.t, rotorid::pipeline::DEFAULT_TIME_TOLERANCE)?;
    let (lo, hi, _) = extremes(&r.phi_dot);
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{path}: response of the finite-element rotor of {scenario}: {} measured degrees of \
         freedom, {n} samples, dt = {:e} s, t = {:e} .. {:e} s, phi_dot = {lo:e} .. {hi:e} rad/s",
        r.dofs.len(),
        grid.dt,
        r.t[0],
        r.t[n - 1],
    );
    for (d, q) in r.dofs.iter().zip(&r.q) {
        let (lo, hi, _) = extremes(q);
        let rms = (q.iter().map(|v| v * v).sum::<f64>() / n as f64).sqrt();
        let _ = writeln!(
            out,
            "  {:<8} [{}]  min {lo:e}  max {hi:e}  RMS {rms:e}",
            d.to_string(),
            d.kind.unit()
        );
    }
    print!("{out}");
    Ok(())
}

/// `rotorid inspect fe.toml`: the finite-element rotor of a scenario, as its matrices file
/// and `[rotor]` make it.
fn finite_element(path: &str) -> anyhow::Result<()> {
    let r = crate::io::finite_element::load_finite_element(path)?;
    let m = &r.matrices;
    let mut nodes: Vec<u32> = m.dofs().iter().map(|d| d.node).collect();
    nodes.dedup();
    let mut out = String::new();
    let _ = writeln!(
        out,
        "{path}: finite-element rotor, {} degrees of freedom at {} nodes ({} .. {}); \
         C: {}, Ka: {}",
        m.n(),
        nodes.len(),
        m.dofs().iter().map(|d| d.node).min().unwrap_or(0),
        m.dofs().iter().map(|d| d.node).max().unwrap_or(0),
        if m.c().is_some() { "given" } else { "none" },
        if m.ka().is_some() { "given" } else { "none" },
    );
    let _ = writeln!(
        out,
        "  {:<12} {:>5} {:>13} {:>13} {:>13} {:>13} {:>13} {:>13} {:>13} {:>13}",
        "bearing",
        "node",
        "kxx [N/m]",
        "kxy [N/m]",
        "kyx [N/m]",
        "kyy [N/m]",
        "cxx [N s/m]",
        "cxy [N s/m]",
        "cyx [N s/m]",
        "cyy [N s/m]"
    );
    for (i, b) in r.bearings.iter().enumerate() {
        let _ = write!(out, "  {:<12} {:>5}", format!("bearing{i}"), b.node);
        for v in [b.kxx, b.kxy, b.kyx, b.kyy, b.cxx, b.cxy, b.cyx, b.cyy] {
            let _ = write!(out, " {v:>13.6e}");
        }
        let _ = writeln!(out);
    }
    let _ = writeln!(
        out,
        "  {:<12} {:>5} {:>13} {:>13}",
        "unbalance", "node", "mud [kg m]", "alpha [deg]"
    );
    for (j, u) in r.unbalances.iter().enumerate() {
        let _ = writeln!(
            out,
            "  {:<12} {:>5} {:>13.6e} {:>13.6}",
            format!("unbalance{j}"),
            u.node,
            u.mud,
            u.alpha.to_degrees()
        );
    }
    out!("{out}")?;
    Ok(())
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
