//! CSV headers and fields shared by the readers: column names (with an optional unit
//! suffix), the search for required columns, and the parsing of one numeric field.
//!
//! Header names are compared after trimming blanks, dropping a UTF-8 byte-order mark,
//! dropping one trailing unit suffix in brackets or parentheses (`x [m]`, `phi_dot (rad/s)`)
//! and lower-casing, so `t,x,z`, `T [s],X [m],Z [m]` and `t (s), x (m), z (m)` all name the
//! same columns. The unit in a suffix is not checked: values are always read as SI.

use csv::ByteRecord;

use super::csv_error::CsvError;

/// The normalised column name (see the module doc).
pub fn normalise(raw: &[u8]) -> String {
    let s = String::from_utf8_lossy(raw);
    let s = s.trim_start_matches('\u{feff}').trim();
    let s = strip_unit(s, '[', ']').unwrap_or_else(|| strip_unit(s, '(', ')').unwrap_or(s));
    s.trim().to_lowercase()
}

fn strip_unit(s: &str, open: char, close: char) -> Option<&str> {
    if !s.ends_with(close) {
        return None;
    }
    let i = s.rfind(open)?;
    let head = s[..i].trim_end();
    (!head.is_empty()).then_some(head)
}

/// The header of a CSV file: normalised names and the line it is on.
#[derive(Debug, Clone)]
pub struct Header {
    /// Normalised names, in file order.
    pub names: Vec<String>,
    /// 1-based line of the header.
    pub line: u64,
}

impl Header {
    /// Read from the header record `rec` found at `line`.
    pub fn new(rec: &ByteRecord, line: u64) -> Self {
        Self {
            names: rec.iter().map(normalise).collect(),
            line,
        }
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
                    self.names.join(",")
                ),
            ))
        }
    }
}

/// Parse field `col` of `rec` as an `f64` that must be finite. `name` is the column's
/// name for the message, `line` the record's line.
pub fn finite_field(
    file: &str,
    rec: &ByteRecord,
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
    rec: &ByteRecord,
    line: u64,
    col: usize,
    name: &str,
) -> Result<f64, CsvError> {
    let raw = rec.get(col).unwrap_or_default();
    std::str::from_utf8(raw)
        .ok()
        .and_then(|s| s.trim().parse::<f64>().ok())
        .ok_or_else(|| {
            let text = String::from_utf8_lossy(raw);
            let what = if text.trim().is_empty() {
                "is empty".to_owned()
            } else {
                format!("{:?} is not a number", text.trim())
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
    rec: &ByteRecord,
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

/// A CSV reader configured as every reader here needs it: no header handling (we read the
/// header ourselves to know its line), rows of any length (checked by the caller, with a
/// better message), blanks trimmed around fields.
pub fn csv_reader<R: std::io::Read>(input: R) -> csv::Reader<R> {
    csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .buffer_capacity(64 * 1024)
        .from_reader(input)
}

/// Map a `csv` crate error (I/O, mostly) to a [`CsvError`] for `file`.
pub fn read_error(file: &str, e: csv::Error) -> CsvError {
    let line = e.position().map(|p| p.line());
    let kind = match e.kind() {
        csv::ErrorKind::Io(io) => Some(io.kind()),
        _ => None,
    };
    let mut err = match line {
        Some(l) => CsvError::line(file, l, format!("cannot read: {e}")),
        None => CsvError::file(file, format!("cannot read: {e}")),
    };
    err.io_kind = kind;
    err
}

/// Check that a record has as many fields as the header.
pub fn check_length(
    file: &str,
    rec: &ByteRecord,
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

    #[test]
    fn names_drop_units_case_and_blanks() {
        assert_eq!(normalise(b" x [m] "), "x");
        assert_eq!(normalise(b"phi_dot (rad/s)"), "phi_dot");
        assert_eq!(normalise("\u{feff}T".as_bytes()), "t");
        assert_eq!(normalise(b"[m]"), "[m]");
        assert_eq!(normalise(b"rcond_x"), "rcond_x");
    }

    #[test]
    fn fields_parse_or_say_why_not() {
        let rec = ByteRecord::from(vec!["1.5", "abc", "", "NaN", "inf"]);
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
