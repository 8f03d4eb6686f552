//! The limits of the pipeline's plausibility check and the unit slips its speed-consistency
//! findings suggest: read by `plausibility` and by `diagnostic`'s messages, and depending
//! on neither (the findings' wording does not import the checks that raise them).

/// Largest plausible peak displacement of a probe channel \[m\].
pub const DISPLACEMENT_MAX_M: f64 = 0.01;
/// Smallest plausible peak displacement of a probe channel \[m\].
pub const DISPLACEMENT_MIN_M: f64 = 1e-9;
/// Largest plausible noise level over the channel's RMS.
pub const NOISE_TO_SIGNAL_MAX: f64 = 0.3;

/// The unit slip a factor suggests (`column` = factor x reference).
pub(crate) fn unit_slip_hint(factor: f64) -> &'static str {
    let near = |v: f64| (factor / v - 1.0).abs() < 0.01;
    if near(60.0 / std::f64::consts::TAU) {
        ": rpm given as rad/s (or rpm/s as rad/s^2)?"
    } else if near(std::f64::consts::TAU / 60.0) {
        ": the angle in rev or the speed in rad/s where rpm was meant?"
    } else if near(1.0 / std::f64::consts::TAU) {
        ": Hz given as rad/s?"
    } else if near(180.0 / std::f64::consts::PI) {
        ": degrees given as radians?"
    } else if near(std::f64::consts::PI / 180.0) {
        ": phi in degrees?"
    } else {
        ""
    }
}
