//! The cascade (waterfall) of spectra of a run-up or coast-down as a colour map:
//! frequency (Hz) across, running speed (rpm) up, amplitude (um pk) as colour on a
//! logarithmic viridis scale with its colour bar, and the order lines f = n rpm / 60
//! (1X, 2X, ...) dashed and labelled. A full spectrum (XY pair) spans negative
//! frequencies, backward whirl, on the left and positive ones, forward whirl, on the
//! right, with the orders drawn on both sides.
//!
//! Each spectrum is a horizontal strip reaching half-way to the spectra of the nearest
//! speeds; within a strip each pixel column shows the largest line that falls in it, so
//! a narrow peak survives any zoom.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, VPos};
use rotorid::transient::Cascade;

use super::canvas::{de, font, polyline, save_drawing, text, viridis, Axes, Drawing};
use super::ticks::TickFormat;

/// Image size of a saved cascade \[pixels\] (width, height).
pub const CASCADE_SIZE: (u32, u32) = (1400, 1000);

/// Colour levels of the map (the scale is quantised so runs of one colour become one
/// rectangle, which keeps the SVG small).
const LEVELS: f64 = 64.0;

/// Metres to the plot's micrometres.
const UM_PER_M: f64 = 1e6;

/// A cascade figure.
#[derive(Debug, Clone, PartialEq)]
pub struct CascadePlot {
    /// Title across the top (say which probe or pair).
    pub title: String,
    /// The spectra (amplitudes in m; shown in um pk).
    pub cascade: Cascade,
    /// Orders drawn as lines f = n rpm / 60 (positive; a full spectrum gets each on both
    /// sides), e.g. 1, 2, 3 or 0.5 for a subsynchronous line.
    pub orders: Vec<f64>,
    /// Decades of amplitude the colour scale spans below the largest amplitude (> 0);
    /// smaller amplitudes take the darkest colour.
    pub decades: f64,
}

impl CascadePlot {
    /// A plot of `cascade` with orders 1X up to the highest whole order the frequency
    /// axis reaches (at most 10X) and a colour scale of 2 decades (40 dB).
    pub fn new(title: impl Into<String>, cascade: Cascade) -> Self {
        let top_rpm = cascade.rpm.iter().fold(0.0f64, |m, r| m.max(r.abs()));
        let f_end = cascade.freq_hz.last().copied().unwrap_or(0.0);
        let n = if top_rpm > 0.0 {
            ((f_end / (top_rpm / 60.0)) + 1e-9).floor().clamp(1.0, 10.0) as u32
        } else {
            1
        };
        Self {
            title: title.into(),
            cascade,
            orders: (1..=n).map(f64::from).collect(),
            decades: 2.0,
        }
    }

    /// Write the figure to `path`, PNG or SVG by its extension, at [`CASCADE_SIZE`].
    pub fn save(&self, path: &Path) -> anyhow::Result<()> {
        anyhow::ensure!(
            !self.cascade.amplitude.is_empty() && self.cascade.freq_hz.len() >= 2,
            "cannot draw the cascade {}: it has {} spectra of {} lines (at least 1 of 2 needed)",
            path.display(),
            self.cascade.amplitude.len(),
            self.cascade.freq_hz.len()
        );
        anyhow::ensure!(
            self.decades.is_finite() && self.decades > 0.0,
            "cannot draw the cascade {}: decades = {} must be finite and > 0",
            path.display(),
            self.decades
        );
        save_drawing(self, CASCADE_SIZE, path)
    }

    /// The colour scale's (lowest, highest) amplitude \[um\]: the largest amplitude and
    /// `decades` below it (1 um when everything is zero).
    pub fn colour_range(&self) -> (f64, f64) {
        let top = self
            .cascade
            .amplitude
            .iter()
            .flatten()
            .filter(|a| a.is_finite())
            .fold(0.0f64, |m, &a| m.max(a))
            * UM_PER_M;
        let top = if top > 0.0 { top } else { 1.0 };
        (top * 10f64.powf(-self.decades), top)
    }

