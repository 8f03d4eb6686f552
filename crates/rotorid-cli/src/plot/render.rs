//! Drawing a [`Figure`] with plotters onto a PNG (bitmap) or SVG backend.
//!
//! Layout of one panel: caption on top; the axes with tick labels on the left and bottom;
//! the legend in a column to the right of the axes (never over the data). Every series
//! is split at non-finite values, decimated to the pixel grid and clipped to the axes
//! before it is handed to plotters (see [`super::geometry`]).
//!
//! PNG is supersampled: drawn at [`SUPERSAMPLE`] times the size with every length scaled
//! alike, then averaged down over SUPERSAMPLE x SUPERSAMPLE blocks (a box filter),
//!
//! ```text
//! out(x, y) = mean { big(S x + i, S y + j) : 0 <= i, j < S }
//! ```
//!
//! which antialiases the lines (plotters' bitmap lines are aliased) and evens out the
//! 1-pixel glyph placement of its text renderer.

use plotters::coord::Shift;
use plotters::element::DashedPathElement;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

use super::canvas::de;
use super::font::FAMILY;
use super::geometry::{clip_polyline, decimate, finite_runs, split_at_sharp_turns, Rect};
use super::ticks::TickFormat;
use super::{rgb, Figure, ImageFormat, Layout, LineStyle, Panel, Series};

/// PNG supersampling factor.
const SUPERSAMPLE: u32 = 2;

/// Every length of the layout, in pixels of the image being drawn (the final image's
/// pixels times the drawing scale). Font sizes are even: plotters places glyphs at
/// size / 2 from the baseline, so an odd size misplaces glyphs by a pixel.
#[derive(Debug, Clone, Copy)]
struct Px {
    k: u32,
    title: u32,
    caption: u32,
    tick: u32,
    desc: u32,
    legend: u32,
    /// Space around the axes inside a panel.
    margin: u32,
    /// Height under the x-axis for tick labels and the axis label.
    x_label_area: u32,
    /// Width left of the y-axis for tick labels and the axis label.
    y_label_area: u32,
    /// At most one x tick label per this width of axis.
    per_x_label: u32,
    /// At most one y tick label per this height of axis.
    per_y_label: u32,
    legend_sample: i32,
    legend_row: i32,
    dash: i32,
    gap: i32,
    /// Draw thick polylines in strokes that never turn by more than 90 degrees: the
    /// bitmap backend outlines a thick polyline with unlimited miter joins, which shoot
    /// far out of the axes at the spikes of an estimate (SVG viewers limit miters).
    split_sharp_turns: bool,
}

impl Px {
    /// The layout at `k` times the nominal size (k > 1: the supersampled bitmap).
    fn scaled(k: u32) -> Self {
        let ki = k as i32;
        Self {
            k,
            title: 28 * k,
            caption: 22 * k,
            tick: 18 * k,
            desc: 20 * k,
            legend: 18 * k,
            margin: 14 * k,
            x_label_area: 64 * k,
            y_label_area: 118 * k,
            per_x_label: 110 * k,
            per_y_label: 40 * k,
            legend_sample: 44 * ki,
            legend_row: 28 * ki,
            dash: 12 * ki,
            gap: 7 * ki,
            split_sharp_turns: k > 1,
        }
    }
}

fn font(px: u32) -> TextStyle<'static> {
    (FAMILY, px).into_font().color(&BLACK)
}

/// Render `fig` in `format`: the bytes of the PNG or SVG file.
pub(super) fn render(fig: &Figure, format: ImageFormat) -> anyhow::Result<Vec<u8>> {
    let (w, h) = fig.size;
    match format {
        ImageFormat::Png => {
            let s = SUPERSAMPLE;
            let (bw, bh) = (w * s, h * s);
            let mut big = vec![0u8; 3 * (bw * bh) as usize];
            {
                let root = BitMapBackend::with_buffer(&mut big, (bw, bh)).into_drawing_area();
                draw_figure(fig, &root, Px::scaled(s))?;
                root.present().map_err(de)?;
            }
            let small = box_downsample(&big, bw, bh, s);
            drop(big);
            encode_png(&small, w, h)
        }
        ImageFormat::Svg => {
            let mut text = String::new();
            {
                let root = SVGBackend::with_string(&mut text, (w, h)).into_drawing_area();
                draw_figure(fig, &root, Px::scaled(1))?;
                root.present().map_err(de)?;
            }
            Ok(text.into_bytes())
        }
    }
}

