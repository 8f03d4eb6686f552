//! CSV headers and fields shared by the readers: column names (with an optional unit
//! suffix), the search for required columns, and the parsing of one numeric field.
//!
//! Header names are compared after trimming blanks, dropping a UTF-8 byte-order mark,
//! splitting off one trailing unit suffix in brackets or parentheses (`x [um]`,
//! `phi_dot (rpm)`; [`crate::units::split_unit`]) and lower-casing, so `t,x,z`,
//! `T [s],X [m],Z [m]` and `t (s), x (m), z (m)` all name the same columns. The unit is
//! kept ([`Header::units`]): a reader converts the columns it uses to SI with
//! [`crate::units::conversion`] and refuses a unit it does not know for the column's role
//! (the response reader: [`super::response`]). No suffix means SI.
//!
//! Limits: a line (header included) holds at most [`MAX_LINE_BYTES`] ([`super::lines`]),
//! a number field at most [`MAX_FIELD_BYTES`]; messages quote at most a short prefix of a
//! bad value ([`super::error::quote`]).

use std::io::Read;

use super::error::{abbreviate, quote, CsvError, WriteFailure, QUOTE_CHARS};
use super::lines::{LineTooLong, MAX_LINE_BYTES};
use super::number::parse_f64;
use super::records::{RawRecord, Record, RecordReader};
use crate::units::{conversion, split_unit, Conversion, Quantity, UnitError};

/// The longest number field accepted, in bytes (the shortest round-trip text of any `f64`
/// has at most 24).
pub const MAX_FIELD_BYTES: usize = 1024;

/// Header names quoted in a message, at most this many characters in all.
const HEADER_QUOTE_CHARS: usize = 200;

/// The normalised column name (see the module doc).
pub fn normalise(raw: &[u8]) -> String {
    name_and_unit(raw).0
}

/// The normalised column name and the unit of its suffix, as written (trimmed), if any:
/// `b" X [um] "` -> `("x", Some("um"))`.
pub fn name_and_unit(raw: &[u8]) -> (String, Option<String>) {
    let s = String::from_utf8_lossy(raw);
    let (name, unit) = split_unit(s.trim_start_matches('\u{feff}'));
    (name.to_lowercase(), unit.map(str::to_owned))
}

/// The header of a CSV file: normalised names, their units and the line it is on.
#[derive(Debug, Clone)]
pub struct Header {
    /// Normalised names, in file order.
    pub names: Vec<String>,
    /// The unit suffix of each column as written (`um`, `rpm`), `None` without one.
    pub units: Vec<Option<String>>,
    /// 1-based line of the header.
    pub line: u64,
}

impl Header {
    /// Read from the header record `rec` found at `line`.
    pub fn new(rec: &Record<'_>, line: u64) -> Self {
        let (names, units) = rec.iter().map(name_and_unit).unzip();
        Self { names, units, line }
    }

    /// How column `col`, holding `quantity` for the role `name`, becomes SI: from its unit
    /// suffix (none: SI). A unit that is unknown or of another quantity is an error naming
    /// the header line, the column and the units accepted.
    pub fn conversion(
        &self,
        file: &str,
        col: usize,
        name: &str,
        quantity: Quantity,
    ) -> Result<Conversion, CsvError> {
        let unit = self.units.get(col).and_then(Option::as_deref);
        conversion(quantity, unit).map_err(|mut e| {
            // the unit as written may be anything: quote a short prefix of it
            let (UnitError::Unknown { unit, .. } | UnitError::WrongQuantity { unit, .. }) = &mut e;
            *unit = abbreviate(unit, QUOTE_CHARS);
            let mut err = CsvError::field(file, self.line, col, name, e.to_string());
            err.unit = Some(Box::new(e));
            err
        })
    }

    /// Position of column `name`, or `None`. A name that appears twice is an error
    /// (which of the two would be meant is ambiguous).
    pub fn find(&self, file: &str, name: &str) -> Result<Option<usize>, CsvError> {
        let mut hits = self.names.iter().enumerate().filter(|(_, n)| *n == name);
        let first = hits.next().map(|(i, _)| i);
        if let Some((j, _)) = hits.next() {
            let i = first.expect("a second hit implies a first");
            return Err(CsvError::field(
                file,
                self.line,
                j,
                name,
                format!(
                    "column {name} appears twice (columns {} and {})",
                    i + 1,
                    j + 1
                ),
            ));
        }
        Ok(first)
    }

