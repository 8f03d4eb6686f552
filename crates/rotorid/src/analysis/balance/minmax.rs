//! The min-max correction: the correction C that minimises the largest weighted predicted
//! residual, subject to optional limits,
//!
//! ```text
//! minimise t   over t, C
//! subject to   w_k |V_k + h_k C| <= t          every key k
//!              |V_k + h_k C| <= L_k            every key k of a sensor with a limit L_k
//! ```
//!
//! a second-order cone program: each |.| <= . is a cone (s_0, s_1, s_2) with
//! s_0 >= sqrt(s_1^2 + s_2^2), s = (t, w Re r_k, w Im r_k) affine in x = (t, Re C_1, Im C_1,
//! ...). Solved by Clarabel (an interior-point conic solver, oxfordcontrol/Clarabel.rs), the
//! data scaled to O(1) first (vectors by their largest magnitude, C by the ratio of that to
//! the largest |h|) and the tolerances tightened to 1e-10; the solution is then polished by
//! Newton's method on the KKT equations of its active set (`polish`), to rounding.
//!
//! When the limits cannot all be met the solver reports primal infeasibility; the problem
//! minimise rho subject to |r_k| <= rho L_k (the limited keys only) then gives by how much
//! the best correction misses them, for the message. Reference: Foiles, Allaire & Gunter,
//! "Min-max optimum flexible rotor balancing compared to weighted least squares", 7th Int.
//! Conf. on Vibrations in Rotating Machinery, IMechE C576/097/2000.

use clarabel::algebra::CscMatrix;
use clarabel::solver::{DefaultSettings, DefaultSolver, IPSolver, SolverStatus, SupportedConeT};
use nalgebra::{Complex, DMatrix, DVector};

use super::correction::Problem;
use super::error::BalanceError;
use crate::analysis::modes::C64;

/// Solver tolerances (scaled problem).
const TOLERANCE: f64 = 1e-10;

/// The outcome of one cone program.
enum Outcome {
    /// x.
    Solved(Vec<f64>),
    /// The constraints cannot be met.
    Infeasible,
}

fn solve_socp(
    ncols: usize,
    rows: Vec<Vec<f64>>,
    b: Vec<f64>,
    cones: usize,
    what: &'static str,
) -> Result<Outcome, BalanceError> {
    let p = CscMatrix::<f64>::zeros((ncols, ncols));
    let mut q = vec![0.0; ncols];
    q[0] = 1.0;
    let a = CscMatrix::from(rows.iter().map(|r| r.iter()));
    let cones: Vec<SupportedConeT<f64>> = (0..cones)
        .map(|_| SupportedConeT::SecondOrderConeT(3))
        .collect();
    let settings = DefaultSettings::<f64> {
        verbose: false,
        tol_gap_abs: TOLERANCE,
        tol_gap_rel: TOLERANCE,
        tol_feas: TOLERANCE,
        max_iter: 200,
        ..DefaultSettings::default()
    };
    let mut solver =
        DefaultSolver::new(&p, &q, &a, &b, &cones, settings).map_err(|e| BalanceError::Solver {
            status: e.to_string(),
            what,
        })?;
    solver.solve();
    match solver.solution.status {
        SolverStatus::Solved | SolverStatus::AlmostSolved => {
            Ok(Outcome::Solved(solver.solution.x.clone()))
        }
        SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => {
            Ok(Outcome::Infeasible)
        }
        s => Err(BalanceError::Solver {
            status: format!("{s:?}"),
            what,
        }),
    }
}

/// Scales of the problem: (vector scale, correction scale).
fn scales(p: &Problem) -> (f64, f64) {
    let vmax = p.v.iter().fold(0.0f64, |m, z| m.max(z.norm()));
    let hmax = p.h.iter().fold(0.0f64, |m, z| m.max(z.norm()));
    let vs = if vmax > 0.0 { vmax } else { 1.0 };
    let cs = if hmax > 0.0 { vs / hmax } else { 1.0 };
    (vs, cs)
}

/// The three rows and right-hand sides of the cone (bound, Re r_k, Im r_k) for key `k`
/// scaled by `w`, the bound being t (x_0) when `bound` is `None`, else the constant.
fn cone_rows(
    p: &Problem,
    k: usize,
    w: f64,
    bound: Option<f64>,
    (vs, cs): (f64, f64),
    (rows, b): (&mut Vec<Vec<f64>>, &mut Vec<f64>),
) {
    let np = p.h.ncols();
    let mut r0 = vec![0.0; 1 + 2 * np];
    let mut r1 = vec![0.0; 1 + 2 * np];
    let mut r2 = vec![0.0; 1 + 2 * np];
    match bound {
        None => {
            r0[0] = -1.0;
            b.push(0.0);
        }
        Some(l) => b.push(l),
    }
    for q in 0..np {
        // h C in scaled units: (h cs / vs) (C / cs)
        let h = p.h[(k, q)] * (cs / vs);
        r1[1 + 2 * q] = -w * h.re;
        r1[2 + 2 * q] = w * h.im;
        r2[1 + 2 * q] = -w * h.im;
        r2[2 + 2 * q] = -w * h.re;
    }
    b.push(w * p.v[k].re / vs);
    b.push(w * p.v[k].im / vs);
    rows.push(r0);
    rows.push(r1);
    rows.push(r2);
}

