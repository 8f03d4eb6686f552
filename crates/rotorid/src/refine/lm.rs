//! Output-error (maximum-likelihood) fit by Gauss-Newton with Levenberg-Marquardt damping.
//!
//! Measurements x_k, z_k (k = 0 .. N-1) with independent white Gaussian noise of unknown
//! standard deviations sigma_x, sigma_z. Maximising the likelihood over sigma first gives
//! sigma^2 = S / N per channel and leaves the concentrated negative log-likelihood
//!
//! ```text
//! L(theta) = N/2 ln S_x(theta) + N/2 ln S_z(theta),     S_x = sum_k (x_k - x(t_k; theta))^2
//! ```
//!
//! (Ljung, *System Identification*, 2nd ed., 1999, sec. 7.4). Its gradient is
//! -(J_x^T r_x / sigma_x^2 + J_z^T r_z / sigma_z^2) with sigma from the current residuals,
//! and its Gauss-Newton Hessian is the Fisher information F, so each iteration solves
//!
//! ```text
//! (Fs + mu I) D delta = D^-1 g,     Fs = D^-1 F D^-1,  D = diag(sqrt(F_ii)),  g = J^T W r
//! ```
//!
//! (Marquardt 1963), accepts the step when L decreases (mu / 10) and otherwise retries with
//! mu * 10 (also, without a model pass, when the step leaves a physical trust region:
//! m, kx, kz changing by more than 50 %, or a damping ratio below -0.01). It stops when
//! the undamped step is shorter than `tolerance` standard errors, sqrt(delta^T F delta)
//! < tol, or when a rejected step is at the rounding floor (|delta_i| <= 1e-11 |theta_i|
//! for every model parameter, with a step below one standard error or a model that
//! reproduces the data to 1e-8 of their RMS). Before the iteration, the
//! parameters that enter the response linearly (initial state, unbalance) are set to
//! their least-squares values (one exact linear solve), so a poor guess of them costs
//! nothing.
//!
//! Continuation: the iteration first runs on a short leading window of the record (two
//! periods of the natural frequency) and then on longer ones, each as long as the current
//! uncertainty of the natural frequencies keeps the free vibration's phase predictable
//! (3 sd(w_n) T <= 1 rad), ending on the whole record. A start a few per cent off would
//! otherwise slip whole periods over a long record and stall in a local minimum.
//!
//! Jacobians are the exact forward sensitivities of the discrete model (`exact_step`,
//! `rk4_step`), not finite differences.

use serde::{Deserialize, Serialize};

use crate::model::{check, InitialState, RotorParams};
use crate::parameter::ModelKind;

use super::discretisation::{Discrete, Discretisation};
use super::error::RefineError;
use super::fisher::Fisher;
use super::record::Record;
use super::result::{
    identifiability_warnings, rows, weakest_names, FittedValue, Refined, RobustCovariance, Warning,
    STD_ERROR_BASIS,
};
use super::steady::{steady_initial_state, TRANSIENT_SIGNIFICANCE};
use super::sweep::{Normal, NormalSink};
use super::unknowns::{check_params, Columns, Kind, Theta, Unknowns};

/// Settings of [`refine`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RefineOptions {
    /// What to estimate (default: m, cx, kx, cz, kz and the initial state).
    pub unknowns: Unknowns,
    /// The discrete model (default: exact at constant speed, RK4 otherwise).
    pub discretisation: Discretisation,
    /// Most model passes (Levenberg-Marquardt trials, over all windows); 0 evaluates the
    /// start on the whole record (the initial state and unbalance, when unknown, still get
    /// their linear least-squares values).
    pub max_iterations: usize,
    /// Stop when the Gauss-Newton step is shorter than this many standard errors
    /// (finite, > 0; default 1e-3).
    pub tolerance: f64,
}

impl Default for RefineOptions {
    fn default() -> Self {
        Self {
            unknowns: Unknowns::default(),
            discretisation: Discretisation::Auto,
            max_iterations: 50,
            tolerance: 1e-3,
        }
    }
}

