//! Whole records: a fold of [`ModulatingIdentifier::push`] (or
//! [`CrossModulatingIdentifier::push`]) over the samples, then one solve, so a batch gives
//! exactly what the streaming identifier gives.

use super::config::ModulatingConfig;
use super::cross::CrossModulatingIdentifier;
use super::cross_estimate::CrossModulatingEstimate;
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
    let record = Columns {
        t,
        x,
        z,
        phi,
        w,
        w_dot,
    };
    let dt = record.dt()?;
    let mut id = ModulatingIdentifier::new(known, dt, config)?;
    record.check_window(id.window_samples(), id.window_s(), dt)?;
    record.feed(|m| id.push(m))?;
    Ok(id.estimate())
}

/// The cross-coupled identifier ([`CrossModulatingIdentifier`]) over a whole record: m
/// and the four bearing coefficients of each row, with their standard errors. The columns
/// and their rules are those of [`identify_modulating`].
#[allow(clippy::too_many_arguments)]
pub fn identify_cross_modulating(
    t: &[f64],
    x: &[f64],
    z: &[f64],
    phi: &[f64],
    w: &[f64],
    w_dot: &[f64],
    known: Known,
    config: ModulatingConfig,
) -> Result<CrossModulatingEstimate, ModulatingError> {
    let record = Columns {
        t,
        x,
        z,
        phi,
        w,
        w_dot,
    };
    let dt = record.dt()?;
    let mut id = CrossModulatingIdentifier::new(known, dt, config)?;
    record.check_window(id.window_samples(), id.window_s(), dt)?;
    record.feed(|m| id.push(m))?;
    Ok(id.estimate())
}

/// [`identify_cross_modulating`] over a simulated record.
pub fn identify_cross_modulating_response(
    resp: &TimeResponse,
    known: Known,
    config: ModulatingConfig,
) -> Result<CrossModulatingEstimate, ModulatingError> {
    identify_cross_modulating(
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

/// The columns of a record (units in [`identify_modulating`]'s docs).
struct Columns<'a> {
    t: &'a [f64],
    x: &'a [f64],
    z: &'a [f64],
    phi: &'a [f64],
    w: &'a [f64],
    w_dot: &'a [f64],
}

impl Columns<'_> {
    /// The sampling period, after checking the columns' lengths.
    fn dt(&self) -> Result<f64, ModulatingError> {
        Ok(record_dt(
            self.t,
            [
                ("x", self.x.len()),
                ("z", self.z.len()),
                ("phi", self.phi.len()),
                ("phi_dot", self.w.len()),
                ("phi_ddot", self.w_dot.len()),
            ],
        )?)
    }

    /// [`ModulatingError::RecordShorterThanWindow`] unless one window of `needed` samples
    /// (`window_s` \[s\] at `dt` \[s\]) fits.
    fn check_window(&self, needed: usize, window_s: f64, dt: f64) -> Result<(), ModulatingError> {
        let samples = self.t.len();
        if samples < needed {
            return Err(ModulatingError::RecordShorterThanWindow {
                samples,
                needed,
                window_s,
                dt,
            });
        }
        Ok(())
    }

    /// Push every sample, in order, until the first error.
    fn feed(
        &self,
        mut push: impl FnMut(&Measurement) -> Result<(), ModulatingError>,
    ) -> Result<(), ModulatingError> {
        for i in 0..self.t.len() {
            push(&Measurement {
                t: self.t[i],
                x: self.x[i],
                z: self.z[i],
                speed: SpeedState {
                    phi: self.phi[i],
                    omega: self.w[i],
                    omega_dot: self.w_dot[i],
                },
            })?;
        }
        Ok(())
    }
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