    /// Speed edges of each spectrum's strip \[rpm\] (lower, upper), half-way to the
    /// neighbouring speeds (the outer strips as wide as their neighbour's half-gap).
    fn strips(&self) -> Vec<(f64, f64)> {
        let rpm = &self.cascade.rpm;
        let mut order: Vec<usize> = (0..rpm.len()).collect();
        order.sort_by(|&a, &b| rpm[a].total_cmp(&rpm[b]));
        let mut edges = vec![(0.0, 0.0); rpm.len()];
        let m = order.len();
        for (j, &i) in order.iter().enumerate() {
            let below = if j > 0 { Some(rpm[order[j - 1]]) } else { None };
            let above = if j + 1 < m {
                Some(rpm[order[j + 1]])
            } else {
                None
            };
            let half = match (below, above) {
                (Some(b), Some(a)) => ((rpm[i] - b) / 2.0, (a - rpm[i]) / 2.0),
                (Some(b), None) => ((rpm[i] - b) / 2.0, (rpm[i] - b) / 2.0),
                (None, Some(a)) => ((a - rpm[i]) / 2.0, (a - rpm[i]) / 2.0),
                (None, None) => (
                    0.5f64.max(0.01 * rpm[i].abs()),
                    0.5f64.max(0.01 * rpm[i].abs()),
                ),
            };
            edges[i] = (rpm[i] - half.0, rpm[i] + half.1);
        }
        edges
    }

    /// Data ranges: frequency \[Hz\], speed \[rpm\].
    fn ranges(&self) -> ((f64, f64), (f64, f64)) {
        let f = &self.cascade.freq_hz;
        let df = self.cascade.df();
        let x = (f[0] - 0.5 * df, f[f.len() - 1] + 0.5 * df);
        let strips = self.strips();
        let lo = strips.iter().fold(f64::INFINITY, |m, s| m.min(s.0));
        let hi = strips.iter().fold(f64::NEG_INFINITY, |m, s| m.max(s.1));
        let y = if hi > lo {
            (lo, hi)
        } else {
            (lo - 1.0, lo + 1.0)
        };
        (x, y)
    }

    /// The colour-map position in \[0, 1\] of an amplitude \[um\], quantised to
    /// [`LEVELS`].
    fn level(&self, a_um: f64, (lo, hi): (f64, f64)) -> f64 {
        let t = if a_um > lo {
            ((a_um / lo).log10() / (hi / lo).log10()).min(1.0)
        } else {
            0.0
        };
        ((t * LEVELS).floor().min(LEVELS - 1.0) + 0.5) / LEVELS
    }

    /// The colour map on the plotting rectangle of `axes`; `col` pixels per column.
    fn draw_map<DB: DrawingBackend>(
        &self,
        root: &DrawingArea<DB, Shift>,
        axes: &Axes,
        col: f64,
        range: (f64, f64),
    ) -> anyhow::Result<()> {
        let c = &self.cascade;
        let (l, r, _, _) = axes.px;
        let df = c.df();
        let f0 = c.freq_hz[0];
        let nl = c.freq_hz.len();
        let columns = ((r - l) / col).ceil().max(1.0) as usize;
        // the lines each column covers: every line whose cell overlaps it
        let span: Vec<(usize, usize)> = (0..columns)
            .map(|j| {
                let fa = axes.x.0 + (axes.x.1 - axes.x.0) * (j as f64 * col) / (r - l);
                let fb = axes.x.0 + (axes.x.1 - axes.x.0) * ((j + 1) as f64 * col) / (r - l);
                let a = ((fa - f0) / df + 0.5).floor().clamp(0.0, (nl - 1) as f64) as usize;
                let b = ((fb - f0) / df + 0.5).ceil() as isize - 1;
                let b = (b.max(a as isize) as usize).min(nl - 1);
                (a, b)
            })
            .collect();
        for (s, (lo, hi)) in self.strips().into_iter().enumerate() {
            let amp = &c.amplitude[s];
            let ytop = axes.map((axes.x.0, hi)).1.round() as i32;
            let ybot = axes.map((axes.x.0, lo)).1.round() as i32;
            let levels: Vec<f64> = span
                .iter()
                .map(|&(a, b)| {
                    let m = amp[a..=b].iter().fold(0.0f64, |m, &v| m.max(v));
                    self.level(m * UM_PER_M, range)
                })
                .collect();
            let mut j = 0;
            while j < columns {
                let mut e = j + 1;
                while e < columns && levels[e] == levels[j] {
                    e += 1;
                }
                let xa = (l + j as f64 * col).round() as i32;
                let xb = (l + e as f64 * col).min(r + 1.0).round() as i32;
                root.draw(&Rectangle::new(
                    [(xa, ytop), (xb, ybot.max(ytop + 1))],
                    viridis(levels[j]).filled(),
                ))
                .map_err(de)?;
                j = e;
            }
        }
        Ok(())
    }
}

