//! Multi-plane, multi-speed balancing of one run: the influence coefficients fitted over
//! every calibration run (influence module), the correction by least squares or min-max
//! with its uncertainty (correction, minmax modules), the split into holes (split module),
//! in one typed result. The steps and conventions are in the parent module's doc.

use nalgebra::{DMatrix, DVector, Matrix2};

use super::correction::{self, block, Problem};
use super::data::{assemble, list, resolve, run_list, Assembled, MassInput, VectorInput};
use super::error::{check_value, BalanceError};
use super::influence::{fit_key, KeyFit, NoiseSource};
use super::minmax::min_max;
use super::single::Correction;
use super::split::{split, Holes, MassSet, Split};
use crate::analysis::modes::C64;

/// A condition number of the weighted influence matrix above this gets a warning: a 1 %
/// error in the vectors can then move the correction by 10 % or more.
pub const CONDITION_WARNING: f64 = 10.0;

/// A fit whose residual RMS exceeds this fraction of the RMS size of its vectors gets a
/// warning: the runs do not follow one linear model.
pub const MISFIT_WARNING: f64 = 0.1;

/// How the correction is chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BalanceMethod {
    /// Minimise the weighted sum of squared residual magnitudes.
    #[default]
    LeastSquares,
    /// Minimise the largest weighted residual magnitude, subject to the limits.
    MinMax,
}

impl BalanceMethod {
    /// `least_squares` or `min_max`.
    pub fn name(self) -> &'static str {
        match self {
            BalanceMethod::LeastSquares => "least_squares",
            BalanceMethod::MinMax => "min_max",
        }
    }
}

/// What to balance and how.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct BalanceOptions {
    /// The run to balance (it must have vectors; it may be a calibration run).
    pub current: String,
    /// Only the vectors within 1 % of these speeds \[rev/min\]; all when `None`.
    pub speeds_rpm: Option<Vec<f64>>,
    /// The planes to correct (a subset of the planes of the masses); all when `None`.
    pub planes: Option<Vec<String>>,
    /// Least squares or min-max.
    pub method: BalanceMethod,
    /// Weight of each named sensor (> 0; 1 when not named): its residuals count w times.
    pub weights: Vec<(String, f64)>,
    /// Largest residual allowed for each named sensor \[sensor unit\] (min-max; with least
    /// squares a residual above it is a warning).
    pub limits: Vec<(String, f64)>,
    /// Radius of each named plane's correction \[m\].
    pub radius: Vec<(String, f64)>,
    /// Radius of the planes not named in `radius` \[m\]; when `None`, the radius of the
    /// plane's calibration masses.
    pub default_radius: Option<f64>,
    /// Holes of each named plane: its correction is split into them.
    pub holes: Vec<(String, Holes)>,
    /// Weights available for the splits (any mass when `None`).
    pub mass_set: Option<MassSet>,
}

/// A sensor as used.
#[derive(Debug, Clone, PartialEq)]
pub struct SensorInfo {
    /// Its name.
    pub name: String,
    /// Its unit.
    pub unit: String,
    /// Its weight.
    pub weight: f64,
    /// Its limit \[sensor unit\].
    pub limit: Option<f64>,
}

/// The influence fit of one sensor at one speed.
#[derive(Debug, Clone)]
pub struct KeyResult {
    /// Sensor index (into `sensors`).
    pub sensor: usize,
    /// Speed \[rev/min\].
    pub speed_rpm: f64,
    /// The fit.
    pub fit: KeyFit,
}

/// The correction of one plane.
#[derive(Debug, Clone, PartialEq)]
pub struct PlaneCorrection {
    /// The plane.
    pub plane: String,
    /// The correction unbalance C \[kg m\].
    pub unbalance: C64,
    /// Covariance of (Re C, Im C) \[kg^2 m^2\], when known.
    pub covariance: Option<Matrix2<f64>>,
    /// Mass, angle and radius with standard deviations.
    pub correction: Correction,
    /// The split into holes, when the plane has holes.
    pub split: Option<Split>,
}

