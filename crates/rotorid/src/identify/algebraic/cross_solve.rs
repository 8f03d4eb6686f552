//! The 5x5 system of the cross-coupled algebraic identifier (docs/method.md section 3.10),
//! scaled and solved at one instant, with its conditioning:
//!
//! ```text
//! A theta = b,   A = [p; I1[p]; I2[p]; I3[p]; I4[p]],   b = [s; I1[s]; I2[s]; I3[s]; I4[s]]
//! ```
//!
//! with p the five regressors of one direction (module docs of `cross`). Row i carries a
//! weight ~ tau^(2+i) / (i + 2)! and the unknowns differ by orders of magnitude (m ~ 10 kg,
//! c ~ 10..1e3 N s/m, k ~ 1e6 N/m), so the system is equilibrated on both sides by powers
//! of two only (exact, found from exponent bits, as LAPACK's `dgeequb`), rows first:
//!
//! ```text
//! A1 = Dr A,   Dr = diag(2^-r_i),  1 <= max_j |A1_ij| < 2                   (rows)
//! As = A1 Dc,  Dc = diag(2^-f_j),  1 <= max_i |As_ij| < 2                   (columns)
//! P As = L U                 (Gaussian elimination with partial pivoting)
//! theta = Dc U^-1 L^-1 P Dr b
//! rcond = 1 / (||As||_1 ||As^-1||_1)                               (exact, not estimated)
//! ```
//!
//! The 3x3 system of the Jeffcott identifier scales its rows by powers of tau instead
//! (`scaled_solve`); for the 5x5 that leaves the factorial decrease of the higher
//! integrals in the rows, which made rcond 30 to 100 times smaller without saying more
//! about the error: on exact data the two-sided rcond separates the instants whose
//! estimate is off far better (docs/method.md section 3.10). An exact power-of-two
//! scaling changes no rounding of the elimination except through the choice of pivots.
//!
//! ||As^-1||_1 is computed exactly from the factors: the columns of (P As)^-1 = U^-1 L^-1
//! are those of As^-1 in another order, and the 1-norm is the largest column sum, so the
//! permutation need not be undone. That costs 5 triangular solve pairs (~125 multiply-adds
//! per direction), small beside the quadrature cascade, and gives the figure LAPACK's
//! `dgecon` only estimates. rcond is in [0, 1], independent of the units of the unknowns
//! and of a common scale of the signal; a singular or non-finite system gives theta = NaN
//! and rcond = 0, never a panic.
//!
//! The x and z systems are solved together, one per lane of a two-lane vector (`simd`); pivoting is done lane
//! by lane: for column k, each row i > k in turn swaps with row k in the lanes where
//! |a_ik| > |a_kk| (a blend of the two rows, skipped when no lane needs it), which leaves
//! the largest candidate of each lane on the diagonal (the order of the other rows differs
//! from LAPACK's single swap, which does not matter to the factorisation's stability; two
//! scalar solves with that single swap took 1.8 times the instructions, measured with
//! callgrind). Every operation is the IEEE operation lane by
//! lane, so the results are bit-for-bit those of scalar code on either lane.

use nalgebra::{SMatrix, SVector};

use super::simd::F2;

/// Unknowns per direction of the cross-coupled identifier.
pub const N5: usize = 5;

/// The solution of one scaled 5x5 system.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScaledSolution5 {
    /// theta (units those of the columns' unknowns); NaN when the system is singular.
    pub theta: SVector<f64, N5>,
    /// Reciprocal 1-norm condition number of the scaled matrix (module docs), in [0, 1];
    /// 0 when singular.
    pub rcond: f64,
}

/// Solve `a theta = b` with the equilibration of the module docs.
pub fn solve_scaled5(a: &SMatrix<f64, N5, N5>, b: &SVector<f64, N5>) -> ScaledSolution5 {
    // Lane 0 holds the system, lane 1 a copy.
    let rows: [[F2; N5]; N5] =
        std::array::from_fn(|i| std::array::from_fn(|j| F2::splat(a[(i, j)])));
    let rhs: [F2; N5] = std::array::from_fn(|i| F2::splat(b[i]));
    let (theta, rcond) = solve5(&rows, &rhs);
    ScaledSolution5 {
        theta: SVector::from_fn(|i, _| theta[i].to_array()[0]),
        rcond: rcond.to_array()[0],
    }
}

