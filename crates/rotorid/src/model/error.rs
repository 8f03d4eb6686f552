//! Validation errors for model inputs: each names the field, the offending value and the
//! allowed range, so a user can fix the input without reading code.

/// A model input outside its allowed range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// A parameter is outside its allowed range (this includes NaN and infinity).
    #[error("{field} = {value} is out of range: must be {allowed}")]
    OutOfRange {
        /// The field's name as the user writes it (e.g. `m`, `rotor.kx`, `sampling.dt`).
        field: &'static str,
        /// The rejected value.
        value: f64,
        /// The allowed range in words, with its unit (e.g. `finite and > 0 (kg)`).
        allowed: &'static str,
    },
    /// Two fields that are each valid do not fit together.
    #[error("{0}")]
    Inconsistent(String),
}

/// Check `value` with `ok`, or return [`ModelError::OutOfRange`] naming `field`.
pub(crate) fn check(
    field: &'static str,
    value: f64,
    allowed: &'static str,
    ok: impl Fn(f64) -> bool,
) -> Result<f64, ModelError> {
    if value.is_finite() && ok(value) {
        Ok(value)
    } else {
        Err(ModelError::OutOfRange {
            field,
            value,
            allowed,
        })
    }
}
