//! The two CSV files of influence-coefficient balancing (docs/balancing.md):
//!
//! - `vectors.csv`: `run,speed_rpm,sensor,re,im` — the 1X vector of each sensor in each run
//!   at each speed, `re + i im` meaning the sensor's 1X component is
//!   Re((re + i im) e^{i phi}), phi the shaft angle from the keyphasor mark in the direction
//!   of rotation; or `amp,phase_deg` instead of `re,im`, with the instrument's convention
//!   given ([`Phase`]: lag, `re + i im = amp e^{-i phase}`; lead, `amp e^{+i phase}`).
//!   Optional columns: `unit` (the sensor's unit, free text: `um`, `mil`, `V`, `mm/s`),
//!   `re_std,im_std` (standard deviations of re and im, with `re,im`) or `std` (the same
//!   standard deviation on each of re and im). Without a `unit` column the unit is the
//!   header's suffix of `re` or `amp` (`re [um]`), else the one the caller gives.
//! - `masses.csv`: `run,plane,mass_kg,radius_m,angle_deg` — the masses added in each
//!   calibration run (angle from the keyphasor mark in the direction of rotation; a run as
//!   found has mass 0 on its planes).
//!
//! Extra columns are ignored; names and the column order are free (header names compared as
//! every reader here compares them: trimmed, lower-cased, a unit suffix split off). Errors
//! name the file, the line, the column, the value and the allowed range. Rows of one run,
//! sensor and speed written twice are an error naming both lines.

use std::io::Read;

use super::columns::{check_length, csv_reader, next_record, number_field, Header};
use super::error::{quote, CsvError};
use super::records::Record;

/// The phase convention of an instrument's `phase_deg`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// The angle from the keyphasor mark to the next positive peak, counted against the
    /// shaft's rotation (as Bently Nevada and most data collectors report it):
    /// `re + i im = amp e^{-i phase}`.
    Lag,
    /// The angle by which the 1X component leads the keyphasor mark:
    /// `re + i im = amp e^{+i phase}`.
    Lead,
}

/// One row of `vectors.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct VectorRow {
    /// Line in the file (header = 1).
    pub line: u64,
    /// Run.
    pub run: String,
    /// Speed \[rev/min\].
    pub speed_rpm: f64,
    /// Sensor.
    pub sensor: String,
    /// Unit of the sensor.
    pub unit: String,
    /// Re V \[unit\].
    pub re: f64,
    /// Im V \[unit\].
    pub im: f64,
    /// Standard deviations of re and im \[unit\], when given.
    pub std: Option<(f64, f64)>,
}

/// One row of `masses.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct MassRow {
    /// Line in the file (header = 1).
    pub line: u64,
    /// Run.
    pub run: String,
    /// Plane.
    pub plane: String,
    /// Mass \[kg\].
    pub mass_kg: f64,
    /// Radius \[m\].
    pub radius_m: f64,
    /// Angle \[deg\].
    pub angle_deg: f64,
}

/// A text field, trimmed; empty is an error.
pub(super) fn text_field(
    file: &str,
    rec: &Record<'_>,
    line: u64,
    col: usize,
    name: &str,
) -> Result<String, CsvError> {
    let raw = rec.get(col).unwrap_or_default();
    let s = String::from_utf8_lossy(raw).trim().to_owned();
    if s.is_empty() {
        return Err(CsvError::field(
            file,
            line,
            col,
            name,
            format!("{name} is empty: every row needs one"),
        ));
    }
    if s.chars().count() > 200 {
        return Err(CsvError::field(
            file,
            line,
            col,
            name,
            format!("{name} {} is longer than 200 characters", quote(raw)),
        ));
    }
    Ok(s)
}