/// The predicted residual of one sensor at one speed.
#[derive(Debug, Clone, PartialEq)]
pub struct PredictedResidual {
    /// Sensor index.
    pub sensor: usize,
    /// Speed \[rev/min\].
    pub speed_rpm: f64,
    /// The current run's vector \[sensor unit\].
    pub before: C64,
    /// The predicted vector after the correction, r = V + H C \[sensor unit\].
    pub after: C64,
    /// Covariance of (Re r, Im r), when known.
    pub covariance: Option<Matrix2<f64>>,
    /// The predicted vector after the split masses (when some plane is split).
    pub after_split: Option<C64>,
}

/// The result of [`balance`].
#[derive(Debug, Clone)]
pub struct MultiPlaneBalance {
    /// The method.
    pub method: BalanceMethod,
    /// The run balanced.
    pub current: String,
    /// Whether the current run is a calibration run.
    pub current_is_calibration: bool,
    /// Sensors.
    pub sensors: Vec<SensorInfo>,
    /// Speeds \[rev/min\].
    pub speeds_rpm: Vec<f64>,
    /// Planes of the masses (fitted).
    pub planes: Vec<String>,
    /// Calibration runs.
    pub calibration_runs: Vec<String>,
    /// Every run with vectors (what [`KeyFit::runs`] indexes).
    pub run_names: Vec<String>,
    /// The influence fits.
    pub fits: Vec<KeyResult>,
    /// One correction per plane corrected.
    pub corrections: Vec<PlaneCorrection>,
    /// The predicted residuals.
    pub residual: Vec<PredictedResidual>,
    /// The condition number of the weighted influence matrix (of the planes corrected).
    pub condition_number: f64,
    /// Things the user must look at.
    pub warnings: Vec<String>,
    /// Assumptions and choices, in words.
    pub notes: Vec<String>,
}

impl MultiPlaneBalance {
    /// The index of the plane named `name` among `planes`.
    pub fn plane_index(&self, name: &str) -> Option<usize> {
        self.planes.iter().position(|p| p == name)
    }
}

/// Everything both the correction and the trial planning need.
pub(crate) struct Prepared {
    pub a: Assembled,
    pub current: usize,
    pub fits: Vec<Option<KeyFit>>,
    pub weights: Vec<f64>,
    pub limits: Vec<Option<f64>>,
    pub corrected: Vec<usize>,
    pub radius: Vec<f64>,
    pub notes: Vec<String>,
}

