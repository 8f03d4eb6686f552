//! Errors of multi-plane balancing: each names the run, sensor, speed or plane at fault, the
//! value and what is allowed, so a user can fix the data without reading code.

use crate::model::OutOfRange;

/// An input to multi-plane balancing that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum BalanceError {
    /// A scalar input (a speed, a mass, a radius, a weight, a limit) is outside its range.
    #[error(transparent)]
    OutOfRange(#[from] OutOfRange),
    /// A name (run, sensor, plane) is empty.
    #[error("a {what} name is empty: every {what} needs a name")]
    EmptyName {
        /// `run`, `sensor` or `plane`.
        what: &'static str,
    },
    /// The run to balance has no 1X vector.
    #[error("run {run:?} has no 1X vector{at}: the runs with vectors are {known}")]
    UnknownRun {
        /// The run as given.
        run: String,
        /// ` at the speeds selected` when speeds were selected, else empty.
        at: &'static str,
        /// The runs that have vectors.
        known: String,
    },
    /// A calibration run (one with masses) has no 1X vector.
    #[error("calibration run {run:?} has masses but no 1X vector{at}: every run of the masses must have vectors")]
    CalibrationWithoutVectors {
        /// The run.
        run: String,
        /// ` at the speeds selected` when speeds were selected, else empty.
        at: &'static str,
    },
    /// A sensor is given in two units.
    #[error(
        "sensor {sensor:?} is in {first} and in {other}: one sensor must have one unit throughout"
    )]
    MixedUnits {
        /// The sensor.
        sensor: String,
        /// The unit of its first vector.
        first: String,
        /// The other unit.
        other: String,
    },
    /// Two vectors for one run, sensor and speed.
    #[error("run {run:?} has two 1X vectors of sensor {sensor:?} at {speed_rpm} rpm (speeds within 1 % are one speed): give one")]
    Duplicate {
        /// The run.
        run: String,
        /// The sensor.
        sensor: String,
        /// The speed group \[rev/min\].
        speed_rpm: f64,
    },
    /// A speed asked for has no vector.
    #[error("no 1X vector at {speed_rpm} rpm (within 1 %): the vectors are at {known} rpm")]
    NoSpeed {
        /// The speed asked for \[rev/min\].
        speed_rpm: f64,
        /// The speeds of the vectors.
        known: String,
    },
    /// A name given in an option is not in the data.
    #[error("{option} names {what} {name:?}, which the data do not have: the {what}s are {known}")]
    UnknownName {
        /// What the option sets (`limit`, `weight`, `radius`, `holes`, `planes`).
        option: &'static str,
        /// `sensor` or `plane`.
        what: &'static str,
        /// The name as given.
        name: String,
        /// The names the data have.
        known: String,
    },
    /// No calibration run, or too few to fit the influence coefficients.
    #[error("{runs} calibration run(s) with vectors of {sensor:?} at {speed_rpm} rpm for {planes} plane(s): at least {needed} are needed (the run as found and one with a mass on each plane)")]
    TooFewRuns {
        /// The sensor.
        sensor: String,
        /// The speed \[rev/min\].
        speed_rpm: f64,
        /// Calibration runs available.
        runs: usize,
        /// Planes fitted.
        planes: usize,
        /// Runs needed (planes + 1).
        needed: usize,
    },
    /// A plane never had a mass in the calibration runs.
    #[error("plane {plane:?} has no non-zero mass in any calibration run: its influence cannot be measured (add a run with a trial mass on it)")]
    PlaneWithoutMass {
        /// The plane.
        plane: String,
    },
    /// The calibration runs do not separate the planes' influences.
    #[error("the calibration runs with vectors of {sensor:?} at {speed_rpm} rpm ({runs}) do not determine the influence of each plane: the masses must differ from run to run independently on every plane (e.g. the run as found and one trial run per plane)")]
    Undetermined {
        /// The sensor.
        sensor: String,
        /// The speed \[rev/min\].
        speed_rpm: f64,
        /// The runs used.
        runs: String,
    },
    /// The correction is not determined (fewer independent vectors than planes).
    #[error("the current run's {keys} vector(s) (sensor and speed) cannot determine corrections on {planes} plane(s): {why}")]
    CorrectionUndetermined {
        /// Vectors of the current run used.
        keys: usize,
        /// Planes corrected.
        planes: usize,
        /// Why, in words.
        why: String,
    },
    /// The radius of a plane's correction is not known.
    #[error("plane {plane:?}: {why}; give the radius at which its correction is placed")]
    NoRadius {
        /// The plane.
        plane: String,
        /// Why it cannot be taken from the calibration masses.
        why: String,
    },
    /// A hole layout that cannot hold a correction.
    #[error("holes of plane {plane:?}: {message}")]
    Holes {
        /// The plane.
        plane: String,
        /// What is wrong and what is allowed.
        message: String,
    },
    /// The limits of the min-max correction cannot all be met.
    #[error("the limits cannot all be met: the best correction still exceeds them by a factor {factor:.3} (sensor {sensor:?} at {speed_rpm} rpm: {predicted:.4} against a limit of {limit}); raise the limits or add planes")]
    LimitsInfeasible {
        /// The smallest achievable max over the limited vectors of |residual| / limit.
        factor: f64,
        /// A sensor at that factor.
        sensor: String,
        /// Its speed \[rev/min\].
        speed_rpm: f64,
        /// Its predicted residual at that best correction \[sensor unit\].
        predicted: f64,
        /// Its limit \[sensor unit\].
        limit: f64,
    },
    /// The conic solver did not converge.
    #[error("the min-max solver (Clarabel) stopped with status {status}: {what}")]
    Solver {
        /// The solver's status.
        status: String,
        /// What was being solved.
        what: &'static str,
    },
    /// A trial cannot be planned.
    #[error("no trial for plane {plane:?}: {why}")]
    Plan {
        /// The plane.
        plane: String,
        /// Why.
        why: String,
    },
}

/// Check a value: finite and `ok`, else [`OutOfRange`] naming `field` and `allowed`.
pub(crate) fn check_value(
    field: &'static str,
    value: f64,
    allowed: &'static str,
    ok: impl Fn(f64) -> bool,
) -> Result<f64, BalanceError> {
    Ok(crate::model::check(field, value, allowed, ok)?)
}
