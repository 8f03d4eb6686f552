//! Records in any format `rotorid_io` reads (MAT, TDMS, UFF58, NPY/NPZ, Parquet, CSV read
//! whole): the channels that play t, x, z, phi... (`--columns`, units converted to SI), and
//! raw acquisitions (probe volts and keyphasor) conditioned by the library
//! (`rotorid::acquisition`) before identification.

use std::path::Path;

use anyhow::Context as _;
use rotorid::acquisition::{
    condition, condition_iterated, Acquisition, Conditioned, FeAcquisition, GuessSource,
    ModelGuess, RawRecord, TimeBase,
};
use rotorid::pipeline::{Knowledge, Method};
use rotorid::scenario_file::ScenarioSpec;
use rotorid_io::{select, ColumnMap, Format, SiBlocks, SiColumns, Table};

/// True when `input` is read whole as a table rather than streamed as a response CSV: a
/// regular file whose extension is not a CSV one, or any file with `--columns`.
pub fn is_tabular(input: &str, columns: Option<&str>) -> bool {
    if input == "-" {
        return false;
    }
    let regular = std::fs::metadata(input).is_ok_and(|m| m.is_file());
    let csv = matches!(
        Format::from_path(Path::new(input)),
        Ok(Format::Csv) | Err(_)
    );
    regular && (!csv || columns.is_some())
}

/// The table of the file at `path` (its format from its extension); what the reader noted
/// about the file (an interrupted recording's unfinished chunk) as `note:` lines on stderr.
pub fn read(path: &str) -> anyhow::Result<Table> {
    let table = rotorid_io::read_table(path)?;
    print_notes(&table.file, &table.notes);
    Ok(table)
}

/// What a reader noted about `file` (an interrupted recording's unfinished chunk), as
/// `note:` lines on stderr.
pub fn print_notes(file: &str, notes: &[String]) {
    for n in notes {
        eprintln!("note: {file}: {n}");
    }
}

/// The channels of `table` that play t, x, z and (when present) phi, phi_dot, phi_ddot, in
/// SI; `columns` is the `--columns` text. Each converted channel is noted on stderr. The
/// table is consumed: its channels become the columns without a copy.
pub fn columns(table: Table, columns: Option<&str>) -> anyhow::Result<SiColumns> {
    let file = table.file.clone();
    let cols = select(table, &ColumnMap::from_spec(columns)?)?;
    print_selection(&file, &cols.used, cols.time_from_axis);
    Ok(cols)
}

/// The file at `path` read a block of rows at a time, when its format streams (TDMS,
/// Parquet: `rotorid_io::stream`), with the channels that play each role (`columns` as in
/// [`columns`]) checked before any sample is read; the reader's notes and each converted
/// channel are noted on stderr as [`read`] and [`columns`] note them. `None` for a format
/// that is read whole.
pub fn blocks(path: &str, columns: Option<&str>) -> anyhow::Result<Option<SiBlocks>> {
    let Some(reader) = rotorid_io::open_blocks(path)? else {
        return Ok(None);
    };
    print_notes(reader.file(), reader.notes());
    let blocks = SiBlocks::new(reader, &ColumnMap::from_spec(columns)?)?;
    print_selection(blocks.file(), blocks.used(), blocks.time_from_axis());
    Ok(Some(blocks))
}

/// The notes on stderr of the channels `used` of `file` that were converted to SI, and of
/// a time taken from the file's time axis.
fn print_selection(file: &str, used: &[rotorid_io::select::Used], time_from_axis: bool) {
    for u in used.iter().filter(|u| !u.conversion.is_identity()) {
        eprintln!(
            "note: {}: {} ({}) in {}, converted to {} (x {:e})",
            file,
            u.channel,
            u.role,
            u.conversion.unit,
            u.conversion.quantity.si(),
            u.conversion.factor()
        );
    }
    if time_from_axis {
        eprintln!(
            "note: {}: time from the file's time axis (no time channel)",
            file
        );
    }
}

/// The raw record of `table` for `acq`: every channel by name, the ones `acq` uses in SI
/// (time in s, probes and keyphasor in V, from their units). An acquisition column names
/// a channel as `--columns` does: exactly, else by its short name when that is unique
/// (`probe_L` for a TDMS `rig/probe_L`); the channel then goes by the acquisition's name.
/// Without a time channel, a file's time axis (TDMS `wf_increment`, a UFF58 abscissa) on
/// the first probe gives it, t_i = start + i increment, with a note on stderr.
pub fn raw_record(table: &Table, acq: &Acquisition) -> anyhow::Result<RawRecord> {
    raw_record_of(table, &acq.columns(), &acq.time, &acq.probes[0].column)
}

