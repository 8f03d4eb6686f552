//! Closed-form steady-state response at constant speed W (the oracle the integrators are
//! tested against). With th = W t + phi0 + alpha and w' = 0, the unbalance force of eq. (1)
//! (docs/method.md section 1.2) is
//!
//! ```text
//! F(t) = Re( F^ e^{i th} ),   F^ = mud W^2 (-i, 1)        (x: sin th, z: cos th)
//! ```
//!
//! and the particular (steady-state) solution of `M q'' + (C1 + W C2) q' + K1 q = F` is
//!
//! ```text
//! q_ss(t) = Re( Q^ e^{i th} ),   D Q^ = F^,   D = K1 - W^2 M + i W (C1 + W C2)   (complex 2x2)
//! q_ss'(t) = Re( i W Q^ e^{i th} )
//! ```
//!
//! with C1 = diag(cx, cz), C2 = [[0, -a], [a, 0]], K1 = diag(kx, kz). D is singular only
//! for an undamped rotor exactly at a whirl frequency; then no bounded steady state exists
//! and [`SteadyState::is_bounded`] is false. Reference: M. Lalanne & G. Ferraris,
//! *Rotordynamics prediction in engineering*, 2nd ed., Wiley, 1998 (unbalance response
//! of the simple rotor).

use nalgebra::{Complex, Matrix2, Vector2};

use crate::model::Rotor;

/// The complex amplitudes of the steady-state response at constant speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SteadyState {
    /// The speed W \[rad/s\].
    pub omega: f64,
    /// The unbalance angle alpha \[rad\] (th = W t + phi0 + alpha).
    pub alpha: f64,
    /// Q^ = (Q^_x, Q^_z) \[m\]: x_ss(t) = Re(Q^_x e^{i th}), z_ss likewise. Non-finite when
    /// there is no bounded steady state (see [`SteadyState::is_bounded`]).
    pub q: Vector2<Complex<f64>>,
}

/// The steady-state response of `rotor` at the constant speed `omega` \[rad/s\].
pub fn steady_state(rotor: &Rotor, omega: f64) -> SteadyState {
    let w = omega;
    let u = rotor.unbalance();
    let re = rotor.stiffness_matrix(0.0) - rotor.mass_matrix() * (w * w);
    let im = rotor.damping_matrix(w) * w;
    let d: Matrix2<Complex<f64>> = Matrix2::from_fn(|i, j| Complex::new(re[(i, j)], im[(i, j)]));
    let fa = u.mud() * w * w;
    let f = Vector2::new(Complex::new(0.0, -fa), Complex::new(fa, 0.0));
    // Cramer's rule on the complex 2x2 system D Q^ = F^.
    let det = d[(0, 0)] * d[(1, 1)] - d[(0, 1)] * d[(1, 0)];
    let qx = (f[0] * d[(1, 1)] - d[(0, 1)] * f[1]) / det;
    let qz = (d[(0, 0)] * f[1] - f[0] * d[(1, 0)]) / det;
    let q = if det == Complex::new(0.0, 0.0) {
        let inf = Complex::new(f64::INFINITY, f64::INFINITY);
        Vector2::new(inf, inf)
    } else {
        Vector2::new(qx, qz)
    };
    SteadyState {
        omega,
        alpha: u.alpha,
        q,
    }
}

impl SteadyState {
    /// True when Q^ is finite (false only for an undamped rotor at a whirl frequency, or a
    /// non-finite speed).
    pub fn is_bounded(&self) -> bool {
        self.q.iter().all(|c| c.re.is_finite() && c.im.is_finite())
    }

    /// Amplitudes (|Q^_x|, |Q^_z|) \[m\].
    pub fn amplitude(&self) -> Vector2<f64> {
        self.q.map(|c| c.norm())
    }

    /// Phases (arg Q^_x, arg Q^_z) \[rad\], in (-pi, pi]: x_ss = |Q^_x| cos(th + arg Q^_x).
    pub fn phase(&self) -> Vector2<f64> {
        self.q.map(|c| c.arg())
    }

    /// e^{i th}, th = W t + phi0 + alpha.
    fn rotor_phasor(&self, t: f64, phi0: f64) -> Complex<f64> {
        let (s, c) = (self.omega * t + phi0 + self.alpha).sin_cos();
        Complex::new(c, s)
    }

