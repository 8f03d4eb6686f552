//! Numbers in CSV files: every `f64` is printed so that parsing it back with
//! `str::parse::<f64>` gives the identical bits (shortest round-trip representation).
//!
//! Rust's `Display` and `LowerExp` for `f64` (without a precision) both print the
//! *shortest* decimal string that reads back to the same value, but `Display` never uses an
//! exponent: `1e-300` would print as 300 zeros. We therefore use
//!
//! ```text
//! v == 0 or 1e-4 <= |v| < 1e15  ->  Display  ("0.0001", "14.29", "1195000")
//! otherwise                     ->  LowerExp ("1.2345e-7", "3e15")
//! NaN, +inf, -inf               ->  "NaN", "inf", "-inf"  (what `f64::from_str` accepts)
//! ```
//!
//! Both branches are exact round trips, so the choice only affects length and readability.
//!
//! The digits come from `ryu` (the shortest digits that read back to `v`, the closest of
//! them to `v`, as `Display` finds them) and are laid out here as `Display` or `LowerExp`
//! lay them out: the text is byte for byte what `format!("{v}")` / `format!("{v:e}")` give
//! (tested on random bit patterns), at a fraction of the cost.
//!
//! Numbers are read with [`parse_f64`]: `str::parse::<f64>` after trimming blanks, bit for
//! bit, through [`super::decimal`]'s fast path and `fast-float2` for plain decimal text
//! (both tested against `str::parse`).
//!
//! Numbers in messages go through [`readable`]: the same text, with an exponent written as
//! `1.0e300` (a decimal point in the mantissa), so a huge or tiny value is never printed
//! as 300 digits and never mistaken for an integer.

use std::fmt;
use std::io::{self, Write};

/// Append the shortest round-trip text of `v` to `out` (see the module doc for the format).
pub fn push_f64(out: &mut Vec<u8>, v: f64) {
    if !v.is_finite() {
        out.extend_from_slice(if v.is_nan() {
            b"NaN"
        } else if v > 0.0 {
            b"inf"
        } else {
            b"-inf"
        });
        return;
    }
    if v.is_sign_negative() {
        out.push(b'-');
    }
    if v == 0.0 {
        out.push(b'0');
        return;
    }
    let mut ryu = ryu::Buffer::new();
    let (mut digits, mut n, mut point) = shortest_digits(ryu.format_finite(v.abs()).as_bytes());
    if is_tie(v.abs(), &digits[..n], point - n as i32) {
        // Exactly halfway between two shortest candidates: ryu takes the even one,
        // `Display` the larger; take the larger.
        let mut i = n;
        loop {
            i -= 1;
            if digits[i] == b'9' {
                digits[i] = b'0';
                if i == 0 {
                    digits[0] = b'1';
                    point += 1;
                    break;
                }
            } else {
                digits[i] += 1;
                break;
            }
        }
        while n > 1 && digits[n - 1] == b'0' {
            n -= 1;
        }
    }
    let digits = &digits[..n];
    if (1e-4..1e15).contains(&v.abs()) {
        // Display: 0.000ddd, dd.ddd or ddd000
        if point <= 0 {
            out.extend_from_slice(b"0.");
            out.resize(out.len() + point.unsigned_abs() as usize, b'0');
            out.extend_from_slice(digits);
        } else if (point as usize) < n {
            let (int, frac) = digits.split_at(point as usize);
            out.extend_from_slice(int);
            out.push(b'.');
            out.extend_from_slice(frac);
        } else {
            out.extend_from_slice(digits);
            out.resize(out.len() + point as usize - n, b'0');
        }
    } else {
        // LowerExp: d.ddde-7, de15
        out.push(digits[0]);
        if n > 1 {
            out.push(b'.');
            out.extend_from_slice(&digits[1..]);
        }
        out.push(b'e');
        push_exponent(out, point - 1);
    }
}

