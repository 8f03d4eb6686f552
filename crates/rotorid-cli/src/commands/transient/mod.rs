//! `rotorid transient RAW... --scenario S.toml --out DIR` (or `--vectors table.csv`): a
//! run-up or coast-down reduced to order-tracked vectors (Bode and polar data), slow-roll
//! compensated, with the critical speeds, their API 684 amplification factors and
//! separation margins (docs/transient.md).
//!
//! A thin caller: the arguments, the files read (`rotorid_io::raw` for raw records, whose
//! scenario's `[acquisition]` describes them; `rotorid_io::csv::bode` for a table), the
//! analysis of the library (`rotorid::transient::analysis`: order tracking, slow-roll
//! compensation, bins, criticals and margins, the same code as the Python package's), then
//! the files (`rotorid::transient::report` gives transient.json and the bode.csv rows) and
//! the figures. Outputs in DIR: `bode.csv`, `transient.json`, `report.html` and the figures
//! (PNG and SVG). Everything is computed before the first file is written, so an error
//! leaves DIR as it was.

mod figures;
mod output;

use std::path::{Path, PathBuf};

use anyhow::{bail, Context as _};
use rotorid::acquisition::{Acquisition, RawRecord, TimeBase};
use rotorid::transient::analysis::{
    analyse_table, Analysis, RawAnalysis, SensorCritical, Settings, SlowRollChoice, TableRow,
};
use rotorid::transient::critical::Position;
use rotorid::transient::slow_roll;
use rotorid::transient::OrderSettings;
use rotorid_io::csv::bode::{read_bode, Amplitude};

use crate::io::tables;
use crate::io::LoadScenario as _;
use crate::io::ScenarioSpec;

const TRANSIENT_HELP: &str = "\
Phase lag: the angle from the keyphasor event to the next positive peak of the nX
component, in degrees of the nX cycle, against the rotation (as machinery-protection
systems report it). Amplitudes are zero-to-peak in m in bode.csv and transient.json; the
figures show um peak-to-peak. API 684: AF = Nc / (N2 - N1) from the half-power speeds;
required separation margin 0 for AF < 2.5, else below the operating range
min(16, 17 (1 - 1/(AF - 1.5))) % and above it min(26, 10 + 17 (1 - 1/(AF - 1.5))) %.

Examples:
  rotorid transient runup.csv --scenario rig.toml --operating-rpm 3000:3600 --out runup/
  rotorid transient part1.tdms part2.tdms --scenario rig.toml --slow-roll 300:500 --out out/
  rotorid transient --vectors bode_export.csv --amplitude pk-pk --out out/";

/// Where the runout comes from (`--slow-roll`).
#[derive(Debug, Clone, PartialEq)]
pub enum SlowRollArg {
    /// The revolutions of a low speed range picked from the record.
    Auto,
    /// No compensation.
    None,
    /// A slow-roll record.
    File(String),
    /// The revolutions of this speed range \[rev/min\].
    Range(f64, f64),
}

fn parse_range(s: &str, what: &str) -> Result<(f64, f64), String> {
    let (a, b) = s
        .split_once(':')
        .ok_or_else(|| format!("{what} {s:?}: give MIN:MAX in rev/min, e.g. 3000:3600"))?;
    let p = |v: &str| {
        v.trim()
            .parse::<f64>()
            .map_err(|_| format!("{what} {s:?}: {v:?} is not a number (rev/min)"))
    };
    let (a, b) = (p(a)?, p(b)?);
    if !(a.is_finite() && b.is_finite() && a >= 0.0 && b > a) {
        return Err(format!(
            "{what} {s:?} is out of range: must be MIN:MAX with 0 <= MIN < MAX (rev/min)"
        ));
    }
    Ok((a, b))
}

