//! Errors of the analysis: each names the offending input, its value and what is allowed,
//! so a user can fix the input without reading code. A quantity that is undefined for a
//! valid input (a double eigenvalue has no whirl direction, an undamped rotor has no
//! bounded response at resonance, a parameter the data did not determine has no standard
//! deviation) is *not* an error: it is an `Option` in the result.

use crate::model::{check, OutOfRange, RotorParams};

/// An input to the analysis that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AnalysisError {
    /// A scalar input (a rotor parameter, a speed, a radius, a trial mass) is outside its
    /// allowed range (this includes NaN and infinity).
    #[error(transparent)]
    OutOfRange(#[from] OutOfRange),
    /// An input of balancing that cannot be used (a run, sensor, plane, speed or option).
    #[error(transparent)]
    Balance(#[from] super::balance::BalanceError),
    /// A finite-element rotor's parameter or degree of freedom that is not the rotor's (e.g.
    /// a covariance naming `bearing3.kxx` on a rotor of two bearings).
    #[error(transparent)]
    FiniteElement(#[from] crate::model::finite_element::FiniteElementError),
    /// A covariance names a parameter the analysis does not know.
    #[error("unknown parameter {name:?} in the covariance: expected names from {allowed}")]
    UnknownParameter {
        /// The name as given.
        name: String,
        /// The accepted names.
        allowed: &'static str,
    },
    /// A covariance names one parameter twice.
    #[error("parameter {name:?} appears twice in the covariance: every name must be distinct")]
    DuplicateParameter {
        /// The repeated name.
        name: String,
    },
    /// A covariance matrix is not square with one row and one column per name.
    #[error("covariance row {row} has {len} entries but there are {expected} names: the matrix must be square, one row and one column per name")]
    NotSquare {
        /// Index of the offending row (or, for a wrong number of rows, the number of rows).
        row: usize,
        /// Its length (or the number of rows).
        len: usize,
        /// The number of names.
        expected: usize,
    },
    /// A variance (diagonal entry of a covariance) is negative.
    #[error("the variance of {name} is {value}: a variance must be >= 0 (or non-finite for an undetermined parameter)")]
    NegativeVariance {
        /// The parameter.
        name: String,
        /// Its diagonal entry.
        value: f64,
    },
    /// A covariance whose entries (i, j) and (j, i) differ.
    #[error("the covariance is not symmetric: its entry ({first}, {second}) is {upper} but ({second}, {first}) is {lower}")]
    NotSymmetric {
        /// The row parameter.
        first: String,
        /// The column parameter.
        second: String,
        /// Entry (first, second).
        upper: f64,
        /// Entry (second, first).
        lower: f64,
    },
    /// A covariance that is not positive semi-definite (it would give imaginary standard
    /// deviations).
    #[error("the covariance is not positive semi-definite: {detail}")]
    NotSemidefinite {
        /// Which correlation or direction, with its value.
        detail: String,
    },
    /// Two per-sample arrays that must have the same length do not.
    #[error(
        "{field} has {len} samples but {other} has {expected}: they must have the same length"
    )]
    LengthMismatch {
        /// The shorter or longer array.
        field: &'static str,
        /// Its length.
        len: usize,
        /// The array it is compared with.
        other: &'static str,
        /// That array's length.
        expected: usize,
    },
    /// Too few samples (or speeds) for the computation.
    #[error("{field} has {len} entries: at least {needed} are needed")]
    TooFew {
        /// The array.
        field: &'static str,
        /// Its length.
        len: usize,
        /// The minimum accepted.
        needed: usize,
    },
    /// A sample is NaN or infinite.
    #[error("{field}[{index}] = {value} is not finite: every sample must be a finite number")]
    NonFinite {
        /// The array.
        field: &'static str,
        /// Index of the first offending sample.
        index: usize,
        /// Its value.
        value: f64,
    },
    /// A speed grid that does not increase strictly.
    #[error(
        "speeds must increase strictly: speed[{index}] = {value} rad/s follows {previous} rad/s"
    )]
    NotIncreasing {
        /// Index of the offending speed.
        index: usize,
        /// Its value \[rad/s\].
        value: f64,
        /// The speed before it \[rad/s\].
        previous: f64,
    },
}

/// Check the parameters the analysis uses: m > 0, kx, kz > 0, everything else (the
/// cross-coupled coefficients included) finite.
/// Damping may be negative: an identified damping that came out below zero is analysed
/// (and reported unstable) rather than rejected.
pub(crate) fn check_params(p: &RotorParams) -> Result<(), AnalysisError> {
    check("m", p.m, "finite and > 0 (kg)", |v| v > 0.0)?;
    check("cx", p.cx, "finite (N s/m)", |_| true)?;
    check("kx", p.kx, "finite and > 0 (N/m)", |v| v > 0.0)?;
    check("cz", p.cz, "finite (N s/m)", |_| true)?;
    check("kz", p.kz, "finite and > 0 (N/m)", |v| v > 0.0)?;
    check("a", p.a, "finite (N s^2/m)", |_| true)?;
    check("m_u", p.unbalance.m_u, "finite (kg)", |_| true)?;
    check("d", p.unbalance.d, "finite (m)", |_| true)?;
    check("alpha", p.unbalance.alpha, "finite (rad)", |_| true)?;
    if let Some(c) = p.coupling {
        check("cxz", c.cxz, "finite (N s/m)", |_| true)?;
        check("czx", c.czx, "finite (N s/m)", |_| true)?;
        check("kxz", c.kxz, "finite (N/m)", |_| true)?;
        check("kzx", c.kzx, "finite (N/m)", |_| true)?;
    }
    Ok(())
}

/// Check one speed: finite and >= 0 \[rad/s\].
pub(crate) fn check_speed(omega: f64) -> Result<f64, AnalysisError> {
    Ok(check("speed", omega, "finite and >= 0 (rad/s)", |v| {
        v >= 0.0
    })?)
}

/// Check a speed grid: at least `needed` speeds, each finite and >= 0, strictly increasing.
pub(crate) fn check_speeds(speeds: &[f64], needed: usize) -> Result<(), AnalysisError> {
    if speeds.len() < needed {
        return Err(AnalysisError::TooFew {
            field: "speeds",
            len: speeds.len(),
            needed,
        });
    }
    for (i, &w) in speeds.iter().enumerate() {
        check_speed(w)?;
        if i > 0 && w <= speeds[i - 1] {
            return Err(AnalysisError::NotIncreasing {
                index: i,
                value: w,
                previous: speeds[i - 1],
            });
        }
    }
    Ok(())
}

/// The first non-finite entry of `v`, as [`AnalysisError::NonFinite`].
pub(crate) fn check_finite(field: &'static str, v: &[f64]) -> Result<(), AnalysisError> {
    match v.iter().position(|s| !s.is_finite()) {
        Some(index) => Err(AnalysisError::NonFinite {
            field,
            index,
            value: v[index],
        }),
        None => Ok(()),
    }
}
