//! The transient-free (steady-state) initial state at constant speed, and the test of
//! whether a fitted free transient is significant.
//!
//! With the forcing oscillator z = (sin phi, cos phi), z' = Om z, Om = [[0, W], [-W, 0]],
//! the state obeys y' = A11 y + A12 z (blocks of the augmented matrix of `exact_step`).
//! The steady-state response is y_ss = P z with
//!
//! ```text
//! A11 P - P Om = -A12            (Sylvester equation, 8 unknowns; vec form
//!                                 (I2 (x) A11 - Om^T (x) I4) vec P = -vec A12)
//! ```
//!
//! and y_ss(0) = P (sin phi0, cos phi0). Any other initial state adds a free transient,
//! the only part of a constant-speed response that depends on m, c, k beyond the four
//! numbers of the steady state (amplitude and phase per channel). When the fitted
//! transient is not significant, the information the local Fisher matrix attributes to it
//! comes from fitted noise; the standard errors are then taken from the Fisher
//! information of the steady-state response alone (conservative).

use nalgebra::{SMatrix, SVector};

use super::exact_step::system_matrix;
use super::unknowns::Theta;

/// A fitted transient counts as significant when its initial-state offset from the
/// steady state is at least this many standard errors (Mahalanobis length): then the
/// information it carries is known to within ~20 %.
pub(crate) const TRANSIENT_SIGNIFICANCE: f64 = 10.0;

/// y_ss(0) for speed `w` \[rad/s\] and phi(0) = `phi0` \[rad\], or `None` when there is no
/// bounded steady state (undamped at a whirl frequency).
pub(crate) fn steady_initial_state(t: &Theta, w: f64, phi0: f64) -> Option<[f64; 4]> {
    let a = system_matrix(t, w);
    let om = [[0.0, w], [-w, 0.0]];
    let mut m = SMatrix::<f64, 8, 8>::zeros();
    let mut rhs = SVector::<f64, 8>::zeros();
    for c in 0..2 {
        for r in 0..4 {
            let row = r + 4 * c;
            for k in 0..4 {
                m[(row, k + 4 * c)] += a[(r, k)];
            }
            for (j, om_j) in om.iter().enumerate() {
                m[(row, r + 4 * j)] -= om_j[c];
            }
            rhs[row] = -a[(r, 4 + c)];
        }
    }
    let p = m.lu().solve(&rhs)?;
    if !p.iter().all(|v| v.is_finite()) {
        return None;
    }
    let (s0, c0) = phi0.sin_cos();
    let mut y = [0.0; 4];
    for (r, yr) in y.iter_mut().enumerate() {
        *yr = p[r] * s0 + p[r + 4] * c0;
    }
    Some(y)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{InitialState, Rotor, Scenario, SpeedProfile};
    use crate::simulate::steady_state;

    #[test]
    fn matches_the_closed_form_steady_state() {
        let rotor = Rotor::table1();
        let SpeedProfile::Constant { omega, .. } = Scenario::table1().speed else {
            unreachable!()
        };
        let phi0 = 0.7;
        let t = Theta::new(&rotor.params(), &InitialState::default());
        let y = steady_initial_state(&t, omega, phi0).unwrap();
        let ss = steady_state(&rotor, omega);
        let (q, v) = (ss.displacement(0.0, phi0), ss.velocity(0.0, phi0));
        let want = [q[0], q[1], v[0], v[1]];
        for i in 0..4 {
            let scale = if i < 2 { q.amax() } else { v.amax() };
            assert!(
                (y[i] - want[i]).abs() < 1e-12 * scale,
                "{i}: {} vs {}",
                y[i],
                want[i]
            );
        }
    }
}
