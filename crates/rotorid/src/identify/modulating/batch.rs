//! Whole records: a fold of [`ModulatingIdentifier::push`] (or
//! [`CrossModulatingIdentifier::push`]) over the samples, then one solve, so a batch gives
//! exactly what the streaming identifier gives.

use super::config::ModulatingConfig;
use super::cross::CrossModulatingIdentifier;
use super::cross_estimate::CrossModulatingEstimate;
use super::error::ModulatingError;
use super::estimate::ModulatingEstimate;
use super::identifier::ModulatingIdentifier;
use crate::identify::sampling::record_columns_dt;
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
    record.identify::<ModulatingIdentifier>(known, config)
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
    record.identify::<CrossModulatingIdentifier>(known, config)
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

/// What a whole record needs of a streaming modulating identifier.
trait Streaming: Sized {
    type Estimate;
    fn build(known: Known, dt: f64, config: ModulatingConfig) -> Result<Self, ModulatingError>;
    fn push(&mut self, m: &Measurement) -> Result<(), ModulatingError>;
    fn finish(&self) -> Result<Self::Estimate, ModulatingError>;
    /// (samples, length \[s\]) of one window.
    fn window(&self) -> (usize, f64);
}

impl Streaming for ModulatingIdentifier {
    type Estimate = ModulatingEstimate;
    fn build(known: Known, dt: f64, config: ModulatingConfig) -> Result<Self, ModulatingError> {
        Self::new(known, dt, config)
    }
    fn push(&mut self, m: &Measurement) -> Result<(), ModulatingError> {
        Self::push(self, m)
    }
    fn finish(&self) -> Result<Self::Estimate, ModulatingError> {
        Self::finish(self)
    }
    fn window(&self) -> (usize, f64) {
        (self.window_samples(), self.window_s())
    }
}

impl Streaming for CrossModulatingIdentifier {
    type Estimate = CrossModulatingEstimate;
    fn build(known: Known, dt: f64, config: ModulatingConfig) -> Result<Self, ModulatingError> {
        Self::new(known, dt, config)
    }
    fn push(&mut self, m: &Measurement) -> Result<(), ModulatingError> {
        Self::push(self, m)
    }
    fn finish(&self) -> Result<Self::Estimate, ModulatingError> {
        Self::finish(self)
    }
    fn window(&self) -> (usize, f64) {
        (self.window_samples(), self.window_s())
    }
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
    /// Check the columns (equal lengths, at least two samples, one whole window), push every
    /// sample in order, stop at the first error, and give the estimate.
    fn identify<I: Streaming>(
        &self,
        known: Known,
        config: ModulatingConfig,
    ) -> Result<I::Estimate, ModulatingError> {
        let dt = record_columns_dt(
            self.t,
            [
                self.x.len(),
                self.z.len(),
                self.phi.len(),
                self.w.len(),
                self.w_dot.len(),
            ],
        )?;
        let mut id = I::build(known, dt, config)?;
        let (needed, window_s) = id.window();
        let samples = self.t.len();
        if samples < needed {
            return Err(ModulatingError::RecordShorterThanWindow {
                samples,
                needed,
                window_s,
                dt,
            });
        }
        for i in 0..samples {
            id.push(&Measurement {
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
        id.finish()
    }
}
