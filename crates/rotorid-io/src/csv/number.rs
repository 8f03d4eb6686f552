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
//! Numbers in messages go through [`readable`]: the same text, with an exponent written as
//! `1.0e300` (a decimal point in the mantissa), so a huge or tiny value is never printed
//! as 300 digits and never mistaken for an integer.

use std::fmt;
use std::io::{self, Write};

/// Append the shortest round-trip text of `v` to `out` (see the module doc for the format).
pub fn push_f64(out: &mut Vec<u8>, v: f64) {
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
