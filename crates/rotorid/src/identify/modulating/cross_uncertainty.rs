//! Standard errors of the cross-coupled modulating estimate: the sandwich covariance of
//! the least squares with correlated equation errors (as module `uncertainty` for the
//! Jeffcott rows, generalised to five unknowns whose equation errors hold both channels'
//! noise in the regressors and in the right-hand side).
//!
//! With theta_s the scaled unknowns of one row (module `cross`), row r = (phi_r, y_r) of
//! window j and function i, and e_r = phi_r . theta_s - y_r:
//!
//! ```text
//! Cov(theta_s) = H^-1 V H^-1,     V = sum_r sum_r' phi_r phi_r'^T Cov(e_r, e_r')
//! ```
//!
//! e_r is linear in the white noise of both channels, e_r = sum_c sum_k n^c_k
//! beta_rc . T_i(k), T = (psi, psi', psi'') (u-derivatives, tabulated), with the
//! coefficients (w, w' at the window's centre, 2/L written l):
//!
//! ```text
//! x row, x noise:  beta = ( th3,            -th1,             th0 )   (m_x, cxx, kxx)
//! x row, z noise:  beta = ( th4,            -th2 + a l w,     0   )   (cxz, kxz, gyroscopic)
//! z row, x noise:  beta = ( th3 - a w',     -th1 - a l w,     0   )   (czx, kzx, gyroscopic)
//! z row, z noise:  beta = ( th4,            -th2,             th0 )   (m_z, czz, kzz)
//! ```
//!
//! Each beta is B(j) t, with t three entries of (theta_s, 1) (the "active" unknowns of that
//! row and channel) and B(j) a 3x3 matrix of the window's speed. For two rows of windows
//! that start d samples apart, with M_ab(d, i, i') = sum_k T_i,a(k) T_i',b(k - d) (the
//! table of module `uncertainty`),
//!
//! ```text
//! Cov(e_r, e_r') = sum_c sigma_c^2 t_c^T K_c t_c,     K_c = B_c(j)^T M(d, i, i') B_c(j')
//! V = sum_c sigma_c^2 sum_pq t_cp t_cq W_cpq,        W_cpq = sum_(r,r') K_c,pq phi_r phi_r'^T
//! ```
//!
//! The theta-free W_cpq are accumulated window by window; since V is symmetric only the
//! symmetric parts are kept (p <= q, upper triangle of each 5x5). The measured phi_r stand
//! in for the noise-free ones and O(sigma^4) terms are dropped: first order, like the CRB.

use super::cross::P5;
use super::uncertainty::{ClosedWindow, Overlaps};

/// Entries of the upper triangle of a 5x5 matrix.
const TRI: usize = P5 * (P5 + 1) / 2;
/// Pairs p <= q of three active unknowns.
const PAIRS: [(usize, usize); 6] = [(0, 0), (0, 1), (0, 2), (1, 1), (1, 2), (2, 2)];
/// Index 5 of (theta_s, 1): the constant.
const ONE: usize = P5;

/// Which entries of (theta_s, 1) enter the noise coefficient of [row][channel].
const ACTIVE: [[[usize; 3]; 2]; 2] = [[[0, 1, 3], [2, 4, ONE]], [[1, 3, ONE], [0, 2, 4]]];

/// B of [row][channel] for a window with speed `w`, acceleration `wd`; `al` = a (2/L),
/// `a` the gyroscopic coefficient. Rows: psi, psi', psi''; columns: the active unknowns.
fn b_matrix(row: usize, ch: usize, w: f64, wd: f64, a: f64, al: f64) -> [[f64; 3]; 3] {
    match (row, ch) {
        // th0 psi'' - th1 psi' + th3 psi, and the z row's th0 psi'' - th2 psi' + th4 psi
        (0, 0) | (1, 1) => [[0.0, 0.0, 1.0], [0.0, -1.0, 0.0], [1.0, 0.0, 0.0]],
        // th4 psi + (-th2 + a l w) psi'
        (0, _) => [[0.0, 1.0, 0.0], [-1.0, 0.0, al * w], [0.0; 3]],
        // (th3 - a w') psi + (-th1 - a l w) psi'
        _ => [[0.0, 1.0, -a * wd], [-1.0, 0.0, -al * w], [0.0; 3]],
    }
}

/// The theta-free parts of V for one row (module docs): `w[c][pair]`, packed upper
/// triangles ([`packed`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct CrossMeat {
    w: [[[f64; TRI]; 6]; 2],
}