fn parse_slow_roll(s: &str) -> Result<SlowRollArg, String> {
    match s {
        "auto" => Ok(SlowRollArg::Auto),
        "none" => Ok(SlowRollArg::None),
        _ if s.contains(':') && parse_range(s, "--slow-roll").is_ok() => {
            let (a, b) = parse_range(s, "--slow-roll")?;
            Ok(SlowRollArg::Range(a, b))
        }
        _ if s.contains(':') && !Path::new(s).exists() => {
            parse_range(s, "--slow-roll").map(|_| unreachable!())
        }
        _ => Ok(SlowRollArg::File(s.to_owned())),
    }
}

fn parse_operating(s: &str) -> Result<(f64, f64), String> {
    let (a, b) = parse_range(s, "--operating-rpm")?;
    if a <= 0.0 {
        return Err(format!(
            "--operating-rpm {s:?}: MIN must be > 0 rev/min (the margin is relative to it)"
        ));
    }
    Ok((a, b))
}

/// The amplitude convention of a `--vectors` table.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum AmplitudeArg {
    /// Zero-to-peak.
    Pk,
    /// Peak-to-peak.
    #[value(name = "pk-pk")]
    PkPk,
}

/// Arguments of `rotorid transient`.
#[derive(Debug, clap::Args)]
#[command(after_long_help = TRANSIENT_HELP)]
pub struct TransientArgs {
    /// Raw records of one run-up or coast-down, in time order (.csv, .mat, .tdms, .uff,
    /// .npy/.npz, .parquet), with the columns the scenario's [acquisition] names.
    #[arg(
        value_name = "RAW",
        required_unless_present = "vectors",
        conflicts_with = "vectors"
    )]
    pub inputs: Vec<String>,

    /// The scenario TOML with an [acquisition] table (nothing else is needed).
    #[arg(long, value_name = "FILE.toml", required_unless_present = "vectors")]
    pub scenario: Option<String>,

    /// A 1X table instead of raw records: speed_rpm,sensor and amplitude,phase_lag_deg or
    /// re,im; optional unit (m, mm, um, mil) and std.
    #[arg(long, value_name = "table.csv", conflicts_with_all = ["scenario", "slow_roll", "bin_rpm", "orders"])]
    pub vectors: Option<String>,

    /// Amplitudes of the --vectors table: zero-to-peak (pk) or peak-to-peak (pk-pk).
    #[arg(long, value_enum, default_value = "pk", requires = "vectors")]
    pub amplitude: AmplitudeArg,

    /// Unit of a --vectors table without a unit column or header suffix (m, mm, um, mil).
    #[arg(long, value_name = "UNIT", requires = "vectors")]
    pub unit: Option<String>,

    /// Runout: auto (a low-speed range of the record, named in the output), none, a
    /// slow-roll record FILE, or RPM_MIN:RPM_MAX. Default: the scenario's
    /// [acquisition.runout] slow_roll record when it names one, else auto.
    #[arg(long, value_name = "auto|none|FILE|RPM_MIN:RPM_MAX", value_parser = parse_slow_roll)]
    pub slow_roll: Option<SlowRollArg>,

    /// Orders to track (1 = 1X), comma-separated.
    #[arg(long, value_name = "N,N", value_delimiter = ',', default_value = "1,2")]
    pub orders: Vec<u32>,

    /// The machine's operating speed range, for API 684 separation margins.
    #[arg(long, value_name = "MIN:MAX", value_parser = parse_operating)]
    pub operating_rpm: Option<(f64, f64)>,

    /// Average the revolutions in speed bins of this width [rev/min] (default: one row per
    /// revolution).
    #[arg(long, value_name = "R")]
    pub bin_rpm: Option<f64>,

    /// Output directory (created if needed).
    #[arg(long, short, value_name = "DIR")]
    pub out: PathBuf,
}

