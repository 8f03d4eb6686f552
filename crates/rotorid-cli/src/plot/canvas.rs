//! Drawing helpers for the analysis figures (Campbell, Bode, polar), which need markers,
//! filled bands, a colour scale and annotations that the line-series [`super::Figure`]
//! does not offer.
//!
//! Each figure implements [`Drawing`]; [`save_drawing`] writes it as PNG (drawn at twice
//! the size and box-filtered down, as [`super::save`] does) or SVG. Axes, ticks and grid
//! are plotters' mesh; the data are drawn in pixel coordinates through an [`Axes`] map
//! (linear or logarithmic in y), clipped to the plotting rectangle with the Liang-Barsky
//! test of [`super::geometry`] and cut at sharp turns so thick bitmap lines never grow
//! miter spikes.

use std::path::Path;

use anyhow::{bail, Context};
use plotters::coord::Shift;
use plotters::element::{DashedPathElement, PathElement};
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::font::{ensure_registered, FAMILY};
use super::geometry::{clip_polyline, split_at_sharp_turns, Point, Rect};
use super::render::box_downsample;
use super::ImageFormat;

/// PNG supersampling factor (as for [`super::save`]).
const SUPERSAMPLE: u32 = 2;

/// A figure that can draw itself on any plotters backend; `k` scales every length (2 for
/// the supersampled bitmap, 1 for SVG).
pub trait Drawing {
    /// Draw on `root` (the whole image).
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>, k: u32)
        -> anyhow::Result<()>;
}

/// Write `d` to `path` (`.png` or `.svg`) at `size` pixels.
pub fn save_drawing(d: &impl Drawing, size: (u32, u32), path: &Path) -> anyhow::Result<()> {
    let format = ImageFormat::from_path(path)?;
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        if !dir.is_dir() {
            bail!(
                "cannot write figure {}: directory {} does not exist",
                path.display(),
                dir.display()
            );
        }
    }
    ensure_registered()?;
    let (w, h) = size;
    let result = match format {
        ImageFormat::Png => {
            let s = SUPERSAMPLE;
            let (bw, bh) = (w * s, h * s);
            let mut big = vec![0u8; 3 * (bw * bh) as usize];
            {
                let root = BitMapBackend::with_buffer(&mut big, (bw, bh)).into_drawing_area();
                root.fill(&WHITE).map_err(de)?;
                d.draw(&root, s)?;
                root.present().map_err(de)?;
            }
            let small = box_downsample(&big, bw, bh, s);
            let mut out = BitMapBackend::new(path, (w, h));
            out.blit_bitmap((0, 0), (w, h), &small).map_err(de)?;
            out.present().map_err(de)
        }
        ImageFormat::Svg => {
            let root = SVGBackend::new(path, (w, h)).into_drawing_area();
            root.fill(&WHITE).map_err(de)?;
            d.draw(&root, 1)?;
            root.present().map_err(de)
        }
    };
    result.with_context(|| format!("cannot write figure {}", path.display()))
}

/// A plotters error as anyhow.
pub fn de<E: std::fmt::Display>(e: E) -> anyhow::Error {
    anyhow::anyhow!("{e}")
}

/// The figures' font at `px` pixels, black.
pub fn font(px: u32) -> TextStyle<'static> {
    (FAMILY, px).into_font().color(&BLACK)
}

/// Text anchored at `pos` (pixels) by `h`, `v`.
pub fn text<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    s: &str,
    pos: (f64, f64),
    px: u32,
    (h, v): (HPos, VPos),
) -> anyhow::Result<()> {
    let style = font(px).pos(Pos::new(h, v));
    root.draw(&Text::new(
        s.to_owned(),
        (pos.0 as i32, pos.1 as i32),
        style,
    ))
    .map_err(de)
}

/// The map from data to pixels of one set of axes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Axes {
    /// Plotting rectangle in pixels: left, right, top, bottom.
    pub px: (f64, f64, f64, f64),
    /// Data range on x.
    pub x: (f64, f64),
    /// Data range on y (positive when `y_log`).
    pub y: (f64, f64),
    /// Logarithmic y axis.
    pub y_log: bool,
}

