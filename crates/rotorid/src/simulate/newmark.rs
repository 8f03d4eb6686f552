//! Newmark's average-acceleration integrator (gamma = 1/2, beta = 1/4), as the paper uses
//! to simulate eq. (1). Reference: N. M. Newmark, "A method of computation for structural
//! dynamics", J. Eng. Mech. Div. ASCE 85 (EM3), 1959, 67-94; the "acceleration form" below
//! is the usual textbook one (e.g. M. Géradin & D. Rixen, *Mechanical Vibrations*, Wiley).
//!
//! With `M q'' + C(w) q' + K(w') q = F(t)`, q = (x, z), and u, v, a the displacement,
//! velocity and acceleration at t_n, the step to t_{n+1} = (n + 1) dt evaluates C, K and F
//! at t_{n+1} and solves the 2x2 system
//!
//! ```text
//! S a_{n+1} = F_{n+1} - C_{n+1} (v_n + dt/2 a_n) - K_{n+1} (u_n + dt v_n + dt^2/4 a_n),
//! S = M + dt/2 C_{n+1} + dt^2/4 K_{n+1}
//! u_{n+1} = u_n + dt v_n + dt^2/4 (a_n + a_{n+1})
//! v_{n+1} = v_n + dt/2 (a_n + a_{n+1})
//! ```
//!
//! and starts from `M a_0 = F_0 - C_0 v_0 - K_0 u_0` (the equation of motion at t = 0).
//! The scheme is unconditionally stable and second-order accurate; for an undamped
//! oscillator of frequency w it keeps the amplitude and lags the phase by about
//! (w dt)^2 / 12 per radian. S is solved by its explicit inverse: it is the sum of
//! diag(m + dt/2 c + dt^2/4 k) (positive) and a skew-like gyroscopic part, so
//!
//! ```text
//! det S = (m + dt/2 cx + dt^2/4 kx) (m + dt/2 cz + dt^2/4 kz) + (a dt/2)^2 w (w + dt/2 w') > 0
//! ```
//!
//! (the last term can only be negative for |w| < dt/2 |w'|, where it is negligible). Bearing
//! cross-coupling adds -(dt/2 cxz + dt^2/4 kxz)(dt/2 czx + dt^2/4 kzx) and cross products
//! with the gyroscopic terms, all of order dt^2 c or dt^4 k^2 against m^2: det S stays positive
//! for any bearing a rotor can have at a sampling rate that resolves it.
//! 1 / det S is recomputed only when (w, w') change, i.e. once per run at constant speed.
//!
//! The phase sin(phi + alpha), cos(phi + alpha) of the unbalance force comes from a
//! rotation recurrence re-synchronised exactly every 64 steps (see `phase.rs`: within
//! 2e-14 + 4 eps |phi| of the exact phase, i.e. < 3.1e-14 for 1 s at 1200 rpm, and
//! cheaper than `sin_cos`: docs/performance.md).

use nalgebra::Vector2;

use super::error::{check_dt, check_speed, SimulateError};
use super::phase::PhaseGenerator;
use super::{finite, Integrator, Sample};
use crate::model::{unbalance_force_from, InitialState, Rotor, SpeedProfile, SpeedState};

/// The paper's integrator: average-acceleration Newmark at a fixed step equal to the
/// sampling period.
#[derive(Debug, Clone)]
pub struct Newmark {
    rotor: Rotor,
    speed: SpeedProfile,
    /// Step = sampling period \[s\].
    dt: f64,
    /// Index of the current sample.
    n: u64,
    /// Speed state at the current sample.
    state: SpeedState,
    /// Displacement q_n \[m\].
    u: Vector2<f64>,
    /// Velocity q'_n \[m/s\].
    v: Vector2<f64>,
    /// Acceleration q''_n \[m/s^2\].
    a: Vector2<f64>,
    /// m + dt/2 cx + dt^2/4 kx and m + dt/2 cz + dt^2/4 kz: the diagonal of S.
    s_diag: (f64, f64),
    /// 1 / det S for the (w, w') it was computed at (reused while they do not change,
    /// i.e. for the whole run at constant speed or on a linear ramp's constant w').
    inv_det: (f64, f64, f64),
    /// (sin, cos) of phi(t_n) + alpha.
    phase: PhaseGenerator,
}

