//! A fast path for the plain decimals of CSV files (`-0.0125`, `5.889325051644407e-11`,
//! `125.66370614359172`), in front of fast-float2: what it takes it reads bit for bit as
//! fast-float2's `parse_partial` (and so `str::parse::<f64>`) reads it, consuming the same
//! bytes; anything else it declines (`None`) and [`number_prefix`] asks fast-float2.
//!
//! Taken: an optional `-`, decimal digits with at most one `.` (19 significant digits at
//! most, leading zeros included), an optional exponent `e`/`E` with an optional sign and 1
//! to 4 digits, a value whose decimal exponent `q` (the value is `w 10^q`, `w` the digits as
//! an integer) lies in [`Q_MIN`, `Q_MAX`] and that is a normal, finite `f64`. Declined: a
//! `+`, `inf`, `nan`, more digits, exponents beyond that range, subnormals and overflows,
//! and the rare values the Eisel-Lemire step cannot round on its own.
//!
//! The value is computed as fast-float does (D. Lemire, "Number Parsing at a Gigabyte per
//! Second", Software: Practice and Experience 51(8), 2021, sections 5-6):
//!
//! ```text
//! w <= 2^53 and |q| <= 22:  w * 10^q or w / 10^-q in f64 (both exact, one rounding; Clinger)
//! otherwise:                 the top bits of (w << lz) * T(q), T(q) the 128 most
//!                            significant bits of 5^q (truncated; for q < 0 of 2^b / 5^-q,
//!                            plus one), rounded to nearest, ties to even (Eisel-Lemire)
//! ```
//!
//! A table (`POW5`) holds T(q) for q in [`Q_MIN`, `Q_MAX`], computed at compile time here,
//! which is why the range is narrow: it covers the decimals instruments and `rotorid` write
//! (a displacement of 1e-11 m with 17 digits has q = -27), and everything outside it goes
//! to fast-float2.
//!
//! Why: the response CSV's 6,000,006 numbers took fast-float2 31 ns each and this path 24 ns
//! (a scratch program over the file in memory); `rotorid inspect table1_100s.csv` takes 12 %
//! less time (0.253 -> 0.223 s, docs/performance.md). The digits after the point go eight
//! at a time (one 64-bit load: SWAR).

/// Smallest decimal exponent taken.
pub const Q_MIN: i32 = -64;
/// Largest decimal exponent taken.
pub const Q_MAX: i32 = 64;

/// The number at the start of `s` as fast-float2's `parse_partial` reads it, `(value, bytes
/// consumed)`, or `None` where it reads none: the fast path when it takes the text, else
/// fast-float2 itself. What the CSV readers call.
#[inline]
pub fn number_prefix(s: &[u8]) -> Option<(f64, usize)> {
    match parse_prefix(s) {
        Some(taken) => Some(taken),
        None => fast_float2::parse_partial::<f64, _>(s).ok(),
    }
}

/// The plain decimal at the start of `s` as `(value, bytes consumed)`, or `None` (module
/// doc): then fast-float2 decides ([`number_prefix`]).
#[inline]
pub fn parse_prefix(s: &[u8]) -> Option<(f64, usize)> {
    let neg = s.first() == Some(&b'-');
    let start = usize::from(neg);
    // integer digits (a leading zero stays in the count: at most 19 digits together)
    let (mut i, mut w) = one_by_one(s, start, 0);
    let mut digits_seen = i - start;
    let mut q: i32 = 0;
    if s.get(i) == Some(&b'.') {
        i += 1;
        let f = i;
        (i, w) = digits(s, i, w, MAX_DIGITS.checked_sub(digits_seen)?)?;
        digits_seen += i - f;
        q = -((i - f) as i32);
    }
    if digits_seen == 0 || digits_seen > MAX_DIGITS {
        return None;
    }
    if matches!(s.get(i), Some(b'e' | b'E')) {
        i += 1;
        let negative = match s.get(i) {
            Some(b'-') => {
                i += 1;
                true
            }
            Some(b'+') => {
                i += 1;
                false
            }
            _ => false,
        };
        let first = i;
        let mut e: i32 = 0;
        while let Some(&c) = s.get(i) {
            let d = c.wrapping_sub(b'0');
            if d > 9 {
                break;
            }
            if i - first == 4 {
                return None;
            }
            e = e * 10 + i32::from(d);
            i += 1;
        }
        if i == first {
            return None;
        }
        q += if negative { -e } else { e };
    }
    let v = to_f64(w, q)?;
    Some((if neg { -v } else { v }, i))
}

