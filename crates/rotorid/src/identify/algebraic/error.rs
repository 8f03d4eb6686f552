//! Errors of the algebraic identifier: those of its inputs ([`InputError`]) and an unknown
//! quadrature name. A singular or ill-conditioned system is NOT an error (the estimate is
//! NaN / flagged).

use crate::identify::InputError;
use crate::model::OutOfRange;

/// Why the algebraic identifier could not be built or could not take a measurement.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AlgebraicError {
    /// A configuration value, known quantity or sample the identifier cannot take.
    #[error(transparent)]
    Input(#[from] InputError),
    /// A quadrature name that is not known.
    #[error("unknown quadrature {name:?}: expected \"trapezoid\", \"am3\", \"am4\" or \"am5\"")]
    UnknownQuadrature {
        /// The name as given.
        name: String,
    },
    /// A restart period the overlapping windows cannot use.
    #[error(
        "restart period of {samples} samples: it must be even and at least {min} samples \
         (two half-periods of two samples each)"
    )]
    RestartPeriod {
        /// The period asked for \[samples\].
        samples: u64,
        /// The shortest allowed \[samples\].
        min: u64,
    },
}

impl From<OutOfRange> for AlgebraicError {
    fn from(e: OutOfRange) -> Self {
        Self::Input(e.into())
    }
}
