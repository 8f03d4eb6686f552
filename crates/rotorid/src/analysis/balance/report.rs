//! `balance.json`: the serialised multi-plane balance and trial plan, field by field in
//! docs/balancing.md of this repository. Angles in degrees in \[0, 360) from the keyphasor
//! mark in the direction of rotation; masses in kg, radii in m, unbalances in kg m; vectors
//! in the sensor's unit, `re + i im` meaning the 1X component Re((re + i im) e^{i phi}). A
//! standard deviation that is not known is `null`. `std` of a vector is
//! sqrt(var re + var im), the RMS size of its error.

use nalgebra::Matrix2;
use serde::Serialize;

use super::multi::MultiPlaneBalance;
use super::plan::TrialPlan;
use super::split::Split;
use crate::analysis::modes::C64;
use crate::analysis::response::wrap;

/// The version of the layout below.
pub const BALANCE_SCHEMA: u32 = 1;

/// Where every angle is measured from.
pub const ANGLE_REFERENCE: &str = "degrees from the keyphasor mark, in the direction of rotation";

/// What a vector means.
pub const VECTOR_CONVENTION: &str = "re + i im: the sensor's 1X component is Re((re + i im) e^{i phi}), phi the shaft angle from the keyphasor mark in the direction of rotation (amplitude |re + i im|, phase lag -arg, phase lead +arg)";

fn deg(a: f64) -> f64 {
    let d = wrap(a).to_degrees();
    if d >= 360.0 {
        0.0
    } else {
        d
    }
}

fn stds(c: Option<&Matrix2<f64>>) -> (Option<f64>, Option<f64>, Option<f64>) {
    match c {
        Some(c) => {
            let (a, b) = (c[(0, 0)].max(0.0), c[(1, 1)].max(0.0));
            (Some(a.sqrt()), Some(b.sqrt()), Some((a + b).sqrt()))
        }
        None => (None, None, None),
    }
}

/// A sensor.
#[derive(Debug, Clone, Serialize)]
pub struct SensorJson {
    /// Name.
    pub name: String,
    /// Unit of its vectors.
    pub unit: String,
    /// Weight in the correction.
    pub weight: f64,
    /// Limit on its residual \[unit\].
    pub limit: Option<f64>,
}

/// One mass of a split.
#[derive(Debug, Clone, Serialize)]
pub struct SplitMassJson {
    /// Hole number, 1-based in the order of `holes_deg`.
    pub hole: usize,
    /// Hole angle \[deg\].
    pub angle_deg: f64,
    /// Mass \[kg\].
    pub mass_kg: f64,
    /// With a mass set: the weights stacked in the hole \[kg\].
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub weights_kg: Vec<f64>,
}

/// A split into holes.
#[derive(Debug, Clone, Serialize)]
pub struct SplitJson {
    /// The hole angles \[deg\].
    pub holes_deg: Vec<f64>,
    /// The masses to place.
    pub masses: Vec<SplitMassJson>,
    /// Size of the unbalance the split leaves, |placed - wanted| \[kg m\].
    pub residual_kg_m: f64,
    /// That as a mass at the radius \[kg\].
    pub residual_mass_kg: f64,
    /// Its angle \[deg\] (0 when it is 0).
    pub residual_angle_deg: f64,
}

impl SplitJson {
    fn new(s: &Split) -> Self {
        Self {
            holes_deg: s.holes.iter().map(|&h| deg(h)).collect(),
            masses: s
                .masses
                .iter()
                .map(|m| SplitMassJson {
                    hole: m.hole + 1,
                    angle_deg: deg(m.angle),
                    mass_kg: m.mass,
                    weights_kg: m.weights.clone(),
                })
                .collect(),
            residual_kg_m: s.residual.norm(),
            residual_mass_kg: s.residual.norm() / s.radius,
            residual_angle_deg: if s.residual.norm() > 0.0 {
                deg(s.residual.arg())
            } else {
                0.0
            },
        }
    }
}

