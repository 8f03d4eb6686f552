//! The error of the CSV readers: it names the file, the line (the header is line 1, as
//! editors count) and the column (1-based position and header name), so a user can find
//! the offending field without reading code.
//!
//! Display: `FILE line L, column C (NAME): MESSAGE`, dropping the parts that do not apply
//! (`FILE: MESSAGE` for an empty file, `FILE line L: MESSAGE` for a short row).

use std::fmt;

/// A CSV input that cannot be used, and where.
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

impl std::error::Error for CsvError {}

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
}
