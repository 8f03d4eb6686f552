//! High-accuracy reference for any speed profile (ramps): the explicit Runge-Kutta method
//! of Dormand and Prince of order 8(5,3), DOP853 (E. Hairer, S. P. Nørsett, G. Wanner,
//! *Solving Ordinary Differential Equations I*, 2nd ed., Springer, 1993, ch. II), as
//! implemented by `russell_ode` (`Method::DoPri8`), at tight tolerance.
//!
//! Eq. (1) (docs/method.md section 1.2) as a first-order system, q = (x, z):
//!
//! ```text
//! q'  = v
//! v'  = M^-1 ( F(t) - C(w(t)) v - K(w'(t)) q )
//! F   = mud ( w^2 sin(phi+alpha) - w' cos(phi+alpha),  w' sin(phi+alpha) + w^2 cos(phi+alpha) )
//! ```
//!
//! with phi(t), w(t), w'(t) from the speed profile in closed form. The state (~1e-7 m) is
//! scaled before it meets the error control: the solver integrates
//! `y = (x / L, z / L, vx / (L w0), vz / (L w0))`, w0 = (kx kz)^(1/4) / sqrt(m),
//! L = max(mud / m, |x0|, |z0|, |vx0| / w0, |vz0| / w0) (mud / m is the amplitude the
//! unbalance response tends to above resonance), and the per-component error weight is
//! `tol + tol |y_i|` (atol = rtol = tol in scaled units).
//!
//! Output at t_i = i dt exactly: each [`Integrator::step`] integrates one sampling interval
//! [t_n, t_{n+1}] (t_n = n dt) with adaptive steps, starting from the step size the
//! previous interval suggested. This was measured against the alternative, one long
//! integration with DOP853's 7th-order dense output evaluated at the t_i (table1,
//! 1200 rpm, 1 s at 0.1 ms, deviation from the exact discretisation relative to the
//! amplitude):
//!
//! ```text
//! interval by interval, tol 1e-13:  7.7e-14   (1 step per interval)
//! dense output,         tol 1e-13:  6.3e-11   (1665 steps in all)
//! dense output,         tol 1e-14:  1.1e-11   (2220 steps)
//! ```
//!
//! The dense route is cheaper (docs/performance.md) but ~1000x less accurate, because at
//! the paper's 0.1 ms the interval caps the step well below what the tolerance allows; we
//! keep accuracy. When the sampling interval is long enough for the tolerance to set the
//! step, the global error is about 100 tol (test `simulate_reference.rs`: 1.0e-11 at tol
//! 1e-13 on a 10 ms grid); with 1 ms sampling it was 4.1e-12.

use russell_lab::Vector;
use russell_ode::{Method as RussellMethod, NoArgs, OdeSolver, Params, System};

use super::error::{check_dt, check_speed, SimulateError};
use super::{finite, Integrator, Sample};
use crate::model::{check, unbalance_force_from, InitialState, Rotor, SpeedProfile, SpeedState};

/// Default DoPri8 tolerance (relative, and absolute in scaled units; see the module doc).
pub const DEFAULT_TOLERANCE: f64 = 1e-13;

/// DOP853 reference integrator, one sampling interval per step.
pub struct DoPri8Reference {
    solver: OdeSolver<'static, NoArgs>,
    params: Params,
    /// Scaled state (x / L, z / L, vx / (L w0), vz / (L w0)).
    y: Vector,
    /// Length scale L \[m\].
    l: f64,
    /// Velocity scale L w0 \[m/s\].
    lv: f64,
    speed: SpeedProfile,
    dt: f64,
    n: u64,
    state: SpeedState,
    /// Accepted DoPri8 steps so far.
    steps: usize,
}

impl std::fmt::Debug for DoPri8Reference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("DoPri8Reference")
            .field("t", &self.current().t)
            .field("dt", &self.dt)
            .field("speed", &self.speed)
            .field("steps", &self.steps)
            .finish_non_exhaustive()
    }
}

impl DoPri8Reference {
    /// Start at t = 0 from `initial`, sampling period `dt` \[s\] (finite, >= 1e-12), with the
    /// default tolerance [`DEFAULT_TOLERANCE`].
    pub fn new(
        rotor: &Rotor,
        speed: &SpeedProfile,
        dt: f64,
        initial: InitialState,
    ) -> Result<Self, SimulateError> {
        Self::with_tolerance(rotor, speed, dt, initial, DEFAULT_TOLERANCE)
    }

