//! The files of `rotorid transient`: `bode.csv`, `transient.json` (the export contract,
//! docs/transient.md section 8, whose model and rows are the library's
//! `rotorid::transient::report`) and `report.html`.

use std::io::Write as _;
use std::path::Path;

use anyhow::Context as _;
use base64::Engine as _;
use minijinja::Environment;
use serde::Serialize;

use rotorid::transient::analysis::Analysis;
use rotorid::transient::report::{bode_rows, lag_deg, TransientJson, BODE_COLUMNS};

use crate::commands::onex::csv_text;
use crate::io::number::format_f64;
use crate::io::{FileMode, Output};

/// `value ± std` with the digits the standard deviation needs (2 significant digits of
/// it), so a small deviation is never printed as 0.
pub fn pm(value: f64, std: f64) -> String {
    if !(std.is_finite() && std > 0.0) {
        return format!("{value:.4}");
    }
    let d = (1.0 - std.log10().floor()).clamp(0.0, 12.0) as usize;
    format!("{value:.d$} \u{b1} {std:.d$}")
}

/// `dir/bode.csv`, written atomically: one row per point, sensor and order, in the order
/// of the points (time), then sensors, then orders.
pub fn write_bode_csv(dir: &Path, a: &Analysis) -> anyhow::Result<()> {
    let path = dir.join("bode.csv");
    let mut out = Output::create(&path.display().to_string(), FileMode::Atomic)?;
    let mut text = String::with_capacity(1 << 16);
    text.push_str(&BODE_COLUMNS.join(","));
    text.push('\n');
    for r in bode_rows(a) {
        let std = if r.std.is_finite() {
            format_f64(r.std)
        } else {
            String::new()
        };
        let v = r.vector;
        text.push_str(&format!(
            "{},{},{},{},{},{},{},{},{},{}\n",
            format_f64(r.speed_rpm),
            csv_text(r.sensor),
            r.order,
            format_f64(v.norm()),
            format_f64(lag_deg(v)),
            format_f64(v.re),
            format_f64(v.im),
            std,
            format_f64(r.raw.re),
            format_f64(r.raw.im)
        ));
        if text.len() > 1 << 20 {
            out.write_all(text.as_bytes())
                .with_context(|| format!("cannot write {}", path.display()))?;
            text.clear();
        }
    }
    out.write_all(text.as_bytes())
        .with_context(|| format!("cannot write {}", path.display()))?;
    out.commit()
}

/// `json` as `dir/transient.json` (pretty, atomically).
pub fn write_json(dir: &Path, json: &TransientJson) -> anyhow::Result<()> {
    let path = dir.join("transient.json");
    let mut out = Output::create(&path.display().to_string(), FileMode::Atomic)?;
    serde_json::to_writer_pretty(&mut out, json)
        .with_context(|| format!("cannot write {}", path.display()))?;
    out.write_all(b"\n")?;
    out.commit()
}

const TEMPLATE: &str = include_str!("transient.html");

#[derive(Serialize)]
struct CriticalRow {
    sensor: String,
    rpm: String,
    amplitude: String,
    lag: String,
    n1: String,
    n2: String,
    af: String,
    zeta: String,
    sweep: String,
    margin: String,
    required: String,
    ok: String,
}

#[derive(Serialize)]
struct FigureView {
    stem: String,
    caption: String,
    png_base64: String,
}

/// A fitted mode in the report.
#[derive(Serialize)]
struct ModeRow {
    rpm: String,
    zeta: String,
    decrement: String,
}

fn opt_pm(v: Option<f64>, s: Option<f64>) -> String {
    match (v, s) {
        (Some(v), Some(s)) => pm(v, s),
        (Some(v), None) => format!("{v:.1}"),
        _ => "\u{2014}".into(),
    }
}

