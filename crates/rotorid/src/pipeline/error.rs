//! Errors of the pipeline: unusable input (with the sample index and field), or an error
//! of the method it ran. Each variant carries the offending values; what the data cannot
//! determine is not an error but a [`super::Diagnostic`].

use crate::identify::algebraic::AlgebraicError;
use crate::identify::modulating::ModulatingError;
use crate::model::OutOfRange;
use crate::refine::RefineError;

/// Why a record could not be built or identified.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum PipelineError {
    /// A setting or known quantity outside its allowed range.
    #[error(transparent)]
    OutOfRange(#[from] OutOfRange),
    /// Columns of a record with different lengths.
    #[error("column {column} has {len} samples but t has {expected}: every column needs one value per sample")]
    ColumnLength {
        /// The column's name (`x`, `z`, `phi`, `phi_dot`, `phi_ddot`).
        column: &'static str,
        /// Its length.
        len: usize,
        /// The number of samples.
        expected: usize,
    },
    /// A sample holds NaN or infinity.
    #[error(
        "sample {index}: {field} = {value:e} is not finite (every value must be a finite number)"
    )]
    NotFinite {
        /// Index of the sample (0 for the first).
        index: usize,
        /// The field: `t`, `x`, `z`, `phi`, `phi_dot` or `phi_ddot`.
        field: &'static str,
        /// The value.
        value: f64,
    },
    /// Times that do not increase.
    #[error("sample {index}: t = {t} s is not after the previous sample's t = {previous} s (times must increase strictly)")]
    NotIncreasing {
        /// Index of the sample.
        index: usize,
        /// Its time \[s\].
        t: f64,
        /// The previous time \[s\].
        previous: f64,
    },
    /// A time stamp off the uniform grid fitted to the record.
    #[error(
        "sample {index}: sampling is not uniform: t = {t} s is {deviation:.3e} s off the \
         uniform grid t0 + i dt (dt = {dt} s, fitted over the time stamps); the allowed \
         deviation is {tolerance:e} of dt{}. Resample the record, or raise the time tolerance \
         if the stamps are merely rounded",
        rounding_clause(*resolution, *rounding)
    )]
    NonUniformSampling {
        /// Index of the sample.
        index: usize,
        /// Its time \[s\].
        t: f64,
        /// Its distance from the grid \[s\].
        deviation: f64,
        /// The fitted sampling period \[s\].
        dt: f64,
        /// The allowed deviation, relative to dt.
        tolerance: f64,
        /// The stamps' resolution \[s\] (one unit of their last decimal; 0: none)
        /// (`TimeGrid::resolution`).
        resolution: f64,
        /// The deviation allowed besides for that rounding \[s\] (`rounding_allowance`).
        rounding: f64,
    },
    /// Fewer samples than the method needs.
    #[error("{samples} sample(s): {method} needs at least {needed} ({why})")]
    TooFewSamples {
        /// Samples given.
        samples: usize,
        /// Samples needed.
        needed: usize,
        /// The method.
        method: &'static str,
        /// Why.
        why: &'static str,
    },
    /// A record too long to keep for the modulating method's Cramer-Rao bound.
    #[error("the record has {samples} samples; the bound is computed for at most {max}")]
    CrbTooLong {
        /// Samples in the record.
        samples: usize,
        /// The most kept.
        max: usize,
    },
    /// The speed is given neither per sample nor as a profile.
    #[error("no speed: give phi, phi_dot, phi_ddot per sample or a speed profile")]
    NoSpeed,
    /// A sample's speed fields were missing (or present) unlike the session's first.
    #[error("sample {index}: the speed (phi, phi_dot, phi_ddot) must be given with every sample or with none")]
    SpeedPresence {
        /// Index of the sample.
        index: usize,
    },
    /// refine has no start: neither identifier gave a usable estimate and the nominal
    /// values lack some unknowns.
    #[error(
        "refine has no starting point: {why}; no nominal value of {missing} to start from. \
         The record may not excite the rotor at all; give nominal values to let the fit \
         say what the record can determine"
    )]
    NoStart {
        /// Why the identifiers' estimates could not be used.
        why: String,
        /// The unknowns without a nominal value, comma-separated.
        missing: String,
    },
    /// `--model auto` with a given start: the start is a rotor of one model.
    #[error("a given start is a {model} rotor: choose the model (jeffcott or cross_coupled) rather than auto")]
    GivenStartNeedsModel {
        /// The model of the given start.
        model: &'static str,
    },
    /// A parameter left known has no value.
    #[error(
        "{missing} left known, but no value given for {missing}: give its value or estimate it"
    )]
    KnownValueMissing {
        /// The parameters, comma-separated.
        missing: String,
    },
    /// The algebraic identifier refused its input.
    #[error(transparent)]
    Algebraic(#[from] AlgebraicError),
    /// The modulating identifier refused its input.
    #[error(transparent)]
    Modulating(#[from] ModulatingError),
    /// The refinement refused its input.
    #[error("the refinement cannot run: {0}")]
    Refine(#[from] RefineError),
}

/// ", plus A s for stamps printed to R s (...)" for the message of
/// [`PipelineError::NonUniformSampling`]; empty without a resolution.
fn rounding_clause(resolution: f64, rounding: f64) -> String {
    if resolution > 0.0 {
        format!(
            ", plus {rounding:e} s for stamps printed to {resolution:e} s (their rounding, \
             at most {} dt)",
            super::grid::MAX_ROUNDING_ALLOWANCE
        )
    } else {
        String::new()
    }
}