/// [`raw_record`] for the raw record of a finite-element rotor: the columns of every
/// node's probes (docs/acquisition.md section 11), the time and the keyphasor once.
pub fn fe_raw_record(table: &Table, acq: &FeAcquisition) -> anyhow::Result<RawRecord> {
    let common = acq.common()?;
    let mut roles: Vec<(&str, &'static str)> = Vec::new();
    for n in &acq.nodes {
        for r in n.acquisition.columns() {
            if !roles.iter().any(|(c, _)| *c == r.0) {
                roles.push(r);
            }
        }
    }
    raw_record_of(table, &roles, &common.time, &common.probes[0].column)
}

/// The raw record of `table` whose channels `roles` (column, role) are converted to SI
/// (`rotorid_io::raw`, shared with the Python package); a time from the time axis of
/// `first_probe` when `time` names no channel of the table, noted on stderr.
fn raw_record_of(
    table: &Table,
    roles: &[(&str, &'static str)],
    time: &TimeBase,
    first_probe: &str,
) -> anyhow::Result<RawRecord> {
    let time = match time {
        TimeBase::Column(t) => Some(t.as_str()),
        TimeBase::RateHz(_) => None,
    };
    let raw = rotorid_io::raw::channels(table, roles, time, first_probe)?;
    print_notes(&table.file, &raw.notes);
    Ok(RawRecord {
        columns: raw.columns,
    })
}

/// The slow-roll record of `acq`, read from its path relative to the scenario file.
pub fn slow_roll(spec: &ScenarioSpec, acq: &Acquisition) -> anyhow::Result<Option<RawRecord>> {
    slow_roll_table(spec, acq)?
        .map(|t| raw_record(&t, acq))
        .transpose()
}

/// [`slow_roll`] of a finite-element rotor: every node's probes ([`fe_raw_record`]).
pub fn fe_slow_roll(spec: &ScenarioSpec, acq: &FeAcquisition) -> anyhow::Result<Option<RawRecord>> {
    slow_roll_table(spec, acq.common()?)?
        .map(|t| fe_raw_record(&t, acq))
        .transpose()
}

/// The table of the slow-roll file of `acq`, read from its path relative to the scenario
/// file, when it has one.
fn slow_roll_table(spec: &ScenarioSpec, acq: &Acquisition) -> anyhow::Result<Option<Table>> {
    let Some(rel) = &acq.slow_roll else {
        return Ok(None);
    };
    let path = rotorid_io::raw::beside(spec.origin(), rel);
    let table = read(&path.to_string_lossy())
        .with_context(|| format!("the slow-roll record of [acquisition.runout] ({rel})"))?;
    Ok(Some(table))
}

/// The scenario's rotor as a guess for the conditioning, when its `[rotor]` is complete
/// (whatever else the scenario lacks: a raw record's has no `[speed]`), else why not.
pub fn scenario_guess(spec: &ScenarioSpec) -> Result<ModelGuess, String> {
    spec.rotor("the conditioning's rotor guess")
        .map(|r| ModelGuess {
            rotor: r.params(),
            initial: None,
            source: GuessSource::Scenario,
        })
        .map_err(|e| e.to_string())
}

/// Condition `raw` for `acq` with the scenario's rotor (when its `[rotor]` is complete;
/// the notes say which rotor, or why none); with `method`, iterated with the
/// identification until the guess settles (`rotorid::acquisition::condition_iterated`,
/// docs/acquisition.md section 6), the estimates checked against their grid within
/// `time_tolerance` dt.
pub fn condition_for(
    raw: &RawRecord,
    acq: &Acquisition,
    slow: Option<&RawRecord>,
    spec: &ScenarioSpec,
    knowledge: &Knowledge,
    method: Option<(&Method, f64)>,
) -> anyhow::Result<Conditioned> {
    let first = scenario_guess(spec);
    let mut c = match method {
        None => condition(raw, acq, slow, first.as_ref().ok())?,
        Some((method, time_tolerance)) => {
            condition_iterated(
                raw,
                acq,
                slow,
                first.as_ref().ok(),
                knowledge,
                method,
                time_tolerance,
            )?
            .conditioned
        }
    };
    if let Err(why) = first {
        c.report
            .notes
            .insert(0, format!("no rotor guess from the scenario: {why}"));
    }
    Ok(c)
}

/// `c` as the columns of a record (SI already).
pub fn conditioned_columns(c: Conditioned) -> SiColumns {
    SiColumns {
        t: c.t,
        x: c.x,
        z: c.z,
        speed: Some([c.phi, c.phi_dot, c.phi_ddot]),
        used: Vec::new(),
        time_from_axis: false,
    }
}

/// The conditioning's findings as `warning:` lines and its notes as `note:` lines.
pub fn print_report(c: &Conditioned) {
    for n in &c.report.notes {
        eprintln!("note: {n}");
    }
    for f in &c.report.findings {
        eprintln!("warning: {}", f.message());
    }
}