/// The runout choice of `args` (module doc): `--slow-roll`, else the scenario's
/// `[acquisition.runout] slow_roll` record when it names one, else auto; a record is read
/// here.
fn slow_roll_choice(
    args: &TransientArgs,
    spec: &ScenarioSpec,
    acq: &Acquisition,
) -> anyhow::Result<SlowRollChoice> {
    let read = |path: &str, label: &str| -> anyhow::Result<SlowRollChoice> {
        let record = raw_record_file(path, acq)?;
        Ok(SlowRollChoice::Record {
            label: label.to_owned(),
            record,
        })
    };
    Ok(match (&args.slow_roll, &acq.slow_roll) {
        (Some(SlowRollArg::Auto), _) | (None, None) => SlowRollChoice::Auto,
        (Some(SlowRollArg::None), _) => SlowRollChoice::None,
        (Some(SlowRollArg::Range(a, b)), _) => SlowRollChoice::Range(*a, *b),
        (Some(SlowRollArg::File(f)), _) => read(f, f)?,
        (None, Some(rel)) => {
            let path = rotorid_io::raw::beside(spec.origin(), rel);
            read(&path.to_string_lossy(), rel)
                .with_context(|| format!("the slow-roll record of [acquisition.runout] ({rel})"))?
        }
    })
}

/// The raw record of the file at `path` for `acq` (`rotorid_io::raw`), its notes on
/// stderr.
fn raw_record_file(path: &str, acq: &Acquisition) -> anyhow::Result<RawRecord> {
    let time = match &acq.time {
        TimeBase::Column(c) => Some(c.as_str()),
        TimeBase::RateHz(_) => None,
    };
    let raw = rotorid_io::raw::read(path, &acq.columns(), time, &acq.probes[0].column)?;
    tables::print_notes(path, &raw.notes);
    Ok(RawRecord {
        columns: raw.columns,
    })
}

fn analyse_raw(args: &TransientArgs, settings: Settings) -> anyhow::Result<Analysis> {
    let path = args.scenario.as_deref().expect("clap requires it");
    let spec = ScenarioSpec::load(path)?;
    let acq = spec.acquisition().ok_or_else(|| {
        anyhow::anyhow!(
            "{}: has no [acquisition] table: it names the probe and keyphasor columns (see docs/acquisition.md)",
            spec.origin()
        )
    })?;
    let mut analysis = RawAnalysis::new(acq, settings).context("--orders")?;
    for input in &args.inputs {
        let raw = raw_record_file(input, acq)?;
        // given away: its columns are moved into the tracking, not copied
        analysis.add_record_owned(input, raw)?;
    }
    let choice = slow_roll_choice(args, &spec, acq)?;
    Ok(analysis.finish(choice)?)
}

fn analyse_vectors(
    args: &TransientArgs,
    file: &str,
    settings: &Settings,
) -> anyhow::Result<Analysis> {
    let amp = match args.amplitude {
        AmplitudeArg::Pk => Amplitude::Peak,
        AmplitudeArg::PkPk => Amplitude::PeakToPeak,
    };
    let input = std::fs::File::open(file).with_context(|| format!("cannot open {file}"))?;
    let rows = read_bode(
        file,
        std::io::BufReader::new(input),
        amp,
        args.unit.as_deref(),
    )?;
    let rows = rows
        .into_iter()
        .map(|r| TableRow {
            speed_rpm: r.speed_rpm,
            sensor: r.sensor,
            re: r.re,
            im: r.im,
            std: r.std,
        })
        .collect();
    Ok(analyse_table(file, rows, settings)?)
}

fn position_name(p: Position) -> &'static str {
    match p {
        Position::Below => "below",
        Position::Inside => "inside",
        Position::Above => "above",
    }
}

