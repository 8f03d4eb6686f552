//! Trial-weight planning: per plane, a trial mass and angle that changes the 1X response by
//! a stated fraction f (default 30 %) at the most sensitive sensor: big enough to measure,
//! small enough to be safe.
//!
//! **From an influence estimate** (the fit of the influence module over earlier calibration
//! runs): for plane p, the most sensitive key is the one with the largest relative
//! sensitivity |H_kp| / |V_k| (V the current run's vector: the change per kg m relative to
//! the level now, free of the sensors' units); the trial is
//!
//! ```text
//! T_p = -f V_k / H_kp      (|H_kp T_p| = f |V_k|, and no key changes by more than f |V_k|)
//! ```
//!
//! placed so that the change opposes the vibration at that key (the safe direction: it
//! lowers the vibration there by f if the estimate holds).
//!
//! **From an identified rotor** (the single-disk model of an identification summary, when
//! there are no calibration runs): the 1X response is h(W) U with U the identified
//! unbalance (response module), so a trial T changes every probe's vector by h T and the
//! fraction |h T| / |h U| = |T| / |U| is the same at every probe and speed; the trial is
//! T = -f U (opposite the identified unbalance), and the most sensitive probe and speed,
//! reported with the predicted change, is that of the largest |h|.

use nalgebra::Complex;

use super::data::{MassInput, VectorInput};
use super::error::{check_value, BalanceError};
use super::multi::{prepare, problem, BalanceOptions};
use super::single::response_per_unbalance;
use super::split::{split, Split};
use crate::analysis::error::AnalysisError;
use crate::analysis::modes::C64;
use crate::analysis::response::Probe;
use crate::model::{rpm_to_rad_per_s, RotorParams};

/// The default fraction by which a trial changes the response.
pub const DEFAULT_FRACTION: f64 = 0.3;

/// A planned trial mass.
#[derive(Debug, Clone, PartialEq)]
pub struct Trial {
    /// The plane.
    pub plane: String,
    /// The trial unbalance T \[kg m\].
    pub unbalance: C64,
    /// Its mass \[kg\] at `radius`.
    pub mass: f64,
    /// Radius \[m\].
    pub radius: f64,
    /// Angle \[rad\] from the keyphasor mark in the direction of rotation, in \[0, 2 pi).
    pub angle: f64,
    /// The most sensitive sensor (a probe direction `x` or `z` for a model).
    pub sensor: String,
    /// Its unit.
    pub unit: String,
    /// The speed \[rev/min\].
    pub speed_rpm: f64,
    /// The current vector there \[sensor unit\].
    pub current: C64,
    /// The predicted change H T there \[sensor unit\].
    pub change: C64,
    /// The split into holes, when the plane has holes.
    pub split: Option<Split>,
}

/// The planned trials.
#[derive(Debug, Clone, PartialEq)]
pub struct TrialPlan {
    /// `influence` or `model`.
    pub source: &'static str,
    /// The fraction f.
    pub fraction: f64,
    /// One trial per plane.
    pub trials: Vec<Trial>,
    /// Assumptions, in words.
    pub notes: Vec<String>,
}

fn check_fraction(fraction: f64) -> Result<f64, BalanceError> {
    check_value("fraction", fraction, "finite, > 0 and <= 1", |v| {
        v > 0.0 && v <= 1.0
    })
}

