//! The polar plot of the unbalance response: each probe's 1X vector over the speed range
//! as one curve, amplitude (peak-to-peak) as the radius and phase lag as the angle, 0 deg
//! at the top and lag increasing against the rotation (counter-clockwise here, for the
//! shaft turns clockwise as seen with x to the right and z up), as Bently and API 684
//! practice draws it. A resonance shows as a loop; each critical speed of the Campbell
//! diagram is marked on every curve by its number, and the curves' ends by their speed.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::bode::dash_of;
use super::campbell::CriticalMark;
use super::canvas::{de, polyline, text, Axes, Drawing};
use super::ticks::TickFormat;
use super::{rgb, Rgb};

/// One probe's 1X vectors.
#[derive(Debug, Clone, PartialEq)]
pub struct PolarChannel {
    /// Legend text.
    pub label: String,
    /// Line colour.
    pub color: Rgb,
    /// Amplitude per speed \[the plot's unit, peak-to-peak\]; NaN where undefined.
    pub amplitude: Vec<f64>,
    /// Phase lag per speed \[deg\]; NaN where undefined.
    pub phase_lag_deg: Vec<f64>,
}

/// A polar plot.
#[derive(Debug, Clone, PartialEq)]
pub struct PolarPlot {
    /// Title across the top.
    pub title: String,
    /// The speeds \[rpm\], increasing.
    pub rpm: Vec<f64>,
    /// Amplitude unit as shown, e.g. `um pk-pk`.
    pub unit: String,
    /// The probes.
    pub channels: Vec<PolarChannel>,
    /// Critical speeds (numbered as on the Campbell diagram).
    pub critical: Vec<CriticalMark>,
}

/// Points closer to the centre than this fraction of the outer radius are not labelled.
const CLEAR: f64 = 0.06;

/// The plane position of amplitude `a` at lag `lag_deg` (module doc): (-a sin, a cos).
fn position(a: f64, lag_deg: f64) -> (f64, f64) {
    let (s, c) = lag_deg.to_radians().sin_cos();
    (-a * s, a * c)
}

impl Drawing for PolarPlot {
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        k: u32,
    ) -> anyhow::Result<()> {
        let kf = k as f64;
        let (w, _) = root.dim_in_pixel();
        let title_style = (super::font::FAMILY, 28 * k)
            .into_font()
            .style(FontStyle::Bold)
            .color(&BLACK);
        let body = root
            .margin(8 * k, 0, 0, 0)
            .titled(&self.title, title_style)
            .map_err(de)?
            .margin(6 * k, 0, 0, 0);
        let side_w = 330 * k;
        let (plot, side) = body.split_horizontally(w - side_w);
        let (pw, ph) = plot.dim_in_pixel();
        let (ox, oy) = plot.get_base_pixel();
        // a square of the largest size that leaves room for the angle labels
        let pad = 60.0 * kf;
        let half = ((pw as f64).min(ph as f64) / 2.0 - pad).max(10.0);
        let (cx, cy) = (ox as f64 + pw as f64 / 2.0, oy as f64 + ph as f64 / 2.0);
        let amax = self
            .channels
            .iter()
            .flat_map(|c| c.amplitude.iter().copied())
            .filter(|a| a.is_finite())
            .fold(0.0f64, f64::max);
        let ticks =
            plotters::coord::types::RangedCoordf64::from(0.0..amax.max(1e-300)).key_points(5);
        let step = ticks
            .windows(2)
            .map(|w| w[1] - w[0])
            .fold(f64::INFINITY, f64::min);
        let r = if step.is_finite() && step > 0.0 {
            (amax / step).ceil().max(1.0) * step
        } else {
            amax.max(1e-300)
        };
        let axes = Axes {
            px: (cx - half, cx + half, cy - half, cy + half),
            x: (-r, r),
            y: (-r, r),
            y_log: false,
        };
        let grid = BLACK.mix(0.18).stroke_width(k);
        // circles and their amplitude labels (along the 0 deg spoke)
        let f = TickFormat::for_axis(0.0, r, 5);
        let mut rings: Vec<f64> = ticks
            .into_iter()
            .filter(|&t| t > 0.0 && t <= r * (1.0 + 1e-9))
            .collect();
        if rings.last().is_none_or(|&t| t < r * (1.0 - 1e-9)) {
            rings.push(r);
        }
        for &t in &rings {
            let pts: Vec<(f64, f64)> = (0..=180).map(|i| position(t, 2.0 * i as f64)).collect();
            polyline(root, &axes, &pts, grid, None)?;
            let p = axes.map(position(t, 0.0));
            text(
                root,
                &f.format(t),
                (p.0 + 4.0 * kf, p.1 + 2.0 * kf),
                16 * k,
                (HPos::Left, VPos::Top),
            )?;
        }
        // spokes every 30 degrees, labelled with the lag
        for i in 0..12 {
            let lag = 30.0 * i as f64;
            polyline(root, &axes, &[(0.0, 0.0), position(r, lag)], grid, None)?;
            let (s, c) = lag.to_radians().sin_cos();
            let (lx, ly) = (cx - (half + 22.0 * kf) * s, cy - (half + 22.0 * kf) * c);
            text(
                root,
                &format!("{lag:.0}\u{b0}"),
                (lx, ly),
                18 * k,
                (HPos::Center, VPos::Center),
            )?;
        }
        root.draw(&Circle::new(
            (cx as i32, cy as i32),
            half as i32,
            BLACK.stroke_width(k),
        ))
        .map_err(de)?;

        for (ci, c) in self.channels.iter().enumerate() {
            let pts: Vec<(f64, f64)> = c
                .amplitude
                .iter()
                .zip(&c.phase_lag_deg)
                .map(|(&a, &l)| position(a, l))
                .collect();
            polyline(
                root,
                &axes,
                &pts,
                rgb(c.color).stroke_width(2 * k),
                dash_of(ci, k),
            )?;
            // points near the centre are not labelled: they would pile up illegibly
            let clear =
                |p: (f64, f64)| p.0.is_finite() && p.1.is_finite() && p.0.hypot(p.1) > CLEAR * r;
            // the ends, labelled with their speed
            let ends = [0, pts.len().saturating_sub(1)];
            for (j, &i) in ends.iter().enumerate() {
                let Some(&p) = pts.get(i) else { continue };
                if !clear(p) {
                    continue;
                }
                let q = axes.map(p);
                root.draw(&Circle::new(
                    (q.0 as i32, q.1 as i32),
                    5 * k as i32,
                    rgb(c.color).filled(),
                ))
                .map_err(de)?;
                if j == 1 {
                    text(
                        root,
                        &format!("{:.0} rpm", self.rpm[i]),
                        (q.0 + 8.0 * kf, q.1),
                        16 * k,
                        (HPos::Left, VPos::Center),
                    )?;
                }
            }
            // critical speeds: the point of the curve nearest in speed
            for (n, cr) in self.critical.iter().enumerate() {
                let Some(i) = nearest(&self.rpm, cr.rpm) else {
                    continue;
                };
                let p = pts[i];
                if !clear(p) {
                    continue;
                }
                let q = axes.map(p);
                root.draw(&Circle::new(
                    (q.0 as i32, q.1 as i32),
                    9 * k as i32,
                    RGBColor(213, 94, 0).stroke_width(2 * k),
                ))
                .map_err(de)?;
                text(
                    root,
                    &format!("{}", n + 1),
                    (q.0 + 10.0 * kf, q.1 - 10.0 * kf),
                    18 * k,
                    (HPos::Left, VPos::Bottom),
                )?;
            }
        }
        self.draw_side(&side, k)
    }
}