    /// As [`DoPri8Reference::new`] with tolerance `tol` (finite, in [1e-14, 1e-2]).
    /// `dt` must also be >= 1e-12 s here (the solver treats shorter intervals as empty).
    pub fn with_tolerance(
        rotor: &Rotor,
        speed: &SpeedProfile,
        dt: f64,
        initial: InitialState,
        tol: f64,
    ) -> Result<Self, SimulateError> {
        check_dt(dt)?;
        // russell_ode treats an interval shorter than 10 eps as already done
        check(
            "dt",
            dt,
            "finite and >= 1e-12 (s) for the DoPri8 reference",
            |v| v >= 1e-12,
        )?;
        check_speed(speed)?;
        check("tolerance", tol, "finite, in [1e-14, 1e-2]", |v| {
            (1e-14..=1e-2).contains(&v)
        })?;
        let initial = initial.validated()?;

        let m = rotor.m();
        let w0 = (rotor.kx() * rotor.kz()).sqrt().sqrt() / m.sqrt();
        let l = [
            rotor.unbalance().mud() / m,
            initial.x.abs(),
            initial.z.abs(),
            initial.vx.abs() / w0,
            initial.vz.abs() / w0,
        ]
        .into_iter()
        .fold(0.0, f64::max);
        let l = if l > 0.0 { l } else { 1.0 };
        let lv = l * w0;

        let (r, sp) = (*rotor, *speed);
        let (mud, alpha) = (r.unbalance().mud(), r.unbalance().alpha);
        let c = r.cross();
        let system = System::new(
            4,
            move |f: &mut Vector, t: f64, y: &Vector, _: &mut NoArgs| {
                let s = sp.at(t);
                let (sn, cs) = (s.phi + alpha).sin_cos();
                let force = unbalance_force_from(mud, s.omega, s.omega_dot, sn, cs);
                let (x, z, vx, vz) = (l * y[0], l * y[1], lv * y[2], lv * y[3]);
                let (aw, awd) = (r.a() * s.omega, r.a() * s.omega_dot);
                // m x'' = Fx - cx x' - cxz z' + a w z' + a w' z - kx x - kxz z
                let ax = (force[0] - r.cx() * vx - c.cxz * vz + aw * vz + awd * z
                    - r.kx() * x
                    - c.kxz * z)
                    / m;
                // m z'' = Fz - czx x' - cz z' - a w x' - kzx x - kz z
                let az =
                    (force[1] - c.czx * vx - r.cz() * vz - aw * vx - c.kzx * x - r.kz() * z) / m;
                f[0] = w0 * y[2];
                f[1] = w0 * y[3];
                f[2] = ax / lv;
                f[3] = az / lv;
                Ok(())
            },
        );
        let mut params = Params::new(RussellMethod::DoPri8);
        params
            .set_tolerances(tol, tol, None)
            .map_err(|message| SimulateError::Integration {
                t0: 0.0,
                t1: 0.0,
                message,
            })?;
        params.step.h_ini = dt.max(1e-8);
        params.step.n_step_max = 10_000_000;
        let solver =
            OdeSolver::new(params, system).map_err(|message| SimulateError::Integration {
                t0: 0.0,
                t1: 0.0,
                message,
            })?;
        let y = Vector::from(&[
            initial.x / l,
            initial.z / l,
            initial.vx / lv,
            initial.vz / lv,
        ]);
        let out = Self {
            solver,
            params,
            y,
            l,
            lv,
            speed: *speed,
            dt,
            n: 0,
            state: speed.at(0.0),
            steps: 0,
        };
        finite(out.current())?;
        Ok(out)
    }

    /// The sampling period \[s\].
    pub fn dt(&self) -> f64 {
        self.dt
    }

    /// Number of accepted DoPri8 steps taken so far (work measure).
    pub fn accepted_steps(&self) -> usize {
        self.steps
    }
}

impl Integrator for DoPri8Reference {
    fn current(&self) -> Sample {
        // unscale (x / L, z / L, vx / (L w0), vz / (L w0))
        let (y, l, lv) = (&self.y, self.l, self.lv);
        Sample::nth(
            self.n,
            self.dt,
            [l * y[0], l * y[1], lv * y[2], lv * y[3]],
            self.state,
        )
    }

    fn step(&mut self) -> Result<Sample, SimulateError> {
        let t0 = self.n as f64 * self.dt;
        let t1 = (self.n + 1) as f64 * self.dt;
        let fail = |message| SimulateError::Integration { t0, t1, message };
        self.solver
            .solve(&mut self.y, t0, t1, None, &mut 0, None)
            .map_err(fail)?;
        let stats = self.solver.stats();
        self.steps += stats.n_accepted;
        // start the next interval from the step size this one suggested
        let h_next = stats.h_accepted;
        if h_next.is_finite() && h_next >= 1e-8 && h_next != self.params.step.h_ini {
            self.params.step.h_ini = h_next;
            self.solver.update_params(self.params).map_err(fail)?;
        }
        self.n += 1;
        self.state = self.speed.at(t1);
        finite(self.current())
    }
}