/// Initial Marquardt damping (on the unit diagonal of the scaled information).
const MU_START: f64 = 1e-6;
/// Smallest damping kept after successful steps.
const MU_MIN: f64 = 1e-12;
/// Damping at which the iteration gives up.
const MU_MAX: f64 = 1e10;
/// Relative step of every model parameter below which a rejected step means the fit sits
/// at the rounding floor.
const ROUNDING_FLOOR: f64 = 1e-11;
/// Residual energy, relative to the data's, below which the model reproduces the data
/// exactly (to 1e-8 of their RMS).
const EXACT_FIT: f64 = 1e-16;
/// Variance floor \[m^2\] so exactly reproduced data do not divide by zero.
const VAR_FLOOR: f64 = 1e-280;

/// One evaluated point: parameters, sums and cost.
struct Point {
    theta: Theta,
    normal: Normal,
    cost: f64,
}

fn cost(n: &Normal) -> f64 {
    let ns = n.samples as f64;
    0.5 * ns * (n.sxx.max(f64::MIN_POSITIVE).ln() + n.szz.max(f64::MIN_POSITIVE).ln())
}

fn variances(n: &Normal) -> (f64, f64) {
    let ns = n.samples as f64;
    ((n.sxx / ns).max(VAR_FLOOR), (n.szz / ns).max(VAR_FLOOR))
}

fn evaluate(disc: &Discrete, rec: &Record, cols: &Columns, t: &Theta, n_used: usize) -> Point {
    let mut sink = NormalSink {
        data: Some((rec.x, rec.z)),
        acc: Normal::new(cols.n),
    };
    disc.run(t, cols, n_used, &mut sink);
    Point {
        theta: *t,
        cost: cost(&sink.acc),
        normal: sink.acc,
    }
}

fn apply(t: &Theta, cols: &Columns, delta: &[f64]) -> Theta {
    let mut out = *t;
    for (j, &k) in cols.kinds().iter().enumerate() {
        out.set(k, t.get(k) + delta[j]);
    }
    out
}

/// Set the parameters that enter the response linearly (initial state, u_c, u_s) to their
/// least-squares values at fixed other parameters: one Gauss-Newton step is exact there.
fn solve_linear(disc: &Discrete, rec: &Record, cols: &Columns, t: &Theta, n_used: usize) -> Theta {
    let lin = cols.filter(|k| k.initial_index().is_some() || matches!(k, Kind::Uc | Kind::Us));
    if lin.n == 0 {
        return *t;
    }
    let p = evaluate(disc, rec, &lin, t, n_used);
    let (vx, vz) = variances(&p.normal);
    let (f, g) = p.normal.combine(vx, vz);
    let (delta, _) = Fisher::new(&f, lin.n).step(&g, 0.0);
    apply(t, &lin, &delta)
}

/// The outcome of the Levenberg-Marquardt iteration on one window.
struct Outcome {
    point: Point,
    fisher: Fisher,
    converged: bool,
    last_step: f64,
    passes: usize,
}

