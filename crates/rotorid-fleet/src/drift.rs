//! Drift alerts: each window's parameters against the machine's baseline.
//!
//! **Baseline.** The mean of the machine's windows numbered 0 .. N-1 (N =
//! [`DriftSettings::baseline_windows`], default 3), per parameter over the windows that
//! determined it; its standard error is the larger of the propagated one,
//! sqrt(sum se_i^2) / n, and the scatter's, sd / sqrt(n) (n >= 2), so a baseline whose
//! windows disagree more than their standard errors say is not trusted beyond its scatter.
//! Or, given per machine, the parameters of an `rotorid identify --summary` file
//! (SUMMARY.json: value and standard error).
//!
//! **Test.** For each parameter determined with a standard error in the window and the
//! baseline, z = (v - b) / sqrt(se_v^2 + se_b^2). A change is *confirmed* when |z| >
//! [`DriftSettings::z_threshold`] (default 5) on two consecutive windows with the same
//! sign; the alert is raised on the second, so a step change is reported within two
//! windows, and a single outlying window (a transient, a bad record) raises nothing. With
//! Gaussian estimates a false alarm needs two independent 5-sigma events (p ~ 3e-13 per
//! parameter and window pair); the test in tests/drift.rs measures the rate on unchanged
//! machines and reports the largest |z| it saw.
//!
//! **Model alerts.** A window whose identification says the model does not explain it
//! (`Finding::ModelInadequate`: its values are withheld, so it has no estimates to test)
//! is remembered; two consecutive such windows raise a [`ModelAlert`] on the later one
//! (one window's verdict was a false alarm in 2 of 2100 records of correct models at 20,
//! 40 and 60 dB, crates/rotorid/tests/it/adequacy.rs; two consecutive ones, ~1e-6), with
//! `Nats-Msg-Id = <ID>/<window>/model`: a rotor that stopped behaving like eq. (1) (a rub,
//! a crack, a loose support) is alerted within two windows.
//!
//! Windows are processed out of order by several workers, so the state (below) lives in
//! the key-value bucket `ROTORID_DRIFT` under the machine's id and is updated by
//! compare-and-set; a window that arrives before the baseline is complete is held and
//! tested when it is. Alerts carry `Nats-Msg-Id = <ID>/<window>/<parameter>`, so a window
//! processed twice alerts once.

use std::collections::BTreeMap;

use rotorid::pipeline::{Finding, Identification};
use serde::{Deserialize, Serialize};

use crate::result::{AlertRecord, ModelAlert, FLEET_SCHEMA, MODEL_INADEQUATE};

/// Windows of z history kept (the newest window number minus this is forgotten).
pub const HISTORY_WINDOWS: u64 = 64;

/// The alert rule (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DriftSettings {
    /// Windows 0 .. N-1 form the baseline (>= 1).
    pub baseline_windows: u64,
    /// |z| above which a window counts as changed (> 0).
    pub z_threshold: f64,
}

impl Default for DriftSettings {
    fn default() -> Self {
        Self {
            baseline_windows: 3,
            z_threshold: 5.0,
        }
    }
}

/// One parameter's value \[SI\] and standard error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Estimate {
    /// The parameter's name (`k_x`, ...).
    pub parameter: String,
    /// Its SI unit.
    pub unit: String,
    /// Value.
    pub value: f64,
    /// Standard error.
    pub std_error: f64,
}

/// The determined parameters of `ident` that have a finite, positive standard error.
pub fn estimates(ident: &Identification) -> Vec<Estimate> {
    ident
        .parameters
        .iter()
        .filter_map(|p| {
            let (v, se) = (p.value?, p.std_error?);
            (p.determined && v.is_finite() && se.is_finite() && se > 0.0).then(|| Estimate {
                parameter: p.parameter.name().to_owned(),
                unit: p.unit.clone(),
                value: v,
                std_error: se,
            })
        })
        .collect()
}