impl Axes {
    /// The axes of a chart built on the ranges `x`, `y`.
    pub fn of<DB: DrawingBackend, CT: CoordTranslate>(
        chart: &ChartContext<'_, DB, CT>,
        x: (f64, f64),
        y: (f64, f64),
        y_log: bool,
    ) -> Self {
        let (xr, yr) = chart.plotting_area().get_pixel_range();
        Self {
            px: (
                xr.start as f64,
                (xr.end - 1) as f64,
                yr.start as f64,
                (yr.end - 1) as f64,
            ),
            x,
            y,
            y_log,
        }
    }

    fn yv(&self, y: f64) -> f64 {
        if self.y_log {
            y.log10()
        } else {
            y
        }
    }

    /// Pixel position of the data point (x, y) (not clipped).
    pub fn map(&self, (x, y): Point) -> Point {
        let (l, r, t, b) = self.px;
        let fx = (x - self.x.0) / (self.x.1 - self.x.0);
        let (y0, y1) = (self.yv(self.y.0), self.yv(self.y.1));
        let fy = (self.yv(y) - y0) / (y1 - y0);
        (l + fx * (r - l), b - fy * (b - t))
    }

    /// The plotting rectangle in pixels, as a clipping rectangle.
    pub fn frame(&self) -> Rect {
        let (l, r, t, b) = self.px;
        Rect {
            x0: l,
            x1: r,
            y0: t,
            y1: b,
        }
    }

    /// True when the data point lies inside the axes.
    pub fn contains(&self, (x, y): Point) -> bool {
        let (a, b) = (self.x.0.min(self.x.1), self.x.0.max(self.x.1));
        let (c, d) = (self.y.0.min(self.y.1), self.y.0.max(self.y.1));
        x >= a && x <= b && y >= c && y <= d
    }
}

/// Draw the polyline through the data points `pts` on `axes`, solid or dashed
/// `(dash, gap)` in pixels; non-finite points break it, and it is clipped to the axes.
pub fn polyline<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    axes: &Axes,
    pts: &[Point],
    style: ShapeStyle,
    dashed: Option<(u32, u32)>,
) -> anyhow::Result<()> {
    let mut runs: Vec<Vec<Point>> = vec![Vec::new()];
    for &p in pts {
        let q = axes.map(p);
        if q.0.is_finite() && q.1.is_finite() {
            runs.last_mut().expect("non-empty").push(q);
        } else if !runs.last().expect("non-empty").is_empty() {
            runs.push(Vec::new());
        }
    }
    for run in runs.iter().filter(|r| r.len() >= 2) {
        for piece in clip_polyline(run, &axes.frame()) {
            let strokes = if style.stroke_width > 1 {
                split_at_sharp_turns(&piece, 1.0, 1.0)
            } else {
                vec![piece]
            };
            for s in strokes {
                let p: Vec<(i32, i32)> = s.iter().map(|&(x, y)| (x as i32, y as i32)).collect();
                match dashed {
                    None => root.draw(&PathElement::new(p, style)),
                    Some((dash, gap)) => {
                        root.draw(&DashedPathElement::new(p, dash as i32, gap as i32, style))
                    }
                }
                .map_err(de)?;
            }
        }
    }
    Ok(())
}

/// Fill the band between `lo` and `hi` (data y per x of `x`) on `axes`, each clamped to
/// the y-range; a non-finite bound breaks the band.
pub fn band<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    axes: &Axes,
    x: &[f64],
    lo: &[f64],
    hi: &[f64],
    color: RGBAColor,
) -> anyhow::Result<()> {
    let (ymin, ymax) = (axes.y.0.min(axes.y.1), axes.y.0.max(axes.y.1));
    let clamp = |v: f64| v.clamp(ymin, ymax);
    let mut start = 0;
    while start < x.len() {
        let ok = |i: usize| x[i].is_finite() && lo[i].is_finite() && hi[i].is_finite();
        if !ok(start) {
            start += 1;
            continue;
        }
        let mut end = start;
        while end + 1 < x.len() && ok(end + 1) {
            end += 1;
        }
        if end > start {
            let mut poly: Vec<(i32, i32)> = Vec::with_capacity(2 * (end - start + 1));
            for i in start..=end {
                let p = axes.map((x[i], clamp(hi[i])));
                poly.push((p.0 as i32, p.1 as i32));
            }
            for i in (start..=end).rev() {
                let p = axes.map((x[i], clamp(lo[i])));
                poly.push((p.0 as i32, p.1 as i32));
            }
            root.draw(&Polygon::new(poly, color.filled())).map_err(de)?;
        }
        start = end + 1;
    }
    Ok(())
}