/// Tick values of a logarithmic scale from `lo` to `hi`: 1, 2, 5 per decade.
pub fn log_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let mut v = Vec::new();
    if !(lo > 0.0 && hi > lo) {
        return v;
    }
    let mut d = 10f64.powf(lo.log10().floor());
    while d <= hi * 1.0001 {
        for m in [1.0, 2.0, 5.0] {
            let x = m * d;
            if x >= lo * 0.9999 && x <= hi * 1.0001 {
                v.push(x);
            }
        }
        d *= 10.0;
    }
    v
}

/// A tick label of a logarithmic scale: as many decimals as the value's decade needs.
pub fn log_label(v: f64) -> String {
    if v >= 1.0 {
        format!("{v:.0}")
    } else {
        let d = (-v.log10()).ceil().max(0.0) as usize;
        format!("{v:.d$}")
    }
}

/// An order's label: `1X`, `2X`, `0.5X`; `-1X` for backward whirl.
fn order_label(n: f64) -> String {
    if (n - n.round()).abs() < 1e-9 {
        format!("{}X", n.round() as i64)
    } else {
        format!("{n}X")
    }
}

impl Drawing for CascadePlot {
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
        let side_w = 230 * k;
        let (plot_area, side) = body.split_horizontally(w - side_w);
        let ((x0, x1), (y0, y1)) = self.ranges();
        let full = self.cascade.full;
        let mut chart = ChartBuilder::on(&plot_area)
            .margin(14 * k)
            .margin_top(40 * k)
            .x_label_area_size(80 * k)
            .y_label_area_size(100 * k)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(de)?;
        let xf = TickFormat::for_axis(x0, x1, 12);
        let yf = TickFormat::for_axis(y0, y1, 10);
        let x_desc = if full {
            "frequency (Hz): backward whirl < 0 < forward whirl"
        } else {
            "frequency (Hz)"
        };
        // the map first, the mesh's axes and ticks over it (no grid: it would hide lines)
        let axes = {
            let (xr, yr) = chart.plotting_area().get_pixel_range();
            Axes {
                px: (
                    xr.start as f64,
                    (xr.end - 1) as f64,
                    yr.start as f64,
                    (yr.end - 1) as f64,
                ),
                x: (x0, x1),
                y: (y0, y1),
                y_log: false,
            }
        };
        let range = self.colour_range();
        self.draw_map(root, &axes, if k == 1 { 2.0 } else { 1.0 }, range)?;
        chart
            .configure_mesh()
            .disable_mesh()
            .x_desc(x_desc)
            .y_desc("running speed (rpm)")
            .x_labels(12)
            .y_labels(10)
            .x_label_formatter(&|v| xf.format(*v))
            .y_label_formatter(&|v| yf.format(*v))
            .label_style(font(18 * k))
            .axis_desc_style(font(20 * k))
            .set_all_tick_mark_size(5 * k)
            .axis_style(BLACK.stroke_width(k))
            .draw()
            .map_err(de)?;
        let (l, r, t, b) = axes.px;
        root.draw(&Rectangle::new(
            [(l as i32, t as i32), (r as i32, b as i32)],
            BLACK.stroke_width(k),
        ))
        .map_err(de)?;