/// Levenberg-Marquardt on the first `n_used` samples from `theta`, at most `max_passes`
/// model passes, until the Gauss-Newton step is below `tol` standard errors.
fn levenberg_marquardt(
    disc: &Discrete,
    rec: &Record,
    cols: &Columns,
    theta: &Theta,
    n_used: usize,
    tol: f64,
    max_passes: usize,
) -> Outcome {
    let mut cur = evaluate(disc, rec, cols, theta, n_used);
    let mut mu = MU_START;
    let mut passes = 0;
    loop {
        let (vx, vz) = variances(&cur.normal);
        let (f, g) = cur.normal.combine(vx, vz);
        let fi = Fisher::new(&f, cols.n);
        let (_, gn_len) = fi.step(&g, 0.0);
        let done = |converged: bool, point: Point, fisher: Fisher| Outcome {
            point,
            fisher,
            converged,
            last_step: gn_len,
            passes,
        };
        if gn_len < tol {
            return done(true, cur, fi);
        }
        if passes >= max_passes || mu > MU_MAX {
            return done(false, cur, fi);
        }
        let (delta, _) = fi.step(&g, mu);
        let trial = apply(&cur.theta, cols, &delta);
        if !plausible_step(&cur.theta, &trial, cols) || !delta.iter().all(|d| d.is_finite()) {
            mu *= 10.0;
            continue;
        }
        passes += 1;
        let next = evaluate(disc, rec, cols, &trial, n_used);
        if next.cost < cur.cost {
            cur = next;
            mu = (mu / 10.0).max(MU_MIN);
        } else {
            // A rejected step at the rounding level of every model parameter, when the step
            // is shorter than one standard error or the model reproduces the data to
            // 1e-8 of their RMS (exact data): nothing left to gain.
            let n = &cur.normal;
            let exact = n.sxx <= EXACT_FIT * n.data_xx && n.szz <= EXACT_FIT * n.data_zz;
            let floor = (gn_len < 1.0 || exact)
                && cols.kinds()[..cols.nphys]
                    .iter()
                    .zip(&delta)
                    .all(|(&k, d)| d.abs() <= ROUNDING_FLOOR * cur.theta.get(k).abs());
            if floor {
                return Outcome {
                    point: cur,
                    fisher: fi,
                    converged: true,
                    last_step: gn_len,
                    passes,
                };
            }
            mu *= 10.0;
        }
    }
}

/// Largest relative change of m, kx, kz in one step.
const MAX_RELATIVE_STEP: f64 = 0.5;
/// Most negative damping ratio c / (2 sqrt(k m)) a step may reach (the response of a
/// negatively damped model grows exponentially and wrecks the linearisation).
const MIN_DAMPING_RATIO: f64 = -0.01;

/// A trust region in physical terms: m, kx, kz change by at most 50 % per step (and m stays
/// positive), cx, cz stay above a damping ratio of -0.01; a cross-coupled stiffness
/// changes by at most 50 % of sqrt(kx kz) and a cross-coupled damping by at most 50 % of
/// the critical damping 2 sqrt(m sqrt(kx kz)) (a step beyond them makes the model grow
/// exponentially or changes its modes beyond what the linearisation describes).
fn plausible_step(cur: &Theta, trial: &Theta, cols: &Columns) -> bool {
    if trial.m.is_nan() || trial.m <= 0.0 {
        return false;
    }
    let k = (cur.kx * cur.kz).abs().sqrt();
    let c_crit = 2.0 * (cur.m * k).sqrt();
    let step = |kind: Kind| (trial.get(kind) - cur.get(kind)).abs();
    cols.kinds()[..cols.nphys].iter().all(|&kind| match kind {
        Kind::M | Kind::Kx | Kind::Kz => step(kind) <= MAX_RELATIVE_STEP * cur.get(kind).abs(),
        Kind::Cx => trial.cx >= MIN_DAMPING_RATIO * 2.0 * (trial.kx.abs() * trial.m).sqrt(),
        Kind::Cz => trial.cz >= MIN_DAMPING_RATIO * 2.0 * (trial.kz.abs() * trial.m).sqrt(),
        Kind::Kxz | Kind::Kzx => step(kind) <= MAX_RELATIVE_STEP * k,
        Kind::Cxz | Kind::Czx => step(kind) <= MAX_RELATIVE_STEP * c_crit,
        _ => true,
    })
}

/// Periods of the fastest natural frequency in the first window.
const FIRST_WINDOW_PERIODS: f64 = 2.0;
/// Step tolerance (standard errors) on the windows before the whole record.
const WINDOW_TOLERANCE: f64 = 0.1;
/// Most model passes on each window before the whole record (a window that does not
/// converge in these hands its best point to the next, longer one).
const WINDOW_MAX_PASSES: usize = 10;
/// Largest allowed 3-sigma phase uncertainty \[rad\] of the free vibration over the next
/// window, from the current window's covariance.
const PHASE_BUDGET: f64 = 1.0;

