//! Checks on the sampling of a record that every identifier makes: the period from the
//! first two times, columns of equal length, and each sample on the uniform grid.

use super::error::InputError;

/// Relative jitter allowed on the sampling period (plus 8 ulp of t).
pub const SAMPLING_TOLERANCE: f64 = 1e-6;

/// The names of a record's columns beside t, in the order [`record_columns_dt`] takes
/// their lengths.
const COLUMNS: [&str; 5] = ["x", "z", "phi", "phi_dot", "phi_ddot"];

/// [`record_dt`] for a record of t and the columns x, z, phi, phi_dot, phi_ddot of
/// lengths `lens`.
pub(crate) fn record_columns_dt(t: &[f64], lens: [usize; 5]) -> Result<f64, InputError> {
    record_dt(t, std::array::from_fn(|i| (COLUMNS[i], lens[i])))
}

/// The sampling period `t[1] - t[0]` \[s\] of a record with times `t` and the other
/// `columns` (name, length), after checking that every column is as long as `t`
/// ([`InputError::ColumnLength`] for the first that is not) and that there are at least
/// two samples ([`InputError::TooFewSamples`]).
pub(crate) fn record_dt(t: &[f64], columns: [(&'static str, usize); 5]) -> Result<f64, InputError> {
    let n = t.len();
    for (column, len) in columns {
        if len != n {
            return Err(InputError::ColumnLength {
                column,
                len,
                expected: n,
            });
        }
    }
    if n < 2 {
        return Err(InputError::TooFewSamples { samples: n });
    }
    Ok(t[1] - t[0])
}

/// Check that sample `index` at time `t` \[s\] is the previous one at `t_prev` \[s\] plus `dt`
/// \[s\] within `SAMPLING_TOLERANCE dt + 8 ulp(max(|t|, |t_prev|))`, else
/// [`InputError::NonUniformSampling`] (a NaN `t` is rejected too).
#[inline(always)]
pub(crate) fn check_on_time(index: u64, t: f64, t_prev: f64, dt: f64) -> Result<(), InputError> {
    let expected = t_prev + dt;
    let tolerance = SAMPLING_TOLERANCE * dt + 8.0 * f64::EPSILON * t.abs().max(t_prev.abs());
    if (t - expected).abs() <= tolerance {
        Ok(())
    } else {
        Err(InputError::NonUniformSampling {
            index,
            t,
            expected,
            tolerance,
            dt,
        })
    }
}