/// Most significant digits taken: `w` holds up to 19 exactly (< 10^19 < 2^64).
const MAX_DIGITS: usize = 19;

/// The digits of `s` from `i` appended to `w`: where they end, and `w`; `None` past `budget`
/// digits (the caller declines those). Eight bytes at a time while eight can be loaded (SWAR):
/// a word of eight digits whole, a shorter run at its start in the same step (so the loop's
/// exit does not depend on how many digits a field has); one by one near the end of `s`.
#[inline(always)]
fn digits(s: &[u8], mut i: usize, mut w: u64, budget: usize) -> Option<(usize, u64)> {
    let first = i;
    while let Some(v) = load8(s, i) {
        let n = leading_digits(v);
        if n == 8 {
            w = w.wrapping_mul(100_000_000).wrapping_add(eight(v));
            i += 8;
            if i - first > budget {
                return None;
            }
            continue;
        }
        if n > 0 {
            w = w
                .wrapping_mul(POW10_U64[n])
                .wrapping_add(eight(right_aligned(v, n)));
            i += n;
        }
        return (i - first <= budget).then_some((i, w));
    }
    (i, w) = one_by_one(s, i, w);
    (i - first <= budget).then_some((i, w))
}

/// The digits of `s` from `i` appended to `w` one by one: where they end, and `w` (which
/// wraps past 19 digits in all; the caller refuses those).
#[inline(always)]
fn one_by_one(s: &[u8], mut i: usize, mut w: u64) -> (usize, u64) {
    while let Some(&c) = s.get(i) {
        let d = c.wrapping_sub(b'0');
        if d > 9 {
            break;
        }
        w = w.wrapping_mul(10).wrapping_add(u64::from(d));
        i += 1;
    }
    (i, w)
}

/// How many of the 8 bytes of `v` (first byte first) are ASCII digits before the first
/// that is not. A byte is flagged when it is below `'0'` (the subtraction borrows) or above
/// `'9'` (adding 0x46 sets its top bit); the bytes before the first flagged one are digits,
/// which neither borrow nor carry, so that one is flagged exactly (later bytes may not be).
#[inline(always)]
fn leading_digits(v: u64) -> usize {
    let a = v.wrapping_add(0x4646_4646_4646_4646);
    let b = v.wrapping_sub(0x3030_3030_3030_3030);
    ((a | b) & 0x8080_8080_8080_8080).trailing_zeros() as usize / 8
}

/// The first `n` (1 to 7) bytes of `v`, digits, as the last `n` of an eight-digit word
/// led by `'0'`s: [`eight`] then reads the `n`-digit number.
#[inline(always)]
fn right_aligned(v: u64, n: usize) -> u64 {
    (v << (8 * (8 - n))) | (0x3030_3030_3030_3030 >> (8 * n))
}

/// 10^n for n = 0 to 8.
const POW10_U64: [u64; 9] = [
    1,
    10,
    100,
    1_000,
    10_000,
    100_000,
    1_000_000,
    10_000_000,
    100_000_000,
];

/// The 8 bytes of `s` from `i`, little endian, when there are 8.
#[inline(always)]
fn load8(s: &[u8], i: usize) -> Option<u64> {
    let b: [u8; 8] = s.get(i..i.checked_add(8)?)?.try_into().ok()?;
    Some(u64::from_le_bytes(b))
}

/// The number the 8 digit bytes of `v` spell (its first byte the most significant digit):
/// pairs, then fours, then the eight, by multiply-and-shift.
#[inline(always)]
fn eight(v: u64) -> u64 {
    let v = v - 0x3030_3030_3030_3030;
    let v = (v * 10) + (v >> 8);
    let v1 = (v & 0x0000_00FF_0000_00FF).wrapping_mul(0x000F_4240_0000_0064);
    let v2 = ((v >> 16) & 0x0000_00FF_0000_00FF).wrapping_mul(0x0000_2710_0000_0001);
    u64::from((v1.wrapping_add(v2) >> 32) as u32)
}

/// The powers of ten an `f64` holds exactly.
const POW10: [f64; 23] = [
    1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16,
    1e17, 1e18, 1e19, 1e20, 1e21, 1e22,
];

/// Mantissa bits of an `f64` below the implicit one.
const MANTISSA_BITS: i32 = 52;