/// A window waiting for the baseline.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Held {
    /// Its t0 \[s\].
    pub t0_s: f64,
    /// Its estimates.
    pub estimates: Vec<Estimate>,
}

/// One window's z per parameter.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Tested {
    /// Its t0 \[s\].
    pub t0_s: f64,
    /// (estimate, z) per parameter tested.
    pub z: Vec<(Estimate, f64)>,
}

/// A machine's drift state (module doc), kept in `ROTORID_DRIFT`.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct DriftState {
    /// Estimates of the baseline windows received so far, by window number.
    pub baseline_windows: BTreeMap<u64, Vec<Estimate>>,
    /// The baseline once complete (or given).
    pub baseline: Option<Vec<Estimate>>,
    /// Windows waiting for the baseline.
    pub held: BTreeMap<u64, Held>,
    /// Recent windows' z.
    pub tested: BTreeMap<u64, Tested>,
    /// Alerts raised (window, parameter), recent ones.
    pub alerted: Vec<(u64, String)>,
    /// The baseline was given (SUMMARY), not formed from windows: every window is tested.
    pub given: bool,
    /// Recent windows the model did not explain, by window number: (t0 \[s\], message).
    #[serde(default)]
    pub inadequate: BTreeMap<u64, (f64, String)>,
    /// Windows a model alert was raised on, recent ones.
    #[serde(default)]
    pub model_alerted: Vec<u64>,
}

/// The `MODEL INADEQUATE` messages of `ident` joined by ` | `, `None` when the model
/// explained the record (or was not judged).
pub fn model_inadequate(ident: &Identification) -> Option<String> {
    let m: Vec<&str> = ident
        .diagnostics
        .iter()
        .filter(|d| matches!(d.finding, Finding::ModelInadequate { .. }))
        .map(|d| d.message.as_str())
        .collect();
    (!m.is_empty()).then(|| m.join(" | "))
}

impl DriftState {
    /// A state whose baseline is the determined parameters of `summary` (an `rotorid
    /// identify --summary` file).
    pub fn from_summary(summary: &Identification) -> Self {
        Self {
            baseline: Some(estimates(summary)),
            given: true,
            ..Self::default()
        }
    }

    /// Take window `window` (t0 `t0_s`, `estimates`; empty when it gave no result) into
    /// the state; returns the alerts it newly confirms (possibly of held windows).
    pub fn observe(
        &mut self,
        machine: &str,
        window: u64,
        t0_s: f64,
        estimates: Vec<Estimate>,
        s: &DriftSettings,
    ) -> Vec<AlertRecord> {
        if !self.given && window < s.baseline_windows {
            // a baseline window delivered again after the baseline is formed changes nothing
            if self.baseline.is_none() {
                self.baseline_windows.insert(window, estimates);
                if self.baseline_windows.len() as u64 >= s.baseline_windows {
                    self.baseline = Some(combine(&self.baseline_windows));
                    for (w, h) in std::mem::take(&mut self.held) {
                        self.test(w, h.t0_s, h.estimates);
                    }
                }
            }
        } else if self.baseline.is_some() {
            self.test(window, t0_s, estimates);
        } else {
            self.held.insert(window, Held { t0_s, estimates });
        }
        self.prune();
        self.confirm(machine, s)
    }

    /// Take window `window`'s model verdict (`inadequate`: its `MODEL INADEQUATE`
    /// messages, see [`model_inadequate`]; `None` when the model explained it or it gave no
    /// result); returns the model alert it newly confirms (module doc).
    pub fn observe_model(
        &mut self,
        machine: &str,
        window: u64,
        t0_s: f64,
        inadequate: Option<String>,
    ) -> Vec<ModelAlert> {
        let Some(message) = inadequate else {
            return Vec::new();
        };
        self.inadequate.insert(window, (t0_s, message));
        self.prune();
        // the pairs this window completes, with the window before or after it
        let mut alerts = Vec::new();
        for w in [window, window + 1] {
            let (Some(prev), Some((t0, msg))) = (
                w.checked_sub(1).filter(|p| self.inadequate.contains_key(p)),
                self.inadequate.get(&w),
            ) else {
                continue;
            };
            if self.model_alerted.contains(&w) {
                continue;
            }
            self.model_alerted.push(w);
            alerts.push(ModelAlert {
                fleet_schema: FLEET_SCHEMA,
                kind: MODEL_INADEQUATE.to_owned(),
                machine: machine.to_owned(),
                window: w,
                t0_s: *t0,
                previous_window: prev,
                message: msg.clone(),
            });
        }
        alerts
    }

