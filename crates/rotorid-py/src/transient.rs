//! `rotorid.transient`: a run-up or coast-down analysed as `rotorid transient` analyses it,
//! through the same code: the raw records read by `rotorid_io::raw` (the command's reader)
//! and analysed by `rotorid::transient::analysis`, or recordings as `rotorid publish` sends
//! them (`t, x, z, phi`, read as `rotorid.read` reads them; the shaft angle phi gives the
//! revolutions), or a 1X table (the CSV text of a file or
//! a DataFrame, read by the command's `rotorid_io::csv::bode` reader, with the same
//! messages); `transient.json` as text (`rotorid::transient::report`, the document the
//! command writes, without figures) and the columns of `bode.csv`.

use rotorid::acquisition::{Acquisition, RawRecord, TimeBase};
use rotorid::scenario_file::ScenarioSpec;
use rotorid::transient::analysis::{
    analyse_table, Analysis, RawAnalysis, Settings, SlowRollChoice, TableRow,
};
use rotorid::transient::report::{bode_rows, lag_deg, transient_json};
use rotorid::transient::OrderSettings;
use rotorid_io::csv::bode::{read_bode, Amplitude};

use crate::error::Error;

/// Where the runout comes from (`slow_roll=`).
#[derive(Debug, Clone, PartialEq)]
pub enum SlowRollKw {
    /// The scenario's `[acquisition.runout] slow_roll` record when it names one, else auto.
    Default,
    /// A low-speed range of the record, picked automatically.
    Auto,
    /// No compensation.
    None,
    /// A slow-roll record (a path).
    File(String),
    /// The revolutions of this range \[rev/min\].
    Range(f64, f64),
}

/// The inputs of a call, as the keyword arguments give them.
#[derive(Debug, Clone, PartialEq)]
pub struct Request {
    /// Raw records of one event, in time order (paths).
    pub records: Vec<String>,
    /// A 1X table instead of records: the name messages give it (its path, or
    /// `vectors_df`) and its CSV text.
    pub vectors: Option<(String, String)>,
    /// `pk` or `pk-pk` (a table's amplitudes).
    pub amplitude: String,
    /// Unit of a table without a unit column or header suffix.
    pub unit: Option<String>,
    /// The runout.
    pub slow_roll: SlowRollKw,
    /// The orders to track (default 1 and 2).
    pub orders: Option<Vec<u32>>,
    /// The operating range \[rev/min\].
    pub operating_rpm: Option<(f64, f64)>,
    /// Bin width \[rev/min\].
    pub bin_rpm: Option<f64>,
}

/// What a call gives back.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// `transient.json` as `rotorid transient` writes it, with `figures` empty.
    pub json: String,
    /// The columns of `bode.csv`.
    pub bode: BodeColumns,
    /// What the readers noted, (file, note).
    pub read_notes: Vec<(String, String)>,
}

/// The columns of `bode.csv` (docs/transient.md section 7), SI.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BodeColumns {
    /// \[rev/min\].
    pub speed_rpm: Vec<f64>,
    /// The sensor of each row.
    pub sensor: Vec<String>,
    /// n of nX.
    pub order: Vec<u32>,
    /// |V| compensated \[m\], zero-to-peak.
    pub amplitude: Vec<f64>,
    /// -arg V \[deg\], in \[0, 360).
    pub phase_lag_deg: Vec<f64>,
    /// Re V compensated \[m\].
    pub re: Vec<f64>,
    /// Im V compensated \[m\].
    pub im: Vec<f64>,
    /// Standard deviation of each of re and im \[m\] (NaN unknown).
    pub std: Vec<f64>,
    /// Re V as measured \[m\].
    pub raw_re: Vec<f64>,
    /// Im V as measured \[m\].
    pub raw_im: Vec<f64>,
}

