//! Figures for engineers: one or more panels of line series, written as PNG or SVG.
//!
//! A [`Figure`] holds a title and 1-4 [`Panel`]s (stacked, or side by side); a panel holds
//! [`Series`] (label, x, y, solid or dashed, colour), axis labels with quantity and unit,
//! an optional zoom window on x with y auto-scaled to what is visible
//! ([`scale`]: NaN and masked points ignored, optional limits around a reference),
//! engineering tick labels ([`ticks`]) and a legend beside the axes. Lines are clipped to
//! the axes ([`geometry`]) and decimated to the pixel grid, so a spike cannot paint over
//! the margins and a long record still makes a small SVG; a record read from a file is
//! thinned to the pixel grid as it streams in ([`thin`]), so memory stays flat too.
//!
//! [`save`] picks the format from the file extension (`.png` or `.svg`). Text uses the
//! embedded DejaVu Sans ([`font`]).
//! The analysis figures ([`campbell`], [`bode`], [`polar`], and the transient's [`cascade`]) draw markers, bands and a colour scale through [`canvas`].

pub mod bode;
pub mod campbell;
pub mod canvas;
pub mod cascade;
pub mod font;
pub mod geometry;
pub mod polar;
mod render;
pub mod scale;
pub mod thin;
pub mod ticks;

use std::io::Write as _;
use std::path::Path;

use anyhow::{bail, Context};

use crate::io::{FileMode, Output};

/// Default image size in pixels (width, height): at least 1200 x 800.
pub const DEFAULT_SIZE: (u32, u32) = (1400, 900);

/// An sRGB colour.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Rgb(pub u8, pub u8, pub u8);

/// `c` as plotters' colour.
pub fn rgb(c: Rgb) -> plotters::style::RGBColor {
    plotters::style::RGBColor(c.0, c.1, c.2)
}

/// Colours from the Okabe-Ito colour-blind-safe palette (M. Okabe, K. Ito, "Color
/// Universal Design", 2008), plus black and grey.
pub mod palette {
    use super::Rgb;
    /// Blue.
    pub const BLUE: Rgb = Rgb(0, 114, 178);
    /// Vermillion.
    pub const VERMILLION: Rgb = Rgb(213, 94, 0);
    /// Black.
    pub const BLACK: Rgb = Rgb(0, 0, 0);
    /// Dark grey.
    pub const GREY: Rgb = Rgb(90, 90, 90);
}

/// How a series' line is drawn.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LineStyle {
    /// A continuous line (estimates, responses).
    Solid,
    /// A dashed line (true values).
    Dashed,
    /// A filled dot at each point, no line (keyphasor marks on an orbit); `width` is the
    /// dot's diameter in pixels.
    Dots,
}

/// One curve: y against x, both in the panel's display units.
#[derive(Debug, Clone, PartialEq)]
pub struct Series {
    /// Legend text; an empty label keeps the series out of the legend.
    pub label: String,
    /// Abscissae (same length as `y`).
    pub x: Vec<f64>,
    /// Ordinates; NaN or infinite values break the line.
    pub y: Vec<f64>,
    /// Solid or dashed.
    pub style: LineStyle,
    /// Line colour.
    pub color: Rgb,
    /// Line width in pixels.
    pub width: u32,
    /// Which points count when auto-scaling y (`false`: drawn, clipped, but ignored, e.g.
    /// an estimate at an ill-conditioned instant). `None`: every point counts.
    pub scale_mask: Option<Vec<bool>>,
}

impl Series {
    /// A solid line of width 2.
    pub fn solid(label: impl Into<String>, x: Vec<f64>, y: Vec<f64>, color: Rgb) -> Self {
        Self {
            label: label.into(),
            x,
            y,
            style: LineStyle::Solid,
            color,
            width: 2,
            scale_mask: None,
        }
    }

    /// A dashed line of width 2.
    pub fn dashed(label: impl Into<String>, x: Vec<f64>, y: Vec<f64>, color: Rgb) -> Self {
        Self {
            style: LineStyle::Dashed,
            ..Self::solid(label, x, y, color)
        }
    }

    /// A filled dot of `diameter` pixels at each point, unjoined.
    pub fn dots(
        label: impl Into<String>,
        x: Vec<f64>,
        y: Vec<f64>,
        color: Rgb,
        diameter: u32,
    ) -> Self {
        Self {
            style: LineStyle::Dots,
            width: diameter,
            ..Self::solid(label, x, y, color)
        }
    }

    /// A dashed horizontal line at `value` from `x0` to `x1` (a true value).
    pub fn level(label: impl Into<String>, x0: f64, x1: f64, value: f64, color: Rgb) -> Self {
        Self::dashed(label, vec![x0, x1], vec![value, value], color)
    }

    /// Set which points count when auto-scaling y.
    pub fn with_scale_mask(mut self, mask: Vec<bool>) -> Self {
        self.scale_mask = Some(mask);
        self
    }

    /// Set the line width in pixels.
    pub fn with_width(mut self, width: u32) -> Self {
        self.width = width;
        self
    }
}

/// One set of axes.
#[derive(Debug, Clone, PartialEq)]
pub struct Panel {
    /// Caption above the axes (may be empty).
    pub title: String,
    /// x-axis label with quantity and unit, e.g. `time t (s)`.
    pub x_label: String,
    /// y-axis label with quantity and unit, e.g. `stiffness k (N/m)`.
    pub y_label: String,
    /// The curves, drawn in order (later on top).
    pub series: Vec<Series>,
    /// Zoom window on x; `None`: the data's extent.
    pub x_range: Option<(f64, f64)>,
    /// Fixed y-range; `None`: auto-scaled (see [`scale::y_range`]).
    pub y_range: Option<(f64, f64)>,
    /// Auto-scaling never goes beyond these limits (e.g. a band around the true value).
    pub y_limits: Option<(f64, f64)>,
    /// Auto-scaling never gives a span narrower than this (y units; 0: no minimum).
    pub min_y_span: f64,
    /// Same data units per pixel on both axes (orbits).
    pub equal_aspect: bool,
}

