//! The correction for the current run and its uncertainty.
//!
//! With the influence matrix H (K keys x P planes), the current run's vectors V (K) and a
//! weight w_k per key (a sensor's weight), the correction C (P, \[kg m\]) leaves the
//! predicted residual r = V + H C.
//!
//! **Least squares**: C minimises sum_k w_k^2 |r_k|^2; with Hw = diag(w) H, Vw = diag(w) V,
//! C = -pinv(Hw) Vw (complex SVD; a smallest singular value below 1e-10 of the largest is
//! an undetermined correction). The condition number of Hw, sigma_max / sigma_min, says how
//! well the planes can be told apart: a relative error e in the vectors can become a
//! relative error up to cond * e in C.
//!
//! **Min-max**: C minimises max_k w_k |r_k| subject to |r_k| <= limit_k (minmax module).
//!
//! **Uncertainty** (delta method): the parameters are q = (H_k, V_k) per key, real and
//! imaginary parts, with the covariance of each key's block from the influence fit (the
//! fitted H and the current V are both linear maps of the measured vectors, so when the
//! current run is a calibration run the correlation of its V with H is kept; different keys
//! are independent). For least squares the derivative is exact: from the normal equations
//! Hw^H (Vw + Hw C) = 0,
//!
//! ```text
//! dC = -N^-1 [ w_k^2 h_k^H (dV_k + dh_k C) + w_k^2 dh_k^H r_k ],    N = Hw^H Hw
//! dr_j = delta_jk (dV_k + dh_k C) + h_j dC
//! ```
//!
//! for a change of row h_k or of V_k; for min-max it is taken by central differences of the
//! solver (steps of 1e-6 of the largest |H| or |V|, of the solution polished on its active
//! set; the solution is piecewise smooth).
//! Cov(C) = J Cov(q) J^T and likewise for r. Reference: Casella & Berger, *Statistical
//! Inference*, 2nd ed., 2002, sec. 5.5.4.

use nalgebra::{Complex, DMatrix, DVector, Matrix2};

use super::error::BalanceError;
use crate::analysis::modes::C64;

/// Smallest singular value accepted, relative to the largest, of the weighted influence
/// matrix.
const RANK_TOLERANCE: f64 = 1e-10;

/// Relative step of the central differences of the min-max correction.
const FD_STEP: f64 = 1e-6;

/// The correction problem (module doc): one row per key with a current vector.
#[derive(Debug, Clone)]
pub(crate) struct Problem {
    /// H, K x P \[sensor unit / (kg m)\].
    pub h: DMatrix<C64>,
    /// V, K \[sensor unit\].
    pub v: DVector<C64>,
    /// w_k, K (> 0).
    pub w: Vec<f64>,
    /// Covariance of (Re H_k1, Im H_k1, ..., Re H_kP, Im H_kP, Re V_k, Im V_k) per key,
    /// when known.
    pub cov: Vec<Option<DMatrix<f64>>>,
}

/// A correction with the Jacobians of C and r over q.
#[derive(Debug, Clone)]
pub(crate) struct Solved {
    /// C, P \[kg m\].
    pub c: DVector<C64>,
    /// r = V + H C, K \[sensor unit\].
    pub r: DVector<C64>,
    /// Covariance of (Re C_1, Im C_1, ...), 2P x 2P, when every key's is known.
    pub cov_c: Option<DMatrix<f64>>,
    /// Covariance of (Re r_1, Im r_1, ...), 2K x 2K, likewise.
    pub cov_r: Option<DMatrix<f64>>,
}

/// The singular values of the weighted influence matrix, largest first.
pub(crate) fn singular_values(p: &Problem) -> (Vec<f64>, DMatrix<C64>) {
    let hw = weighted(p);
    let svd = hw.svd(false, true);
    let mut s: Vec<(f64, usize)> = svd
        .singular_values
        .iter()
        .copied()
        .enumerate()
        .map(|(i, v)| (v, i))
        .collect();
    s.sort_by(|a, b| b.0.total_cmp(&a.0));
    let vt = svd.v_t.expect("asked for");
    // rows of v_t reordered like the values: row i is the right singular vector i
    let order: Vec<usize> = s.iter().map(|x| x.1).collect();
    let vt = DMatrix::from_fn(vt.nrows(), vt.ncols(), |i, j| vt[(order[i], j)]);
    (s.into_iter().map(|x| x.0).collect(), vt)
}

fn weighted(p: &Problem) -> DMatrix<C64> {
    DMatrix::from_fn(p.h.nrows(), p.h.ncols(), |i, j| p.h[(i, j)] * p.w[i])
}

