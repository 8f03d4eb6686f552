//! The modulating (test) functions and their derivatives, tabulated on one window.
//!
//! On a window [t_j, t_j + L] with u = 2 (t - t_j) / L - 1 in [-1, 1]:
//!
//! ```text
//! psi_i(u) = B(u) P_i(u) / n_i,     B(u) = (1 - u^2)^p,  p = SMOOTHNESS = 6,  i = 0 .. F-1
//! ```
//!
//! with P_i the Legendre polynomials and n_i the RMS of B P_i over the window's samples
//! (every row of the least squares gets the same scale). B vanishes with its first p - 1
//! derivatives at u = -1 and u = +1, so every psi_i, psi_i', psi_i'' vanishes at both ends
//! of the window: integrating by parts leaves no boundary term (module docs of
//! [`super`]). Time derivatives are d/dt = (2/L) d/du; this table holds the u-derivatives:
//!
//! ```text
//! B'  = -2 p u (1 - u^2)^(p-1)
//! B'' = -2 p (1 - u^2)^(p-1) + 4 p (p-1) u^2 (1 - u^2)^(p-2)
//! psi' = B' P + B P',   psi'' = B'' P + 2 B' P' + B P''
//! (i+1) P_{i+1}   = (2i+1) u P_i - i P_{i-1}                         (Bonnet)
//! (i+1) P'_{i+1}  = (2i+1) (P_i + u P'_i) - i P'_{i-1}
//! (i+1) P''_{i+1} = (2i+1) (2 P'_i + u P''_i) - i P''_{i-1}
//! ```
//!
//! (recurrences, not expanded monomials, so the values are accurate to a few ulp).
//!
//! Quadrature: the window integrals are the plain sums h sum_k f(t_k) (the composite
//! trapezoid rule, whose end weights 1/2 meet zeros). By Euler-Maclaurin its error is
//! sum_r B_2r h^2r / (2r)! [f^(2r-1)] at the two ends; the integrands f = psi x, psi' x,
//! psi'' x vanish at the ends to orders p, p - 1, p - 2 = 4, so their first and third
//! derivatives vanish there and the first non-zero end term is h^6: sixth order (observed
//! 2^6 when h is halved, `tests/modulating_clean.rs`; with p = 4 it was fourth order,
//! ~1e-8 instead of ~1e-11 on table1 at h = 0.1 ms, L = 20 ms, with the same noise
//! performance). The expansion is asymptotic in h / (period of the signal): the window
//! must hold many samples per period of its highest test function (at least 8 sampling
//! intervals per test function are required).

/// The exponent p of the envelope (1 - u^2)^p.
pub const SMOOTHNESS: i32 = 6;

/// The test functions of one window, tabulated at the window's n + 1 samples.
#[derive(Debug, Clone)]
pub(crate) struct TestFunctions {
    /// Intervals per window (the window has `intervals + 1` samples).
    intervals: usize,
    /// Number of test functions F.
    functions: usize,
    /// `[psi_i, psi_i', psi_i'']` (u-derivatives) at sample offset k, function i:
    /// index `k * functions + i`.
    table: Vec<[f64; 3]>,
    /// Noise Gram of one window: sum_i sum_k g g^T with g = (psi_i'', -psi_i', psi_i)(u_k)
    /// (the regressor weights of one row; module docs of `normal_equations`).
    noise_gram: [[f64; 3]; 3],
}

/// (B, B', B'') at u for B = (1 - u^2)^p.
fn envelope(u: f64) -> [f64; 3] {
    let p = SMOOTHNESS;
    let v = 1.0 - u * u;
    let pf = p as f64;
    [
        v.powi(p),
        -2.0 * pf * u * v.powi(p - 1),
        -2.0 * pf * v.powi(p - 1) + 4.0 * pf * (pf - 1.0) * u * u * v.powi(p - 2),
    ]
}

/// (P_i, P_i', P_i'') at u for i = 0 .. out.len() - 1.
fn legendre(u: f64, out: &mut [[f64; 3]]) {
    let mut prev = [0.0; 3]; // P_{-1} = 0
    let mut cur = [1.0, 0.0, 0.0]; // P_0 = 1
    for (i, o) in out.iter_mut().enumerate() {
        *o = cur;
        let fi = i as f64;
        let a = 2.0 * fi + 1.0;
        let next = [
            (a * u * cur[0] - fi * prev[0]) / (fi + 1.0),
            (a * (cur[0] + u * cur[1]) - fi * prev[1]) / (fi + 1.0),
            (a * (2.0 * cur[1] + u * cur[2]) - fi * prev[2]) / (fi + 1.0),
        ];
        prev = cur;
        cur = next;
    }
}

