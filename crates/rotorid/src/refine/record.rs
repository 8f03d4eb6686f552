//! The measured record (x, z sampled at t_i = i dt) and the known speed during it.
//!
//! The speed is either an analytic [`SpeedProfile`] (evaluated exactly at any time) or
//! per-sample arrays phi_i, w_i, w'_i (measured data: a tachometer / encoder). Between two
//! samples the rotor angle is the quintic Hermite interpolant that matches phi, phi' = w and
//! phi'' = w' at both ends (exact for any polynomial phi(t) of degree <= 5, so exact for
//! constant speed and linear ramps); w and w' are its first and second derivatives.

use crate::model::{check, Scenario, SpeedProfile};
use crate::simulate::TimeResponse;

use super::error::{check_finite, RefineError};

/// The rotor angle, speed and acceleration during a record.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SpeedData<'a> {
    /// An analytic profile (constant speed or linear ramp).
    Profile(SpeedProfile),
    /// Per-sample values at t_i = i dt, each as long as the record.
    Samples {
        /// Rotor angle phi_i \[rad\] (wrapped or unwrapped: it is unwrapped internally using w).
        phi: &'a [f64],
        /// Speed w_i = phi' \[rad/s\].
        omega: &'a [f64],
        /// Angular acceleration w'_i = phi'' \[rad/s^2\].
        omega_dot: &'a [f64],
    },
}

impl SpeedData<'_> {
    /// The constant speed W \[rad/s\] and phi(0) \[rad\] when the speed is an analytic
    /// profile with w' = 0, else `None` (per-sample data always goes through the general
    /// integrator).
    pub(crate) fn constant(&self) -> Option<(f64, f64)> {
        match *self {
            SpeedData::Profile(SpeedProfile::Constant { omega, phi0 }) => Some((omega, phi0)),
            SpeedData::Profile(SpeedProfile::Ramp {
                omega0,
                accel: 0.0,
                phi0,
            }) => Some((omega0, phi0)),
            _ => None,
        }
    }

    /// A short name for messages.
    pub(crate) fn describe(&self) -> &'static str {
        match self {
            SpeedData::Profile(SpeedProfile::Constant { .. }) => "a constant speed",
            SpeedData::Profile(SpeedProfile::Ramp { .. }) => "a speed ramp",
            SpeedData::Samples { .. } => "per-sample speed data",
        }
    }
}

/// The experiment without the measurements: sampling and speed. Enough to compute the
/// model response and the Cramer-Rao bound.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Experiment<'a> {
    /// Sampling period dt \[s\], finite and > 0.
    pub dt: f64,
    /// Number of samples per channel, t_0 = 0 ... t_(samples-1) = (samples-1) dt.
    pub samples: usize,
    /// The speed during the record.
    pub speed: SpeedData<'a>,
}

impl Experiment<'static> {
    /// The sampling grid and speed profile of a scenario (`samples()` samples).
    pub fn from_scenario(s: &Scenario) -> Self {
        Self {
            dt: s.sampling.dt(),
            samples: s.sampling.samples(),
            speed: SpeedData::Profile(s.speed),
        }
    }
}

impl Experiment<'_> {
    /// Check dt, the sample count and the speed arrays (lengths, finiteness).
    pub(crate) fn validate(&self) -> Result<(), RefineError> {
        check("dt", self.dt, "finite and > 0 (s)", |v| v > 0.0)?;
        if self.samples < 2 {
            return Err(RefineError::TooFewSamples {
                samples: self.samples,
                unknowns: 0,
                needed: 2,
            });
        }
        if let SpeedData::Samples {
            phi,
            omega,
            omega_dot,
        } = self.speed
        {
            for (field, v) in [("phi", phi), ("omega", omega), ("omega_dot", omega_dot)] {
                if v.len() != self.samples {
                    return Err(RefineError::LengthMismatch {
                        field,
                        len: v.len(),
                        expected: self.samples,
                    });
                }
                check_finite(field, v)?;
            }
        }
        Ok(())
    }
}

/// A measured record: displacements x, z \[m\] at t_i = i dt and the speed during it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Record<'a> {
    /// Sampling period dt \[s\], finite and > 0.
    pub dt: f64,
    /// Horizontal displacement x_i \[m\].
    pub x: &'a [f64],
    /// Vertical displacement z_i \[m\], same length as `x`.
    pub z: &'a [f64],
    /// The speed during the record.
    pub speed: SpeedData<'a>,
}

impl<'a> Record<'a> {
    /// The record of a simulated scenario: x, z from `resp`, speed from the scenario's
    /// profile (exact), dt from its sampling.
    pub fn from_simulation(scenario: &Scenario, resp: &'a TimeResponse) -> Self {
        Self {
            dt: scenario.sampling.dt(),
            x: &resp.x,
            z: &resp.z,
            speed: SpeedData::Profile(scenario.speed),
        }
    }

    /// The same record with the speed taken from the response's per-sample phi, phi',
    /// phi'' (as measured data would give it) instead of the analytic profile.
    pub fn from_simulation_samples(scenario: &Scenario, resp: &'a TimeResponse) -> Self {
        Self {
            speed: SpeedData::Samples {
                phi: &resp.phi,
                omega: &resp.phi_dot,
                omega_dot: &resp.phi_ddot,
            },
            ..Self::from_simulation(scenario, resp)
        }
    }

    /// The experiment (sampling and speed) of this record.
    pub fn experiment(&self) -> Experiment<'a> {
        Experiment {
            dt: self.dt,
            samples: self.x.len(),
            speed: self.speed,
        }
    }

    /// Check lengths and finiteness of every array and dt.
    pub(crate) fn validate(&self) -> Result<(), RefineError> {
        if self.z.len() != self.x.len() {
            return Err(RefineError::LengthMismatch {
                field: "z",
                len: self.z.len(),
                expected: self.x.len(),
            });
        }
        check_finite("x", self.x)?;
        check_finite("z", self.z)?;
        self.experiment().validate()
    }
}
