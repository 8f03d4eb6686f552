//! Errors of the refinement: each names the offending input, its value and the allowed
//! range, so a user can fix the input without reading code. An unidentifiable parameter
//! set is *not* an error: it is reported in the result (flag, warnings, infinite standard
//! errors).

use crate::model::{ModelError, OutOfRange};

/// An input to [`refine`](super::refine), [`crb`](super::crb()) or
/// [`model_response`](super::model_response) that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RefineError {
    /// A scalar input (e.g. `dt`, `m`, `sigma_x`) is outside its allowed range (this
    /// includes NaN and infinity).
    #[error(transparent)]
    OutOfRange(#[from] OutOfRange),
    /// A per-sample array does not have as many samples as the record.
    #[error("{field} has {len} samples but the record has {expected}: every per-sample array must have the same length")]
    LengthMismatch {
        /// The array's name (`z`, `phi`, `omega`, `omega_dot`).
        field: &'static str,
        /// Its length.
        len: usize,
        /// The record's length (the length of `x`).
        expected: usize,
    },
    /// A sample is NaN or infinite.
    #[error("{field}[{index}] = {value} is not finite: every sample must be a finite number")]
    NonFinite {
        /// The array's name.
        field: &'static str,
        /// Index of the first bad sample.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// Not enough samples for the number of unknowns.
    #[error("the record has {samples} samples (x and z each) for {unknowns} unknowns: at least {needed} samples are needed")]
    TooFewSamples {
        /// Samples per channel.
        samples: usize,
        /// Number of estimated quantities (parameters and initial state).
        unknowns: usize,
        /// The minimum accepted.
        needed: usize,
    },
    /// Nothing to estimate.
    #[error("no unknown selected: choose at least one of m, cx, kx, cz, kz, a, unbalance, initial state")]
    NoUnknowns,
    /// The exact (matrix-exponential) discretisation was requested for a speed that is
    /// not constant.
    #[error("the exact discretisation needs a constant speed profile (got {0}); use Discretisation::Auto or Discretisation::Rk4")]
    ExactNeedsConstantSpeed(&'static str),
    /// The model description is invalid.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// Cross-coupled coefficients were asked for, but the start is a Jeffcott rotor (no
    /// cross-coupling): the model has no such parameters.
    #[error("the unknowns {unknowns} are cross-coupled coefficients, which the Jeffcott model does not have: start from a cross-coupled rotor (RotorParams::coupling)")]
    CrossUnknownsNeedCrossModel {
        /// The cross-coupled unknowns asked for, comma-separated.
        unknowns: String,
    },
}

/// First non-finite entry of `v`, as [`RefineError::NonFinite`].
pub(crate) fn check_finite(field: &'static str, v: &[f64]) -> Result<(), RefineError> {
    match v.iter().position(|s| !s.is_finite()) {
        Some(index) => Err(RefineError::NonFinite {
            field,
            index,
            value: v[index],
        }),
        None => Ok(()),
    }
}
