//! The response CSV `rotorid simulate` writes and `rotorid identify` reads, read whole into
//! columns by the rules of the command's reader (crates/rotorid-cli/src/io/response_csv.rs
//! and columns.rs), which lives in the binary crate: header names compared after trimming,
//! dropping a byte-order mark and one unit suffix (`x [m]`, `t (s)`) and lower-casing;
//! columns in any order, extra ones ignored; `t`, `x`, `z` required; `phi`, `phi_dot`,
//! `phi_ddot` all three or none; every used field a finite number parsed as
//! `str::parse::<f64>` does (so the values are bit for bit the command's); rows as long as
//! the header. Messages name the file, the line (header = line 1) and the column.

use std::io::Read;

use csv::ByteRecord;

use crate::columns::SPEED_NAMES;
use crate::error::Error;

/// A response read whole: t \[s\], x, z \[m\] and, when the file has them, phi \[rad\],
/// phi_dot \[rad/s\], phi_ddot \[rad/s^2\].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Response {
    /// Time stamps \[s\].
    pub t: Vec<f64>,
    /// Horizontal displacement \[m\].
    pub x: Vec<f64>,
    /// Vertical displacement \[m\].
    pub z: Vec<f64>,
    /// phi, phi_dot, phi_ddot.
    pub speed: Option<[Vec<f64>; 3]>,
}

/// Read the response CSV at `path` (module doc).
pub fn read(path: &str) -> Result<Response, Error> {
    let file = std::fs::File::open(path).map_err(|source| Error::Io {
        path: path.to_owned(),
        source,
    })?;
    parse(path, std::io::BufReader::with_capacity(1 << 16, file))
}

/// Read a response CSV from `input`; `file` names it in messages.
pub fn parse<R: Read>(file: &str, input: R) -> Result<Response, Error> {
    let mut csv = csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .trim(csv::Trim::All)
        .buffer_capacity(1 << 16)
        .from_reader(input);
    let mut rec = ByteRecord::new();
    if !csv.read_byte_record(&mut rec).map_err(|e| io(file, e))? {
        return Err(Error::invalid(format!(
            "{file}: the file is empty: expected a header line naming at least t,x,z, then \
             one row per sample"
        )));
    }
    let header_line = rec.position().map_or(1, |p| p.line());
    let names: Vec<String> = rec.iter().map(normalise).collect();
    let find = |name: &str| -> Result<Option<usize>, Error> {
        let mut hits = names.iter().enumerate().filter(|(_, n)| *n == name);
        let first = hits.next().map(|(i, _)| i);
        match (first, hits.next()) {
            (Some(i), Some((j, _))) => Err(at(
                file,
                header_line,
                Some((j, name)),
                format!(
                    "column {name} appears twice (columns {} and {})",
                    i + 1,
                    j + 1
                ),
            )),
            _ => Ok(first),
        }
    };
    let required = ["t", "x", "z"];
    let mut txz = Vec::with_capacity(3);
    let mut missing = Vec::new();
    for name in required {
        match find(name)? {
            Some(i) => txz.push(i),
            None => missing.push(name),
        }
    }
    if !missing.is_empty() {
        return Err(at(
            file,
            header_line,
            None,
            format!(
                "the header lacks column{} {}; it must name at least {} (found: {})",
                if missing.len() > 1 { "s" } else { "" },
                missing.join(", "),
                required.join(","),
                names.join(",")
            ),
        ));
    }
    let phis = [find("phi")?, find("phi_dot")?, find("phi_ddot")?];
    let phi = match phis {
        [Some(a), Some(b), Some(c)] => Some([a, b, c]),
        [None, None, None] => None,
        _ => {
            let missing: Vec<&str> = SPEED_NAMES
                .iter()
                .zip(phis)
                .filter(|(_, p)| p.is_none())
                .map(|(n, _)| *n)
                .collect();
            return Err(at(
                file,
                header_line,
                None,
                format!(
                    "the header has some but not all of phi, phi_dot, phi_ddot: missing {}; \
                     give all three or none (then the scenario's speed profile is used)",
                    missing.join(", ")
                ),
            ));
        }
    };
    let mut r = Response {
        speed: phi.map(|_| [Vec::new(), Vec::new(), Vec::new()]),
        ..Response::default()
    };
    while csv.read_byte_record(&mut rec).map_err(|e| io(file, e))? {
        let line = rec.position().map_or(0, |p| p.line());
        let (n, h) = (rec.len(), names.len());
        if n != h {
            return Err(at(
                file,
                line,
                None,
                format!(
                    "{} row: {n} field{} where the header (line {header_line}) has {h}",
                    if n < h { "short" } else { "long" },
                    if n == 1 { "" } else { "s" },
                ),
            ));
        }
        let field = |col: usize, name: &str| finite(file, &rec, line, col, name);
        r.t.push(field(txz[0], "t")?);
        r.x.push(field(txz[1], "x")?);
        r.z.push(field(txz[2], "z")?);
        if let (Some(cols), Some(speed)) = (phi, r.speed.as_mut()) {
            for ((c, name), v) in cols.iter().zip(SPEED_NAMES).zip(speed.iter_mut()) {
                v.push(field(*c, name)?);
            }
        }
    }
    Ok(r)
}