/// `w 10^q` rounded to the nearest `f64` (ties to even), or `None` (module doc).
#[inline]
fn to_f64(w: u64, q: i32) -> Option<f64> {
    if w == 0 {
        return Some(0.0);
    }
    if w <= 1 << 53 && (-22..=22).contains(&q) {
        let v = w as f64;
        return Some(if q < 0 {
            v / POW10[(-q) as usize]
        } else {
            v * POW10[q as usize]
        });
    }
    if !(Q_MIN..=Q_MAX).contains(&q) {
        return None;
    }
    let lz = w.leading_zeros();
    let w = w << lz;
    let (hi5, lo5) = POW5[(q - Q_MIN) as usize];
    let first = u128::from(w) * u128::from(hi5);
    let (mut lo, mut hi) = (first as u64, (first >> 64) as u64);
    // the bits below the mantissa and its rounding bits all ones: the second word decides
    const BELOW: u64 = u64::MAX >> (MANTISSA_BITS + 3);
    if hi & BELOW == BELOW {
        let second_hi = ((u128::from(w) * u128::from(lo5)) >> 64) as u64;
        lo = lo.wrapping_add(second_hi);
        if second_hi > lo {
            hi += 1;
        }
    }
    // still ambiguous outside the exponents where 5^q fits in 64 bits: decline
    if lo == u64::MAX && !(-27..=55).contains(&q) {
        return None;
    }
    let upper = (hi >> 63) as i32;
    let shift = upper + 64 - MANTISSA_BITS - 3;
    let mut m = hi >> shift;
    // floor(log2(10^q)) + 63, by the fixed-point 217706 / 2^16 ~ log2(10)
    let power = (q.wrapping_mul(152_170 + 65_536) >> 16) + 63;
    let mut exponent = power + upper - lz as i32 + 1023;
    if exponent <= 0 {
        return None; // subnormal
    }
    // exactly halfway between two f64 (possible only for these q): round to even
    if lo <= 1 && (-4..=23).contains(&q) && m & 3 == 1 && (m << shift) == hi {
        m &= !1;
    }
    m += m & 1;
    m >>= 1;
    if m >= 2 << MANTISSA_BITS {
        m = 1 << MANTISSA_BITS;
        exponent += 1;
    }
    m &= !(1 << MANTISSA_BITS);
    if exponent >= 0x7FF {
        return None; // beyond f64::MAX
    }
    Some(f64::from_bits(m | (exponent as u64) << MANTISSA_BITS))
}

/// T(q) for q = [`Q_MIN`] + index, as (high, low) 64-bit words.
static POW5: [(u64, u64); (Q_MAX - Q_MIN + 1) as usize] = {
    let mut t = [(0, 0); (Q_MAX - Q_MIN + 1) as usize];
    let mut i = 0;
    while i < t.len() {
        t[i] = pow5_128(Q_MIN + i as i32);
        i += 1;
    }
    t
};

/// Limbs of the compile-time big integers (least significant first): 512 bits hold
/// 2^(2 z + 128) for 5^64 (z = 149).
const LIMBS: usize = 8;
type Big = [u64; LIMBS];

/// T(q) (module doc): 5^q for q >= 0; for q < 0, floor(2^b / 5^-q) + 1 with z the bit
/// length of 5^-q and b = z + 127 (q >= -27) or 2 z + 128; then its 128 most significant
/// bits (shifted left when shorter).
const fn pow5_128(q: i32) -> (u64, u64) {
    let mut c = one();
    if q >= 0 {
        let mut k = 0;
        while k < q {
            c = mul_small(c, 5);
            k += 1;
        }
    } else {
        let mut p = one();
        let mut k = 0;
        while k < -q {
            p = mul_small(p, 5);
            k += 1;
        }
        let z = bit_length(&p);
        let b = if q < -27 { 2 * z + 128 } else { z + 127 };
        c = [0; LIMBS];
        c[(b / 64) as usize] = 1 << (b % 64);
        // floor(floor(x / 5) / 5) = floor(x / 25): k divisions by 5 give floor(2^b / 5^k)
        let mut k = 0;
        while k < -q {
            c = div_small(c, 5);
            k += 1;
        }
        c = add_one(c);
    }
    let n = bit_length(&c);
    c = if n < 128 {
        shift_left(c, 128 - n)
    } else {
        shift_right(c, n - 128)
    };
    (c[1], c[0])
}

const fn one() -> Big {
    let mut c = [0; LIMBS];
    c[0] = 1;
    c
}

const fn mul_small(mut c: Big, f: u64) -> Big {
    let mut carry = 0u128;
    let mut i = 0;
    while i < LIMBS {
        let v = c[i] as u128 * f as u128 + carry;
        c[i] = v as u64;
        carry = v >> 64;
        i += 1;
    }
    c
}

