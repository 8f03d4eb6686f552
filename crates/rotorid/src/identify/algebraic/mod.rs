//! The paper's algebraic identifier of m, c, k per direction (Barredo et al. 2024, eqs. 2-8;
//! docs/method.md section 3), streaming and batch.
//!
//! Multiplying eq. (1) by tau^2 = (t - t_0)^2 and integrating twice removes the unknown
//! initial displacement and velocity (`I2[tau^2 y''] = tau^2 y - 4 I1[tau y] + 2 I2[y]`,
//! `I2[tau^2 y'] = I1[tau^2 y] - 2 I2[tau y]`); integrating the resulting scalar equation
//! p(t) . theta = s(t) once and twice more gives the 3x3 system A(t) theta = b(t) solved at
//! every sample:
//!
//! - [`quadrature`]: the running iterated integrals I1..I4 and their rules ([`Quadrature`]).
//! - [`AlgebraicIdentifier`]: signals, assembly, one [`AlgebraicEstimate`] per
//!   [`Measurement`](super::Measurement), general (variable speed) or constant-speed
//!   ([`SpeedModel`]).
//! - [`scaled_solve`]: scaling, solution and conditioning (rcond) of the 3x3 system.
//! - [`RestartingIdentifier`]: overlapping restarts for records of any length.
//! - [`ConvergenceTracker`]: final values and identification times in bounded memory.
//! - [`identify_batch`], [`identify_response`]: whole records.
//!
//! The cross-coupled rotor (docs/method.md section 3.10): per row m and that
//! row's four bearing coefficients, five unknowns, from the same scalar equation and its
//! iterated integrals I1..I4 (a 5x5 system of I0..I6 of the same signals):
//!
//! - [`CrossAlgebraicIdentifier`]: one [`CrossAlgebraicEstimate`] per measurement.
//! - [`cross_solve`]: scaling, LU solution and exact 1-norm rcond of the 5x5 system.
//! - [`identify_cross_batch`], [`identify_cross_response`]: whole records.
//!
//! `simd` holds the two-lane (x and z) arithmetic the solves run on.

mod batch;
mod config;
mod convergence;
mod cross;
mod cross_estimate;
pub mod cross_solve;
mod error;
mod estimate;
mod identifier;
pub mod quadrature;
pub mod scaled_solve;
mod simd;
mod windows;

pub use batch::{
    identify_batch, identify_cross_batch, identify_cross_response, identify_response, measurement,
};
pub use config::{
    AlgebraicConfig, SpeedModel, DEFAULT_ALGEBRAIC_RCOND_MIN, DEFAULT_CROSS_ALGEBRAIC_RCOND_MIN,
};
pub use convergence::{
    ConvergenceTracker, ParameterConvergence, DEFAULT_STACK_CAPACITY, DEFAULT_TOLERANCE,
};
pub use cross::CrossAlgebraicIdentifier;
pub use cross_estimate::{CrossAlgebraicEstimate, CrossDirectionEstimate};
pub use cross_solve::{solve_scaled5, ScaledSolution5};
pub use error::AlgebraicError;
pub use estimate::{AlgebraicEstimate, DirectionEstimate};
pub use identifier::AlgebraicIdentifier;
pub use quadrature::{Quadrature, RunningIntegrals, LEVELS};
pub use scaled_solve::{solve_scaled, ScaledSolution};
pub use windows::{Restartable, RestartingIdentifier, WindowedEstimate, MIN_RESTART_SAMPLES};
