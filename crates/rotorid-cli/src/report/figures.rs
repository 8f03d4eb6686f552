//! The paper's figures 2-9 rebuilt from the runs, each in two views:
//!
//! - `figN`: the paper's window t = 0.10-0.23 s (the paper: "solo se muestran los
//!   resultados para un tiempo de 0.1 a 0.23 segundos");
//! - `figN_full`: the whole record, t = 0 to the duration.
//!
//! | figure | paper content | panels |
//! |---|---|---|
//! | 2 / 6 | response x(t), z(t) at 1200 rpm / on the ramp | (a) x, (b) z; Newmark (the paper's data) and exact |
//! | 3-5 / 7-9 | m, c, k vs time | (a) paper's setting, (b) ours; estimates from x and z solid, true value dashed |
//!
//! The two panels of an identification figure share one y-scale, so the settings compare
//! at a glance. Estimates at ill-conditioned instants (rcond < rcond_min) are drawn but
//! ignored when scaling y, and y never extends beyond +-50 % of the true value.

use rotorid::Parameter;

use super::experiment::{Case, Run, Setting};
use super::results::{index, symbol, true_value, well_conditioned};
use crate::plot::scale::si_prefix;
use crate::plot::{palette, Figure, Panel, Series};

/// The paper's zoom window [s].
pub const PAPER_WINDOW: (f64, f64) = (0.10, 0.23);
/// Auto-scaled y never extends beyond true value * (1 -+ this).
const Y_BAND: f64 = 0.5;
/// Auto-scaled y never spans less than this fraction of the true value.
const MIN_SPAN: f64 = 2e-3;

/// A figure to write, its file stem and a caption for the report.
#[derive(Debug, Clone)]
pub struct PaperFigure {
    /// File stem: `fig3` or `fig3_full`.
    pub stem: String,
    /// The paper's figure number (2-9).
    pub number: u32,
    /// Whole record (true) or the paper's window (false).
    pub full: bool,
    /// One-paragraph caption.
    pub caption: String,
    /// The figure.
    pub figure: Figure,
}

/// All figures of `case` from its runs in both settings (`paper` then `ours`).
pub fn case_figures(case: Case, paper: &Run, ours: &Run) -> Vec<PaperFigure> {
    let first = match case {
        Case::Constant => 2,
        Case::Ramp => 6,
    };
    let mut out = Vec::new();
    for full in [false, true] {
        out.push(response_figure(first, full, paper, ours));
        for (i, sym) in ["m", "c", "k"].into_iter().enumerate() {
            out.push(parameter_figure(
                first + 1 + i as u32,
                full,
                sym,
                paper,
                ours,
            ));
        }
    }
    out.sort_by_key(|f| (f.number, f.full));
    out
}

fn stem(number: u32, full: bool) -> String {
    if full {
        format!("fig{number}_full")
    } else {
        format!("fig{number}")
    }
}

fn window_text(full: bool, duration: f64) -> String {
    if full {
        format!("t = 0-{duration} s (whole record)")
    } else {
        format!(
            "t = {:.2}-{:.2} s (paper's window)",
            PAPER_WINDOW.0, PAPER_WINDOW.1
        )
    }
}

fn apply_window(p: Panel, full: bool, duration: f64) -> Panel {
    if full {
        p.with_x_range(0.0, duration)
    } else {
        p.with_x_range(PAPER_WINDOW.0, PAPER_WINDOW.1)
    }
}

/// Figure 2 or 6: the response in x and z, Newmark (paper's data) under exact.
fn response_figure(number: u32, full: bool, paper: &Run, ours: &Run) -> PaperFigure {
    let duration = ours.scenario.sampling.duration();
    let (rp, ro) = (&paper.response, &ours.response);
    let peak =
        rp.x.iter()
            .chain(&rp.z)
            .chain(&ro.x)
            .chain(&ro.z)
            .fold(0.0f64, |m, v| m.max(v.abs()));
    let (factor, prefix) = si_prefix(peak);
    let scaled = |v: &[f64]| v.iter().map(|y| y * factor).collect::<Vec<f64>>();
    let panel = |label: &str, name: &str, newmark: &[f64], exact: &[f64]| {
        let p = Panel::new(label, "time t (s)", format!("{name} ({prefix}m)")).with_series(vec![
            Series::solid(
                format!("{name}, Newmark (paper's data)"),
                rp.t.clone(),
                scaled(newmark),
                palette::VERMILLION,
            )
            .with_width(3),
            Series::solid(
                format!("{name}, exact"),
                ro.t.clone(),
                scaled(exact),
                palette::BLACK,
            )
            .with_width(1),
        ]);
        apply_window(p, full, duration)
    };
    let case = ours.case;
    let figure = Figure::new(
        format!(
            "Fig. {number}: response, {}, {}",
            case.describe(),
            window_text(full, duration)
        ),
        vec![
            panel("(a) horizontal direction x", "x", &rp.x, &ro.x),
            panel("(b) vertical direction z", "z", &rp.z, &ro.z),
        ],
    );
    PaperFigure {
        stem: stem(number, full),
        number,
        full,
        caption: format!(
            "Response of the table1 rotor, {}: (a) x(t), (b) z(t); {}. Thick: the paper's \
             data (average-acceleration Newmark, dt = 0.1 ms); thin black: the exact response.",
            case.describe(),
            window_text(full, duration)
        ),
        figure,
    }
}

