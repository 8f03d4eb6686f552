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
//! - columns in any order, extra columns ignored (their content is not even parsed, their
//!   units not checked);
//! - a used column may carry a unit suffix, `x [um]`, `t (ms)`, `phi_dot [rpm]`,
//!   `phi [deg]`, `phi_ddot [rpm/s]` (see [`crate::units`] for every unit taken): its
//!   values are converted to SI as they are read (t a time, x and z displacements, phi an
//!   angle, phi_dot an angular speed, phi_ddot an angular acceleration), and
//!   [`ResponseReader::conversions`] says which were. A unit that is unknown or of another
//!   quantity is an error naming the header line, the column and the units accepted:
//!   `data.csv line 1, column 2 (x): unknown unit "furlong" for a displacement: use one of
//!   m, mm, um (µm), nm, mil, in`. No suffix, or the SI unit, leaves the values bit for
//!   bit as written;
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

use std::ops::Range;

use super::columns::{
    check_length, csv_reader, finite_field, line_prefix, next_raw, next_record, one_pass,
    CsvReader, Header,
};
use super::error::CsvError;
use super::number::{format_f64, readable};
use super::records::{split_line, RawRecord};
use crate::units::{Conversion, Quantity};

/// The header `rotorid simulate` writes.
pub const RESPONSE_HEADER: [&str; 6] = ["t", "x", "z", "phi", "phi_dot", "phi_ddot"];

/// What each column of [`RESPONSE_HEADER`] holds.
pub const RESPONSE_QUANTITIES: [Quantity; 6] = [
    Quantity::Time,
    Quantity::Displacement,
    Quantity::Displacement,
    Quantity::Angle,
    Quantity::AngularSpeed,
    Quantity::AngularAcceleration,
];

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
    /// The conversion to SI of t, x, z, phi, phi_dot, phi_ddot.
    conv: [Conversion; 6],
    /// Per column, the index in t, x, z, phi, phi_dot, phi_ddot it plays, or [`UNUSED`].
    roles: Vec<u8>,
    /// Scratch fields of a line split for the general path.
    fields: Vec<Range<usize>>,
    /// Try the one-pass parse first (off only in tests, to compare both paths).
    fast: bool,
}

/// The role of a column the reader does not use ([`ResponseReader`]'s `roles`).
const UNUSED: u8 = u8::MAX;

impl<R: Read> ResponseReader<R> {
    /// Read and check the header of `input`; `file` names it in messages.
    pub fn new(file: &str, input: R) -> Result<Self, CsvError> {
        let mut csv = csv_reader(input);
        let Some(rec) = next_record(file, &mut csv)? else {
            return Err(CsvError::file(
                file,
                "the file is empty: expected a header line naming at least t,x,z, then one \
                 row per sample",
            ));
        };
        let line = rec.line();
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
        let mut conv = RESPONSE_QUANTITIES.map(Conversion::si);
        let used = txz.iter().chain(phi.iter().flatten());
        for ((c, &col), (name, q)) in conv
            .iter_mut()
            .zip(used)
            .zip(RESPONSE_HEADER.iter().zip(RESPONSE_QUANTITIES))
        {
            *c = header.conversion(file, col, name, q)?;
        }
        let mut roles = vec![UNUSED; header.names.len()];
        for (role, &col) in txz.iter().chain(phi.iter().flatten()).enumerate() {
            roles[col] = role as u8;
        }
        Ok(Self {
            file: file.to_owned(),
            csv,
            header,
            txz: [txz[0], txz[1], txz[2]],
            phi,
            conv,
            roles,
            fields: Vec::with_capacity(16),
            fast: true,
        })
    }

    /// The columns whose unit is not SI, each with its conversion, in the order t, x, z,
    /// phi, phi_dot, phi_ddot (empty for a file in SI).
    pub fn conversions(&self) -> Vec<(&'static str, Conversion)> {
        RESPONSE_HEADER
            .into_iter()
            .zip(self.conv)
            .filter(|(_, c)| !c.is_identity())
            .collect()
    }

