//! `report.html` of `rotorid analyze`: one self-contained page (no network, no external
//! CSS or JS) rendered from the content of `analysis.json` (the export contract, read
//! here as JSON so the page can never say something the file does not) and the PNG
//! figures, embedded as base64 `data:` URIs. Template `analysis.html`, minijinja with HTML
//! auto-escaping on; only the base64 text (alphabet A-Z a-z 0-9 + / =) is marked safe.

use std::path::Path;

use anyhow::Context;
use base64::Engine;
use minijinja::Environment;
use serde::Serialize;
use serde_json::Value;

use crate::io::identified::{CROSS_ROTOR_FIELDS, ROTOR_FIELDS};
use crate::io::number::format_sig as fmt_sig;
use crate::plot::campbell::with_std;

const TEMPLATE: &str = include_str!("analysis.html");

/// A figure of the page: `STEM.png` is embedded, `STEM.svg` linked.
#[derive(Debug, Clone, PartialEq)]
pub struct ReportFigure {
    /// File stem in the output directory.
    pub stem: &'static str,
    /// Caption.
    pub caption: String,
}

#[derive(Serialize)]
struct RotorRow {
    name: &'static str,
    value: String,
    std: String,
    unit: &'static str,
}

#[derive(Serialize)]
struct CriticalRow {
    n: usize,
    rpm: String,
    whirl: String,
    hz: String,
    zeta: String,
    log_dec: String,
}

#[derive(Serialize)]
struct PeakRow {
    name: String,
    angle: String,
    amplitude: String,
    rpm: String,
}

#[derive(Serialize)]
struct FigureView {
    stem: &'static str,
    caption: String,
    svg: String,
    png_base64: String,
}

#[derive(Serialize)]
struct View {
    title: String,
    generator: String,
    source: String,
    rotor: Vec<RotorRow>,
    uncertainty: &'static str,
    range: String,
    critical: Vec<CriticalRow>,
    stable: bool,
    stability: String,
    peaks: Vec<PeakRow>,
    figures: Vec<FigureView>,
    format_version: u64,
}

fn num(v: &Value) -> Option<f64> {
    v.as_f64()
}

/// `v` in scientific notation with `sig` significant digits.
fn fmt_sci(v: f64, sig: usize) -> String {
    format!("{v:.prec$e}", prec = sig.max(1) - 1)
}

fn text(v: &Value) -> String {
    v.as_str().unwrap_or("-").to_string()
}