impl Newmark {
    /// Start at t = 0 from `initial`, with step `dt` \[s\] (finite, > 0). The initial
    /// acceleration comes from the equation of motion at t = 0.
    pub fn new(
        rotor: &Rotor,
        speed: &SpeedProfile,
        dt: f64,
        initial: InitialState,
    ) -> Result<Self, SimulateError> {
        check_dt(dt)?;
        check_speed(speed)?;
        let initial = initial.validated()?;
        let state = speed.at(0.0);
        let u = Vector2::new(initial.x, initial.z);
        let v = Vector2::new(initial.vx, initial.vz);
        // M a_0 = F_0 - C_0 v_0 - K_0 u_0
        let f = rotor.unbalance_force(&state);
        let a = (f
            - rotor.damping_matrix(state.omega) * v
            - rotor.stiffness_matrix(state.omega_dot) * u)
            / rotor.m();
        let (h1, h2) = (0.5 * dt, 0.25 * dt * dt);
        let s_diag = (
            rotor.m() + h1 * rotor.cx() + h2 * rotor.kx(),
            rotor.m() + h1 * rotor.cz() + h2 * rotor.kz(),
        );
        let out = Self {
            rotor: *rotor,
            speed: *speed,
            dt,
            n: 0,
            state,
            u,
            v,
            a,
            s_diag,
            inv_det: (f64::NAN, f64::NAN, f64::NAN),
            phase: PhaseGenerator::new(speed, rotor.unbalance().alpha, dt),
        };
        finite(out.current())?;
        Ok(out)
    }

    /// The sampling period \[s\].
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// The current acceleration (x'', z'') \[m/s^2\].
    pub fn acceleration(&self) -> Vector2<f64> {
        self.a
    }
}

impl Integrator for Newmark {
    fn current(&self) -> Sample {
        let (u, v) = (self.u, self.v);
        Sample::nth(self.n, self.dt, [u[0], u[1], v[0], v[1]], self.state)
    }