        // order lines, labelled where they leave the axes
        let line_style = WHITE.mix(0.85).stroke_width(k + k / 2);
        let signs: &[f64] = if full { &[1.0, -1.0] } else { &[1.0] };
        for &n in self.orders.iter().filter(|n| n.is_finite() && **n > 0.0) {
            for &sign in signs {
                let o = sign * n;
                let f = |rpm: f64| o * rpm / 60.0;
                let pts = [(f(y0.max(0.0)), y0.max(0.0)), (f(y1), y1)];
                polyline(root, &axes, &pts, line_style, Some((10 * k, 6 * k)))?;
                // exit point: the top edge (or within the top tenth of the side edge:
                // labelled above the corner), else the side edge it reaches first
                let edge_rpm = if o > 0.0 { x1 } else { x0 } * 60.0 / o;
                let (lx, ly, anchor) =
                    if (f(y1) <= x1 && f(y1) >= x0) || edge_rpm > y1 - 0.1 * (y1 - y0) {
                        let p = axes.map((f(y1).clamp(x0, x1), y1));
                        let h = if p.0 > r - 20.0 * kf {
                            HPos::Right
                        } else if p.0 < l + 20.0 * kf {
                            HPos::Left
                        } else {
                            HPos::Center
                        };
                        (p.0, t - 4.0 * kf, (h, VPos::Bottom))
                    } else {
                        let edge = if o > 0.0 { x1 } else { x0 };
                        let rpm = edge * 60.0 / o;
                        if rpm < y0 {
                            continue;
                        }
                        let p = axes.map((edge, rpm));
                        if o > 0.0 {
                            (r + 4.0 * kf, p.1, (HPos::Left, VPos::Center))
                        } else {
                            (l - 4.0 * kf, p.1, (HPos::Right, VPos::Center))
                        }
                    };
                text(root, &order_label(o), (lx, ly), 17 * k, anchor)?;
            }
        }
        if full {
            polyline(
                root,
                &axes,
                &[(0.0, y0), (0.0, y1)],
                WHITE.mix(0.5).stroke_width(k),
                None,
            )?;
            let below = b + 62.0 * kf;
            text(
                root,
                "\u{2190} backward",
                (l, below),
                18 * k,
                (HPos::Left, VPos::Center),
            )?;
            text(
                root,
                "forward \u{2192}",
                (r, below),
                18 * k,
                (HPos::Right, VPos::Center),
            )?;
        }
        self.draw_side(&side, k, range)
    }
}

impl CascadePlot {
    /// The colour bar and notes in the column right of the axes.
    fn draw_side<DB: DrawingBackend>(
        &self,
        side: &DrawingArea<DB, Shift>,
        k: u32,
        (lo, hi): (f64, f64),
    ) -> anyhow::Result<()> {
        let (ki, kf) = (k as i32, k as f64);
        let (_, sh) = side.dim_in_pixel();
        let x = 14.0 * kf;
        let mut y = 60.0 * kf;
        let left = (HPos::Left, VPos::Center);
        text(side, "amplitude (um pk)", (x, y), 18 * k, left)?;
        y += 30.0 * kf;
        let (bx0, bx1) = (x as i32, (x + 28.0 * kf) as i32);
        let by0 = y as i32;
        let by1 = (sh as f64 - 240.0 * kf).max(y + 80.0 * kf) as i32;
        let n = 128;
        for i in 0..n {
            let t0 = i as f64 / n as f64;
            let t1 = (i + 1) as f64 / n as f64;
            let ya = by1 - ((by1 - by0) as f64 * t0) as i32;
            let yb = by1 - ((by1 - by0) as f64 * t1) as i32;
            let a = lo * (hi / lo).powf(0.5 * (t0 + t1));
            side.draw(&Rectangle::new(
                [(bx0, yb), (bx1, ya)],
                viridis(self.level(a, (lo, hi))).filled(),
            ))
            .map_err(de)?;
        }
        side.draw(&Rectangle::new(
            [(bx0, by0), (bx1, by1)],
            BLACK.stroke_width(k),
        ))
        .map_err(de)?;
        for v in log_ticks(lo, hi) {
            let ty = by1 as f64 - (by1 - by0) as f64 * (v / lo).log10() / (hi / lo).log10();
            side.draw(&PathElement::new(
                vec![(bx1, ty as i32), (bx1 + 6 * ki, ty as i32)],
                BLACK.stroke_width(k),
            ))
            .map_err(de)?;
            text(
                side,
                &log_label(v),
                (bx1 as f64 + 10.0 * kf, ty),
                18 * k,
                left,
            )?;
        }
        let c = &self.cascade;
        let mut y = by1 as f64 + 40.0 * kf;
        let notes = [
            format!("max {} um pk", sig3(hi)),
            format!("{} spectra", c.amplitude.len()),
            format!("{} samples each", c.lines),
            format!("lines {} Hz apart", sig3(c.df())),
            "Hann window".to_string(),
        ];
        for line in &notes {
            text(side, line, (x, y), 16 * k, left)?;
            y += 24.0 * kf;
        }
        side.draw(&plotters::element::DashedPathElement::new(
            vec![(x as i32, y as i32), ((x + 26.0 * kf) as i32, y as i32)],
            8 * ki,
            5 * ki,
            BLACK.stroke_width(2 * k),
        ))
        .map_err(de)?;
        text(side, "order nX:", (x + 34.0 * kf, y), 16 * k, left)?;
        y += 24.0 * kf;
        text(side, "f = n rpm / 60", (x + 34.0 * kf, y), 16 * k, left)
    }
}

