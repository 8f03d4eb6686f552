//! The 3x3 system of the paper's eqs. (7)-(8) (docs/method.md sections 3.4 and 3.6), scaled
//! and solved at one instant, with its conditioning:
//!
//! ```text
//! A theta = b,    A = [p; I1[p]; I2[p]],  b = [s; I1[s]; I2[s]],  theta = (m, c, k)
//! ```
//!
//! Row i of A carries a weight ~ tau^(2+i) and the columns multiply unknowns of very
//! different sizes (m ~ 10 kg, c ~ 10 N s/m, k ~ 1e6 N/m), so A is solved after scaling:
//!
//! ```text
//! A1 = T A,      T  = diag(1, 2^-e, 2^-2e),  2^e <= tau < 2^(e+1)    (row weights ~ tau^-i)
//! As = A1 Dc,    Dc = diag(2^-f_j),  1 <= max_i |As_ij| < 2         (column equilibration)
//! theta = Dc As^-1 T b                                              (As^-1 by the adjugate)
//! rcond = 1 / (||As||_1 ||As^-1||_1)                                (exact, not an estimate)
//! ```
//!
//! All factors are powers of 2 (as LAPACK's `dgeequb`): the scaling is exact and found from
//! exponent bits, without a division; the whole solve costs one division. (An exact
//! power-of-2 scaling does not change the rounding of the adjugate solution at all: it is
//! there to keep products in range and to define rcond.)
//!
//! rcond is the reciprocal 1-norm condition number of the scaled matrix As, in [0, 1]:
//! 1 for a perfectly conditioned system, ~1e-16 at the edge of singularity in f64. Through
//! Dc it does not depend on the units of m, c, k, nor on the scale of the signal (a common
//! factor in A). A singular or non-finite system gives theta = NaN and rcond = 0; this never
//! panics and is not an error.

use nalgebra::{Matrix3, Vector3};

use super::simd::F2;

/// The solution of one scaled 3x3 system.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScaledSolution {
    /// theta = (m \[kg\], c \[N s/m\], k \[N/m\]); NaN when the system is singular.
    pub theta: Vector3<f64>,
    /// Reciprocal 1-norm condition number of the scaled matrix (module docs), in [0, 1];
    /// 0 when singular.
    pub rcond: f64,
}

/// Solve `a theta = b` at `tau` = t - t_0 \[s\] (finite, > 0; anything else gives the
/// singular answer) with the scaling of the module docs.
pub fn solve_scaled(a: &Matrix3<f64>, b: &Vector3<f64>, tau: f64) -> ScaledSolution {
    if !(tau > 0.0 && tau.is_finite()) {
        return ScaledSolution {
            theta: Vector3::from_element(f64::NAN),
            rcond: 0.0,
        };
    }
    // Lane 0 holds the system, lane 1 a copy.
    let rows = [0, 1, 2].map(|i| [0, 1, 2].map(|j| F2::splat(a[(i, j)])));
    let (theta, rcond) = solve3(&rows, &[0, 1, 2].map(|i| F2::splat(b[i])), recip_pow2(tau));
    ScaledSolution {
        theta: Vector3::new(
            theta[0].to_array()[0],
            theta[1].to_array()[0],
            theta[2].to_array()[0],
        ),
        rcond: rcond.to_array()[0],
    }
}

/// 2^-e for x = f 2^e with f in [1, 2) (x > 0 normal), from the exponent bits.
#[inline(always)]
pub(crate) fn recip_pow2(x: f64) -> f64 {
    F2::splat(x).recip_pow2().to_array()[0]
}

/// max(|a|, |b|, |c|) (no NaN handling: a NaN ends as a NaN solution anyway)
#[inline(always)]
fn abs_max(a: F2, b: F2, c: F2) -> F2 {
    a.abs().max(b.abs()).max(c.abs())
}

/// |a| + |b| + |c|
#[inline(always)]
fn abs_sum(a: F2, b: F2, c: F2) -> F2 {
    a.abs() + b.abs() + c.abs()
}

