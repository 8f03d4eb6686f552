//! MATLAB v7.3 MAT-files (HDF5). Placeholder until the HDF5 reader lands.

use crate::error::ReadError;
use crate::table::Table;

/// Reads a v7.3 MAT-file's bytes.
pub fn read(file: &str, _bytes: &[u8]) -> Result<Table, ReadError> {
    Err(ReadError::NotHandledHere {
        file: file.to_string(),
        format: "MAT v7.3",
    })
}
