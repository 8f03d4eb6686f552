//! Time-domain simulation of finite-element rotors (docs/finite_element.md
//! section 3), in full or reduced coordinates ([`FeSystem`]):
//!
//! ```text
//! M q'' + (C0 + w G) q' + (K0 + w' Ka) q = Re((w^2 - i w') P e^{i phi})
//! ```
//!
//! Three integrators ([`FeMethod`]), each producing sample i at t_i = i dt exactly from the
//! initial state at t_0 = 0 (rest by default):
//! - [`FeExactConstant`]: at constant speed, exact: the closed-form 1X steady state plus
//!   the homogeneous part advanced by the matrix exponential of the state matrix;
//! - [`FeNewmark`]: average-acceleration Newmark, second order, any speed profile (the
//!   reference on the full model, as the paper's integrator is for the Jeffcott rotor);
//! - [`FeMagnus`]: fourth-order Magnus exponential integrator of the system augmented
//!   with its forcing oscillators, any speed profile; exact at constant speed, and on a
//!   ramp fourth order (2.3e-11 of the response at 10 kHz on a 400 rad/s^2 run-up of the
//!   reduced two-disk rotor, `tests/it/fe_simulate.rs`): the integrator for the reduced
//!   model on run-ups.
//!
//! The output is the response at every degree of freedom or at a chosen list
//! ([`FeResponse`]: columns `t`, `<node>.<dof>` ..., `phi`, `phi_dot`, `phi_ddot`).

mod exact;
mod magnus;
mod newmark;

use std::fmt;
use std::str::FromStr;

use nalgebra::{DMatrix, DVector};
use serde::Serialize;

use super::error::SimulateError;
use crate::model::finite_element::{Dof, FeSystem};
use crate::model::{Sampling, SpeedProfile, SpeedState};

pub use exact::FeExactConstant;
pub use magnus::FeMagnus;
pub use newmark::FeNewmark;

/// The time integration method of a finite-element rotor.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
pub enum FeMethod {
    /// Average-acceleration Newmark, second order ([`FeNewmark`]).
    Newmark,
    /// Exact discretisation, constant speed only ([`FeExactConstant`]).
    Exact,
    /// Fourth-order Magnus exponential integrator, any speed profile ([`FeMagnus`]).
    Magnus,
}

impl fmt::Display for FeMethod {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            FeMethod::Newmark => "newmark",
            FeMethod::Exact => "exact",
            FeMethod::Magnus => "magnus",
        })
    }
}

impl FromStr for FeMethod {
    type Err = SimulateError;
    /// Parse `newmark`, `exact` or `magnus` (case-insensitive).
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "newmark" => Ok(FeMethod::Newmark),
            "exact" => Ok(FeMethod::Exact),
            "magnus" => Ok(FeMethod::Magnus),
            _ => Err(SimulateError::UnknownMethod {
                name: s.to_string(),
            }),
        }
    }
}

/// Displacements q0 \[m or rad\] and velocities v0 \[m/s or rad/s\] of every physical degree
/// of freedom at t = 0, in the order of the rotor's dofs. A reduced system starts from
/// their M-orthogonal projection on its basis (exact when they lie in it, as rest does).
#[derive(Debug, Clone, PartialEq)]
pub struct FeInitialState {
    /// q(0).
    pub q: DVector<f64>,
    /// q'(0).
    pub v: DVector<f64>,
}

impl FeInitialState {
    /// At rest: q = q' = 0 for `n` degrees of freedom.
    pub fn rest(n: usize) -> Self {
        Self {
            q: DVector::zeros(n),
            v: DVector::zeros(n),
        }
    }

    /// Checked against `system` (lengths, finite) and put in its coordinates.
    pub(crate) fn coordinates(
        &self,
        system: &FeSystem,
    ) -> Result<(DVector<f64>, DVector<f64>), SimulateError> {
        let n = system.dofs().len();
        for (what, x) in [("q0", &self.q), ("v0", &self.v)] {
            if x.len() != n {
                return Err(SimulateError::InitialStateLength {
                    what,
                    len: x.len(),
                    n,
                });
            }
            if let Some(i) = x.iter().position(|v| !v.is_finite()) {
                return Err(SimulateError::Model(
                    crate::model::ModelError::Inconsistent(format!(
                        "initial {what} at {} = {} is not finite: every entry must be finite \
                         (m or rad for q0, m/s or rad/s for v0)",
                        system.dofs()[i],
                        x[i]
                    )),
                ));
            }
        }
        Ok((
            system.to_coordinates(&self.q),
            system.to_coordinates(&self.v),
        ))
    }
}