/// sqrt(k / m) \[rad/s\] with k = ||K||_inf = max(|kx| + |kxz|, |kzx| + |kz|) (max(kx, kz)
/// for a Jeffcott rotor), 0 when not finite.
fn natural_frequency(t: &Theta) -> f64 {
    let k = (t.kx.abs() + t.kxz.abs()).max(t.kzx.abs() + t.kz.abs());
    let w = (k / t.m).sqrt();
    if w.is_finite() {
        w
    } else {
        0.0
    }
}

/// Samples in the first window: FIRST_WINDOW_PERIODS periods of sqrt(k/m), at least 50
/// per unknown (of a record `stride` times as dense: the same time span when the record
/// is every `stride`-th sample of another), at most the record. Two periods keep a start
/// up to ~8 % off in w_n within one radian of phase; the next window then usually reaches
/// the whole record.
fn first_window(t: &Theta, dt: f64, samples: usize, unknowns: usize, stride: usize) -> usize {
    let w = natural_frequency(t);
    let n = if w > 0.0 {
        (FIRST_WINDOW_PERIODS * std::f64::consts::TAU / w / dt).ceil()
    } else {
        samples as f64
    };
    let n = if n.is_finite() { n as usize } else { samples };
    n.max((50 * unknowns).div_ceil(stride.max(1)))
        .max(unknowns)
        .min(samples)
}

/// The next window: as long as the free vibration's phase stays predictable,
/// 3 sigma(w_n) T <= PHASE_BUDGET with sigma(w_n)/w_n = sd((ln k - ln m)/2) from the
/// current window's covariance, and at least twice the current window.
fn next_window(
    fi: &Fisher,
    cols: &Columns,
    t: &Theta,
    n_used: usize,
    dt: f64,
    samples: usize,
) -> usize {
    let n = cols.n;
    let pos = |k| cols.position(k);
    let var = |i: Option<usize>, j: Option<usize>| match (i, j) {
        (Some(i), Some(j)) => fi.cov[i * n + j],
        _ => 0.0,
    };
    let im = pos(Kind::M);
    let mut rel = 0.0f64;
    for (kk, k) in [(Kind::Kx, t.kx), (Kind::Kz, t.kz)] {
        let ik = pos(kk);
        let v = 0.25
            * (var(ik, ik) / (k * k) + var(im, im) / (t.m * t.m) - 2.0 * var(im, ik) / (t.m * k));
        rel = rel.max(v.max(0.0).sqrt());
    }
    let w = natural_frequency(t);
    let allowed = PHASE_BUDGET / (3.0 * w * rel) / dt;
    let grow = if allowed.is_finite() {
        allowed.min(samples as f64) as usize
    } else if rel == 0.0 {
        samples
    } else {
        0
    };
    grow.max(2 * n_used).min(samples)
}

/// The continuation's end: the discrete model, the columns, the start (after the damping
/// clamp) and the last window's outcome on the whole record.
struct Continued {
    disc: Discrete,
    cols: Columns,
    theta0: Theta,
    out: Outcome,
    passes: usize,
}

