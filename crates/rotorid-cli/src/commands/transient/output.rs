//! The files of `rotorid transient`: `bode.csv`, `transient.json` (the export contract,
//! docs/transient.md section 7) and `report.html`.

use std::io::Write as _;
use std::path::Path;

use anyhow::Context as _;
use base64::Engine as _;
use minijinja::Environment;
use serde::Serialize;

use super::{Analysis, Sensor};
use crate::commands::onex::csv_text;
use crate::io::number::format_f64;
use crate::io::{FileMode, Output};

/// Version of the `transient.json` layout.
pub const TRANSIENT_FORMAT_VERSION: u32 = 1;

/// The header of `bode.csv` (fixed: relied on by users' scripts).
pub const BODE_HEADER: &str =
    "speed_rpm,sensor,order,amplitude,phase_lag_deg,re,im,std,raw_re,raw_im";

/// `value ± std` with the digits the standard deviation needs (2 significant digits of
/// it), so a small deviation is never printed as 0.
pub fn pm(value: f64, std: f64) -> String {
    if !(std.is_finite() && std > 0.0) {
        return format!("{value:.4}");
    }
    let d = (1.0 - std.log10().floor()).clamp(0.0, 12.0) as usize;
    format!("{value:.d$} \u{b1} {std:.d$}")
}

/// Phase lag \[deg\] of a vector in \[0, 360).
pub fn lag_deg(v: rotorid::transient::order::C64) -> f64 {
    (-v.arg()).to_degrees().rem_euclid(360.0)
}