/// Solve the x and z systems at once (lane 0 and lane 1 of every entry): `a[i][j]`,
/// `b[i]`, with `p` = 2^-e, 2^e <= tau < 2^(e+1) (see [`recip_pow2`]); returns
/// (`theta[j]`, `rcond`), NaN / 0 in a singular lane.
#[inline(always)]
pub(crate) fn solve3(a: &[[F2; 3]; 3], b: &[F2; 3], p: f64) -> ([F2; 3], F2) {
    // A1 = T A, T b with T = diag(1, p, p^2) (powers of 2: exact).
    let t = [F2::splat(1.0), F2::splat(p), F2::splat(p * p)];
    let mut m: [[F2; 3]; 3] = std::array::from_fn(|i| a[i].map(|e| e * t[i]));
    let v: [F2; 3] = std::array::from_fn(|i| b[i] * t[i]);
    // As = A1 Dc (powers of 2: exact): columns' largest entries into [1, 2). 2^-e comes from
    // the exponent bits (2^1023 for a subnormal; -inf for inf or NaN, which then makes the
    // system singular): no division, no branch.
    let dc: [F2; 3] = std::array::from_fn(|j| abs_max(m[0][j], m[1][j], m[2][j]).recip_pow2());
    for row in m.iter_mut() {
        for (e, d) in row.iter_mut().zip(dc.iter()) {
            *e = *e * *d;
        }
    }
    // Cofactors: cof[i][j] = (-1)^(i+j) minor_ij; As^-1 = cof^T / det.
    let x = |i: usize, j: usize| m[i][j];
    let cof = [
        [
            x(1, 1) * x(2, 2) - x(1, 2) * x(2, 1),
            x(1, 2) * x(2, 0) - x(1, 0) * x(2, 2),
            x(1, 0) * x(2, 1) - x(1, 1) * x(2, 0),
        ],
        [
            x(0, 2) * x(2, 1) - x(0, 1) * x(2, 2),
            x(0, 0) * x(2, 2) - x(0, 2) * x(2, 0),
            x(0, 1) * x(2, 0) - x(0, 0) * x(2, 1),
        ],
        [
            x(0, 1) * x(1, 2) - x(0, 2) * x(1, 1),
            x(0, 2) * x(1, 0) - x(0, 0) * x(1, 2),
            x(0, 0) * x(1, 1) - x(0, 1) * x(1, 0),
        ],
    ];
    let det = x(0, 0) * cof[0][0] + x(0, 1) * cof[0][1] + x(0, 2) * cof[0][2];
    // ||As||_1 = max column sum; ||adj||_1 = max_j sum_i |cof[j][i]| (= ||As^-1||_1 |det|)
    let col = |j: usize| abs_sum(x(0, j), x(1, j), x(2, j));
    let norm_a = col(0).max(col(1)).max(col(2));
    let row = |c: &[F2; 3]| abs_sum(c[0], c[1], c[2]);
    let norm_adj = row(&cof[0]).max(row(&cof[1])).max(row(&cof[2]));
    // One division: r = 1 / (det ||As|| ||adj||); 1/det = r ||As|| ||adj||,
    // rcond = |det| / (||As|| ||adj||) = det^2 |r|.
    let r = F2::splat(1.0).div(det * norm_a * norm_adj);
    let inv_det = r * norm_a * norm_adj;
    let rcond = det * det * r.abs();
    // theta_i = Dc_i (As^-1 T b)_i = Dc_i sum_j cof[j][i] v_j / det
    let theta: [F2; 3] = std::array::from_fn(|i| {
        dc[i] * ((cof[0][i] * v[0] + cof[1][i] * v[1] + cof[2][i] * v[2]) * inv_det)
    });
    // x * 0 == 0 exactly when x is finite: a NaN anywhere (0 * inf, det = 0, overflow) or
    // rcond <= 0 gives the singular answer (NaN, 0). Branch-free.
    let zero = F2::splat(0.0);
    let finite = theta[0] * zero + theta[1] * zero + theta[2] * zero + rcond * zero;
    let nan = F2::splat(f64::NAN);
    (
        theta.map(|t| t.select_ok(finite, rcond, nan)),
        rcond.min(F2::splat(1.0)).select_ok(finite, rcond, zero),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// rcond of a matrix computed with nalgebra's inverse, for the test.
    fn rcond_ref(m: &Matrix3<f64>) -> f64 {
        let n1 = |x: &Matrix3<f64>| (0..3).map(|j| x.column(j).abs().sum()).fold(0.0, f64::max);
        1.0 / (n1(m) * n1(&m.try_inverse().unwrap()))
    }

    #[test]
    fn solves_a_badly_scaled_system_to_rounding() {
        // Columns scaled like (m, c, k) = (14, 10, 1e6), rows like tau^2..tau^4.
        let theta = Vector3::new(14.29, 10.0, 1.195e6);
        let tau: f64 = 0.05;
        let base = Matrix3::new(1.0, 0.3, -0.2, 0.4, -1.1, 0.5, 0.1, 0.7, 0.9);
        let a =
            Matrix3::from_fn(|i, j| base[(i, j)] * tau.powi(2 + i as i32) * [1e-7, 1e-6, 1e-12][j]);
        let b = a * theta;
        let s = solve_scaled(&a, &b, tau);
        for i in 0..3 {
            assert!(((s.theta[i] - theta[i]) / theta[i]).abs() < 1e-13, "{s:?}");
        }
        // rcond is the scaled matrix's: compare with a direct computation.
        let p2 = |x: f64| 2f64.powi(-(x.log2().floor() as i32));
        assert_eq!(p2(tau), 32.0); // 2^-5 <= 0.05 < 2^-4: the row weight ~ 1/tau
        let a1 = Matrix3::from_fn(|i, j| a[(i, j)] * p2(tau).powi(i as i32));
        let dc = Vector3::from_fn(|j, _| p2(a1.column(j).abs().max()));
        let as_ = Matrix3::from_fn(|i, j| a1[(i, j)] * dc[j]);
        assert!((s.rcond - rcond_ref(&as_)).abs() < 1e-14 * s.rcond, "{s:?}");
        assert!(s.rcond > 0.01 && s.rcond <= 1.0, "{s:?}");
        // Invariant to a common scale and to column scaling (by powers of 2 exactly).
        let scaled = Matrix3::from_fn(|i, j| a[(i, j)] * 8.0 * [0.5, 64.0, 2.0][j]);
        let s2 = solve_scaled(&scaled, &(b * 8.0), tau);
        assert_eq!(s2.rcond, s.rcond);
        assert_eq!(s2.theta[1] * 64.0, s.theta[1]);
    }

    #[test]
    fn two_lanes_give_the_one_lane_answers_bit_for_bit() {
        let a1 = Matrix3::new(1.0, 0.3, -0.2, 0.4, -1.1, 0.5, 0.1, 0.7, 0.9);
        let a2 = Matrix3::new(2e-9, 3e-3, 4.0, 1e-9, -2e-3, 3.0, 5e-10, 1e-3, -1.0);
        let (b1, b2) = (Vector3::new(1.0, 2.0, 3.0), Vector3::new(-1.0, 0.5, 2.0));
        let rows = [0, 1, 2].map(|i| [0, 1, 2].map(|j| F2::new(a1[(i, j)], a2[(i, j)])));
        let (theta, rcond) = solve3(&rows, &[0, 1, 2].map(|i| F2::new(b1[i], b2[i])), 1.0);
        let (s1, s2) = (solve_scaled(&a1, &b1, 1.0), solve_scaled(&a2, &b2, 1.0));
        for (i, t) in theta.iter().enumerate() {
            assert_eq!(t.to_array(), [s1.theta[i], s2.theta[i]]);
        }
        assert_eq!(rcond.to_array(), [s1.rcond, s2.rcond]);
        // One singular lane does not disturb the other.
        let rows = [0, 1, 2].map(|i| [0, 1, 2].map(|j| F2::new(a1[(i, j)], 0.0)));
        let (theta, rcond) = solve3(&rows, &[0, 1, 2].map(|i| F2::new(b1[i], 1.0)), 1.0);
        assert_eq!(theta[2].to_array()[0], s1.theta[2]);
        assert!(theta[2].to_array()[1].is_nan());
        assert_eq!(rcond.to_array(), [s1.rcond, 0.0]);
    }

    #[test]
    fn power_of_two_scale_factors() {
        for x in [1.0, 1.5, 1.999, 2.0, 3.0e-7, 5.0e12, f64::MIN_POSITIVE] {
            let s = recip_pow2(x);
            assert!((1.0..2.0).contains(&(x * s)), "{x} -> {s}");
        }
    }

    #[test]
    fn identity_has_rcond_one() {
        let s = solve_scaled(&Matrix3::identity(), &Vector3::new(1.0, 2.0, 3.0), 1.0);
        assert_eq!(s.rcond, 1.0);
        assert_eq!(s.theta, Vector3::new(1.0, 2.0, 3.0));
    }

    #[test]
    fn singular_inputs_give_nan_and_zero_never_panic() {
        let b = Vector3::new(1.0, 1.0, 1.0);
        let cases = [
            Matrix3::zeros(),
            Matrix3::new(1.0, 2.0, 3.0, 2.0, 4.0, 6.0, 1.0, 0.0, 1.0),
            Matrix3::new(1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0),
            Matrix3::from_element(f64::NAN),
            Matrix3::from_element(f64::INFINITY),
            Matrix3::from_element(f64::MAX),
        ];
        for a in cases {
            let s = solve_scaled(&a, &b, 1.0);
            assert_eq!(s.rcond, 0.0, "{a}");
            assert!(s.theta.iter().all(|x| x.is_nan()));
        }
        let s = solve_scaled(&Matrix3::identity(), &Vector3::new(f64::NAN, 0.0, 0.0), 1.0);
        assert_eq!(s.rcond, 0.0);
        for tau in [0.0, -1.0, f64::NAN, f64::INFINITY] {
            assert_eq!(solve_scaled(&Matrix3::identity(), &b, tau).rcond, 0.0);
        }
    }

    #[test]
    fn nearly_singular_is_flagged_by_a_small_rcond() {
        let eps = 1e-9;
        let a = Matrix3::new(1.0, 1.0, 0.0, 1.0, 1.0 + eps, 0.0, 0.0, 0.0, 1.0);
        let s = solve_scaled(&a, &Vector3::new(1.0, 1.0, 1.0), 1.0);
        assert!(s.rcond < 1e-8 && s.rcond > 1e-11, "{}", s.rcond);
    }
}
