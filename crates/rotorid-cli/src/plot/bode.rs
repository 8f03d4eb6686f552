//! The Bode plot of the unbalance response (API 684 practice): 1X amplitude (peak-to-peak,
//! logarithmic scale) and phase lag (degrees, unwrapped along the speed so it climbs
//! through each resonance) against running speed (rpm), one colour per probe, each with
//! its uncertainty band (shaded, +-2 standard deviations), and the critical speeds of the
//! Campbell diagram as numbered dashed lines.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};

use super::campbell::{critical_legend, CriticalMark};
use super::canvas::{band, de, font, polyline, text, Axes, Drawing};
use super::ticks::TickFormat;
use super::{rgb, Rgb};

/// Decades of amplitude shown below the largest value.
const DECADES: i32 = 4;

/// Width of the uncertainty band in standard deviations (each side).
pub const BAND_SIGMAS: f64 = 2.0;

/// One probe's response over the speeds of a [`BodePlot`].
#[derive(Debug, Clone, PartialEq)]
pub struct BodeChannel {
    /// Legend text, e.g. `x (horizontal)`.
    pub label: String,
    /// Line colour.
    pub color: Rgb,
    /// Amplitude per speed \[the plot's unit, peak-to-peak\]; NaN where undefined.
    pub amplitude: Vec<f64>,
    /// Its standard deviation \[same unit\]; `None` where unknown.
    pub std_amplitude: Vec<Option<f64>>,
    /// Phase lag per speed \[deg\], unwrapped; NaN where undefined.
    pub phase_lag_deg: Vec<f64>,
    /// Its standard deviation \[deg\].
    pub std_phase_lag_deg: Vec<Option<f64>>,
}

/// A Bode plot.
#[derive(Debug, Clone, PartialEq)]
pub struct BodePlot {
    /// Title across the top.
    pub title: String,
    /// The speeds \[rpm\], increasing.
    pub rpm: Vec<f64>,
    /// Amplitude unit as shown, e.g. `um pk-pk`.
    pub unit: String,
    /// The probes.
    pub channels: Vec<BodeChannel>,
    /// Critical speeds (numbered as on the Campbell diagram).
    pub critical: Vec<CriticalMark>,
}

/// Unwrap phases \[deg\] along the sequence: each step by less than 180 degrees in
/// magnitude; the first finite value is kept in \[0, 360). NaN passes through.
pub fn unwrap_deg(v: &[f64]) -> Vec<f64> {
    let mut out = Vec::with_capacity(v.len());
    let mut prev: Option<f64> = None;
    for &x in v {
        if !x.is_finite() {
            out.push(f64::NAN);
            continue;
        }
        let y = match prev {
            None => x.rem_euclid(360.0),
            Some(p) => p + (x - p + 180.0).rem_euclid(360.0) - 180.0,
        };
        out.push(y);
        prev = Some(y);
    }
    out
}

/// A tick label for a value on a logarithmic axis: as many decimals as its decade needs.
fn log_label(v: f64) -> String {
    if v >= 1.0 {
        format!("{v:.0}")
    } else {
        let d = (-(v.log10()).floor()).max(0.0) as usize;
        format!("{v:.d$}")
    }
}

/// Channel `i`'s dash pattern: the first solid, the others dashed, so coinciding curves
/// (x and z of an isotropic rotor) both stay visible.
pub fn dash_of(i: usize, k: u32) -> Option<(u32, u32)> {
    match i {
        0 => None,
        i => Some(((6 + 6 * i as u32) * k, 6 * k)),
    }
}

impl BodePlot {
    fn bands(&self, c: &BodeChannel) -> [Vec<f64>; 4] {
        let s = BAND_SIGMAS;
        let band = |v: &[f64], sd: &[Option<f64>], sign: f64| -> Vec<f64> {
            v.iter()
                .zip(sd)
                .map(|(&x, s2)| s2.map_or(f64::NAN, |d| x + sign * s * d))
                .collect()
        };
        [
            band(&c.amplitude, &c.std_amplitude, -1.0),
            band(&c.amplitude, &c.std_amplitude, 1.0),
            band(&c.phase_lag_deg, &c.std_phase_lag_deg, -1.0),
            band(&c.phase_lag_deg, &c.std_phase_lag_deg, 1.0),
        ]
    }

