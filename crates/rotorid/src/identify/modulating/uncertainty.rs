//! Standard errors of the modulating-function estimate: the sandwich (robust) covariance
//! of least squares with correlated equation errors (White 1980; for overlapping windows,
//! the errors of rows whose windows overlap are correlated and every such pair counts).
//!
//! With theta_s the scaled unknowns of one direction, row r = (phi_r, y_r) and its
//! equation error e_r = phi_r . theta_s - y_r, the estimate theta_s = H^-1 b (H the
//! noise-compensated normal matrix, `normal_equations`) has, to first order in the noise,
//!
//! ```text
//! Cov(theta_s) = H^-1 V H^-1,     V = sum_r sum_r' phi_r phi_r'^T Cov(e_r, e_r').
//! ```
//!
//! The equation error is linear in the white measurement noise n (sd sigma_x on x, sigma_z
//! on z). For the x rows, e_r = sum_k n^x_k (theta_s . g_r(k)) + a (2/L) sum_k psi_r'(k)
//! w_k n^z_k, with g_r = (psi'', -psi', psi) (u-derivatives, `test_functions`); for the z
//! rows, e_r = sum_k n^z_k (theta_s . g_r(k)) - a sum_k ((2/L) w_k psi_r'(k) + w'_k psi_r(k))
//! n^x_k. For two rows of windows that start d samples apart, functions i and i':
//!
//! ```text
//! M_ab(d, i, i') = sum_k T_i,a(k) T_i',b(k - d)          (T = (psi, psi', psi''), tabulated once)
//! x: Cov(e_r, e_r') = sigma_x^2 sum_ab theta_a theta_b s_a s_b M_(c_a c_b)
//!                   + sigma_z^2 a^2 (2/L)^2 w_j w_j' M_11
//! z: Cov(e_r, e_r') = sigma_z^2 sum_ab theta_a theta_b s_a s_b M_(c_a c_b)
//!                   + sigma_x^2 a^2 ((2/L)^2 w_j w_j' M_11 + (2/L) w_j w'_j' M_10
//!                                    + (2/L) w'_j w_j' M_01 + w'_j w'_j' M_00)
//! ```
//!
//! (c = (2, 1, 0), s = (+, -, +) map the unknowns' columns to the table; w and w' are taken
//! at each window's centre: over a 20 ms window of the 10 rad/s^2 ramp w changes by 0.3 %).
//! V is accumulated window by window as the theta-free matrices Q_ab = sum phi_r phi_r'^T
//! s_a s_b M_(c_a c_b) and Qc = sum phi_r phi_r'^T (coupling coefficient), so that at the
//! end V = sigma_own^2 sum_ab theta_a theta_b Q_ab + sigma_other^2 Qc. The measured
//! (noisy) phi_r stand in for the noise-free ones, and terms of order sigma^4 are
//! neglected: the standard errors are asymptotic (first order), like the CRB.

use std::collections::VecDeque;

use super::test_functions::TestFunctions;

/// Column of the table (psi, psi', psi'') and sign for each unknown (m, c, k): the row is
/// (psi'', -psi', psi).
const COLUMN: [(usize, f64); 3] = [(2, 1.0), (1, -1.0), (0, 1.0)];

/// The overlap sums M_ab(d, i, i') for d = lag * hop, lag = 0 .. lags - 1.
#[derive(Debug, Clone)]
pub(crate) struct Overlaps {
    functions: usize,
    lags: usize,
    m: Vec<[[f64; 3]; 3]>,
}

impl Overlaps {
    /// Tabulate for windows of `tf` started every `hop` samples.
    pub(crate) fn new(tf: &TestFunctions, hop: usize) -> Self {
        let n = tf.intervals();
        let f = tf.functions();
        let lags = n / hop + 1;
        let mut m = vec![[[0.0; 3]; 3]; lags * f * f];
        for lag in 0..lags {
            let d = lag * hop;
            for k in d..=n {
                let (early, late) = (tf.at(k), tf.at(k - d));
                for i in 0..f {
                    for j in 0..f {
                        let e = &mut m[(lag * f + i) * f + j];
                        for a in 0..3 {
                            for b in 0..3 {
                                e[a][b] += early[i][a] * late[j][b];
                            }
                        }
                    }
                }
            }
        }
        Self {
            functions: f,
            lags,
            m,
        }
    }

    /// Number of lags tabulated (windows that start within one window length).
    pub(crate) fn lags(&self) -> usize {
        self.lags
    }

    /// Test functions per window.
    pub(crate) fn functions(&self) -> usize {
        self.functions
    }

    /// M(lag hop, i, j): `[a][b]` = sum_k T_i,a(k) T_j,b(k - lag hop), T = (psi, psi',
    /// psi'') of the early window's function i and the late one's j.
    #[inline]
    pub(crate) fn get(&self, lag: usize, i: usize, j: usize) -> &[[f64; 3]; 3] {
        &self.m[(lag * self.functions + i) * self.functions + j]
    }
}

