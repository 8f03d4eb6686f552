//! The response CSV: the rotor's measured or simulated vibration, one row per sample.
//!
//! ```text
//! t,x,z,phi,phi_dot,phi_ddot
//! s,m,m,rad,rad/s,rad/s^2          (units, not written: SI throughout)
//! ```
//!
//! Written by `rotorid simulate` with exactly that header, every value in shortest
//! round-trip form (see [`super::number`]). Read by `rotorid identify`, `rotorid plot` and
//! the Python package's `read` ([`ResponseReader`], streaming), which accept more:
//!
//! - columns in any order, extra columns ignored (their content is not even parsed);
//!   header names may carry a unit suffix (`x [m]`; see [`super::columns`]);
//! - `t`, `x`, `z` required; `phi`, `phi_dot`, `phi_ddot` all three or none (partial is an
//!   error naming the missing ones);
//! - every used field a finite number; rows as long as the header.
//!
//! The time grid (increasing, uniform within a tolerance, dt fitted over the stamps) is
//! checked by the library (`rotorid::pipeline::TimeGrid`), not here.
//!
//! Errors name the file, the line (header = line 1) and the column (see
//! [`super::error`]).

use std::io::Read;

use csv::ByteRecord;

use super::columns::{check_length, csv_reader, finite_field, next_record, CsvReader, Header};
use super::error::CsvError;

/// The header `rotorid simulate` writes.
pub const RESPONSE_HEADER: [&str; 6] = ["t", "x", "z", "phi", "phi_dot", "phi_ddot"];

/// The rotor's angle and its derivatives at one sample.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Speed {
    /// Rotor angle phi \[rad\].
    pub phi: f64,
    /// Speed w = phi_dot \[rad/s\].
    pub phi_dot: f64,
    /// Acceleration w' = phi_ddot \[rad/s^2\].
    pub phi_ddot: f64,
}

/// One validated row of a response CSV.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResponseRow {
    /// 1-based line in the file.
    pub line: u64,
    /// Time t \[s\].
    pub t: f64,
    /// Horizontal displacement x \[m\].
    pub x: f64,
    /// Vertical displacement z \[m\].
    pub z: f64,
    /// phi, phi_dot, phi_ddot, when the file has them.
    pub speed: Option<Speed>,
}

/// Streaming reader of a response CSV: validates each row as it is read and keeps O(1)
/// state, so it reads a live pipe of any length (see the module doc for the rules).
pub struct ResponseReader<R: Read> {
    file: String,
    csv: CsvReader<R>,
    header: Header,
    txz: [usize; 3],
    phi: Option<[usize; 3]>,
    rec: ByteRecord,
}

impl<R: Read> ResponseReader<R> {
    /// Read and check the header of `input`; `file` names it in messages.
    pub fn new(file: &str, input: R) -> Result<Self, CsvError> {
        let mut csv = csv_reader(input);
        let mut rec = ByteRecord::new();
        let Some(line) = next_record(file, &mut csv, &mut rec)? else {
            return Err(CsvError::file(
                file,
                "the file is empty: expected a header line naming at least t,x,z, then one \
                 row per sample",
            ));
        };
        let header = Header::new(&rec, line);
        let txz = header.require(file, &["t", "x", "z"])?;
        let phis = [
            header.find(file, "phi")?,
            header.find(file, "phi_dot")?,
            header.find(file, "phi_ddot")?,
        ];
        let phi = match phis {
            [Some(a), Some(b), Some(c)] => Some([a, b, c]),
            [None, None, None] => None,
            _ => {
                let missing: Vec<&str> = ["phi", "phi_dot", "phi_ddot"]
                    .iter()
                    .zip(phis)
                    .filter(|(_, p)| p.is_none())
                    .map(|(n, _)| *n)
                    .collect();
                return Err(CsvError::line(
                    file,
                    line,
                    format!(
                        "the header has some but not all of phi, phi_dot, phi_ddot: missing {}; \
                         give all three or none (then the scenario's speed profile is used)",
                        missing.join(", ")
                    ),
                ));
            }
        };
        Ok(Self {
            file: file.to_owned(),
            csv,
            header,
            txz: [txz[0], txz[1], txz[2]],
            phi,
            rec,
        })
    }

