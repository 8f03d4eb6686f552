//! Whole records: a fold of [`ModulatingIdentifier::push`] over the samples, then one
//! solve, so a batch gives exactly what the streaming identifier gives.

use super::config::ModulatingConfig;
use super::error::ModulatingError;
use super::estimate::ModulatingEstimate;
use super::identifier::ModulatingIdentifier;
use crate::identify::sampling::record_dt;
use crate::identify::{Known, Measurement};
use crate::model::SpeedState;
use crate::simulate::TimeResponse;

/// Identify m, c, k per direction from a whole record: time `t` \[s\] (uniform), the
/// displacements `x`, `z` \[m\], the rotor angle `phi` \[rad\], speed `w` \[rad/s\] and
/// acceleration `w_dot` \[rad/s^2\], every column as long as `t` (at least two samples; dt
/// is `t[1] - t[0]`). The record must hold at least one window.
#[allow(clippy::too_many_arguments)]
pub fn identify_modulating(
    t: &[f64],
    x: &[f64],
    z: &[f64],
    phi: &[f64],
    w: &[f64],
    w_dot: &[f64],
    known: Known,
    config: ModulatingConfig,
) -> Result<ModulatingEstimate, ModulatingError> {
    let dt = record_dt(
        t,
        [
            ("x", x.len()),
            ("z", z.len()),
            ("phi", phi.len()),
            ("phi_dot", w.len()),
            ("phi_ddot", w_dot.len()),
        ],
    )?;
    let n = t.len();
    let mut id = ModulatingIdentifier::new(known, dt, config)?;
    if n < id.window_samples() {
        return Err(ModulatingError::RecordShorterThanWindow {
            samples: n,
            needed: id.window_samples(),
            window_s: id.window_s(),
            dt,
        });
    }
    for i in 0..n {
        id.push(&Measurement {
            t: t[i],
            x: x[i],
            z: z[i],
            speed: SpeedState {
                phi: phi[i],
                omega: w[i],
                omega_dot: w_dot[i],
            },
        })?;
    }
    Ok(id.estimate())
}

/// [`identify_modulating`] over a simulated record.
pub fn identify_modulating_response(
    resp: &TimeResponse,
    known: Known,
    config: ModulatingConfig,
) -> Result<ModulatingEstimate, ModulatingError> {
    identify_modulating(
        &resp.t,
        &resp.x,
        &resp.z,
        &resp.phi,
        &resp.phi_dot,
        &resp.phi_ddot,
        known,
        config,
    )
}