/// The fit of [`refine`] without what it reports besides the estimate (module doc).
fn continuation(
    record: &Record,
    start: &RotorParams,
    start_initial: &InitialState,
    options: &RefineOptions,
    how: &Continuation,
) -> Result<Continued, RefineError> {
    record.validate()?;
    check_params(start)?;
    start_initial.validated()?;
    check(
        "tolerance",
        options.tolerance,
        "finite and > 0 (standard errors)",
        |v| v > 0.0,
    )?;
    let cols = columns(&options.unknowns, start)?;
    let samples = record.x.len();
    if samples < cols.n {
        return Err(RefineError::TooFewSamples {
            samples,
            unknowns: cols.n,
            needed: cols.n,
        });
    }
    let theta0 = Theta::new(start, start_initial);
    let mut theta = theta0;
    if options.unknowns.cx {
        theta.cx = theta.cx.max(0.0);
    }
    if options.unknowns.cz {
        theta.cz = theta.cz.max(0.0);
    }
    let disc = Discrete::within(
        &record.experiment(),
        options.discretisation,
        &theta,
        how.rk4_freq_tol,
    )?;
    let disc = if how.balanced { disc.balanced() } else { disc };

    let dt = record.dt;
    let mut n_used = if options.max_iterations == 0 {
        samples
    } else {
        first_window(&theta, dt, samples, cols.n, how.stride)
    };
    theta = solve_linear(&disc, record, &cols, &theta, n_used);
    let mut passes = 0;
    let out = loop {
        let last = n_used == samples;
        let tol = if last {
            options.tolerance
        } else {
            how.window_tolerance
        };
        let mut budget = options.max_iterations.saturating_sub(passes);
        if !last {
            budget = budget.min(WINDOW_MAX_PASSES);
        }
        let out = levenberg_marquardt(&disc, record, &cols, &theta, n_used, tol, budget);
        passes += out.passes;
        theta = out.point.theta;
        if last {
            break out;
        }
        if passes >= options.max_iterations {
            // out of budget before the whole record: evaluate there, not converged
            let mut o = levenberg_marquardt(&disc, record, &cols, &theta, samples, tol, 0);
            o.converged = false;
            break o;
        }
        n_used = next_window(&out.fisher, &cols, &theta, n_used, dt, samples);
    };
    Ok(Continued {
        disc,
        cols,
        theta0,
        out,
        passes,
    })
}

/// The maximum-likelihood estimate alone and the model's response there: what the
/// adequacy test needs (`pipeline::adequacy`), without the covariances, the sandwich and
/// the transient's significance that [`refine`] adds.
pub(crate) struct Fit {
    /// The fitted rotor.
    pub rotor: RotorParams,
    /// The fitted initial state.
    pub initial: InitialState,
    /// Whether the last step was below the tolerance.
    pub converged: bool,
    /// Model passes with sensitivities.
    pub passes: usize,
    /// The model's x, z at the record's samples \[m\].
    pub x: Vec<f64>,
    /// The model's z.
    pub z: Vec<f64>,
}

/// How the continuation runs besides [`RefineOptions`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Continuation {
    /// The record is every `stride`-th sample of another: the first window spans the time
    /// it would span there.
    pub stride: usize,
    /// Step tolerance on the windows before the whole record \[standard errors\].
    pub window_tolerance: f64,
    /// Exact steps on the balanced state (`Discrete::balanced`).
    pub balanced: bool,
    /// Bound on the automatic RK4 sub-steps' relative frequency error
    /// (`Discrete::within`; refine's own: `FREQ_TOL`, 1e-9).
    pub rk4_freq_tol: f64,
}

impl Default for Continuation {
    fn default() -> Self {
        Self {
            stride: 1,
            window_tolerance: WINDOW_TOLERANCE,
            balanced: false,
            rk4_freq_tol: super::rk4_step::FREQ_TOL,
        }
    }
}

/// [`refine`]'s estimate alone (see [`Fit`]).
pub(crate) fn fit(
    record: &Record,
    start: &RotorParams,
    start_initial: &InitialState,
    options: &RefineOptions,
    how: &Continuation,
) -> Result<Fit, RefineError> {
    let c = continuation(record, start, start_initial, options, how)?;
    let theta = c.out.point.theta;
    let samples = record.x.len();
    let mut rotor = theta.params_with(start);
    if !options.unknowns.unbalance {
        rotor.unbalance = start.unbalance;
    }
    let none = Columns::new(&Unknowns::from_parameters(&[], false), rotor.model());
    let mut sink = super::sweep::ResponseSink {
        x: Vec::with_capacity(samples),
        z: Vec::with_capacity(samples),
    };
    c.disc.run(&theta, &none, samples, &mut sink);
    Ok(Fit {
        rotor,
        initial: theta.initial(),
        converged: c.out.converged,
        passes: c.passes,
        x: sink.x,
        z: sink.z,
    })
}

