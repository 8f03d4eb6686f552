//! The export contract of a transient analysis (docs/transient.md section 8):
//! `transient.json` as one serde model ([`TransientJson`], the same document from the
//! `rotorid transient` command and from the Python package's `to_dict()`), and the rows of
//! `bode.csv` ([`bode_rows`], in the file's order, in SI). Writing the files is the
//! caller's.
//!
//! A new section of `transient.json` is a new field of [`TransientJson`] (after
//! `criticals`, before `notes`, so that the documented order stays: sources, settings,
//! sensors, results, notes, figures) filled in [`transient_json`]; a new field changes no
//! existing one and keeps [`TRANSIENT_FORMAT_VERSION`].

use serde::Serialize;

use super::analysis::{Analysis, Direction};
use super::critical::Position;
use super::modes::{Candidate, FitBasis, FittedMode};
use super::order::C64;
use super::slow_roll;

/// Version of the `transient.json` layout.
pub const TRANSIENT_FORMAT_VERSION: u32 = 1;

/// The columns of `bode.csv` (fixed: relied on by users' scripts).
pub const BODE_COLUMNS: [&str; 10] = [
    "speed_rpm",
    "sensor",
    "order",
    "amplitude",
    "phase_lag_deg",
    "re",
    "im",
    "std",
    "raw_re",
    "raw_im",
];

/// Phase lag \[deg\] of a vector in \[0, 360) (docs/transient.md section 1: `V = A e^{-i lag}`).
pub fn lag_deg(v: C64) -> f64 {
    (-v.arg()).to_degrees().rem_euclid(360.0)
}

/// A critical in `transient.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
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
    /// Nc / (N2 - N1) \[-\].
    pub amplification_factor: Option<f64>,
    /// Its standard deviation \[-\].
    pub amplification_factor_std: Option<f64>,
    /// 1 / (2 AF) \[-\].
    pub damping_ratio: Option<f64>,
    /// Its standard deviation \[-\].
    pub damping_ratio_std: Option<f64>,
    /// The peak's prominence over the noise of that difference \[-\].
    pub significance: f64,
    /// Sweep rate at the critical \[rev/min per s\] (raw records).
    pub sweep_rpm_per_s: Option<f64>,
    /// below, inside or above the operating range (with an operating range).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub position: Option<Position>,
    /// Actual separation margin \[%\] (with an operating range).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub separation_margin_pct: Option<f64>,
    /// API 684's required margin \[%\] (with an operating range).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub required_margin_pct: Option<f64>,
    /// Whether the margin is met (with an operating range).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub margin_ok: Option<bool>,
}

/// A slow-roll vector in `transient.json`.
#[derive(Debug, Clone, PartialEq, Serialize)]
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
#[derive(Debug, Clone, PartialEq, Serialize)]
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
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TransientJson {
    /// Layout version.
    pub format_version: u32,
    /// `rotorid transient` and the version.
    pub generator: String,
    /// The inputs.
    pub sources: Vec<String>,
    /// run_up, coast_down or mixed.
    pub direction: Direction,
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
    /// The modes fitted to the 1X vectors, by speed (empty without a fit).
    pub modes: Vec<FittedMode>,
    /// How the modes were fitted (None without a fit).
    pub mode_fit: Option<ModeFitJson>,
    /// Notes.
    pub notes: Vec<String>,
    /// The figures written (file names; empty where none are drawn).
    pub figures: Vec<String>,
}

/// How the modes in `transient.json` were fitted (docs/transient.md section 6).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ModeFitJson {
    /// `transient` (along the measured speed: free of the sweep's bias) or
    /// `steady_state` (a table without times).
    pub basis: FitBasis,
    /// The sensors fitted.
    pub sensors: Vec<String>,
    /// The speeds fitted \[rev/min\].
    pub window_rpm: (f64, f64),
    /// Real data N and unknowns p.
    pub data: usize,
    /// Unknowns p.
    pub unknowns: usize,
    /// sqrt(S / (N - p)): the residual's level against the vectors' noise (about 1 when
    /// the model explains them; null when their stds are unknown).
    pub noise_ratio: Option<f64>,
    /// Per sensor, the Ljung-Box p-value of its residuals (the smaller of re and im).
    pub ljung_box_p: Vec<f64>,
    /// False when the residuals show what the model misses.
    pub adequate: bool,
    /// Whether the iteration converged.
    pub converged: bool,
    /// Each number of modes tried, with its BIC (the least chosen).
    pub candidates: Vec<Candidate>,
}

/// The mode fit of `a` for `transient.json`.
pub fn mode_fit_json(a: &Analysis) -> Option<ModeFitJson> {
    a.modes.as_ref().map(|m| ModeFitJson {
        basis: m.fit.basis,
        sensors: m
            .sensors
            .iter()
            .map(|&k| a.sensors[k].name.clone())
            .collect(),
        window_rpm: m.fit.window_rpm,
        data: m.fit.data,
        unknowns: m.fit.unknowns,
        noise_ratio: m.fit.noise_ratio.is_finite().then_some(m.fit.noise_ratio),
        ljung_box_p: m.fit.ljung_box_p.clone(),
        adequate: m.fit.adequate,
        converged: m.fit.converged,
        candidates: m.fit.candidates.clone(),
    })
}