/// Solve the x and z systems at once (lane 0 and lane 1 of every entry): `a[i][j]`,
/// `b[i]`; returns (`theta[j]`, `rcond`), NaN / 0 in a singular lane.
#[inline(always)]
pub(crate) fn solve5(a: &[[F2; N5]; N5], b: &[F2; N5]) -> ([F2; N5], F2) {
    // A1 = Dr A, Dr b: rows' largest entries into [1, 2) (powers of 2: exact).
    let dr: [F2; N5] = std::array::from_fn(|i| {
        let mut mx = a[i][0].abs();
        for e in a[i].iter().skip(1) {
            mx = mx.max(e.abs());
        }
        mx.recip_pow2()
    });
    let mut m: [[F2; N5]; N5] = std::array::from_fn(|i| a[i].map(|e| e * dr[i]));
    let mut v: [F2; N5] = std::array::from_fn(|i| b[i] * dr[i]);
    // As = A1 Dc: columns' largest entries into [1, 2) (2^-e from the exponent bits; -inf
    // for inf or NaN, which then makes the lane singular).
    let dc: [F2; N5] = std::array::from_fn(|j| {
        let mut mx = m[0][j].abs();
        for row in m.iter().skip(1) {
            mx = mx.max(row[j].abs());
        }
        mx.recip_pow2()
    });
    for row in m.iter_mut() {
        for (e, d) in row.iter_mut().zip(dc.iter()) {
            *e = *e * *d;
        }
    }
    // ||As||_1: the largest column sum.
    let mut norm_a = F2::splat(0.0);
    for j in 0..N5 {
        let mut s = m[0][j].abs();
        for row in m.iter().skip(1) {
            s = s + row[j].abs();
        }
        norm_a = norm_a.max(s);
    }
    // P As = L U in place (L unit lower, below the diagonal), the same swaps on v;
    // inv[k] = 1 / U_kk.
    let mut inv = [F2::splat(0.0); N5];
    for k in 0..N5 {
        for i in k + 1..N5 {
            let (top, bottom) = m.split_at_mut(i);
            let (rk, ri) = (&mut top[k], &mut bottom[0]);
            let (cand, cur) = (ri[k].abs(), rk[k].abs());
            if !cand.any_gt(cur) {
                continue; // no lane swaps: the blends below would change nothing
            }
            for (a, b) in rk.iter_mut().zip(ri.iter_mut()) {
                let (x, y) = (*a, *b);
                *a = cand.pick_gt(cur, y, x);
                *b = cand.pick_gt(cur, x, y);
            }
            let (vk, vi) = (v[k], v[i]);
            v[k] = cand.pick_gt(cur, vi, vk);
            v[i] = cand.pick_gt(cur, vk, vi);
        }
        let r = F2::splat(1.0).div(m[k][k]);
        inv[k] = r;
        let (top, bottom) = m.split_at_mut(k + 1);
        let (pivot, vk) = (&top[k], v[k]);
        for (row, vi) in bottom.iter_mut().zip(v[k + 1..].iter_mut()) {
            let l = row[k] * r;
            row[k] = l;
            for (e, p) in row[k + 1..].iter_mut().zip(pivot[k + 1..].iter()) {
                *e = *e - l * *p;
            }
            *vi = *vi - l * vk;
        }
    }
    // theta_s = U^-1 (L^-1 P v) (v is already L^-1 P T b)
    let back = |y: &mut [F2; N5]| {
        for i in (0..N5).rev() {
            let mut s = y[i];
            for j in i + 1..N5 {
                s = s - m[i][j] * y[j];
            }
            y[i] = s * inv[i];
        }
    };
    back(&mut v);
    // ||As^-1||_1 = max over c of the column sums of U^-1 L^-1 e_c.
    let mut norm_inv = F2::splat(0.0);
    for c in 0..N5 {
        let mut y = [F2::splat(0.0); N5];
        y[c] = F2::splat(1.0);
        for i in c + 1..N5 {
            let mut s = F2::splat(0.0);
            for j in c..i {
                s = s - m[i][j] * y[j];
            }
            y[i] = s;
        }
        back(&mut y);
        let mut s = y[0].abs();
        for e in y.iter().skip(1) {
            s = s + e.abs();
        }
        norm_inv = norm_inv.max(s);
    }
    let rcond = F2::splat(1.0).div(norm_a * norm_inv);
    let theta: [F2; N5] = std::array::from_fn(|j| dc[j] * v[j]);
    // x * 0 == 0 exactly when x is finite: a NaN or infinity anywhere (a zero pivot,
    // overflow) or rcond <= 0 gives the singular answer (NaN, 0). Branch-free.
    let zero = F2::splat(0.0);
    let mut finite = rcond * zero;
    for t in &theta {
        finite = finite + *t * zero;
    }
    let nan = F2::splat(f64::NAN);
    (
        theta.map(|t| t.select_ok(finite, rcond, nan)),
        rcond.min(F2::splat(1.0)).select_ok(finite, rcond, zero),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    type M5 = SMatrix<f64, N5, N5>;
    type V5 = SVector<f64, N5>;

    /// 2^-floor(log2 x), independently of the exponent-bit trick.
    fn p2(x: f64) -> f64 {
        2f64.powi(-(x.log2().floor() as i32))
    }

    /// The two-sided equilibration and its rcond, computed with nalgebra's inverse.
    fn rcond_ref(a: &M5) -> f64 {
        let dr = V5::from_fn(|i, _| p2(a.row(i).abs().max()));
        let a1 = M5::from_fn(|i, j| a[(i, j)] * dr[i]);
        let dc = V5::from_fn(|j, _| p2(a1.column(j).abs().max()));
        let s = M5::from_fn(|i, j| a1[(i, j)] * dc[j]);
        let n1 = |x: &M5| (0..N5).map(|j| x.column(j).abs().sum()).fold(0.0, f64::max);
        1.0 / (n1(&s) * n1(&s.try_inverse().unwrap()))
    }

    fn base() -> M5 {
        M5::from_fn(|i, j| (1.3 * i as f64 + 0.7 * j as f64 + 0.2 * (i * j) as f64).sin())
    }

    #[test]
    fn solves_a_badly_scaled_system_to_rounding_with_the_exact_rcond() {
        // columns like (m, c, c, k, k), rows like tau^2 .. tau^6
        let theta = V5::from([14.29, 600.0, -5.0, 1.195e6, -1.195e5]);
        let tau: f64 = 0.05;
        let col = [1e-7, 1e-6, 1e-6, 1e-12, 1e-12];
        let a = M5::from_fn(|i, j| base()[(i, j)] * tau.powi(2 + i as i32) * col[j]);
        let b = a * theta;
        let s = solve_scaled5(&a, &b);
        let lu = a.lu().solve(&b).unwrap();
        // each error against the size of its column's kind of unknown (m, c, c, k, k);
        // nalgebra's LU makes errors of the same size (2e-13 of m)
        let size = [14.29, 600.0, 600.0, 1.195e6, 1.195e6];
        for i in 0..N5 {
            assert!((s.theta[i] - theta[i]).abs() < 1e-12 * size[i], "{s:?}");
            assert!(
                (s.theta[i] - lu[i]).abs() < 1e-12 * size[i],
                "{s:?} vs {lu}"
            );
        }
        assert!(
            (s.rcond - rcond_ref(&a)).abs() < 1e-13 * s.rcond,
            "{} vs {}",
            s.rcond,
            rcond_ref(&a)
        );
        assert!(s.rcond > 1e-3 && s.rcond <= 1.0, "{s:?}");
        // invariant to a common scale and to power-of-two row scales, bit for bit (the
        // rows are equilibrated first, exactly); column scales change the row scaling, so
        // only the solution is the same, to rounding
        let r = [2.0, 0.25, 64.0, 1.0, 0.5];
        let a2 = M5::from_fn(|i, j| a[(i, j)] * 4.0 * r[i]);
        let b2 = V5::from_fn(|i, _| b[i] * 4.0 * r[i]);
        let s2 = solve_scaled5(&a2, &b2);
        assert_eq!(s2.rcond, s.rcond);
        assert_eq!(s2.theta, s.theta);
        let c = [8.0, 0.5, 1.0, 1024.0, 2.0];
        let s3 = solve_scaled5(&M5::from_fn(|i, j| a[(i, j)] * c[j]), &b);
        for j in 0..N5 {
            assert!(
                (s3.theta[j] * c[j] - theta[j]).abs() < 1e-12 * size[j],
                "{s3:?}"
            );
        }
    }

    #[test]
    fn pivots_where_the_leading_entries_vanish() {
        // a permutation of a diagonal of powers of two (equilibrated to a permutation
        // matrix, rcond 1): no elimination without row exchanges
        let mut a = M5::zeros();
        let perm = [3, 0, 4, 1, 2];
        for (i, &j) in perm.iter().enumerate() {
            a[(i, j)] = [4.0, -0.5, 8.0, 1.0, -2.0][i];
        }
        let theta = V5::from([1.0, -2.0, 3.0, -4.0, 5.0]);
        let s = solve_scaled5(&a, &(a * theta));
        assert_eq!(s.theta, theta);
        assert_eq!(s.rcond, 1.0);
        // and a general matrix whose first pivot is tiny
        let mut a = base();
        a[(0, 0)] = 1e-14;
        let theta = V5::from([0.5, 1.5, -2.5, 3.5, -4.5]);
        let s = solve_scaled5(&a, &(a * theta));
        for i in 0..N5 {
            assert!((s.theta[i] - theta[i]).abs() < 1e-13, "{s:?}");
        }
        assert!((s.rcond - rcond_ref(&a)).abs() < 1e-13 * s.rcond);
    }

    #[test]
    fn two_lanes_give_the_one_lane_answers_bit_for_bit() {
        let a1 = base();
        let a2 =
            M5::from_fn(|i, j| (0.3 + i as f64 - 2.0 * j as f64).cos() * 10f64.powi(j as i32 - 2));
        let (b1, b2) = (
            V5::from([1.0, 2.0, 3.0, 4.0, 5.0]),
            V5::from([-1.0, 0.5, 2.0, 0.0, 7.0]),
        );
        let rows: [[F2; N5]; N5] =
            std::array::from_fn(|i| std::array::from_fn(|j| F2::new(a1[(i, j)], a2[(i, j)])));
        let rhs: [F2; N5] = std::array::from_fn(|i| F2::new(b1[i], b2[i]));
        let (theta, rcond) = solve5(&rows, &rhs);
        let (s1, s2) = (solve_scaled5(&a1, &b1), solve_scaled5(&a2, &b2));
        for (i, t) in theta.iter().enumerate() {
            assert_eq!(t.to_array(), [s1.theta[i], s2.theta[i]]);
        }
        assert_eq!(rcond.to_array(), [s1.rcond, s2.rcond]);
        // a singular lane does not disturb the other
        let rows: [[F2; N5]; N5] =
            std::array::from_fn(|i| std::array::from_fn(|j| F2::new(a1[(i, j)], 0.0)));
        let rhs: [F2; N5] = std::array::from_fn(|i| F2::new(b1[i], 1.0));
        let (theta, rcond) = solve5(&rows, &rhs);
        for (i, t) in theta.iter().enumerate() {
            assert_eq!(t.to_array()[0], s1.theta[i]);
            assert!(t.to_array()[1].is_nan());
        }
        assert_eq!(rcond.to_array(), [s1.rcond, 0.0]);
    }

    #[test]
    fn singular_inputs_give_nan_and_zero_never_panic() {
        let b = V5::from_element(1.0);
        let mut rank4 = base();
        let r0 = rank4.row(0).into_owned();
        rank4.set_row(4, &(r0 * 2.0));
        let mut zero_col = base();
        zero_col.set_column(2, &V5::zeros());
        let cases = [
            M5::zeros(),
            rank4,
            zero_col,
            M5::from_element(f64::NAN),
            M5::from_element(f64::INFINITY),
            M5::from_element(f64::MAX),
        ];
        for a in cases {
            let s = solve_scaled5(&a, &b);
            assert_eq!(s.rcond, 0.0, "{a}");
            assert!(s.theta.iter().all(|x| x.is_nan()), "{a}");
        }
        let mut nan_rhs = b;
        nan_rhs[3] = f64::NAN;
        assert_eq!(solve_scaled5(&M5::identity(), &nan_rhs).rcond, 0.0);
    }

    #[test]
    fn nearly_singular_is_flagged_by_a_small_rcond() {
        let mut a = base();
        let eps = 1e-9;
        let r0 = a.row(0).into_owned();
        let r1 = a.row(1).into_owned();
        a.set_row(4, &(r0 + r1 * (1.0 + eps)));
        a[(4, 4)] += eps;
        let s = solve_scaled5(&a, &V5::from_element(1.0));
        assert!(s.rcond < 1e-8 && s.rcond > 1e-12, "{}", s.rcond);
        assert!((s.rcond / rcond_ref(&a) - 1.0).abs() < 1e-6);
    }
}
