//! Maximum-likelihood (output-error) identification of the bearings and unbalances of a
//! finite-element rotor from the response at its measured degrees of freedom
//! (docs/finite_element.md section 6).
//!
//! **Model.** `M q'' + (C + C_b + w G) q' + (K + K_b + w' Ka) q = F` (see
//! [`crate::model::finite_element`]), reduced to a Ritz basis T (the lowest `modes` modes
//! at the current bearings plus static shapes at the bearing and unbalance nodes,
//! [`RitzBasis`]) and simulated at the record's samples exactly at constant speed and by
//! the fourth-order Magnus integrator on a ramp ([`crate::simulate::finite_element`]). The
//! basis is rebuilt at every accepted step, so it follows the bearings as they change;
//! the bias the reduction leaves at the estimate is measured (below).
//!
//! **Measurements.** y_c(t_i) = (C q)(t_i) + e_c,i for each measured degree of freedom c,
//! white Gaussian noise of unknown standard deviation sigma_c per channel (estimated from
//! the residuals). The fit minimises sum_c sum_i r_c,i^2 / sigma_c^2 by Gauss-Newton with
//! Levenberg-Marquardt damping.
//!
//! **Unknowns.** Any subset of the bearing coefficients and the unbalances
//! ([`FeParameter`]), plus, unless the record starts at rest ([`FeInitial::Rest`]), the
//! initial state in the reduced coordinates (2r nuisance parameters), plus, on request
//! ([`FeRefineOptions::offsets`]), one constant offset per channel (a conditioned raw
//! record keeps the mean of the motion over its revolutions in each probe's DC). Both
//! nuisances enter linearly and are solved for at every step (variable projection).
//!
//! **Sensitivities.** The response is linear in each unbalance's complex amplitude U_j =
//! mud_j e^{i alpha_j} and in the initial state: y = sum_j (Re U_j Y_j + Im U_j Y'_j) +
//! sum_k x0_k Z_k, with Y_j, Y'_j the responses to U_j = 1 and U_j = i from rest and Z_k the
//! free responses. So the unbalances' and the initial state's sensitivities are exact
//! (mud: Re(e^{i alpha}) Y + Im(e^{i alpha}) Y', alpha: -Im U Y + Re U Y'). The bearing
//! coefficients enter the matrices: their sensitivities are forward differences of the
//! simulation with a relative step of 1e-6 of the coefficient's scale (error ~1e-6 of the
//! sensitivity; the fitted optimum does not depend on it, only the search's path and the
//! standard errors at the 1e-6 level).
//!
//! **Cost.** One pass is 2 per unbalance + 1 per unknown bearing coefficient (+ 2r with
//! the initial state unknown) simulations of the reduced model. The fit runs first on
//! every `coarse`-th sample (the exact and Magnus steps have no stability limit, and the
//! model sampled every k-th sample is the model at those instants: no aliasing), then on
//! every sample until the step is below `tolerance` standard errors.
//!
//! **Diagnostics.** Standard errors from the Fisher information at the estimate; the
//! condition number of the unit-diagonal Fisher information (identifiability); each
//! channel's residual tests (Ljung-Box whiteness and level against the data's own noise
//! estimate, as for the other models); and the reduction's bias: the full model's response
//! at the estimate minus the reduced one, delta y, moves the estimate by about
//! F^-1 J^T W delta y, reported per parameter in standard errors.

mod evaluate;
mod result;
mod summary;

use nalgebra::{DMatrix, DVector};

use crate::model::finite_element::{
    FeParameter, FiniteElementError, FiniteElementRotor, RitzBasis,
};
use crate::model::{ModelError, SpeedProfile};
use crate::simulate::finite_element::{FeInitialState, FeResponse};
use crate::simulate::SimulateError;

pub use evaluate::FeProblem;
pub use result::{FeFittedValue, FeOffset, FeReduction, FeRefined, FeWarning};
pub use summary::{
    FeAdequacy, FeCovariance, FeInitialStateSummary, FeNoise, FeParameterSummary, FeRecordSummary,
    FeRotorSummary, FeSummary,
};

