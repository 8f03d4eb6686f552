//! Are the speed columns consistent with each other? phi \[rad\], phi_dot \[rad/s\] and
//! phi_ddot \[rad/s^2\] given per sample must satisfy phi_dot = d(phi)/dt and phi_ddot =
//! d(phi_dot)/dt; a column in other units (rpm for rad/s, degrees for radians, rpm/s for
//! rad/s^2) breaks it by a constant factor, and the identifiers then produce confident
//! nonsense (docs/method.md section 6.4). Over the record, the factor is the least-squares
//! ratio
//!
//! ```text
//! f = sum (d_i * v_i) / sum (v_i^2),   d_i = (phi_i - phi_(i-1)) / dt (wrapped to (-pi, pi]),
//!                                      v_i = (phi_dot_i + phi_dot_(i-1)) / 2
//! ```
//!
//! (the trapezoid rule is exact to O(dt^2) for the derivative at the mid-point), and
//! likewise for phi_dot and phi_ddot where the acceleration is not negligible. A factor off
//! 1 by more than [`SPEED_FACTOR_TOLERANCE`] is reported with the unit slip it suggests.

use super::diagnostic::{Diagnostic, Finding};

/// Relative mismatch of a derivative above which the speed columns are inconsistent
/// (the trapezoid mid-point error on table1's ramps is ~1e-8).
pub const SPEED_FACTOR_TOLERANCE: f64 = 1e-3;

/// Running sums of the two ratios (module doc).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct SpeedConsistency {
    last: Option<(f64, f64, f64)>,
    dv: f64,
    vv: f64,
    aw: f64,
    ww: f64,
    /// sum of |phi_dot| and of |d(phi_dot)/dt| dt over the record, to judge whether the
    /// acceleration is measurable
    speed: f64,
    change: f64,
    /// sum of phi_dot times the profile's speed, and of the profile's speed squared
    cp: f64,
    pp: f64,
}

impl SpeedConsistency {
    /// The next sample's phi, phi_dot, phi_ddot, `dt` \[s\] after the previous.
    pub(crate) fn push(&mut self, phi: f64, omega: f64, omega_dot: f64, dt: f64) {
        if let Some((p, w, a)) = self.last {
            let mut dphi = phi - p;
            let tau = std::f64::consts::TAU;
            let turns = dphi / tau;
            // (round is a library call; within half a turn it gives 0 and changes nothing)
            if turns.abs() >= 0.5 {
                dphi -= tau * turns.round();
            }
            let d = dphi / dt;
            let v = 0.5 * (omega + w);
            self.dv += d * v;
            self.vv += v * v;
            let dw = (omega - w) / dt;
            let va = 0.5 * (omega_dot + a);
            self.aw += dw * va;
            self.ww += va * va;
            self.speed += v.abs();
            self.change += (omega - w).abs();
        }
        self.last = Some((phi, omega, omega_dot));
    }

    /// The speed `profile_omega` \[rad/s\] a profile (the scenario's) gives at the same
    /// sample, with the sample's `omega`, to compare the two.
    pub(crate) fn push_profile(&mut self, omega: f64, profile_omega: f64) {
        self.cp += omega * profile_omega;
        self.pp += profile_omega * profile_omega;
    }

    /// A warning when the data's speed and the profile's differ by more than 1 %.
    pub(crate) fn profile_finding(&self) -> Option<Diagnostic> {
        let f = self.cp / self.pp;
        (self.pp > 0.0 && f.is_finite() && (f - 1.0).abs() > 0.01)
            .then(|| Diagnostic::new(Finding::SpeedDiffersFromProfile { factor: f }))
    }

    /// The findings: each inconsistent column with its factor.
    pub(crate) fn findings(&self) -> Vec<Diagnostic> {
        let mut out = Vec::new();
        if self.vv > 0.0 {
            let f = self.dv / self.vv; // d(phi)/dt over phi_dot
            if (f - 1.0).abs() > SPEED_FACTOR_TOLERANCE && f.is_finite() {
                out.push(Diagnostic::new(Finding::SpeedInconsistent {
                    column: "phi_dot".to_owned(),
                    factor: 1.0 / f,
                    reference: "d(phi)/dt".to_owned(),
                }));
            }
        }
        // the acceleration is judged only where the speed changes measurably
        if self.ww > 0.0 && self.change > 1e-6 * self.speed {
            let f = self.aw / self.ww; // d(phi_dot)/dt over phi_ddot
            if (f - 1.0).abs() > SPEED_FACTOR_TOLERANCE && f.is_finite() {
                out.push(Diagnostic::new(Finding::SpeedInconsistent {
                    column: "phi_ddot".to_owned(),
                    factor: 1.0 / f,
                    reference: "d(phi_dot)/dt".to_owned(),
                }));
            }
        }
        out
    }
}
