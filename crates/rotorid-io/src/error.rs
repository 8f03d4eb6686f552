//! The one error type of every reader: each variant names the file, the channel when one is
//! concerned, the byte offset in the file, what was found and what was allowed.

use std::fmt;

/// Why a file could not be read.
///
/// Offsets are bytes from the start of the file. Inside a compressed element (a MAT
/// `miCOMPRESSED` variable, an NPZ member) the offset is that of the compressed element, and
/// `what` says where in its decompressed bytes the problem lies.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReadError {
    /// The file could not be opened or read.
    #[error("{file}: {source}")]
    Io {
        /// The file.
        file: String,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// The extension names no format this crate reads.
    #[error("{file}: unknown file extension {ext:?}; known: {known}")]
    UnknownFormat {
        /// The file.
        file: String,
        /// Its extension (lower-cased), empty when it has none.
        ext: String,
        /// The extensions read here.
        known: &'static str,
    },
    /// A CSV file that cannot be read as a table.
    #[error(transparent)]
    Csv(Box<crate::csv::CsvError>),
    /// A field or block extends past the end of the file (a truncated file, or a length or
    /// dimension field larger than the file).
    #[error(
        "{file}{}: {what} at byte {offset} needs {need} bytes but only {available} remain \
         (truncated file, or a length field larger than the file)",
        Ch(channel)
    )]
    Truncated {
        /// The file.
        file: String,
        /// The channel being read, if any.
        channel: Option<String>,
        /// Byte offset of the field.
        offset: u64,
        /// The field.
        what: String,
        /// Bytes it needs.
        need: u64,
        /// Bytes left in the file (or in the decompressed element).
        available: u64,
    },
    /// A field holds a value the format or this reader does not allow.
    #[error(
        "{file}{}: {what} at byte {offset} is {found}; allowed: {allowed}",
        Ch(channel)
    )]
    Invalid {
        /// The file.
        file: String,
        /// The channel being read, if any.
        channel: Option<String>,
        /// Byte offset of the field.
        offset: u64,
        /// The field.
        what: String,
        /// What the file holds.
        found: String,
        /// What is allowed.
        allowed: String,
    },
    /// A name or unit is not UTF-8.
    #[error(
        "{file}{}: {what} at byte {offset} is not UTF-8 (bytes {bytes:02x?})",
        Ch(channel)
    )]
    NotUtf8 {
        /// The file.
        file: String,
        /// The channel being read, if any.
        channel: Option<String>,
        /// Byte offset of the text.
        offset: u64,
        /// The text's role (a channel name, a unit).
        what: String,
        /// Up to its first 16 bytes.
        bytes: Vec<u8>,
    },
    /// An integer sample that `f64` cannot hold exactly (beyond 2^53 in magnitude and not a
    /// representable value); converting it would silently round.
    #[error(
        "{file}, channel {channel:?}: sample {index} at byte {offset} is the integer {value}, \
         which f64 cannot hold exactly (allowed: integers of magnitude up to 2^53, or exactly \
         representable ones)"
    )]
    InexactInteger {
        /// The file.
        file: String,
        /// The channel.
        channel: String,
        /// Sample index in the channel.
        index: usize,
        /// Byte offset of the sample (of its compressed element when compressed).
        offset: u64,
        /// The value.
        value: i128,
    },
    /// The file holds no channel this crate can read.
    #[error("{file}: no numeric channel found ({why})")]
    NoChannels {
        /// The file.
        file: String,
        /// What was there instead.
        why: String,
    },
    /// A member of an archive with a fixed set of members (the finite-element matrices
    /// file, [`crate::fe_matrices`]) that is missing, repeated, unknown, or of a shape or
    /// dtype the file's contract does not allow.
    #[error("{file}: member {member} {found}: {allowed}")]
    Member {
        /// The file.
        file: String,
        /// The member (`K`, `dofs`).
        member: String,
        /// What the file holds (`is 38 x 40`, `is missing`, `has dtype '<f4'`).
        found: String,
        /// What is allowed (`must be 40 x 40 (one row and column per entry of dofs)`).
        allowed: String,
    },
    /// A library reading the container (HDF5 for MAT v7.3, Parquet, zip for NPZ) failed.
    #[error("{file}{}: {container}: {message}", Ch(channel))]
    Container {
        /// The file.
        file: String,
        /// The channel being read, if any.
        channel: Option<String>,
        /// The container format.
        container: &'static str,
        /// The library's message.
        message: String,
    },
}

impl ReadError {
    /// [`ReadError::Invalid`]: field `what` at byte `offset` of `file` (in `channel`) holds
    /// `found` where `allowed` is allowed.
    pub(crate) fn invalid(
        file: &str,
        channel: Option<String>,
        offset: u64,
        what: String,
        found: impl ToString,
        allowed: impl ToString,
    ) -> Self {
        ReadError::Invalid {
            file: file.to_string(),
            channel,
            offset,
            what,
            found: found.to_string(),
            allowed: allowed.to_string(),
        }
    }

    /// The file the error is about.
    pub fn file(&self) -> &str {
        match self {
            ReadError::Io { file, .. }
            | ReadError::UnknownFormat { file, .. }
            | ReadError::Truncated { file, .. }
            | ReadError::Invalid { file, .. }
            | ReadError::NotUtf8 { file, .. }
            | ReadError::InexactInteger { file, .. }
            | ReadError::NoChannels { file, .. }
            | ReadError::Member { file, .. }
            | ReadError::Container { file, .. } => file,
            ReadError::Csv(e) => &e.file,
        }
    }
}

/// Formats `, channel "x"` when there is a channel.
struct Ch<'a>(&'a Option<String>);

impl fmt::Display for Ch<'_> {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.0 {
            Some(c) => write!(f, ", channel {c:?}"),
            None => Ok(()),
        }
    }
}