/// The initial state of a finite-element fit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FeInitial {
    /// The record starts at rest (q = q' = 0 at its first sample): known.
    Rest,
    /// Unknown: estimated in the reduced coordinates with the parameters.
    Estimated,
}

impl std::str::FromStr for FeInitial {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "rest" => Ok(Self::Rest),
            "estimated" | "estimate" => Ok(Self::Estimated),
            other => Err(format!(
                "initial state `{other}`: allowed `rest` (the record starts at rest) or \
                 `estimated` (the default: fitted with the parameters)"
            )),
        }
    }
}

/// Options of [`refine_fe`].
#[derive(Debug, Clone, PartialEq)]
pub struct FeRefineOptions {
    /// The parameters to estimate (the others keep the starting rotor's values).
    pub unknowns: Vec<FeParameter>,
    /// Initial state known (rest) or estimated.
    pub initial: FeInitial,
    /// Modes in the Ritz basis (with the static shapes). On the two-disk rotor of
    /// docs/finite_element.md (1 s run-up through two criticals, 40 dB) the reduction moves
    /// no estimate by more than 0.027 standard error with 4 modes, 6e-4 with 6 (the
    /// default), 3e-5 with 8; every fit measures its own ([`FeReduction`]).
    pub modes: usize,
    /// Most Levenberg-Marquardt trials in all.
    pub max_iterations: usize,
    /// Converged when every step is below this many standard errors.
    pub tolerance: f64,
    /// Decimation of the first stage (1: fit every sample from the start).
    pub coarse: usize,
    /// Simulate the full model once at the estimate to measure the reduction's bias.
    pub reduction_bias: bool,
    /// Estimate one constant offset per channel (data = response + offset + noise): for
    /// a record conditioned from raw probes without a rotor guess, whose channels keep the
    /// mean of the motion over the record's revolutions. Off by default.
    pub offsets: bool,
}

impl FeRefineOptions {
    /// The default unknowns for `rotor`: the direct coefficients of every bearing and every
    /// unbalance unknown, initial state estimated, 6 modes (at most the degrees of freedom).
    pub fn new(rotor: &FiniteElementRotor) -> Self {
        Self {
            unknowns: FeParameter::default_unknowns(rotor),
            initial: FeInitial::Estimated,
            modes: 6.min(rotor.matrices.n()),
            max_iterations: 80,
            tolerance: 1e-2,
            coarse: 8,
            reduction_bias: true,
            offsets: false,
        }
    }
}