/// The min-max correction of `p` with `limits` per key (module doc).
pub(crate) fn min_max(
    p: &Problem,
    limits: &[Option<f64>],
    names: &dyn Fn(usize) -> (String, f64),
) -> Result<DVector<C64>, BalanceError> {
    let (k, np) = p.h.shape();
    let (vs, cs) = scales(p);
    let mut rows = Vec::new();
    let mut b = Vec::new();
    let mut cones = 0;
    for i in 0..k {
        cone_rows(p, i, p.w[i], None, (vs, cs), (&mut rows, &mut b));
        cones += 1;
    }
    for (i, l) in limits.iter().enumerate() {
        if let Some(l) = l {
            cone_rows(p, i, 1.0, Some(l / vs), (vs, cs), (&mut rows, &mut b));
            cones += 1;
        }
    }
    match solve_socp(1 + 2 * np, rows, b, cones, "the min-max correction")? {
        Outcome::Solved(x) => {
            let c = DVector::from_fn(np, |q, _| Complex::new(x[1 + 2 * q], x[2 + 2 * q]) * cs);
            Ok(polish(p, limits, &c).unwrap_or(c))
        }
        Outcome::Infeasible => Err(infeasible(p, limits, names)?),
    }
}

/// Relative closeness of a constraint to its bound that counts it as active.
const ACTIVE: f64 = 1e-5;