/// The page for the analysis `analysis` (anything that serialises to the layout of
/// `analysis.json`), reading `STEM.png` of each of `figures` from `dir`.
pub fn render_report(
    analysis: &impl Serialize,
    dir: &Path,
    figures: &[ReportFigure],
) -> anyhow::Result<String> {
    let a = serde_json::to_value(analysis).context("cannot serialise the analysis")?;
    let std_of = |name: &str| -> String {
        match a["rotor_std"].get(name) {
            None => "-".to_string(),
            Some(Value::Null) => "undetermined".to_string(),
            Some(v) => match num(v) {
                Some(0.0) => "known".to_string(),
                Some(s) => fmt_sci(s, 2),
                None => "-".to_string(),
            },
        }
    };
    let cross = a["model"].as_str() == Some("cross_coupled");
    let rows: &[(&str, &str)] = if cross {
        &CROSS_ROTOR_FIELDS
    } else {
        &ROTOR_FIELDS
    };
    let rotor = rows
        .iter()
        .map(|&(name, unit)| {
            (
                name,
                if unit == "N s^2/m" {
                    "N s\u{b2}/m"
                } else {
                    unit
                },
            )
        })
        .map(|(name, unit)| RotorRow {
            name,
            value: num(&a["rotor"][name]).map_or("-".into(), |v| fmt_sig(v, 7)),
            std: if a["rotor_std"].is_null() {
                "-".into()
            } else {
                std_of(name)
            },
            unit,
        })
        .collect();
    let critical = a["critical_speeds"]
        .as_array()
        .map(|cs| {
            cs.iter()
                .enumerate()
                .map(|(i, c)| CriticalRow {
                    n: i + 1,
                    rpm: num(&c["rpm"]).map_or("-".into(), |v| with_std(v, num(&c["std_rpm"]), "")),
                    whirl: c["whirl"].as_str().unwrap_or("no direction").to_string(),
                    hz: num(&c["frequency_hz"]).map_or("-".into(), |v| format!("{v:.3}")),
                    zeta: num(&c["damping_ratio"]).map_or("-".into(), |v| fmt_sci(v, 3)),
                    log_dec: num(&c["log_dec"]).map_or("-".into(), |v| fmt_sig(v, 4)),
                })
                .collect()
        })
        .unwrap_or_default();
    let s = &a["stability"];
    let stable = s["stable"].as_bool().unwrap_or(true);
    let mut stability = match (num(&s["threshold_rpm"]), num(&s["min_log_dec"])) {
        (Some(t), _) => {
            let whirl = s["threshold_whirl"]
                .as_str()
                .map_or("A".to_string(), |w| format!("The {w}"));
            let at = if s["unstable_at_start"].as_bool() == Some(true) {
                format!("Unstable from the start of the range ({t:.1} rpm)")
            } else {
                format!(
                    "Unstable above the threshold speed {} rpm",
                    with_std(t, num(&s["threshold_rpm_std"]), "")
                )
            };
            let again = num(&s["stable_from_rpm"]).map_or(String::new(), |w| {
                format!(
                    "; stable again from {} rpm",
                    with_std(w, num(&s["stable_from_rpm_std"]), "")
                )
            });
            let cause = if cross {
                "the bearings' cross-coupled coefficients feed that whirl faster than the \
                 damping dissipates it"
            } else {
                "the Jeffcott rotor is stable at every speed when cx and cz are positive: check \
                 the identified damping"
            };
            format!(
                "{at}{again}: {whirl} whirl mode's logarithmic decrement is negative ({cause})."
            )
        }
        (None, Some(d)) => format!(
            "Stable over the whole range. Smallest logarithmic decrement {} ({} mode at {:.0} rpm).",
            fmt_sig(d, 4),
            ["lower", "higher"][s["min_log_dec_mode"].as_u64().unwrap_or(0).min(1) as usize],
            num(&s["min_log_dec_rpm"]).unwrap_or(f64::NAN)
        ),
        (None, None) => "Stable over the whole range.".to_string(),
    };
    let op = &s["operating"];
    if let Some(rpm) = num(&op["rpm"]) {
        stability.push_str(&format!(
            " At the operating speed {rpm:.1} rpm the least damped mode ({} whirl) has \
             logarithmic decrement {}{}.",
            op["whirl"].as_str().unwrap_or("no"),
            num(&op["log_dec"]).map_or("-".into(), |d| match num(&op["log_dec_std"]) {
                Some(sd) if sd > 0.0 => with_std(d, Some(sd), ""),
                _ => fmt_sig(d, 4),
            }),
            if op["stable"].as_bool() == Some(false) {
                ": UNSTABLE"
            } else {
                ""
            }
        ));
    }
    let peaks = a["unbalance_response"]["channels"]
        .as_array()
        .map(|chs| {
            chs.iter()
                .map(|c| PeakRow {
                    name: text(&c["name"]),
                    angle: num(&c["probe_deg"]).map_or("-".into(), |v| format!("{v:.1}\u{b0}")),
                    amplitude: num(&c["peak"]["amplitude_um_pp"])
                        .map_or("-".into(), |v| fmt_sig(v, 4)),
                    rpm: num(&c["peak"]["rpm"]).map_or("-".into(), |v| format!("{v:.1}")),
                })
                .collect()
        })
        .unwrap_or_default();
    let b64 = base64::engine::general_purpose::STANDARD;
    let mut views = Vec::with_capacity(figures.len());
    for f in figures {
        let path = dir.join(format!("{}.png", f.stem));
        let bytes = std::fs::read(&path)
            .with_context(|| format!("cannot read {} to embed it", path.display()))?;
        views.push(FigureView {
            stem: f.stem,
            caption: f.caption.clone(),
            svg: format!("{}.svg", f.stem),
            png_base64: b64.encode(bytes),
        });
    }
    let g = &a["speed_range_rpm"];
    let view = View {
        title: format!("Rotor analysis: {}", text(&a["source"])),
        generator: text(&a["generator"]),
        source: text(&a["source"]),
        rotor,
        uncertainty: if a["rotor_std"].is_null() {
            "No covariance was given: the analysis carries no uncertainty."
        } else {
            "Standard deviations from the identification's covariance; every uncertainty below is propagated from it."
        },
        range: format!(
            "{}-{} rpm",
            num(&g["start"]).unwrap_or(f64::NAN),
            num(&g["stop"]).unwrap_or(f64::NAN)
        ),
        critical,
        stable,
        stability,
        peaks,
        figures: views,
        format_version: a["format_version"].as_u64().unwrap_or(0),
    };
    let mut env = Environment::new();
    env.add_template("analysis.html", TEMPLATE)
        .context("the analysis report template does not parse")?;
    env.get_template("analysis.html")
        .and_then(|t| t.render(&view))
        .context("cannot render report.html")
}
