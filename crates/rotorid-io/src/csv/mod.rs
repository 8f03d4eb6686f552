//! The CSV files of rotorid: the response CSV (`t,x,z[,phi,phi_dot,phi_ddot]`, one row per
//! sample) read by [`ResponseReader`], and the pieces every CSV reader and writer here
//! shares.
//!
//! - [`columns`]: header names (trimmed, lower-cased, a unit suffix split off), the search
//!   for required columns, one field parsed as a number;
//! - [`balance`]: `vectors.csv` and `masses.csv` of influence-coefficient balancing;
//! - [`lines`]: line numbers as an editor counts them (LF, CRLF and CR alike) and a cap on
//!   a line's length, so a file that is not line-based text cannot exhaust memory;
//! - [`error`]: [`CsvError`], `FILE line L, column C (NAME): message`;
//! - [`number`]: numbers written in shortest round-trip form (reading one back gives the
//!   identical `f64`) and read as `str::parse::<f64>` reads them;
//! - [`decimal`]: the fast path for plain decimals in front of fast-float2 (the same values,
//!   bit for bit).

pub mod balance;
pub mod bode;
pub mod columns;
pub mod decimal;
pub mod error;
pub mod lines;
pub mod number;
pub mod records;
pub mod response;
pub mod table;

pub use balance::{read_masses, read_vectors, MassRow, Phase, VectorRow};
pub use error::{CsvError, WriteFailure};
pub use response::{ResponseReader, ResponseRow, Speed, RESPONSE_HEADER};
pub use table::read_csv_table;

/// A reader giving at most `step` bytes per read (tests): lines end up split across the
/// record reader's buffer fills, where the readers' one-pass parse must leave them to the
/// general path.
#[cfg(test)]
pub(crate) struct Trickle<'a> {
    pub text: &'a [u8],
    pub step: usize,
}

#[cfg(test)]
impl std::io::Read for Trickle<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let n = self.step.min(buf.len()).min(self.text.len());
        buf[..n].copy_from_slice(&self.text[..n]);
        self.text = &self.text[n..];
        Ok(n)
    }
}

/// The line end the readers' property tests put after a row (tests): by `code` (0 to 4) LF,
/// CRLF, a lone CR, LF and a blank line, or LF; code 4 on the `last` row is no line end.
#[cfg(test)]
pub(crate) fn test_line_end(code: u8, last: bool) -> &'static str {
    match (code, last) {
        (4, true) => "",
        (e, _) => ["\n", "\r\n", "\r", "\n\n", "\n"][usize::from(e)],
    }
}