/// A simulated finite-element record: one column per output degree of freedom (column
/// `<node>.<dof>`, m or rad), with t \[s\], phi \[rad\], phi' \[rad/s\], phi'' \[rad/s^2\].
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct FeResponse {
    /// The degrees of freedom of the columns of `q`, in order.
    #[serde(serialize_with = "names")]
    pub dofs: Vec<Dof>,
    /// Time t_i = i dt \[s\].
    pub t: Vec<f64>,
    /// q\[j\]\[i\]: degree of freedom `dofs[j]` at sample i \[m or rad\].
    pub q: Vec<Vec<f64>>,
    /// Rotor angle phi \[rad\].
    pub phi: Vec<f64>,
    /// Speed w = phi' \[rad/s\].
    pub phi_dot: Vec<f64>,
    /// Angular acceleration w' = phi'' \[rad/s^2\].
    pub phi_ddot: Vec<f64>,
}

fn names<S: serde::Serializer>(dofs: &[Dof], s: S) -> Result<S::Ok, S::Error> {
    s.collect_seq(dofs.iter().map(|d| d.to_string()))
}

impl FeResponse {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// True when there is no sample.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// The column of `dof`, if it was output.
    pub fn column(&self, dof: Dof) -> Option<&[f64]> {
        let j = self.dofs.iter().position(|&d| d == dof)?;
        Some(&self.q[j])
    }

    /// The table's column names: `t`, one `<node>.<dof>` per output, `phi`, `phi_dot`,
    /// `phi_ddot` (the order of the response files, docs/formats.md).
    pub fn header(&self) -> Vec<String> {
        let mut h = vec!["t".to_owned()];
        h.extend(self.dofs.iter().map(|d| d.to_string()));
        h.extend(["phi", "phi_dot", "phi_ddot"].map(str::to_owned));
        h
    }
}

/// A finite-element integrator positioned at a sample, in its system's coordinates.
pub trait FeIntegrator {
    /// The index i of the current sample (t = i dt).
    fn index(&self) -> u64;
    /// The sampling period dt \[s\].
    fn dt(&self) -> f64;
    /// The speed state at the current sample.
    fn speed(&self) -> SpeedState;
    /// The coordinates q_s at the current sample.
    fn q(&self) -> &DVector<f64>;
    /// Their velocities q_s'.
    fn v(&self) -> &DVector<f64>;
    /// Advance one sampling period.
    fn step(&mut self) -> Result<(), SimulateError>;
}

/// Simulate `system` over `sampling` with `method`, from `initial` (None: rest), giving
/// the response at `outputs` (None: every degree of freedom).
pub fn simulate_fe(
    system: &FeSystem,
    speed: &SpeedProfile,
    sampling: &Sampling,
    initial: Option<&FeInitialState>,
    outputs: Option<&[Dof]>,
    method: FeMethod,
) -> Result<FeResponse, SimulateError> {
    let rest = FeInitialState::rest(system.dofs().len());
    let initial = initial.unwrap_or(&rest);
    let dt = sampling.dt();
    let mut integ: Box<dyn FeIntegrator> = match method {
        FeMethod::Newmark => Box::new(FeNewmark::new(system, speed, dt, initial)?),
        FeMethod::Exact => Box::new(FeExactConstant::new(system, speed, dt, initial)?),
        FeMethod::Magnus => Box::new(FeMagnus::new(system, speed, dt, initial)?),
    };
    let dofs = outputs.unwrap_or(system.dofs()).to_vec();
    let map = system.output_map(&dofs)?;
    run_fe(integ.as_mut(), &map, dofs, sampling.samples())
}

/// Collect `samples` samples from `integ` (its current one and `samples - 1` steps),
/// mapping its coordinates by `map` (one row per entry of `dofs`).
pub fn run_fe(
    integ: &mut dyn FeIntegrator,
    map: &DMatrix<f64>,
    dofs: Vec<Dof>,
    samples: usize,
) -> Result<FeResponse, SimulateError> {
    let mut r = FeResponse {
        q: vec![Vec::with_capacity(samples); dofs.len()],
        dofs,
        t: Vec::with_capacity(samples),
        phi: Vec::with_capacity(samples),
        phi_dot: Vec::with_capacity(samples),
        phi_ddot: Vec::with_capacity(samples),
    };
    let dt = integ.dt();
    let mut y = DVector::zeros(map.nrows());
    for s in 0..samples {
        if s > 0 {
            integ.step()?;
        }
        let i = integ.index();
        let sp = integ.speed();
        map.mul_to(integ.q(), &mut y);
        r.t.push(i as f64 * dt);
        for (col, v) in r.q.iter_mut().zip(y.iter()) {
            col.push(*v);
        }
        r.phi.push(sp.phi);
        r.phi_dot.push(sp.omega);
        r.phi_ddot.push(sp.omega_dot);
    }
    Ok(r)
}

/// An error unless every entry of `x` is finite.
pub(crate) fn finite_state(x: &DVector<f64>, t: f64) -> Result<(), SimulateError> {
    if x.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(SimulateError::NonFinite { t })
    }
}
