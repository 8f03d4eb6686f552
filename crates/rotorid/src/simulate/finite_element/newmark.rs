//! Newmark's average-acceleration integrator (gamma = 1/2, beta = 1/4) for a
//! finite-element rotor, any speed profile: the reference on the full model (the same
//! scheme as the Jeffcott `Newmark`, in n dimensions). With u, v, a at t_n and C, K, F
//! at t_{n+1}:
//!
//! ```text
//! S a_{n+1} = F_{n+1} - C_{n+1} (v_n + dt/2 a_n) - K_{n+1} (u_n + dt v_n + dt^2/4 a_n)
//! S = M + dt/2 C_{n+1} + dt^2/4 K_{n+1}
//! u_{n+1} = u_n + dt v_n + dt^2/4 (a_n + a_{n+1}),   v_{n+1} = v_n + dt/2 (a_n + a_{n+1})
//! ```
//!
//! starting from `M a_0 = F_0 - C_0 v_0 - K_0 u_0`. Second order, unconditionally stable;
//! S is factorised (LU) again only when (w, w') change: once per run at constant speed,
//! every step on a ramp.

use nalgebra::{DMatrix, DVector, LU};

use super::super::error::{check_dt, check_speed, SimulateError};
use super::{finite_state, FeInitialState, FeIntegrator};
use crate::model::finite_element::{force_of, FeSystem};
use crate::model::{SpeedProfile, SpeedState};

/// Average-acceleration Newmark at a fixed step equal to the sampling period.
#[derive(Debug, Clone)]
pub struct FeNewmark {
    system: FeSystem,
    speed: SpeedProfile,
    dt: f64,
    n: u64,
    state: SpeedState,
    u: DVector<f64>,
    v: DVector<f64>,
    a: DVector<f64>,
    /// (w, w') and the LU of S at them.
    factor: Option<(f64, f64, LU<f64, nalgebra::Dyn, nalgebra::Dyn>)>,
}

fn singular(t: f64) -> SimulateError {
    SimulateError::NonFinite { t }
}

impl FeNewmark {
    /// Start at t = 0 from `initial` with step `dt` \[s\] (finite, > 0); the initial
    /// acceleration from the equation of motion at t = 0.
    pub fn new(
        system: &FeSystem,
        speed: &SpeedProfile,
        dt: f64,
        initial: &FeInitialState,
    ) -> Result<Self, SimulateError> {
        check_dt(dt)?;
        check_speed(speed)?;
        let (u, v) = initial.coordinates(system)?;
        let state = speed.at(0.0);
        let rhs = force_of(system.load(), &state)
            - system.damping(state.omega) * &v
            - system.stiffness(state.omega_dot) * &u;
        let a = system
            .mass()
            .clone()
            .lu()
            .solve(&rhs)
            .ok_or_else(|| singular(0.0))?;
        finite_state(&a, 0.0)?;
        Ok(Self {
            system: system.clone(),
            speed: *speed,
            dt,
            n: 0,
            state,
            u,
            v,
            a,
            factor: None,
        })
    }

    /// The current acceleration q_s'' in the system's coordinates.
    pub fn acceleration(&self) -> &DVector<f64> {
        &self.a
    }
}

impl FeIntegrator for FeNewmark {
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
        &self.u
    }
    fn v(&self) -> &DVector<f64> {
        &self.v
    }
    fn step(&mut self) -> Result<(), SimulateError> {
        let dt = self.dt;
        let (h1, h2) = (0.5 * dt, 0.25 * dt * dt);
        let n1 = self.n + 1;
        let t1 = n1 as f64 * dt;
        let s1 = self.speed.at(t1);
        let sys = &self.system;
        let c1 = sys.damping(s1.omega);
        let k1 = sys.stiffness(s1.omega_dot);
        let vp = &self.v + &self.a * h1;
        let up = &self.u + &self.v * dt + &self.a * h2;
        let rhs = force_of(sys.load(), &s1) - &c1 * &vp - &k1 * &up;
        let fresh =
            !matches!(&self.factor, Some((w, wd, _)) if (*w, *wd) == (s1.omega, s1.omega_dot));
        if fresh {
            let s: DMatrix<f64> = sys.mass() + c1 * h1 + k1 * h2;
            self.factor = Some((s1.omega, s1.omega_dot, s.lu()));
        }
        let lu = &self.factor.as_ref().expect("just set").2;
        let a1 = lu.solve(&rhs).ok_or_else(|| singular(t1))?;
        self.u = up + &a1 * h2;
        self.v = vp + &a1 * h1;
        self.a = a1;
        self.n = n1;
        self.state = s1;
        finite_state(&self.u, t1)
    }
}
