//! `rotorid transient RAW... --scenario S.toml --out DIR` (or `--vectors table.csv`): a
//! run-up or coast-down reduced to order-tracked vectors (Bode and polar data), slow-roll
//! compensated, with the critical speeds, their API 684 amplification factors and
//! separation margins (docs/transient.md).
//!
//! Raw records are described by the scenario's `[acquisition]` (the scenario may hold
//! nothing else): each probe's nX vectors per revolution (`rotorid::transient::order`),
//! the runout subtracted (`rotorid::transient::slow_roll`), the criticals of each probe's
//! compensated 1X (`rotorid::transient::critical`). Outputs in DIR: `bode.csv`,
//! `transient.json`, `report.html` and the figures (PNG and SVG). Everything is computed
//! before the first file is written, so an error leaves DIR as it was.

mod figures;
mod output;

use std::path::{Path, PathBuf};

use anyhow::{bail, Context as _};
use rotorid::acquisition::{Acquisition, Which};
use rotorid::model::rad_per_s_to_rpm;
use rotorid::transient::critical::Position;
use rotorid::transient::order::{bin, C64};
use rotorid::transient::slow_roll::{self, SlowRoll, SlowRollSource};
use rotorid::transient::{
    criticals, separation_margin, track_record, Critical, CriticalSettings, Margin, OrderSettings,
    Tracked, TransientError,
};
use rotorid_io::csv::bode::{read_bode, Amplitude};

use crate::io::tables;
use crate::io::LoadScenario as _;
use crate::io::ScenarioSpec;

/// The least relative speed change (max - min over the mean) of a Bode record \[%\].
pub const MIN_SPEED_CHANGE_PCT: f64 = 10.0;

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

/// One point of a sensor's Bode data.
#[derive(Debug, Clone, PartialEq)]
pub struct Point {
    /// Mid time of the revolution or bin \[s\] (None from a table).
    pub t: Option<f64>,
    /// Speed \[rev/min\].
    pub rpm: f64,
    /// Vectors per order as measured \[m\].
    pub raw: Vec<C64>,
    /// Vectors per order, runout subtracted \[m\].
    pub comp: Vec<C64>,
    /// Standard deviation of each of re and im of `comp` per order \[m\]; NaN unknown.
    pub std: Vec<f64>,
    /// The probe's gap (DC) \[m\], raw records only.
    pub dc: Option<f64>,
}

/// One sensor's data and results.
#[derive(Debug, Clone, PartialEq)]
pub struct Sensor {
    /// Its name (the probe's column, or the table's sensor).
    pub name: String,
    /// The probe's angle from +x towards +z \[deg\] (raw records).
    pub angle_deg: Option<f64>,
    /// The orders of each point's vectors.
    pub orders: Vec<u32>,
    /// The points, in time (or table) order.
    pub points: Vec<Point>,
    /// The runout subtracted.
    pub slow_roll: Option<SlowRoll>,
    /// Its criticals (1X) with their margins.
    pub criticals: Vec<(Critical, Option<Margin>)>,
}

/// Everything a run computes.
#[derive(Debug, Clone)]
pub struct Analysis {
    /// The inputs as given.
    pub sources: Vec<String>,
    /// run_up, coast_down or mixed.
    pub direction: &'static str,
    /// The sensors.
    pub sensors: Vec<Sensor>,
    /// The keyphasor reports per record (raw records).
    pub keyphasor: Vec<rotorid::acquisition::KeyphasorReport>,
    /// Per sample data for the spectra (raw records): t \[s\], omega \[rad/s\], each probe's
    /// displacement \[m\], per record.
    pub samples: Vec<Samples>,
    /// Notes for the reader (also on stderr).
    pub notes: Vec<String>,
    /// The operating range \[rev/min\].
    pub operating_rpm: Option<(f64, f64)>,
    /// The bin width \[rev/min\].
    pub bin_rpm: Option<f64>,
    /// The probe angles \[rad\] of the XY pair, when two probes.
    pub pair_angles: Option<[f64; 2]>,
    /// Whether the probes are DC-coupled (their mean voltage is a gap voltage: at least
    /// [`DC_COUPLED_V`] in magnitude on each).
    pub dc_coupled: bool,
}

/// A probe whose mean voltage reaches this magnitude \[V\] is taken as DC-coupled (a gap
/// voltage; an AC-coupled channel averages to about 0 V).
pub const DC_COUPLED_V: f64 = 0.5;

