//! MATLAB `.mat` files: level 5 ([`v5`], what MATLAB writes with `-v6` and `-v7`, and
//! `scipy.io.savemat`) and v7.3 ([`v73`], HDF5 with MATLAB conventions, `-v7.3`).
//!
//! Both yield the same channels: every top-level real numeric variable that is a vector
//! (`1 x n`, `n x 1`, or a scalar) as a channel named after the variable, and each such
//! field of a top-level scalar struct as `struct.field`. Any numeric class (double, single,
//! int8..int64, uint8..uint64, logical) converts to `f64` exactly; a 64-bit integer `f64`
//! cannot hold exactly is an error. Matrices, complex arrays, char, cell, sparse, object and
//! struct-array variables are skipped (the error when nothing is left lists them). MAT
//! files carry no units.
//!
//! Which of the two a file is follows from its 128-byte header: bytes 124..126 hold the
//! version, `0x0100` for level 5 and `0x0200` for v7.3; a v7.3 file is an HDF5 file with a
//! 512-byte user block holding that header. Level 4 files (no text header) are refused.

pub mod v5;
pub mod v73;

use crate::error::ReadError;
use crate::table::Table;

/// Reads a `.mat` file's bytes, level 5 or v7.3 as its header says.
pub fn read(file: &str, bytes: &[u8]) -> Result<Table, ReadError> {
    if is_v73(bytes) {
        return v73::read(file, bytes);
    }
    v5::read(file, bytes)
}

/// True when the file starting with `head` (its first 520 bytes or more) is v7.3: the
/// header's version, or the HDF5 signature after the 512-byte user block.
fn is_v73(head: &[u8]) -> bool {
    head.len() >= 128
        && head.starts_with(b"MATLAB")
        && ([head[124], head[125]] == [0x00, 0x02]
            || [head[124], head[125]] == [0x02, 0x00]
            || head.get(512..520) == Some(b"\x89HDF\r\n\x1a\n".as_slice()))
}

/// Reads the `.mat` file at `path` from disk: level 5 element by element
/// ([`v5::read_file`]: memory holds the channels and one variable), v7.3 through the HDF5
/// layer's streaming mode ([`v73::read_file`]).
pub fn read_file(file: &str, path: &std::path::Path) -> Result<Table, ReadError> {
    use std::io::Read as _;
    let io = |source| ReadError::Io {
        file: file.to_string(),
        source,
    };
    let mut head = Vec::with_capacity(520);
    std::fs::File::open(path)
        .map_err(io)?
        .take(520)
        .read_to_end(&mut head)
        .map_err(io)?;
    if is_v73(&head) {
        return v73::read_file(file, path);
    }
    v5::read_file(file, path)
}