/// `v` with three significant digits.
fn sig3(v: f64) -> String {
    if !(v.is_finite() && v > 0.0) {
        return format!("{v}");
    }
    let d = (2.0 - v.log10().floor()).clamp(0.0, 9.0) as usize;
    format!("{v:.d$}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use rotorid::transient::{cascade, full_cascade, CascadeSettings};

    /// A run-up 50 -> 350 rad/s at 10 kHz with 1X of 30 um, 2X of 6 um and a forward
    /// subsynchronous whirl at 0.45X of 3 um (x, z), plus a little noise.
    fn run_up() -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
        let dt = 1e-4;
        let n = 300_000;
        let (w0, acc) = (50.0, 10.0);
        let mut t = Vec::with_capacity(n);
        let mut omega = Vec::with_capacity(n);
        let mut x = Vec::with_capacity(n);
        let mut z = Vec::with_capacity(n);
        let mut seed = 12345u64;
        let mut noise = || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.4e-6
        };
        for i in 0..n {
            let ti = i as f64 * dt;
            let phi = w0 * ti + 0.5 * acc * ti * ti;
            let w = w0 + acc * ti;
            // 1X ellipse (forward), 2X, subsynchronous forward circle
            let xi = 30e-6 * phi.sin() + 6e-6 * (2.0 * phi + 0.5).sin() + 3e-6 * (0.45 * phi).sin();
            let zi = 20e-6 * phi.cos() + 6e-6 * (2.0 * phi + 0.5).cos() + 3e-6 * (0.45 * phi).cos();
            t.push(ti);
            omega.push(w);
            x.push(xi + noise());
            z.push(zi + noise());
        }
        (t, omega, x, z)
    }

    fn png_size(path: &Path) -> (u32, u32, Vec<u8>) {
        let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size()];
        let info = reader.next_frame(&mut buf).unwrap();
        buf.truncate(info.buffer_size());
        (info.width, info.height, buf)
    }

    /// Distinct colours among the pixels (a blank or one-colour figure has few).
    fn colours(rgb: &[u8]) -> usize {
        let mut set: Vec<[u8; 3]> = rgb.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
        set.sort_unstable();
        set.dedup();
        set.len()
    }

    fn keep() -> Option<std::path::PathBuf> {
        std::env::var_os("ROTORID_KEEP_PLOTS").map(std::path::PathBuf::from)
    }

    #[test]
    fn one_probe_cascade_draws_as_png_and_svg() {
        let (t, omega, x, _) = run_up();
        let c = cascade(&t, &omega, &x, &CascadeSettings::default()).unwrap();
        let plot = CascadePlot::new("Cascade \u{2014} probe X, run-up", c);
        assert_eq!(plot.orders, (1..=10).map(f64::from).collect::<Vec<_>>());
        let dir = tempfile::tempdir().unwrap();
        let png = dir.path().join("cascade.png");
        plot.save(&png).unwrap();
        let (w, h, rgb) = png_size(&png);
        assert_eq!((w, h), CASCADE_SIZE);
        // the map uses many viridis colours; white background, black text
        assert!(colours(&rgb) > 60, "{} colours", colours(&rgb));
        let svg = dir.path().join("cascade.svg");
        plot.save(&svg).unwrap();
        let text = std::fs::read_to_string(&svg).unwrap();
        assert!(text.starts_with("<svg"));
        for label in [
            "frequency (Hz)",
            "running speed (rpm)",
            "amplitude (um pk)",
            "1X",
            "2X",
            "10X",
            "probe X",
        ] {
            assert!(text.contains(label), "cascade.svg lacks {label:?}");
        }
        assert!(!text.contains("backward"));
        assert!(text.len() < 4_000_000, "svg of {} bytes", text.len());
        if let Some(d) = keep() {
            std::fs::copy(&png, d.join("cascade.png")).unwrap();
            std::fs::copy(&svg, d.join("cascade.svg")).unwrap();
        }
    }

    #[test]
    fn full_cascade_draws_with_both_whirl_directions() {
        let (t, omega, x, z) = run_up();
        let settings = CascadeSettings {
            max_order: 3.0,
            ..CascadeSettings::default()
        };
        let c = full_cascade(&t, &omega, &x, &z, &settings).unwrap();
        let mut plot = CascadePlot::new("Full spectrum cascade \u{2014} probes X, Z", c);
        plot.orders = vec![0.5, 1.0, 2.0, 3.0];
        let dir = tempfile::tempdir().unwrap();
        let png = dir.path().join("full.png");
        plot.save(&png).unwrap();
        let (w, h, rgb) = png_size(&png);
        assert_eq!((w, h), CASCADE_SIZE);
        assert!(colours(&rgb) > 60);
        let svg = dir.path().join("full.svg");
        plot.save(&svg).unwrap();
        let text = std::fs::read_to_string(&svg).unwrap();
        for label in [
            "backward",
            "forward",
            "-1X",
            "1X",
            "0.5X",
            "-0.5X",
            "amplitude (um pk)",
        ] {
            assert!(text.contains(label), "full.svg lacks {label:?}");
        }
        if let Some(d) = keep() {
            std::fs::copy(&png, d.join("full_cascade.png")).unwrap();
            std::fs::copy(&svg, d.join("full_cascade.svg")).unwrap();
        }
    }

    #[test]
    fn empty_cascades_and_bad_scales_are_refused() {
        let (t, omega, x, _) = run_up();
        let c = cascade(
            &t[..4096],
            &omega[..4096],
            &x[..4096],
            &CascadeSettings::default(),
        )
        .unwrap();
        let dir = tempfile::tempdir().unwrap();
        let plot_ok = || CascadePlot::new("c", c.clone());
        let mut plot = plot_ok();
        plot.decades = 0.0;
        let e = plot.save(&dir.path().join("a.png")).unwrap_err();
        assert!(e.to_string().contains("decades = 0"), "{e}");
        let mut empty = plot_ok();
        empty.cascade.amplitude.clear();
        let e = empty.save(&dir.path().join("a.png")).unwrap_err();
        assert!(e.to_string().contains("0 spectra"), "{e}");
        let e = plot_ok().save(&dir.path().join("a.jpg")).unwrap_err();
        assert!(e.to_string().contains(".jpg"), "{e}");
    }

    #[test]
    fn colour_scale_spans_the_decades_below_the_top() {
        let (t, omega, x, _) = run_up();
        let c = cascade(&t, &omega, &x, &CascadeSettings::default()).unwrap();
        let top = c.amplitude.iter().flatten().fold(0.0f64, |m, &a| m.max(a)) * 1e6;
        let plot = CascadePlot::new("c", c);
        let (lo, hi) = plot.colour_range();
        assert!((hi - top).abs() < 1e-12 * top && (lo - top / 100.0).abs() < 1e-12 * top);
        assert_eq!(plot.level(hi, (lo, hi)), 63.5 / 64.0);
        assert_eq!(plot.level(lo / 2.0, (lo, hi)), 0.5 / 64.0);
        assert_eq!(log_ticks(0.3, 30.0), vec![0.5, 1.0, 2.0, 5.0, 10.0, 20.0]);
        assert_eq!(log_label(0.05), "0.05");
        assert_eq!(order_label(-1.0), "-1X");
        assert_eq!(order_label(0.5), "0.5X");
    }
}