const fn div_small(mut c: Big, d: u64) -> Big {
    let mut rem = 0u128;
    let mut i = LIMBS;
    while i > 0 {
        i -= 1;
        let v = (rem << 64) | c[i] as u128;
        c[i] = (v / d as u128) as u64;
        rem = v % d as u128;
    }
    c
}

const fn add_one(mut c: Big) -> Big {
    let mut i = 0;
    while i < LIMBS {
        let (v, carry) = c[i].overflowing_add(1);
        c[i] = v;
        if !carry {
            break;
        }
        i += 1;
    }
    c
}

const fn bit_length(c: &Big) -> u32 {
    let mut i = LIMBS;
    while i > 0 {
        i -= 1;
        if c[i] != 0 {
            return i as u32 * 64 + 64 - c[i].leading_zeros();
        }
    }
    0
}

const fn shift_left(c: Big, s: u32) -> Big {
    let mut out = [0; LIMBS];
    let (limbs, bits) = ((s / 64) as usize, s % 64);
    let mut i = LIMBS;
    while i > limbs {
        i -= 1;
        let from = i - limbs;
        let mut v = c[from] << bits;
        if bits > 0 && from > 0 {
            v |= c[from - 1] >> (64 - bits);
        }
        out[i] = v;
    }
    out
}