    fn test(&mut self, window: u64, t0_s: f64, estimates: Vec<Estimate>) {
        let Some(base) = &self.baseline else { return };
        let z = estimates
            .into_iter()
            .filter_map(|e| {
                let b = base.iter().find(|b| b.parameter == e.parameter)?;
                let z = (e.value - b.value) / e.std_error.hypot(b.std_error);
                z.is_finite().then_some((e, z))
            })
            .collect();
        self.tested.insert(window, Tested { t0_s, z });
    }

    fn prune(&mut self) {
        let newest = [
            self.tested.keys().last(),
            self.held.keys().last(),
            self.inadequate.keys().last(),
        ]
        .into_iter()
        .flatten()
        .max()
        .copied()
        .unwrap_or(0);
        let oldest = newest.saturating_sub(HISTORY_WINDOWS);
        self.tested.retain(|&w, _| w >= oldest);
        self.held.retain(|&w, _| w >= oldest);
        self.alerted.retain(|(w, _)| *w >= oldest);
        self.inadequate.retain(|&w, _| w >= oldest);
        self.model_alerted.retain(|&w| w >= oldest);
    }

    /// Alerts for every pair of consecutive tested windows both over the threshold with the
    /// same sign, not raised before.
    fn confirm(&mut self, machine: &str, s: &DriftSettings) -> Vec<AlertRecord> {
        let Some(base) = self.baseline.clone() else {
            return Vec::new();
        };
        let mut alerts = Vec::new();
        for (&w, t) in &self.tested {
            let Some(prev) = w.checked_sub(1).and_then(|p| self.tested.get(&p)) else {
                continue;
            };
            for (e, z) in &t.z {
                let Some((_, pz)) = prev.z.iter().find(|(p, _)| p.parameter == e.parameter) else {
                    continue;
                };
                let over = |z: f64| z.abs() > s.z_threshold;
                if !(over(*z) && over(*pz) && z.signum() == pz.signum()) {
                    continue;
                }
                let key = (w, e.parameter.clone());
                if self.alerted.contains(&key) {
                    continue;
                }
                let Some(b) = base.iter().find(|b| b.parameter == e.parameter) else {
                    continue;
                };
                alerts.push(AlertRecord {
                    fleet_schema: FLEET_SCHEMA,
                    machine: machine.to_owned(),
                    window: w,
                    t0_s: t.t0_s,
                    parameter: e.parameter.clone(),
                    unit: e.unit.clone(),
                    baseline: b.value,
                    baseline_std_error: b.std_error,
                    value: e.value,
                    std_error: e.std_error,
                    change: e.value - b.value,
                    relative_change: (e.value - b.value) / b.value,
                    z: *z,
                    previous_z: *pz,
                });
            }
        }
        for a in &alerts {
            self.alerted.push((a.window, a.parameter.clone()));
        }
        alerts
    }
}

