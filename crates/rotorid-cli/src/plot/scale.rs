//! Axis ranges: x from the data or a zoom window, y auto-scaled to what is visible.
//!
//! ```text
//! x-range = the zoom window [a, b] if given, else [min x, max x] over all finite points
//! y-range = [min y, max y] over points with x in the x-range, y finite and not masked
//!           (a series' scale mask drops e.g. the ill-conditioned instants of an estimate),
//!           intersected with the panel's limits (a sane band around the truth),
//!           widened to the panel's minimum span about its centre, then padded by 5 %
//! ```
//!
//! Display units: [`si_prefix`] picks the SI prefix that puts the largest magnitude in
//! [1, 1000) (so 2.3e-7 m is plotted as 0.23 um rather than as 2.3e-7).

use super::{Panel, Series};

/// Fraction of the span added above and below the data.
const PAD: f64 = 0.05;

/// The x-range of `panel`: its zoom window, else the extent of its finite data.
pub fn x_range(panel: &Panel) -> (f64, f64) {
    if let Some(r) = panel.x_range {
        return r;
    }
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for s in &panel.series {
        for (&x, &y) in s.x.iter().zip(&s.y) {
            if x.is_finite() && y.is_finite() {
                lo = lo.min(x);
                hi = hi.max(x);
            }
        }
    }
    widen((lo, hi), 0.0)
}

/// The y-range of `panel` over the x-range `(x0, x1)`: a fixed range if the panel has one,
/// else auto-scaled as in the module doc.
pub fn y_range(panel: &Panel, (x0, x1): (f64, f64)) -> (f64, f64) {
    if let Some(r) = panel.y_range {
        return r;
    }
    let (mut lo, mut hi) = visible_extent(&panel.series, x0, x1);
    if let Some((a, b)) = panel.y_limits {
        if lo > b || hi < a || lo > hi {
            // nothing visible within the limits: show the limits themselves
            (lo, hi) = (a, b);
        } else {
            lo = lo.max(a);
            hi = hi.min(b);
        }
    }
    let (lo, hi) = widen((lo, hi), panel.min_y_span);
    let pad = (hi - lo) * PAD;
    (lo - pad, hi + pad)
}

/// min and max of the visible, finite, unmasked y values of `series` (inf, -inf if none).
fn visible_extent(series: &[Series], x0: f64, x1: f64) -> (f64, f64) {
    let mut lo = f64::INFINITY;
    let mut hi = f64::NEG_INFINITY;
    for s in series {
        let mut any_inside = false;
        for (i, (&x, &y)) in s.x.iter().zip(&s.y).enumerate() {
            let counts = s
                .scale_mask
                .as_ref()
                .is_none_or(|m| m.get(i).copied().unwrap_or(true));
            if x >= x0 && x <= x1 {
                any_inside = true;
                if counts && y.is_finite() {
                    lo = lo.min(y);
                    hi = hi.max(y);
                }
            }
        }
        // a line crossing the window with no sample inside it (e.g. a two-point truth line)
        if !any_inside {
            if let Some(y) = interpolate_at(s, 0.5 * (x0 + x1)) {
                lo = lo.min(y);
                hi = hi.max(y);
            }
        }
    }
    (lo, hi)
}

/// Linear interpolation of `s` at `x` when its x is sorted and brackets `x`.
fn interpolate_at(s: &Series, x: f64) -> Option<f64> {
    if s.x.len() < 2 || !s.x.windows(2).all(|w| w[1] >= w[0]) {
        return None;
    }
    let i = s.x.partition_point(|&v| v < x);
    if i == 0 || i >= s.x.len() {
        return None;
    }
    let (xa, xb, ya, yb) = (s.x[i - 1], s.x[i], s.y[i - 1], s.y[i]);
    let y = if xb > xa {
        ya + (yb - ya) * (x - xa) / (xb - xa)
    } else {
        yb
    };
    y.is_finite().then_some(y)
}

/// Make `(lo, hi)` a usable range: no data gives (0, 1); a span below `min_span` (or a
/// zero span) is widened about its centre.
fn widen((lo, hi): (f64, f64), min_span: f64) -> (f64, f64) {
    if !(lo.is_finite() && hi.is_finite()) || lo > hi {
        return (0.0, 1.0);
    }
    let centre = 0.5 * (lo + hi);
    // never narrower than 1e-9 of the magnitude: below that the axis is f64 noise
    let floor = (centre.abs() * 1e-9).max(f64::MIN_POSITIVE);
    let need = min_span.max(floor);
    if hi - lo >= need {
        return (lo, hi);
    }
    let half = if hi - lo > 0.0 || min_span > 0.0 {
        0.5 * need
    } else if centre != 0.0 {
        0.5 * centre.abs() // a constant: show it at mid-height
    } else {
        0.5
    };
    (centre - half, centre + half)
}