/// The correction of one plane.
#[derive(Debug, Clone, Serialize)]
pub struct CorrectionJson {
    /// The plane.
    pub plane: String,
    /// Mass \[kg\].
    pub mass_kg: f64,
    /// Its standard deviation \[kg\].
    pub mass_kg_std: Option<f64>,
    /// Radius \[m\].
    pub radius_m: f64,
    /// Angle \[deg\].
    pub angle_deg: f64,
    /// Its standard deviation \[deg\].
    pub angle_deg_std: Option<f64>,
    /// The correction as an unbalance, Re \[kg m\].
    pub unbalance_re_kg_m: f64,
    /// Im \[kg m\].
    pub unbalance_im_kg_m: f64,
    /// The split into holes (`null` without holes).
    pub split: Option<SplitJson>,
}

/// The predicted residual of one sensor at one speed.
#[derive(Debug, Clone, Serialize)]
pub struct ResidualJson {
    /// Sensor.
    pub sensor: String,
    /// Speed \[rev/min\].
    pub speed_rpm: f64,
    /// Unit.
    pub unit: String,
    /// The current run's vector, Re \[unit\].
    pub before_re: f64,
    /// Im \[unit\].
    pub before_im: f64,
    /// Its amplitude \[unit\].
    pub before_amplitude: f64,
    /// Predicted vector after the correction, Re \[unit\].
    pub re: f64,
    /// Im \[unit\].
    pub im: f64,
    /// Standard deviation of `re` \[unit\].
    pub re_std: Option<f64>,
    /// Standard deviation of `im` \[unit\].
    pub im_std: Option<f64>,
    /// sqrt(var re + var im) \[unit\].
    pub std: Option<f64>,
    /// Predicted amplitude \[unit\].
    pub amplitude: f64,
    /// The sensor's limit \[unit\].
    pub limit: Option<f64>,
    /// Predicted vector with the split masses, Re \[unit\] (`null` without a split).
    pub split_re: Option<f64>,
    /// Im \[unit\].
    pub split_im: Option<f64>,
    /// Its amplitude \[unit\].
    pub split_amplitude: Option<f64>,
}

/// An influence coefficient.
#[derive(Debug, Clone, Serialize)]
pub struct InfluenceJson {
    /// Sensor.
    pub sensor: String,
    /// Speed \[rev/min\].
    pub speed_rpm: f64,
    /// Plane.
    pub plane: String,
    /// Unit: the sensor's per kg m.
    pub unit: String,
    /// Re \[unit\].
    pub re: f64,
    /// Im \[unit\].
    pub im: f64,
    /// Standard deviation of `re`.
    pub re_std: Option<f64>,
    /// Standard deviation of `im`.
    pub im_std: Option<f64>,
    /// sqrt(var re + var im).
    pub std: Option<f64>,
    /// Amplitude |re + i im|.
    pub amplitude: f64,
    /// Phase lag -arg \[deg\] in \[0, 360).
    pub phase_lag_deg: f64,
}

/// The fit of one sensor at one speed.
#[derive(Debug, Clone, Serialize)]
pub struct FitJson {
    /// Sensor.
    pub sensor: String,
    /// Speed \[rev/min\].
    pub speed_rpm: f64,
    /// The calibration runs fitted.
    pub runs: Vec<String>,
    /// Real degrees of freedom of the residuals.
    pub dof: usize,
    /// RMS of the residual vectors' magnitudes \[unit\].
    pub residual_rms: f64,
    /// The vector as found (fitted), Re \[unit\].
    pub as_found_re: f64,
    /// Im \[unit\].
    pub as_found_im: f64,
    /// `given`, `residuals` or `none`.
    pub noise: &'static str,
    /// Factor on the given standard deviations (`given`).
    pub noise_scale: Option<f64>,
}