/// Why a finite-element fit could not be made (bad input; an unidentifiable problem is
/// reported in the result instead).
#[derive(Debug, thiserror::Error)]
pub enum FeRefineError {
    /// The rotor, a parameter or the basis is invalid.
    #[error(transparent)]
    Model(#[from] FiniteElementError),
    /// A model input is out of range.
    #[error(transparent)]
    Scalar(#[from] ModelError),
    /// The simulation failed.
    #[error(transparent)]
    Simulate(#[from] SimulateError),
    /// The record is unusable.
    #[error("record: {0}")]
    Record(String),
    /// Nothing to estimate.
    #[error("no unknown selected: name bearing coefficients (bearing0.kxx, ..., the groups bearings, bearing<i>) or unbalances (unbalance<j>.mud, unbalance<j>.alpha, unbalances), or estimate the initial state")]
    NoUnknowns,
    /// Too few samples for the unknowns.
    #[error("the record has {samples} samples per channel for {unknowns} unknowns: at least {needed} are needed")]
    TooFewSamples {
        /// Samples per channel.
        samples: usize,
        /// Unknowns (parameters and initial state).
        unknowns: usize,
        /// The minimum.
        needed: usize,
    },
}

/// A record of a finite-element rotor: the measured degrees of freedom of `response`
/// (columns `dofs`, uniform times) and the speed profile over the record's time (t minus
/// its first stamp).
#[derive(Debug, Clone, Copy)]
pub struct FeData<'a> {
    /// The measurements (its `phi*` columns are not used: the speed is `speed`).
    pub response: &'a FeResponse,
    /// The speed profile from the record's first sample.
    pub speed: SpeedProfile,
}

impl FeData<'_> {
    /// The sampling period \[s\], checked: at least 2 samples, stamps on the uniform grid
    /// t0 + i dt within 0.3 dt (the samples are taken as on that grid: a reader checks the
    /// stamps against the user's tolerance first, as `rotorid identify` does), every value
    /// finite, every column as long as t.
    pub fn checked_dt(&self) -> Result<f64, FeRefineError> {
        let r = self.response;
        let n = r.t.len();
        if n < 2 {
            return Err(FeRefineError::Record(format!(
                "{n} sample(s): at least 2 are needed"
            )));
        }
        if r.dofs.is_empty() {
            return Err(FeRefineError::Record(
                "no measured degree of freedom: at least one `<node>.<dof>` column is needed"
                    .to_owned(),
            ));
        }
        let dt = (r.t[n - 1] - r.t[0]) / (n - 1) as f64;
        if !(dt.is_finite() && dt > 0.0) {
            return Err(FeRefineError::Record(format!(
                "times from {} to {} s: they must increase",
                r.t[0],
                r.t[n - 1]
            )));
        }
        for (i, &t) in r.t.iter().enumerate() {
            let dev = t - (r.t[0] + i as f64 * dt);
            if dev.abs().is_nan() || dev.abs() > 0.3 * dt {
                return Err(FeRefineError::Record(format!(
                    "t at sample {i} is {t} s, {dev:e} s from the uniform grid of dt = {dt} s: \
                     the finite-element fit needs uniform times (within 0.3 dt)"
                )));
            }
        }
        for (dof, col) in r.dofs.iter().zip(&r.q) {
            if col.len() != n {
                return Err(FeRefineError::Record(format!(
                    "column {dof} has {} samples, t has {n}",
                    col.len()
                )));
            }
            if let Some(i) = col.iter().position(|v| !v.is_finite()) {
                return Err(FeRefineError::Record(format!(
                    "column {dof} at sample {i} is {}: every value must be finite (m or rad)",
                    col[i]
                )));
            }
        }
        Ok(dt)
    }
}

/// The leading windows of the continuation (fractions of the record).
const WINDOWS: [f64; 6] = [0.2, 0.3, 0.45, 0.65, 0.85, 1.0];
/// Most trials of a coarse stage.
const STAGE_TRIALS: usize = 12;
/// Step tolerance of the coarse stages \[standard errors\].
const COARSE_TOLERANCE: f64 = 0.3;

/// Identify `options.unknowns` of `start` (its other values known) from `data` (module
/// doc).
pub fn refine_fe(
    data: &FeData,
    start: &FiniteElementRotor,
    options: &FeRefineOptions,
) -> Result<FeRefined, FeRefineError> {
    let dt = data.checked_dt()?;
    let problem = FeProblem::new(
        start,
        data.response.dofs.clone(),
        data.speed,
        dt,
        data.response.len(),
        options.unknowns.clone(),
        options.initial,
        options.modes,
    )?
    .with_offsets(options.offsets);
    let np = problem.unknowns().len();
    let nuisance = problem.nuisance();
    if np + nuisance == 0 {
        return Err(FeRefineError::NoUnknowns);
    }
    let needed = 10 * (np + nuisance);
    if data.response.len() < needed {
        return Err(FeRefineError::TooFewSamples {
            samples: data.response.len(),
            unknowns: np + nuisance,
            needed,
        });
    }
    let y: Vec<&[f64]> = data.response.q.iter().map(|c| c.as_slice()).collect();
    let mut fit = Fit::new(&problem, &y, start)?;
    // continuation: growing leading windows on every `coarse`-th sample, then the
    // whole record at every sample
    let n = data.response.len();
    let coarse = options.coarse.max(1);
    let mut stages = Vec::new();
    for f in WINDOWS {
        let w = ((n - 1) as f64 * f).round() as usize + 1;
        if coarse > 1 && (w - 1) / coarse + 1 >= needed.max(200) {
            stages.push((coarse, w, COARSE_TOLERANCE));
        }
    }
    stages.push((1, n, options.tolerance));
    let mut trials = 0;
    let mut converged = false;
    let last = stages.len() - 1;
    for (s, &(k, w, tol)) in stages.iter().enumerate() {
        let left = options.max_iterations.saturating_sub(trials);
        let budget = if s < last {
            left.min(STAGE_TRIALS)
        } else {
            left
        };
        let (c, used) = fit.run((k, w), tol, budget, s < last)?;
        trials += used;
        converged = c;
    }
    result::finish(&problem, &y, fit, trials, converged, options)
}

/// The Cramer-Rao bound of `options.unknowns` for a record like `data` (its channels,
/// sampling and speed; its values are not used) of the rotor `truth` from rest, with noise
/// `sigma[c]` \[m or rad\] on channel c, the nuisances of `options` (initial state,
/// offsets) unknown as in the fit, the basis of `options.modes` modes: sqrt of the diagonal
/// of the inverse Fisher information, in the order of the unknowns (+infinity when
/// singular).
pub fn crb_fe(
    data: &FeData,
    truth: &FiniteElementRotor,
    options: &FeRefineOptions,
    sigma: &[f64],
) -> Result<Vec<f64>, FeRefineError> {
    let dt = data.checked_dt()?;
    let unknowns = &options.unknowns;
    let modes = options.modes;
    let problem = FeProblem::new(
        truth,
        data.response.dofs.clone(),
        data.speed,
        dt,
        data.response.len(),
        unknowns.clone(),
        options.initial,
        modes,
    )?
    .with_offsets(options.offsets);
    if sigma.len() != data.response.dofs.len() || sigma.iter().any(|s| s.is_nan() || *s <= 0.0) {
        return Err(FeRefineError::Record(format!(
            "{} noise levels for {} channels: one > 0 per channel",
            sigma.len(),
            data.response.dofs.len()
        )));
    }
    let basis = RitzBasis::new(truth, modes)?;
    let x0 = DVector::zeros(problem.nuisance());
    let e = problem.evaluate(truth, basis.matrix(), &x0, (1, data.response.len()), true)?;
    let w: Vec<f64> = sigma.iter().map(|s| 1.0 / (s * s)).collect();
    let (a, _) = evaluate::normal_equations(&e, None, &w);
    let cov = result::inverse(&a);
    Ok((0..unknowns.len())
        .map(|i| match &cov {
            Some(c) if c[(i, i)] > 0.0 => c[(i, i)].sqrt(),
            _ => f64::INFINITY,
        })
        .collect())
}

/// The state of a fit: current rotor, initial state, basis, noise weights.
pub(crate) struct Fit<'a> {
    problem: &'a FeProblem,
    y: &'a [&'a [f64]],
    pub(crate) rotor: FiniteElementRotor,
    pub(crate) x0: DVector<f64>,
    pub(crate) basis: RitzBasis,
    /// 1 / sigma_c^2.
    pub(crate) weights: Vec<f64>,
    /// The last evaluation (at the current state, the last stage's decimation).
    pub(crate) eval: Option<evaluate::Evaluation>,
    start: Vec<f64>,
}