/// A number in a range.
pub(super) fn ranged(
    file: &str,
    rec: &Record<'_>,
    line: u64,
    col: usize,
    name: &str,
    allowed: &str,
    ok: impl Fn(f64) -> bool,
) -> Result<f64, CsvError> {
    let v = number_field(file, rec, line, col, name)?;
    if v.is_finite() && ok(v) {
        Ok(v)
    } else {
        Err(CsvError::field(
            file,
            line,
            col,
            name,
            format!("{name} = {v} is out of range: must be {allowed}"),
        ))
    }
}

/// Read the header of `csv`, or the error of an empty file.
pub(super) fn header<R: Read>(
    file: &str,
    csv: &mut super::columns::CsvReader<R>,
    what: &str,
) -> Result<Header, CsvError> {
    match next_record(file, csv)? {
        Some(rec) => {
            let line = rec.line();
            Ok(Header::new(&rec, line))
        }
        None => Err(CsvError::file(
            file,
            format!("the file is empty: expected a header line ({what}), then one row per line"),
        )),
    }
}

/// Call `row` for every non-blank data row of `csv` (as long as the header `h`) with its
/// line.
pub(super) fn each_row<R: Read>(
    file: &str,
    csv: &mut super::columns::CsvReader<R>,
    h: &Header,
    mut row: impl FnMut(&Record<'_>, u64) -> Result<(), CsvError>,
) -> Result<(), CsvError> {
    while let Some(rec) = next_record(file, csv)? {
        let line = rec.line();
        if rec.iter().all(|f| f.iter().all(u8::is_ascii_whitespace)) {
            continue;
        }
        check_length(file, &rec, line, h)?;
        row(&rec, line)?;
    }
    Ok(())
}

/// The header of `vectors.csv` (the column names every caller accepts).
pub const VECTORS_HEADER: &str = "run,speed_rpm,sensor,re,im";
/// The header of `masses.csv`.
pub const MASSES_HEADER: &str = "run,plane,mass_kg,radius_m,angle_deg";

/// Read `vectors.csv` (module doc); `phase` is the convention of `phase_deg` (needed with
/// `amp,phase_deg`), `unit` the unit of the vectors when the file gives none.
pub fn read_vectors<R: Read>(
    file: &str,
    input: R,
    phase: Option<Phase>,
    unit: Option<&str>,
) -> Result<Vec<VectorRow>, CsvError> {
    let mut csv = csv_reader(input);
    let h = header(file, &mut csv, VECTORS_HEADER)?;
    let base = h.require(file, &["run", "speed_rpm", "sensor"])?;
    let (re, im) = (h.find(file, "re")?, h.find(file, "im")?);
    let (amp, ph) = (h.find(file, "amp")?, h.find(file, "phase_deg")?);
    enum Form {
        Cartesian(usize, usize),
        Polar(usize, usize, Phase),
    }
    let form = match (re, im, amp, ph) {
        (Some(_), Some(_), Some(_), _) | (Some(_), Some(_), _, Some(_)) => {
            return Err(CsvError::line(
                file,
                h.line,
                "the header has both re,im and amp,phase_deg: give one form of the vectors",
            ))
        }
        (Some(a), Some(b), None, None) => Form::Cartesian(a, b),
        (None, None, Some(a), Some(b)) => match phase {
            Some(p) => Form::Polar(a, b, p),
            None => {
                return Err(CsvError::line(
                    file,
                    h.line,
                    "the vectors are given as amp,phase_deg: say which phase convention the instrument uses (lag: re + i im = amp e^{-i phase}, as most data collectors report it; lead: amp e^{+i phase})",
                ))
            }
        },
        _ => {
            return Err(CsvError::line(
                file,
                h.line,
                format!(
                    "the header must name run,speed_rpm,sensor and either re,im or amp,phase_deg (found: {})",
                    h.names.join(",")
                ),
            ))
        }
    };
    let unit_col = h.find(file, "unit")?;
    let value_col = match form {
        Form::Cartesian(a, _) | Form::Polar(a, _, _) => a,
    };
    let header_unit = h.units[value_col].clone();
    let fallback = header_unit.or_else(|| unit.map(str::to_owned));
    if unit_col.is_none() && fallback.is_none() {
        return Err(CsvError::line(
            file,
            h.line,
            "the vectors have no unit: give a unit column, a unit in the header (re [um]), or the unit of every vector",
        ));
    }
    let std_col = h.find(file, "std")?;
    let (re_std, im_std) = (h.find(file, "re_std")?, h.find(file, "im_std")?);
    let std_cols = match (re_std, im_std, std_col, &form) {
        (Some(a), Some(b), None, Form::Cartesian(..)) => Some((a, b)),
        (None, None, Some(s), _) => Some((s, s)),
        (None, None, None, _) => None,
        (Some(_), Some(_), None, Form::Polar(..)) => {
            return Err(CsvError::line(
                file,
                h.line,
                "re_std,im_std go with re,im: with amp,phase_deg give std (the same standard deviation on each of re and im)",
            ))
        }
        (Some(_), Some(_), Some(_), _) => {
            return Err(CsvError::line(
                file,
                h.line,
                "the header has both re_std,im_std and std: give one",
            ))
        }
        _ => {
            return Err(CsvError::line(
                file,
                h.line,
                "re_std and im_std go together: give both or neither",
            ))
        }
    };
    let mut rows: Vec<VectorRow> = Vec::new();
    each_row(file, &mut csv, &h, |rec, line| {
        let run = text_field(file, rec, line, base[0], "run")?;
        let speed_rpm = ranged(
            file,
            rec,
            line,
            base[1],
            "speed_rpm",
            "finite and > 0 (rev/min)",
            |v| v > 0.0,
        )?;
        let sensor = text_field(file, rec, line, base[2], "sensor")?;
        let (re, im) = match form {
            Form::Cartesian(a, b) => (
                ranged(file, rec, line, a, "re", "finite", |_| true)?,
                ranged(file, rec, line, b, "im", "finite", |_| true)?,
            ),
            Form::Polar(a, b, p) => {
                let amp = ranged(file, rec, line, a, "amp", "finite and >= 0", |v| v >= 0.0)?;
                let phase =
                    ranged(file, rec, line, b, "phase_deg", "finite (deg)", |_| true)?.to_radians();
                let sign = if p == Phase::Lag { -1.0 } else { 1.0 };
                (amp * phase.cos(), sign * amp * phase.sin())
            }
        };
        let unit = match unit_col {
            Some(c) => {
                let raw = rec.get(c).unwrap_or_default();
                let s = String::from_utf8_lossy(raw).trim().to_owned();
                if s.is_empty() {
                    match &fallback {
                        Some(u) => u.clone(),
                        None => {
                            return Err(CsvError::field(
                                file,
                                line,
                                c,
                                "unit",
                                "unit is empty: give the sensor's unit (um, mil, V, mm/s, ...)",
                            ))
                        }
                    }
                } else {
                    s
                }
            }
            None => fallback.clone().expect("checked above"),
        };
        let std = match std_cols {
            Some((a, b)) => {
                let names = if a == b {
                    ("std", "std")
                } else {
                    ("re_std", "im_std")
                };
                Some((
                    ranged(file, rec, line, a, names.0, "finite and >= 0", |v| v >= 0.0)?,
                    ranged(file, rec, line, b, names.1, "finite and >= 0", |v| v >= 0.0)?,
                ))
            }
            None => None,
        };
        if let Some(prev) = rows
            .iter()
            .find(|r| r.run == run && r.sensor == sensor && r.speed_rpm == speed_rpm)
        {
            return Err(CsvError::line(
                file,
                line,
                format!(
                    "run {run:?}, sensor {sensor:?} at {speed_rpm} rpm is also on line {}: give each vector once",
                    prev.line
                ),
            ));
        }
        rows.push(VectorRow {
            line,
            run,
            speed_rpm,
            sensor,
            unit,
            re,
            im,
            std,
        });
        Ok(())
    })?;
    if rows.is_empty() {
        return Err(CsvError::file(
            file,
            "no vector: the file has a header but no row",
        ));
    }
    Ok(rows)
}

/// Read `masses.csv` (module doc).
pub fn read_masses<R: Read>(file: &str, input: R) -> Result<Vec<MassRow>, CsvError> {
    let mut csv = csv_reader(input);
    let h = header(file, &mut csv, MASSES_HEADER)?;
    let cols = h.require(file, &["run", "plane", "mass_kg", "radius_m", "angle_deg"])?;
    let mut rows = Vec::new();
    each_row(file, &mut csv, &h, |rec, line| {
        let run = text_field(file, rec, line, cols[0], "run")?;
        let plane = text_field(file, rec, line, cols[1], "plane")?;
        let mass_kg = ranged(
            file,
            rec,
            line,
            cols[2],
            "mass_kg",
            "finite and >= 0 (kg)",
            |v| v >= 0.0,
        )?;
        let radius_m = if mass_kg > 0.0 {
            ranged(
                file,
                rec,
                line,
                cols[3],
                "radius_m",
                "finite and > 0 (m) for a non-zero mass",
                |v| v > 0.0,
            )?
        } else {
            ranged(
                file,
                rec,
                line,
                cols[3],
                "radius_m",
                "finite and >= 0 (m)",
                |v| v >= 0.0,
            )?
        };
        let angle_deg = ranged(
            file,
            rec,
            line,
            cols[4],
            "angle_deg",
            "finite (deg)",
            |_| true,
        )?;
        rows.push(MassRow {
            line,
            run,
            plane,
            mass_kg,
            radius_m,
            angle_deg,
        });
        Ok(())
    })?;
    if rows.is_empty() {
        return Err(CsvError::file(
            file,
            "no mass: the file has a header but no row (the run as found has a row with mass_kg 0 on each plane)",
        ));
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vectors(
        text: &str,
        phase: Option<Phase>,
        unit: Option<&str>,
    ) -> Result<Vec<VectorRow>, String> {
        read_vectors("v.csv", text.as_bytes(), phase, unit).map_err(|e| e.to_string())
    }

    #[test]
    fn vectors_in_both_forms_and_conventions() {
        let r = vectors(
            "run,speed_rpm,sensor,re,im,unit\nA,1200,B1X,3,-4,um\n",
            None,
            None,
        )
        .unwrap();
        assert_eq!(
            (r[0].re, r[0].im, r[0].unit.as_str(), r[0].line),
            (3.0, -4.0, "um", 2)
        );
        // 5 at a lag of 30 deg is 5 e^{-i 30 deg}; lead is the conjugate
        let text = "Sensor, RUN , speed_rpm, amp [mil], phase_deg\nB1X,A,1200,5,30\n";
        let lag = vectors(text, Some(Phase::Lag), None).unwrap();
        let lead = vectors(text, Some(Phase::Lead), None).unwrap();
        let w = 30f64.to_radians();
        assert!(
            (lag[0].re - 5.0 * w.cos()).abs() < 1e-15 && (lag[0].im + 5.0 * w.sin()).abs() < 1e-15
        );
        assert_eq!(lead[0].im, -lag[0].im);
        assert_eq!(lag[0].unit, "mil");
        let e = vectors(text, None, None).unwrap_err();
        assert!(
            e.starts_with("v.csv line 1: the vectors are given as amp,phase_deg"),
            "{e}"
        );
        // --unit where the file has none; std columns
        let r = vectors(
            "run,speed_rpm,sensor,re,im,std\nA,1200,s,1,2,0.1\n",
            None,
            Some("V"),
        )
        .unwrap();
        assert_eq!((r[0].unit.as_str(), r[0].std), ("V", Some((0.1, 0.1))));
        let r = vectors(
            "run,speed_rpm,sensor,re,im,re_std,im_std\nA,1200,s,1,2,0.1,0.2\n",
            None,
            Some("V"),
        )
        .unwrap();
        assert_eq!(r[0].std, Some((0.1, 0.2)));
    }

    #[test]
    fn bad_vectors_are_named_by_line_column_value_and_range() {
        let cases = [
            ("run,speed_rpm,sensor,re,im\nA,1200,s,1,2\n", None, "v.csv line 1: the vectors have no unit"),
            ("run,speed_rpm,sensor,re\nA,1200,s,1\n", Some("um"), "v.csv line 1: the header must name run,speed_rpm,sensor and either re,im or amp,phase_deg (found: run,speed_rpm,sensor,re)"),
            ("run,speed_rpm,sensor,re,im\nA,-5,s,1,2\n", Some("um"), "v.csv line 2, column 2 (speed_rpm): speed_rpm = -5 is out of range: must be finite and > 0 (rev/min)"),
            ("run,speed_rpm,sensor,re,im\nA,1200,s,abc,2\n", Some("um"), "v.csv line 2, column 4 (re): re \"abc\" is not a number: expected a number"),
            ("run,speed_rpm,sensor,re,im\nA,1200,,1,2\n", Some("um"), "v.csv line 2, column 3 (sensor): sensor is empty: every row needs one"),
            ("run,speed_rpm,sensor,re,im\nA,1200,s,1,2\nA,1200,s,3,4\n", Some("um"), "v.csv line 3: run \"A\", sensor \"s\" at 1200 rpm is also on line 2: give each vector once"),
            ("run,speed_rpm,sensor,re,im,std\nA,1200,s,1,2,-1\n", Some("um"), "v.csv line 2, column 6 (std): std = -1 is out of range: must be finite and >= 0"),
            ("run,speed_rpm,sensor,re,im\nA,1200,s,1\n", Some("um"), "v.csv line 2: short row: 4 fields where the header (line 1) has 5"),
            ("", Some("um"), "v.csv: the file is empty"),
            ("run,speed_rpm,sensor,re,im\n", Some("um"), "v.csv: no vector"),
            ("run,speed_rpm,sensor,re,im,re_std\nA,1200,s,1,2,3\n", Some("um"), "v.csv line 1: re_std and im_std go together"),
        ];
        for (text, unit, want) in cases {
            let e = vectors(text, None, unit).unwrap_err();
            assert!(e.starts_with(want), "{text:?}: {e}");
        }
    }

    #[test]
    fn masses_and_their_errors() {
        let m = read_masses(
            "m.csv",
            "run,plane,mass_kg,radius_m,angle_deg\nA,P1,0,0,0\nT1,P1,0.002,0.1,-30\n".as_bytes(),
        )
        .unwrap();
        assert_eq!(m.len(), 2);
        assert_eq!(
            (m[1].mass_kg, m[1].radius_m, m[1].angle_deg, m[1].line),
            (0.002, 0.1, -30.0, 3)
        );
        let cases = [
            ("run,plane,mass_kg,radius_m\nA,P,0,0\n", "m.csv line 1: the header lacks column angle_deg"),
            ("run,plane,mass_kg,radius_m,angle_deg\nA,P,-1,0.1,0\n", "m.csv line 2, column 3 (mass_kg): mass_kg = -1 is out of range: must be finite and >= 0 (kg)"),
            ("run,plane,mass_kg,radius_m,angle_deg\nA,P,0.1,0,0\n", "m.csv line 2, column 4 (radius_m): radius_m = 0 is out of range: must be finite and > 0 (m) for a non-zero mass"),
            ("run,plane,mass_kg,radius_m,angle_deg\nA,P,0.1,0.1,inf\n", "m.csv line 2, column 5 (angle_deg): angle_deg = inf is out of range: must be finite (deg)"),
        ];
        for (text, want) in cases {
            let e = read_masses("m.csv", text.as_bytes())
                .unwrap_err()
                .to_string();
            assert!(e.starts_with(want), "{text:?}: {e}");
        }
    }
}