    /// The file's name in messages.
    pub fn file(&self) -> &str {
        &self.file
    }

    /// True when the file has the phi, phi_dot, phi_ddot columns.
    pub fn has_phi(&self) -> bool {
        self.phi.is_some()
    }

    /// The next validated row, or `None` at the end of the input.
    pub fn next_row(&mut self) -> Result<Option<ResponseRow>, CsvError> {
        let f = self.file.as_str();
        let Some(line) = next_record(f, &mut self.csv, &mut self.rec)? else {
            return Ok(None);
        };
        check_length(f, &self.rec, line, &self.header)?;
        let field = |col: usize, name: &str| finite_field(f, &self.rec, line, col, name);
        let [ct, cx, cz] = self.txz;
        let t = field(ct, "t")?;
        let x = field(cx, "x")?;
        let z = field(cz, "z")?;
        let speed = match self.phi {
            Some([a, b, c]) => Some(Speed {
                phi: field(a, "phi")?,
                phi_dot: field(b, "phi_dot")?,
                phi_ddot: field(c, "phi_ddot")?,
            }),
            None => None,
        };
        Ok(Some(ResponseRow {
            line,
            t,
            x,
            z,
            speed,
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(crate) fn read_all(text: &str) -> Result<Vec<ResponseRow>, CsvError> {
        let mut r = ResponseReader::new("d.csv", text.as_bytes())?;
        let mut rows = Vec::new();
        while let Some(row) = r.next_row()? {
            rows.push(row);
        }
        Ok(rows)
    }

    fn err(text: &str) -> String {
        read_all(text).expect_err("must be rejected").to_string()
    }

    #[test]
    fn any_order_units_and_extra_columns() {
        let rows = read_all("note,Z [m],t (s),x\nabc,2,0,1\nzz,4,0.5,3\n,6,1,5\n").unwrap();
        assert_eq!(rows.len(), 3);
        assert_eq!((rows[1].t, rows[1].x, rows[1].z), (0.5, 3.0, 4.0));
        assert_eq!(rows[1].line, 3);
        assert!(rows[0].speed.is_none());
        let rows =
            read_all("t,x,z,phi,phi_dot,phi_ddot\n0,1.5e-7,-3.3e-300,0.1,125.66370614359172,0\n")
                .unwrap();
        assert_eq!(rows[0].z, -3.3e-300);
        assert_eq!(
            rows[0].speed,
            Some(Speed {
                phi: 0.1,
                phi_dot: 125.66370614359172,
                phi_ddot: 0.0
            })
        );
    }

    #[test]
    fn header_problems_name_line_1() {
        assert_eq!(
            err(""),
            "d.csv: the file is empty: expected a header line naming at least t,x,z, then one \
             row per sample"
        );
        assert!(err("t,x\n0,1\n").starts_with("d.csv line 1: the header lacks column z;"));
        assert!(err("time,x,y\n").starts_with("d.csv line 1: the header lacks columns t, z;"));
        assert!(err("t,x,z,phi\n").starts_with(
            "d.csv line 1: the header has some but not all of phi, phi_dot, phi_ddot: missing \
             phi_dot, phi_ddot"
        ));
        assert!(err("t,x,z,x\n")
            .starts_with("d.csv line 1, column 4 (x): column x appears twice (columns 2 and 4)"));
    }

    #[test]
    fn bad_rows_name_line_and_column() {
        let h = "t,x,z\n0,0,0\n0.1,0,0\n";
        assert_eq!(
            err(&format!("{h}0.2,abc,0\n")),
            "d.csv line 4, column 2 (x): x \"abc\" is not a number: expected a number"
        );
        assert!(err(&format!("{h}0.2,0,nan\n"))
            .starts_with("d.csv line 4, column 3 (z): z = NaN is not finite"));
        assert!(err(&format!("{h}0.2,0,-inf\n"))
            .starts_with("d.csv line 4, column 3 (z): z = -inf is not finite"));
        assert_eq!(
            err(&format!("{h}0.2,0\n")),
            "d.csv line 4: short row: 2 fields where the header (line 1) has 3"
        );
        assert!(err(&format!("{h}0.2,0,0,9\n")).starts_with("d.csv line 4: long row"));
    }
}