/// The significant digits of ryu's text of a positive finite number (`"1.2345e-7"`,
/// `"0.0001"`, `"1195000.0"`): the digits without leading or trailing zeros, their count,
/// and the position of the decimal point before the first (the value is `0.DIGITS` times
/// ten to that power).
fn shortest_digits(text: &[u8]) -> ([u8; 24], usize, i32) {
    let (mantissa, exp) = match text.iter().position(|&b| b == b'e') {
        Some(i) => (&text[..i], parse_small_int(&text[i + 1..])),
        None => (text, 0),
    };
    let mut digits = [0u8; 24];
    let (mut n, mut int_len, mut seen_point, mut leading) = (0usize, 0i32, false, 0i32);
    for &b in mantissa {
        if b == b'.' {
            seen_point = true;
            continue;
        }
        if !seen_point {
            int_len += 1;
        }
        if n == 0 && b == b'0' {
            leading += 1;
            continue;
        }
        digits[n] = b;
        n += 1;
    }
    while n > 1 && digits[n - 1] == b'0' {
        n -= 1;
    }
    (digits, n, int_len - leading + exp)
}

/// True when `v` > 0 is exactly `(DIGITS + 1/2) * 10^k`: halfway between the shortest
/// candidate `DIGITS * 10^k` and the next one up. With `v = m * 2^e`, `m` odd, and
/// `2 DIGITS + 1` odd, that is `e = k - 1` and `m = (2 DIGITS + 1) * 5^k` (k >= 0) or
/// `m * 5^-k = 2 DIGITS + 1` (k < 0), checked in integers.
fn is_tie(v: f64, digits: &[u8], k: i32) -> bool {
    let bits = v.to_bits();
    let (mut m, mut e) = match (bits >> 52) as i32 {
        0 => (bits, -1074),
        biased => ((bits & ((1 << 52) - 1)) | (1 << 52), biased - 1075),
    };
    let zeros = m.trailing_zeros();
    m >>= zeros;
    e += zeros as i32;
    if e != k - 1 {
        return false;
    }
    let odd = digits
        .iter()
        .fold(0u128, |acc, &d| acc * 10 + u128::from(d - b'0'))
        * 2
        + 1;
    let pow5 = |j: u32| 5u128.checked_pow(j);
    if k >= 0 {
        pow5(k as u32)
            .and_then(|p| odd.checked_mul(p))
            .is_some_and(|x| x == u128::from(m))
    } else {
        pow5(k.unsigned_abs())
            .and_then(|p| u128::from(m).checked_mul(p))
            .is_some_and(|x| x == odd)
    }
}

/// A decimal exponent such as `-7` or `15` (ryu writes at most three digits).
fn parse_small_int(text: &[u8]) -> i32 {
    let (neg, digits) = match text.split_first() {
        Some((b'-', rest)) => (true, rest),
        _ => (false, text),
    };
    let v = digits
        .iter()
        .fold(0i32, |acc, &d| acc * 10 + i32::from(d - b'0'));
    if neg {
        -v
    } else {
        v
    }
}

/// Append the decimal text of the exponent `e` (|e| < 1000) to `out`.
fn push_exponent(out: &mut Vec<u8>, e: i32) {
    if e < 0 {
        out.push(b'-');
    }
    let u = e.unsigned_abs();
    if u >= 100 {
        out.push(b'0' + (u / 100) as u8);
    }
    if u >= 10 {
        out.push(b'0' + (u / 10 % 10) as u8);
    }
    out.push(b'0' + (u % 10) as u8);
}

/// `raw` (a field, ASCII blanks already trimmed) as `str::parse::<f64>` reads it after
/// `str::trim`, bit for bit; `None` where that refuses it. First
/// [`super::decimal::number_prefix`] (its fast path, then fast-float2, which accepts exactly
/// the texts `str::parse` accepts: decimal with sign, point and exponent; `inf`,
/// `infinity`, `nan` in any case, signed; and rounds them correctly as it does: the
/// property tests below check both claims), taken when the number is the whole field; what
/// that refuses (Unicode blanks, garbage) goes to `str::parse`, which trims and decides. No
/// pre-scan of the bytes: that cost a third of the CSV reader's time.
#[inline]
pub fn parse_f64(raw: &[u8]) -> Option<f64> {
    if let Some((v, n)) = super::decimal::number_prefix(raw) {
        if n == raw.len() {
            return Some(v);
        }
    }
    std::str::from_utf8(raw)
        .ok()
        .and_then(|s| s.trim().parse::<f64>().ok())
}

