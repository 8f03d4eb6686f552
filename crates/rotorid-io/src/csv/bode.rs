//! A 1X (Bode) table as machinery-protection systems export it, for `rotorid transient
//! --vectors` (docs/transient.md section 6): one row per sensor and speed,
//!
//! - `speed_rpm,sensor` and either `amplitude,phase_lag_deg` (the phase lag: the angle
//!   from the keyphasor event to the next positive peak, against the rotation, so that
//!   the vector is `amplitude e^{-i lag}`) or `re,im` (the nX part of the signal is
//!   `Re((re + i im) e^{i phi})`);
//! - optional `unit` per row: `m`, `mm`, `um` (or `µm`, `micron`) or `mil` (without the
//!   column, the header's unit suffix of `amplitude`/`re` (`amplitude [um]`), else the
//!   caller's default);
//! - optional `std` (the standard deviation of each of re and im) or `re_std,im_std`.
//!
//! Amplitudes are zero-to-peak, or peak-to-peak when the caller says so
//! ([`Amplitude::PeakToPeak`]: halved). Everything read is converted to m. Extra columns
//! are ignored; a sensor given twice at one speed is an error naming both lines.

use std::collections::HashMap;
use std::io::Read;

use super::balance::{each_row, header, ranged, text_field};
use super::columns::csv_reader;
use super::error::CsvError;

/// How the table's amplitudes are measured.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Amplitude {
    /// Zero-to-peak.
    Peak,
    /// Peak-to-peak (twice the zero-to-peak of a sinusoid).
    PeakToPeak,
}

/// One row of a Bode table, in SI.
#[derive(Debug, Clone, PartialEq)]
pub struct BodeRow {
    /// Line in the file (header = 1).
    pub line: u64,
    /// Speed \[rev/min\].
    pub speed_rpm: f64,
    /// Sensor.
    pub sensor: String,
    /// Re V \[m\], zero-to-peak.
    pub re: f64,
    /// Im V \[m\], zero-to-peak.
    pub im: f64,
    /// Standard deviation of each of re and im \[m\], when given.
    pub std: Option<(f64, f64)>,
}

/// The header a Bode table needs (the column names every caller accepts).
pub const BODE_HEADER: &str = "speed_rpm,sensor,amplitude,phase_lag_deg";

/// Metres per unit of `unit` (module doc), `None` for an unknown unit.
pub fn metres_per(unit: &str) -> Option<f64> {
    match unit.trim().to_ascii_lowercase().as_str() {
        "m" => Some(1.0),
        "mm" => Some(1e-3),
        "um" | "µm" | "μm" | "micron" | "microns" => Some(1e-6),
        "mil" | "mils" => Some(25.4e-6),
        _ => None,
    }
}

/// The units [`metres_per`] knows, for messages.
pub const UNITS: &str = "m, mm, um, mil";

