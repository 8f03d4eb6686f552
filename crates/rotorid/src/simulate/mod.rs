//! Time-domain simulation of the rotor of paper eq. (1) (docs/method.md sections 1 and 2):
//!
//! ```text
//! m x'' + cx x' - a w z' - a w' z + kx x = mud ( w^2 sin(phi+alpha) - w' cos(phi+alpha) )
//! m z'' + cz z' + a w x'          + kz z = mud ( w' sin(phi+alpha) + w^2 cos(phi+alpha) )
//! ```
//!
//! i.e. `M q'' + C(w) q' + K(w') q = F(t)`, q = (x, z) \[m\], with the speed profile phi(t),
//! w = phi', w' = phi'' given (see [`crate::model`]).
//!
//! Two methods ([`Method`]):
//! - [`Method::Newmark`]: the paper's average-acceleration Newmark integrator
//!   ([`Newmark`], Newmark 1959), second order, error ~ (w dt)^2 / 12 in phase.
//! - [`Method::Exact`]: the reference, accurate to 1e-10 of the signal amplitude or better
//!   (measured <= 4e-13 at dt <= 0.5 ms, see `tests/simulate_exact.rs`): at constant speed the exact discretisation of the LTI system augmented with the
//!   forcing oscillator ([`ExactConstant`], matrix exponential: Van Loan 1978, Higham 2005);
//!   for any other speed profile the 8th-order Dormand-Prince integrator DOP853
//!   ([`DoPri8Reference`], Hairer, Nørsett & Wanner 1993) run at tight tolerance.
//!
//! Every integrator produces sample i at t_i = i * dt exactly (computed so, never by
//! accumulating dt), starting from t_0 = 0 with the scenario's initial state.
//!
//! Finite-element rotors have their own integrators and response table in
//! [`finite_element`] (the Jeffcott and cross-coupled path above is unchanged).
//!
//! Also here: [`add_noise`] (white Gaussian measurement noise at a given SNR, reproducible
//! from a seed) and [`steady_state()`] (the closed-form constant-speed steady state, the
//! oracle the tests check the integrators against).

mod error;
mod exact_constant;
pub mod finite_element;
mod newmark;
mod noise;
mod phase;
mod reference_dopri8;
mod steady_state;

use std::fmt;
use std::str::FromStr;

use serde::Serialize;

use crate::model::{Scenario, SpeedState};

pub use error::SimulateError;
pub use exact_constant::ExactConstant;
pub use newmark::Newmark;
pub use noise::{add_noise, add_noise_to, NoiseLevel};
pub use reference_dopri8::{DoPri8Reference, DEFAULT_TOLERANCE};
pub use steady_state::{steady_state, SteadyState};

/// The time integration method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum Method {
    /// Average-acceleration Newmark (gamma = 1/2, beta = 1/4), as in the paper.
    Newmark,
    /// Exact discretisation at constant speed, DoPri8 at tight tolerance otherwise
    /// (accurate to ~1e-10 of the signal amplitude).
    Exact,
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Method::Newmark => "newmark",
            Method::Exact => "exact",
        })
    }
}

impl FromStr for Method {
    type Err = SimulateError;
    /// Parse `newmark` or `exact` (case-insensitive).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "newmark" => Ok(Method::Newmark),
            "exact" => Ok(Method::Exact),
            _ => Err(SimulateError::UnknownMethod {
                name: s.to_string(),
            }),
        }
    }
}

/// The state of the rotor at one sampling instant.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Sample {
    /// Time t \[s\] (exactly `i as f64 * dt` for sample i).
    pub t: f64,
    /// Horizontal displacement x \[m\].
    pub x: f64,
    /// Vertical displacement z \[m\].
    pub z: f64,
    /// Horizontal velocity x' \[m/s\].
    pub vx: f64,
    /// Vertical velocity z' \[m/s\].
    pub vz: f64,
    /// Rotor angle phi \[rad\], speed w \[rad/s\] and acceleration w' \[rad/s^2\] at t.
    pub speed: SpeedState,
}

impl Sample {
    /// Sample `n` of a record sampled every `dt` \[s\]: t = n dt exactly (never accumulated),
    /// state (x, z, vx, vz) \[m, m, m/s, m/s\] and `speed` at that instant.
    #[inline]
    pub(crate) fn nth(n: u64, dt: f64, [x, z, vx, vz]: [f64; 4], speed: SpeedState) -> Self {
        Self {
            t: n as f64 * dt,
            x,
            z,
            vx,
            vz,
            speed,
        }
    }
}

/// A simulated record, one entry per sample (column-wise).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct TimeResponse {
    /// Time t_i = i dt \[s\].
    pub t: Vec<f64>,
    /// Horizontal displacement x \[m\].
    pub x: Vec<f64>,
    /// Vertical displacement z \[m\].
    pub z: Vec<f64>,
    /// Rotor angle phi \[rad\].
    pub phi: Vec<f64>,
    /// Speed w = phi' \[rad/s\].
    pub phi_dot: Vec<f64>,
    /// Angular acceleration w' = phi'' \[rad/s^2\].
    pub phi_ddot: Vec<f64>,
}