/// The text `push_f64` wrote before it used ryu: `Display` or `LowerExp` (the reference
/// the fast layout is tested against).
#[cfg(test)]
fn push_f64_std(out: &mut Vec<u8>, v: f64) {
    // Writing into a Vec<u8> cannot fail.
    let a = v.abs();
    if v == 0.0 || (1e-4..1e15).contains(&a) || !v.is_finite() {
        if v.is_nan() {
            out.extend_from_slice(b"NaN");
        } else {
            write!(out, "{v}").expect("writing to a Vec cannot fail");
        }
    } else {
        write!(out, "{v:e}").expect("writing to a Vec cannot fail");
    }
}

/// The shortest round-trip text of `v` as a `String` (see the module doc).
pub fn format_f64(v: f64) -> String {
    let mut buf = Vec::with_capacity(24);
    push_f64(&mut buf, v);
    String::from_utf8(buf).expect("number text is ASCII")
}

/// `v` for a message: the shortest round-trip text, with an exponent beyond
/// 1e-4 <= |v| < 1e15 and a decimal point in its mantissa (`14.29`, `1.0e300`, `-2.5e-7`,
/// `inf`, `NaN`). Use it as `format!("t = {} s", readable(t))`.
pub fn readable(v: f64) -> Readable {
    Readable(v)
}

/// The [`fmt::Display`] of [`readable`].
#[derive(Debug, Clone, Copy)]
pub struct Readable(pub f64);

impl fmt::Display for Readable {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut buf = Vec::with_capacity(24);
        push_f64(&mut buf, self.0);
        let text = String::from_utf8_lossy(&buf);
        match text.split_once('e') {
            Some((mantissa, exp)) if !mantissa.contains('.') => write!(f, "{mantissa}.0e{exp}"),
            _ => f.write_str(&text),
        }
    }
}

/// `v` with `sig` significant digits for people (not a round trip): fixed notation for
/// 1e-3 <= |v| < 1e7 (`14.290000`, `1195000.0`), scientific otherwise (`1.2345e-7`).
pub fn format_sig(v: f64, sig: usize) -> String {
    let sig = sig.max(1);
    let a = v.abs();
    if !v.is_finite() || a == 0.0 {
        return format!("{v}");
    }
    if (1e-3..1e7).contains(&a) {
        let mag = a.log10().floor() as i64;
        let decimals = (sig as i64 - 1 - mag).max(0) as usize;
        let s = format!("{v:.decimals$}");
        // Rounding may carry into a new digit (9.9996 -> 10.000): keep `sig` digits.
        if s.trim_start_matches('-')
            .replace('.', "")
            .trim_start_matches('0')
            .len()
            > sig
            && decimals > 0
        {
            return format!("{v:.prec$}", prec = decimals - 1);
        }
        s
    } else {
        format!("{v:.prec$e}", prec = sig - 1)
    }
}

