//! Configuration of the algebraic identifier: the running quadrature, the conditioning
//! threshold below which an instant is flagged, and the speed model
//! (docs/method.md section 3.3: the general, variable-speed identifier or its
//! constant-speed special case).

use serde::{Deserialize, Serialize};

use super::error::AlgebraicError;
use super::quadrature::Quadrature;
use crate::model::check;

/// Default [`AlgebraicConfig::rcond_min`]: instants whose scaled 3x3 system has a
/// reciprocal condition number below this are flagged (ill-conditioned).
///
/// Calibrated on table1 (1200 rpm and the 10 rad/s^2 ramps from rest and from 1200 rpm,
/// exact data, dt = 0.1 ms, 1 s, default quadrature): after the first 20 ms the median
/// rcond is ~1.5e-3, and A(t) passes near singularity at isolated instants where rcond
/// drops to 1e-8 .. 1e-6 for a few samples; the estimate's error there grows like
/// ~1e-9 / rcond (up to 1e-2). At 1e-5, 0.02-0.7 % of the instants are flagged and every
/// unflagged estimate is within 6e-4 of the truth (every error above 1e-3 is flagged).
/// Errors in the data (noise, a discretised simulation) raise the error of a
/// well-conditioned instant to ~(data error)/rcond: raise the threshold for such data.
/// See `tests/identify_conditioning.rs`.
pub const DEFAULT_ALGEBRAIC_RCOND_MIN: f64 = 1e-5;

/// Default [`AlgebraicConfig::rcond_min`] for the cross-coupled identifier
/// ([`super::CrossAlgebraicIdentifier`]): the same value as the Jeffcott identifier's, so
/// [`AlgebraicConfig::default`] serves both, but a different matrix (the two-sided
/// equilibrated 5x5 system, [`super::cross_solve`]).
///
/// Calibrated on exact data (dt = 0.1 ms, 1 s, default quadrature; tests
/// `cross_algebraic.rs`): table1 and four cross-coupled rotors at 1200 rpm and on the
/// 10 rad/s^2 ramps from rest and from 1200 rpm. Every unflagged estimate from 20 ms on is
/// within 1e-3 of the truth (cross terms against the direct coefficient of their row). Far
/// more instants are flagged than for the 3x3 system (12-30 % on table1, up to 83 % on a
/// well-damped cross-coupled rotor at constant speed): once the free transient has died
/// out, a single-frequency response cannot separate m from the stiffness (P\[y\] = -W^2 R\[y\]
/// for a sinusoid of frequency W) nor the five coefficients of a row, and the 5x5 system
/// says so. Data errors raise an instant's error to ~(data error)/rcond, as for the 3x3.
pub const DEFAULT_CROSS_ALGEBRAIC_RCOND_MIN: f64 = DEFAULT_ALGEBRAIC_RCOND_MIN;

/// How the rotor angle and speed are obtained.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub enum SpeedModel {
    /// Variable speed: phi, w = phi', w' = phi'' are taken from every measurement
    /// (docs/method.md section 3.3, general case).
    #[default]
    General,
    /// Constant speed W: w = W, w' = 0 and phi = phi0 + W t (t the measurement's time);
    /// the measurements' speed fields are ignored (docs/method.md section 3.3, constant
    /// case).
    Constant {
        /// Speed W \[rad/s\], finite.
        omega: f64,
        /// Rotor angle at t = 0 \[rad\], finite.
        phi0: f64,
    },
}

/// Settings of [`super::AlgebraicIdentifier`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AlgebraicConfig {
    /// The running quadrature for every iterated integral (default: order 5).
    pub quadrature: Quadrature,
    /// Instants with rcond < `rcond_min` are flagged as ill-conditioned (dimensionless,
    /// in [0, 1]; default [`DEFAULT_ALGEBRAIC_RCOND_MIN`]).
    pub rcond_min: f64,
    /// Where phi, w, w' come from (default: from the measurements).
    pub speed_model: SpeedModel,
}

impl Default for AlgebraicConfig {
    fn default() -> Self {
        Self {
            quadrature: Quadrature::default(),
            rcond_min: DEFAULT_ALGEBRAIC_RCOND_MIN,
            speed_model: SpeedModel::General,
        }
    }
}

impl AlgebraicConfig {
    /// A validated configuration (see [`validated`](Self::validated)).
    pub fn new(
        quadrature: Quadrature,
        rcond_min: f64,
        speed_model: SpeedModel,
    ) -> Result<Self, AlgebraicError> {
        Self {
            quadrature,
            rcond_min,
            speed_model,
        }
        .validated()
    }

    /// The default configuration for a rotor at constant speed `omega` \[rad/s\] from angle
    /// `phi0` \[rad\] at t = 0.
    pub fn constant_speed(omega: f64, phi0: f64) -> Result<Self, AlgebraicError> {
        Self {
            speed_model: SpeedModel::Constant { omega, phi0 },
            ..Self::default()
        }
        .validated()
    }

    /// Check: rcond_min in [0, 1]; a constant speed's omega and phi0 finite.
    pub fn validated(self) -> Result<Self, AlgebraicError> {
        check("rcond_min", self.rcond_min, "finite and in [0, 1]", |v| {
            (0.0..=1.0).contains(&v)
        })?;
        if let SpeedModel::Constant { omega, phi0 } = self.speed_model {
            check("omega", omega, "finite (rad/s)", |_| true)?;
            check("phi0", phi0, "finite (rad)", |_| true)?;
        }
        Ok(self)
    }
}