const fn shift_right(c: Big, s: u32) -> Big {
    let mut out = [0; LIMBS];
    let (limbs, bits) = ((s / 64) as usize, s % 64);
    let mut i = 0;
    while i + limbs < LIMBS {
        let from = i + limbs;
        let mut v = c[from] >> bits;
        if bits > 0 && from + 1 < LIMBS {
            v |= c[from + 1] << (64 - bits);
        }
        out[i] = v;
        i += 1;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// fast-float2's reading of the start of `s`, which ours must equal when we take it.
    fn reference(s: &[u8]) -> Option<(u64, usize)> {
        fast_float2::parse_partial::<f64, _>(s)
            .ok()
            .map(|(v, n)| (v.to_bits(), n))
    }

    fn agrees(s: &[u8]) -> Result<(), TestCaseError> {
        if let Some((v, n)) = parse_prefix(s) {
            prop_assert_eq!(
                Some((v.to_bits(), n)),
                reference(s),
                "{:?}",
                String::from_utf8_lossy(s)
            );
        }
        Ok(())
    }

    #[test]
    fn the_table_holds_known_powers() {
        // 5^0 = 2^127 normalised; 5^1 = 0b101 << 125; 5^-1 = 2^b / 5 + 1 normalised:
        // 0xCCCC...CCCD (0.2 = 0.0011 0011... in binary, rounded up)
        assert_eq!(POW5[(-Q_MIN) as usize], (1 << 63, 0));
        assert_eq!(POW5[(1 - Q_MIN) as usize], (0b101 << 61, 0));
        assert_eq!(
            POW5[(-1 - Q_MIN) as usize],
            (0xCCCC_CCCC_CCCC_CCCC, 0xCCCC_CCCC_CCCC_CCCD)
        );
        // q >= 0 up to 55: exactly 5^q shifted to 128 bits (5^55 < 2^128)
        for q in 0..=55u32 {
            let p = 5u128.pow(q);
            let t = p << p.leading_zeros();
            let (hi, lo) = POW5[(q as i32 - Q_MIN) as usize];
            assert_eq!((u128::from(hi) << 64) | u128::from(lo), t, "q = {q}");
        }
        // -27 <= q < 0: T = floor(2^b / 5^k) + 1 with b = z + 127 (128 bits already), so
        // 0 < T 5^k - 2^b <= 5^k; the product fits in 256 bits (5^27 < 2^63)
        for k in 1..=27u32 {
            let (hi, lo) = POW5[(-(k as i32) - Q_MIN) as usize];
            let t = (u128::from(hi) << 64) | u128::from(lo);
            let p = 5u128.pow(k);
            let z = 128 - p.leading_zeros();
            let b = z + 127;
            // t * p = (high, low) in 256 bits; p < 2^64
            let (t1, t0) = (t >> 64, t & u128::from(u64::MAX));
            let low0 = t0 * p;
            let mid = t1 * p + (low0 >> 64);
            let (high, low) = (mid >> 64, (mid << 64) | (low0 & u128::from(u64::MAX)));
            // minus 2^b (b >= 128 here: a bit of `high`)
            assert!(b >= 128, "k = {k}");
            let high = high - (1u128 << (b - 128));
            assert!(high == 0 && low > 0 && low <= p, "k = {k}");
        }
    }

    /// A few values of every decimal exponent the table covers, 1 to 19 digits, against
    /// fast-float2 (a wrong T(q) shows at its q).
    #[test]
    fn every_exponent_of_the_table_reads_as_fast_float2_reads_it() {
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            // xorshift64
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        let mut taken = 0;
        for q in Q_MIN..=Q_MAX {
            for digits in 1..=19u32 {
                for _ in 0..8 {
                    let w = next() % 10u64.pow(digits);
                    let s = format!("{w}e{q},");
                    agrees(s.as_bytes()).unwrap();
                    taken += usize::from(parse_prefix(s.as_bytes()).is_some());
                }
            }
        }
        // all but the odd ambiguous product, subnormal or overflow are taken
        assert!(taken > 19_000, "{taken}");
    }

    #[test]
    fn numbers_of_the_response_csv_are_taken_bit_for_bit() {
        for s in [
            "0",
            "-0",
            "0.0001",
            "5.889325051644407e-11",
            "-5.830368903832546e-11",
            "0.012566370614359173",
            "125.66370614359172",
            "12566.370614359172",
            "1195000",
            "1e-4",
            "1E5",
            "2.5e+3",
            ".5",
            "5.",
            "9007199254740993",
            "1.7976931348623157e308",
            "2.2250738585072014e-308",
        ] {
            let s = format!("{s},");
            agrees(s.as_bytes()).unwrap();
        }
        // taken where they should be (not just declined)
        assert_eq!(parse_prefix(b"5.889325051644407e-11,").unwrap().1, 21);
        assert_eq!(parse_prefix(b"-0\n"), Some((-0.0, 2)));
        assert!(parse_prefix(b"-0\n").unwrap().0.is_sign_negative());
        // declined: fast-float2 decides
        for s in [
            "+1", "inf", "nan", "-", ".", "e5", "1e", "1e+", "1e12345", "1e-400", "",
        ] {
            assert_eq!(parse_prefix(s.as_bytes()), None, "{s}");
        }
    }

    #[test]
    fn halfway_values_round_to_even_as_fast_float2_does() {
        // 2^53 + 1 and + 3 are halfway between two f64; so are their scaled copies
        for w in [9_007_199_254_740_993u64, 9_007_199_254_740_995] {
            for q in -4..=23 {
                let s = format!("{w}e{q} ");
                agrees(s.as_bytes()).unwrap();
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(20_000))]

        #[test]
        fn every_f64_written_shortest_or_with_17_digits_reads_back(bits in any::<u64>()) {
            let v = f64::from_bits(bits);
            prop_assume!(v.is_finite());
            for s in [format!("{v}"), format!("{v:e}"), format!("{v:.16e}"), format!("{v:?}")] {
                let line = format!("{s},1\n");
                agrees(line.as_bytes())?;
                if let Some((got, _)) = parse_prefix(line.as_bytes()) {
                    prop_assert_eq!(got.to_bits(), s.parse::<f64>().unwrap().to_bits());
                }
            }
        }

        #[test]
        fn digit_strings_and_exponents_read_as_fast_float2_reads_them(
            neg in any::<bool>(),
            int in "[0-9]{0,12}",
            frac in proptest::option::of("[0-9]{0,20}"),
            exp in proptest::option::of((
                prop_oneof![Just("e"), Just("E")],
                prop_oneof![Just(""), Just("-"), Just("+")],
                0u32..400,
            )),
            // (a long tail: the digits are read 8 bytes at a time up to the number's end)
            tail in prop_oneof![Just(","), Just("\n"), Just("\r"), Just("x"), Just(""), Just(",1.5"),
                Just(",125.66370614359172,5.889325051644407e-11\n")],
        ) {
            let mut s = String::new();
            if neg {
                s.push('-');
            }
            s.push_str(&int);
            if let Some(f) = &frac {
                s.push('.');
                s.push_str(f);
            }
            if let Some((e, sign, n)) = &exp {
                s.push_str(&format!("{e}{sign}{n}"));
            }
            s.push_str(tail);
            agrees(s.as_bytes())?;
        }

        #[test]
        fn arbitrary_bytes_are_taken_only_as_fast_float2_takes_them(
            s in proptest::collection::vec(
                prop_oneof![Just(b'-'), Just(b'+'), Just(b'.'), Just(b'e'), Just(b','), 0x30u8..0x3A, any::<u8>()],
                0..40,
            )
        ) {
            agrees(&s)?;
        }
    }
}
