//! Whole-record identification: a fold of [`AlgebraicIdentifier::push`] over the samples,
//! so a batch gives bit-for-bit the estimates the streaming identifier gives.

use super::config::IdentifierConfig;
use super::error::IdentifyError;
use super::estimate::Estimate;
use super::identifier::AlgebraicIdentifier;
use super::inputs::{Known, Measurement};
use crate::model::SpeedState;
use crate::simulate::TimeResponse;

/// Identify over `measurements` (uniformly sampled every `dt` \[s\]): one estimate per
/// measurement. Stops at the first invalid measurement with its error.
pub fn identify_batch(
    measurements: &[Measurement],
    known: Known,
    dt: f64,
    config: IdentifierConfig,
) -> Result<Vec<Estimate>, IdentifyError> {
    let mut id = AlgebraicIdentifier::new(known, dt, config)?;
    let mut out = Vec::with_capacity(measurements.len());
    for m in measurements {
        out.push(id.push(m)?);
    }
    Ok(out)
}

/// Identify over a simulated record; dt is `t[1] - t[0]` (at least 2 samples).
pub fn identify_response(
    resp: &TimeResponse,
    known: Known,
    config: IdentifierConfig,
) -> Result<Vec<Estimate>, IdentifyError> {
    let dt = record_dt(
        &resp.t,
        [
            ("x", resp.x.len()),
            ("z", resp.z.len()),
            ("phi", resp.phi.len()),
            ("phi_dot", resp.phi_dot.len()),
            ("phi_ddot", resp.phi_ddot.len()),
        ],
    )?;
    let mut id = AlgebraicIdentifier::new(known, dt, config)?;
    let n = resp.t.len();
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        out.push(id.push(&measurement(resp, i))?);
    }
    Ok(out)
}

/// The sampling period `t[1] - t[0]` \[s\] of a record with times `t` and the other
/// `columns` (name, length), after checking that every column is as long as `t`
/// ([`IdentifyError::ColumnLength`] for the first that is not) and that there are at least
/// two samples ([`IdentifyError::TooFewSamples`]).
pub(crate) fn record_dt(
    t: &[f64],
    columns: [(&'static str, usize); 5],
) -> Result<f64, IdentifyError> {
    let n = t.len();
    for (column, len) in columns {
        if len != n {
            return Err(IdentifyError::ColumnLength {
                column,
                len,
                expected: n,
            });
        }
    }
    if n < 2 {
        return Err(IdentifyError::TooFewSamples { samples: n });
    }
    Ok(t[1] - t[0])
}

/// Sample `i` of `resp` as a [`Measurement`].
pub fn measurement(resp: &TimeResponse, i: usize) -> Measurement {
    Measurement {
        t: resp.t[i],
        x: resp.x[i],
        z: resp.z[i],
        speed: SpeedState {
            phi: resp.phi[i],
            omega: resp.phi_dot[i],
            omega_dot: resp.phi_ddot[i],
        },
    }
}
