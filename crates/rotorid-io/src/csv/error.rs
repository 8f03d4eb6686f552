//! The error of the CSV readers: it names the file, the line (the header is line 1, as
//! editors count) and the column (1-based position and header name), so a user can find
//! the offending field without reading code.
//!
//! Display: `FILE line L, column C (NAME): MESSAGE`, dropping the parts that do not apply
//! (`FILE: MESSAGE` for an empty file, `FILE line L: MESSAGE` for a short row).
//!
//! A message quotes at most a short prefix of what it complains about ([`quote`],
//! [`abbreviate`]): a bad field of a megabyte, or a header of NUL bytes, must not flood
//! the terminal.

use std::fmt;

use crate::units::UnitError;

/// Most characters of a value that a message quotes.
pub const QUOTE_CHARS: usize = 40;

/// `raw` quoted for a message (Rust string syntax, control characters escaped): whole if
/// it has at most [`QUOTE_CHARS`] characters, else its first ones followed by `...` and its
/// length in bytes.
pub fn quote(raw: &[u8]) -> String {
    let text = String::from_utf8_lossy(raw);
    match text.char_indices().nth(QUOTE_CHARS) {
        None => format!("{text:?}"),
        Some((cut, _)) => format!("{:?}... ({} bytes)", &text[..cut], raw.len()),
    }
}

/// `text` cut to at most `max_chars` characters, with `... (N bytes in all)` when cut.
pub fn abbreviate(text: &str, max_chars: usize) -> String {
    match text.char_indices().nth(max_chars) {
        None => text.to_owned(),
        Some((cut, _)) => format!("{}... ({} bytes in all)", &text[..cut], text.len()),
    }
}

/// A CSV input that cannot be used, and where.
///
/// A located message rather than an enum of causes: every reader builds its own message
/// (what is wrong, the value, what is allowed); the parts a caller acts on are fields
/// ([`CsvError::io_kind`] for a broken pipe, [`CsvError::unit`] for a unit the file gives).
#[derive(Debug, Clone, PartialEq)]
pub struct CsvError {
    /// The file name as given on the command line (`<stdin>` for `-`).
    pub file: String,
    /// 1-based line number (header = line 1), when the error is on one line.
    pub line: Option<u64>,
    /// 1-based column position and its header name, when the error is in one field.
    pub column: Option<(usize, String)>,
    /// What is wrong and what is allowed.
    pub message: String,
    /// Set when the failure was an I/O error (e.g. a broken pipe on the output, which a
    /// flush-before-read input reports), so a command can react to its kind.
    pub io_kind: Option<std::io::ErrorKind>,
    /// Set when the failure is a unit in the header that the column's role cannot take (its
    /// text is in the message too).
    pub unit: Option<Box<UnitError>>,
}

impl CsvError {
    /// An error about the whole file.
    pub fn file(file: &str, message: impl Into<String>) -> Self {
        Self {
            file: file.to_owned(),
            line: None,
            column: None,
            message: message.into(),
            io_kind: None,
            unit: None,
        }
    }

    /// An error on one line.
    pub fn line(file: &str, line: u64, message: impl Into<String>) -> Self {
        Self {
            line: Some(line),
            ..Self::file(file, message)
        }
    }

    /// An error in one field: `column` is 0-based here and shown 1-based.
    pub fn field(
        file: &str,
        line: u64,
        column: usize,
        name: &str,
        message: impl Into<String>,
    ) -> Self {
        Self {
            line: Some(line),
            column: Some((column + 1, name.to_owned())),
            ..Self::file(file, message)
        }
    }
}

impl fmt::Display for CsvError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.file)?;
        if let Some(l) = self.line {
            write!(f, " line {l}")?;
        }
        if let Some((c, name)) = &self.column {
            write!(f, ", column {c} ({name})")?;
        }
        write!(f, ": {}", self.message)
    }
}

// No `source`: the message already holds the cause's text, and `{:#}` would repeat it.
impl std::error::Error for CsvError {}

/// The payload of every `io::Error` a caller's output returns (the `rotorid` command's
/// `Output`): it remembers which output failed, so that a write error a reader meets (a
/// command may flush its output before each read of the input) is reported against the
/// output, not the input. Its `Display` is the underlying error's, so `cannot write NAME: {e}`
/// reads as for a plain I/O error.
#[derive(Debug)]
pub struct WriteFailure {
    /// The output's name as given (`-` for stdout).
    pub output: String,
    message: String,
}

impl WriteFailure {
    /// The failure of `output`, described by `message`.
    pub fn new(output: &str, message: &str) -> Self {
        Self {
            output: output.to_owned(),
            message: message.to_owned(),
        }
    }
}

impl fmt::Display for WriteFailure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for WriteFailure {}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_names_what_applies() {
        assert_eq!(CsvError::file("a.csv", "empty").to_string(), "a.csv: empty");
        assert_eq!(
            CsvError::line("a.csv", 3, "short").to_string(),
            "a.csv line 3: short"
        );
        assert_eq!(
            CsvError::field("a.csv", 7, 2, "z", "bad").to_string(),
            "a.csv line 7, column 3 (z): bad"
        );
    }

    #[test]
    fn quotes_are_short() {
        assert_eq!(quote(b"abc"), "\"abc\"");
        let long = vec![0u8; 1 << 20];
        let q = quote(&long);
        assert!(q.ends_with("... (1048576 bytes)"), "{q}");
        assert!(q.len() < 250, "{q}");
        assert_eq!(abbreviate("t,x,z", 10), "t,x,z");
        assert_eq!(abbreviate("abcdef", 3), "abc... (6 bytes in all)");
    }
}
