//! Raw acquisitions (probe volts and a keyphasor, described by a scenario's
//! `[acquisition]`, docs/acquisition.md) as named channels in SI, the one reading shared by
//! the `rotorid` command and the Python package: every channel of the table by name, the
//! ones the acquisition uses converted to SI from their units (time in s, probes and
//! keyphasor in V). The caller hands the channels to `rotorid::acquisition::RawRecord`.
//!
//! An acquisition column names a channel as `--columns` does: exactly, else by its short
//! name when that is unique (`probe_L` for a TDMS `rig/probe_L`); the channel then goes by
//! the acquisition's name. Without a time channel, the file's time axis of the first probe
//! (TDMS `wf_increment`, a UFF58 abscissa) gives it, t_i = start + i increment, with a
//! note.

use std::path::{Path, PathBuf};

use crate::table::Table;
use crate::units::{conversion, Quantity, UnitError};
use crate::ReadError;

/// The named SI channels of a raw record.
#[derive(Debug, Clone, PartialEq)]
pub struct RawChannels {
    /// (name, values), in file order; a time made from the file's time axis last.
    pub columns: Vec<(String, Vec<f64>)>,
    /// Notes about the file (each without the file name): [`channels`] notes a time
    /// taken from the file's time axis, [`read`] also what the reader noted (an interrupted
    /// recording's unfinished chunk), first.
    pub notes: Vec<String>,
}

/// Why a raw record cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum RawError {
    /// The file cannot be read.
    #[error(transparent)]
    Read(Box<ReadError>),
    /// A channel the acquisition uses has a unit of another quantity, or an unknown one.
    #[error("{file}, channel {channel:?} ({role}): {source}")]
    Unit {
        /// The file.
        file: String,
        /// The channel as the file names it.
        channel: String,
        /// What the acquisition uses it as (`time`, `probe 1`, `keyphasor`, ...).
        role: String,
        /// The unit's problem.
        source: UnitError,
    },
    /// Context for an error: which record (`the slow-roll record of ...`).
    #[error("{what}: {source}")]
    Within {
        /// The record.
        what: String,
        /// The error.
        source: Box<RawError>,
    },
}

impl From<ReadError> for RawError {
    fn from(e: ReadError) -> Self {
        Self::Read(Box::new(e))
    }
}

/// The channels of `table` with `roles` ((column, role): role `time` in s, any other in V)
/// converted to SI (module doc); `time_column` the acquisition's time column, if it has
/// one (else a sampling rate), `first_probe` the column whose time axis stands in for a
/// missing time channel.
pub fn channels(
    table: &Table,
    roles: &[(&str, &str)],
    time_column: Option<&str>,
    first_probe: &str,
) -> Result<RawChannels, RawError> {
    let data = table.channels.iter().map(|c| c.data.clone()).collect();
    convert(table, data, roles, time_column, first_probe)
}

/// [`channels`] of `table` whose samples are `data` (each channel's, in file order; the
/// table's own may have been taken out of it), converted in place.
fn convert(
    table: &Table,
    data: Vec<Vec<f64>>,
    roles: &[(&str, &str)],
    time_column: Option<&str>,
    first_probe: &str,
) -> Result<RawChannels, RawError> {
    let found: Vec<(&str, &str, Option<&str>)> = roles
        .iter()
        .map(|&(n, what)| (n, what, table.channel(n).map(|c| c.name.as_str())))
        .collect();
    let probe = table.channel(first_probe);
    let probe_len = table
        .channels
        .iter()
        .zip(&data)
        .find(|(c, _)| probe.is_some_and(|p| std::ptr::eq(*c, p)))
        .map_or(0, |(_, d)| d.len());
    let mut columns = Vec::with_capacity(table.channels.len() + 1);
    for (c, mut data) in table.channels.iter().zip(data) {
        let role = found.iter().find(|(_, _, f)| *f == Some(c.name.as_str()));
        let name = match role {
            Some(&(name, what, _)) => {
                let q = if what == "time" {
                    Quantity::Time
                } else {
                    Quantity::Voltage
                };
                let conv = conversion(q, c.unit.as_deref()).map_err(|source| RawError::Unit {
                    file: table.file.clone(),
                    channel: c.name.clone(),
                    role: what.to_owned(),
                    source,
                })?;
                conv.apply_all(&mut data);
                name.to_string()
            }
            None => c.name.clone(),
        };
        columns.push((name, data));
    }
    let mut notes = Vec::new();
    if let Some(t) = time_column {
        if let (None, Some(axis), Some(probe)) =
            (table.channel(t), probe.and_then(|p| p.axis), probe)
        {
            notes.push(format!(
                "time from the file's time axis of {:?} (no channel {t:?})",
                probe.name
            ));
            columns.push((t.to_owned(), axis.times(probe_len)));
        }
    }
    Ok(RawChannels { columns, notes })
}

