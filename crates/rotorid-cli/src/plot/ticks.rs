//! Tick labels in engineering notation: as many digits as the tick spacing resolves, and
//! no more (`1.195e6`, `14.285`, `0.12`; never `1195000.0000`).
//!
//! ```text
//! step  = smallest spacing between adjacent ticks
//! fixed notation       (1e-3 <= max|v| < 1e5):  decimals = max(0, ceil(-log10(step)))
//! scientific notation  (otherwise):              mantissa decimals of v =
//!                                                max(0, floor(log10|v|) - floor(log10(step)))
//! ```
//!
//! The tick positions themselves are plotters' (its 1-2-5 key points for the axis range);
//! [`TickFormat::for_axis`] asks plotters for the same key points the mesh will draw, so
//! the precision always matches the spacing actually shown.

use plotters::coord::ranged1d::Ranged;
use plotters::coord::types::RangedCoordf64;

/// Axis magnitudes at or above this use scientific notation.
const SCI_ABOVE: f64 = 1e5;
/// Non-zero axis magnitudes below this use scientific notation.
const SCI_BELOW: f64 = 1e-3;
/// Slack for floating-point error in log10 of exact decades (log10(0.1) = -0.99999...).
const LOG_SLACK: f64 = 1e-6;

/// How to print the tick values of one axis.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TickFormat {
    /// The smallest spacing between adjacent ticks (same unit as the values).
    step: f64,
    /// Scientific (mantissa e exponent) rather than fixed notation.
    scientific: bool,
}

impl TickFormat {
    /// The format for an axis `lo..hi` labelled with plotters' key points for `n_labels`.
    pub fn for_axis(lo: f64, hi: f64, n_labels: usize) -> Self {
        let ticks = RangedCoordf64::from(lo..hi).key_points(n_labels);
        Self::for_ticks(&ticks, lo, hi)
    }

    /// The format for explicit tick positions on the axis `lo..hi`.
    pub fn for_ticks(ticks: &[f64], lo: f64, hi: f64) -> Self {
        let step = ticks
            .windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .filter(|d| *d > 0.0 && d.is_finite())
            .fold(f64::INFINITY, f64::min);
        let step = if step.is_finite() {
            step
        } else {
            let span = (hi - lo).abs();
            if span > 0.0 && span.is_finite() {
                span
            } else {
                lo.abs().max(hi.abs()).max(1.0)
            }
        };
        let mag = lo.abs().max(hi.abs());
        let scientific = mag >= SCI_ABOVE || (mag > 0.0 && mag < SCI_BELOW);
        Self { step, scientific }
    }

    /// The label for tick value `v`.
    pub fn format(&self, v: f64) -> String {
        if !v.is_finite() {
            return format!("{v}");
        }
        // A value within rounding noise of zero is zero (avoids "-0.00" and "3e-17").
        if v.abs() < self.step * 1e-6 {
            return if self.scientific {
                "0".to_string()
            } else {
                format!("{:.*}", self.fixed_decimals(), 0.0)
            };
        }
        if self.scientific {
            let step_exp = (self.step.log10() + LOG_SLACK).floor();
            let v_exp = (v.abs().log10() + LOG_SLACK).floor();
            let decimals = (v_exp - step_exp).max(0.0) as usize;
            format!("{v:.decimals$e}")
        } else {
            let d = self.fixed_decimals();
            let scale = 10f64.powi(d as i32);
            // + 0.0 turns a rounded -0.0 into 0.0.
            let r = (v * scale).round() / scale + 0.0;
            format!("{r:.d$}")
        }
    }

    fn fixed_decimals(&self) -> usize {
        (-self.step.log10() - LOG_SLACK).ceil().max(0.0) as usize
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn labels(ticks: &[f64]) -> Vec<String> {
        let f = TickFormat::for_ticks(ticks, ticks[0], *ticks.last().unwrap());
        ticks.iter().map(|v| f.format(*v)).collect()
    }

    #[test]
    fn stiffness_ticks_are_engineering() {
        assert_eq!(
            labels(&[1.194e6, 1.195e6, 1.196e6]),
            ["1.194e6", "1.195e6", "1.196e6"]
        );
        assert_eq!(labels(&[0.0, 5e5, 1e6]), ["0", "5e5", "1.0e6"]);
        assert_eq!(labels(&[1.0e6, 1.5e6, 2.0e6]), ["1.0e6", "1.5e6", "2.0e6"]);
    }

    #[test]
    fn fixed_ticks_carry_just_enough_decimals() {
        assert_eq!(
            labels(&[14.28, 14.285, 14.29]),
            ["14.280", "14.285", "14.290"]
        );
        assert_eq!(labels(&[0.1, 0.12, 0.14 + 3e-17]), ["0.10", "0.12", "0.14"]);
        assert_eq!(labels(&[0.0, 0.1, 0.2, 0.3]), ["0.0", "0.1", "0.2", "0.3"]);
        assert_eq!(labels(&[-20.0, 0.0, 20.0]), ["-20", "0", "20"]);
        assert_eq!(labels(&[-1e-17, 0.5, 1.0]), ["0.0", "0.5", "1.0"]);
    }

    #[test]
    fn tiny_values_are_scientific() {
        assert_eq!(
            labels(&[-1e-7, -5e-8, 0.0, 5e-8, 1e-7]),
            ["-1.0e-7", "-5e-8", "0", "5e-8", "1.0e-7"]
        );
    }

    #[test]
    fn plotters_key_points_drive_the_precision() {
        let f = TickFormat::for_axis(0.1, 0.23, 10);
        assert_eq!(f.format(0.12), "0.12");
        let f = TickFormat::for_axis(1.19e6, 1.2e6, 8);
        assert_eq!(f.format(1.195e6), "1.195e6");
    }
}
