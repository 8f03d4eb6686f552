//! `report.html`: one self-contained page (no network, no external CSS or JS): the same
//! scenario, settings and tables as `report.md`, and every figure embedded as a base64
//! `data:image/png` URI. Rendered from `template.html` with minijinja (HTML auto-escaping
//! on; only the base64 text, whose alphabet A-Z a-z 0-9 + / = needs no escaping, is marked
//! safe).

use std::path::Path;

use anyhow::Context;
use base64::Engine;
use minijinja::Environment;
use serde::Serialize;

use super::tables::{attribution_tables, case_tables, AttributionTable, CaseTable};
use super::{Report, SettingInfo};

const TEMPLATE: &str = include_str!("template.html");

#[derive(Serialize)]
struct ResponseView {
    case: &'static str,
    peak: String,
    diff: String,
    relative: String,
}

#[derive(Serialize)]
struct FigureView {
    stem: String,
    caption: String,
    png: String,
    svg: String,
    png_base64: String,
}

#[derive(Serialize)]
struct View<'a> {
    title: &'static str,
    generator: &'a str,
    scenario: String,
    settings: &'a [SettingInfo],
    method_note: String,
    tables: Vec<CaseTable>,
    attribution: Vec<AttributionTable>,
    estimate_time: f64,
    responses: Vec<ResponseView>,
    figures: Vec<FigureView>,
    format_version: u32,
}

/// The page for `report`, reading the PNG of every figure from `dir`.
pub fn render(report: &Report, dir: &Path) -> anyhow::Result<String> {
    let b64 = base64::engine::general_purpose::STANDARD;
    let mut figures = Vec::with_capacity(report.figures.len());
    for f in &report.figures {
        let path = dir.join(&f.png);
        let bytes = std::fs::read(&path)
            .with_context(|| format!("cannot read {} to embed it", path.display()))?;
        figures.push(FigureView {
            stem: f.stem.clone(),
            caption: f.caption.clone(),
            png: f.png.clone(),
            svg: f.svg.clone(),
            png_base64: b64.encode(bytes),
        });
    }
    let view = View {
        title: "Barredo et al. (2024), figures 2-9, reproduced by rotorid",
        generator: &report.generator,
        scenario: report.scenario.description(report.scenario.name),
        settings: &report.settings,
        method_note: format!(
            "Estimates are read at t = {} s (the last well-conditioned instant at or before it). \
             Identification time: the instant from which every well-conditioned estimate in the \
             record stays within {} % of the true value. Instants with rcond < {:e} are \
             ill-conditioned, not estimates, and are skipped. Paper: the identification time the \
             paper reports (an upper bound).",
            report.estimate_time,
            report.tolerance * 100.0,
            report.rcond_min
        ),
        tables: case_tables(report),
        attribution: attribution_tables(report),
        estimate_time: report.estimate_time,
        responses: report
            .responses
            .iter()
            .map(|c| ResponseView {
                case: c.case,
                peak: format!("{:.4e}", c.exact_peak),
                diff: format!("{:.4e}", c.max_difference),
                relative: format!("{:.2e}", c.relative),
            })
            .collect(),
        figures,
        format_version: report.format_version,
    };
    let mut env = Environment::new();
    env.add_template("report.html", TEMPLATE)
        .context("the report template does not parse")?;
    env.get_template("report.html")
        .and_then(|t| t.render(&view))
        .context("cannot render report.html")
}