impl TestFunctions {
    /// Tabulate `functions` test functions on a window of `intervals` sampling intervals
    /// (intervals >= 2, functions >= 1; checked by the caller).
    pub(crate) fn new(intervals: usize, functions: usize) -> Self {
        let n = intervals;
        let mut table = vec![[0.0; 3]; (n + 1) * functions];
        let mut p = vec![[0.0; 3]; functions];
        for k in 0..=n {
            // u exactly -1 and +1 at the ends
            let u = (2 * k) as f64 / n as f64 - 1.0;
            let [b, b1, b2] = envelope(u);
            legendre(u, &mut p);
            for (i, pi) in p.iter().enumerate() {
                table[k * functions + i] = [
                    b * pi[0],
                    b1 * pi[0] + b * pi[1],
                    b2 * pi[0] + 2.0 * b1 * pi[1] + b * pi[2],
                ];
            }
        }
        // unit RMS of psi_i over the window's samples
        for i in 0..functions {
            let ss: f64 = (0..=n).map(|k| table[k * functions + i][0].powi(2)).sum();
            let scale = ((n + 1) as f64 / ss).sqrt();
            for k in 0..=n {
                for v in table[k * functions + i].iter_mut() {
                    *v *= scale;
                }
            }
        }
        let mut noise_gram = [[0.0; 3]; 3];
        for e in &table {
            let g = [e[2], -e[1], e[0]];
            for r in 0..3 {
                for c in 0..3 {
                    noise_gram[r][c] += g[r] * g[c];
                }
            }
        }
        Self {
            intervals,
            functions,
            table,
            noise_gram,
        }
    }

    /// Intervals per window.
    pub(crate) fn intervals(&self) -> usize {
        self.intervals
    }

    /// Number of test functions per window.
    pub(crate) fn functions(&self) -> usize {
        self.functions
    }

    /// `[psi_i, psi_i', psi_i'']` (u-derivatives) of every function at sample offset `k`.
    #[inline]
    pub(crate) fn at(&self, k: usize) -> &[[f64; 3]] {
        &self.table[k * self.functions..(k + 1) * self.functions]
    }

    /// The noise Gram of one window (see the field's doc).
    pub(crate) fn noise_gram(&self) -> [[f64; 3]; 3] {
        self.noise_gram
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn functions_and_first_two_derivatives_vanish_at_both_ends() {
        let tf = TestFunctions::new(200, 6);
        for k in [0, 200] {
            for e in tf.at(k) {
                assert_eq!(*e, [0.0, 0.0, 0.0]);
            }
        }
        // and they are not trivially zero inside
        assert!(tf.at(100)[0][0] > 1.0);
    }

    #[test]
    fn derivatives_match_finite_differences() {
        // u-spacing 2 / n; central differences of the table against the tabulated derivative
        let n = 4000;
        let tf = TestFunctions::new(n, 7);
        let du = 2.0 / n as f64;
        for k in [37, 1000, 2001, 3500] {
            for i in 0..7 {
                let (a, b, c) = (tf.at(k - 1)[i], tf.at(k)[i], tf.at(k + 1)[i]);
                let d1 = (c[0] - a[0]) / (2.0 * du);
                let d2 = (c[0] - 2.0 * b[0] + a[0]) / (du * du);
                let scale1 = b[1].abs().max(10.0);
                let scale2 = b[2].abs().max(100.0);
                assert!(
                    (d1 - b[1]).abs() < 1e-4 * scale1,
                    "k {k} i {i}: {d1} vs {}",
                    b[1]
                );
                assert!(
                    (d2 - b[2]).abs() < 1e-3 * scale2,
                    "k {k} i {i}: {d2} vs {}",
                    b[2]
                );
            }
        }
    }

    #[test]
    fn legendre_recurrence_matches_closed_forms() {
        let mut p = [[0.0; 3]; 4];
        let u: f64 = 0.3;
        legendre(u, &mut p);
        assert_eq!(p[0], [1.0, 0.0, 0.0]);
        assert_eq!(p[1], [u, 1.0, 0.0]);
        let p2 = [(3.0 * u * u - 1.0) / 2.0, 3.0 * u, 3.0];
        let p3 = [
            (5.0 * u.powi(3) - 3.0 * u) / 2.0,
            (15.0 * u * u - 3.0) / 2.0,
            15.0 * u,
        ];
        for j in 0..3 {
            assert!((p[2][j] - p2[j]).abs() < 1e-15);
            assert!((p[3][j] - p3[j]).abs() < 1e-14);
        }
    }
}
