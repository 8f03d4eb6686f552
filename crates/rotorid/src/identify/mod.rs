//! Identification of m, c, k per direction from a uniformly sampled record, by two methods
//! side by side, and what they share:
//!
//! - [`algebraic`]: the paper's algebraic identifier (Barredo et al. 2024): one estimate
//!   per sample from a 3x3 system of running iterated integrals (docs/method.md section 3).
//! - [`modulating`]: least squares over sliding windows of modulating-function equations,
//!   robust to noise (docs/method.md section 4).
//! - Both for the cross-coupled rotor too (m and the four bearing coefficients of each
//!   row, [`CROSS_NAMES`]): [`algebraic::CrossAlgebraicIdentifier`] (a 5x5 system from
//!   I1..I6, docs/method.md section 3.10) and [`modulating::CrossModulatingIdentifier`]
//!   (docs/method.md section 4.8).
//! - shared: the known quantities and one sample ([`Known`], [`Measurement`]), the errors
//!   in them ([`InputError`]), the sampling checks and a fast sin/cos.
//!
//! Most callers want [`crate::pipeline`], which reads a record, picks the method and
//! reports the result with its diagnostics.

pub mod algebraic;
mod coupled;
mod error;
mod inputs;
pub mod modulating;
pub(crate) mod sampling;
mod trig;

pub use coupled::{CROSS_NAMES, CROSS_UNITS};
pub use error::InputError;
pub use inputs::{Known, Measurement};
pub use sampling::SAMPLING_TOLERANCE;