/// The samples of one record.
#[derive(Debug, Clone)]
pub struct Samples {
    /// Time \[s\].
    pub t: Vec<f64>,
    /// Shaft speed \[rad/s\].
    pub omega: Vec<f64>,
    /// Each probe's displacement towards it \[m\].
    pub displacement: Vec<Vec<f64>>,
}

fn speed_check(rpm: impl Iterator<Item = f64>) -> Result<(), TransientError> {
    let (mut lo, mut hi, mut sum, mut n) = (f64::INFINITY, f64::NEG_INFINITY, 0.0, 0usize);
    for r in rpm {
        lo = lo.min(r);
        hi = hi.max(r);
        sum += r;
        n += 1;
    }
    let mean = sum / n.max(1) as f64;
    let change = (hi - lo) / mean * 100.0;
    if n == 0 || change.is_nan() || change < MIN_SPEED_CHANGE_PCT {
        return Err(TransientError::SpeedTooSteady {
            min_rpm: lo,
            max_rpm: hi,
            change_pct: if change.is_finite() { change } else { 0.0 },
            needed_pct: MIN_SPEED_CHANGE_PCT,
        });
    }
    Ok(())
}

fn direction(rpm: &[f64]) -> &'static str {
    let n = rpm.len();
    if n < 2 {
        return "mixed";
    }
    let k = (n / 10).max(1);
    let head = rpm[..k].iter().sum::<f64>() / k as f64;
    let tail = rpm[n - k..].iter().sum::<f64>() / k as f64;
    let (lo, hi) = rpm
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let span = hi - lo;
    if tail - head > 0.5 * span {
        "run_up"
    } else if head - tail > 0.5 * span {
        "coast_down"
    } else {
        "mixed"
    }
}

/// The probes of `acq` to track: both, or the one of a single-probe scenario.
fn probe_indices(acq: &Acquisition) -> &'static [usize] {
    if acq.single_probe {
        &[0]
    } else {
        &[0, 1]
    }
}

/// The raw records tracked, concatenated per probe, with their samples.
fn track_raw(
    args: &TransientArgs,
    acq: &Acquisition,
    settings: &OrderSettings,
) -> anyhow::Result<(
    Vec<Tracked>,
    Vec<rotorid::acquisition::KeyphasorReport>,
    Vec<Samples>,
)> {
    let mut tracked: Vec<Tracked> = Vec::new();
    let mut reports = Vec::new();
    let mut samples = Vec::new();
    for input in &args.inputs {
        let table = tables::read(input)?;
        let raw = tables::raw_record(&table, acq)?;
        drop(table);
        let r = track_record(&raw, acq, probe_indices(acq), settings, Which::Running)
            .with_context(|| format!("{input}: order tracking"))?;
        for (k, p) in r.probes.into_iter().enumerate() {
            match tracked.get_mut(k) {
                Some(t) => t.revolutions.extend(p.tracked.revolutions),
                None => tracked.push(p.tracked),
            }
        }
        reports.push(r.keyphasor);
        samples.push(Samples {
            t: r.t,
            omega: r.omega,
            displacement: r.displacement,
        });
    }
    Ok((tracked, reports, samples))
}

/// The runout of probe `k` per `--slow-roll` (module doc).
fn slow_roll_of(
    args: &TransientArgs,
    spec: &ScenarioSpec,
    acq: &Acquisition,
    settings: &OrderSettings,
    tracked: &[Tracked],
    notes: &mut Vec<String>,
) -> anyhow::Result<Vec<Option<SlowRoll>>> {
    let choice = match (&args.slow_roll, &acq.slow_roll) {
        (Some(c), _) => c.clone(),
        (None, Some(_)) => SlowRollArg::File(String::new()),
        (None, None) => SlowRollArg::Auto,
    };
    let all_rpm: Vec<f64> = tracked[0].revolutions.iter().map(|r| r.rpm()).collect();
    match choice {
        SlowRollArg::None => {
            notes.push(
                "no slow-roll compensation (--slow-roll none): the vectors are as measured".into(),
            );
            Ok(vec![None; tracked.len()])
        }
        SlowRollArg::File(f) => {
            let (label, raw) = if f.is_empty() {
                let rel = acq.slow_roll.clone().unwrap_or_default();
                let raw = tables::slow_roll(spec, acq)?.expect("the scenario names one");
                (rel, raw)
            } else {
                let table = tables::read(&f)?;
                (f.clone(), tables::raw_record(&table, acq)?)
            };
            let r = track_record(&raw, acq, probe_indices(acq), settings, Which::SlowRoll)
                .with_context(|| format!("{label}: order tracking of the slow-roll record"))?;
            let out = r
                .probes
                .iter()
                .map(|p| slow_roll::from_record(&p.tracked, &label).map(Some))
                .collect::<Result<Vec<_>, _>>()
                .with_context(|| format!("{label}: the slow-roll record"))?;
            Ok(out)
        }
        SlowRollArg::Range(a, b) => tracked
            .iter()
            .map(|t| {
                slow_roll::from_revolutions(
                    t,
                    a,
                    b,
                    SlowRollSource::Range {
                        min_rpm: a,
                        max_rpm: b,
                    },
                )
                .map(Some)
            })
            .collect::<Result<Vec<_>, _>>()
            .context("--slow-roll"),
        SlowRollArg::Auto => {
            let (a, b) = slow_roll::auto_range(&all_rpm).context("no revolution")?;
            notes.push(format!(
                "slow roll: the runout is taken from the revolutions from {a:.1} to {b:.1} rpm (the record's lowest speeds, picked automatically; --slow-roll FILE or RPM_MIN:RPM_MAX overrides)"
            ));
            tracked
                .iter()
                .map(|t| {
                    slow_roll::from_revolutions(
                        t,
                        a,
                        b,
                        SlowRollSource::Auto {
                            min_rpm: a,
                            max_rpm: b,
                        },
                    )
                    .map(Some)
                })
                .collect::<Result<Vec<_>, _>>()
                .context("--slow-roll auto")
        }
    }
}