    /// q_ss(t) = Re(Q^ e^{i th}) \[m\], for a rotor at angle phi0 \[rad\] at t = 0.
    pub fn displacement(&self, t: f64, phi0: f64) -> Vector2<f64> {
        let e = self.rotor_phasor(t, phi0);
        self.q.map(|c| (c * e).re)
    }

    /// q_ss'(t) = Re(i W Q^ e^{i th}) \[m/s\], for a rotor at angle phi0 \[rad\] at t = 0.
    pub fn velocity(&self, t: f64, phi0: f64) -> Vector2<f64> {
        let e = self.rotor_phasor(t, phi0) * Complex::new(0.0, self.omega);
        self.q.map(|c| (c * e).re)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{SpeedProfile, SpeedState};

    /// Residual of eq. (1) for the steady state, assembled from the rotor's own M, C, K and
    /// force (not from D), relative to the force; and q_ss' against a central difference.
    #[test]
    fn satisfies_the_equation_of_motion() {
        let r = Rotor::table1();
        let w = 125.66370614359172;
        let ss = steady_state(&r, w);
        assert!(ss.is_bounded());
        let phi0 = 0.4;
        let sp = SpeedProfile::Constant { omega: w, phi0 };
        for &t in &[0.0, 0.013, 0.37] {
            // q'' = Re(-W^2 Q^ e^{i th}) exactly
            let q = ss.displacement(t, phi0);
            let qd = ss.velocity(t, phi0);
            let qdd = -ss.displacement(t, phi0) * (w * w);
            let s: SpeedState = sp.at(t);
            let res =
                r.mass_matrix() * qdd + r.damping_matrix(w) * qd + r.stiffness_matrix(0.0) * q
                    - r.unbalance_force(&s);
            assert!(res.norm() < 1e-12 * r.unbalance_force(&s).norm(), "{res}");
            // the velocity is the derivative of the displacement
            let h = 1e-6;
            let fd = (ss.displacement(t + h, phi0) - ss.displacement(t - h, phi0)) / (2.0 * h);
            assert!((fd - qd).norm() < 1e-8 * qd.norm());
        }
    }

    #[test]
    fn isotropic_rotor_without_gyroscopic_term_matches_the_textbook_formula() {
        // a = 0, kx = kz = k, cx = cz = c: each direction is m q'' + c q' + k q = mud W^2 (.)
        // with amplitude mud W^2 / sqrt((k - m W^2)^2 + (c W)^2).
        let mut p = Rotor::table1().params();
        p.a = 0.0;
        let r = Rotor::new(p).unwrap();
        let w = 200.0;
        let ss = steady_state(&r, w);
        let expect =
            p.unbalance.mud() * w * w / ((p.kx - p.m * w * w).powi(2) + (p.cx * w).powi(2)).sqrt();
        let amp = ss.amplitude();
        assert!((amp[0] / expect - 1.0).abs() < 1e-14);
        assert!((amp[1] / expect - 1.0).abs() < 1e-14);
        // below resonance the response lags the force by atan(c W / (k - m W^2)):
        // x force is sin th = cos(th - pi/2)
        let lag = (p.cx * w).atan2(p.kx - p.m * w * w);
        let ph = ss.phase();
        assert!((ph[0] - (-std::f64::consts::FRAC_PI_2 - lag)).abs() < 1e-14);
        assert!((ph[1] - (-lag)).abs() < 1e-14);
    }

    #[test]
    fn undamped_resonance_has_no_bounded_steady_state() {
        let mut p = Rotor::table1().params();
        p.a = 0.0;
        p.cx = 0.0;
        p.cz = 0.0;
        let r = Rotor::new(p).unwrap();
        let wn = (p.kx / p.m).sqrt();
        // D is exactly singular only if k - m wn^2 rounds to 0; either way the response
        // there is unbounded or enormous
        let ss = steady_state(&r, wn);
        let exact_zero = p.kx - p.m * wn * wn == 0.0;
        assert_eq!(ss.is_bounded(), !exact_zero);
        assert!(ss.amplitude()[0] > 1e3 * p.unbalance.mud() / p.m);
        assert!(!steady_state(&r, f64::NAN).is_bounded());
    }
}