/// A completed window as the covariance needs it (P regressors per row).
#[derive(Debug, Clone)]
pub(crate) struct ClosedWindow<const P: usize> {
    /// Index of its first sample.
    pub start: u64,
    /// phi of each test function, x rows then z rows.
    pub phi: [Vec<[f64; P]>; 2],
    /// w \[rad/s\] at the window's centre.
    pub w: f64,
    /// w' \[rad/s^2\] at the window's centre.
    pub w_dot: f64,
}

/// Pair the window `done`, just completed, with the completed windows it overlaps: drop
/// from `closed` those it no longer reaches (starts more than `reach` samples apart), call
/// `add(early, &done, lag)` for each one within the `lags` tabulated (lag in hops of `hop`
/// samples), then `add(&done, &done, 0)`, and keep `done` for the windows to come.
pub(crate) fn pair_overlapping<const P: usize>(
    closed: &mut VecDeque<ClosedWindow<P>>,
    done: ClosedWindow<P>,
    reach: u64,
    hop: u64,
    lags: usize,
    mut add: impl FnMut(&ClosedWindow<P>, &ClosedWindow<P>, usize),
) {
    while closed.front().is_some_and(|c| done.start - c.start > reach) {
        closed.pop_front();
    }
    for early in closed.iter() {
        let lag = ((done.start - early.start) / hop) as usize;
        if lag < lags {
            add(early, &done, lag);
        }
    }
    add(&done, &done, 0);
    closed.push_back(done);
}

/// The theta-free parts of V for one direction (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct Meat {
    q: [[[[f64; 3]; 3]; 3]; 3],
    qc: [[f64; 3]; 3],
}

/// Add c (u v^T + v u^T) to `acc` when `both`, else c u v^T.
#[inline]
fn add_outer(acc: &mut [[f64; 3]; 3], c: f64, u: &[f64; 3], v: &[f64; 3], both: bool) {
    for r in 0..3 {
        for s in 0..3 {
            acc[r][s] += c * if both {
                u[r] * v[s] + v[r] * u[s]
            } else {
                u[r] * v[s]
            };
        }
    }
}

/// Add the pairs of rows of windows `early` and `late` (the same window when `lag` = 0)
/// to the x and z meats. `a` \[N s^2/m\] is the gyroscopic coefficient, `two_l` = 2 / L
/// \[1/s\].
pub(crate) fn add_pair(
    meat: &mut [Meat; 2],
    ov: &Overlaps,
    early: &ClosedWindow<3>,
    late: &ClosedWindow<3>,
    lag: usize,
    a: f64,
    two_l: f64,
) {
    let both = lag > 0;
    let f = ov.functions;
    for i in 0..f {
        for j in 0..f {
            let m = ov.get(lag, i, j);
            let ww = two_l * two_l * early.w * late.w;
            let cx = a * a * ww * m[1][1];
            let cz = a
                * a
                * (ww * m[1][1]
                    + two_l * early.w * late.w_dot * m[1][0]
                    + two_l * early.w_dot * late.w * m[0][1]
                    + early.w_dot * late.w_dot * m[0][0]);
            for (dir, c) in [(0, cx), (1, cz)] {
                let (u, v) = (&early.phi[dir][i], &late.phi[dir][j]);
                let acc = &mut meat[dir];
                for (p, &(ca, sa)) in COLUMN.iter().enumerate() {
                    for (q, &(cb, sb)) in COLUMN.iter().enumerate() {
                        add_outer(&mut acc.q[p][q], sa * sb * m[ca][cb], u, v, both);
                    }
                }
                add_outer(&mut acc.qc, c, u, v, both);
            }
        }
    }
}

impl Meat {
    /// V = sigma_own^2 sum_ab theta_a theta_b Q_ab + sigma_other^2 Qc.
    pub(crate) fn combine(
        &self,
        theta: &[f64; 3],
        sigma_own: f64,
        sigma_other: f64,
    ) -> [[f64; 3]; 3] {
        let (so, st) = (sigma_own * sigma_own, sigma_other * sigma_other);
        std::array::from_fn(|r| {
            std::array::from_fn(|s| {
                let mut acc = st * self.qc[r][s];
                for (p, tp) in theta.iter().enumerate() {
                    for (q, tq) in theta.iter().enumerate() {
                        acc += so * tp * tq * self.q[p][q][r][s];
                    }
                }
                acc
            })
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overlap_at_lag_zero_is_the_window_gram() {
        let tf = TestFunctions::new(96, 3);
        let ov = Overlaps::new(&tf, 12);
        assert_eq!(ov.lags(), 9);
        // lag 0, the psi'' and psi columns of function 0 and 2
        let direct: f64 = (0..=96).map(|k| tf.at(k)[0][2] * tf.at(k)[2][0]).sum();
        assert!((ov.get(0, 0, 2)[2][0] - direct).abs() < 1e-12 * direct.abs().max(1.0));
        // lag 3 (36 samples): the early window's sample k meets the late one's k - 36
        let direct: f64 = (36..=96)
            .map(|k| tf.at(k)[1][1] * tf.at(k - 36)[0][1])
            .sum();
        assert!((ov.get(3, 1, 0)[1][1] - direct).abs() < 1e-12 * direct.abs().max(1.0));
    }
}