    /// Positions of every name in `required`; the error names all that are missing.
    pub fn require(&self, file: &str, required: &[&str]) -> Result<Vec<usize>, CsvError> {
        let mut found = Vec::with_capacity(required.len());
        let mut missing = Vec::new();
        for name in required {
            match self.find(file, name)? {
                Some(i) => found.push(i),
                None => missing.push(*name),
            }
        }
        if missing.is_empty() {
            Ok(found)
        } else {
            Err(CsvError::line(
                file,
                self.line,
                format!(
                    "the header lacks column{} {}; it must name at least {} (found: {})",
                    if missing.len() > 1 { "s" } else { "" },
                    missing.join(", "),
                    required.join(","),
                    abbreviate(&self.names.join(","), HEADER_QUOTE_CHARS)
                ),
            ))
        }
    }
}

/// The numbers of the plain line `text` (no quote, line end excluded) in one pass, for the
/// readers' fast path: `cols` fields separated by `,`; field `j` is parsed where it starts by
/// [`super::decimal::number_prefix`] (the parser [`number_field`] uses, so a value is the
/// same bit for bit) when `used(j)` and must be exactly one number of at most
/// [`MAX_FIELD_BYTES`] bytes, then `take(j, value)` decides (`None`: the line needs the
/// general path); an unused field is skipped to the next `,`. `None` for anything else (blanks, an empty or
/// non-number field, another field count): the caller then splits and checks the line
/// field by field, which names what is wrong.
#[inline]
pub fn one_pass(
    text: &[u8],
    cols: usize,
    used: impl Fn(usize) -> bool,
    take: impl FnMut(usize, f64) -> Option<()>,
) -> Option<()> {
    (fields(text, cols, used, take)? == text.len()).then_some(())
}

/// [`one_pass`] over the start of `text`, which runs on past the line: the length of the
/// line it took, whose end (`\n` or `\r`) follows in `text`. `None` when the line has a
/// quote, is not whole in `text`, or needs the general path for any reason `one_pass` gives.
/// A reader that has not looked for the line's end yet parses it this way (one pass over
/// the bytes instead of two): the values are those `one_pass` takes from the same line,
/// since a number ends before a line end.
#[inline]
pub fn line_prefix(
    text: &[u8],
    cols: usize,
    used: impl Fn(usize) -> bool,
    take: impl FnMut(usize, f64) -> Option<()>,
) -> Option<usize> {
    let p = fields(text, cols, used, take)?;
    matches!(text.get(p), Some(b'\n' | b'\r')).then_some(p)
}

/// Where the fields of [`one_pass`] end in `text`; an unused field ends at a `,` or a line
/// end, and holds no `"`.
#[inline]
fn fields(
    text: &[u8],
    cols: usize,
    used: impl Fn(usize) -> bool,
    mut take: impl FnMut(usize, f64) -> Option<()>,
) -> Option<usize> {
    let last = cols.checked_sub(1)?;
    let mut p = 0;
    for j in 0..cols {
        let rest = text.get(p..)?;
        if used(j) {
            let (v, n) = super::decimal::number_prefix(rest)?;
            if n > MAX_FIELD_BYTES {
                return None;
            }
            take(j, v)?;
            p += n;
        } else {
            let n = rest
                .iter()
                .position(|&c| matches!(c, b',' | b'\n' | b'\r' | b'"'))
                .unwrap_or(rest.len());
            if rest.get(n) == Some(&b'"') {
                return None;
            }
            p += n;
        }
        if j < last {
            if text.get(p) != Some(&b',') {
                return None;
            }
            p += 1;
        }
    }
    Some(p)
}

/// Parse field `col` of `rec` as an `f64` that must be finite. `name` is the column's
/// name for the message, `line` the record's line.
pub fn finite_field(
    file: &str,
    rec: &Record<'_>,
    line: u64,
    col: usize,
    name: &str,
) -> Result<f64, CsvError> {
    let v = number_field(file, rec, line, col, name)?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(CsvError::field(
            file,
            line,
            col,
            name,
            format!("{name} = {v} is not finite: every value must be a finite number"),
        ))
    }
}

/// Parse field `col` of `rec` as an `f64` (NaN and infinity accepted).
pub fn number_field(
    file: &str,
    rec: &Record<'_>,
    line: u64,
    col: usize,
    name: &str,
) -> Result<f64, CsvError> {
    let raw = rec.get(col).unwrap_or_default();
    if raw.len() > MAX_FIELD_BYTES {
        return Err(CsvError::field(
            file,
            line,
            col,
            name,
            format!(
                "{name} {} is {} bytes long: a number field may hold at most {MAX_FIELD_BYTES}",
                quote(raw),
                raw.len()
            ),
        ));
    }
    parse_f64(raw).ok_or_else(|| {
        let text = String::from_utf8_lossy(raw);
        let what = if text.trim().is_empty() {
            "is empty".to_owned()
        } else {
            format!("{} is not a number", quote(text.trim().as_bytes()))
        };
        CsvError::field(
            file,
            line,
            col,
            name,
            format!("{name} {what}: expected a number"),
        )
    })
}