impl<'a> Fit<'a> {
    fn new(
        problem: &'a FeProblem,
        y: &'a [&'a [f64]],
        start: &FiniteElementRotor,
    ) -> Result<Self, FeRefineError> {
        let basis = RitzBasis::new(start, problem.modes())?;
        let start_values = problem
            .unknowns()
            .iter()
            .map(|p| p.get(start).unwrap_or(f64::NAN))
            .collect();
        Ok(Self {
            problem,
            y,
            rotor: start.clone(),
            x0: DVector::zeros(problem.nuisance()),
            basis,
            weights: vec![1.0; y.len()],
            eval: None,
            start: start_values,
        })
    }

    pub(crate) fn start_values(&self) -> &[f64] {
        &self.start
    }

    /// Levenberg-Marquardt on every `k`-th sample until the step is below `tol` standard
    /// errors or `budget` trials are used: (converged, trials).
    fn run(
        &mut self,
        at: (usize, usize),
        tol: f64,
        budget: usize,
        freeze: bool,
    ) -> Result<(bool, usize), FeRefineError> {
        let p = self.problem;
        let k = at.0;
        let mut eval = p.evaluate(&self.rotor, self.basis.matrix(), &self.x0, at, true)?;
        self.weights = evaluate::noise_weights(self.y, at);
        eval.solve_linear(p, &mut self.rotor, &mut self.x0, self.y, &self.weights);
        let mut cost = eval.cost(self.y, k, &self.weights);
        let mut lambda = 1e-3;
        let mut trials = 0;
        let mut converged = false;
        while trials < budget {
            let (a, g) = evaluate::normal_equations(&eval, Some((self.y, k)), &self.weights);
            // positive parameters (direct bearing coefficients, mud) move in log space
            let d = self.log_scales();
            let a = DMatrix::from_fn(a.nrows(), a.ncols(), |i, j| a[(i, j)] * d[i] * d[j]);
            let g = DVector::from_fn(g.len(), |i, _| g[i] * d[i]);
            let cov = result::inverse(&a);
            // a coarse stage moves only what its window determines (the others keep their
            // values until a longer window informs them: damping below the first critical)
            let free: Vec<bool> = (0..g.len())
                .map(|i| !freeze || self.determined(i, cov.as_ref(), &d))
                .collect();
            let Some(step) = lm_step(&a, &g, lambda, &free) else {
                lambda *= 10.0;
                if lambda > 1e12 {
                    break;
                }
                continue;
            };
            // the step in standard errors (at lambda -> 0 the Gauss-Newton step)
            let small = cov.as_ref().is_some_and(|cov| {
                (0..step.len()).all(|i| step[i].abs() <= tol * cov[(i, i)].max(0.0).sqrt())
            });
            if small && (freeze || lambda <= 1e-2) {
                // the Gauss-Newton step is below the tolerance: taking it would not move
                // any estimate by more than `tol` standard errors
                converged = true;
                break;
            }
            trials += 1;
            let Some((mut rotor, mut x0)) = self.apply(&step) else {
                lambda *= 10.0;
                if lambda > 1e12 {
                    break;
                }
                continue;
            };
            let basis = RitzBasis::new(&rotor, p.modes())?;
            let mut trial = p.evaluate(&rotor, basis.matrix(), &x0, at, true)?;
            trial.solve_linear(p, &mut rotor, &mut x0, self.y, &self.weights);
            let new_cost = trial.cost(self.y, k, &self.weights);
            if new_cost <= cost {
                let gain = cost - new_cost;
                self.rotor = rotor;
                self.x0 = x0;
                self.basis = basis;
                eval = trial;
                cost = new_cost;
                lambda = (lambda / 10.0).max(1e-9);
                if small || gain <= 1e-12 * cost {
                    // nothing left to gain at this stage
                    converged = small;
                    break;
                }
            } else {
                lambda *= 10.0;
                if small || lambda > 1e12 {
                    // at the optimum to the noise's rounding: nothing left to gain
                    converged = small;
                    break;
                }
            }
        }
        self.eval = Some(eval);
        Ok((converged, trials))
    }

    /// Whether the current window determines internal parameter `i` (its standard error
    /// `cov`, in the step's coordinates: log for a positive parameter, below 0.3; an angle
    /// below 0.5 rad; a cross coefficient below 0.3 of its bearing's direct scale; the
    /// initial state always).
    fn determined(&self, i: usize, cov: Option<&DMatrix<f64>>, d: &[f64]) -> bool {
        let Some(cov) = cov else {
            return true;
        };
        let s = cov[(i, i)].max(0.0).sqrt();
        let Some(&par) = self.problem.unknowns().get(i) else {
            return true;
        };
        match par {
            _ if d[i] != 1.0 => s < 0.3,
            FeParameter::Alpha { .. } => s < 0.5,
            FeParameter::Bearing { index, coefficient } => {
                s < 0.3 * evaluate::scale(&self.rotor, index, coefficient)
            }
            FeParameter::Mud { .. } => s < 0.3 * par.get(&self.rotor).unwrap_or(0.0).abs(),
        }
    }

    /// d theta / d u for each unknown: its value for a positive one moved in log space
    /// (u = ln theta), else 1.
    fn log_scales(&self) -> Vec<f64> {
        let mut d: Vec<f64> = self
            .problem
            .unknowns()
            .iter()
            .map(|&p| match p.get(&self.rotor) {
                Some(v) if positive(p) && v > 0.0 => v,
                _ => 1.0,
            })
            .collect();
        d.resize(self.problem.unknowns().len() + self.problem.nuisance(), 1.0);
        d
    }

    /// The rotor and initial state after `step` (None when the step leaves the allowed
    /// range: a direct stiffness <= 0, a negative damping).
    fn apply(&self, step: &DVector<f64>) -> Option<(FiniteElementRotor, DVector<f64>)> {
        let mut rotor = self.rotor.clone();
        let np = self.problem.unknowns().len();
        let d = self.log_scales();
        for (i, &par) in self.problem.unknowns().iter().enumerate() {
            let v = par.get(&rotor)?;
            let v = if d[i] != 1.0 || positive(par) && v > 0.0 {
                v * step[i].clamp(-1.0, 1.0).exp()
            } else {
                v + step[i]
            };
            par.set(&mut rotor, v);
        }
        for u in rotor.unbalances.iter_mut() {
            if u.mud < 0.0 {
                u.mud = -u.mud;
                u.alpha += std::f64::consts::PI;
            }
            u.alpha = wrap(u.alpha);
        }
        for (i, b) in rotor.bearings.iter().enumerate() {
            if b.validated(&format!("bearing{i}")).is_err() {
                return None;
            }
        }
        let x0 = &self.x0 + step.rows(np, step.len() - np);
        Some((rotor, x0))
    }
}