/// The baseline of the windows' estimates (module doc).
fn combine(windows: &BTreeMap<u64, Vec<Estimate>>) -> Vec<Estimate> {
    let mut by: BTreeMap<&str, Vec<&Estimate>> = BTreeMap::new();
    for e in windows.values().flatten() {
        by.entry(&e.parameter).or_default().push(e);
    }
    by.into_values()
        .map(|es| {
            let n = es.len() as f64;
            let mean = es.iter().map(|e| e.value).sum::<f64>() / n;
            let propagated = es.iter().map(|e| e.std_error.powi(2)).sum::<f64>().sqrt() / n;
            let scatter = if es.len() >= 2 {
                (es.iter().map(|e| (e.value - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
                    / n.sqrt()
            } else {
                0.0
            };
            Estimate {
                parameter: es[0].parameter.clone(),
                unit: es[0].unit.clone(),
                value: mean,
                std_error: propagated.max(scatter),
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn kx(v: f64, se: f64) -> Vec<Estimate> {
        vec![Estimate {
            parameter: "k_x".into(),
            unit: "N/m".into(),
            value: v,
            std_error: se,
        }]
    }

    fn run(values: &[(u64, f64)]) -> Vec<AlertRecord> {
        let s = DriftSettings::default();
        let mut st = DriftState::default();
        let mut out = Vec::new();
        for &(w, v) in values {
            out.extend(st.observe("m1", w, w as f64, kx(v, 1.0), &s));
        }
        out
    }

    #[test]
    fn a_step_alerts_on_its_second_window_once() {
        let mut v: Vec<(u64, f64)> = (0..10).map(|w| (w, 100.0 + (w % 2) as f64)).collect();
        for (w, x) in v.iter_mut().skip(5) {
            *x -= 20.0;
            let _ = w;
        }
        let a = run(&v);
        assert_eq!(a.len(), 5 - 1, "{a:?}"); // windows 6..9 each confirm with the one before
        assert_eq!(a[0].window, 6);
        assert!(a[0].z < -5.0 && a[0].previous_z < -5.0);
        assert!((a[0].baseline - 100.0 - 1.0 / 3.0).abs() < 1e-12);
    }

    #[test]
    fn two_consecutive_inadequate_windows_alert_once_in_any_order() {
        let bad = |w: u64| Some(format!("MODEL INADEQUATE in window {w}"));
        for order in [[3u64, 4, 5, 8], [5, 8, 4, 3], [8, 4, 5, 3]] {
            let mut st = DriftState::default();
            let mut alerts = Vec::new();
            for w in order {
                alerts.extend(st.observe_model("m1", w, w as f64, bad(w)));
                // a window the model explained, and one delivered again, change nothing
                assert!(st.observe_model("m1", 20, 20.0, None).is_empty());
                let again: Vec<u64> = st
                    .observe_model("m1", w, w as f64, bad(w))
                    .iter()
                    .map(|a| a.window)
                    .collect();
                assert!(again.is_empty(), "{again:?}");
            }
            let mut windows: Vec<(u64, u64)> = alerts
                .iter()
                .map(|a| (a.previous_window, a.window))
                .collect();
            windows.sort();
            // 3-4 and 4-5 are consecutive, 8 alone raises nothing
            assert_eq!(windows, vec![(3, 4), (4, 5)], "{order:?}");
            assert!(alerts.iter().all(|a| a.kind == MODEL_INADEQUATE));
            let a = alerts.iter().find(|a| a.window == 5).unwrap();
            assert_eq!(
                (a.t0_s, a.message.as_str()),
                (5.0, "MODEL INADEQUATE in window 5")
            );
        }
    }

    #[test]
    fn one_outlier_raises_nothing() {
        let v: Vec<(u64, f64)> = (0..10)
            .map(|w| (w, if w == 5 { 50.0 } else { 100.0 }))
            .collect();
        assert!(run(&v).is_empty());
    }

    #[test]
    fn out_of_order_windows_give_the_same_alerts() {
        let v: Vec<(u64, f64)> = (0..10)
            .map(|w| (w, if w >= 5 { 80.0 } else { 100.0 }))
            .collect();
        let mut shuffled = v.clone();
        shuffled.reverse();
        let key = |a: &AlertRecord| (a.window, a.parameter.clone(), a.z.to_bits());
        let mut a: Vec<_> = run(&v).iter().map(key).collect();
        let mut b: Vec<_> = run(&shuffled).iter().map(key).collect();
        a.sort();
        b.sort();
        assert_eq!(a, b);
        assert_eq!(a.len(), 4);
    }
}