/// `dir/report.html` from `json` and the PNG figures `figures` (stem, caption) in `dir`.
pub fn write_report(
    dir: &Path,
    json: &TransientJson,
    figures: &[(String, String)],
) -> anyhow::Result<()> {
    let rows: Vec<CriticalRow> = json
        .criticals
        .iter()
        .map(|c| CriticalRow {
            sensor: c.sensor.clone(),
            rpm: pm(c.rpm, c.rpm_std),
            amplitude: pm(2e6 * c.amplitude, 2e6 * c.amplitude_std),
            lag: format!("{:.0}", c.phase_lag_deg),
            n1: opt_pm(c.n1_rpm, c.n1_rpm_std),
            n2: opt_pm(c.n2_rpm, c.n2_rpm_std),
            af: opt_pm(c.amplification_factor, c.amplification_factor_std),
            zeta: opt_pm(c.damping_ratio, c.damping_ratio_std),
            sweep: c
                .sweep_rpm_per_s
                .map_or("\u{2014}".into(), |s| format!("{s:.1}")),
            margin: c
                .separation_margin_pct
                .map_or("\u{2014}".into(), |m| format!("{m:.1}")),
            required: c
                .required_margin_pct
                .map_or("\u{2014}".into(), |m| format!("{m:.1}")),
            ok: c.margin_ok.map_or(String::new(), |ok| {
                if ok { "met" } else { "NOT MET" }.into()
            }),
        })
        .collect();
    let modes: Vec<ModeRow> = json
        .modes
        .iter()
        .map(|m| ModeRow {
            rpm: pm(m.rpm, m.rpm_std),
            zeta: pm(m.damping_ratio, m.damping_ratio_std),
            decrement: opt_pm(m.log_decrement, m.log_decrement_std),
        })
        .collect();
    let mode_fit = json.mode_fit.as_ref().map(|f| {
        format!(
            "{} of {} ({} data, {} unknowns), {:.0} to {:.0} rpm; residual level {} of the noise, whiteness p {}: {}{}",
            match f.basis {
                rotorid::transient::FitBasis::Transient => "the transient response along the measured speed fitted to the compensated 1X",
                rotorid::transient::FitBasis::SteadyState => "the steady-state response fitted to the table's 1X (no times: the sweep's bias is in these modes)",
            },
            f.sensors.join(", "),
            f.data,
            f.unknowns,
            f.window_rpm.0,
            f.window_rpm.1,
            f.noise_ratio.map_or("\u{2014}".into(), |r| format!("{r:.2}")),
            f.ljung_box_p.iter().map(|p| format!("{p:.2}")).collect::<Vec<_>>().join(", "),
            if f.adequate { "adequate" } else { "NOT adequate: the residuals show what the model misses, the standard deviations understate the error" },
            if f.converged { "" } else { "; the iteration did not converge" },
        )
    });
    let mut views = Vec::new();
    for (stem, caption) in figures {
        let png = dir.join(format!("{stem}.png"));
        let bytes =
            std::fs::read(&png).with_context(|| format!("cannot read {}", png.display()))?;
        views.push(FigureView {
            stem: stem.clone(),
            caption: caption.clone(),
            png_base64: base64::engine::general_purpose::STANDARD.encode(bytes),
        });
    }
    let mut env = Environment::new();
    env.set_auto_escape_callback(|_| minijinja::AutoEscape::Html);
    env.add_template("transient.html", TEMPLATE)
        .context("the report template")?;
    let html = env
        .get_template("transient.html")
        .context("the report template")?
        .render(minijinja::context! {
            title => format!("Transient ({}) \u{2014} {}", json.direction.as_str().replace('_', "-"), json.sources.join(", ")),
            generator => &json.generator,
            sources => json.sources.join(", "),
            speed => format!("{:.0} to {:.0} rpm", json.speed_rpm.0, json.speed_rpm.1),
            operating => json.operating_rpm.map(|(a, b)| format!("{a:.0} to {b:.0} rpm")),
            criticals => rows,
            modes => modes,
            mode_fit => mode_fit,
            mode_adequate => json.mode_fit.as_ref().is_none_or(|f| f.adequate),
            sensors => &json.sensors,
            notes => &json.notes,
            figures => views,
            format_version => json.format_version,
        })
        .context("rendering the report")?;
    let path = dir.join("report.html");
    let mut out = Output::create(&path.display().to_string(), FileMode::Atomic)?;
    out.write_all(html.as_bytes())
        .with_context(|| format!("cannot write {}", path.display()))?;
    out.commit()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plus_minus_keeps_the_digits_of_the_deviation() {
        assert_eq!(pm(0.0794, 0.00003), "0.079400 \u{b1} 0.000030");
        assert_eq!(pm(6012.3, 2.71), "6012.3 \u{b1} 2.7");
        assert_eq!(pm(18.234, 0.61), "18.23 \u{b1} 0.61");
        assert_eq!(pm(5.0, f64::NAN), "5.0000");
    }
}