/// Fit the model to the record by maximum likelihood, starting from `start` (rotor
/// parameters; e.g. the algebraic identifier's estimate) and `start_initial` (the
/// initial-state guess, or its known value when `options.unknowns.initial_state` is
/// false). Quantities not selected as unknown keep their starting values.
///
/// The fit runs on a growing window of the record (a continuation that keeps the start
/// inside the basin of the global optimum): first two periods of the natural frequency,
/// then as long a stretch as the current uncertainty of the natural frequencies allows
/// (3-sigma phase error <= 1 rad), finally the whole record. A negative starting damping
/// of an unknown cx or cz is raised to 0 (negative damping makes the model response grow
/// exponentially).
///
/// Errors only on unusable input; an unidentifiable problem returns `Ok` with
/// `identifiable == false`, warnings and infinite standard errors.
pub fn refine(
    record: &Record,
    start: &RotorParams,
    start_initial: &InitialState,
    options: &RefineOptions,
) -> Result<Refined, RefineError> {
    let Continued {
        disc,
        cols,
        theta0,
        out,
        passes,
    } = continuation(
        record,
        start,
        start_initial,
        options,
        &Continuation::default(),
    )?;
    let samples = record.x.len();
    let cur = out.point;
    let (converged, last_step, iterations) = (out.converged, out.last_step, passes);

    let (vx, vz) = variances(&cur.normal);
    let mut fi = out.fisher;
    let mut no_transient = None;
    if let (Some((w, phi0)), true) = (record.speed.constant(), options.unknowns.initial_state) {
        if let Some(yss) = steady_initial_state(&cur.theta, w, phi0) {
            let d = transient_significance(&fi, &cols, &cur.theta, &yss);
            if d.is_nan() || d < TRANSIENT_SIGNIFICANCE {
                let mut t_ss = cur.theta;
                t_ss.y0 = yss;
                let mut sink = NormalSink {
                    data: None,
                    acc: Normal::new(cols.n),
                };
                disc.run(&t_ss, &cols, samples, &mut sink);
                let (f_ss, _) = sink.acc.combine(vx, vz);
                fi = Fisher::new(&f_ss, cols.n);
                no_transient = Some(d);
            }
        }
    }
    let robust = (!fi.unidentifiable.iter().any(|&u| u) && fi.cov.iter().all(|v| v.is_finite()))
        .then(|| {
            super::robust::robust_covariance(
                &disc, &cur.theta, &cols, samples, record.x, record.z, vx, vz, &fi,
            )
        });
    let ns = cur.normal.samples as f64;
    let sigma_x = (cur.normal.sxx / ns).sqrt();
    let sigma_z = (cur.normal.szz / ns).sqrt();
    Ok(assemble(
        &cur.theta,
        &theta0,
        start,
        &cols,
        &fi,
        robust,
        Summary {
            sigma_x,
            sigma_z,
            samples,
            iterations,
            converged,
            last_step,
            discretisation: disc.describe(),
            unbalance_estimated: options.unknowns.unbalance,
            no_transient,
        },
    ))
}

/// The columns of `u` in the model of `start`; cross-coupled unknowns need a
/// cross-coupled start.
pub(crate) fn columns(u: &Unknowns, start: &RotorParams) -> Result<Columns, RefineError> {
    let model = start.model();
    if u.any_cross() && model == ModelKind::Jeffcott {
        let cross: Vec<&str> = [
            (u.cxz, "cxz"),
            (u.czx, "czx"),
            (u.kxz, "kxz"),
            (u.kzx, "kzx"),
        ]
        .iter()
        .filter_map(|(on, n)| on.then_some(*n))
        .collect();
        return Err(RefineError::CrossUnknownsNeedCrossModel {
            unknowns: cross.join(", "),
        });
    }
    let cols = Columns::new(u, model);
    if cols.n == 0 {
        return Err(RefineError::NoUnknowns);
    }
    Ok(cols)
}

struct Summary {
    sigma_x: f64,
    sigma_z: f64,
    samples: usize,
    iterations: usize,
    converged: bool,
    last_step: f64,
    discretisation: String,
    unbalance_estimated: bool,
    no_transient: Option<f64>,
}