/// Index of the speed nearest `rpm`, if any lies within the range.
fn nearest(speeds: &[f64], rpm: f64) -> Option<usize> {
    let (first, last) = (*speeds.first()?, *speeds.last()?);
    if rpm < first || rpm > last {
        return None;
    }
    (0..speeds.len()).min_by(|&a, &b| (speeds[a] - rpm).abs().total_cmp(&(speeds[b] - rpm).abs()))
}

impl PolarPlot {
    fn draw_side<DB: DrawingBackend>(
        &self,
        side: &DrawingArea<DB, Shift>,
        k: u32,
    ) -> anyhow::Result<()> {
        let kf = k as f64;
        let row = 30.0 * kf;
        let (x, mut y) = (14.0 * kf, 30.0 * kf);
        for (i, c) in self.channels.iter().enumerate() {
            let seg = vec![(x as i32, y as i32), ((x + 36.0 * kf) as i32, y as i32)];
            let style = rgb(c.color).stroke_width(3 * k);
            match dash_of(i, k) {
                None => side.draw(&PathElement::new(seg, style)),
                Some((d, g)) => side.draw(&plotters::element::DashedPathElement::new(
                    seg, d as i32, g as i32, style,
                )),
            }
            .map_err(de)?;
            text(
                side,
                &c.label,
                (x + 46.0 * kf, y),
                18 * k,
                (HPos::Left, VPos::Center),
            )?;
            y += row;
        }
        y += 0.5 * row;
        for line in [
            format!("radius: 1X amplitude ({})", self.unit),
            "angle: phase lag, 0\u{b0} at the top,".to_string(),
            "increasing against rotation".to_string(),
            "(the shaft turns from +z to +x)".to_string(),
            "points near the centre: not labelled".to_string(),
        ] {
            text(side, &line, (x, y), 16 * k, (HPos::Left, VPos::Center))?;
            y += 0.8 * row;
        }
        y += 0.5 * row;
        for (n, c) in self.critical.iter().enumerate() {
            let whirl = c.whirl.map_or("no whirl direction", |w| w.name());
            text(
                side,
                &format!("{}: {:.1} rpm, {whirl}", n + 1, c.rpm),
                (x, y),
                16 * k,
                (HPos::Left, VPos::Center),
            )?;
            y += 0.8 * row;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_lag_is_up_and_lag_turns_counter_clockwise() {
        let (x, y) = position(2.0, 0.0);
        assert!(x.abs() < 1e-15 && (y - 2.0).abs() < 1e-15);
        let (x, y) = position(1.0, 90.0);
        assert!((x + 1.0).abs() < 1e-15 && y.abs() < 1e-15);
        assert_eq!(nearest(&[0.0, 10.0, 20.0], 14.0), Some(1));
        assert_eq!(nearest(&[0.0, 10.0, 20.0], 24.0), None);
    }
}