/// An optional number: an empty field or NaN is `None` (the estimates file writes missing
/// estimates as empty fields).
pub fn optional_field(
    file: &str,
    rec: &Record<'_>,
    line: u64,
    col: usize,
    name: &str,
) -> Result<Option<f64>, CsvError> {
    let raw = rec.get(col).unwrap_or_default();
    if raw.iter().all(u8::is_ascii_whitespace) {
        return Ok(None);
    }
    let v = number_field(file, rec, line, col, name)?;
    Ok((!v.is_nan()).then_some(v))
}

/// The CSV reader of every file here: records split in place, lines numbered and capped
/// ([`super::records`]).
pub type CsvReader<R> = RecordReader<R>;

/// A CSV reader configured as every reader here needs it: no header handling (we read the
/// header ourselves to know its line), rows of any length (checked by the caller, with a
/// better message), blanks trimmed around fields, lines numbered and capped
/// ([`super::lines`]).
pub fn csv_reader<R: Read>(input: R) -> CsvReader<R> {
    RecordReader::new(input)
}

/// The next record of `csv` (its line: [`Record::line`], 1-based, LF, CRLF and CR line
/// ends alike), or `None` at the end of the input. A line over the cap names the cap; a
/// failed write of the caller's output (flushed before a read, carrying a
/// [`WriteFailure`]) names the output, not the input.
pub fn next_record<'a, R: Read>(
    file: &str,
    csv: &'a mut CsvReader<R>,
) -> Result<Option<Record<'a>>, CsvError> {
    csv.next_record()
        .map_err(|e| io_error(file, &e.error, e.line))
}

/// The next record of `csv` as [`RecordReader::next_raw`](super::records::RecordReader::next_raw)
/// gives it (a plain line unsplit), an I/O error named as [`next_record`] names it.
pub fn next_raw<'a, R: Read>(
    file: &str,
    csv: &'a mut CsvReader<R>,
) -> Result<Option<RawRecord<'a>>, CsvError> {
    csv.next_raw().map_err(|e| io_error(file, &e.error, e.line))
}

/// The [`CsvError`] of an I/O error met at `line` of `file` (see [`next_record`]).
pub fn io_error(file: &str, io: &std::io::Error, line: u64) -> CsvError {
    let inner = io.get_ref();
    if let Some(t) = inner.and_then(|i| i.downcast_ref::<LineTooLong>()) {
        let what = if t.line == 1 {
            "the header line"
        } else {
            "the line"
        };
        return CsvError::line(
            file,
            t.line,
            format!(
                "{what} is longer than {} bytes{}, the most one line may hold: is this a CSV \
                 file with line ends (LF, CRLF or CR)?",
                t.cap,
                if t.cap == MAX_LINE_BYTES {
                    " (1 MiB)"
                } else {
                    ""
                }
            ),
        );
    }
    let mut err = match inner.and_then(|i| i.downcast_ref::<WriteFailure>()) {
        Some(w) => CsvError::file(&w.output, format!("cannot write: {w}")),
        None => CsvError::line(file, line, format!("cannot read: {io}")),
    };
    err.io_kind = Some(io.kind());
    err
}