/// An 8-bit RGB image of `w x h` pixels as a PNG file.
fn encode_png(rgb: &[u8], w: u32, h: u32) -> anyhow::Result<Vec<u8>> {
    let mut out = Vec::new();
    let mut enc = png::Encoder::new(&mut out, w, h);
    enc.set_color(png::ColorType::Rgb);
    enc.set_depth(png::BitDepth::Eight);
    let mut writer = enc.write_header()?;
    writer.write_image_data(rgb)?;
    writer.finish()?;
    Ok(out)
}

/// Average an RGB image of `bw x bh` pixels over `s x s` blocks (module doc).
pub(super) fn box_downsample(big: &[u8], bw: u32, bh: u32, s: u32) -> Vec<u8> {
    let (w, h) = (bw / s, bh / s);
    let n = s * s;
    let mut out = vec![0u8; 3 * (w * h) as usize];
    for y in 0..h {
        for x in 0..w {
            for c in 0..3 {
                let mut sum = 0u32;
                for j in 0..s {
                    for i in 0..s {
                        let idx = 3 * ((y * s + j) * bw + (x * s + i)) as usize + c;
                        sum += u32::from(big[idx]);
                    }
                }
                out[3 * (y * w + x) as usize + c] = ((sum + n / 2) / n) as u8;
            }
        }
    }
    out
}

fn draw_figure<DB: DrawingBackend>(
    fig: &Figure,
    root: &DrawingArea<DB, Shift>,
    px: Px,
) -> anyhow::Result<()> {
    root.fill(&WHITE).map_err(de)?;
    let body = if fig.title.is_empty() {
        root.clone()
    } else {
        let style = (FAMILY, px.title)
            .into_font()
            .style(FontStyle::Bold)
            .color(&BLACK);
        root.margin(8 * px.k, 0, 0, 0)
            .titled(&fig.title, style)
            .map_err(de)?
            .margin(6 * px.k, 0, 0, 0)
    };
    let n = fig.panels.len();
    match fig.layout {
        Layout::Stacked => {
            // one legend width for all, so the stacked axes line up
            let mut legend_w = 0;
            for p in &fig.panels {
                legend_w = legend_w.max(legend_width(&body, &labelled(p), px)?);
            }
            for (panel, area) in fig.panels.iter().zip(&body.split_evenly((n, 1))) {
                draw_panel(panel, area, px, Some(legend_w))?;
            }
        }
        Layout::SideBySide => {
            for (panel, area) in fig
                .panels
                .iter()
                .zip(&side_by_side(&body, &fig.panels, px)?)
            {
                draw_panel(panel, area, px, None)?;
            }
        }
    }
    Ok(())
}

fn labelled(panel: &Panel) -> Vec<&Series> {
    panel
        .series
        .iter()
        .filter(|s| !s.label.is_empty())
        .collect()
}

/// Columns for panels side by side: an equal-aspect panel (an orbit) gets the width that
/// makes its axes square; the others share the rest equally.
fn side_by_side<DB: DrawingBackend>(
    body: &DrawingArea<DB, Shift>,
    panels: &[Panel],
    px: Px,
) -> anyhow::Result<Vec<DrawingArea<DB, Shift>>> {
    let (w, h) = body.dim_in_pixel();
    let caption_h = 2 * px.caption;
    let square = h.saturating_sub(caption_h + px.x_label_area + 2 * px.margin);
    let mut widths = Vec::with_capacity(panels.len());
    for p in panels {
        widths.push(if p.equal_aspect {
            Some(square + px.y_label_area + 2 * px.margin + legend_width(body, &labelled(p), px)?)
        } else {
            None
        });
    }
    let fixed: u32 = widths.iter().flatten().sum();
    let flexible = widths.iter().filter(|w| w.is_none()).count() as u32;
    let fits = fixed < w && (flexible == 0 || (w - fixed) / flexible >= w / 4);
    if !fits {
        return Ok(body.split_evenly((1, panels.len())));
    }
    let share = (w - fixed).checked_div(flexible).unwrap_or(0);
    let mut areas = Vec::with_capacity(panels.len());
    let mut rest = body.clone();
    for (i, width) in widths.iter().enumerate() {
        if i + 1 == panels.len() {
            areas.push(rest.clone());
            break;
        }
        let (left, right) = rest.split_horizontally(width.unwrap_or(share));
        areas.push(left);
        rest = right;
    }
    Ok(areas)
}

