//! Whole-record identification: a fold of [`AlgebraicIdentifier::push`] (or
//! [`CrossAlgebraicIdentifier::push`]) over the samples, so a batch gives bit-for-bit the
//! estimates the streaming identifier gives.

use super::config::AlgebraicConfig;
use super::cross::CrossAlgebraicIdentifier;
use super::cross_estimate::CrossAlgebraicEstimate;
use super::error::AlgebraicError;
use super::estimate::AlgebraicEstimate;
use super::identifier::AlgebraicIdentifier;
use crate::identify::sampling::record_columns_dt;
use crate::identify::{Known, Measurement};
use crate::model::SpeedState;
use crate::simulate::TimeResponse;

/// Identify over `measurements` (uniformly sampled every `dt` \[s\]): one estimate per
/// measurement. Stops at the first invalid measurement with its error.
pub fn identify_batch(
    measurements: &[Measurement],
    known: Known,
    dt: f64,
    config: AlgebraicConfig,
) -> Result<Vec<AlgebraicEstimate>, AlgebraicError> {
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
    config: AlgebraicConfig,
) -> Result<Vec<AlgebraicEstimate>, AlgebraicError> {
    let dt = response_dt(resp)?;
    let mut id = AlgebraicIdentifier::new(known, dt, config)?;
    (0..resp.len())
        .map(|i| id.push(&measurement(resp, i)))
        .collect()
}

/// The cross-coupled identifier ([`CrossAlgebraicIdentifier`]) over `measurements`
/// (uniformly sampled every `dt` \[s\]): one estimate per measurement. Stops at the first
/// invalid measurement with its error.
pub fn identify_cross_batch(
    measurements: &[Measurement],
    known: Known,
    dt: f64,
    config: AlgebraicConfig,
) -> Result<Vec<CrossAlgebraicEstimate>, AlgebraicError> {
    let mut id = CrossAlgebraicIdentifier::new(known, dt, config)?;
    measurements.iter().map(|m| id.push(m)).collect()
}

/// The cross-coupled identifier over a simulated record; dt is `t[1] - t[0]` (at least 2
/// samples).
pub fn identify_cross_response(
    resp: &TimeResponse,
    known: Known,
    config: AlgebraicConfig,
) -> Result<Vec<CrossAlgebraicEstimate>, AlgebraicError> {
    let dt = response_dt(resp)?;
    let mut id = CrossAlgebraicIdentifier::new(known, dt, config)?;
    (0..resp.len())
        .map(|i| id.push(&measurement(resp, i)))
        .collect()
}

/// The sampling period of `resp` after checking its columns (see `record_dt`).
fn response_dt(resp: &TimeResponse) -> Result<f64, AlgebraicError> {
    Ok(record_columns_dt(
        &resp.t,
        [
            resp.x.len(),
            resp.z.len(),
            resp.phi.len(),
            resp.phi_dot.len(),
            resp.phi_ddot.len(),
        ],
    )?)
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
