//! Readers and writers of the files rotor records come in, shared by every caller of the
//! identification pipeline (the `rotorid` command, the Python package, the fleet worker).
//!
//! A reader yields a [`Table`]: named [`Channel`]s of `f64` samples, each with the unit the
//! file gives (a CSV header suffix `x [um]`, a TDMS `unit_string`, a UFF58 ordinate unit) and,
//! where the format carries one, an implied time axis. [`units`] converts a channel to SI
//! for the role it plays (time, displacement, angle, speed, acceleration) and refuses a unit
//! it does not know, naming the channel.
//!
//! [`read_table`] picks the reader by the file's extension ([`Format::from_path`]):
//! [`mat`] (`.mat`, level 5 and v7.3), [`tdms`], [`uff`] (`.uff`, `.unv`, `.58`), [`npy`],
//! [`npz`], [`parquet`] and CSV ([`csv::read_csv_table`]; the response CSV is also streamed
//! by [`csv::ResponseReader`]). Every binary reader checks each length and dimension field
//! against the bytes the file has left before allocating, and fails with a [`ReadError`]
//! that names the file, the channel and the byte offset; none panics on any input (each
//! has a cargo-fuzz target in `fuzz/`). Each reads the file's bytes in memory (`read`, for
//! bytes already held) or from disk piece by piece (`read_file`, what [`read_table`] uses:
//! Parquet column chunks, NPZ members, MAT level 5 elements, MAT v7.3 through the HDF5
//! layer's streaming mode, TDMS segments, UFF58 lines), so memory holds the channels and
//! one piece (about 1.3x the channels at most); both accept and refuse alike.
//!
//! Where the format allows it (Parquet row groups and pages, TDMS segments), a record can
//! also be read a block of rows at a time ([`open_blocks`]), with the channels for t, x, z,
//! ... picked and converted to SI a block at a time ([`SiBlocks`]) exactly as [`select()`]
//! picks and converts them: `rotorid identify` reads such a file on one thread while it
//! identifies on another, and `rotorid inspect` reads it, in memory that does not grow with
//! the record ([`stream`]).
//!
//! [`write_table`] writes a table back as NPZ, MAT level 5 or Parquet ([`mod@write`]).
//!
//! [`fe_matrices`] reads and writes the matrices file of a finite-element rotor (an NPZ of
//! `M`, `K`, `G`, optional `C`, `Ka`, and `dofs`), not a table: its members are checked
//! against that contract by name, shape and dtype.
//!
//! Samples are passed through as stored: NaN and infinities are data here, and the
//! identification pipeline checks finiteness. Integers convert to `f64` exactly or not at
//! all ([`ReadError::InexactInteger`]).
//!
//! The crate does no identification: it turns bytes into SI samples and back.
//!
//! [`csv`] reads the response CSV that `rotorid simulate` writes (and any CSV with the
//! same columns, units in its header converted), streaming, at close to the speed the file
//! can be read: a plain line parsed in one pass (`csv::columns::one_pass`), any other split
//! in place, numbers parsed bit for bit as `str::parse` parses them and written in shortest
//! round-trip form.

// ReadError carries the file, channel, offset, found and allowed values inline so callers can
// match on them; it is returned once per failed read, so its size costs nothing measurable.
#![allow(clippy::result_large_err)]

pub mod csv;
mod cursor;
pub mod error;
pub mod fe_matrices;
pub mod format;
mod guard;
pub mod mat;
pub mod npy;
pub mod npz;
pub mod num;
mod par;
pub mod parquet;
pub mod raw;
pub mod select;
mod source;
pub mod stream;
pub mod table;
pub mod tdms;
pub mod uff;
pub mod units;
pub mod write;

pub use error::ReadError;
pub use fe_matrices::FeMatricesFile;
pub use format::{read_bytes, read_table, Format};
pub use select::{select, ColumnMap, SelectError, SiColumns};
pub use stream::{open_blocks, RowBlocks, SiBlock, SiBlocks};
pub use table::{Channel, ChannelInfo, Table, TimeAxis};
pub use units::{Conversion, Quantity, UnitError};
pub use write::{write_table, WriteError};