/// The normalised column name (module doc).
fn normalise(raw: &[u8]) -> String {
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

/// Field `col` of `rec` as a finite `f64`.
fn finite(file: &str, rec: &ByteRecord, line: u64, col: usize, name: &str) -> Result<f64, Error> {
    let raw = rec.get(col).unwrap_or_default();
    let text = std::str::from_utf8(raw).ok().map(str::trim);
    let Some(v) = text.and_then(|s| s.parse::<f64>().ok()) else {
        let text = String::from_utf8_lossy(raw);
        let what = if text.trim().is_empty() {
            "is empty".to_owned()
        } else {
            format!("{:?} is not a number", text.trim())
        };
        return Err(at(
            file,
            line,
            Some((col, name)),
            format!("{name} {what}: expected a number"),
        ));
    };
    if !v.is_finite() {
        return Err(at(
            file,
            line,
            Some((col, name)),
            format!("{name} = {v} is not finite: every value must be a finite number"),
        ));
    }
    Ok(v)
}

/// `FILE line L, column C (NAME): MESSAGE` (`col` 0-based, shown 1-based).
fn at(file: &str, line: u64, col: Option<(usize, &str)>, message: String) -> Error {
    Error::Invalid(match col {
        Some((c, name)) => format!("{file} line {line}, column {} ({name}): {message}", c + 1),
        None => format!("{file} line {line}: {message}"),
    })
}

fn io(file: &str, e: csv::Error) -> Error {
    match e.into_kind() {
        csv::ErrorKind::Io(source) => Error::Io {
            path: file.to_owned(),
            source,
        },
        kind => Error::invalid(format!("{file}: cannot read: {kind:?}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> String {
        parse("d.csv", text.as_bytes())
            .expect_err("must be refused")
            .to_string()
    }

    #[test]
    fn any_order_units_and_extra_columns() {
        let r = parse(
            "d.csv",
            "note,Z [m],t (s),x\nabc,2,0,1\nzz,4,0.5,3\n".as_bytes(),
        )
        .unwrap();
        assert_eq!(
            (r.t, r.x, r.z),
            (vec![0.0, 0.5], vec![1.0, 3.0], vec![2.0, 4.0])
        );
        assert!(r.speed.is_none());
        let r = parse(
            "d.csv",
            "t,x,z,phi,phi_dot,phi_ddot\n0,1.5e-7,-3.3e-300,0.1,125.66370614359172,0\n".as_bytes(),
        )
        .unwrap();
        assert_eq!(r.z[0], -3.3e-300);
        assert_eq!(r.speed.unwrap()[1][0], 125.66370614359172);
    }

    #[test]
    fn messages_are_the_commands() {
        assert!(err("").starts_with("d.csv: the file is empty"));
        assert!(err("t,x\n0,1\n").starts_with("d.csv line 1: the header lacks column z;"));
        assert!(err("t,x,z,phi\n").starts_with(
            "d.csv line 1: the header has some but not all of phi, phi_dot, phi_ddot: missing \
             phi_dot, phi_ddot"
        ));
        assert!(err("t,x,z,x\n")
            .starts_with("d.csv line 1, column 4 (x): column x appears twice (columns 2 and 4)"));
        let h = "t,x,z\n0,0,0\n0.1,0,0\n";
        assert_eq!(
            err(&format!("{h}0.2,abc,0\n")),
            "d.csv line 4, column 2 (x): x \"abc\" is not a number: expected a number"
        );
        assert!(err(&format!("{h}0.2,0,nan\n"))
            .starts_with("d.csv line 4, column 3 (z): z = NaN is not finite"));
        assert_eq!(
            err(&format!("{h}0.2,0\n")),
            "d.csv line 4: short row: 2 fields where the header (line 1) has 3"
        );
    }
}
