//! Errors in what every identifier takes: a configuration value out of range, a sample that is
//! not finite or off the uniform grid, record columns of unequal length. Each variant carries
//! the offending value, sample or name, and its message states what is allowed, so a user can
//! fix the input without reading code. Each method wraps it in its own error type
//! ([`super::algebraic::AlgebraicError`], [`super::modulating::ModulatingError`]).

use crate::model::OutOfRange;

/// Why an identifier could not be built or could not take a measurement.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum InputError {
    /// A configuration value or known quantity (e.g. `dt`, `rcond_min`, `known.a`) is
    /// outside its allowed range (this includes NaN and infinity).
    #[error(transparent)]
    OutOfRange(#[from] OutOfRange),
    /// A measurement holds NaN or infinity.
    #[error("sample {index}: {field} = {value} is not finite (the identifier needs finite measurements)")]
    NotFinite {
        /// Index of the sample since the identifier started (0 for the first).
        index: u64,
        /// The field's name: `t`, `x`, `z`, `phi`, `phi_dot` or `phi_ddot`.
        field: &'static str,
        /// The rejected value.
        value: f64,
    },
    /// The sample is not one period after the previous one (or time goes backwards).
    #[error(
        "sample {index} at t = {t} s breaks uniform sampling: expected t = {expected} s \
         within {tolerance:e} s (period dt = {dt} s; allowed jitter 1e-6 dt + 8 ulp(t)); \
         the identifier needs strictly increasing, uniformly sampled times"
    )]
    NonUniformSampling {
        /// Index of the sample since the identifier started.
        index: u64,
        /// Its time \[s\].
        t: f64,
        /// The previous sample's time plus dt \[s\].
        expected: f64,
        /// The allowed deviation from `expected` \[s\].
        tolerance: f64,
        /// The nominal sampling period \[s\].
        dt: f64,
    },
    /// A record too short to derive the sampling period from.
    #[error(
        "the record has {samples} sample(s): at least 2 are needed to derive the sampling period"
    )]
    TooFewSamples {
        /// Number of samples in the record.
        samples: usize,
    },
    /// The columns of a record have different lengths.
    #[error("column {column} has {len} samples but t has {expected}: every column must have one value per time")]
    ColumnLength {
        /// The column's name.
        column: &'static str,
        /// Its length.
        len: usize,
        /// The length of `t`.
        expected: usize,
    },
}