/// Run `rotorid transient`.
pub fn run(args: TransientArgs) -> anyhow::Result<()> {
    if let Some(w) = args.bin_rpm {
        if !(w.is_finite() && w > 0.0) {
            bail!("--bin-rpm {w} is out of range: must be finite and > 0 (rev/min)");
        }
    }
    let settings = Settings {
        order: OrderSettings {
            orders: args.orders.clone(),
            ..OrderSettings::default()
        },
        bin_rpm: args.bin_rpm,
        operating_rpm: args.operating_rpm,
        ..Settings::default()
    };
    let a = match &args.vectors {
        Some(file) => analyse_vectors(&args, file, &settings)?,
        None => analyse_raw(&args, settings)?,
    };
    for n in &a.notes {
        eprintln!("note: {n}");
    }
    // everything computed: now the files
    let figs = figures::render(&a)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create output directory {}", args.out.display()))?;
    output::write_bode_csv(&args.out, &a)?;
    let json = rotorid::transient::report::transient_json(&a, &figs.names());
    let written = figs.save(&args.out)?;
    output::write_json(&args.out, &json)?;
    output::write_report(&args.out, &json, &figs.report_figures())?;
    // the numbers that matter, on stdout
    let (lo, hi) = a.speed_range();
    outln!(
        "{} from {:.0} to {:.0} rpm, {} points per sensor{}",
        a.direction.as_str().replace('_', "-"),
        lo,
        hi,
        a.sensors[0].points.len(),
        match (a.bin_rpm, a.keyphasor.is_empty()) {
            (Some(w), _) => format!(" (bins of {w} rpm)"),
            (None, false) => " (one per revolution)".to_string(),
            (None, true) => " (the table's rows)".to_string(),
        }
    )?;
    for s in &a.sensors {
        if let Some(sr) = &s.slow_roll {
            outln!(
                "{}: runout {} (from {})",
                s.name,
                sr.orders
                    .iter()
                    .zip(&sr.vectors)
                    .map(|(n, v)| format!(
                        "{n}X {:.3} um pk-pk at {:.0} deg",
                        2e6 * v.norm(),
                        (-v.arg()).to_degrees().rem_euclid(360.0)
                    ))
                    .collect::<Vec<_>>()
                    .join(", "),
                slow_roll::describe(&sr.source)
            )?;
        }
        if s.criticals.is_empty() {
            outln!("{}: no critical speed in the record's range", s.name)?;
        }
        for SensorCritical {
            critical: c,
            margin: m,
        } in &s.criticals
        {
            let af = match (c.amplification_factor, c.amplification_factor_std) {
                (Some(af), Some(sd)) => format!(
                    "AF {}, damping ratio {}",
                    output::pm(af, sd),
                    output::pm(
                        c.damping_ratio.unwrap_or(f64::NAN),
                        c.damping_ratio_std.unwrap_or(f64::NAN)
                    )
                ),
                _ => "AF undetermined (a half-power speed is outside the record)".to_string(),
            };
            outln!(
                "{}: critical {} rpm, {} um pk-pk, phase lag {:.0} deg, {}",
                s.name,
                output::pm(c.rpm, c.rpm_std),
                output::pm(2e6 * c.amplitude, 2e6 * c.amplitude_std),
                c.phase_lag_deg,
                af
            )?;
            if let Some(m) = m {
                outln!(
                    "    separation margin {:.1} % ({} the operating range), API 684 requires {:.1} %: {}",
                    m.separation_pct,
                    position_name(m.position),
                    m.required_pct,
                    if m.ok { "met" } else { "NOT MET" }
                )?;
            }
        }
    }
    outln!(
        "wrote {}: bode.csv, transient.json, report.html, {}",
        args.out.display(),
        written.join(", ")
    )?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slow_roll_and_ranges_parse_or_say_why() {
        assert_eq!(parse_slow_roll("auto"), Ok(SlowRollArg::Auto));
        assert_eq!(parse_slow_roll("none"), Ok(SlowRollArg::None));
        assert_eq!(
            parse_slow_roll("300:500"),
            Ok(SlowRollArg::Range(300.0, 500.0))
        );
        assert_eq!(
            parse_slow_roll("sr.csv"),
            Ok(SlowRollArg::File("sr.csv".into()))
        );
        let e = parse_slow_roll("500:300").unwrap_err();
        assert!(e.contains("0 <= MIN < MAX"), "{e}");
        assert!(parse_operating("0:3600").is_err());
        assert_eq!(parse_operating("3000:3600"), Ok((3000.0, 3600.0)));
    }
}
