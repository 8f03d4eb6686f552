//! Errors of the transient analysis: each names the record or channel, the field, the
//! offending value and what is allowed.

use crate::acquisition::AcquisitionError;
use crate::model::OutOfRange;

/// An input to the transient analysis that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum TransientError {
    /// A setting outside its allowed range (NaN and infinity included).
    #[error(transparent)]
    OutOfRange(#[from] OutOfRange),
    /// The keyphasor or a channel of a raw record cannot be used.
    #[error(transparent)]
    Acquisition(#[from] AcquisitionError),
    /// The model of a mode fit refused its parameters.
    #[error(transparent)]
    Description(#[from] crate::model::description::DescriptionError),
    /// The model's response cannot be computed (a singular matrix, a growing response).
    #[error("{0}")]
    ModelResponse(String),
    /// Two inputs that must have the same length do not.
    #[error("{field} has {len} values but {other} has {expected}")]
    LengthMismatch {
        /// The input that is off.
        field: &'static str,
        /// Its length.
        len: usize,
        /// The input it is compared with.
        other: &'static str,
        /// That input's length.
        expected: usize,
    },
    /// A sample that is NaN or infinite.
    #[error("{field}[{index}] is {value}: every value must be a finite number")]
    NonFinite {
        /// The input.
        field: &'static str,
        /// Index of the sample.
        index: usize,
        /// The value.
        value: f64,
    },
    /// Too little data for what was asked.
    #[error("{what}: {found} found, at least {needed} needed")]
    TooFew {
        /// What is counted (e.g. `whole revolutions of the record`).
        what: String,
        /// How many there are.
        found: usize,
        /// How many are needed.
        needed: usize,
    },
    /// The shaft speed does not change enough for a Bode plot.
    #[error("the speed changes only from {min_rpm:.1} to {max_rpm:.1} rpm ({change_pct:.2} % of its mean): a run-up or coast-down must change the speed by at least {needed_pct} %; for a record at one speed use `rotorid onex`")]
    SpeedTooSteady {
        /// Lowest revolution speed \[rev/min\].
        min_rpm: f64,
        /// Highest revolution speed \[rev/min\].
        max_rpm: f64,
        /// (max - min) / mean \[%\].
        change_pct: f64,
        /// The least change accepted \[%\].
        needed_pct: f64,
    },
    /// A revolution has fewer samples than the harmonics fitted to it need.
    #[error("revolution {revolution} (t = {t:.6} s) has {samples} samples: order {order} needs at least {needed} per revolution (sample faster, or drop the order with --orders)")]
    TooFewSamplesPerRevolution {
        /// Index of the revolution.
        revolution: usize,
        /// Its start time \[s\].
        t: f64,
        /// Its samples.
        samples: usize,
        /// The highest order asked for.
        order: u32,
        /// The fewest samples per revolution that order needs.
        needed: usize,
    },
    /// An input this analysis cannot take (a raw record where the shaft angle is given,
    /// or the other way round).
    #[error("{input}: {reason}")]
    Unusable {
        /// The input as given.
        input: String,
        /// Why, and what to give instead.
        reason: &'static str,
    },
    /// An error of one input or step (a record, a table's sensor), named first.
    #[error("{input}: {source}")]
    Within {
        /// The input or step (`runup.csv: order tracking`).
        input: String,
        /// What went wrong there.
        source: Box<TransientError>,
    },
    /// A time step that differs from the record's median step by more than the tolerance
    /// (spectra need uniform sampling; a step <= 0 means the times do not increase).
    #[error("{field}[{index}] - {field}[{prev}] = {dt:e} s but the median step is {median_dt:e} s: a spectrum needs uniform sampling (every step within {tolerance_pct} % of the median); resample the record first", prev = .index - 1)]
    NonUniformSampling {
        /// The time input (e.g. `t`).
        field: &'static str,
        /// Index of the sample that ends the step.
        index: usize,
        /// That step \[s\].
        dt: f64,
        /// The median step of the record \[s\].
        median_dt: f64,
        /// The largest deviation from the median accepted \[%\].
        tolerance_pct: f64,
    },
}

/// The first NaN or infinite value of `v`, as an error naming `field`.
pub(crate) fn check_finite(field: &'static str, v: &[f64]) -> Result<(), TransientError> {
    match v.iter().position(|x| !x.is_finite()) {
        Some(index) => Err(TransientError::NonFinite {
            field,
            index,
            value: v[index],
        }),
        None => Ok(()),
    }
}

/// `Ok` when `a` and `b` have the same length.
pub(crate) fn same_length(
    field: &'static str,
    a: usize,
    other: &'static str,
    b: usize,
) -> Result<(), TransientError> {
    if a == b {
        Ok(())
    } else {
        Err(TransientError::LengthMismatch {
            field,
            len: a,
            other,
            expected: b,
        })
    }
}