fn quantity(sym: &str) -> (&'static str, &'static str) {
    match sym {
        "m" => ("mass", "kg"),
        "c" => ("damping", "N s/m"),
        _ => ("stiffness", "N/m"),
    }
}

/// Figures 3-5 or 7-9: one parameter's estimates against time in both settings.
fn parameter_figure(number: u32, full: bool, sym: &str, paper: &Run, ours: &Run) -> PaperFigure {
    let duration = ours.scenario.sampling.duration();
    let (px, pz) = match sym {
        "m" => (Parameter::MX, Parameter::MZ),
        "c" => (Parameter::Cx, Parameter::Cz),
        _ => (Parameter::Kx, Parameter::Kz),
    };
    debug_assert_eq!(symbol(px), sym);
    let (tx, tz) = (true_value(ours, px), true_value(ours, pz));
    let (name, unit) = quantity(sym);
    let panel = |run: &Run, caption: String| {
        let t: Vec<f64> = run.estimates.iter().map(|e| e.t).collect();
        let values = |p: Parameter| {
            run.estimates
                .iter()
                .map(|e| e.values()[index(p)])
                .collect::<Vec<f64>>()
        };
        let (sx, sz) = if sym == "m" {
            ("m from x".to_string(), "m from z".to_string())
        } else {
            (format!("{sym}x estimate"), format!("{sym}z estimate"))
        };
        let mut series = vec![
            Series::solid(sx, t.clone(), values(px), palette::BLUE)
                .with_scale_mask(well_conditioned(run, px)),
            Series::solid(sz, t.clone(), values(pz), palette::VERMILLION)
                .with_scale_mask(well_conditioned(run, pz)),
        ];
        if tx == tz {
            let label = if sym == "m" {
                "true m".to_string()
            } else {
                format!("true {sym}x = {sym}z")
            };
            series.push(Series::level(label, 0.0, duration, tx, palette::BLACK));
        } else {
            series.push(Series::level(
                format!("true {sym}x"),
                0.0,
                duration,
                tx,
                palette::BLACK,
            ));
            series.push(Series::level(
                format!("true {sym}z"),
                0.0,
                duration,
                tz,
                palette::GREY,
            ));
        }
        let (lo, hi) = (tx.min(tz), tx.max(tz));
        let p = Panel::new(caption, "time t (s)", format!("{name} {sym} ({unit})"))
            .with_series(series)
            .with_y_limits(lo - Y_BAND * lo.abs(), hi + Y_BAND * hi.abs())
            .with_min_y_span(MIN_SPAN * hi.abs());
        apply_window(p, full, duration)
    };
    let case = ours.case;
    let figure = Figure::new(
        format!(
            "Fig. {number}: identified {name} {sym}, {}, {}",
            case.describe(),
            window_text(full, duration)
        ),
        vec![
            panel(paper, format!("(a) {}", Setting::Paper.describe())),
            panel(ours, format!("(b) {}", Setting::Ours.describe())),
        ],
    )
    .share_y();
    PaperFigure {
        stem: stem(number, full),
        number,
        full,
        caption: format!(
            "Identified {name} {sym} against time, {}; {}. Solid: estimates from the x and z \
             equations; dashed: true value. (a) the paper's setting (Newmark data, trapezoid \
             integrals); (b) ours (exact data, {} integrals). Both panels share one y-scale; \
             estimates at ill-conditioned instants (rcond < {:e}) are drawn but do not set the scale.",
            case.describe(),
            window_text(full, duration),
            Setting::Ours.quadrature().name(),
            ours.config.rcond_min,
        ),
        figure,
    }
}