/// The least-squares correction (module doc).
pub(crate) fn least_squares(p: &Problem) -> Result<DVector<C64>, BalanceError> {
    let (k, np) = p.h.shape();
    if k < np {
        return Err(BalanceError::CorrectionUndetermined {
            keys: k,
            planes: np,
            why: "there must be at least as many vectors as planes".into(),
        });
    }
    let hw = weighted(p);
    let vw = DVector::from_fn(k, |i, _| p.v[i] * p.w[i]);
    let svd = hw.svd(true, true);
    let smax = svd.singular_values.max();
    let smin = svd.singular_values.min();
    if !(smax > 0.0 && smin > RANK_TOLERANCE * smax) {
        return Err(BalanceError::CorrectionUndetermined {
            keys: k,
            planes: np,
            why: "the planes act alike on every sensor and speed (the influence matrix is singular): drop a plane".into(),
        });
    }
    let c = svd
        .solve(&vw, 0.0)
        .map_err(|e| BalanceError::CorrectionUndetermined {
            keys: k,
            planes: np,
            why: e.to_string(),
        })?;
    Ok(-c)
}

/// The number of real parameters q of `p`.
fn nq(p: &Problem) -> usize {
    p.h.nrows() * 2 * (p.h.ncols() + 1)
}

/// A unit change of parameter `j` of q: (key, Some(plane) or None for V, the complex
/// change 1 or i).
fn direction(p: &Problem, j: usize) -> (usize, Option<usize>, C64) {
    let per = 2 * (p.h.ncols() + 1);
    let (k, rem) = (j / per, j % per);
    let d = if rem % 2 == 0 {
        Complex::new(1.0, 0.0)
    } else {
        Complex::new(0.0, 1.0)
    };
    let which = rem / 2;
    (k, (which < p.h.ncols()).then_some(which), d)
}

/// Jacobian of (Re C, Im C) over q for the least-squares correction (module doc).
fn ls_jacobian(p: &Problem, c: &DVector<C64>, r: &DVector<C64>) -> Option<DMatrix<f64>> {
    let np = p.h.ncols();
    let hw = weighted(p);
    let n = hw.adjoint() * &hw;
    let ninv = n.try_inverse()?;
    let mut jac = DMatrix::<f64>::zeros(2 * np, nq(p));
    for j in 0..nq(p) {
        let (k, plane, d) = direction(p, j);
        let w2 = p.w[k] * p.w[k];
        let hk = p.h.row(k);
        // dV + dh C, and dh^H r
        let (change, term2) = match plane {
            Some(q) => {
                let mut t2 = DVector::<C64>::zeros(np);
                t2[q] = d.conj() * r[k] * w2;
                (d * c[q], t2)
            }
            None => (d, DVector::<C64>::zeros(np)),
        };
        let term1 = hk.adjoint() * (change * w2);
        let dc = -(&ninv * (term1 + term2));
        for q in 0..np {
            jac[(2 * q, j)] = dc[q].re;
            jac[(2 * q + 1, j)] = dc[q].im;
        }
    }
    Some(jac)
}

/// Jacobian of (Re C, Im C) over q by central differences of `solve` (min-max).
fn fd_jacobian(p: &Problem, solve: Solver<'_>) -> Result<DMatrix<f64>, BalanceError> {
    let np = p.h.ncols();
    let hmax = p.h.iter().fold(0.0f64, |m, z| m.max(z.norm()));
    let vmax = p.v.iter().fold(0.0f64, |m, z| m.max(z.norm()));
    let mut jac = DMatrix::<f64>::zeros(2 * np, nq(p));
    for j in 0..nq(p) {
        let (k, plane, d) = direction(p, j);
        let step = FD_STEP * if plane.is_some() { hmax } else { vmax };
        if step <= 0.0 {
            continue;
        }
        let bump = |sign: f64| {
            let mut q = p.clone();
            match plane {
                Some(pl) => q.h[(k, pl)] += d * (sign * step),
                None => q.v[k] += d * (sign * step),
            }
            solve(&q)
        };
        let (up, dn) = (bump(1.0)?, bump(-1.0)?);
        for q in 0..np {
            let g = (up[q] - dn[q]) / (2.0 * step);
            jac[(2 * q, j)] = g.re;
            jac[(2 * q + 1, j)] = g.im;
        }
    }
    Ok(jac)
}

