//! The CSV files of rotorid: the response CSV (`t,x,z[,phi,phi_dot,phi_ddot]`, one row per
//! sample) read by [`ResponseReader`], and the pieces every CSV reader and writer here
//! shares.
//!
//! - [`columns`]: header names (trimmed, lower-cased, a unit suffix split off), the search
//!   for required columns, one field parsed as a number;
//! - [`lines`]: line numbers as an editor counts them (LF, CRLF and CR alike) and a cap on
//!   a line's length, so a file that is not line-based text cannot exhaust memory;
//! - [`error`]: [`CsvError`], `FILE line L, column C (NAME): message`;
//! - [`number`]: numbers written in shortest round-trip form (reading one back gives the
//!   identical `f64`) and read as `str::parse::<f64>` reads them.

pub mod columns;
pub mod error;
pub mod lines;
pub mod number;
pub mod records;
pub mod response;
pub mod table;

pub use error::{CsvError, WriteFailure};
pub use response::{ResponseReader, ResponseRow, Speed, RESPONSE_HEADER};
pub use table::read_csv_table;
