//! Placeholder.
use crate::error::ReadError;
use crate::table::Table;
/// Placeholder.
pub fn read(file: &str, _bytes: &[u8]) -> Result<Table, ReadError> {
    Err(ReadError::NotHandledHere {
        file: file.to_string(),
        format: "uff",
    })
}