/// The interior-point solution polished on its active set: Newton on the KKT equations
///
/// ```text
/// sum_k lambda_k grad_c g_k = 0,   1 - 2 t sum_(k bounded by t) lambda_k = 0,   g_k = 0 (k active)
/// g_k = w_k^2 |r_k|^2 - t^2  (or |r_k|^2 - L_k^2 for a limit)
/// ```
///
/// in scaled units, the multipliers started from the least-squares solution of the
/// stationarity equations at the solver's point. The solver stops at a tolerance whose
/// effect on C is far larger than rounding (the optimum is flat along the active set's
/// tangents); the polished C is accurate to rounding, which the central differences of the
/// standard deviations need. `None` (the solver's C stands) when a multiplier is not
/// positive (a degenerate active set) or Newton does not converge to rounding.
fn polish(p: &Problem, limits: &[Option<f64>], c0: &DVector<C64>) -> Option<DVector<C64>> {
    let (k, np) = p.h.shape();
    let (vs, cs) = scales(p);
    // units: C by cs, vectors by the largest weighted residual at the solver's point, so
    // that t is 1 and every equation is O(1)
    let rw = (0..k)
        .map(|i| p.w[i] * (p.v[i] + (p.h.row(i) * c0)[0]).norm())
        .fold(0.0f64, f64::max);
    if !(rw > 0.0 && rw.is_finite()) {
        return None;
    }
    let vs = vs.min(rw);
    let h = p.h.map(|z| z * (cs / vs));
    let v = p.v.map(|z| z / vs);
    let r_of = |c: &DVector<C64>| &v + &h * c;
    let c_start = c0.map(|z| z / cs);
    let r0 = r_of(&c_start);
    let t0 = (0..k).map(|i| p.w[i] * r0[i].norm()).fold(0.0f64, f64::max);
    // active constraints: (key, Some(limit) or None for t)
    let mut active: Vec<(usize, Option<f64>)> = (0..k)
        .filter(|&i| p.w[i] * r0[i].norm() >= t0 * (1.0 - ACTIVE))
        .map(|i| (i, None))
        .collect();
    for (i, l) in limits.iter().enumerate() {
        if let Some(l) = l {
            let l = l / vs;
            if r0[i].norm() >= l * (1.0 - ACTIVE) {
                active.push((i, Some(l)));
            }
        }
    }
    let n = 2 * np + 1;
    let na = active.len();
    // the real Jacobian of r_i over (Re c_1, Im c_1, ...)
    let jr = |i: usize| {
        let mut m = DMatrix::<f64>::zeros(2, 2 * np);
        for q in 0..np {
            let z = h[(i, q)];
            m[(0, 2 * q)] = z.re;
            m[(0, 2 * q + 1)] = -z.im;
            m[(1, 2 * q)] = z.im;
            m[(1, 2 * q + 1)] = z.re;
        }
        m
    };
    let scale_of = |i: usize, l: Option<f64>| if l.is_some() { 1.0 } else { p.w[i] * p.w[i] };
    // z = (c (2P), t, lambda (na))
    let residual = |z: &DVector<f64>| -> (DVector<f64>, DMatrix<f64>) {
        let c = DVector::from_fn(np, |q, _| Complex::new(z[2 * q], z[2 * q + 1]));
        let t = z[2 * np];
        let r = r_of(&c);
        let mut f = DVector::<f64>::zeros(n + na);
        let mut jac = DMatrix::<f64>::zeros(n + na, n + na);
        f[2 * np] = 1.0;
        for (a, &(i, l)) in active.iter().enumerate() {
            let s = scale_of(i, l);
            let j = jr(i);
            let rv = nalgebra::Vector2::new(r[i].re, r[i].im);
            let grad = j.transpose() * rv * (2.0 * s);
            let lam = z[n + a];
            for x in 0..2 * np {
                f[x] += lam * grad[x];
                jac[(x, n + a)] = grad[x];
                jac[(n + a, x)] = grad[x];
            }
            let hess = j.transpose() * &j * (2.0 * s * lam);
            for x in 0..2 * np {
                for y in 0..2 * np {
                    jac[(x, y)] += hess[(x, y)];
                }
            }
            match l {
                None => {
                    f[2 * np] -= 2.0 * t * lam;
                    jac[(2 * np, 2 * np)] -= 2.0 * lam;
                    jac[(2 * np, n + a)] = -2.0 * t;
                    jac[(n + a, 2 * np)] = -2.0 * t;
                    f[n + a] = s * r[i].norm_sqr() - t * t;
                }
                Some(lim) => f[n + a] = r[i].norm_sqr() - lim * lim,
            }
        }
        (f, jac)
    };
    // multipliers from the stationarity equations at the start
    let mut z = DVector::<f64>::zeros(n + na);
    for q in 0..np {
        z[2 * q] = c_start[q].re;
        z[2 * q + 1] = c_start[q].im;
    }
    z[2 * np] = t0;
    let (_, jac0) = residual(&z);
    let a = jac0.view((0, n), (n, na)).into_owned();
    let mut rhs = DVector::<f64>::zeros(n);
    rhs[2 * np] = -1.0;
    let lam = a.svd(true, true).solve(&rhs, 1e-12).ok()?;
    if lam.iter().any(|&x| x.is_nan() || x <= 0.0) {
        return None;
    }
    z.view_mut((n, 0), (na, 1)).copy_from(&lam);
    for _ in 0..30 {
        let (f, jac) = residual(&z);
        let step = jac.lu().solve(&(-&f))?;
        z += &step;
        // converged: the step is at rounding of the unknowns
        if step.amax() <= 1e-13 * z.amax() {
            let (f, _) = residual(&z);
            let c = DVector::from_fn(np, |q, _| Complex::new(z[2 * q], z[2 * q + 1]) * cs);
            let moved = (&c - c0).norm() / c0.norm().max(f64::MIN_POSITIVE);
            // and no constraint left out of the active set is violated
            let r = r_of(&DVector::from_fn(np, |q, _| {
                Complex::new(z[2 * q], z[2 * q + 1])
            }));
            let t = z[2 * np];
            let feasible = (0..k).all(|i| p.w[i] * r[i].norm() <= t * (1.0 + 1e-9))
                && limits
                    .iter()
                    .enumerate()
                    .all(|(i, l)| l.is_none_or(|l| r[i].norm() <= l / vs * (1.0 + 1e-9)));
            let fine = feasible && f.amax() < 1e-9 * (1.0 + z.amax());
            // the polished point is the solver's, refined: a large move is a wrong active
            // set, and every multiplier stays positive
            return (fine && moved < 1e-3 && z.rows(n, na).iter().all(|&x| x > 0.0)).then_some(c);
        }
    }
    None
}

/// The error of limits that cannot be met, with the factor by which the best correction
/// misses them (module doc).
fn infeasible(
    p: &Problem,
    limits: &[Option<f64>],
    names: &dyn Fn(usize) -> (String, f64),
) -> Result<BalanceError, BalanceError> {
    let np = p.h.ncols();
    let (vs, cs) = scales(p);
    let mut rows = Vec::new();
    let mut b = Vec::new();
    let mut cones = 0;
    for (i, l) in limits.iter().enumerate() {
        if let Some(l) = l {
            cone_rows(p, i, 1.0 / (l / vs), None, (vs, cs), (&mut rows, &mut b));
            cones += 1;
        }
    }
    let Outcome::Solved(x) = solve_socp(1 + 2 * np, rows, b, cones, "the limits' excess")? else {
        return Err(BalanceError::Solver {
            status: "PrimalInfeasible".into(),
            what: "the limits' excess",
        });
    };
    let c = DVector::from_fn(np, |q, _| Complex::new(x[1 + 2 * q], x[2 + 2 * q]) * cs);
    let r = &p.v + &p.h * &c;
    let (worst, ratio) = limits
        .iter()
        .enumerate()
        .filter_map(|(i, l)| l.map(|l| (i, r[i].norm() / l)))
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap_or((0, f64::NAN));
    let (sensor, speed_rpm) = names(worst);
    Ok(BalanceError::LimitsInfeasible {
        factor: ratio,
        sensor,
        speed_rpm,
        predicted: r[worst].norm(),
        limit: limits[worst].unwrap_or(f64::NAN),
    })
}