impl TimeResponse {
    /// An empty record with room for `n` samples.
    pub fn with_capacity(n: usize) -> Self {
        Self {
            t: Vec::with_capacity(n),
            x: Vec::with_capacity(n),
            z: Vec::with_capacity(n),
            phi: Vec::with_capacity(n),
            phi_dot: Vec::with_capacity(n),
            phi_ddot: Vec::with_capacity(n),
        }
    }

    /// Number of samples (the length of `t`).
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// True when there is no sample.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// Append one sample (its velocities are not stored).
    pub fn push(&mut self, s: &Sample) {
        self.t.push(s.t);
        self.x.push(s.x);
        self.z.push(s.z);
        self.phi.push(s.speed.phi);
        self.phi_dot.push(s.speed.omega);
        self.phi_ddot.push(s.speed.omega_dot);
    }
}

/// A time integrator that produces one sample per sampling period, for streaming.
pub trait Integrator {
    /// The current sample (sample 0, the initial state, right after construction).
    fn current(&self) -> Sample;
    /// Advance one sampling period: from sample i to sample i + 1, at t = (i + 1) dt
    /// exactly, and return it.
    fn step(&mut self) -> Result<Sample, SimulateError>;
}

/// The integrator for `scenario` with `method`, positioned at sample 0 (t = 0, the
/// scenario's initial state). [`Method::Exact`] picks [`ExactConstant`] when the speed is
/// constant (including a ramp with zero acceleration) and [`DoPri8Reference`] otherwise.
pub fn integrator(
    scenario: &Scenario,
    method: Method,
) -> Result<Box<dyn Integrator>, SimulateError> {
    let (rotor, speed, dt, initial) = (
        &scenario.rotor,
        &scenario.speed,
        scenario.sampling.dt(),
        scenario.initial,
    );
    Ok(match method {
        Method::Newmark => Box::new(Newmark::new(rotor, speed, dt, initial)?),
        Method::Exact if speed.is_constant() => {
            Box::new(ExactConstant::new(rotor, speed, dt, initial)?)
        }
        Method::Exact => Box::new(DoPri8Reference::new(rotor, speed, dt, initial)?),
    })
}

/// Simulate the whole record: all `scenario.sampling.samples()` samples, t_0 = 0 to
/// t_N = N dt.
pub fn simulate(scenario: &Scenario, method: Method) -> Result<TimeResponse, SimulateError> {
    let mut integ = integrator(scenario, method)?;
    run(integ.as_mut(), scenario.sampling.samples())
}

/// Collect `samples` samples (the current one and `samples - 1` steps) from `integ`.
pub fn run(integ: &mut dyn Integrator, samples: usize) -> Result<TimeResponse, SimulateError> {
    let mut resp = TimeResponse::with_capacity(samples);
    if samples == 0 {
        return Ok(resp);
    }
    resp.push(&integ.current());
    for _ in 1..samples {
        resp.push(&integ.step()?);
    }
    Ok(resp)
}

/// Return `s` if its state is finite, else [`SimulateError::NonFinite`].
#[inline]
pub(crate) fn finite(s: Sample) -> Result<Sample, SimulateError> {
    if (s.x + s.z + s.vx + s.vz).is_finite() {
        Ok(s)
    } else {
        Err(SimulateError::NonFinite { t: s.t })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn method_names_round_trip() {
        for m in [Method::Newmark, Method::Exact] {
            assert_eq!(m.to_string().parse::<Method>().unwrap(), m);
        }
        assert_eq!(Method::Newmark.to_string(), "newmark");
        assert_eq!(Method::Exact.to_string(), "exact");
        let e = "rk4".parse::<Method>().unwrap_err();
        assert!(e.to_string().contains("\"rk4\""), "{e}");
    }

    #[test]
    fn non_finite_states_are_reported_with_their_time() {
        let mut s = Sample {
            t: 0.25,
            x: 0.0,
            z: 0.0,
            vx: 0.0,
            vz: 0.0,
            speed: SpeedState::default(),
        };
        assert!(finite(s).is_ok());
        for v in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            s.vz = v;
            match finite(s) {
                Err(SimulateError::NonFinite { t }) => assert_eq!(t, 0.25),
                other => panic!("{v}: {other:?}"),
            }
        }
    }

    #[test]
    fn push_keeps_columns_aligned() {
        let mut r = TimeResponse::with_capacity(2);
        assert!(r.is_empty());
        let s = Sample {
            t: 0.5,
            x: 1.0,
            z: 2.0,
            vx: 3.0,
            vz: 4.0,
            speed: SpeedState {
                phi: 5.0,
                omega: 6.0,
                omega_dot: 7.0,
            },
        };
        r.push(&s);
        assert_eq!(r.len(), 1);
        assert_eq!(
            (
                r.t[0],
                r.x[0],
                r.z[0],
                r.phi[0],
                r.phi_dot[0],
                r.phi_ddot[0]
            ),
            (0.5, 1.0, 2.0, 5.0, 6.0, 7.0)
        );
    }
}
