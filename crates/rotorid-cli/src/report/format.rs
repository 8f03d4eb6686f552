//! Number formatting for the report tables (markdown and HTML alike).
//!
//! ```text
//! value     7 significant digits: 14.29000, 10.00004, 1.195000e6 (scientific from 1e5 up)
//! error     signed, 2 decimals in scientific: +1.23e-4
//! time      seconds to 0.1 ms (the sampling period): 0.0163 s
//! share     percent to 2 decimals: 1.91 %
//! ```

/// A parameter value with 7 significant digits.
pub fn value(v: f64) -> String {
    if !v.is_finite() {
        return format!("{v}");
    }
    let a = v.abs();
    if a != 0.0 && !(1e-3..1e5).contains(&a) {
        return format!("{v:.6e}");
    }
    let digits_before = if a < 1.0 {
        1
    } else {
        a.log10().floor() as i32 + 1
    };
    let decimals = (7 - digits_before).max(0) as usize;
    format!("{v:.decimals$}")
}

/// An optional value, or an em dash.
pub fn opt_value(v: Option<f64>) -> String {
    v.map_or_else(|| "\u{2014}".to_string(), value)
}

/// A signed relative error, or an em dash.
pub fn rel_error(e: Option<f64>) -> String {
    match e {
        Some(0.0) => "0".to_string(),
        Some(e) => format!("{e:+.2e}"),
        None => "\u{2014}".to_string(),
    }
}

/// A time in seconds to 0.1 ms, or `not within 1 %` when the estimate never settled.
pub fn time(t: Option<f64>) -> String {
    t.map_or_else(|| "not within 1 %".to_string(), |t| format!("{t:.4} s"))
}

/// A fraction as a percentage with 2 decimals; `< 0.01 %` for a non-zero fraction that
/// would print as zero.
pub fn percent(f: f64) -> String {
    if f > 0.0 && f < 5e-5 {
        "< 0.01 %".to_string()
    } else {
        format!("{:.2} %", 100.0 * f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_keep_seven_significant_digits() {
        assert_eq!(value(14.29), "14.29000");
        assert_eq!(value(10.000_04), "10.00004");
        assert_eq!(value(1.195e6), "1.195000e6");
        assert_eq!(value(0.5), "0.500000");
        assert_eq!(rel_error(Some(-1.234e-4)), "-1.23e-4");
        assert_eq!(rel_error(Some(3e-9)), "+3.00e-9");
        assert_eq!(time(Some(0.01634)), "0.0163 s");
        assert_eq!(time(None), "not within 1 %");
        assert_eq!(opt_value(None), "\u{2014}");
        assert_eq!(percent(0.0191), "1.91 %");
        assert_eq!(percent(1.25e-5), "< 0.01 %");
        assert_eq!(percent(0.0), "0.00 %");
    }
}