impl BodeColumns {
    fn of(a: &Analysis) -> Self {
        let mut c = Self::default();
        for r in bode_rows(a) {
            c.speed_rpm.push(r.speed_rpm);
            c.sensor.push(r.sensor.to_owned());
            c.order.push(r.order);
            c.amplitude.push(r.vector.norm());
            c.phase_lag_deg.push(lag_deg(r.vector));
            c.re.push(r.vector.re);
            c.im.push(r.vector.im);
            c.std.push(r.std);
            c.raw_re.push(r.raw.re);
            c.raw_im.push(r.raw.im);
        }
        c
    }
}

/// The analysis of `r` (`spec`: the scenario, for raw records).
pub fn transient(spec: Option<&ScenarioSpec>, r: &Request) -> Result<Outcome, Error> {
    let settings = Settings {
        order: OrderSettings {
            orders: r
                .orders
                .clone()
                .unwrap_or_else(|| OrderSettings::default().orders),
            ..OrderSettings::default()
        },
        bin_rpm: r.bin_rpm,
        operating_rpm: r.operating_rpm,
        // the package returns no cascade: not computed
        cascade: None,
        ..Settings::default()
    };
    // the settings first, as the command's arguments are checked before any file is read
    settings.validate()?;
    let mut read_notes = Vec::new();
    let a = match &r.vectors {
        Some(v) => {
            if !r.records.is_empty() {
                return Err(Error::invalid(
                    "records and vectors: give raw records (with a scenario) or a 1X table, not both",
                ));
            }
            table(v, r, &settings)?
        }
        None => match spec {
            Some(spec) if spec.acquisition().is_some() => raw(spec, r, settings, &mut read_notes)?,
            _ => with_angles(spec, r, settings, &mut read_notes)?,
        },
    };
    let json = serde_json::to_string_pretty(&transient_json(&a, &[]))
        .map_err(|e| Error::invalid(format!("transient.json: {e}")))?;
    Ok(Outcome {
        json,
        bode: BodeColumns::of(&a),
        read_notes,
    })
}

fn raw_record(
    path: &str,
    acq: &Acquisition,
    notes: &mut Vec<(String, String)>,
) -> Result<RawRecord, Error> {
    let time = match &acq.time {
        TimeBase::Column(c) => Some(c.as_str()),
        TimeBase::RateHz(_) => None,
    };
    let raw = rotorid_io::raw::read(path, &acq.columns(), time, &acq.probes[0].column)?;
    notes.extend(raw.notes.into_iter().map(|n| (path.to_owned(), n)));
    Ok(RawRecord {
        columns: raw.columns,
    })
}

fn raw(
    spec: &ScenarioSpec,
    r: &Request,
    settings: Settings,
    notes: &mut Vec<(String, String)>,
) -> Result<Analysis, Error> {
    if r.records.is_empty() {
        return Err(Error::invalid(
            "records: give at least one raw record (a path), or vectors= for a 1X table",
        ));
    }
    let acq = spec.acquisition().ok_or_else(|| {
        Error::invalid(format!(
            "{}: has no [acquisition] table: it names the probe and keyphasor columns (see docs/acquisition.md)",
            spec.origin()
        ))
    })?;
    if r.amplitude != "pk" || r.unit.is_some() {
        return Err(Error::invalid(
            "amplitude and unit apply to a 1X table (vectors=) only",
        ));
    }
    let mut analysis = RawAnalysis::new(acq, settings)?;
    for path in &r.records {
        let record = raw_record(path, acq, notes)?;
        analysis.add_record(path, &record)?;
    }
    let choice = match (&r.slow_roll, &acq.slow_roll) {
        (SlowRollKw::Auto, _) | (SlowRollKw::Default, None) => SlowRollChoice::Auto,
        (SlowRollKw::None, _) => SlowRollChoice::None,
        (SlowRollKw::Range(a, b), _) => SlowRollChoice::Range(*a, *b),
        (SlowRollKw::File(f), _) => SlowRollChoice::Record {
            label: f.clone(),
            record: raw_record(f, acq, notes)?,
        },
        (SlowRollKw::Default, Some(rel)) => {
            let path = rotorid_io::raw::beside(spec.origin(), rel);
            let record = raw_record(&path.to_string_lossy(), acq, notes).map_err(|e| {
                Error::invalid(format!(
                    "the slow-roll record of [acquisition.runout] ({rel}): {e}"
                ))
            })?;
            SlowRollChoice::Record {
                label: rel.clone(),
                record,
            }
        }
    };
    Ok(analysis.finish(choice)?)
}