/// Assemble, resolve the options and fit every key.
pub(crate) fn prepare(
    vectors: &[VectorInput],
    masses: &[MassInput],
    opts: &BalanceOptions,
) -> Result<Prepared, BalanceError> {
    let a = assemble(vectors, masses, opts.speeds_rpm.as_deref())?;
    let at = if opts.speeds_rpm.is_some() {
        " at the speeds selected"
    } else {
        ""
    };
    let current = a
        .run_index(&opts.current)
        .ok_or_else(|| BalanceError::UnknownRun {
            run: opts.current.clone(),
            at,
            known: run_list(&a),
        })?;
    let sensor_names: Vec<String> = a.sensors.iter().map(|s| s.0.clone()).collect();
    let mut weights = vec![1.0; a.sensors.len()];
    for (i, (_, w)) in resolve(
        "weight",
        "sensor",
        opts.weights.iter().map(|x| x.0.as_str()),
        &sensor_names,
    )?
    .into_iter()
    .zip(&opts.weights)
    {
        weights[i] = check_value("weight", *w, "finite and > 0", |v| v > 0.0)?;
    }
    let mut limits = vec![None; a.sensors.len()];
    for (i, (_, l)) in resolve(
        "limit",
        "sensor",
        opts.limits.iter().map(|x| x.0.as_str()),
        &sensor_names,
    )?
    .into_iter()
    .zip(&opts.limits)
    {
        limits[i] = Some(check_value(
            "limit",
            *l,
            "finite and > 0 (sensor unit)",
            |v| v > 0.0,
        )?);
    }
    let corrected = match &opts.planes {
        Some(p) => resolve("planes", "plane", p.iter().map(String::as_str), &a.planes)?,
        None => (0..a.planes.len()).collect(),
    };
    if corrected.is_empty() {
        return Err(BalanceError::CorrectionUndetermined {
            keys: 0,
            planes: 0,
            why: "no plane to correct".into(),
        });
    }
    let mut radius_given = vec![None; a.planes.len()];
    for (i, (_, r)) in resolve(
        "radius",
        "plane",
        opts.radius.iter().map(|x| x.0.as_str()),
        &a.planes,
    )?
    .into_iter()
    .zip(&opts.radius)
    {
        radius_given[i] = Some(check_value("radius", *r, "finite and > 0 (m)", |v| {
            v > 0.0
        })?);
    }
    if let Some(r) = opts.default_radius {
        check_value("radius", r, "finite and > 0 (m)", |v| v > 0.0)?;
    }
    let mut radius = vec![f64::NAN; a.planes.len()];
    for p in 0..a.planes.len() {
        radius[p] = match (radius_given[p], opts.default_radius) {
            (Some(r), _) | (None, Some(r)) => r,
            (None, None) => {
                let rs = &a.radii[p];
                let first = rs[0];
                if rs.iter().any(|&r| (r - first).abs() > 1e-12 * first) {
                    if corrected.contains(&p) {
                        return Err(BalanceError::NoRadius {
                            plane: a.planes[p].clone(),
                            why: format!(
                                "its calibration masses are at several radii ({} m)",
                                list(rs.iter().map(|r| format!("{r}")))
                            ),
                        });
                    }
                    f64::NAN
                } else {
                    first
                }
            }
        };
    }
    let mut notes = Vec::new();
    let mut fits = Vec::with_capacity(a.keys());
    for key in 0..a.keys() {
        let has_current = a.vector[key][current].is_some();
        let has_any = a.calibration.iter().any(|&r| a.vector[key][r].is_some());
        if !has_any {
            fits.push(None);
            continue;
        }
        match fit_key(&a, key) {
            Ok(f) => fits.push(Some(f)),
            Err(e) if !has_current => {
                let (s, v) = a.key(key);
                notes.push(format!(
                    "sensor {s:?} at {v} rpm is not used (the current run has no vector there): {e}"
                ));
                fits.push(None);
            }
            Err(e) => return Err(e),
        }
    }
    Ok(Prepared {
        a,
        current,
        fits,
        weights,
        limits,
        corrected,
        radius,
        notes,
    })
}

/// The covariance of (H_k of the planes `planes`, V_k of run `current`) for fit `f`: both
/// linear maps of the measured vectors (the calibration runs' and, if it is not one of
/// them, the current run's), whose covariance is that of the fit (influence module); the
/// current run, when not a calibration run, has its own covariance (scaled like the fit's
/// when given), or the fit's residual noise when not given.
fn key_covariance(
    f: &KeyFit,
    planes: &[usize],
    current: usize,
    own: Option<Matrix2<f64>>,
) -> Option<DMatrix<f64>> {
    let covs = f.run_covariance.as_ref()?;
    let n = f.runs.len();
    let at = f.runs.iter().position(|&r| r == current);
    let extra = at.is_none();
    let nm = 2 * n + if extra { 2 } else { 0 };
    let mut s = DMatrix::<f64>::zeros(nm, nm);
    for (i, c) in covs.iter().enumerate() {
        s.fixed_view_mut::<2, 2>(2 * i, 2 * i).copy_from(c);
    }
    if extra {
        let c = match (f.noise, own) {
            (NoiseSource::Given { scale }, Some(c)) => c * (scale * scale),
            (NoiseSource::Residuals, Some(c)) => c,
            (NoiseSource::Residuals, None) => covs[0],
            (NoiseSource::Given { .. }, None) | (NoiseSource::None, _) => return None,
        };
        s.fixed_view_mut::<2, 2>(2 * n, 2 * n).copy_from(&c);
    }
    let np = planes.len();
    let mut g = DMatrix::<f64>::zeros(2 * np + 2, nm);
    for (j, &p) in planes.iter().enumerate() {
        for c in 0..2 * n {
            g[(2 * j, c)] = f.map[(2 + 2 * p, c)];
            g[(2 * j + 1, c)] = f.map[(3 + 2 * p, c)];
        }
    }
    let col = 2 * at.unwrap_or(n);
    g[(2 * np, col)] = 1.0;
    g[(2 * np + 1, col + 1)] = 1.0;
    Some(&g * s * g.transpose())
}

