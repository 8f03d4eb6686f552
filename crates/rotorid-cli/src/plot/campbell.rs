//! The Campbell diagram as ROSS and API 684 draw it: damped natural frequency (Hz) of each
//! mode against running speed (rpm); markers pointing up for forward whirl and down for
//! backward whirl (a circle where the orbit is a line or undefined), coloured by the
//! logarithmic decrement (viridis scale with its colour bar); the 1X line dashed; each
//! critical speed (a mode meeting 1X) circled and numbered, listed beside the axes with
//! its standard deviation.

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};
use rotorid::analysis::Whirl;

use super::canvas::{de, font, marker, polyline, text, viridis, Axes, Drawing, Marker};
use super::ticks::TickFormat;

/// Markers drawn along each mode.
const MARKERS_PER_MODE: usize = 36;

/// One mode over the speeds of a [`CampbellPlot`].
#[derive(Debug, Clone, PartialEq)]
pub struct CampbellMode {
    /// Damped natural frequency \[Hz\] per speed.
    pub frequency_hz: Vec<f64>,
    /// Logarithmic decrement per speed (`None`: the mode does not oscillate).
    pub log_dec: Vec<Option<f64>>,
    /// Whirl per speed (`None`: straight-line orbit or undefined).
    pub whirl: Vec<Option<Whirl>>,
}

/// A critical speed to mark.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CriticalMark {
    /// Speed \[rpm\] (the frequency there is rpm / 60 Hz).
    pub rpm: f64,
    /// Standard deviation \[rpm\], when known.
    pub std_rpm: Option<f64>,
    /// Whirl of the crossing mode.
    pub whirl: Option<Whirl>,
}

/// A Campbell diagram.
#[derive(Debug, Clone, PartialEq)]
pub struct CampbellPlot {
    /// Title across the top.
    pub title: String,
    /// The speeds \[rpm\], increasing.
    pub rpm: Vec<f64>,
    /// The modes.
    pub modes: Vec<CampbellMode>,
    /// The critical speeds.
    pub critical: Vec<CriticalMark>,
}

/// `value ± std unit` with as many decimals as the standard deviation needs (1 without;
/// no unit when `unit` is empty).
pub fn with_std(value: f64, std: Option<f64>, unit: &str) -> String {
    let s = match std {
        Some(s) if s > 0.0 && s.is_finite() => {
            let d = (-(s.log10()).floor() + 1.0).clamp(0.0, 6.0) as usize;
            format!("{value:.d$} \u{b1} {s:.d$} {unit}")
        }
        _ => format!("{value:.1} {unit}"),
    };
    s.trim_end().to_string()
}

/// The side panel's list of critical speeds (`Critical speeds:`, then each with its
/// standard deviation and whirl, or `none in range`) from `(x, y)` at scale `k`; returns
/// the y below it. Shared by the Campbell diagram and the Bode plot.
pub fn critical_legend<DB: DrawingBackend>(
    side: &DrawingArea<DB, Shift>,
    critical: &[CriticalMark],
    (x, mut y): (f64, f64),
    k: u32,
) -> anyhow::Result<f64> {
    let kf = k as f64;
    let row = 30.0 * kf;
    let left = (HPos::Left, VPos::Center);
    text(side, "Critical speeds:", (x, y), 18 * k, left)?;
    y += row;
    if critical.is_empty() {
        text(side, "none in range", (x + 10.0 * kf, y), 18 * k, left)?;
        y += row;
    }
    for (n, c) in critical.iter().enumerate() {
        let whirl = c.whirl.map_or("no whirl direction", |w| w.name());
        text(
            side,
            &format!("{}: {}", n + 1, with_std(c.rpm, c.std_rpm, "rpm")),
            (x + 10.0 * kf, y),
            18 * k,
            left,
        )?;
        y += 0.8 * row;
        text(
            side,
            &format!("    {whirl}"),
            (x + 10.0 * kf, y),
            18 * k,
            left,
        )?;
        y += row;
    }
    Ok(y)
}

fn whirl_marker(w: Option<Whirl>) -> Marker {
    match w {
        Some(Whirl::Forward) => Marker::Up,
        Some(Whirl::Backward) => Marker::Down,
        None => Marker::Circle,
    }
}

impl CampbellPlot {
    /// (lowest, highest) logarithmic decrement, widened when (nearly) constant.
    fn log_dec_range(&self) -> Option<(f64, f64)> {
        let vals = self
            .modes
            .iter()
            .flat_map(|m| m.log_dec.iter().flatten().copied())
            .filter(|v| v.is_finite());
        let (lo, hi) = vals.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
        if lo > hi {
            return None;
        }
        let span = hi - lo;
        let min_span = 0.02 * lo.abs().max(hi.abs()).max(1e-6);
        if span < min_span {
            let c = 0.5 * (lo + hi);
            Some((c - 0.5 * min_span, c + 0.5 * min_span))
        } else {
            Some((lo, hi))
        }
    }