/// Lawson's algorithm for the unweighted, unconstrained complex Chebyshev problem
/// min_C max_k |V_k + h_k C| (tests: an independent check of the cone program). Weighted
/// least squares with weights u_k, then u_k <- u_k |r_k| / sum_j u_j |r_j|, which
/// converges to the minimax solution (C. L. Lawson, thesis, UCLA, 1961; Rice & Usow, Math.
/// Comp. 22, 1968).
#[cfg(test)]
pub(crate) fn lawson(h: &DMatrix<C64>, v: &DVector<C64>, iterations: usize) -> DVector<C64> {
    let k = h.nrows();
    let mut u = vec![1.0 / k as f64; k];
    let mut c = DVector::zeros(h.ncols());
    for _ in 0..iterations {
        let sw: Vec<f64> = u.iter().map(|x| x.sqrt()).collect();
        let hw = DMatrix::from_fn(k, h.ncols(), |i, j| h[(i, j)] * sw[i]);
        let vw = DVector::from_fn(k, |i, _| v[i] * sw[i]);
        c = -hw.svd(true, true).solve(&vw, 0.0).expect("full rank");
        let r = v + h * &c;
        let s: f64 = u.iter().zip(r.iter()).map(|(a, b)| a * b.norm()).sum();
        for (ui, ri) in u.iter_mut().zip(r.iter()) {
            *ui *= ri.norm() / s;
        }
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;

    fn problem(seed: u64) -> Problem {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut z =
            |s: f64| Complex::new(rng.gen_range(-1.0..1.0) * s, rng.gen_range(-1.0..1.0) * s);
        let h = DMatrix::from_fn(8, 2, |_, _| z(1e6));
        let v = DVector::from_fn(8, |_, _| z(50.0));
        Problem {
            h,
            v,
            w: vec![1.0; 8],
            cov: vec![None; 8],
        }
    }

    #[test]
    fn the_cone_program_matches_lawsons_algorithm() {
        for seed in 0..5 {
            let p = problem(seed);
            let c = min_max(&p, &[None; 8], &|_| (String::new(), 0.0)).unwrap();
            let c2 = lawson(&p.h, &p.v, 20000);
            let peak = |c: &DVector<C64>| {
                (&p.v + &p.h * c)
                    .iter()
                    .fold(0.0f64, |m, z| m.max(z.norm()))
            };
            let (a, b) = (peak(&c), peak(&c2));
            // the optimum value agrees; Lawson converges from above, linearly
            assert!((a - b).abs() < 1e-6 * b, "seed {seed}: {a} vs {b}");
            assert!(a <= b * (1.0 + 1e-9));
            assert!(
                (&c - &c2).norm() < 1e-4 * c.norm(),
                "seed {seed}: {c} vs {c2}"
            );
            // and it beats least squares on the peak
            let ls = super::super::correction::least_squares(&p).unwrap();
            assert!(a <= peak(&ls) * (1.0 + 1e-9));
        }
    }

    #[test]
    fn limits_are_met_or_reported_with_the_factor_missed() {
        let p = problem(7);
        let free = min_max(&p, &[None; 8], &|_| (String::new(), 0.0)).unwrap();
        let r = &p.v + &p.h * &free;
        // a limit on key 0 below its free value: met, at the price of the others
        let target = 0.5 * r[0].norm();
        let mut limits = vec![None; 8];
        limits[0] = Some(target);
        let c = min_max(&p, &limits, &|_| (String::new(), 0.0)).unwrap();
        let r2 = &p.v + &p.h * &c;
        assert!(
            r2[0].norm() <= target * (1.0 + 1e-7),
            "{} > {target}",
            r2[0].norm()
        );
        // impossible limits: every key at 1e-6 of its size
        let limits: Vec<Option<f64>> = p.v.iter().map(|v| Some(1e-6 * v.norm())).collect();
        let e = min_max(&p, &limits, &|k| (format!("s{k}"), 1000.0)).unwrap_err();
        match e {
            BalanceError::LimitsInfeasible { factor, .. } => assert!(factor > 1.0, "{factor}"),
            e => panic!("{e}"),
        }
    }
}