    #[inline]
    fn step(&mut self) -> Result<Sample, SimulateError> {
        let dt = self.dt;
        let (h1, h2) = (0.5 * dt, 0.25 * dt * dt);
        let n1 = self.n + 1;
        let s1 = self.speed.at(n1 as f64 * dt);
        let r = &self.rotor;
        let (aw, awd) = (r.a() * s1.omega, r.a() * s1.omega_dot);
        let (sn, cs) = self.phase.next();
        let f = unbalance_force_from(r.unbalance().mud(), s1.omega, s1.omega_dot, sn, cs);
        // predictors: v_n + dt/2 a_n and u_n + dt v_n + dt^2/4 a_n
        let (u, v, a) = (self.u, self.v, self.a);
        let vp = v + a * h1;
        let up = u + v * dt + a * h2;
        // rhs = F - C vp - K up,  C = [[cx, cxz - a w], [czx + a w, cz]],
        // K = [[kx, kxz - a w'], [kzx, kz]] (cross terms 0 for a Jeffcott rotor: then every
        // sum below is bit for bit the one without them)
        let c = r.cross();
        let r0 = f[0]
            - (r.cx() * vp[0] + (c.cxz - aw) * vp[1])
            - (r.kx() * up[0] + (c.kxz - awd) * up[1]);
        let r1 = f[1] - ((c.czx + aw) * vp[0] + r.cz() * vp[1]) - (c.kzx * up[0] + r.kz() * up[1]);
        // S = M + dt/2 C + dt^2/4 K = [[p, s01], [g, q]]: s01 = -(gw + h) + dt/2 cxz + dt^2/4 kxz,
        // g = gw + dt/2 czx + dt^2/4 kzx, gw = dt/2 a w, h = dt^2/4 a w'
        let (p, q) = self.s_diag;
        let (g, s01) = (
            h1 * aw + (h1 * c.czx + h2 * c.kzx),
            -(h1 * aw + h2 * awd) + (h1 * c.cxz + h2 * c.kxz),
        );
        if (s1.omega, s1.omega_dot) != (self.inv_det.0, self.inv_det.1) {
            // det S = p q + g (g + h) > 0 (module doc)
            self.inv_det = (s1.omega, s1.omega_dot, 1.0 / (p * q - s01 * g));
        }
        let inv_det = self.inv_det.2;
        // a_{n+1} = S^-1 rhs, S^-1 = [[q, g + h], [-g, p]] / det S
        let a1 = Vector2::new((q * r0 - s01 * r1) * inv_det, (p * r1 - g * r0) * inv_det);
        // u_{n+1} = up + dt^2/4 a_{n+1};  v_{n+1} = vp + dt/2 a_{n+1}
        self.u = up + a1 * h2;
        self.v = vp + a1 * h1;
        self.a = a1;
        self.n = n1;
        self.state = s1;
        finite(self.current())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rejects_bad_dt_and_speed() {
        let r = Rotor::table1();
        let sp = SpeedProfile::constant_rpm(1200.0, 0.0).unwrap();
        let e = Newmark::new(&r, &sp, -1.0, InitialState::default()).unwrap_err();
        assert_eq!(
            e.to_string(),
            "dt = -1 is out of range: must be finite and > 0 (s)"
        );
        assert!(Newmark::new(&r, &sp, f64::NAN, InitialState::default()).is_err());
        let bad = SpeedProfile::Constant {
            omega: f64::INFINITY,
            phi0: 0.0,
        };
        let e = Newmark::new(&r, &bad, 1e-4, InitialState::default()).unwrap_err();
        assert!(e.to_string().starts_with("omega = inf"), "{e}");
        let init = InitialState {
            x: f64::NAN,
            ..Default::default()
        };
        let e = Newmark::new(&r, &sp, 1e-4, init).unwrap_err();
        assert!(e.to_string().starts_with("x0 = NaN"), "{e}");
    }

    #[test]
    fn initial_acceleration_satisfies_the_equation_of_motion() {
        let r = Rotor::table1();
        let sp = SpeedProfile::ramp(600.0, 10.0, 0.3).unwrap();
        let init = InitialState {
            x: 1e-6,
            z: -2e-6,
            vx: 3e-4,
            vz: 1e-4,
        };
        let nm = Newmark::new(&r, &sp, 1e-4, init).unwrap();
        let s = sp.at(0.0);
        let q = Vector2::new(init.x, init.z);
        let qd = Vector2::new(init.vx, init.vz);
        let res = r.mass_matrix() * nm.acceleration()
            + r.damping_matrix(s.omega) * qd
            + r.stiffness_matrix(s.omega_dot) * q
            - r.unbalance_force(&s);
        assert!(res.norm() < 1e-12 * r.kx() * 1e-6, "{res}");
    }

    #[test]
    fn each_step_satisfies_the_newmark_relations() {
        // After a step, M a + C v + K u = F at t_{n+1} (the scheme enforces the equation of
        // motion at every step), and the update formulas hold. Anisotropic supports and a
        // non-zero start so that every term of C and K matters.
        let mut p = Rotor::table1().params();
        (p.cx, p.cz, p.kx, p.kz) = (30.0, 7.0, 0.9e6, 1.5e6);
        let r = Rotor::new(p).unwrap();
        let init = InitialState {
            x: 1e-7,
            z: -3e-7,
            vx: 2e-5,
            vz: 0.0,
        };
        let dt = 1e-4;
        for sp in [
            SpeedProfile::ramp(1200.0, 10.0, 0.0).unwrap(),
            SpeedProfile::ramp(3000.0, -400.0, 0.2).unwrap(),
            SpeedProfile::constant_rpm(2000.0, 1.0).unwrap(),
        ] {
            let mut nm = Newmark::new(&r, &sp, dt, init).unwrap();
            for _ in 0..50 {
                let (u0, v0, a0) = (nm.u, nm.v, nm.a);
                let s = nm.step().unwrap();
                let q = Vector2::new(s.x, s.z);
                let qd = Vector2::new(s.vx, s.vz);
                let st = sp.at(s.t);
                let res = r.mass_matrix() * nm.a
                    + r.damping_matrix(st.omega) * qd
                    + r.stiffness_matrix(st.omega_dot) * q
                    - r.unbalance_force(&st);
                let f_scale = r.unbalance_force(&st).norm();
                assert!(res.norm() < 1e-12 * f_scale, "{res}");
                let du = q - (u0 + v0 * dt + (a0 + nm.a) * (dt * dt / 4.0));
                let dv = qd - (v0 + (a0 + nm.a) * (dt / 2.0));
                assert!(du.norm() < 1e-15 * q.norm() + 1e-30, "{du}");
                assert!(dv.norm() < 1e-15 * qd.norm() + 1e-30, "{dv}");
            }
            assert_eq!(nm.current().t, 50.0 * dt);
        }
    }

    #[test]
    fn undamped_free_oscillation_keeps_amplitude_and_lags_phase_as_predicted() {
        // a = 0, c = 0, no unbalance: x'' + w^2 x = 0. Average acceleration conserves
        // energy exactly and its discrete frequency is w_d = (2/dt) atan(w dt / 2).
        let mut p = Rotor::table1().params();
        p.a = 0.0;
        p.cx = 0.0;
        p.cz = 0.0;
        p.unbalance.m_u = 0.0;
        let r = Rotor::new(p).unwrap();
        let sp = SpeedProfile::constant_rpm(0.0, 0.0).unwrap();
        let dt = 1e-4;
        let x0 = 1e-6;
        let init = InitialState {
            x: x0,
            ..Default::default()
        };
        let mut nm = Newmark::new(&r, &sp, dt, init).unwrap();
        let w = (p.kx / p.m).sqrt();
        let wd = 2.0 / dt * (w * dt / 2.0).atan();
        for _ in 0..5000 {
            let s = nm.step().unwrap();
            let expect = x0 * (wd * s.t).cos();
            assert!((s.x - expect).abs() < 1e-12 * x0, "t = {}", s.t);
            let energy = 0.5 * p.m * s.vx * s.vx + 0.5 * p.kx * s.x * s.x;
            assert!((energy / (0.5 * p.kx * x0 * x0) - 1.0).abs() < 1e-12);
        }
    }
}