/// A marker shape.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Marker {
    /// Triangle pointing up (forward whirl, as ROSS draws it).
    Up,
    /// Triangle pointing down (backward whirl).
    Down,
    /// Circle (no whirl direction).
    Circle,
}

/// Draw `marker` of half-size `r` pixels at pixel `at`, filled with `fill` and outlined
/// in `edge`.
pub fn marker<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    at: Point,
    marker: Marker,
    r: i32,
    fill: RGBColor,
    edge: ShapeStyle,
) -> anyhow::Result<()> {
    let (x, y) = (at.0 as i32, at.1 as i32);
    let pts = match marker {
        Marker::Up => vec![(x, y - r), (x + r, y + r * 3 / 4), (x - r, y + r * 3 / 4)],
        Marker::Down => vec![(x, y + r), (x + r, y - r * 3 / 4), (x - r, y - r * 3 / 4)],
        Marker::Circle => {
            root.draw(&Circle::new((x, y), r, fill.filled()))
                .map_err(de)?;
            return root.draw(&Circle::new((x, y), r, edge)).map_err(de);
        }
    };
    root.draw(&Polygon::new(pts.clone(), fill.filled()))
        .map_err(de)?;
    let mut closed = pts.clone();
    closed.push(pts[0]);
    root.draw(&PathElement::new(closed, edge)).map_err(de)
}

/// The viridis colour map (perceptually uniform, colour-blind safe; van der Walt & Smith,
/// matplotlib 2015) at `t` in \[0, 1\], by linear interpolation between 9 of its colours.
pub fn viridis(t: f64) -> RGBColor {
    const STOPS: [(u8, u8, u8); 9] = [
        (68, 1, 84),
        (71, 44, 122),
        (59, 81, 139),
        (44, 113, 142),
        (33, 144, 141),
        (39, 173, 129),
        (92, 200, 99),
        (170, 220, 50),
        (253, 231, 37),
    ];
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let f = t * (STOPS.len() - 1) as f64;
    let i = (f.floor() as usize).min(STOPS.len() - 2);
    let u = f - i as f64;
    let lerp = |a: u8, b: u8| (a as f64 + u * (b as f64 - a as f64)).round() as u8;
    let (a, b) = (STOPS[i], STOPS[i + 1]);
    RGBColor(lerp(a.0, b.0), lerp(a.1, b.1), lerp(a.2, b.2))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viridis_ends_are_the_map_ends() {
        assert_eq!(viridis(0.0), RGBColor(68, 1, 84));
        assert_eq!(viridis(1.0), RGBColor(253, 231, 37));
        assert_eq!(viridis(f64::NAN), RGBColor(68, 1, 84));
        assert_eq!(viridis(0.5), RGBColor(33, 144, 141));
    }

    #[test]
    fn axes_map_corners_and_decades() {
        let a = Axes {
            px: (100.0, 500.0, 50.0, 450.0),
            x: (0.0, 10.0),
            y: (0.1, 1000.0),
            y_log: true,
        };
        assert_eq!(a.map((0.0, 0.1)), (100.0, 450.0));
        assert_eq!(a.map((10.0, 1000.0)), (500.0, 50.0));
        let mid = a.map((5.0, 10.0));
        assert!((mid.0 - 300.0).abs() < 1e-9 && (mid.1 - 250.0).abs() < 1e-9);
    }
}