/// The file at `path` (any format [`crate::read_table`] reads) as [`channels`].
pub fn read(
    path: &str,
    roles: &[(&str, &str)],
    time_column: Option<&str>,
    first_probe: &str,
) -> Result<RawChannels, RawError> {
    let mut table = crate::read_table(path)?;
    // the samples moved out of the table, not copied: one copy of the record held, not two
    let data = table
        .channels
        .iter_mut()
        .map(|c| std::mem::take(&mut c.data))
        .collect();
    let mut out = convert(&table, data, roles, time_column, first_probe)?;
    let mut notes = table.notes;
    notes.append(&mut out.notes);
    out.notes = notes;
    Ok(out)
}

/// The path of a file a scenario names (`[acquisition.runout] slow_roll`): relative to
/// the scenario file `scenario_origin`'s directory (an absolute `rel` stays as it is).
pub fn beside(scenario_origin: &str, rel: &str) -> PathBuf {
    let base = Path::new(scenario_origin)
        .parent()
        .unwrap_or(Path::new("."));
    base.join(rel)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::table::{Channel, TimeAxis};

    fn channel(name: &str, unit: Option<&str>, data: &[f64], axis: Option<TimeAxis>) -> Channel {
        Channel {
            name: name.into(),
            unit: unit.map(Into::into),
            data: data.to_vec(),
            axis,
        }
    }

    const ROLES: [(&str, &str); 3] = [("t", "time"), ("probe_L", "probe 1"), ("kp", "keyphasor")];

    #[test]
    fn channels_in_si_by_the_acquisitions_names_and_the_others_as_they_are() {
        let table = Table {
            file: "r.tdms".into(),
            channels: vec![
                channel("rig/probe_L", Some("mV"), &[1500.0, -250.0], None),
                channel("kp", Some("V"), &[0.0, -5.0], None),
                channel("t", Some("ms"), &[0.0, 0.5], None),
                channel("other", Some("mV"), &[7.0, 8.0], None),
            ],
            notes: vec!["an unfinished chunk was not read".into()],
        };
        let r = channels(&table, &ROLES, Some("t"), "probe_L").unwrap();
        let names: Vec<&str> = r.columns.iter().map(|(n, _)| n.as_str()).collect();
        assert_eq!(names, ["probe_L", "kp", "t", "other"]);
        assert_eq!(r.columns[0].1, [1.5, -0.25]);
        assert_eq!(r.columns[2].1, [0.0, 0.0005]);
        assert_eq!(
            r.columns[3].1,
            [7.0, 8.0],
            "a channel without a role is as the file gives it"
        );
        assert!(
            r.notes.is_empty(),
            "the reader's notes are read()'s: {:?}",
            r.notes
        );
    }

    #[test]
    fn a_missing_time_comes_from_the_first_probes_axis_with_a_note() {
        let axis = TimeAxis {
            start: 1.0,
            increment: 0.25,
        };
        let table = Table {
            file: "r.uff".into(),
            channels: vec![channel("probe_L", None, &[0.0; 3], Some(axis))],
            notes: Vec::new(),
        };
        let r = channels(&table, &ROLES, Some("t"), "probe_L").unwrap();
        assert_eq!(r.columns[1], ("t".to_string(), vec![1.0, 1.25, 1.5]));
        assert!(
            r.notes[0].contains("time axis of \"probe_L\""),
            "{:?}",
            r.notes
        );
        // a sampling rate instead of a time column: no time is made
        let r = channels(&table, &ROLES, None, "probe_L").unwrap();
        assert_eq!(r.columns.len(), 1);
    }

    #[test]
    fn a_unit_of_another_quantity_names_the_file_channel_and_role() {
        let table = Table {
            file: "r.csv".into(),
            channels: vec![channel("kp", Some("um"), &[0.0], None)],
            notes: Vec::new(),
        };
        let e = channels(&table, &ROLES, Some("t"), "probe_L").unwrap_err();
        assert!(
            e.to_string()
                .starts_with("r.csv, channel \"kp\" (keyphasor): "),
            "{e}"
        );
    }

    #[test]
    fn a_scenarios_file_is_beside_it() {
        assert_eq!(beside("rigs/a.toml", "sr.csv"), Path::new("rigs/sr.csv"));
        assert_eq!(beside("a.toml", "sr.csv"), Path::new("sr.csv"));
        assert_eq!(
            beside("rigs/a.toml", "/data/sr.csv"),
            Path::new("/data/sr.csv")
        );
    }
}
