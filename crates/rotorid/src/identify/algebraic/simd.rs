//! Two f64 lanes, one per direction (x, z), so that the two 3x3 systems of `scaled_solve`
//! (and the two 5x5 systems of `cross_solve`) are solved with one SIMD instruction per
//! operation.
//!
//! Every operation is the IEEE-754 operation lane by lane (no fused multiply-add, no
//! reassociation), so the results are bit-for-bit those of the scalar code. On x86_64 the
//! lanes are an SSE2 register (SSE2 is part of the x86_64 baseline, always present); on
//! other targets a plain `[f64; 2]`.

#[cfg(target_arch = "x86_64")]
mod imp {
    use std::arch::x86_64::*;

    /// Two f64 lanes in an SSE2 register.
    #[derive(Clone, Copy)]
    pub(crate) struct F2(__m128d);

    // SAFETY (every `unsafe` block below): the intrinsics used need only SSE2, which every
    // x86_64 CPU has (it is enabled in the x86_64 baseline target); they have no memory
    // side effects except `_mm_storeu_pd`, which is given a pointer to two valid f64
    // (unaligned access allowed).
    impl F2 {
        #[inline(always)]
        pub(crate) fn new(a: f64, b: f64) -> Self {
            unsafe { F2(_mm_set_pd(b, a)) }
        }
        #[inline(always)]
        pub(crate) fn splat(a: f64) -> Self {
            unsafe { F2(_mm_set1_pd(a)) }
        }
        #[inline(always)]
        pub(crate) fn to_array(self) -> [f64; 2] {
            let mut out = [0.0; 2];
            unsafe { _mm_storeu_pd(out.as_mut_ptr(), self.0) };
            out
        }
        #[inline(always)]
        pub(crate) fn add(self, o: Self) -> Self {
            unsafe { F2(_mm_add_pd(self.0, o.0)) }
        }
        #[inline(always)]
        pub(crate) fn sub(self, o: Self) -> Self {
            unsafe { F2(_mm_sub_pd(self.0, o.0)) }
        }
        #[inline(always)]
        pub(crate) fn mul(self, o: Self) -> Self {
            unsafe { F2(_mm_mul_pd(self.0, o.0)) }
        }
        #[inline(always)]
        pub(crate) fn div(self, o: Self) -> Self {
            unsafe { F2(_mm_div_pd(self.0, o.0)) }
        }
        /// |x| (clears the sign bit).
        #[inline(always)]
        pub(crate) fn abs(self) -> Self {
            unsafe { F2(_mm_andnot_pd(_mm_set1_pd(-0.0), self.0)) }
        }
        /// `if a > b { a } else { b }` per lane (so `o` when either is NaN).
        #[inline(always)]
        pub(crate) fn max(self, o: Self) -> Self {
            unsafe { F2(_mm_max_pd(self.0, o.0)) }
        }
        /// `if a < b { a } else { b }` per lane (so `o` when either is NaN).
        #[inline(always)]
        pub(crate) fn min(self, o: Self) -> Self {
            unsafe { F2(_mm_min_pd(self.0, o.0)) }
        }
        /// 2^-e for x = f 2^e, f in [1, 2), from the exponent bits:
        /// `from_bits((2046 - biased_exponent) << 52)` with wrapping arithmetic.
        #[inline(always)]
        pub(crate) fn recip_pow2(self) -> Self {
            unsafe {
                let bits = _mm_castpd_si128(self.0);
                let e = _mm_and_si128(_mm_srli_epi64::<52>(bits), _mm_set1_epi64x(0x7ff));
                let r = _mm_slli_epi64::<52>(_mm_sub_epi64(_mm_set1_epi64x(2046), e));
                F2(_mm_castsi128_pd(r))
            }
        }
        /// Per lane: `if ok { self } else { other }`, ok = (finite == 0 && positive > 0).
        #[inline(always)]
        pub(crate) fn select_ok(self, finite: Self, positive: Self, other: Self) -> Self {
            unsafe {
                let zero = _mm_setzero_pd();
                let ok = _mm_and_pd(_mm_cmpeq_pd(finite.0, zero), _mm_cmpgt_pd(positive.0, zero));
                F2(_mm_or_pd(
                    _mm_and_pd(ok, self.0),
                    _mm_andnot_pd(ok, other.0),
                ))
            }
        }
        /// Per lane: `if self > o { yes } else { no }` (`no` when either is NaN).
        #[inline(always)]
        pub(crate) fn pick_gt(self, o: Self, yes: Self, no: Self) -> Self {
            unsafe {
                let gt = _mm_cmpgt_pd(self.0, o.0);
                F2(_mm_or_pd(_mm_and_pd(gt, yes.0), _mm_andnot_pd(gt, no.0)))
            }
        }
        /// `self > o` in either lane (false for NaN).
        #[inline(always)]
        pub(crate) fn any_gt(self, o: Self) -> bool {
            unsafe { _mm_movemask_pd(_mm_cmpgt_pd(self.0, o.0)) != 0 }
        }
    }
}

#[cfg(not(target_arch = "x86_64"))]
mod imp {
    /// Two f64 lanes.
    #[derive(Clone, Copy)]
    pub(crate) struct F2([f64; 2]);

