//! Algebraic identification of m, c, k per direction (Barredo et al. 2024, eqs. 2-8;
//! method.md sections 2-5), streaming and batch.
//!
//! Multiplying eq. (1) by tau^2 = (t - t_0)^2 and integrating twice removes the unknown
//! initial displacement and velocity (`I2[tau^2 y''] = tau^2 y - 4 I1[tau y] + 2 I2[y]`,
//! `I2[tau^2 y'] = I1[tau^2 y] - 2 I2[tau y]`); integrating the resulting scalar equation
//! p(t) . theta = s(t) once and twice more gives the 3x3 system A(t) theta = b(t) solved at
//! every sample:
//!
//! - [`quadrature`]: the running iterated integrals I1..I4 and their rules ([`Quadrature`]).
//! - [`AlgebraicIdentifier`]: signals, assembly, one estimate per [`Measurement`], general
//!   (variable speed) or constant-speed ([`SpeedModel`]).
//! - [`system`]: scaling, solution and conditioning (rcond) of the 3x3 system.
//! - [`ConvergenceTracker`]: final values and identification times in bounded memory.
//! - [`identify_batch`], [`identify_response`]: whole records.

mod batch;
mod config;
mod convergence;
mod error;
mod estimate;
mod identifier;
mod inputs;
mod lanes;
pub mod quadrature;
pub mod system;
mod trig;

pub use batch::{identify_batch, identify_response, measurement};
pub use config::{IdentifierConfig, SpeedModel, DEFAULT_RCOND_MIN};
pub use convergence::{
    ConvergenceTracker, Parameter, ParameterConvergence, DEFAULT_STACK_CAPACITY, DEFAULT_TOLERANCE,
};
pub use error::IdentifyError;
pub use estimate::{DirectionEstimate, Estimate};
pub use identifier::{AlgebraicIdentifier, SAMPLING_TOLERANCE};
pub use inputs::{Known, Measurement};
pub use quadrature::{Quadrature, RunningIntegrals, LEVELS};
pub use system::{solve_scaled, ScaledSolution};
pub mod modulating;