/// Draw one panel in `area`; `legend_w` fixes the legend column's width (else it fits the
/// labels).
fn draw_panel<DB: DrawingBackend>(
    panel: &Panel,
    area: &DrawingArea<DB, Shift>,
    px: Px,
    legend_w: Option<u32>,
) -> anyhow::Result<()> {
    let area = if panel.title.is_empty() {
        area.clone()
    } else {
        area.titled(&panel.title, font(px.caption)).map_err(de)?
    };
    let labelled = labelled(panel);
    let (w, h) = area.dim_in_pixel();
    let legend_w = match legend_w {
        Some(lw) => lw,
        None => legend_width(&area, &labelled, px)?,
    }
    .min(w * 2 / 5);
    let (plot_area, legend_area) = area.split_horizontally(w - legend_w);

    // Pixel size of the axes' interior, used for decimation, tick density and equal aspect.
    let pw = (w - legend_w)
        .saturating_sub(2 * px.margin + px.y_label_area)
        .max(1);
    let ph = h.saturating_sub(2 * px.margin + px.x_label_area).max(1);
    let ((mut x0, mut x1), (mut y0, mut y1)) = panel.ranges();
    if panel.equal_aspect {
        (x0, x1, y0, y1) = equalise(x0, x1, y0, y1, pw, ph);
    }

    let mut chart = ChartBuilder::on(&plot_area)
        .margin(px.margin)
        .x_label_area_size(px.x_label_area)
        .y_label_area_size(px.y_label_area)
        .build_cartesian_2d(x0..x1, y0..y1)
        .map_err(de)?;
    let n_x_labels = (pw / px.per_x_label).clamp(2, 10) as usize;
    let n_y_labels = (ph / px.per_y_label).clamp(2, 8) as usize;
    let xf = TickFormat::for_axis(x0, x1, n_x_labels);
    let yf = TickFormat::for_axis(y0, y1, n_y_labels);
    let x_fmt = |v: &f64| xf.format(*v);
    let y_fmt = |v: &f64| yf.format(*v);
    chart
        .configure_mesh()
        .x_desc(panel.x_label.as_str())
        .y_desc(panel.y_label.as_str())
        .x_labels(n_x_labels)
        .y_labels(n_y_labels)
        .max_light_lines(2)
        .x_label_formatter(&x_fmt)
        .y_label_formatter(&y_fmt)
        .label_style(font(px.tick))
        .axis_desc_style(font(px.desc))
        .set_all_tick_mark_size(5 * px.k)
        .bold_line_style(BLACK.mix(0.14).stroke_width(px.k))
        .light_line_style(BLACK.mix(0.05).stroke_width(px.k))
        .axis_style(BLACK.stroke_width(px.k))
        .draw()
        .map_err(de)?;

    let rect = Rect { x0, x1, y0, y1 };
    for s in &panel.series {
        let style = ShapeStyle {
            color: rgb(s.color).to_rgba(),
            filled: false,
            stroke_width: s.width * px.k,
        };
        if s.style == LineStyle::Dots {
            let r = (s.width * px.k / 2).max(1) as i32;
            let fill = style.filled();
            let inside =
                s.x.iter()
                    .zip(&s.y)
                    .map(|(&x, &y)| (x, y))
                    .filter(|&(x, y)| (x0..=x1).contains(&x) && (y0..=y1).contains(&y));
            chart
                .draw_series(inside.map(|p| Circle::new(p, r, fill)))
                .map_err(de)?;
            continue;
        }
        for run in finite_runs(&s.x, &s.y) {
            let run = decimate(&run, x0, x1, pw as usize);
            for piece in clip_polyline(&run, &rect) {
                let strokes = if px.split_sharp_turns && style.stroke_width > 1 {
                    split_at_sharp_turns(&piece, pw as f64 / (x1 - x0), ph as f64 / (y1 - y0))
                } else {
                    vec![piece]
                };
                for stroke in strokes {
                    match s.style {
                        LineStyle::Solid => chart.draw_series(LineSeries::new(stroke, style)),
                        LineStyle::Dashed => {
                            chart.draw_series(DashedLineSeries::new(stroke, px.dash, px.gap, style))
                        }
                        LineStyle::Dots => continue, // drawn above
                    }
                    .map_err(de)?;
                }
            }
        }
    }
    // frame the axes
    chart
        .plotting_area()
        .draw(&Rectangle::new(
            [(x0, y0), (x1, y1)],
            BLACK.stroke_width(px.k),
        ))
        .map_err(de)?;
    if !labelled.is_empty() {
        draw_legend(&legend_area, &labelled, px)?;
    }
    Ok(())
}

