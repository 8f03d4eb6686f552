//! Whole-record identification: a fold of [`AlgebraicIdentifier::push`] over the samples,
//! so a batch gives bit-for-bit the estimates the streaming identifier gives.

use super::config::AlgebraicConfig;
use super::error::AlgebraicError;
use super::estimate::AlgebraicEstimate;
use super::identifier::AlgebraicIdentifier;
use crate::identify::sampling::record_dt;
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
