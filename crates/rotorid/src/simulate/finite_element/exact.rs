//! Exact discretisation of a finite-element rotor at constant speed W.
//!
//! With w = W, w' = 0 the equation is linear time-invariant with a harmonic force, and its
//! solution is the closed-form steady state plus a free motion:
//!
//! ```text
//! x(t) = x_p(t) + e^{A t} (x(0) - x_p(0)),      x = (q, q')
//! x_p(t) = (Re(Q e^{i phi(t)}), Re(i W Q e^{i phi(t)})),   (K0 - W^2 M + i W (C0 + W G)) Q = W^2 P
//! A = [[0, I], [-M^-1 K0, -M^-1 (C0 + W G)]]
//! ```
//!
//! so with Phi = expm(A dt) formed once (balanced, `crate::expm::exp_balanced`) the
//! deviation e_n = x_n - x_p(t_n) obeys e_{n+1} = Phi e_n exactly, and the step is one
//! matrix-vector product plus the particular solution at t_{n+1} (its phase phi(t_n)
//! evaluated at every step from the profile: no drift). The only errors are rounding.

use nalgebra::{Complex, DMatrix, DVector};

use super::super::error::{check_dt, check_speed, SimulateError};
use super::{finite_state, FeInitialState, FeIntegrator};
use crate::model::finite_element::FeSystem;
use crate::model::{check, SpeedProfile, SpeedState};

/// Exact discretisation at constant speed (module doc).
#[derive(Debug, Clone)]
pub struct FeExactConstant {
    speed: SpeedProfile,
    dt: f64,
    n: u64,
    state: SpeedState,
    /// expm(A dt) (2r x 2r).
    phi: DMatrix<f64>,
    /// The steady state Q and i W Q.
    qc: DVector<Complex<f64>>,
    vc: DVector<Complex<f64>>,
    /// e_n = x_n - x_p(t_n).
    e: DVector<f64>,
    e_next: DVector<f64>,
    q: DVector<f64>,
    v: DVector<f64>,
}

/// The constant speed W \[rad/s\] of `speed`, or an error if it accelerates.
pub(super) fn constant_omega(speed: &SpeedProfile) -> Result<f64, SimulateError> {
    match *speed {
        SpeedProfile::Constant { omega, .. } => Ok(omega),
        SpeedProfile::Ramp { omega0, accel, .. } => {
            check(
                "accel",
                accel,
                "0 for the exact constant-speed discretisation (rad/s^2); use Magnus or \
                 Newmark for a ramp",
                |v| v == 0.0,
            )?;
            Ok(omega0)
        }
    }
}

/// The state matrix [[0, I], [-M^-1 K, -M^-1 C]] of `M q'' + C q' + K q`.
pub(super) fn state_matrix(m: &DMatrix<f64>, c: &DMatrix<f64>, k: &DMatrix<f64>) -> DMatrix<f64> {
    let n = m.nrows();
    let lu = m.clone().lu();
    let mk = lu
        .solve(k)
        .unwrap_or_else(|| DMatrix::from_element(n, n, f64::NAN));
    let mc = lu
        .solve(c)
        .unwrap_or_else(|| DMatrix::from_element(n, n, f64::NAN));
    let mut a = DMatrix::zeros(2 * n, 2 * n);
    a.view_mut((0, n), (n, n)).fill_with_identity();
    a.view_mut((n, 0), (n, n)).copy_from(&(-mk));
    a.view_mut((n, n), (n, n)).copy_from(&(-mc));
    a
}

impl FeExactConstant {
    /// Start at t = 0 from `initial`, sampling period `dt` \[s\] (finite, > 0); `speed`
    /// must be constant.
    pub fn new(
        system: &FeSystem,
        speed: &SpeedProfile,
        dt: f64,
        initial: &FeInitialState,
    ) -> Result<Self, SimulateError> {
        check_dt(dt)?;
        check_speed(speed)?;
        let w = constant_omega(speed)?;
        let (q0, v0) = initial.coordinates(system)?;
        let n = system.len();
        let a = state_matrix(system.mass(), &system.damping(w), system.stiffness0());
        let phi = crate::expm::exp_balanced(&(a * dt));
        let qc = system.steady_state(w)?;
        let vc = qc.map(|z| z * Complex::new(0.0, w));
        let state = speed.at(0.0);
        let mut out = Self {
            speed: *speed,
            dt,
            n: 0,
            state,
            phi,
            qc,
            vc,
            e: DVector::zeros(2 * n),
            e_next: DVector::zeros(2 * n),
            q: q0,
            v: v0,
        };
        let (qp, vp) = out.particular(&state);
        out.e.rows_mut(0, n).copy_from(&(&out.q - qp));
        out.e.rows_mut(n, n).copy_from(&(&out.v - vp));
        finite_state(&out.e, 0.0)?;
        Ok(out)
    }

    /// x_p at `s`: (Re(Q e^{i phi}), Re(i W Q e^{i phi})).
    fn particular(&self, s: &SpeedState) -> (DVector<f64>, DVector<f64>) {
        let e = Complex::from_polar(1.0, s.phi);
        (self.qc.map(|z| (z * e).re), self.vc.map(|z| (z * e).re))
    }
}

impl FeIntegrator for FeExactConstant {
    fn index(&self) -> u64 {
        self.n
    }
    fn dt(&self) -> f64 {
        self.dt
    }
    fn speed(&self) -> SpeedState {
        self.state
    }
    fn q(&self) -> &DVector<f64> {
        &self.q
    }
    fn v(&self) -> &DVector<f64> {
        &self.v
    }
    fn step(&mut self) -> Result<(), SimulateError> {
        self.phi.mul_to(&self.e, &mut self.e_next);
        std::mem::swap(&mut self.e, &mut self.e_next);
        self.n += 1;
        self.state = self.speed.at(self.n as f64 * self.dt);
        let r = self.q.len();
        let e = Complex::from_polar(1.0, self.state.phi);
        for i in 0..r {
            self.q[i] = (self.qc[i] * e).re + self.e[i];
            self.v[i] = (self.vc[i] * e).re + self.e[r + i];
        }
        finite_state(&self.q, self.n as f64 * self.dt)
    }
}