impl Panel {
    /// An empty panel with a caption and axis labels.
    pub fn new(
        title: impl Into<String>,
        x_label: impl Into<String>,
        y_label: impl Into<String>,
    ) -> Self {
        Self {
            title: title.into(),
            x_label: x_label.into(),
            y_label: y_label.into(),
            series: Vec::new(),
            x_range: None,
            y_range: None,
            y_limits: None,
            min_y_span: 0.0,
            equal_aspect: false,
        }
    }

    /// Add the curves.
    pub fn with_series(mut self, series: Vec<Series>) -> Self {
        self.series.extend(series);
        self
    }

    /// Zoom to `x0..x1`.
    pub fn with_x_range(mut self, x0: f64, x1: f64) -> Self {
        self.x_range = Some((x0, x1));
        self
    }

    /// Bound the auto-scaled y-range.
    pub fn with_y_limits(mut self, lo: f64, hi: f64) -> Self {
        self.y_limits = Some((lo, hi));
        self
    }

    /// Never auto-scale y narrower than `span`.
    pub fn with_min_y_span(mut self, span: f64) -> Self {
        self.min_y_span = span;
        self
    }

    /// Equal units per pixel on x and y.
    pub fn with_equal_aspect(mut self) -> Self {
        self.equal_aspect = true;
        self
    }

    /// The x- and y-ranges this panel will be drawn with.
    pub fn ranges(&self) -> ((f64, f64), (f64, f64)) {
        let xr = scale::x_range(self);
        (xr, scale::y_range(self, xr))
    }
}

/// How panels are arranged.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Layout {
    /// One above the other.
    Stacked,
    /// Left to right.
    SideBySide,
}

/// A titled figure of panels.
#[derive(Debug, Clone, PartialEq)]
pub struct Figure {
    /// Title across the top.
    pub title: String,
    /// The panels (1 to 4).
    pub panels: Vec<Panel>,
    /// Their arrangement.
    pub layout: Layout,
    /// Image size in pixels (width, height).
    pub size: (u32, u32),
}

impl Figure {
    /// A figure of stacked panels at [`DEFAULT_SIZE`].
    pub fn new(title: impl Into<String>, panels: Vec<Panel>) -> Self {
        Self {
            title: title.into(),
            panels,
            layout: Layout::Stacked,
            size: DEFAULT_SIZE,
        }
    }

    /// Arrange the panels side by side.
    pub fn side_by_side(mut self) -> Self {
        self.layout = Layout::SideBySide;
        self
    }

    /// Set the size in pixels.
    pub fn with_size(mut self, width: u32, height: u32) -> Self {
        self.size = (width, height);
        self
    }

    /// Give every panel the same y-range: the union of their auto-scaled ranges (so two
    /// settings compared panel against panel are on one scale).
    pub fn share_y(mut self) -> Self {
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for p in &self.panels {
            let (_, (a, b)) = p.ranges();
            lo = lo.min(a);
            hi = hi.max(b);
        }
        if lo < hi {
            for p in &mut self.panels {
                p.y_range = Some((lo, hi));
            }
        }
        self
    }
}

/// The image formats [`save`] writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ImageFormat {
    /// Portable Network Graphics (raster).
    Png,
    /// Scalable Vector Graphics.
    Svg,
}

impl ImageFormat {
    /// The format named by `path`'s extension (case-insensitive), or an error naming it.
    pub fn from_path(path: &Path) -> anyhow::Result<Self> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("png") => Ok(Self::Png),
            Some("svg") => Ok(Self::Svg),
            Some(other) => bail!(
                "cannot write figure {}: unknown image extension `.{other}` (use .png or .svg)",
                path.display()
            ),
            None => bail!(
                "cannot write figure {}: no file extension (use .png or .svg)",
                path.display()
            ),
        }
    }
}

/// Write `fig` to `path` as PNG or SVG according to the extension, atomically (a failed
/// run leaves no half image; see [`crate::io::output`]).
pub fn save(fig: &Figure, path: &Path) -> anyhow::Result<()> {
    let format = ImageFormat::from_path(path)?;
    if fig.panels.is_empty() || fig.panels.len() > 4 {
        bail!(
            "cannot write figure {}: it has {} panels (1 to 4 are supported)",
            path.display(),
            fig.panels.len()
        );
    }
    let (w, h) = fig.size;
    if w < 200 || h < 200 {
        bail!(
            "cannot write figure {}: size {w} x {h} px is below 200 x 200",
            path.display()
        );
    }
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        if !dir.is_dir() {
            bail!(
                "cannot write figure {}: directory {} does not exist",
                path.display(),
                dir.display()
            );
        }
    }
    font::ensure_registered()?;
    let bytes = render::render(fig, format)
        .with_context(|| format!("cannot draw figure {}", path.display()))?;
    let name = path.to_string_lossy();
    let mut out = Output::create(&name, FileMode::Atomic)
        .with_context(|| format!("cannot write figure {}", path.display()))?;
    out.write_all(&bytes)
        .with_context(|| format!("cannot write figure {}", path.display()))?;
    out.commit()
        .with_context(|| format!("cannot write figure {}", path.display()))
}