/// Mahalanobis length of the fitted initial state's offset from the steady state,
/// sqrt(d^T Cov(y0)^-1 d), with the marginal covariance of the initial state (0 when that
/// covariance is unusable).
fn transient_significance(fi: &Fisher, cols: &Columns, t: &Theta, yss: &[f64; 4]) -> f64 {
    let idx: Vec<(usize, usize)> = cols
        .kinds()
        .iter()
        .enumerate()
        .filter_map(|(j, k)| k.initial_index().map(|i| (j, i)))
        .collect();
    let n = cols.n;
    let m = idx.len();
    let cov = nalgebra::DMatrix::from_fn(m, m, |a, b| fi.cov[idx[a].0 * n + idx[b].0]);
    let d = nalgebra::DVector::from_fn(m, |a, _| t.y0[idx[a].1] - yss[idx[a].1]);
    if !cov.iter().all(|v| v.is_finite()) {
        return 0.0;
    }
    match cov.cholesky() {
        Some(ch) => {
            let d2 = d.dot(&ch.solve(&d));
            if d2.is_finite() && d2 > 0.0 {
                d2.sqrt()
            } else {
                0.0
            }
        }
        None => 0.0,
    }
}

fn assemble(
    t: &Theta,
    t0: &Theta,
    start: &RotorParams,
    cols: &Columns,
    fi: &Fisher,
    robust: Option<super::robust::Robust>,
    s: Summary,
) -> Refined {
    let rs = rows(t, cols, fi);
    let robust_rows = robust.as_ref().map(|r| {
        let mut f = fi.clone();
        f.cov = r.cov.clone();
        rows(t, cols, &f)
    });
    let starts = rows(t0, cols, fi);
    let mut warnings = Vec::new();
    if let Some(significance) = s.no_transient {
        warnings.push(Warning::NoSignificantTransient { significance });
    }
    if !s.converged {
        warnings.push(Warning::NotConverged {
            iterations: s.iterations,
            last_step: s.last_step,
        });
    }
    let mut id_warnings =
        identifiability_warnings(&rs, fi.condition_number, weakest_names(fi, cols));
    if s.no_transient.is_some() {
        for w in &mut id_warnings {
            if let Warning::NotIdentifiable {
                steady_state_only, ..
            } = w
            {
                *steady_state_only = true;
            }
        }
    }
    let identifiable = id_warnings.is_empty();
    warnings.extend(id_warnings);
    for r in rs.iter().filter(|r| !r.initial && r.unphysical) {
        warnings.push(Warning::Unphysical {
            parameter: r.name,
            value: r.value,
        });
    }
    let mut parameters = Vec::new();
    let mut initial_state = Vec::new();
    for (i, (r, r0)) in rs.iter().zip(&starts).enumerate() {
        let e = FittedValue {
            name: r.name,
            unit: r.unit,
            value: r.value,
            std_error: r.std,
            relative_std_error: r.relative,
            robust_std_error: robust_rows.as_ref().map(|rr| rr[i].std),
            start: r0.value,
            scale: r.scale,
            crb: None,
        };
        if r.initial {
            initial_state.push(e);
        } else {
            parameters.push(e);
        }
    }
    let mut rotor = t.params_with(start);
    if !s.unbalance_estimated {
        rotor.unbalance = start.unbalance;
    }
    let n = cols.n;
    Refined {
        parameters,
        initial_state,
        rotor,
        initial: t.initial(),
        sigma_x: s.sigma_x,
        sigma_z: s.sigma_z,
        samples: s.samples,
        iterations: s.iterations,
        converged: s.converged,
        identifiable,
        condition_number: fi.condition_number,
        fisher_rank: fi.rank(),
        warnings,
        discretisation: s.discretisation,
        std_error_basis: STD_ERROR_BASIS,
        covariance: (0..n)
            .map(|i| fi.cov[i * n..(i + 1) * n].to_vec())
            .collect(),
        covariance_names: cols.kinds().iter().map(|k| k.name_in(cols.model)).collect(),
        robust: robust.map(|r| RobustCovariance {
            bandwidth: r.bandwidth,
            residual_lag1_autocorrelation: r.rho,
            covariance: (0..n).map(|i| r.cov[i * n..(i + 1) * n].to_vec()).collect(),
        }),
    }
}