impl Default for CrossMeat {
    fn default() -> Self {
        Self {
            w: [[[0.0; TRI]; 6]; 2],
        }
    }
}

/// Index of entry (r, s) of a symmetric 5x5 matrix in its packed upper triangle (row by
/// row: (0, 0) .. (0, 4), (1, 1) .. (1, 4), ..).
#[inline]
fn packed(r: usize, s: usize) -> usize {
    let (a, b) = if r <= s { (r, s) } else { (s, r) };
    a * (2 * P5 - a + 1) / 2 + (b - a)
}

/// The packed upper triangle of u v^T + v u^T.
#[inline]
fn sym_outer(u: &[f64; P5], v: &[f64; P5]) -> [f64; TRI] {
    let mut o = [0.0; TRI];
    for (r, (ur, vr)) in u.iter().zip(v).enumerate() {
        for (s, (us, vs)) in u.iter().zip(v).enumerate().skip(r) {
            o[packed(r, s)] = ur * vs + vr * us;
        }
    }
    o
}

/// Add the pairs of rows of windows `early` and `late` (the same window when `lag` = 0)
/// to the x and z meats. `a` \[N s^2/m\] is the gyroscopic coefficient, `two_l` = 2 / L
/// \[1/s\].
pub(crate) fn add_cross_pair(
    meat: &mut [CrossMeat; 2],
    ov: &Overlaps,
    early: &ClosedWindow<P5>,
    late: &ClosedWindow<P5>,
    lag: usize,
    a: f64,
    two_l: f64,
) {
    let f = ov.functions();
    let al = a * two_l;
    // B for each row and channel, early and late window
    let bs = |win: &ClosedWindow<P5>| -> [[[[f64; 3]; 3]; 2]; 2] {
        std::array::from_fn(|row| {
            std::array::from_fn(|ch| b_matrix(row, ch, win.w, win.w_dot, a, al))
        })
    };
    let (be, bl) = (bs(early), bs(late));
    for i in 0..f {
        // at lag 0 the pair (i, j) and (j, i) give the same symmetric term: take i <= j once,
        // the diagonal at half weight (sym_outer doubles)
        let j0 = if lag == 0 { i } else { 0 };
        for j in j0..f {
            let m = ov.get(lag, i, j);
            let weight = if lag == 0 && i == j { 0.5 } else { 1.0 };
            for (row, meat_row) in meat.iter_mut().enumerate() {
                let o = sym_outer(&early.phi[row][i], &late.phi[row][j]);
                for (ch, wc) in meat_row.w.iter_mut().enumerate() {
                    let (b1, b2) = (&be[row][ch], &bl[row][ch]);
                    // K = B1^T M B2 (3x3 in the active unknowns)
                    let mut mb = [[0.0; 3]; 3];
                    for (ra, mrow) in m.iter().enumerate() {
                        for q in 0..3 {
                            mb[ra][q] =
                                mrow[0] * b2[0][q] + mrow[1] * b2[1][q] + mrow[2] * b2[2][q];
                        }
                    }
                    let k = |p: usize, q: usize| {
                        b1[0][p] * mb[0][q] + b1[1][p] * mb[1][q] + b1[2][p] * mb[2][q]
                    };
                    for (pair, &(p, q)) in PAIRS.iter().enumerate() {
                        let kpq = if p == q { k(p, p) } else { k(p, q) + k(q, p) };
                        let c = weight * kpq;
                        if c != 0.0 {
                            for (acc, ov) in wc[pair].iter_mut().zip(o.iter()) {
                                *acc += c * ov;
                            }
                        }
                    }
                }
            }
        }
    }
}

impl CrossMeat {
    /// V (5x5) of row `row` for the scaled estimate `theta` and noise levels
    /// `sigma` = (sigma_x, sigma_z) \[m\].
    pub(crate) fn combine(
        &self,
        row: usize,
        theta: &[f64; P5],
        sigma: [f64; 2],
    ) -> [[f64; P5]; P5] {
        let ext = |i: usize| if i == ONE { 1.0 } else { theta[i] };
        let mut tri = [0.0; TRI];
        for (ch, wc) in self.w.iter().enumerate() {
            let act = ACTIVE[row][ch];
            let s2 = sigma[ch] * sigma[ch];
            for (pair, &(p, q)) in PAIRS.iter().enumerate() {
                let c = s2 * ext(act[p]) * ext(act[q]);
                for (acc, v) in tri.iter_mut().zip(wc[pair].iter()) {
                    *acc += c * v;
                }
            }
        }
        std::array::from_fn(|r| std::array::from_fn(|s| tri[packed(r, s)]))
    }
}
