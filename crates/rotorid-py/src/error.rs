//! The one error of the package's core: the library's own errors (each already names the
//! field, the value and the allowed range, or the sample index and column), a keyword
//! argument or column the caller got wrong, or a file that cannot be read. The extension
//! module raises `OSError` for [`Error::Io`] (and a CSV read that failed) and `ValueError`
//! for every other variant.

use rotorid::pipeline::PipelineError;
use rotorid::scenario_file::ScenarioFileError;
use rotorid::simulate::SimulateError;

/// Why a call could not be done.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// The pipeline refused the record or a setting.
    #[error(transparent)]
    Pipeline(#[from] PipelineError),
    /// The scenario is incomplete or out of range.
    #[error(transparent)]
    Scenario(#[from] ScenarioFileError),
    /// The simulation could not be done.
    #[error(transparent)]
    Simulate(#[from] SimulateError),
    /// The transient analysis refused an input (the message names the file, the channel
    /// or sensor, the value and what is allowed).
    #[error(transparent)]
    Transient(#[from] rotorid::transient::TransientError),
    /// A raw record that cannot be read or whose channels have units of another quantity.
    #[error(transparent)]
    Raw(Box<rotorid_io::raw::RawError>),
    /// A keyword argument, a column or a file's content that cannot be used; the message
    /// names it and what is allowed.
    #[error("{0}")]
    Invalid(String),
    /// A CSV file whose content cannot be used, or whose reading failed: the message names
    /// the file, the line and the column (`io_kind` is set for a failed read).
    #[error(transparent)]
    Csv(#[from] rotorid_io::csv::CsvError),
    /// A binary file (MAT, TDMS, UFF58, NPY/NPZ, Parquet) that cannot be read.
    #[error(transparent)]
    Read(Box<rotorid_io::ReadError>),
    /// A channel that cannot play its role (missing, ambiguous, wrong unit or length).
    #[error(transparent)]
    Select(Box<rotorid_io::SelectError>),
    /// A file that cannot be read.
    #[error("cannot read {path}: {source}")]
    Io {
        /// The path as given.
        path: String,
        /// The operating system's error.
        source: std::io::Error,
    },
}

impl From<rotorid_io::ReadError> for Error {
    fn from(e: rotorid_io::ReadError) -> Self {
        Self::Read(Box::new(e))
    }
}

impl From<rotorid_io::raw::RawError> for Error {
    fn from(e: rotorid_io::raw::RawError) -> Self {
        Self::Raw(Box::new(e))
    }
}

impl From<rotorid_io::SelectError> for Error {
    fn from(e: rotorid_io::SelectError) -> Self {
        Self::Select(Box::new(e))
    }
}

impl Error {
    /// An [`Error::Invalid`] with `message`.
    pub fn invalid(message: impl Into<String>) -> Self {
        Self::Invalid(message.into())
    }
}