/// Read a Bode table (module doc); `default_unit` is the unit when the file gives none.
pub fn read_bode<R: Read>(
    file: &str,
    input: R,
    amplitude: Amplitude,
    default_unit: Option<&str>,
) -> Result<Vec<BodeRow>, CsvError> {
    let mut csv = csv_reader(input);
    let h = header(file, &mut csv, BODE_HEADER)?;
    let base = h.require(file, &["speed_rpm", "sensor"])?;
    let (re, im) = (h.find(file, "re")?, h.find(file, "im")?);
    let (amp, lag) = (h.find(file, "amplitude")?, h.find(file, "phase_lag_deg")?);
    let (ca, cb, is_polar) = match (re, im, amp, lag) {
        (Some(a), Some(b), None, None) => (a, b, false),
        (None, None, Some(a), Some(b)) => (a, b, true),
        (Some(_), Some(_), Some(_), _) | (Some(_), Some(_), _, Some(_)) => {
            return Err(CsvError::line(
                file,
                h.line,
                "the header has both re,im and amplitude,phase_lag_deg: give one form of the vectors",
            ))
        }
        _ => {
            return Err(CsvError::line(
                file,
                h.line,
                format!(
                    "the header must name speed_rpm,sensor and either amplitude,phase_lag_deg or re,im (found: {})",
                    h.names.join(",")
                ),
            ))
        }
    };
    let unit_col = h.find(file, "unit")?;
    let header_unit = h.units[ca].clone();
    let fallback = header_unit.or_else(|| default_unit.map(str::to_owned));
    if let Some(u) = &fallback {
        if metres_per(u).is_none() {
            return Err(CsvError::line(
                file,
                h.line,
                format!(
                    "the unit {u:?} of column {} is not one of {UNITS}",
                    h.names[ca]
                ),
            ));
        }
    }
    if unit_col.is_none() && fallback.is_none() {
        return Err(CsvError::line(
            file,
            h.line,
            format!("the vectors have no unit: give a unit column ({UNITS}), a unit in the header (amplitude [um]), or --unit"),
        ));
    }
    let std_col = h.find(file, "std")?;
    let (re_std, im_std) = (h.find(file, "re_std")?, h.find(file, "im_std")?);
    let std_cols = match (re_std, im_std, std_col) {
        (Some(a), Some(b), None) if !is_polar => Some((a, b)),
        (None, None, Some(s)) => Some((s, s)),
        (None, None, None) => None,
        _ => {
            return Err(CsvError::line(
                file,
                h.line,
                "give either std (each of re and im) or re_std,im_std (with re,im), not both",
            ))
        }
    };
    let scale_pp = match amplitude {
        Amplitude::Peak => 1.0,
        Amplitude::PeakToPeak => 0.5,
    };
    let mut rows: Vec<BodeRow> = Vec::new();
    let mut seen: HashMap<(String, u64), u64> = HashMap::new();
    each_row(file, &mut csv, &h, |rec, line| {
        let speed_rpm = ranged(
            file,
            rec,
            line,
            base[0],
            "speed_rpm",
            "finite and > 0 (rev/min)",
            |v| v > 0.0,
        )?;
        let sensor = text_field(file, rec, line, base[1], "sensor")?;
        let unit = match unit_col {
            Some(c) => {
                let s = String::from_utf8_lossy(rec.get(c).unwrap_or_default())
                    .trim()
                    .to_owned();
                match (s.is_empty(), &fallback) {
                    (true, Some(u)) => u.clone(),
                    (true, None) => {
                        return Err(CsvError::field(
                            file,
                            line,
                            c,
                            "unit",
                            format!("unit is empty: give one of {UNITS}"),
                        ))
                    }
                    (false, _) => s,
                }
            }
            None => fallback.clone().expect("checked above"),
        };
        let Some(per) = metres_per(&unit) else {
            return Err(CsvError::field(
                file,
                line,
                unit_col.unwrap_or(ca),
                "unit",
                format!("unit {unit:?} is not one of {UNITS}"),
            ));
        };
        let k = per * scale_pp;
        let (re, im) = if is_polar {
            let a = ranged(file, rec, line, ca, "amplitude", "finite and >= 0", |v| {
                v >= 0.0
            })?;
            let lag = ranged(file, rec, line, cb, "phase_lag_deg", "finite (deg)", |_| {
                true
            })?
            .to_radians();
            (a * lag.cos() * k, -a * lag.sin() * k)
        } else {
            (
                ranged(file, rec, line, ca, "re", "finite", |_| true)? * k,
                ranged(file, rec, line, cb, "im", "finite", |_| true)? * k,
            )
        };
        let std = match std_cols {
            Some((a, b)) => {
                let names = if a == b {
                    ("std", "std")
                } else {
                    ("re_std", "im_std")
                };
                Some((
                    ranged(file, rec, line, a, names.0, "finite and >= 0", |v| v >= 0.0)? * k,
                    ranged(file, rec, line, b, names.1, "finite and >= 0", |v| v >= 0.0)? * k,
                ))
            }
            None => None,
        };
        if let Some(prev) = seen.insert((sensor.clone(), speed_rpm.to_bits()), line) {
            return Err(CsvError::line(
                file,
                line,
                format!(
                    "sensor {sensor:?} at {speed_rpm} rpm is also on line {prev}: give each speed of a sensor once (average repeated readings first)"
                ),
            ));
        }
        rows.push(BodeRow {
            line,
            speed_rpm,
            sensor,
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn polar_rows_in_mils_pk_pk_become_metres_zero_to_peak() {
        let text =
            "speed_rpm,sensor,amplitude,phase_lag_deg,unit\n1000,x,2,90,mil\n1010,x,4,0,um\n";
        let rows = read_bode("t.csv", text.as_bytes(), Amplitude::PeakToPeak, None).unwrap();
        assert_eq!(rows.len(), 2);
        // 2 mil pk-pk = 25.4 um 0-pk, lag 90 deg: e^{-i pi/2} = -i
        assert!(rows[0].re.abs() < 1e-18);
        assert!((rows[0].im + 25.4e-6).abs() < 1e-15);
        assert!((rows[1].re - 2e-6).abs() < 1e-18);
    }

    #[test]
    fn cartesian_rows_with_a_header_unit_and_std() {
        let text = "speed_rpm,sensor,re [um],im,std\n1000,a,1,-2,0.1\n";
        let rows = read_bode("t.csv", text.as_bytes(), Amplitude::Peak, None).unwrap();
        assert_eq!(rows[0].std, Some((1e-7, 1e-7)));
        assert!((rows[0].im + 2e-6).abs() < 1e-18);
    }

    #[test]
    fn errors_name_the_line_and_the_field() {
        let dup = "speed_rpm,sensor,re,im,unit\n1000,a,1,2,um\n1000,a,1,2,um\n";
        let e = read_bode("t.csv", dup.as_bytes(), Amplitude::Peak, None).unwrap_err();
        let m = e.to_string();
        assert!(
            m.contains("t.csv") && m.contains('3') && m.contains("line 2"),
            "{m}"
        );
        let unit = "speed_rpm,sensor,re,im,unit\n1000,a,1,2,furlong\n";
        let m = read_bode("t.csv", unit.as_bytes(), Amplitude::Peak, None)
            .unwrap_err()
            .to_string();
        assert!(m.contains("furlong") && m.contains("m, mm, um, mil"), "{m}");
        let none = "speed_rpm,sensor,re,im\n1000,a,1,2\n";
        let m = read_bode("t.csv", none.as_bytes(), Amplitude::Peak, None)
            .unwrap_err()
            .to_string();
        assert!(m.contains("no unit"), "{m}");
        let speed = "speed_rpm,sensor,re,im,unit\n-5,a,1,2,um\n";
        let m = read_bode("t.csv", speed.as_bytes(), Amplitude::Peak, None)
            .unwrap_err()
            .to_string();
        assert!(m.contains("speed_rpm") && m.contains("> 0"), "{m}");
    }
}