/// The critical rows of `a`, by sensor then speed.
pub fn critical_rows(a: &Analysis) -> Vec<CriticalJson> {
    let mut out = Vec::new();
    for s in &a.sensors {
        for sc in &s.criticals {
            let (c, m) = (&sc.critical, &sc.margin);
            out.push(CriticalJson {
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
                sweep_rpm_per_s: s.sweep_rate(c.rpm),
                position: m.as_ref().map(|m| m.position),
                separation_margin_pct: m.as_ref().map(|m| m.separation_pct),
                required_margin_pct: m.as_ref().map(|m| m.required_pct),
                margin_ok: m.as_ref().map(|m| m.ok),
            });
        }
    }
    out
}

/// The contents of `transient.json` of `a`, with the names of the figures drawn.
pub fn transient_json(a: &Analysis, figures: &[String]) -> TransientJson {
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
                .map(|sr| slow_roll::describe(&sr.source)),
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
        speed_rpm: a.speed_range(),
        orders: a.sensors[0].orders.clone(),
        bin_rpm: a.bin_rpm,
        operating_rpm: a.operating_rpm,
        sensors,
        criticals: critical_rows(a),
        modes: a
            .modes
            .as_ref()
            .map(|m| m.fit.modes.clone())
            .unwrap_or_default(),
        mode_fit: mode_fit_json(a),
        notes: a.notes.clone(),
        figures: figures.to_vec(),
    }
}

/// One row of `bode.csv`, in SI.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodeRow<'a> {
    /// Speed of the revolution or bin \[rev/min\].
    pub speed_rpm: f64,
    /// The sensor.
    pub sensor: &'a str,
    /// n of nX.
    pub order: u32,
    /// The compensated vector \[m\], zero-to-peak (amplitude |V|, phase lag [`lag_deg`]).
    pub vector: C64,
    /// Standard deviation of each of re and im \[m\]; NaN when unknown (an empty cell).
    pub std: f64,
    /// The vector as measured \[m\].
    pub raw: C64,
}

/// The rows of `bode.csv`: one per point, sensor and order, in the order of the points
/// (time), then sensors, then orders.
pub fn bode_rows(a: &Analysis) -> impl Iterator<Item = BodeRow<'_>> + '_ {
    let n = a.sensors.iter().map(|s| s.points.len()).max().unwrap_or(0);
    (0..n).flat_map(move |i| {
        a.sensors.iter().flat_map(move |s| {
            s.points.get(i).into_iter().flat_map(move |p| {
                s.orders.iter().enumerate().map(move |(o, &order)| BodeRow {
                    speed_rpm: p.rpm,
                    sensor: &s.name,
                    order,
                    vector: p.comp[o],
                    std: p.std[o],
                    raw: p.raw[o],
                })
            })
        })
    })
}

#[cfg(test)]
mod tests {
    use super::super::analysis::{analyse_table, Settings, TableRow};
    use super::*;

    #[test]
    fn lag_is_minus_the_argument_in_0_360() {
        assert_eq!(lag_deg(C64::new(1.0, 0.0)), 0.0);
        assert!((lag_deg(C64::new(0.0, -1.0)) - 90.0).abs() < 1e-12);
        assert!((lag_deg(C64::new(0.0, 1.0)) - 270.0).abs() < 1e-12);
    }

    fn two_sensor_table() -> Analysis {
        let rows = (0..40)
            .flat_map(|i| {
                let rpm = 1000.0 + 50.0 * f64::from(i);
                ["a", "b"].map(|s| TableRow {
                    speed_rpm: rpm,
                    sensor: s.into(),
                    re: 1e-6 * rpm,
                    im: if s == "a" { 0.0 } else { -1e-3 },
                    std: None,
                })
            })
            .collect();
        analyse_table("t.csv", rows, &Settings::default()).unwrap()
    }

    #[test]
    fn bode_rows_go_by_point_then_sensor() {
        let a = two_sensor_table();
        let rows: Vec<BodeRow<'_>> = bode_rows(&a).collect();
        assert_eq!(rows.len(), 80);
        assert_eq!((rows[0].sensor, rows[1].sensor), ("a", "b"));
        assert_eq!(rows[2].speed_rpm, 1050.0);
        assert!(rows[0].std.is_nan());
    }

    #[test]
    fn json_fields_keep_their_order_and_skip_margins_without_a_range() {
        let a = two_sensor_table();
        let j = serde_json::to_string(&transient_json(&a, &[])).unwrap();
        let keys = [
            "\"format_version\":1",
            "\"generator\"",
            "\"sources\":[\"t.csv\"]",
            "\"direction\":\"run_up\"",
            "\"speed_rpm\":[1000.0,2950.0]",
            "\"orders\":[1]",
            "\"bin_rpm\":null",
            "\"operating_rpm\":null",
            "\"sensors\"",
            "\"criticals\"",
            "\"modes\"",
            "\"mode_fit\"",
            "\"notes\"",
            "\"figures\":[]",
        ];
        let mut at = 0;
        for k in keys {
            let i = j[at..]
                .find(k)
                .unwrap_or_else(|| panic!("{k} not after {at} in {j}"));
            at += i;
        }
        assert!(!j.contains("margin_ok"));
    }
}
