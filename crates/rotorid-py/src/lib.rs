//! The core of rotorid's Python package: pure functions over borrowed columns (no Python
//! types), called by the extension module `rotorid._rotorid` (feature `python`), which
//! only converts arrays and releases the GIL around them. Every computation is the
//! library's pipeline (`rotorid::pipeline`), run as `rotorid identify` runs it, so a
//! record gives the identical result from Python as from the command line.
//!
//! - [`scenario`]: scenarios from `table1`, a TOML file or keyword arguments; simulation.
//! - [`response`]: the response CSV, read into columns.
//! - [`columns`]: borrowed columns in, the estimates table out.
//! - [`options`]: the method and its settings from keyword arguments.
//! - [`stream`]: identification of a record, or of a live stream of chunks.
//! - [`balance`]: multi-plane balancing and trial planning from the two CSV tables.
//! - [`transient`]: run-ups and coast-downs, as `rotorid transient` analyses them.
//! - [`finite_element`]: a finite-element rotor's scenario joined with its matrices file.

pub mod balance;
pub mod columns;
pub mod error;
pub mod finite_element;
pub mod options;
pub mod response;
pub mod scenario;
pub mod stream;
pub mod transient;

#[cfg(feature = "python")]
mod python;

/// The extension's own allocations (a reader's channels, which numpy then owns) are
/// advised for transparent huge pages as in the `rotorid` binary: `rotorid.read` of the
/// 48 MB TDMS benchmark record takes 0.038 s instead of 0.061 s (docs/performance.md).
/// Only the extension module has it; the library's tests use the system allocator.
#[cfg(feature = "python")]
#[global_allocator]
static ALLOCATOR: rotorid_alloc::HugePageAdvice = rotorid_alloc::HugePageAdvice;

pub use error::Error;
