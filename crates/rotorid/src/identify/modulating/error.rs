//! Errors of the modulating-function identifier. Each names the offending input and
//! states what is allowed. A singular least-squares problem is NOT an error (the estimate
//! is NaN with rcond = 0).

use crate::identify::InputError;
use crate::model::OutOfRange;

/// Why the modulating-function identifier could not be built or run.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModulatingError {
    /// A value, measurement or record column the algebraic identifier would also reject
    /// (out of range, not finite, non-uniform sampling, columns of unequal length).
    #[error(transparent)]
    Input(#[from] InputError),
    /// The window is too short in samples for its test functions.
    #[error(
        "window_s = {window_s} s is {intervals} sampling intervals at dt = {dt} s: \
         must be at least {needed} intervals (8 per test function, {functions} functions, and 24)"
    )]
    WindowTooShort {
        /// The window length asked for \[s\].
        window_s: f64,
        /// The sampling period \[s\].
        dt: f64,
        /// The window in sampling intervals (rounded).
        intervals: usize,
        /// The fewest intervals accepted.
        needed: usize,
        /// Test functions per window.
        functions: usize,
    },
    /// The record does not hold one whole window.
    #[error(
        "the record has {samples} samples but one window needs {needed} \
         (window_s = {window_s} s at dt = {dt} s): shorten the window or give more data"
    )]
    RecordShorterThanWindow {
        /// Samples in the record.
        samples: usize,
        /// Samples in one window.
        needed: usize,
        /// The window length \[s\].
        window_s: f64,
        /// The sampling period \[s\].
        dt: f64,
    },
}

/// An out-of-range value is the same [`InputError`] the algebraic identifier returns.
impl From<OutOfRange> for ModulatingError {
    fn from(e: OutOfRange) -> Self {
        Self::Input(e.into())
    }
}