/// A parameter that is positive by nature (direct bearing coefficients, mud).
fn positive(p: FeParameter) -> bool {
    match p {
        FeParameter::Bearing { coefficient, .. } => !coefficient.is_cross(),
        FeParameter::Mud { .. } => true,
        FeParameter::Alpha { .. } => false,
    }
}

/// Wrap an angle to (-pi, pi].
fn wrap(a: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    let w = a - tau * (a / tau).round();
    if w <= -std::f64::consts::PI {
        w + tau
    } else {
        w
    }
}

/// (A + lambda diag A) delta = g over the `free` unknowns (the others 0) by Cholesky; None
/// when not positive definite.
fn lm_step(a: &DMatrix<f64>, g: &DVector<f64>, lambda: f64, free: &[bool]) -> Option<DVector<f64>> {
    let idx: Vec<usize> = (0..g.len()).filter(|&i| free[i]).collect();
    let n = idx.len();
    let mut m = DMatrix::from_fn(n, n, |i, j| a[(idx[i], idx[j])]);
    for i in 0..n {
        let d = m[(i, i)];
        m[(i, i)] = d + lambda * if d > 0.0 { d } else { 1.0 };
    }
    let rhs = DVector::from_fn(n, |i, _| g[idx[i]]);
    let sub = m.cholesky().map(|c| c.solve(&rhs))?;
    let mut step = DVector::zeros(g.len());
    for (i, &j) in idx.iter().enumerate() {
        step[j] = sub[i];
    }
    Some(step)
}

/// The initial state in full coordinates from reduced ones (q = T x0\[..r\], q' = T
/// x0\[r..\]).
pub(crate) fn full_initial(basis: &DMatrix<f64>, x0: &DVector<f64>) -> FeInitialState {
    let r = basis.ncols();
    FeInitialState {
        q: basis * x0.rows(0, r),
        v: basis * x0.rows(r, r),
    }
}