    /// One line per converted column, for the user: `FILE: x in um, converted to m (x 1e-6)`.
    pub fn conversion_notes(&self) -> Vec<String> {
        self.conversions()
            .into_iter()
            .map(|(name, c)| conversion_note(&self.file, name, &c))
            .collect()
    }

    /// The file's name in messages.
    pub fn file(&self) -> &str {
        &self.file
    }

    /// Every remaining row, as columns in SI (the reader's conversions are in
    /// [`Self::conversions`]; `used` is left empty).
    pub fn read_columns(&mut self) -> Result<crate::SiColumns, CsvError> {
        let mut c = crate::SiColumns {
            speed: self.has_phi().then(Default::default),
            ..Default::default()
        };
        while let Some(row) = self.next_row()? {
            c.t.push(row.t);
            c.x.push(row.x);
            c.z.push(row.z);
            if let (Some(s), Some([p, w, a])) = (row.speed, c.speed.as_mut()) {
                p.push(s.phi);
                w.push(s.phi_dot);
                a.push(s.phi_ddot);
            }
        }
        Ok(c)
    }

    /// True when the file has the phi, phi_dot, phi_ddot columns.
    pub fn has_phi(&self) -> bool {
        self.phi.is_some()
    }

    /// The next validated row, or `None` at the end of the input.
    ///
    /// A line without quotes is first parsed in one pass straight out of the read buffer
    /// (`RecordReader::try_line` with `columns::line_prefix`), or, when it is not whole in
    /// the buffer, once found (`columns::one_pass`); a line that pass does not take (blanks
    /// around a field, a bad or non-finite number, a wrong field count, ...) is split and
    /// checked field by field, which gives the same values and names what is wrong.
    pub fn next_row(&mut self) -> Result<Option<ResponseRow>, CsvError> {
        if self.fast {
            let (roles, conv, has_phi) = (&self.roles, &self.conv, self.phi.is_some());
            if let Some((row, line)) = self.csv.try_line(|rest| {
                let mut v = [0.0_f64; 6];
                let len = line_prefix(
                    rest,
                    roles.len(),
                    |j| roles[j] != UNUSED,
                    |j, raw| take_si(&mut v, roles, conv, j, raw),
                )?;
                Some((row_of(v, has_phi), len))
            }) {
                return Ok(Some(ResponseRow { line, ..row }));
            }
        }
        let Some(raw) = next_raw(&self.file, &mut self.csv)? else {
            return Ok(None);
        };
        let rec = match raw {
            RawRecord::Line { text, line } => {
                if self.fast {
                    if let Some(row) =
                        fast_row(text, line, &self.roles, &self.conv, self.phi.is_some())
                    {
                        return Ok(Some(row));
                    }
                }
                split_line(text, line, &mut self.fields)
            }
            RawRecord::Quoted(rec) => rec,
        };
        let f = self.file.as_str();
        let line = rec.line();
        check_length(f, &rec, line, &self.header)?;
        let conv = &self.conv;
        let field = |col: usize, role: usize| {
            let name = RESPONSE_HEADER[role];
            let v = finite_field(f, &rec, line, col, name)?;
            convert(f, line, col, name, &conv[role], v)
        };
        let [ct, cx, cz] = self.txz;
        let t = field(ct, 0)?;
        let x = field(cx, 1)?;
        let z = field(cz, 2)?;
        let speed = match self.phi {
            Some([a, b, c]) => Some(Speed {
                phi: field(a, 3)?,
                phi_dot: field(b, 4)?,
                phi_ddot: field(c, 5)?,
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

/// The row of the plain line `text` parsed in one pass ([`one_pass`]: the same values bit
/// for bit as the general path); `None` when the line needs the general path, which also
/// refuses a value that is not finite in the file or in SI.
#[inline]
fn fast_row(
    text: &[u8],
    line: u64,
    roles: &[u8],
    conv: &[Conversion; 6],
    has_phi: bool,
) -> Option<ResponseRow> {
    let mut v = [0.0_f64; 6];
    one_pass(
        text,
        roles.len(),
        |j| roles[j] != UNUSED,
        |j, raw| take_si(&mut v, roles, conv, j, raw),
    )?;
    Some(ResponseRow {
        line,
        ..row_of(v, has_phi)
    })
}

/// Column `j`'s value `raw` into `v`, in SI, by its role; `None` (the general path) when
/// it is not finite in the file or in SI.
#[inline]
fn take_si(
    v: &mut [f64; 6],
    roles: &[u8],
    conv: &[Conversion; 6],
    j: usize,
    raw: f64,
) -> Option<()> {
    let role = usize::from(roles[j]);
    let si = conv.get(role)?.apply(raw);
    if !(raw.is_finite() && si.is_finite()) {
        return None;
    }
    v[role] = si;
    Some(())
}

/// The row of the values `v` by role (line 0: the caller sets it).
#[inline]
fn row_of(v: [f64; 6], has_phi: bool) -> ResponseRow {
    ResponseRow {
        line: 0,
        t: v[0],
        x: v[1],
        z: v[2],
        speed: has_phi.then_some(Speed {
            phi: v[3],
            phi_dot: v[4],
            phi_ddot: v[5],
        }),
    }
}

/// `v` of column `col` in SI by `c`; a finite value that overflows (`1e308 rev`) is an
/// error, never an infinity.
#[inline]
fn convert(
    file: &str,
    line: u64,
    col: usize,
    name: &str,
    c: &Conversion,
    v: f64,
) -> Result<f64, CsvError> {
    let si = c.apply(v);
    if si.is_finite() {
        return Ok(si);
    }
    Err(CsvError::field(
        file,
        line,
        col,
        name,
        format!(
            "{name} = {} {} is {} in {}: every value must be a finite number",
            readable(v),
            c.unit,
            readable(si),
            c.quantity.si()
        ),
    ))
}

/// `FILE: NAME in UNIT, converted to SI (x FACTOR)`: what the reader did to a column.
pub fn conversion_note(file: &str, name: &str, c: &Conversion) -> String {
    format!(
        "{file}: {name} in {}, converted to {} (x {})",
        c.unit,
        c.quantity.si(),
        format_f64(c.factor())
    )
}

#[cfg(test)]
mod tests {
    use std::f64::consts::PI;

    use proptest::strategy::Strategy;

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
    fn units_in_the_header_convert_to_si_by_their_definitions() {
        let text = "T (ms),x [um],z [µm],phi [deg],phi_dot [rpm],phi_ddot [rpm/s],note [furlong]\n\
                    0.1,12.5,-3.3,180,60,30,abc\n0.2,0.7,1e-3,-90,3000,-1.5,\n";
        let mut r = ResponseReader::new("d.csv", text.as_bytes()).unwrap();
        let names: Vec<&str> = r.conversions().iter().map(|(n, _)| *n).collect();
        assert_eq!(names, RESPONSE_HEADER);
        assert_eq!(
            r.conversion_notes()[1],
            "d.csv: x in um, converted to m (x 1e-6)"
        );
        assert_eq!(
            r.conversion_notes()[4],
            "d.csv: phi_dot in rpm, converted to rad/s (x 0.10471975511965977)"
        );
        let rows: Vec<ResponseRow> = std::iter::from_fn(|| r.next_row().unwrap()).collect();
        // decimal prefixes: one correctly rounded division, within one ulp of the decimal
        let ulps = |a: f64, text: &str| {
            let b: f64 = text.parse().unwrap();
            (a.to_bits() as i64 - b.to_bits() as i64).abs()
        };
        assert_eq!(rows[0].t, 1e-4);
        assert_eq!(rows[1].t, 2e-4);
        assert!(ulps(rows[0].x, "12.5e-6") <= 1 && ulps(rows[0].z, "-3.3e-6") <= 1);
        assert!(ulps(rows[1].x, "0.7e-6") <= 1 && ulps(rows[1].z, "1e-9") <= 1);
        // the other factors: 180 deg = pi rad, 60 rpm = 1 rev/s = 2 pi rad/s,
        // 30 rpm/s = pi rad/s^2
        let close = |a: f64, b: f64| (a - b).abs() <= 2e-16 * b.abs();
        let s = rows[0].speed.unwrap();
        assert!(close(s.phi, PI) && close(s.phi_dot, 2.0 * PI) && close(s.phi_ddot, PI));
        let s = rows[1].speed.unwrap();
        assert!(close(s.phi, -PI / 2.0) && close(s.phi_dot, 100.0 * PI));
        assert!(close(s.phi_ddot, -0.05 * PI));
    }

    #[test]
    fn si_units_and_no_units_leave_the_bits_alone() {
        let values =
            "0.1,1.2345678901234567e-7,-3.3e-300,0.30000000000000004,125.66370614359172,5e-324";
        for header in [
            "t,x,z,phi,phi_dot,phi_ddot",
            "t [s],x [m],z (m),phi [rad],phi_dot [rad/s],phi_ddot [rad/s^2]",
        ] {
            let text = format!("{header}\n{values}\n");
            let r = ResponseReader::new("d.csv", text.as_bytes()).unwrap();
            assert!(r.conversions().is_empty(), "{header}");
            let row = read_all(&text).unwrap()[0];
            assert_eq!(row.x.to_bits(), 1.2345678901234567e-7f64.to_bits());
            assert_eq!(row.speed.unwrap().phi_ddot.to_bits(), 5e-324f64.to_bits());
        }
    }

    #[test]
    fn a_converted_file_reads_as_the_same_file_in_si() {
        // x written in um (the value times 1e6, exact for these dyadic values) reads back
        // as the SI file, bit for bit where the decimal division is exact
        let mut si = String::from("t,x,z\n");
        let mut um = String::from("t,x [um],z [mm]\n");
        for i in 0..200 {
            let x = f64::from(i) * 0.5 - 37.0; // um
            let z = f64::from(i) * 0.25; // mm
            si.push_str(&format!(
                "{i},{},{}\n",
                format_f64(x / 1e6),
                format_f64(z / 1e3)
            ));
            um.push_str(&format!("{i},{},{}\n", format_f64(x), format_f64(z)));
        }
        assert_eq!(read_all(&si).unwrap(), read_all(&um).unwrap());
    }

    #[test]
    fn unknown_and_wrong_units_name_the_column_and_what_is_accepted() {
        assert_eq!(
            err("t,x [furlong],z\n0,1,2\n"),
            "d.csv line 1, column 2 (x): unknown unit \"furlong\" for a displacement: use one of \
             m, mm, um (µm), nm, mil, in"
        );
        assert_eq!(
            err("\nt,z,x [rpm]\n"),
            "d.csv line 2, column 3 (x): unit \"rpm\" is an angular speed unit, but this channel \
             holds a displacement: use one of m, mm, um (µm), nm, mil, in"
        );
        let e = ResponseReader::new(
            "d.csv",
            "t,x,z,phi [deg],phi_dot [deg],phi_ddot\n".as_bytes(),
        )
        .err()
        .unwrap();
        assert!(matches!(
            e.unit.as_deref(),
            Some(crate::UnitError::WrongQuantity {
                found: Quantity::Angle,
                expected: Quantity::AngularSpeed,
                ..
            })
        ));
        assert!(e
            .to_string()
            .starts_with("d.csv line 1, column 5 (phi_dot): unit \"deg\""));
        // the unit of an ignored column is not looked at
        assert!(read_all("t,x,z,comment [furlong]\n0,1,2,x\n").is_ok());
    }

    #[test]
    fn a_conversion_that_overflows_is_an_error() {
        let e = err("t,x,z,phi [rev],phi_dot,phi_ddot\n0,0,0,1e308,0,0\n");
        assert_eq!(
            e,
            "d.csv line 2, column 4 (phi): phi = 1.0e308 rev is inf in rad: every value must be \
             a finite number"
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

    /// Every row of `text` with the one-pass parse on, off, and on with `text` coming
    /// `step` bytes per read ([`super::super::Trickle`]): the rows' bits, or the error.
    fn read_three(text: &[u8], step: usize) -> [Result<Vec<[u64; 7]>, String>; 3] {
        [(true, usize::MAX), (false, usize::MAX), (true, step)].map(|(fast, step)| {
            let input = super::super::Trickle { text, step };
            let mut r = ResponseReader::new("d.csv", input).map_err(|e| e.to_string())?;
            r.fast = fast;
            let mut rows = Vec::new();
            while let Some(row) = r.next_row().map_err(|e| e.to_string())? {
                let s = row.speed.map_or([u64::MAX; 3], |s| {
                    [s.phi.to_bits(), s.phi_dot.to_bits(), s.phi_ddot.to_bits()]
                });
                rows.push([
                    row.line,
                    row.t.to_bits(),
                    row.x.to_bits(),
                    row.z.to_bits(),
                    s[0],
                    s[1],
                    s[2],
                ]);
            }
            Ok(rows)
        })
    }

    #[test]
    fn the_one_pass_parse_takes_plain_rows_and_leaves_the_rest() {
        let roles = [0, 1, 2];
        let conv = RESPONSE_QUANTITIES.map(Conversion::si);
        let row = |t: &str| fast_row(t.as_bytes(), 7, &roles, &conv, false);
        let r = row("0.5,-1.25e-7,3").unwrap();
        assert_eq!(
            (r.line, r.t, r.x, r.z, r.speed),
            (7, 0.5, -1.25e-7, 3.0, None)
        );
        for general in [
            " 0.5,1,2",
            "0.5,1,2 ",
            "0.5,,2",
            "0.5,1",
            "0.5,1,2,",
            "0.5,1,2,3",
            "nan,1,2",
            "0.5,inf,2",
            "0.5,1e400,2",
            "0.5,1x,2",
            "0.5,1e,2",
            "",
            "0.5;1;2",
        ] {
            assert!(row(general).is_none(), "{general:?}");
        }
        let long = format!(
            "0.{},1,2",
            "0".repeat(super::super::columns::MAX_FIELD_BYTES)
        );
        assert!(row(&long).is_none(), "a number over MAX_FIELD_BYTES");
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(3000))]

        /// Rows read with and without the one-pass parse are the same bit for bit, and a
        /// refused file gives the same message, whatever the header's order, units and
        /// extra columns and whatever the fields hold.
        #[test]
        fn the_one_pass_parse_changes_no_value_and_no_message(
            header in proptest::sample::select(vec![
                "t,x,z", "x,t,z,note", "t (ms),x [um],z,phi,phi_dot,phi_ddot",
                "note,phi_ddot,phi,z,x,phi_dot [rpm],t",
                "t,x [mm],z,phi [deg],phi_dot,phi_ddot [rpm/s]",
            ]),
            rows in proptest::collection::vec(
                proptest::collection::vec(
                    proptest::prop_oneof![
                        4 => (-1e6f64..1e6).prop_map(|v| v.to_string()),
                        4 => proptest::num::f64::NORMAL.prop_map(|v| format!("{v:e}")),
                        1 => proptest::sample::select(vec![
                            "", " 1", "1 ", "nan", "-inf", "inf", "1e400", "-1e-400", "+2.5",
                            ".5", "5.", "1e", "0x10", "abc", "1_0", "\"3\"", "1e308",
                            "-0", "00012", "1.7976931348623157e308", "4.9e-324",
                        ]).prop_map(str::to_owned),
                    ],
                    5..9,
                ),
                0..6,
            ),
            ends in proptest::collection::vec(0u8..5, 1..4),
            step in 1usize..40,
        ) {
            let cols = header.split(',').count();
            let mut text = format!("{header}\n");
            for (i, row) in rows.iter().enumerate() {
                // mostly the header's count of fields, sometimes one more or fewer
                let n = match i % 4 { 1 => cols + 1, 3 => cols - 1, _ => cols }.min(row.len());
                text.push_str(&row[..n].join(","));
                // LF, CRLF, a lone CR, a blank line after, or no line end at the end
                let last = i + 1 == rows.len();
                text.push_str(super::super::test_line_end(ends[i % ends.len()], last));
            }
            let [fast, general, trickled] = read_three(text.as_bytes(), step);
            proptest::prop_assert_eq!(&fast, &general, "{}", text);
            proptest::prop_assert_eq!(&trickled, &general, "{} bytes per read: {}", step, text);
        }
    }
}