    /// Amplitude range in whole decades covering the curves and upper bands.
    fn amplitude_range(&self) -> (f64, f64) {
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for c in &self.channels {
            let [_, up, _, _] = self.bands(c);
            for (&a, &u) in c.amplitude.iter().zip(&up) {
                if a.is_finite() && a > 0.0 {
                    lo = lo.min(a);
                    hi = hi.max(a);
                }
                if u.is_finite() {
                    hi = hi.max(u);
                }
            }
        }
        if !(lo.is_finite() && hi > 0.0) {
            return (0.1, 1.0);
        }
        // at most DECADES below the peak: the response at standstill is 0
        let lo = lo.max(hi * 10f64.powi(-DECADES));
        let lo = 10f64.powf(lo.log10().floor());
        let hi = 10f64.powf(hi.log10().ceil()).max(lo * 10.0);
        (lo, hi)
    }

    /// Phase range in multiples of 90 degrees covering curves and bands.
    fn phase_range(&self) -> (f64, f64) {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for c in &self.channels {
            let [_, _, dn, up] = self.bands(c);
            for v in c.phase_lag_deg.iter().chain(&dn).chain(&up) {
                if v.is_finite() {
                    lo = lo.min(*v);
                    hi = hi.max(*v);
                }
            }
        }
        if lo > hi {
            return (0.0, 360.0);
        }
        let lo = (lo / 90.0).floor() * 90.0;
        let hi = ((hi / 90.0).ceil() * 90.0).max(lo + 90.0);
        (lo, hi)
    }
}

impl Drawing for BodePlot {
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
        let (plots, side) = body.split_horizontally(w - side_w);
        let panels = plots.split_evenly((2, 1));
        let x0 = self.rpm.first().copied().unwrap_or(0.0);
        let x1 = self.rpm.last().copied().unwrap_or(1.0).max(x0 + 1.0);
        let xf = TickFormat::for_axis(x0, x1, 10);

        // amplitude, logarithmic
        let (a0, a1) = self.amplitude_range();
        let mut chart = ChartBuilder::on(&panels[0])
            .margin(14 * k)
            .x_label_area_size(56 * k)
            .y_label_area_size(100 * k)
            .build_cartesian_2d(x0..x1, (a0..a1).log_scale())
            .map_err(de)?;
        chart
            .configure_mesh()
            .x_desc("running speed (rpm)")
            .y_desc(format!("1X amplitude ({})", self.unit))
            .x_labels(10)
            .y_labels(12)
            .max_light_lines(1)
            .x_label_formatter(&|v| xf.format(*v))
            .y_label_formatter(&|v| log_label(*v))
            .label_style(font(18 * k))
            .axis_desc_style(font(20 * k))
            .set_all_tick_mark_size(5 * k)
            .bold_line_style(BLACK.mix(0.14).stroke_width(k))
            .light_line_style(BLACK.mix(0.05).stroke_width(k))
            .axis_style(BLACK.stroke_width(k))
            .draw()
            .map_err(de)?;
        let amp_axes = Axes::of(&chart, (x0, x1), (a0, a1), true);

        // phase lag, linear with a line every 90 degrees (drawn here: plotters' key points
        // are 1-2-5 steps)
        let (p0, p1) = self.phase_range();
        let mut chart = ChartBuilder::on(&panels[1])
            .margin(14 * k)
            .x_label_area_size(56 * k)
            .y_label_area_size(100 * k)
            .build_cartesian_2d(x0..x1, p0..p1)
            .map_err(de)?;
        chart
            .configure_mesh()
            .x_desc("running speed (rpm)")
            .y_desc("phase lag (deg)")
            .x_labels(10)
            .y_labels(0)
            .disable_y_mesh()
            .max_light_lines(1)
            .x_label_formatter(&|v| xf.format(*v))
            .label_style(font(18 * k))
            .axis_desc_style(font(20 * k))
            .set_all_tick_mark_size(5 * k)
            .bold_line_style(BLACK.mix(0.14).stroke_width(k))
            .light_line_style(BLACK.mix(0.05).stroke_width(k))
            .axis_style(BLACK.stroke_width(k))
            .draw()
            .map_err(de)?;
        let ph_axes = Axes::of(&chart, (x0, x1), (p0, p1), false);
        let step = if p1 - p0 > 720.0 { 180.0 } else { 90.0 };
        let mut v = p0;
        while v <= p1 + 1e-9 {
            polyline(
                root,
                &ph_axes,
                &[(x0, v), (x1, v)],
                BLACK.mix(0.14).stroke_width(k),
                None,
            )?;
            let p = ph_axes.map((x0, v));
            text(
                root,
                &format!("{v:.0}"),
                (p.0 - 10.0 * kf, p.1),
                18 * k,
                (HPos::Right, VPos::Center),
            )?;
            v += step;
        }