/// Write one CSV row of numbers (comma-separated, `\n`-terminated) with a single
/// `write_all`, so a buffered writer never holds half a row when it flushes. `scratch` is
/// reused between rows to avoid an allocation per row.
pub fn write_row<W: Write + ?Sized>(
    out: &mut W,
    scratch: &mut Vec<u8>,
    fields: &[Option<f64>],
) -> io::Result<()> {
    scratch.clear();
    for (i, v) in fields.iter().enumerate() {
        if i > 0 {
            scratch.push(b',');
        }
        if let Some(v) = v {
            push_f64(scratch, *v);
        }
    }
    scratch.push(b'\n');
    out.write_all(scratch)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn round_trips(v: f64) {
        let s = format_f64(v);
        let back: f64 = s
            .parse()
            .unwrap_or_else(|e| panic!("{s:?} does not parse: {e}"));
        if v.is_nan() {
            assert!(back.is_nan(), "{v:?} -> {s} -> {back:?}");
        } else {
            assert_eq!(back.to_bits(), v.to_bits(), "{v:?} -> {s} -> {back:?}");
        }
        assert!(s.len() <= 24, "{v:?} printed as {s} ({} chars)", s.len());
    }

    #[test]
    fn edge_values_round_trip() {
        let edges = [
            0.0,
            -0.0,
            1.0,
            -1.0,
            1e-4,
            9.999999999999999e-5,
            1e15,
            999999999999999.9,
            1e-300,
            -1e300,
            f64::MIN_POSITIVE,
            f64::MIN_POSITIVE / 3.0, // subnormal
            5e-324,
            f64::MAX,
            f64::MIN,
            f64::EPSILON,
            0.1 + 0.2,
            1.195e6,
            14.29,
            2.871,
            3.0 * 1e-4,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        for v in edges {
            round_trips(v);
        }
    }

    /// Property test over random bit patterns (every sign, exponent and mantissa is
    /// reachable), and over `i * dt` grids as written by `simulate`. A xorshift generator
    /// with a fixed seed keeps the test deterministic.
    #[test]
    fn random_bit_patterns_round_trip() {
        let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
        for _ in 0..200_000 {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            round_trips(f64::from_bits(s));
        }
        for i in 0..20_000u32 {
            round_trips(f64::from(i) * 1e-4);
            round_trips(f64::from(i) * 3.3e-5);
        }
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(100_000))]

        /// The ryu layout is byte for byte the `Display`/`LowerExp` text, on any bits.
        #[test]
        fn ryu_layout_is_the_std_text(bits in proptest::prelude::any::<u64>()) {
            let v = f64::from_bits(bits);
            let (mut fast, mut std) = (Vec::new(), Vec::new());
            push_f64(&mut fast, v);
            push_f64_std(&mut std, v);
            proptest::prop_assert_eq!(fast, std);
        }

        /// ... and on values of ordinary size, near the notation's edges and on grids.
        #[test]
        fn ryu_layout_is_the_std_text_near_the_edges(
            m in 1.0f64..10.0,
            e in -8i32..18,
            i in 0u32..2_000_000,
            neg in proptest::prelude::any::<bool>(),
        ) {
            let s = if neg { -1.0 } else { 1.0 };
            for v in [s * m * 10f64.powi(e), s * f64::from(i) * 1e-4, s * f64::from(i) * 3.3e-5] {
                let (mut fast, mut std) = (Vec::new(), Vec::new());
                push_f64(&mut fast, v);
                push_f64_std(&mut std, v);
                proptest::prop_assert_eq!(fast, std, "{:e}", v);
            }
        }

        /// `parse_f64` is `str::parse` bit for bit: on the shortest text of any bits ...
        #[test]
        fn parse_is_std_on_shortest_texts(bits in proptest::prelude::any::<u64>()) {
            let v = f64::from_bits(bits);
            for text in [format_f64(v), format!("{v:e}"), format!("{v:.17e}"), format!("{v:?}")] {
                same_as_std(&text)?;
            }
        }

        /// ... on decimal text of every shape (long mantissas, halfway cases, signs,
        /// exponents out of range, malformed) ...
        #[test]
        fn parse_is_std_on_decimal_text(text in "[-+]?[0-9]{0,25}(\\.[0-9]{0,25})?([eE][-+]?[0-9]{1,4})?") {
            same_as_std(&text)?;
        }

        /// ... and on anything made of its characters, or of the words infinity and NaN.
        #[test]
        fn parse_is_std_on_garbage(text in "[-+.eE0-9]{0,12}") {
            same_as_std(&text)?;
        }

        #[test]
        fn parse_is_std_on_words(text in "[-+ ]?[iInNfFaAtTyY0-9.e]{0,9}[ \t]?") {
            same_as_std(&text)?;
        }
    }

    #[test]
    fn parse_is_std_on_special_words() {
        for text in [
            "inf",
            "-inf",
            "+inf",
            "INF",
            "Infinity",
            "-infinity",
            "+INFINITY",
            "infinit",
            "infinityy",
            "in",
            "nan",
            "NaN",
            "-nan",
            "+NAN",
            "nana",
            "na",
            "-",
            "+",
            "",
            "1e",
            "1e+",
            ".e1",
            "+.5",
            "-.5e-3",
            "5.",
            "0x10",
            "1_0",
            "1 2",
            "\u{a0}1",
        ] {
            same_as_std(text).unwrap();
        }
    }

    fn same_as_std(text: &str) -> Result<(), proptest::test_runner::TestCaseError> {
        let ours = parse_f64(text.as_bytes()).map(f64::to_bits);
        let std = text.trim().parse::<f64>().ok().map(f64::to_bits);
        proptest::prop_assert_eq!(ours, std, "{:?}", text);
        Ok(())
    }

    #[test]
    // the literals are exact binary values: their last digit is the point
    #[allow(clippy::excessive_precision)]
    fn halfway_digits_round_up_as_display_does() {
        // exactly halfway between two 17-digit candidates: ryu alone says ...812
        for (v, text) in [
            (14003347900076.8125, "14003347900076.812"),
            (f64::from_bits(4803503317274417568), ""),
            (-78004056428445.625, "-78004056428445.62"),
        ] {
            let mut std = Vec::new();
            push_f64_std(&mut std, v);
            assert_eq!(format_f64(v).as_bytes(), std.as_slice(), "{v:e}");
            assert!(!format_f64(v).starts_with(text) || text.is_empty(), "{v:e}");
        }
    }

    #[test]
    fn parse_tricky_decimals_as_std() {
        for text in [
            "0",
            "-0",
            "+0",
            "1",
            "1.",
            ".5",
            "-.5",
            "1e5",
            "1E-5",
            "1e+5",
            "1e",
            "e5",
            ".",
            "-",
            "+",
            "",
            "1..2",
            "1e5.5",
            "--1",
            "0x10",
            "inf",
            "-inf",
            "+infinity",
            "NaN",
            "nan",
            "-NaN",
            " 1.5 ",
            "1.5\u{a0}",
            "\u{b}2",
            "1_000",
            // halfway between two doubles, and one digit either side
            "9007199254740993",
            "9007199254740992.9999999999999999999999",
            "9007199254740993.0000000000000000000001",
            "2.2250738585072011e-308",
            "2.2250738585072012e-308",
            "4.9406564584124654e-324",
            "2.4703282292062327e-324",
            "2.4703282292062328e-324",
            "1.7976931348623157e308",
            "1.7976931348623158e308",
            "1.7976931348623159e308",
            "1e400",
            "-1e400",
            "1e-400",
            "0.1000000000000000055511151231257827021181583404541015625",
            "0.1000000000000000055511151231257827021181583404541015624",
            "0.1000000000000000055511151231257827021181583404541015626",
            "123456789012345678901234567890e-10",
            "0.000000000000000000000000000001e30",
            "7.2057594037927933e16",
            "3.3e-300",
            "125.66370614359172",
        ] {
            same_as_std(text).unwrap();
        }
    }

    #[test]
    fn readable_choice_of_notation() {
        assert_eq!(format_f64(0.0), "0");
        assert_eq!(format_f64(1e-4), "0.0001");
        assert_eq!(format_f64(14.29), "14.29");
        assert_eq!(format_f64(1.195e6), "1195000");
        assert_eq!(format_f64(1.5e-7), "1.5e-7");
        assert_eq!(format_f64(1e-300), "1e-300");
        assert_eq!(format_f64(2e15), "2e15");
        assert_eq!(format_f64(f64::NAN), "NaN");
        assert_eq!(format_f64(f64::NEG_INFINITY), "-inf");
    }

    #[test]
    fn messages_never_spell_out_huge_numbers() {
        assert_eq!(readable(1e300).to_string(), "1.0e300");
        assert_eq!(readable(-2.5e-7).to_string(), "-2.5e-7");
        assert_eq!(readable(14.29).to_string(), "14.29");
        assert_eq!(readable(0.0).to_string(), "0");
        assert_eq!(readable(f64::MAX).to_string(), "1.7976931348623157e308");
        assert_eq!(readable(f64::INFINITY).to_string(), "inf");
        assert_eq!(readable(f64::NAN).to_string(), "NaN");
    }

    #[test]
    fn significant_digits_for_people() {
        assert_eq!(format_sig(14.29, 8), "14.290000");
        assert_eq!(format_sig(1.195e6, 8), "1195000.0");
        assert_eq!(format_sig(9.99996, 4), "10.00");
        assert_eq!(format_sig(-0.0123456, 3), "-0.0123");
        assert_eq!(format_sig(1.5e-7, 3), "1.50e-7");
        assert_eq!(format_sig(0.0, 3), "0");
    }

    #[test]
    fn rows_are_whole_lines_and_missing_values_are_empty() {
        let mut out = Vec::new();
        let mut scratch = Vec::new();
        write_row(&mut out, &mut scratch, &[Some(0.5), None, Some(-2.0)]).unwrap();
        assert_eq!(out, b"0.5,,-2\n");
    }
}