    impl F2 {
        #[inline(always)]
        fn zip(self, o: Self, f: impl Fn(f64, f64) -> f64) -> Self {
            F2([f(self.0[0], o.0[0]), f(self.0[1], o.0[1])])
        }
        #[inline(always)]
        pub(crate) fn new(a: f64, b: f64) -> Self {
            F2([a, b])
        }
        #[inline(always)]
        pub(crate) fn splat(a: f64) -> Self {
            F2([a; 2])
        }
        #[inline(always)]
        pub(crate) fn to_array(self) -> [f64; 2] {
            self.0
        }
        #[inline(always)]
        pub(crate) fn add(self, o: Self) -> Self {
            self.zip(o, |a, b| a + b)
        }
        #[inline(always)]
        pub(crate) fn sub(self, o: Self) -> Self {
            self.zip(o, |a, b| a - b)
        }
        #[inline(always)]
        pub(crate) fn mul(self, o: Self) -> Self {
            self.zip(o, |a, b| a * b)
        }
        #[inline(always)]
        pub(crate) fn div(self, o: Self) -> Self {
            self.zip(o, |a, b| a / b)
        }
        #[inline(always)]
        pub(crate) fn abs(self) -> Self {
            F2([self.0[0].abs(), self.0[1].abs()])
        }
        #[inline(always)]
        pub(crate) fn max(self, o: Self) -> Self {
            self.zip(o, |a, b| if a > b { a } else { b })
        }
        #[inline(always)]
        pub(crate) fn min(self, o: Self) -> Self {
            self.zip(o, |a, b| if a < b { a } else { b })
        }
        #[inline(always)]
        pub(crate) fn recip_pow2(self) -> Self {
            let r = |x: f64| {
                let e = (x.to_bits() >> 52) & 0x7ff;
                f64::from_bits(2046u64.wrapping_sub(e) << 52)
            };
            F2([r(self.0[0]), r(self.0[1])])
        }
        #[inline(always)]
        pub(crate) fn select_ok(self, finite: Self, positive: Self, other: Self) -> Self {
            let pick = |l: usize| {
                if finite.0[l] == 0.0 && positive.0[l] > 0.0 {
                    self.0[l]
                } else {
                    other.0[l]
                }
            };
            F2([pick(0), pick(1)])
        }
        #[inline(always)]
        pub(crate) fn pick_gt(self, o: Self, yes: Self, no: Self) -> Self {
            let pick = |l: usize| {
                if self.0[l] > o.0[l] {
                    yes.0[l]
                } else {
                    no.0[l]
                }
            };
            F2([pick(0), pick(1)])
        }
        #[inline(always)]
        pub(crate) fn any_gt(self, o: Self) -> bool {
            self.0[0] > o.0[0] || self.0[1] > o.0[1]
        }
    }
}

pub(crate) use imp::F2;

impl std::ops::Add for F2 {
    type Output = F2;
    #[inline(always)]
    fn add(self, o: F2) -> F2 {
        F2::add(self, o)
    }
}
impl std::ops::Sub for F2 {
    type Output = F2;
    #[inline(always)]
    fn sub(self, o: F2) -> F2 {
        F2::sub(self, o)
    }
}
impl std::ops::Mul for F2 {
    type Output = F2;
    #[inline(always)]
    fn mul(self, o: F2) -> F2 {
        F2::mul(self, o)
    }
}
impl std::fmt::Debug for F2 {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "F2{:?}", self.to_array())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each lane operation against the scalar f64 operation, bit for bit, on awkward values.
    #[test]
    fn lanes_are_the_scalar_operations() {
        let vals = [
            0.0,
            -0.0,
            1.0,
            -2.5,
            3.0e-7,
            1.0e300,
            -1.0e-310,
            f64::MIN_POSITIVE,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        let same = |a: f64, b: f64| a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan());
        for &a in &vals {
            for &b in &vals {
                let (x, y) = (F2::new(a, b), F2::new(b, a));
                let check = |got: F2, want: [f64; 2], what: &str| {
                    let g = got.to_array();
                    assert!(
                        same(g[0], want[0]) && same(g[1], want[1]),
                        "{what} {a} {b}: {g:?} vs {want:?}"
                    );
                };
                check(x + y, [a + b, b + a], "add");
                check(x - y, [a - b, b - a], "sub");
                check(x * y, [a * b, b * a], "mul");
                check(x.div(y), [a / b, b / a], "div");
                check(x.abs(), [a.abs(), b.abs()], "abs");
                let mx = |p: f64, q: f64| if p > q { p } else { q };
                let mn = |p: f64, q: f64| if p < q { p } else { q };
                check(x.max(y), [mx(a, b), mx(b, a)], "max");
                check(x.min(y), [mn(a, b), mn(b, a)], "min");
                let r = |v: f64| {
                    f64::from_bits(2046u64.wrapping_sub((v.to_bits() >> 52) & 0x7ff) << 52)
                };
                check(x.recip_pow2(), [r(a), r(b)], "recip_pow2");
                let sel = F2::splat(7.0).select_ok(x, y, F2::splat(-1.0)).to_array();
                assert_eq!(sel[0], if a == 0.0 && b > 0.0 { 7.0 } else { -1.0 });
                assert_eq!(sel[1], if b == 0.0 && a > 0.0 { 7.0 } else { -1.0 });
                let pick = x.pick_gt(y, F2::splat(1.0), F2::splat(2.0)).to_array();
                assert_eq!(pick[0], if a > b { 1.0 } else { 2.0 });
                assert_eq!(pick[1], if b > a { 1.0 } else { 2.0 });
                assert_eq!(x.any_gt(y), a > b || b > a);
            }
        }
        assert_eq!(F2::new(1.0, 2.0).to_array(), [1.0, 2.0]);
        assert_eq!(F2::splat(3.0).to_array(), [3.0, 3.0]);
    }
}