/// Check that a record has as many fields as the header.
pub fn check_length(
    file: &str,
    rec: &Record<'_>,
    line: u64,
    header: &Header,
) -> Result<(), CsvError> {
    let (n, h) = (rec.len(), header.names.len());
    if n == h {
        return Ok(());
    }
    let what = if n < h { "short row" } else { "long row" };
    Err(CsvError::line(
        file,
        line,
        format!(
            "{what}: {n} field{} where the header (line {}) has {h}",
            if n == 1 { "" } else { "s" },
            header.line
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A reader of the one line `fields` joined by commas.
    fn line_of(fields: &[&str]) -> RecordReader<std::io::Cursor<Vec<u8>>> {
        RecordReader::new(std::io::Cursor::new(fields.join(",").into_bytes()))
    }

    #[test]
    fn names_split_units_drop_case_and_blanks() {
        assert_eq!(
            name_and_unit(" X [um] ".as_bytes()),
            ("x".to_owned(), Some("um".to_owned()))
        );
        assert_eq!(
            name_and_unit("\u{feff}t (ms)".as_bytes()),
            ("t".to_owned(), Some("ms".to_owned()))
        );
        assert_eq!(name_and_unit(b"Phi_Dot"), ("phi_dot".to_owned(), None));
        assert_eq!(normalise(b" x [m] "), "x");
        assert_eq!(normalise(b"phi_dot (rad/s)"), "phi_dot");
        assert_eq!(normalise("\u{feff}T".as_bytes()), "t");
        assert_eq!(normalise(b"[m]"), "[m]");
        assert_eq!(normalise(b"rcond_x"), "rcond_x");
    }

    #[test]
    fn long_fields_and_headers_are_quoted_short() {
        let long = "9".repeat(2000);
        let mut r = line_of(&[long.as_str(), "x".repeat(500).as_str()]);
        let rec = r.next_record().unwrap().unwrap();
        let e = finite_field("f", &rec, 2, 0, "t").unwrap_err().to_string();
        assert!(
            e.starts_with("f line 2, column 1 (t): t \"9999")
                && e.ends_with("is 2000 bytes long: a number field may hold at most 1024"),
            "{e}"
        );
        let e = finite_field("f", &rec, 2, 1, "x").unwrap_err().to_string();
        assert!(
            e.contains("\"xxxxx") && e.contains("... (500 bytes) is not a number"),
            "{e}"
        );
        assert!(e.len() < 200, "{e}");
        let names = vec!["q".repeat(10_000); 3];
        let names: Vec<&str> = names.iter().map(String::as_str).collect();
        let mut r = line_of(&names);
        let h = Header::new(&r.next_record().unwrap().unwrap(), 1);
        let e = h.require("f", &["t", "x", "z"]).unwrap_err().to_string();
        assert!(e.len() < 400 && e.ends_with("(30002 bytes in all))"), "{e}");
    }

    #[test]
    fn a_long_unit_is_quoted_short() {
        let header = format!("x [{}]", "\u{7}".repeat(10_000));
        let mut r = line_of(&[header.as_str()]);
        let h = Header::new(&r.next_record().unwrap().unwrap(), 1);
        let e = h
            .conversion("f", 0, "x", Quantity::Displacement)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("f line 1, column 1 (x): unknown unit \"\\u{7}"),
            "{e}"
        );
        assert!(
            e.contains("... (10000 bytes in all)\" for a displacement"),
            "{e}"
        );
        assert!(e.len() < 400, "{} bytes: {e}", e.len());
    }

    #[test]
    fn records_know_their_line_whatever_the_line_ends() {
        for text in [
            "h\n1\n\n2\n",
            "h\r\n1\r\n\r\n2\r\n",
            "h\r1\r\r2\r",
            "h\n1\n\n2",
        ] {
            let mut csv = csv_reader(text.as_bytes());
            let mut lines = Vec::new();
            while let Some(rec) = next_record("f", &mut csv).unwrap() {
                lines.push((rec.line(), rec.get(0).unwrap().to_vec()));
            }
            assert_eq!(
                lines,
                vec![(1, b"h".to_vec()), (2, b"1".to_vec()), (4, b"2".to_vec())],
                "{text:?}"
            );
        }
    }

    #[test]
    fn fields_parse_or_say_why_not() {
        let mut r = line_of(&["1.5", "abc", "", "NaN", "inf"]);
        let rec = r.next_record().unwrap().unwrap();
        assert_eq!(finite_field("f", &rec, 2, 0, "t").unwrap(), 1.5);
        let e = finite_field("f", &rec, 2, 1, "x").unwrap_err();
        assert_eq!(
            e.to_string(),
            "f line 2, column 2 (x): x \"abc\" is not a number: expected a number"
        );
        let e = finite_field("f", &rec, 2, 2, "z").unwrap_err();
        assert_eq!(
            e.to_string(),
            "f line 2, column 3 (z): z is empty: expected a number"
        );
        let e = finite_field("f", &rec, 2, 3, "z").unwrap_err();
        assert!(e.to_string().contains("z = NaN is not finite"));
        assert_eq!(optional_field("f", &rec, 2, 2, "m_x").unwrap(), None);
        assert_eq!(optional_field("f", &rec, 2, 3, "m_x").unwrap(), None);
        assert_eq!(
            optional_field("f", &rec, 2, 4, "m_x").unwrap(),
            Some(f64::INFINITY)
        );
    }
}