fn analyse_raw(args: &TransientArgs) -> anyhow::Result<Analysis> {
    let path = args.scenario.as_deref().expect("clap requires it");
    let spec = ScenarioSpec::load(path)?;
    let acq = spec.acquisition().ok_or_else(|| {
        anyhow::anyhow!(
            "{}: has no [acquisition] table: it names the probe and keyphasor columns (see docs/acquisition.md)",
            spec.origin()
        )
    })?;
    let settings = OrderSettings {
        orders: args.orders.clone(),
        ..OrderSettings::default()
    };
    settings.validate().context("--orders")?;
    let (tracked, keyphasor, samples) = track_raw(args, acq, &settings)?;
    speed_check(tracked[0].revolutions.iter().map(|r| r.rpm()))
        .with_context(|| args.inputs.join(", "))?;
    let mut notes = Vec::new();
    if acq.single_probe {
        notes.push(format!(
            "one probe ({}): everything but the full spectrum and the shaft centreline (they need an XY pair)",
            acq.probes[0].column
        ));
    }
    let srs = slow_roll_of(args, &spec, acq, &settings, &tracked, &mut notes)?;
    let mut sensors = Vec::new();
    for (k, (t, sr)) in tracked.iter().zip(srs).enumerate() {
        let comp = match &sr {
            Some(s) => slow_roll::compensate(t, s),
            None => t.clone(),
        };
        let (raw, comp) = match args.bin_rpm {
            Some(w) => (bin(t, w)?, bin(&comp, w)?),
            None => (t.clone(), comp),
        };
        let points = raw
            .revolutions
            .iter()
            .zip(&comp.revolutions)
            .map(|(r, c)| Point {
                t: Some(0.5 * (r.t_start + r.t_end)),
                rpm: rad_per_s_to_rpm(c.speed),
                raw: r.vectors.clone(),
                comp: c.vectors.clone(),
                std: c.std.clone(),
                dc: Some(r.dc),
            })
            .collect();
        let p = &acq.probes[k];
        sensors.push(Sensor {
            name: p.column.clone(),
            angle_deg: Some(p.angle.to_degrees()),
            orders: settings.orders.clone(),
            points,
            slow_roll: sr,
            criticals: Vec::new(),
        });
    }
    let rpm: Vec<f64> = sensors[0].points.iter().map(|p| p.rpm).collect();
    let dc_coupled = !acq.single_probe
        && sensors.iter().zip(&acq.probes).all(|(s, p)| {
            let n = s.points.len().max(1) as f64;
            let volts = s.points.iter().filter_map(|q| q.dc).sum::<f64>() / n * p.sensitivity;
            volts.abs() >= DC_COUPLED_V
        });
    Ok(Analysis {
        sources: args.inputs.clone(),
        direction: direction(&rpm),
        sensors,
        keyphasor,
        samples,
        notes,
        operating_rpm: args.operating_rpm,
        bin_rpm: args.bin_rpm,
        pair_angles: (!acq.single_probe).then(|| [acq.probes[0].angle, acq.probes[1].angle]),
        dc_coupled,
    })
}