/// `balance.json` of a multi-plane balance.
#[derive(Debug, Clone, Serialize)]
pub struct BalanceReport {
    /// [`BALANCE_SCHEMA`].
    pub schema: u32,
    /// `least_squares` or `min_max`.
    pub method: &'static str,
    /// The run balanced.
    pub current_run: String,
    /// [`ANGLE_REFERENCE`].
    pub angle_reference: &'static str,
    /// [`VECTOR_CONVENTION`].
    pub vector_convention: &'static str,
    /// Planes of the masses.
    pub planes: Vec<String>,
    /// Speeds \[rev/min\].
    pub speeds_rpm: Vec<f64>,
    /// Sensors.
    pub sensors: Vec<SensorJson>,
    /// Calibration runs.
    pub calibration_runs: Vec<String>,
    /// One correction per plane corrected.
    pub corrections: Vec<CorrectionJson>,
    /// Predicted residual per sensor and speed.
    pub residual: Vec<ResidualJson>,
    /// Influence coefficients.
    pub influence: Vec<InfluenceJson>,
    /// The fits.
    pub fit: Vec<FitJson>,
    /// Condition number of the weighted influence matrix.
    pub condition_number: f64,
    /// Warnings.
    pub warnings: Vec<String>,
    /// Notes.
    pub notes: Vec<String>,
}

impl MultiPlaneBalance {
    /// The serialisable report (`balance.json`).
    pub fn report(&self) -> BalanceReport {
        let sensor = |i: usize| self.sensors[i].name.clone();
        let unit = |i: usize| self.sensors[i].unit.clone();
        let corrections = self
            .corrections
            .iter()
            .map(|c| CorrectionJson {
                plane: c.plane.clone(),
                mass_kg: c.correction.mass,
                mass_kg_std: c.correction.std_mass,
                radius_m: c.correction.radius,
                angle_deg: deg(c.correction.angle),
                angle_deg_std: c.correction.std_angle.map(f64::to_degrees),
                unbalance_re_kg_m: c.unbalance.re,
                unbalance_im_kg_m: c.unbalance.im,
                split: c.split.as_ref().map(SplitJson::new),
            })
            .collect();
        let residual = self
            .residual
            .iter()
            .map(|r| {
                let (re_std, im_std, std) = stds(r.covariance.as_ref());
                ResidualJson {
                    sensor: sensor(r.sensor),
                    speed_rpm: r.speed_rpm,
                    unit: unit(r.sensor),
                    before_re: r.before.re,
                    before_im: r.before.im,
                    before_amplitude: r.before.norm(),
                    re: r.after.re,
                    im: r.after.im,
                    re_std,
                    im_std,
                    std,
                    amplitude: r.after.norm(),
                    limit: self.sensors[r.sensor].limit,
                    split_re: r.after_split.map(|z| z.re),
                    split_im: r.after_split.map(|z| z.im),
                    split_amplitude: r.after_split.map(|z| z.norm()),
                }
            })
            .collect();
        let mut influence = Vec::new();
        let mut fit = Vec::new();
        for k in &self.fits {
            for (p, h) in k.fit.h.iter().enumerate() {
                let (re_std, im_std, std) = match k.fit.h_std(p) {
                    Some((a, b)) => (Some(a), Some(b), Some(a.hypot(b))),
                    None => (None, None, None),
                };
                influence.push(InfluenceJson {
                    sensor: sensor(k.sensor),
                    speed_rpm: k.speed_rpm,
                    plane: self.planes[p].clone(),
                    unit: format!("{}/(kg m)", unit(k.sensor)),
                    re: h.re,
                    im: h.im,
                    re_std,
                    im_std,
                    std,
                    amplitude: h.norm(),
                    phase_lag_deg: deg(-h.arg()),
                });
            }
            let (noise, noise_scale) = match k.fit.noise {
                super::influence::NoiseSource::Given { scale } => ("given", Some(scale)),
                super::influence::NoiseSource::Residuals => ("residuals", None),
                super::influence::NoiseSource::None => ("none", None),
            };
            fit.push(FitJson {
                sensor: sensor(k.sensor),
                speed_rpm: k.speed_rpm,
                runs: k
                    .fit
                    .runs
                    .iter()
                    .map(|&r| self.run_names[r].clone())
                    .collect(),
                dof: k.fit.dof,
                residual_rms: k.fit.residual_rms,
                as_found_re: k.fit.as_found.re,
                as_found_im: k.fit.as_found.im,
                noise,
                noise_scale,
            });
        }
        BalanceReport {
            schema: BALANCE_SCHEMA,
            method: self.method.name(),
            current_run: self.current.clone(),
            angle_reference: ANGLE_REFERENCE,
            vector_convention: VECTOR_CONVENTION,
            planes: self.planes.clone(),
            speeds_rpm: self.speeds_rpm.clone(),
            sensors: self
                .sensors
                .iter()
                .map(|s| SensorJson {
                    name: s.name.clone(),
                    unit: s.unit.clone(),
                    weight: s.weight,
                    limit: s.limit,
                })
                .collect(),
            calibration_runs: self.calibration_runs.clone(),
            corrections,
            residual,
            influence,
            fit,
            condition_number: self.condition_number,
            warnings: self.warnings.clone(),
            notes: self.notes.clone(),
        }
    }
}