/// Plan trials from the influence estimate of the calibration runs (module doc).
pub fn plan_from_influence(
    vectors: &[VectorInput],
    masses: &[MassInput],
    opts: &BalanceOptions,
    fraction: f64,
) -> Result<TrialPlan, BalanceError> {
    check_fraction(fraction)?;
    let pr = prepare(vectors, masses, opts)?;
    let (prob, keys) = problem(&pr);
    let a = &pr.a;
    let mut trials = Vec::new();
    for (j, &p) in pr.corrected.iter().enumerate() {
        let best = (0..keys.len())
            .filter(|&i| prob.v[i].norm() > 0.0 && prob.h[(i, j)].norm() > 0.0)
            .max_by(|&x, &y| {
                let rx = prob.h[(x, j)].norm() / prob.v[x].norm();
                let ry = prob.h[(y, j)].norm() / prob.v[y].norm();
                rx.total_cmp(&ry)
            })
            .ok_or_else(|| BalanceError::Plan {
                plane: a.planes[p].clone(),
                why: "no sensor of the current run has both a non-zero vector and an influence coefficient of this plane".into(),
            })?;
        let (sensor, speed_rpm) = a.key(keys[best]);
        let (v, h) = (prob.v[best], prob.h[(best, j)]);
        let t = -v * fraction / h;
        let radius = pr.radius[p];
        let holes = opts.holes.iter().find(|(n, _)| *n == a.planes[p]);
        let sp = match holes {
            Some((_, hl)) => Some(split(&a.planes[p], t, radius, hl, opts.mass_set.as_ref())?),
            None => None,
        };
        trials.push(Trial {
            plane: a.planes[p].clone(),
            unbalance: t,
            mass: t.norm() / radius,
            radius,
            angle: crate::analysis::response::wrap(t.arg()),
            sensor: sensor.to_owned(),
            unit: a.sensors[a.sensor_of(keys[best])].1.clone(),
            speed_rpm,
            current: v,
            change: h * t,
            split: sp,
        });
    }
    Ok(TrialPlan {
        source: "influence",
        fraction,
        trials,
        notes: pr.notes,
    })
}

/// Plan the trial of the identified rotor `p` (one plane, `plane`, radius `radius` \[m\])
/// at `speeds_rpm` (module doc); `holes` splits it.
pub fn plan_from_model(
    p: &RotorParams,
    speeds_rpm: &[f64],
    plane: &str,
    radius: f64,
    fraction: f64,
    holes: Option<(&super::split::Holes, Option<&super::split::MassSet>)>,
) -> Result<TrialPlan, BalanceError> {
    check_fraction(fraction)?;
    check_value("radius", radius, "finite and > 0 (m)", |v| v > 0.0)?;
    if speeds_rpm.is_empty() {
        return Err(BalanceError::Plan {
            plane: plane.to_owned(),
            why: "no speed to plan at".into(),
        });
    }
    let u = Complex::from_polar(p.unbalance.mud(), p.unbalance.alpha);
    if !(u.norm() > 0.0 && u.norm().is_finite()) {
        return Err(BalanceError::Plan {
            plane: plane.to_owned(),
            why: format!(
                "the identified unbalance is {} kg m: the model cannot say how large the response is (identify the unbalance, or give calibration runs)",
                u.norm()
            ),
        });
    }
    let model_err = |e: AnalysisError| BalanceError::Plan {
        plane: plane.to_owned(),
        why: e.to_string(),
    };
    let mut best: Option<(f64, &str, f64, C64)> = None;
    for &rpm in speeds_rpm {
        check_value("speed", rpm, "finite and > 0 (rev/min)", |v| v > 0.0)?;
        for (name, probe) in [("x", Probe::X), ("z", Probe::Z)] {
            let h = response_per_unbalance(p, rpm_to_rad_per_s(rpm), probe)
                .map_err(model_err)?
                .ok_or_else(|| BalanceError::Plan {
                    plane: plane.to_owned(),
                    why: format!(
                        "the model has no bounded response at {rpm} rpm (undamped resonance)"
                    ),
                })?;
            if best.is_none_or(|b| h.norm() > b.0) {
                best = Some((h.norm(), name, rpm, h));
            }
        }
    }
    let (_, sensor, speed_rpm, h) = best.expect("at least one speed");
    let t = -u * fraction;
    let sp = match holes {
        Some((hl, set)) => Some(split(plane, t, radius, hl, set)?),
        None => None,
    };
    Ok(TrialPlan {
        source: "model",
        fraction,
        trials: vec![Trial {
            plane: plane.to_owned(),
            unbalance: t,
            mass: t.norm() / radius,
            radius,
            angle: crate::analysis::response::wrap(t.arg()),
            sensor: sensor.to_owned(),
            unit: "m".into(),
            speed_rpm,
            current: h * u,
            change: h * t,
            split: sp,
        }],
        notes: vec![format!(
            "from the identified rotor: the trial is {} times the identified unbalance ({:.4e} kg m at {:.1} deg), opposite it; it changes every probe's 1X vector by that fraction of the response the identified unbalance causes",
            fraction,
            u.norm(),
            crate::analysis::response::wrap(u.arg()).to_degrees()
        )],
    })
}