/// Recordings as `rotorid publish` sends them (docs/fleet.md): `t, x, z` \[s, m\] and the
/// shaft angle `phi` \[rad\] from the file or, without it, from the scenario's `[speed]`
/// profile (as `rotorid publish --scenario` makes it); x and z are probes at 0 and 90 deg.
fn with_angles(
    spec: Option<&ScenarioSpec>,
    r: &Request,
    settings: Settings,
    notes: &mut Vec<(String, String)>,
) -> Result<Analysis, Error> {
    if r.records.is_empty() {
        return Err(Error::invalid(
            "records: give at least one record (a path), or vectors= for a 1X table",
        ));
    }
    if r.amplitude != "pk" || r.unit.is_some() {
        return Err(Error::invalid(
            "amplitude and unit apply to a 1X table (vectors=) only",
        ));
    }
    let mut analysis = RawAnalysis::with_angles(RawAnalysis::xz_probes(), settings)?;
    for path in &r.records {
        let rec = crate::response::read_any(path, None)?;
        notes.extend(rec.notes.iter().map(|n| (path.clone(), n.clone())));
        let phi = match rec.speed {
            Some([phi, _, _]) => phi,
            None => {
                let profile = spec.and_then(|s| s.speed_profile()).ok_or_else(|| {
                    Error::invalid(format!(
                        "{path}: has no phi column (the shaft angle) and {}: give a record with phi, a scenario whose [speed] profile gives it (as for `rotorid publish --scenario`), or raw records (probe volts and a keyphasor) with a scenario's [acquisition]",
                        match spec {
                            Some(s) => format!("{} has neither [acquisition] nor a [speed] profile", s.origin()),
                            None => "no scenario was given".to_owned(),
                        }
                    ))
                })?;
                rec.t.iter().map(|&t| profile.at(t).phi).collect()
            }
        };
        analysis.add_angles(path, rec.t, &phi, vec![rec.x, rec.z])?;
    }
    let choice = match &r.slow_roll {
        SlowRollKw::Default | SlowRollKw::Auto => SlowRollChoice::Auto,
        SlowRollKw::None => SlowRollChoice::None,
        SlowRollKw::Range(a, b) => SlowRollChoice::Range(*a, *b),
        // refused by the analysis, which says why
        SlowRollKw::File(f) => SlowRollChoice::Record {
            label: f.clone(),
            record: RawRecord {
                columns: Vec::new(),
            },
        },
    };
    Ok(analysis.finish(choice)?)
}

fn table(v: &(String, String), r: &Request, settings: &Settings) -> Result<Analysis, Error> {
    let amp = match r.amplitude.as_str() {
        "pk" => Amplitude::Peak,
        "pk-pk" => Amplitude::PeakToPeak,
        other => {
            return Err(Error::invalid(format!(
                "amplitude={other:?}: expected \"pk\" (zero-to-peak) or \"pk-pk\" (peak-to-peak)"
            )))
        }
    };
    if r.slow_roll != SlowRollKw::Default || r.bin_rpm.is_some() || r.orders.is_some() {
        return Err(Error::invalid(
            "slow_roll, bin_rpm and orders apply to raw records only: a 1X table is taken as it is (compensated, one point per row, order 1)",
        ));
    }
    let (name, text) = v;
    let rows = read_bode(name, text.as_bytes(), amp, r.unit.as_deref())?;
    let rows = rows
        .into_iter()
        .map(|b| TableRow {
            speed_rpm: b.speed_rpm,
            sensor: b.sensor,
            re: b.re,
            im: b.im,
            std: b.std,
        })
        .collect();
    Ok(analyse_table(name, rows, settings)?)
}