/// The SI prefix for values whose largest magnitude is `max_abs`: `(factor, prefix)` with
/// `max_abs * factor` in [1, 1000) when possible (prefixes from pico to giga).
pub fn si_prefix(max_abs: f64) -> (f64, &'static str) {
    const PREFIXES: [(i32, &str); 8] = [
        (-12, "p"),
        (-9, "n"),
        (-6, "\u{b5}"),
        (-3, "m"),
        (0, ""),
        (3, "k"),
        (6, "M"),
        (9, "G"),
    ];
    if !(max_abs.is_finite() && max_abs > 0.0) {
        return (1.0, "");
    }
    let e = max_abs.log10().floor() as i32;
    let (p, name) = PREFIXES
        .iter()
        .rev()
        .find(|(p, _)| *p <= e)
        .copied()
        .unwrap_or(PREFIXES[0]);
    (10f64.powi(-p), name)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plot::{Rgb, Series};

    fn panel(series: Vec<Series>) -> Panel {
        Panel::new("", "t (s)", "y").with_series(series)
    }

    #[test]
    fn y_follows_the_zoom_window_and_ignores_nan_and_masked_points() {
        let x: Vec<f64> = (0..=100).map(|i| i as f64 / 100.0).collect();
        let mut y: Vec<f64> = x.iter().map(|t| 10.0 + t).collect();
        y[5] = 1e9; // a spike outside the window
        y[50] = f64::NAN;
        y[60] = -1e9; // inside the window but masked
        let mut mask = vec![true; x.len()];
        mask[60] = false;
        let s = Series::solid("est", x, y, Rgb(0, 0, 0)).with_scale_mask(mask);
        let p = panel(vec![s]).with_x_range(0.4, 0.8);
        let (x0, x1) = x_range(&p);
        assert_eq!((x0, x1), (0.4, 0.8));
        let (lo, hi) = y_range(&p, (x0, x1));
        let pad = 0.4 * PAD;
        assert!((lo - (10.4 - pad)).abs() < 1e-12 && (hi - (10.8 + pad)).abs() < 1e-12);
    }

    #[test]
    fn limits_clip_a_divergent_estimate_and_min_span_widens_a_flat_one() {
        let x = vec![0.0, 1.0, 2.0];
        let est = Series::solid("est", x.clone(), vec![1e6, 14.3, 14.29], Rgb(0, 0, 0));
        let p = panel(vec![est]).with_y_limits(0.0, 28.58);
        let (lo, hi) = y_range(&p, x_range(&p));
        assert!((hi - 28.58 - (28.58 - 14.29) * PAD).abs() < 1e-9);
        assert!((lo - 14.29 + (28.58 - 14.29) * PAD).abs() < 1e-9);
        let truth = Series::dashed("true", vec![0.0, 2.0], vec![14.29, 14.29], Rgb(0, 0, 0));
        let p = panel(vec![truth]).with_min_y_span(0.02);
        let (lo, hi) = y_range(&p, (0.0, 2.0));
        assert!((hi - lo - 0.02 * (1.0 + 2.0 * PAD)).abs() < 1e-12);
        assert!((0.5 * (lo + hi) - 14.29).abs() < 1e-12);
    }

    #[test]
    fn a_two_point_line_counts_inside_a_narrow_window() {
        let truth = Series::dashed("true", vec![0.0, 1.0], vec![5.0, 5.0], Rgb(0, 0, 0));
        let p = panel(vec![truth]).with_x_range(0.4, 0.6);
        let (lo, hi) = y_range(&p, (0.4, 0.6));
        assert!(lo < 5.0 && hi > 5.0);
    }

    #[test]
    fn empty_panels_get_a_unit_range() {
        let p = panel(vec![]);
        assert_eq!(x_range(&p), (0.0, 1.0));
    }

    #[test]
    fn si_prefixes() {
        assert_eq!(si_prefix(2.3e-7), (1e9, "n"));
        assert_eq!(si_prefix(4.5e-6), (1e6, "\u{b5}"));
        assert_eq!(si_prefix(4.0e-10).1, "p");
        assert_eq!(si_prefix(1.195e6), (1e-6, "M"));
        assert_eq!(si_prefix(14.29), (1.0, ""));
        assert_eq!(si_prefix(0.0), (1.0, ""));
    }
}