    fn ranges(&self) -> ((f64, f64), (f64, f64)) {
        let x0 = self.rpm.first().copied().unwrap_or(0.0);
        let x1 = self.rpm.last().copied().unwrap_or(1.0).max(x0 + 1.0);
        let fmax = self
            .modes
            .iter()
            .flat_map(|m| m.frequency_hz.iter().copied())
            .filter(|f| f.is_finite())
            .fold(0.0f64, f64::max);
        let one_x = x1 / 60.0;
        let top = if fmax > 0.0 {
            fmax.max(one_x.min(2.0 * fmax))
        } else {
            one_x
        };
        ((x0, x1), (0.0, 1.08 * top.max(1e-3)))
    }
}

impl Drawing for CampbellPlot {
    fn draw<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        k: u32,
    ) -> anyhow::Result<()> {
        let ki = k as i32;
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
        let (plot_area, side) = body.split_horizontally(w - side_w);
        let ((x0, x1), (y0, y1)) = self.ranges();
        let mut chart = ChartBuilder::on(&plot_area)
            .margin(14 * k)
            .x_label_area_size(64 * k)
            .y_label_area_size(100 * k)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(de)?;
        let xf = TickFormat::for_axis(x0, x1, 10);
        let yf = TickFormat::for_axis(y0, y1, 10);
        chart
            .configure_mesh()
            .x_desc("running speed (rpm)")
            .y_desc("damped natural frequency (Hz)")
            .x_labels(10)
            .y_labels(10)
            .max_light_lines(1)
            .x_label_formatter(&|v| xf.format(*v))
            .y_label_formatter(&|v| yf.format(*v))
            .label_style(font(18 * k))
            .axis_desc_style(font(20 * k))
            .set_all_tick_mark_size(5 * k)
            .bold_line_style(BLACK.mix(0.14).stroke_width(k))
            .light_line_style(BLACK.mix(0.05).stroke_width(k))
            .axis_style(BLACK.stroke_width(k))
            .draw()
            .map_err(de)?;
        let axes = Axes::of(&chart, (x0, x1), (y0, y1), false);

        // 1X
        let one_x = [(x0, x0 / 60.0), (x1, x1 / 60.0)];
        polyline(
            root,
            &axes,
            &one_x,
            BLACK.stroke_width(2 * k),
            Some((12 * k, 7 * k)),
        )?;
        let label_at = if x1 / 60.0 <= y1 {
            (x1, x1 / 60.0)
        } else {
            (y1 * 60.0, y1)
        };
        // above-left of the line's end: the line runs below that corner
        let p = axes.map(label_at);
        text(
            root,
            "1X",
            (p.0 - 16.0 * k as f64, p.1 - 2.0 * k as f64),
            20 * k,
            (HPos::Right, VPos::Bottom),
        )?;

        // modes: a thin line, and markers coloured by the logarithmic decrement
        let ld = self.log_dec_range();
        let colour = |d: Option<f64>| match (d, ld) {
            (Some(d), Some((lo, hi))) => viridis((d - lo) / (hi - lo)),
            _ => RGBColor(150, 150, 150),
        };
        for m in &self.modes {
            let pts: Vec<(f64, f64)> = self
                .rpm
                .iter()
                .copied()
                .zip(m.frequency_hz.iter().copied())
                .collect();
            polyline(root, &axes, &pts, BLACK.mix(0.45).stroke_width(k), None)?;
            let n = pts.len();
            let every = (n / MARKERS_PER_MODE).max(1);
            for i in (0..n).step_by(every) {
                if !axes.contains(pts[i]) {
                    continue;
                }
                marker(
                    root,
                    axes.map(pts[i]),
                    whirl_marker(m.whirl[i]),
                    9 * ki,
                    colour(m.log_dec[i]),
                    BLACK.mix(0.8).stroke_width(k),
                )?;
            }
        }

        // critical speeds
        for (n, c) in self.critical.iter().enumerate() {
            let at = (c.rpm, c.rpm / 60.0);
            if !axes.contains(at) {
                continue;
            }
            polyline(
                root,
                &axes,
                &[(c.rpm, y0), at],
                BLACK.mix(0.6).stroke_width(k),
                Some((4 * k, 4 * k)),
            )?;
            let p = axes.map(at);
            root.draw(&Circle::new(
                (p.0 as i32, p.1 as i32),
                14 * ki,
                RGBColor(213, 94, 0).stroke_width(3 * k),
            ))
            .map_err(de)?;
            text(
                root,
                &format!("{}", n + 1),
                (p.0 - 14.0 * k as f64, p.1 - 14.0 * k as f64),
                20 * k,
                (HPos::Right, VPos::Bottom),
            )?;
        }
        self.draw_side(&side, k, ld)
    }
}