        // critical speeds
        for (axes, numbered) in [(&amp_axes, true), (&ph_axes, false)] {
            for (n, c) in self.critical.iter().enumerate() {
                if c.rpm < x0 || c.rpm > x1 {
                    continue;
                }
                polyline(
                    root,
                    axes,
                    &[(c.rpm, axes.y.0), (c.rpm, axes.y.1)],
                    BLACK.mix(0.55).stroke_width(k),
                    Some((6 * k, 5 * k)),
                )?;
                if numbered {
                    let p = axes.map((c.rpm, axes.y.1));
                    text(
                        root,
                        &format!("{}", n + 1),
                        (p.0 + 5.0 * kf, p.1 + 4.0 * kf),
                        18 * k,
                        (HPos::Left, VPos::Top),
                    )?;
                }
            }
        }

        // bands first, then the curves on top
        for c in &self.channels {
            let [a_lo, a_hi, p_lo, p_hi] = self.bands(c);
            let fill = rgb(c.color).mix(0.22);
            band(
                root,
                &amp_axes,
                &self.rpm,
                &a_lo.iter().map(|v| v.max(a0)).collect::<Vec<_>>(),
                &a_hi,
                fill,
            )?;
            band(root, &ph_axes, &self.rpm, &p_lo, &p_hi, fill)?;
        }
        for (i, c) in self.channels.iter().enumerate() {
            let style = rgb(c.color).stroke_width(2 * k);
            let dash = dash_of(i, k);
            let amp: Vec<(f64, f64)> = self
                .rpm
                .iter()
                .zip(&c.amplitude)
                .map(|(&x, &a)| (x, if a > 0.0 { a } else { f64::NAN }))
                .collect();
            polyline(root, &amp_axes, &amp, style, dash)?;
            let ph: Vec<(f64, f64)> = self
                .rpm
                .iter()
                .copied()
                .zip(c.phase_lag_deg.iter().copied())
                .collect();
            polyline(root, &ph_axes, &ph, style, dash)?;
        }
        self.draw_side(&side, k)
    }
}

impl BodePlot {
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
        let any_band = self
            .channels
            .iter()
            .any(|c| c.std_amplitude.iter().any(Option::is_some));
        if any_band {
            side.draw(&Rectangle::new(
                [
                    (x as i32, (y - 8.0 * kf) as i32),
                    ((x + 36.0 * kf) as i32, (y + 8.0 * kf) as i32),
                ],
                BLACK.mix(0.22).filled(),
            ))
            .map_err(de)?;
            text(
                side,
                &format!("\u{b1}{BAND_SIGMAS:.0} std (covariance)"),
                (x + 46.0 * kf, y),
                18 * k,
                (HPos::Left, VPos::Center),
            )?;
        } else {
            text(
                side,
                "no covariance: no bands",
                (x, y),
                18 * k,
                (HPos::Left, VPos::Center),
            )?;
        }
        y += 1.5 * row;
        y = critical_legend(side, &self.critical, (x, y), k)?;
        y += 0.5 * row;
        for line in [
            "Phase lag: shaft angle from",
            "the keyphasor to the positive",
            "peak of the signal.",
        ] {
            text(side, line, (x, y), 16 * k, (HPos::Left, VPos::Center))?;
            y += 0.8 * row;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phases_unwrap_through_the_wrap() {
        let v = [350.0, 5.0, 20.0, f64::NAN, 200.0, 10.0];
        let u = unwrap_deg(&v);
        assert_eq!(&u[..3], &[350.0, 365.0, 380.0]);
        assert!(u[3].is_nan());
        assert_eq!(&u[4..], &[200.0, 370.0]);
        assert_eq!(unwrap_deg(&[-30.0])[0], 330.0);
    }

    #[test]
    fn log_labels_have_the_decade_decimals() {
        assert_eq!(log_label(100.0), "100");
        assert_eq!(log_label(0.2), "0.2");
        assert_eq!(log_label(0.05), "0.05");
    }
}