/// `dir/bode.csv`, written atomically: one row per point, sensor and order, in the order
/// of the points (time), then sensors, then orders.
pub fn write_bode_csv(dir: &Path, a: &Analysis) -> anyhow::Result<()> {
    let path = dir.join("bode.csv");
    let mut out = Output::create(&path.display().to_string(), FileMode::Atomic)?;
    let mut text = String::with_capacity(1 << 16);
    text.push_str(BODE_HEADER);
    text.push('\n');
    let n = a.sensors.iter().map(|s| s.points.len()).max().unwrap_or(0);
    for i in 0..n {
        for s in &a.sensors {
            let Some(p) = s.points.get(i) else { continue };
            for (o, &order) in s.orders.iter().enumerate() {
                let v = p.comp[o];
                let r = p.raw[o];
                let std = if p.std[o].is_finite() {
                    format_f64(p.std[o])
                } else {
                    String::new()
                };
                text.push_str(&format!(
                    "{},{},{},{},{},{},{},{},{},{}\n",
                    format_f64(p.rpm),
                    csv_text(&s.name),
                    order,
                    format_f64(v.norm()),
                    format_f64(lag_deg(v)),
                    format_f64(v.re),
                    format_f64(v.im),
                    std,
                    format_f64(r.re),
                    format_f64(r.im)
                ));
            }
        }
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

/// A critical in `transient.json`.
#[derive(Debug, Clone, Serialize)]
pub struct CriticalJson {
    /// The sensor.
    pub sensor: String,
    /// The order (1).
    pub order: u32,
    /// Peak speed Nc \[rev/min\].
    pub rpm: f64,
    /// Its standard deviation \[rev/min\].
    pub rpm_std: f64,
    /// Peak amplitude, zero-to-peak \[`unit`\].
    pub amplitude: f64,
    /// Its standard deviation \[`unit`\].
    pub amplitude_std: f64,
    /// `m`.
    pub unit: &'static str,
    /// Phase lag at the peak \[deg\].
    pub phase_lag_deg: f64,
    /// Lower half-power speed \[rev/min\].
    pub n1_rpm: Option<f64>,
    /// Its standard deviation \[rev/min\].
    pub n1_rpm_std: Option<f64>,
    /// Upper half-power speed \[rev/min\].
    pub n2_rpm: Option<f64>,
    /// Its standard deviation \[rev/min\].
    pub n2_rpm_std: Option<f64>,
    /// Nc / (N2 - N1).
    pub amplification_factor: Option<f64>,
    /// Its standard deviation.
    pub amplification_factor_std: Option<f64>,
    /// 1 / (2 AF).
    pub damping_ratio: Option<f64>,
    /// Its standard deviation.
    pub damping_ratio_std: Option<f64>,
    /// The peak's prominence over the noise of that difference.
    pub significance: f64,
    /// Sweep rate at the critical \[rev/min per s\] (raw records).
    pub sweep_rpm_per_s: Option<f64>,
    /// below, inside or above the operating range (with `--operating-rpm`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub position: Option<&'static str>,
    /// Actual separation margin \[%\] (with `--operating-rpm`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub separation_margin_pct: Option<f64>,
    /// API 684's required margin \[%\] (with `--operating-rpm`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub required_margin_pct: Option<f64>,
    /// Whether the margin is met (with `--operating-rpm`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub margin_ok: Option<bool>,
}

/// A slow-roll vector in `transient.json`.
#[derive(Debug, Clone, Serialize)]
pub struct RunoutJson {
    /// The order.
    pub order: u32,
    /// Re \[m\].
    pub re: f64,
    /// Im \[m\].
    pub im: f64,
    /// Standard deviation of each of re and im \[m\].
    pub std: f64,
    /// Amplitude, zero-to-peak \[m\].
    pub amplitude: f64,
    /// Phase lag \[deg\].
    pub phase_lag_deg: f64,
}

/// A sensor in `transient.json`.
#[derive(Debug, Clone, Serialize)]
pub struct SensorJson {
    /// Its name.
    pub name: String,
    /// The probe's angle from +x towards +z \[deg\] (raw records).
    pub angle_deg: Option<f64>,
    /// Points (revolutions, bins or table rows).
    pub points: usize,
    /// Where the runout came from (a description), when compensated.
    pub slow_roll: Option<String>,
    /// Its speed range \[rev/min\].
    pub slow_roll_rpm: Option<(f64, f64)>,
    /// The runout vectors.
    pub runout: Vec<RunoutJson>,
}

/// `transient.json`.
#[derive(Debug, Clone, Serialize)]
pub struct TransientJson {
    /// Layout version.
    pub format_version: u32,
    /// `rotorid transient` and the version.
    pub generator: String,
    /// The inputs.
    pub sources: Vec<String>,
    /// run_up, coast_down or mixed.
    pub direction: &'static str,
    /// Speed range of the points \[rev/min\].
    pub speed_rpm: (f64, f64),
    /// The orders tracked.
    pub orders: Vec<u32>,
    /// Bin width \[rev/min\], when binned.
    pub bin_rpm: Option<f64>,
    /// The operating range \[rev/min\], when given.
    pub operating_rpm: Option<(f64, f64)>,
    /// The sensors.
    pub sensors: Vec<SensorJson>,
    /// The critical speeds, by sensor then speed.
    pub criticals: Vec<CriticalJson>,
    /// Notes.
    pub notes: Vec<String>,
    /// The figures written (file names).
    pub figures: Vec<String>,
}

/// The sweep rate \[rpm/s\] of `s` near `rpm`: the slope of speed against time over the
/// points within 2 % of it.
fn sweep_rate(s: &Sensor, rpm: f64) -> Option<f64> {
    let near: Vec<(f64, f64)> = s
        .points
        .iter()
        .filter(|p| (p.rpm - rpm).abs() <= 0.02 * rpm)
        .filter_map(|p| p.t.map(|t| (t, p.rpm)))
        .collect();
    if near.len() < 3 {
        return None;
    }
    let n = near.len() as f64;
    let (mt, mr) = near
        .iter()
        .fold((0.0, 0.0), |(a, b), (t, r)| (a + t / n, b + r / n));
    let (sxy, sxx) = near.iter().fold((0.0, 0.0), |(a, b), (t, r)| {
        (a + (t - mt) * (r - mr), b + (t - mt) * (t - mt))
    });
    (sxx > 0.0).then(|| sxy / sxx)
}

/// The contents of `transient.json`.
pub fn transient_json(a: &Analysis, figures: &[String]) -> TransientJson {
    let (lo, hi) = a
        .sensors
        .iter()
        .flat_map(|s| s.points.iter().map(|p| p.rpm))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(x, y), v| {
            (x.min(v), y.max(v))
        });
    let mut criticals = Vec::new();
    for s in &a.sensors {
        for (c, m) in &s.criticals {
            criticals.push(CriticalJson {
                sensor: s.name.clone(),
                order: 1,
                rpm: c.rpm,
                rpm_std: c.rpm_std,
                amplitude: c.amplitude,
                amplitude_std: c.amplitude_std,
                unit: "m",
                phase_lag_deg: c.phase_lag_deg,
                n1_rpm: c.n1_rpm,
                n1_rpm_std: c.n1_std,
                n2_rpm: c.n2_rpm,
                n2_rpm_std: c.n2_std,
                amplification_factor: c.amplification_factor,
                amplification_factor_std: c.amplification_factor_std,
                damping_ratio: c.damping_ratio,
                damping_ratio_std: c.damping_ratio_std,
                significance: c.significance,
                sweep_rpm_per_s: sweep_rate(s, c.rpm),
                position: m.as_ref().map(|m| super::position_name(m.position)),
                separation_margin_pct: m.as_ref().map(|m| m.separation_pct),
                required_margin_pct: m.as_ref().map(|m| m.required_pct),
                margin_ok: m.as_ref().map(|m| m.ok),
            });
        }
    }
    let sensors = a
        .sensors
        .iter()
        .map(|s| SensorJson {
            name: s.name.clone(),
            angle_deg: s.angle_deg,
            points: s.points.len(),
            slow_roll: s
                .slow_roll
                .as_ref()
                .map(|sr| rotorid::transient::slow_roll::describe(&sr.source)),
            slow_roll_rpm: s.slow_roll.as_ref().map(|sr| sr.speed_rpm),
            runout: s
                .slow_roll
                .as_ref()
                .map(|sr| {
                    sr.orders
                        .iter()
                        .zip(sr.vectors.iter().zip(&sr.std))
                        .map(|(&order, (v, &std))| RunoutJson {
                            order,
                            re: v.re,
                            im: v.im,
                            std,
                            amplitude: v.norm(),
                            phase_lag_deg: lag_deg(*v),
                        })
                        .collect()
                })
                .unwrap_or_default(),
        })
        .collect();
    TransientJson {
        format_version: TRANSIENT_FORMAT_VERSION,
        generator: format!("rotorid transient {}", env!("CARGO_PKG_VERSION")),
        sources: a.sources.clone(),
        direction: a.direction,
        speed_rpm: (lo, hi),
        orders: a.sensors[0].orders.clone(),
        bin_rpm: a.bin_rpm,
        operating_rpm: a.operating_rpm,
        sensors,
        criticals,
        notes: a.notes.clone(),
        figures: figures.to_vec(),
    }
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
            title => format!("Transient ({}) \u{2014} {}", json.direction.replace('_', "-"), json.sources.join(", ")),
            generator => &json.generator,
            sources => json.sources.join(", "),
            speed => format!("{:.0} to {:.0} rpm", json.speed_rpm.0, json.speed_rpm.1),
            operating => json.operating_rpm.map(|(a, b)| format!("{a:.0} to {b:.0} rpm")),
            criticals => rows,
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