impl CampbellPlot {
    /// Legend, list of critical speeds and the colour bar, in the column right of the axes.
    fn draw_side<DB: DrawingBackend>(
        &self,
        side: &DrawingArea<DB, Shift>,
        k: u32,
        ld: Option<(f64, f64)>,
    ) -> anyhow::Result<()> {
        let (ki, kf) = (k as i32, k as f64);
        let (_, sh) = side.dim_in_pixel();
        let row = 30.0 * kf;
        let mut y = 30.0 * kf;
        let x = 14.0 * kf;
        let grey = RGBColor(150, 150, 150);
        let any_planar = self
            .modes
            .iter()
            .any(|m| m.whirl.iter().any(Option::is_none));
        let mut entries = vec![
            (Marker::Up, "forward whirl"),
            (Marker::Down, "backward whirl"),
        ];
        if any_planar {
            entries.push((Marker::Circle, "no direction (line or double)"));
        }
        for (m, label) in entries {
            marker(
                side,
                (x + 12.0 * kf, y),
                m,
                9 * ki,
                grey,
                BLACK.mix(0.8).stroke_width(k),
            )?;
            text(
                side,
                label,
                (x + 34.0 * kf, y),
                18 * k,
                (HPos::Left, VPos::Center),
            )?;
            y += row;
        }
        side.draw(&plotters::element::DashedPathElement::new(
            vec![(x as i32, y as i32), ((x + 26.0 * kf) as i32, y as i32)],
            8 * ki,
            5 * ki,
            BLACK.stroke_width(2 * k),
        ))
        .map_err(de)?;
        text(
            side,
            "1X (running speed)",
            (x + 34.0 * kf, y),
            18 * k,
            (HPos::Left, VPos::Center),
        )?;
        y += row;
        side.draw(&Circle::new(
            ((x + 12.0 * kf) as i32, y as i32),
            10 * ki,
            RGBColor(213, 94, 0).stroke_width(3 * k),
        ))
        .map_err(de)?;
        text(
            side,
            "critical speed",
            (x + 34.0 * kf, y),
            18 * k,
            (HPos::Left, VPos::Center),
        )?;
        y += 1.5 * row;

        y = critical_legend(side, &self.critical, (x, y), k)?;

        // colour bar
        y += 0.5 * row;
        text(
            side,
            "logarithmic decrement",
            (x, y),
            18 * k,
            (HPos::Left, VPos::Center),
        )?;
        y += 0.8 * row;
        let Some((lo, hi)) = ld else {
            return text(
                side,
                "(no oscillating mode)",
                (x, y),
                18 * k,
                (HPos::Left, VPos::Center),
            );
        };
        let (bx0, bx1) = (x as i32, (x + 28.0 * kf) as i32);
        let by0 = y as i32;
        let by1 = (sh as f64 - 90.0 * kf).max(y + 60.0 * kf) as i32;
        let n = 120;
        for i in 0..n {
            let t0 = i as f64 / n as f64;
            let t1 = (i + 1) as f64 / n as f64;
            let ya = by1 - ((by1 - by0) as f64 * t0) as i32;
            let yb = by1 - ((by1 - by0) as f64 * t1) as i32;
            side.draw(&Rectangle::new(
                [(bx0, yb), (bx1, ya)],
                viridis(0.5 * (t0 + t1)).filled(),
            ))
            .map_err(de)?;
        }
        side.draw(&Rectangle::new(
            [(bx0, by0), (bx1, by1)],
            BLACK.stroke_width(k),
        ))
        .map_err(de)?;
        let ticks = plotters::coord::types::RangedCoordf64::from(lo..hi).key_points(6);
        let f = TickFormat::for_ticks(&ticks, lo, hi);
        for v in ticks {
            let ty = by1 as f64 - (by1 - by0) as f64 * (v - lo) / (hi - lo);
            side.draw(&PathElement::new(
                vec![(bx1, ty as i32), (bx1 + 6 * ki, ty as i32)],
                BLACK.stroke_width(k),
            ))
            .map_err(de)?;
            text(
                side,
                &f.format(v),
                (bx1 as f64 + 10.0 * kf, ty),
                18 * k,
                (HPos::Left, VPos::Center),
            )?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_carry_the_decimals_their_std_needs() {
        assert_eq!(
            with_std(2519.93, Some(1.234), "rpm"),
            "2519.9 \u{b1} 1.2 rpm"
        );
        assert_eq!(
            with_std(2519.93, Some(0.0123), "rpm"),
            "2519.930 \u{b1} 0.012 rpm"
        );
        assert_eq!(with_std(2519.93, Some(25.0), "rpm"), "2520 \u{b1} 25 rpm");
        assert_eq!(with_std(2519.93, None, "rpm"), "2519.9 rpm");
    }
}