/// Jacobian of (Re r, Im r) over q, from that of C.
fn residual_jacobian(p: &Problem, c: &DVector<C64>, jc: &DMatrix<f64>) -> DMatrix<f64> {
    let (k, np) = p.h.shape();
    let mut jr = DMatrix::<f64>::zeros(2 * k, nq(p));
    for j in 0..nq(p) {
        let (kk, plane, d) = direction(p, j);
        let dc =
            DVector::<C64>::from_fn(np, |q, _| Complex::new(jc[(2 * q, j)], jc[(2 * q + 1, j)]));
        for i in 0..k {
            let mut dr = (p.h.row(i) * &dc)[0];
            if i == kk {
                dr += match plane {
                    Some(q) => d * c[q],
                    None => d,
                };
            }
            jr[(2 * i, j)] = dr.re;
            jr[(2 * i + 1, j)] = dr.im;
        }
    }
    jr
}

/// J Cov(q) J^T with Cov(q) block diagonal per key; `None` when a key's block is unknown
/// and J depends on it.
fn propagate(p: &Problem, jac: &DMatrix<f64>) -> Option<DMatrix<f64>> {
    let per = 2 * (p.h.ncols() + 1);
    let mut out = DMatrix::<f64>::zeros(jac.nrows(), jac.nrows());
    for (k, block) in p.cov.iter().enumerate() {
        let jk = jac.columns(k * per, per);
        match block {
            Some(s) => out += jk * s * jk.transpose(),
            None if jk.iter().all(|v| *v == 0.0) => {}
            None => return None,
        }
    }
    out.iter().all(|v| v.is_finite()).then_some(out)
}

/// A solver of a correction problem (the min-max one).
pub(crate) type Solver<'a> = &'a dyn Fn(&Problem) -> Result<DVector<C64>, BalanceError>;

/// Solve `p` by least squares, or by `minmax` when given, and propagate the uncertainty
/// (module doc).
pub(crate) fn solve(p: &Problem, minmax: Option<Solver<'_>>) -> Result<Solved, BalanceError> {
    let c = match minmax {
        Some(f) => f(p)?,
        None => least_squares(p)?,
    };
    let r = &p.v + &p.h * &c;
    let any_cov = p.cov.iter().any(Option::is_some);
    let jc = if !any_cov {
        None
    } else {
        match minmax {
            Some(f) => Some(fd_jacobian(p, f)?),
            None => ls_jacobian(p, &c, &r),
        }
    };
    let (cov_c, cov_r) = match &jc {
        Some(jc) => {
            let jr = residual_jacobian(p, &c, jc);
            (propagate(p, jc), propagate(p, &jr))
        }
        None => (None, None),
    };
    Ok(Solved { c, r, cov_c, cov_r })
}

/// The 2x2 block `i` of a covariance of stacked complex numbers.
pub(crate) fn block(cov: &DMatrix<f64>, i: usize) -> Matrix2<f64> {
    cov.fixed_view::<2, 2>(2 * i, 2 * i).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn problem() -> Problem {
        let h = DMatrix::from_row_slice(
            4,
            2,
            &[
                Complex::new(3e5, 1e5),
                Complex::new(-5e4, 2e4),
                Complex::new(1e5, -2e5),
                Complex::new(2e5, 1e5),
                Complex::new(-1e5, 4e4),
                Complex::new(3e5, -2e5),
                Complex::new(5e4, 5e4),
                Complex::new(1e5, 2e5),
            ],
        );
        let v = DVector::from_column_slice(&[
            Complex::new(20.0, -5.0),
            Complex::new(-3.0, 12.0),
            Complex::new(8.0, 8.0),
            Complex::new(-10.0, 2.0),
        ]);
        let cov = (0..4)
            .map(|k| Some(DMatrix::<f64>::identity(6, 6) * (1.0 + k as f64) * 1e-2))
            .collect();
        Problem {
            h,
            v,
            w: vec![1.0, 2.0, 0.5, 1.0],
            cov,
        }
    }

    #[test]
    fn the_least_squares_jacobian_matches_central_differences() {
        let p = problem();
        let c = least_squares(&p).unwrap();
        let r = &p.v + &p.h * &c;
        let exact = ls_jacobian(&p, &c, &r).unwrap();
        let fd = fd_jacobian(&p, &least_squares).unwrap();
        let scale = exact.amax();
        assert!(
            (&exact - &fd).amax() < 1e-6 * scale,
            "{}",
            (&exact - &fd).amax() / scale
        );
        // and the normal equations hold: Hw^H rw = 0
        let hw = weighted(&p);
        let rw = DVector::from_fn(4, |i, _| r[i] * p.w[i]);
        assert!((hw.adjoint() * rw).camax() < 1e-9 * hw.camax() * p.v.camax());
    }
}