/// Widen one axis so a data unit spans as many pixels on x as on y.
fn equalise(x0: f64, x1: f64, y0: f64, y1: f64, pw: u32, ph: u32) -> (f64, f64, f64, f64) {
    let ux = (x1 - x0) / pw as f64;
    let uy = (y1 - y0) / ph as f64;
    if ux > uy {
        let (c, half) = (0.5 * (y0 + y1), 0.5 * ux * ph as f64);
        (x0, x1, c - half, c + half)
    } else {
        let (c, half) = (0.5 * (x0 + x1), 0.5 * uy * pw as f64);
        (c - half, c + half, y0, y1)
    }
}

fn legend_width<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    labelled: &[&Series],
    px: Px,
) -> anyhow::Result<u32> {
    let mut widest = 0;
    for s in labelled {
        let (tw, _) = area
            .estimate_text_size(&s.label, &font(px.legend))
            .map_err(de)?;
        widest = widest.max(tw);
    }
    Ok(if labelled.is_empty() {
        0
    } else {
        widest + px.legend_sample as u32 + 40 * px.k
    })
}

fn draw_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    labelled: &[&Series],
    px: Px,
) -> anyhow::Result<()> {
    let (w, _) = area.dim_in_pixel();
    let k = px.k as i32;
    let top = px.margin as i32 + 6 * k;
    let bottom = top + px.legend_row * labelled.len() as i32 + 8 * k;
    area.draw(&Rectangle::new(
        [(2 * k, top - 4 * k), (w as i32 - 6 * k, bottom)],
        BLACK.mix(0.35).stroke_width(px.k),
    ))
    .map_err(de)?;
    for (i, s) in labelled.iter().enumerate() {
        let y = top + 4 * k + px.legend_row / 2 + px.legend_row * i as i32;
        let (xa, xb) = (12 * k, 12 * k + px.legend_sample);
        let style = ShapeStyle {
            color: rgb(s.color).to_rgba(),
            filled: false,
            stroke_width: s.width.max(2) * px.k,
        };
        match s.style {
            LineStyle::Solid => area.draw(&PathElement::new(vec![(xa, y), (xb, y)], style)),
            LineStyle::Dashed => area.draw(&DashedPathElement::new(
                vec![(xa, y), (xb, y)],
                10 * k,
                6 * k,
                style,
            )),
            LineStyle::Dots => area.draw(&Circle::new(
                ((xa + xb) / 2, y),
                (s.width * px.k / 2).max(1) as i32,
                style.filled(),
            )),
        }
        .map_err(de)?;
        let text_style = font(px.legend).pos(Pos::new(HPos::Left, VPos::Center));
        area.draw(&Text::new(s.label.clone(), (xb + 10 * k, y), text_style))
            .map_err(de)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn box_filter_averages_blocks() {
        // 2x2 image of 2x2 blocks: one black block, three white
        let mut big = vec![255u8; 3 * 16];
        for (x, y) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
            for c in 0..3 {
                big[3 * (y * 4 + x) + c] = 0;
            }
        }
        big[3 * (2 * 4 + 2)] = 0; // one red-channel pixel of the last block
        let small = box_downsample(&big, 4, 4, 2);
        assert_eq!(&small[0..3], &[0, 0, 0]);
        assert_eq!(&small[3..6], &[255, 255, 255]);
        assert_eq!(&small[9..12], &[191, 255, 255]); // (0 + 3 * 255) / 4 = 191.25
    }
}