/// A planned trial.
#[derive(Debug, Clone, Serialize)]
pub struct TrialJson {
    /// The plane.
    pub plane: String,
    /// Mass \[kg\].
    pub mass_kg: f64,
    /// Radius \[m\].
    pub radius_m: f64,
    /// Angle \[deg\].
    pub angle_deg: f64,
    /// The most sensitive sensor.
    pub sensor: String,
    /// Its speed \[rev/min\].
    pub speed_rpm: f64,
    /// Its unit.
    pub unit: String,
    /// Its current amplitude \[unit\].
    pub current_amplitude: f64,
    /// The predicted change there, Re \[unit\].
    pub change_re: f64,
    /// Im \[unit\].
    pub change_im: f64,
    /// Its amplitude \[unit\].
    pub change_amplitude: f64,
    /// The split into holes (`null` without holes).
    pub split: Option<SplitJson>,
}

/// `balance.json` of a trial plan (`--plan`).
#[derive(Debug, Clone, Serialize)]
pub struct PlanReport {
    /// [`BALANCE_SCHEMA`].
    pub schema: u32,
    /// `plan`.
    pub method: &'static str,
    /// `influence` or `model`.
    pub source: &'static str,
    /// The fraction by which each trial changes the response at its sensor.
    pub fraction: f64,
    /// [`ANGLE_REFERENCE`].
    pub angle_reference: &'static str,
    /// [`VECTOR_CONVENTION`].
    pub vector_convention: &'static str,
    /// One trial per plane.
    pub trials: Vec<TrialJson>,
    /// Notes.
    pub notes: Vec<String>,
}

impl TrialPlan {
    /// The serialisable report.
    pub fn report(&self) -> PlanReport {
        PlanReport {
            schema: BALANCE_SCHEMA,
            method: "plan",
            source: self.source,
            fraction: self.fraction,
            angle_reference: ANGLE_REFERENCE,
            vector_convention: VECTOR_CONVENTION,
            trials: self
                .trials
                .iter()
                .map(|t| TrialJson {
                    plane: t.plane.clone(),
                    mass_kg: t.mass,
                    radius_m: t.radius,
                    angle_deg: deg(t.angle),
                    sensor: t.sensor.clone(),
                    speed_rpm: t.speed_rpm,
                    unit: t.unit.clone(),
                    current_amplitude: t.current.norm(),
                    change_re: t.change.re,
                    change_im: t.change.im,
                    change_amplitude: t.change.norm(),
                    split: t.split.as_ref().map(SplitJson::new),
                })
                .collect(),
            notes: self.notes.clone(),
        }
    }
}

/// A complex number's angle in degrees in \[0, 360) (0 for 0).
pub fn angle_deg(z: C64) -> f64 {
    if z.norm() > 0.0 {
        deg(z.arg())
    } else {
        0.0
    }
}
