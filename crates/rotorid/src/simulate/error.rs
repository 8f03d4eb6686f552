//! Errors of the simulators and of the noise generator. Each variant carries the offending
//! value or instant, and its message states what is allowed, so a user can fix the input
//! without reading code.

use crate::model::{check, ModelError, OutOfRange};

/// Why a simulation (or adding noise to one) could not be done.
#[derive(Debug, thiserror::Error)]
pub enum SimulateError {
    /// A model input (rotor, speed profile, initial state) is invalid.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// A simulation input (e.g. `dt`, `snr_db`, `tolerance`) is outside its allowed range
    /// (this includes NaN and infinity).
    #[error(transparent)]
    OutOfRange(#[from] OutOfRange),
    /// The DoPri8 reference integrator (russell_ode) reported a failure on one sampling
    /// interval.
    #[error(
        "the DoPri8 reference integration failed between t = {t0} s and t = {t1} s: {message}"
    )]
    Integration {
        /// Start of the failed interval \[s\].
        t0: f64,
        /// End of the failed interval \[s\].
        t1: f64,
        /// The solver's message.
        message: &'static str,
    },
    /// The computed state stopped being finite (overflow: inputs of absurd magnitude).
    #[error("the response became non-finite at t = {t} s (overflow; check the magnitudes of the rotor parameters, speed and initial state)")]
    NonFinite {
        /// Time of the first non-finite sample \[s\].
        t: f64,
    },
    /// A channel that noise is to be added to has no samples.
    #[error("channel {channel} is empty: cannot compute its RMS to scale the noise")]
    EmptyChannel {
        /// `x` or `z`.
        channel: &'static str,
    },
    /// A channel that noise is to be added to holds a NaN or infinite value.
    #[error("channel {channel} holds a non-finite value at sample {index}: cannot scale the noise to its RMS")]
    NonFiniteChannel {
        /// `x` or `z`.
        channel: &'static str,
        /// Index of the first offending sample.
        index: usize,
    },
    /// A finite-element rotor or system that cannot be simulated as given.
    #[error(transparent)]
    FiniteElement(#[from] crate::model::finite_element::FiniteElementError),
    /// A finite-element initial state whose length is not the number of degrees of freedom.
    #[error(
        "initial {what} has {len} entries: must have one per degree of freedom of the rotor ({n})"
    )]
    InitialStateLength {
        /// `q0` (displacements, m or rad) or `v0` (velocities, m/s or rad/s).
        what: &'static str,
        /// Its length.
        len: usize,
        /// The rotor's number of degrees of freedom.
        n: usize,
    },
    /// A method name that is neither `newmark` nor `exact`.
    #[error("unknown simulation method {name:?}: expected \"newmark\" or \"exact\"")]
    UnknownMethod {
        /// The name as given.
        name: String,
    },
}

/// Validate a speed profile whose fields may have been set directly (they are public):
/// every field finite; a constant speed or a ramp's initial speed >= 0.
pub(crate) fn check_speed(speed: &crate::model::SpeedProfile) -> Result<(), SimulateError> {
    use crate::model::SpeedProfile;
    match *speed {
        SpeedProfile::Constant { omega, phi0 } => {
            check("omega", omega, "finite and >= 0 (rad/s)", |v| v >= 0.0)?;
            check("phi0", phi0, "finite (rad)", |_| true)?;
        }
        SpeedProfile::Ramp {
            omega0,
            accel,
            phi0,
        } => {
            check("omega0", omega0, "finite and >= 0 (rad/s)", |v| v >= 0.0)?;
            check("accel", accel, "finite (rad/s^2)", |_| true)?;
            check("phi0", phi0, "finite (rad)", |_| true)?;
        }
    }
    Ok(())
}

/// Validate a sampling period: finite and > 0 (s).
pub(crate) fn check_dt(dt: f64) -> Result<f64, SimulateError> {
    Ok(check("dt", dt, "finite and > 0 (s)", |v| v > 0.0)?)
}