/// The correction problem of the keys with a fit and a current vector: the problem and the
/// key of each row.
pub(crate) fn problem(pr: &Prepared) -> (Problem, Vec<usize>) {
    let a = &pr.a;
    let keys: Vec<usize> = (0..a.keys())
        .filter(|&k| pr.fits[k].is_some() && a.vector[k][pr.current].is_some())
        .collect();
    let np = pr.corrected.len();
    let h = DMatrix::from_fn(keys.len(), np, |i, j| {
        pr.fits[keys[i]].as_ref().expect("filtered").h[pr.corrected[j]]
    });
    let v = DVector::from_fn(keys.len(), |i, _| {
        a.vector[keys[i]][pr.current].expect("filtered").0
    });
    let w = keys.iter().map(|&k| pr.weights[a.sensor_of(k)]).collect();
    let cov = keys
        .iter()
        .map(|&k| {
            let f = pr.fits[k].as_ref().expect("filtered");
            let own = a.vector[k][pr.current].and_then(|x| x.1);
            key_covariance(f, &pr.corrected, pr.current, own)
        })
        .collect();
    (Problem { h, v, w, cov }, keys)
}

/// Balance run `opts.current` from the 1X vectors and calibration masses (parent module
/// doc).
pub fn balance(
    vectors: &[VectorInput],
    masses: &[MassInput],
    opts: &BalanceOptions,
) -> Result<MultiPlaneBalance, BalanceError> {
    let pr = prepare(vectors, masses, opts)?;
    let a = &pr.a;
    let mut notes = pr.notes.clone();
    let mut warnings = Vec::new();
    let (prob, keys) = problem(&pr);
    if prob.h.nrows() == 0 {
        return Err(BalanceError::CorrectionUndetermined {
            keys: 0,
            planes: pr.corrected.len(),
            why: format!(
                "run {:?} has no vector at a sensor and speed of the calibration runs",
                opts.current
            ),
        });
    }
    let key_limits: Vec<Option<f64>> = keys.iter().map(|&k| pr.limits[a.sensor_of(k)]).collect();
    let names = |i: usize| {
        let (s, v) = a.key(keys[i]);
        (s.to_owned(), v)
    };
    let solved = match opts.method {
        BalanceMethod::LeastSquares => correction::solve(&prob, None)?,
        BalanceMethod::MinMax => {
            let f = |p: &Problem| min_max(p, &key_limits, &names);
            correction::solve(&prob, Some(&f))?
        }
    };
    let (sv, vt) = correction::singular_values(&prob);
    let smin = *sv.last().unwrap_or(&0.0);
    let condition_number = if smin > 0.0 {
        sv[0] / smin
    } else {
        f64::INFINITY
    };
    if condition_number > CONDITION_WARNING && pr.corrected.len() > 1 {
        // the right singular vector of the smallest singular value: the combination of
        // planes that changes the vibration least
        let row = vt.row(vt.nrows() - 1);
        let combo: Vec<String> = row
            .iter()
            .zip(&pr.corrected)
            .filter(|(z, _)| z.norm() > 0.05)
            .map(|(z, &p)| {
                format!(
                    "{:.2} x {:?} at {:.0} deg",
                    z.norm(),
                    a.planes[p],
                    z.conj().arg().to_degrees().rem_euclid(360.0)
                )
            })
            .collect();
        warnings.push(format!(
            "the influence matrix has condition number {condition_number:.1} (above {CONDITION_WARNING}): the planes can hardly be told apart; unbalances {} together change the vibration {condition_number:.0} times less than the best-seen combination, so the correction's split between these planes is poorly determined (see the standard deviations); consider correcting fewer planes",
            combo.join(" + ")
        ));
    }
    let mut corrections = Vec::with_capacity(pr.corrected.len());
    for (j, &p) in pr.corrected.iter().enumerate() {
        let c = solved.c[j];
        let cov = solved.cov_c.as_ref().map(|m| block(m, j));
        let radius = pr.radius[p];
        let holes = opts.holes.iter().find(|(n, _)| *n == a.planes[p]);
        let split = match holes {
            Some((_, h)) => Some(split(&a.planes[p], c, radius, h, opts.mass_set.as_ref())?),
            None => None,
        };
        corrections.push(PlaneCorrection {
            plane: a.planes[p].clone(),
            unbalance: c,
            covariance: cov,
            correction: Correction::new(c, radius, cov),
            split,
        });
    }
    resolve(
        "holes",
        "plane",
        opts.holes.iter().map(|h| h.0.as_str()),
        &a.planes,
    )?;
    for (name, _) in &opts.holes {
        if !corrections.iter().any(|c| c.plane == *name) {
            notes.push(format!(
                "plane {name:?} has holes but is not corrected (not among the planes asked for)"
            ));
        }
    }
    let any_split = corrections.iter().any(|c| c.split.is_some());
    let placed = DVector::from_fn(pr.corrected.len(), |j, _| match &corrections[j].split {
        Some(s) => s.placed(),
        None => corrections[j].unbalance,
    });
    let after_split = &prob.v + &prob.h * &placed;
    let residual: Vec<PredictedResidual> = keys
        .iter()
        .enumerate()
        .map(|(i, &k)| PredictedResidual {
            sensor: a.sensor_of(k),
            speed_rpm: a.key(k).1,
            before: prob.v[i],
            after: solved.r[i],
            covariance: solved.cov_r.as_ref().map(|m| block(m, i)),
            after_split: any_split.then(|| after_split[i]),
        })
        .collect();
    for (r, l) in residual.iter().zip(&key_limits) {
        if let Some(l) = l {
            let s = &a.sensors[r.sensor].0;
            if r.after.norm() > *l {
                warnings.push(format!(
                    "sensor {s:?} at {} rpm: the predicted residual {:.4} exceeds its limit {l}{}",
                    r.speed_rpm,
                    r.after.norm(),
                    if opts.method == BalanceMethod::LeastSquares {
                        " (least squares does not enforce limits: use the min-max method)"
                    } else {
                        ""
                    }
                ));
            }
            if let Some(s2) = r.after_split {
                if s2.norm() > *l && r.after.norm() <= *l {
                    warnings.push(format!(
                        "sensor {s:?} at {} rpm: with the split masses the predicted residual {:.4} exceeds its limit {l}",
                        r.speed_rpm,
                        s2.norm()
                    ));
                }
            }
        }
    }
    // notes: noise, units, current masses, std
    let mut units: Vec<&str> = a.sensors.iter().map(|s| s.1.as_str()).collect();
    units.sort_unstable();
    units.dedup();
    if units.len() > 1 && opts.weights.is_empty() {
        warnings.push(format!(
            "the sensors are in different units ({}) and weigh alike: give weights to say how a unit of each compares",
            units.join(", ")
        ));
    }
    let given: Vec<f64> = pr
        .fits
        .iter()
        .flatten()
        .filter_map(|f| match f.noise {
            NoiseSource::Given { scale } => Some(scale),
            _ => None,
        })
        .collect();
    if let Some(worst) = given.iter().copied().reduce(f64::max) {
        if worst > 1.5 {
            notes.push(format!(
                "the runs scatter more than the vectors' stated noise explains (up to {worst:.1} times): their standard deviations were scaled up accordingly"
            ));
        }
    }
    if pr
        .fits
        .iter()
        .flatten()
        .any(|f| f.noise == NoiseSource::None)
    {
        notes.push(
            "with exactly as many calibration runs as unknowns and no standard deviations given, the fit has no residual to estimate the noise from: the influence coefficients and the correction have no standard deviation (give re_std, im_std or a std column, or one more run)".into(),
        );
    }
    // runs that do not fit one set of coefficients: a sign convention, an angle or a mass
    // written wrong, or a rotor that is not linear
    for (k, f) in pr.fits.iter().enumerate() {
        let Some(f) = f else { continue };
        if f.dof == 0 {
            continue;
        }
        let size = (f
            .runs
            .iter()
            .filter_map(|&r| a.vector[k][r].map(|v| v.0.norm_sqr()))
            .sum::<f64>()
            / f.runs.len() as f64)
            .sqrt();
        if f.residual_rms > MISFIT_WARNING * size {
            let (s, v) = a.key(k);
            warnings.push(format!(
                "the calibration runs of sensor {s:?} at {v} rpm do not fit one set of influence coefficients: residual RMS {:.4} against vectors of RMS {size:.4} {}; check the phase convention (lag or lead), that the masses' angles are measured in the direction of rotation from the keyphasor mark, and the masses themselves",
                f.residual_rms, a.sensors[a.sensor_of(k)].1
            ));
        }
    }
    let current_is_calibration = a.calibration.contains(&pr.current);
    if current_is_calibration {
        let c = a
            .calibration
            .iter()
            .position(|&r| r == pr.current)
            .expect("contains");
        let on: Vec<String> = a.trial[c]
            .iter()
            .zip(&a.planes)
            .filter(|(t, _)| t.norm() > 0.0)
            .map(|(t, n)| {
                format!(
                    "{n:?} ({:.4e} kg m at {:.1} deg)",
                    t.norm(),
                    t.arg().to_degrees().rem_euclid(360.0)
                )
            })
            .collect();
        if !on.is_empty() {
            notes.push(format!(
                "run {:?} has masses on {}: the corrections are to be added with them in place",
                opts.current,
                on.join(", ")
            ));
        }
    }
    if opts.method == BalanceMethod::MinMax && solved.cov_c.is_some() {
        notes.push("the min-max correction's standard deviations are first-order (derivatives by central differences of the polished solution): they hold while the set of sensors at the largest residual does not change with the noise, and overstate the scatter when the predicted residuals are at the noise level".into());
    }
    let fits = (0..a.keys())
        .filter_map(|k| {
            pr.fits[k].clone().map(|fit| KeyResult {
                sensor: a.sensor_of(k),
                speed_rpm: a.key(k).1,
                fit,
            })
        })
        .collect();
    Ok(MultiPlaneBalance {
        method: opts.method,
        current: opts.current.clone(),
        current_is_calibration,
        sensors: a
            .sensors
            .iter()
            .enumerate()
            .map(|(i, (n, u))| SensorInfo {
                name: n.clone(),
                unit: u.clone(),
                weight: pr.weights[i],
                limit: pr.limits[i],
            })
            .collect(),
        speeds_rpm: a.speeds_rpm.clone(),
        planes: a.planes.clone(),
        calibration_runs: a.calibration.iter().map(|&r| a.runs[r].clone()).collect(),
        run_names: a.runs.clone(),
        fits,
        corrections,
        residual,
        condition_number,
        warnings,
        notes,
    })
}