fn analyse_table(args: &TransientArgs, file: &str) -> anyhow::Result<Analysis> {
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
    let mut sensors: Vec<Sensor> = Vec::new();
    for r in rows {
        let v = C64::new(r.re, r.im);
        let std = r
            .std
            .map_or(f64::NAN, |(a, b)| (0.5 * (a * a + b * b)).sqrt());
        let point = Point {
            t: None,
            rpm: r.speed_rpm,
            raw: vec![v],
            comp: vec![v],
            std: vec![std],
            dc: None,
        };
        match sensors.iter_mut().find(|s| s.name == r.sensor) {
            Some(s) => s.points.push(point),
            None => sensors.push(Sensor {
                name: r.sensor.clone(),
                angle_deg: None,
                orders: vec![1],
                points: vec![point],
                slow_roll: None,
                criticals: Vec::new(),
            }),
        }
    }
    for s in &sensors {
        speed_check(s.points.iter().map(|p| p.rpm))
            .with_context(|| format!("{file}: sensor {:?}", s.name))?;
    }
    let mut notes = vec![format!(
        "{file}: a 1X table: its vectors are taken as compensated (subtract the slow-roll vector before exporting if the system did not); no cascade or full spectrum without the raw signals"
    )];
    if sensors.len() == 1 {
        notes
            .push("one sensor: no full spectrum or shaft centreline (they need an XY pair)".into());
    }
    let rpm: Vec<f64> = sensors[0].points.iter().map(|p| p.rpm).collect();
    Ok(Analysis {
        sources: vec![file.to_owned()],
        direction: direction(&rpm),
        sensors,
        keyphasor: Vec::new(),
        samples: Vec::new(),
        notes,
        operating_rpm: args.operating_rpm,
        bin_rpm: None,
        pair_angles: None,
        dc_coupled: false,
    })
}

/// The criticals of each sensor's compensated 1X, with their margins.
fn find_criticals(a: &mut Analysis) -> anyhow::Result<()> {
    let settings = CriticalSettings::default();
    for s in &mut a.sensors {
        let Some(o) = s.orders.iter().position(|&n| n == 1) else {
            continue;
        };
        let rpm: Vec<f64> = s.points.iter().map(|p| p.rpm).collect();
        let v: Vec<C64> = s.points.iter().map(|p| p.comp[o]).collect();
        let std: Vec<f64> = s.points.iter().map(|p| p.std[o]).collect();
        let found = criticals(&rpm, &v, &std, &settings)
            .with_context(|| format!("the critical speeds of {}", s.name))?;
        s.criticals = found
            .into_iter()
            .map(|c| {
                let m = a
                    .operating_rpm
                    .map(|(lo, hi)| separation_margin(c.rpm, c.amplification_factor, lo, hi));
                (c, m)
            })
            .collect();
    }
    Ok(())
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
    let mut a = match &args.vectors {
        Some(file) => analyse_table(&args, file)?,
        None => analyse_raw(&args)?,
    };
    find_criticals(&mut a)?;
    for n in &a.notes {
        eprintln!("note: {n}");
    }
    // everything computed: now the files
    let figs = figures::render(&a)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create output directory {}", args.out.display()))?;
    output::write_bode_csv(&args.out, &a)?;
    let json = output::transient_json(&a, &figs.names());
    let written = figs.save(&args.out)?;
    output::write_json(&args.out, &json)?;
    output::write_report(&args.out, &json, &figs.report_figures())?;
    // the numbers that matter, on stdout
    let (lo, hi) = a
        .sensors
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.rpm))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(x, y), v| {
            (x.min(v), y.max(v))
        });
    outln!(
        "{} from {:.0} to {:.0} rpm, {} points per sensor{}",
        a.direction.replace('_', "-"),
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
        for (c, m) in &s.criticals {
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

    #[test]
    fn direction_of_a_sweep() {
        let up: Vec<f64> = (0..100).map(f64::from).collect();
        let down: Vec<f64> = up.iter().rev().copied().collect();
        assert_eq!(direction(&up), "run_up");
        assert_eq!(direction(&down), "coast_down");
        assert_eq!(direction(&[1.0, 5.0, 1.0]), "mixed");
    }

    #[test]
    fn a_steady_speed_is_refused_with_its_change() {
        let e = speed_check([1000.0, 1010.0, 1020.0].into_iter()).unwrap_err();
        let m = e.to_string();
        assert!(
            m.contains("1000.0 to 1020.0 rpm") && m.contains("1.98 %"),
            "{m}"
        );
        assert!(speed_check([1000.0, 1500.0].into_iter()).is_ok());
    }
}
