//! sin and cos of the rotor phase, together, for the identifier's hot loop.
//!
//! ```text
//! x = k pi/2 + r,   k = nearest integer to x 2/pi,   |r| <= pi/4
//! r = (x - k P1) - k P1t            (Cody-Waite; P1 = pi/2 to 33 bits, P1t the next 53)
//! sin r = r + r^3 (S1 + r^2 S2 + ... + r^10 S6)
//! cos r = 1 - r^2/2 + r^4 (C1 + r^2 C2 + ... + r^10 C6)
//! (sin x, cos x) = (sin r, cos r) rotated by the quadrant k mod 4
//! ```
//!
//! The reduction constants and the minimax coefficients S1..S6, C1..C6 are fdlibm's
//! (`e_rem_pio2.c`, `k_sin.c`, `k_cos.c`, Sun Microsystems 1993; also in musl and Go).
//! For |x| <= 1.6e6 rad (< 2^20 pi/2; 3.5 h at 1200 rpm) k P1 is exact and the result is
//! within ~1 ulp of 1 (absolute error <= 2.5e-16; checked against `f64::sin_cos` in the
//! tests); beyond that, and for non-finite x, it is `f64::sin_cos`. Faster than the C
//! library's `sincos` (docs/performance.md) and branch-free in the common case.

/// 2/pi
const INV_PIO2: f64 = f64::from_bits(0x3FE4_5F30_6DC9_C883);
/// pi/2, first 33 bits
const PIO2_1: f64 = f64::from_bits(0x3FF9_21FB_5440_0000);
/// pi/2 - PIO2_1
const PIO2_1T: f64 = f64::from_bits(0x3DD0_B461_1A62_6331);
/// Largest |x| of the fast path (< 2^20 pi/2, so that k < 2^20 and k P1 is exact).
const FAST_MAX: f64 = 1.6e6;
/// 1.5 * 2^52: adding and subtracting it rounds to the nearest integer (|v| < 2^51).
const ROUND: f64 = 6_755_399_441_055_744.0;

// fdlibm k_sin.c: S1 = -1.66666666666666324348e-01 .. S6 = 1.58969099521155010221e-10
const S1: f64 = f64::from_bits(0xBFC5_5555_5555_5549);
const S2: f64 = f64::from_bits(0x3F81_1111_1110_F8A6);
const S3: f64 = f64::from_bits(0xBF2A_01A0_19C1_61D5);
const S4: f64 = f64::from_bits(0x3EC7_1DE3_57B1_FE7D);
const S5: f64 = f64::from_bits(0xBE5A_E5E6_8A2B_9CEB);
const S6: f64 = f64::from_bits(0x3DE5_D93A_5ACF_D57C);

// fdlibm k_cos.c: C1 = 4.16666666666666019037e-02 .. C6 = -1.13596475577881948265e-11
const C1: f64 = f64::from_bits(0x3FA5_5555_5555_554C);
const C2: f64 = f64::from_bits(0xBF56_C16C_16C1_5177);
const C3: f64 = f64::from_bits(0x3EFA_01A0_19CB_1590);
const C4: f64 = f64::from_bits(0xBE92_7E4F_809C_52AD);
const C5: f64 = f64::from_bits(0x3E21_EE9E_BDB4_B1C4);
const C6: f64 = f64::from_bits(0xBDA8_FAE9_BE88_38D4);

/// (sin x, cos x) (module docs).
#[inline(always)]
pub(crate) fn sin_cos(x: f64) -> (f64, f64) {
    if x.abs() > FAST_MAX || x.is_nan() {
        return x.sin_cos();
    }
    // k = round(x 2/pi); its low bits are the quadrant.
    let shifted = x * INV_PIO2 + ROUND;
    let q = shifted.to_bits();
    let k = shifted - ROUND;
    let r = (x - k * PIO2_1) - k * PIO2_1T;
    let z = r * r;
    let s = r + r * z * (S1 + z * (S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)))));
    let hz = 0.5 * z;
    let w = 1.0 - hz;
    let c =
        w + (((1.0 - w) - hz) + z * z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6))))));
    // quadrant: 0 (s, c), 1 (c, -s), 2 (-s, -c), 3 (-c, s)
    let (a, b) = if q & 1 == 0 { (s, c) } else { (c, s) };
    let sign_sin = (q & 2) << 62;
    let sign_cos = ((q + 1) & 2) << 62;
    (
        f64::from_bits(a.to_bits() ^ sign_sin),
        f64::from_bits(b.to_bits() ^ sign_cos),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check(x: f64) -> f64 {
        let (s, c) = sin_cos(x);
        let (s0, c0) = x.sin_cos();
        let e = (s - s0).abs().max((c - c0).abs());
        assert!(
            e <= 2.5e-16,
            "x = {x}: ({s}, {c}) vs ({s0}, {c0}), error {e:e}"
        );
        e
    }

    #[test]
    fn matches_the_library_to_an_ulp_over_the_fast_range() {
        let mut worst: f64 = 0.0;
        // dense near 0 and the quadrant boundaries, then spread out to the fast limit
        for i in -20_000..=20_000 {
            worst = worst.max(check(i as f64 * 1e-3));
            worst = worst.max(check(
                i as f64 * std::f64::consts::FRAC_PI_4 + 1e-9 * i as f64,
            ));
        }
        let mut x = 1.0;
        while x < FAST_MAX {
            for d in [-1.0, 1.0] {
                worst = worst.max(check(d * x));
                worst = worst.max(check(d * x * std::f64::consts::PI));
            }
            x *= 1.000_37;
        }
        for x in [FAST_MAX, -FAST_MAX, FAST_MAX * 0.999_999_9] {
            check(x);
        }
        assert!(worst > 0.0); // the comparison did run
    }

    #[test]
    fn coefficients_are_fdlibms() {
        let decimal = [
            (S1, "-1.66666666666666324348e-01"),
            (S2, "8.33333333332248946124e-03"),
            (S3, "-1.98412698298579493134e-04"),
            (S4, "2.75573137070700676789e-06"),
            (S5, "-2.50507602534068634195e-08"),
            (S6, "1.58969099521155010221e-10"),
            (C1, "4.16666666666666019037e-02"),
            (C2, "-1.38888888888741095749e-03"),
            (C3, "2.48015872894767294178e-05"),
            (C4, "-2.75573143513906633035e-07"),
            (C5, "2.08757232129817482790e-09"),
            (C6, "-1.13596475577881948265e-11"),
            (INV_PIO2, "6.36619772367581382433e-01"),
            (PIO2_1, "1.57079632673412561417e+00"),
            (PIO2_1T, "6.07710050650619224932e-11"),
        ];
        for (c, d) in decimal {
            assert_eq!(c, d.parse::<f64>().unwrap(), "{d}");
        }
        let pio2 = std::f64::consts::FRAC_PI_2;
        assert!((PIO2_1 + PIO2_1T - pio2).abs() <= f64::EPSILON);
        assert!(FAST_MAX < 1048576.0 * pio2);
    }

    #[test]
    fn outside_the_fast_range_it_is_the_library() {
        for x in [FAST_MAX * 1.000_001, -3.0e7, 1.0e300, f64::MAX] {
            assert_eq!(sin_cos(x), x.sin_cos());
        }
        let (s, c) = sin_cos(f64::NAN);
        assert!(s.is_nan() && c.is_nan());
        let (s, c) = sin_cos(f64::INFINITY);
        assert!(s.is_nan() && c.is_nan());
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
    }
}
