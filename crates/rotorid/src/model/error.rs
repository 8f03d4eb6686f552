//! Validation errors for inputs: each names the field, the offending value and the allowed
//! range, so a user can fix the input without reading code.
//!
//! [`OutOfRange`] and [`check`] serve every module: the simulators', identifiers' and
//! refinement's error types each wrap an [`OutOfRange`] in a variant of that name
//! ([`ModelError::OutOfRange`] spells out its fields), and `check(...)?` converts it into
//! whichever error the caller returns.

/// A scalar input outside its allowed range (this includes NaN and infinity).
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error("{field} = {value} is out of range: must be {allowed}")]
pub struct OutOfRange {
    /// The input's name as the user writes it (e.g. `m`, `dt`, `known.a`, `sigma_x`).
    pub field: &'static str,
    /// The rejected value.
    pub value: f64,
    /// The allowed range in words, with its unit (e.g. `finite and > 0 (kg)`).
    pub allowed: &'static str,
}

/// A model input outside its allowed range.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ModelError {
    /// A parameter is outside its allowed range (this includes NaN and infinity). The same
    /// fields and message as [`OutOfRange`] (the unit test holds them equal), spelt out
    /// rather than wrapped because callers destructure them.
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
    /// The damping matrix's symmetric part is not positive semi-definite: the bearings
    /// would feed energy into every motion in some direction.
    #[error(
        "the damping matrix [[cxx, cxz], [czx, czz]] = [[{cxx}, {cxz}], [{czx}, {czz}]] N s/m \
         is not dissipative: its symmetric part must be positive semi-definite, \
         cxx >= 0, czz >= 0 and cxx czz >= ((cxz + czx) / 2)^2"
    )]
    DampingNotDissipative {
        /// cxx \[N s/m\].
        cxx: f64,
        /// cxz \[N s/m\].
        cxz: f64,
        /// czx \[N s/m\].
        czx: f64,
        /// czz \[N s/m\].
        czz: f64,
    },
}

impl From<OutOfRange> for ModelError {
    fn from(e: OutOfRange) -> Self {
        Self::OutOfRange {
            field: e.field,
            value: e.value,
            allowed: e.allowed,
        }
    }
}

/// `value` if it is finite and passes `ok`, else [`OutOfRange`] naming `field` (`?`
/// converts it into the caller's error type).
pub(crate) fn check(
    field: &'static str,
    value: f64,
    allowed: &'static str,
    ok: impl Fn(f64) -> bool,
) -> Result<f64, OutOfRange> {
    if value.is_finite() && ok(value) {
        Ok(value)
    } else {
        Err(OutOfRange {
            field,
            value,
            allowed,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn check_rejects_non_finite_values_and_states_the_range() {
        let allowed = "finite and > 0 (s)";
        assert_eq!(check("dt", 2.0, allowed, |v| v > 0.0), Ok(2.0));
        let e = check("dt", -1.0, allowed, |v| v > 0.0).unwrap_err();
        let msg = "dt = -1 is out of range: must be finite and > 0 (s)";
        assert_eq!(e.to_string(), msg);
        assert_eq!(ModelError::from(e).to_string(), msg);
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let e = check("a", bad, "finite (N s^2/m)", |_| true).unwrap_err();
            assert_eq!((e.field, e.allowed), ("a", "finite (N s^2/m)"));
            assert!(e.value == bad || (bad.is_nan() && e.value.is_nan()));
        }
    }
}
