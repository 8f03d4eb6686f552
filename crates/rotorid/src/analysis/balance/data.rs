//! The inputs of multi-plane balancing and their assembly into a problem: the 1X vectors
//! (run, speed, sensor), the masses of the calibration runs (run, plane, mass, radius,
//! angle), grouped by speed (speeds within 1 % are one speed), indexed by (sensor, speed)
//! "keys", with every consistency check a user can fail named in a [`BalanceError`].

use nalgebra::{Complex, Matrix2};

use super::error::{check_value, BalanceError};
use crate::analysis::modes::C64;

/// Speeds within this fraction of a group's first speed are one speed; a speed asked for
/// takes the vectors within this fraction of it.
pub const SPEED_TOLERANCE: f64 = 0.01;

/// One 1X vector: the sensor's 1X component in the run is Re(V e^{i phi}), phi the shaft
/// angle from the keyphasor mark in the direction of rotation.
#[derive(Debug, Clone, PartialEq)]
pub struct VectorInput {
    /// The run.
    pub run: String,
    /// Speed \[rev/min\], > 0.
    pub speed_rpm: f64,
    /// The sensor.
    pub sensor: String,
    /// The sensor's unit (free text: `um`, `mil`, `V`, `mm/s`, `m`); one per sensor.
    pub unit: String,
    /// V \[sensor unit\].
    pub value: C64,
    /// Covariance of (Re V, Im V) \[sensor unit^2\], when the vector's own noise is known.
    pub covariance: Option<Matrix2<f64>>,
}

impl VectorInput {
    /// A vector from its components, with standard deviations of Re V and Im V when known
    /// (independent).
    pub fn new(
        run: &str,
        speed_rpm: f64,
        sensor: &str,
        unit: &str,
        re: f64,
        im: f64,
        std: Option<(f64, f64)>,
    ) -> Self {
        Self {
            run: run.to_owned(),
            speed_rpm,
            sensor: sensor.to_owned(),
            unit: unit.to_owned(),
            value: Complex::new(re, im),
            covariance: std.map(|(a, b)| Matrix2::new(a * a, 0.0, 0.0, b * b)),
        }
    }
}

/// A mass added in a calibration run.
#[derive(Debug, Clone, PartialEq)]
pub struct MassInput {
    /// The run.
    pub run: String,
    /// The plane it is on.
    pub plane: String,
    /// Mass \[kg\], >= 0 (0: the run as found on this plane).
    pub mass: f64,
    /// Radius \[m\], >= 0 (> 0 when the mass is).
    pub radius: f64,
    /// Angle \[rad\] from the keyphasor mark in the direction of rotation.
    pub angle: f64,
}

impl MassInput {
    /// The unbalance m R e^{i angle} \[kg m\].
    pub fn unbalance(&self) -> C64 {
        Complex::from_polar(self.mass * self.radius, self.angle)
    }
}

/// A measured vector \[sensor unit\] and its covariance when known.
pub(crate) type Measured = (C64, Option<Matrix2<f64>>);

/// The vectors and masses checked and indexed (module doc).
#[derive(Debug, Clone)]
pub(crate) struct Assembled {
    /// Sensors in order of first appearance, with their units.
    pub sensors: Vec<(String, String)>,
    /// Speed groups \[rev/min\], increasing.
    pub speeds_rpm: Vec<f64>,
    /// Planes in order of first appearance in the masses.
    pub planes: Vec<String>,
    /// Runs with vectors, in order of first appearance.
    pub runs: Vec<String>,
    /// Calibration runs (indices into `runs`), in order of first appearance in the masses.
    pub calibration: Vec<usize>,
    /// The added unbalance of each calibration run on each plane \[kg m\]
    /// (`trial[c][p]`, c indexing `calibration`).
    pub trial: Vec<Vec<C64>>,
    /// The radii of the non-zero masses of each plane \[m\].
    pub radii: Vec<Vec<f64>>,
    /// `vector[key][run]`: the vector and its covariance, key = sensor * speeds + speed.
    pub vector: Vec<Vec<Option<Measured>>>,
}

impl Assembled {
    /// Number of (sensor, speed) keys.
    pub fn keys(&self) -> usize {
        self.sensors.len() * self.speeds_rpm.len()
    }

    /// The sensor and speed of `key`.
    pub fn key(&self, key: usize) -> (&str, f64) {
        let n = self.speeds_rpm.len();
        (&self.sensors[key / n].0, self.speeds_rpm[key % n])
    }

    /// The sensor index of `key`.
    pub fn sensor_of(&self, key: usize) -> usize {
        key / self.speeds_rpm.len()
    }

    /// The index of run `name`.
    pub fn run_index(&self, name: &str) -> Option<usize> {
        self.runs.iter().position(|r| r == name)
    }
}

fn check_name(what: &'static str, name: &str) -> Result<(), BalanceError> {
    if name.trim().is_empty() {
        Err(BalanceError::EmptyName { what })
    } else {
        Ok(())
    }
}

/// The speed groups of `speeds` \[rev/min\] (module doc) and the group of each, or of the
/// `requested` speeds (a speed outside 1 % of every one gets `None`).
pub(crate) fn group_speeds(
    speeds: &[f64],
    requested: Option<&[f64]>,
) -> Result<(Vec<f64>, Vec<Option<usize>>), BalanceError> {
    if let Some(req) = requested {
        for &s in req {
            check_value("speed", s, "finite and > 0 (rev/min)", |v| v > 0.0)?;
        }
        let mut groups: Vec<f64> = req.to_vec();
        groups.sort_by(f64::total_cmp);
        groups.dedup();
        let assign: Vec<Option<usize>> = speeds
            .iter()
            .map(|&v| {
                groups
                    .iter()
                    .enumerate()
                    .filter(|(_, &s)| (v - s).abs() <= SPEED_TOLERANCE * s)
                    .min_by(|a, b| (v - a.1).abs().total_cmp(&(v - b.1).abs()))
                    .map(|(i, _)| i)
            })
            .collect();
        for (i, &s) in groups.iter().enumerate() {
            if !assign.contains(&Some(i)) {
                let (all, _) = group_speeds(speeds, None)?;
                return Err(BalanceError::NoSpeed {
                    speed_rpm: s,
                    known: list(all.iter().map(|v| format!("{v}"))),
                });
            }
        }
        return Ok((groups, assign));
    }
    let mut sorted: Vec<f64> = speeds.to_vec();
    sorted.sort_by(f64::total_cmp);
    // groups: (first, sum, count)
    let mut groups: Vec<(f64, f64, usize)> = Vec::new();
    for v in sorted {
        match groups.last_mut() {
            Some(g) if v <= g.0 * (1.0 + SPEED_TOLERANCE) => {
                g.1 += v;
                g.2 += 1;
            }
            _ => groups.push((v, v, 1)),
        }
    }
    let firsts: Vec<f64> = groups.iter().map(|g| g.0).collect();
    let means: Vec<f64> = groups.iter().map(|g| g.1 / g.2 as f64).collect();
    let assign = speeds
        .iter()
        .map(|&v| {
            // the last group whose first speed is <= v
            Some(firsts.iter().rposition(|&f| f <= v).unwrap_or(0))
        })
        .collect();
    Ok((means, assign))
}

/// Names for a message: `"a", "b", "c"`.
pub(crate) fn list(names: impl Iterator<Item = String>) -> String {
    let v: Vec<String> = names.collect();
    if v.is_empty() {
        "(none)".into()
    } else {
        v.join(", ")
    }
}

fn quoted<'a>(names: impl Iterator<Item = &'a String>) -> String {
    list(names.map(|n| format!("{n:?}")))
}

/// Check and index the vectors and masses (module doc); `requested` selects speeds.
pub(crate) fn assemble(
    vectors: &[VectorInput],
    masses: &[MassInput],
    requested: Option<&[f64]>,
) -> Result<Assembled, BalanceError> {
    for v in vectors {
        check_name("run", &v.run)?;
        check_name("sensor", &v.sensor)?;
        check_value("speed_rpm", v.speed_rpm, "finite and > 0 (rev/min)", |s| {
            s > 0.0
        })?;
        check_value("re", v.value.re, "finite (sensor unit)", |_| true)?;
        check_value("im", v.value.im, "finite (sensor unit)", |_| true)?;
        if let Some(c) = &v.covariance {
            check_value("re_std^2", c[(0, 0)], "finite and >= 0", |s| s >= 0.0)?;
            check_value("im_std^2", c[(1, 1)], "finite and >= 0", |s| s >= 0.0)?;
        }
    }
    for m in masses {
        check_name("run", &m.run)?;
        check_name("plane", &m.plane)?;
        check_value("mass_kg", m.mass, "finite and >= 0 (kg)", |s| s >= 0.0)?;
        if m.mass > 0.0 {
            check_value(
                "radius_m",
                m.radius,
                "finite and > 0 (m) for a non-zero mass",
                |s| s > 0.0,
            )?;
        } else {
            check_value("radius_m", m.radius, "finite and >= 0 (m)", |s| s >= 0.0)?;
        }
        check_value("angle_deg", m.angle, "finite (deg)", |_| true)?;
    }
    let speeds: Vec<f64> = vectors.iter().map(|v| v.speed_rpm).collect();
    let (speeds_rpm, assign) = group_speeds(&speeds, requested)?;
    let at = if requested.is_some() {
        " at the speeds selected"
    } else {
        ""
    };

    let mut sensors: Vec<(String, String)> = Vec::new();
    let mut runs: Vec<String> = Vec::new();
    for v in vectors {
        match sensors.iter().find(|(s, _)| *s == v.sensor) {
            Some((_, u)) if *u != v.unit => {
                return Err(BalanceError::MixedUnits {
                    sensor: v.sensor.clone(),
                    first: u.clone(),
                    other: v.unit.clone(),
                })
            }
            Some(_) => {}
            None => sensors.push((v.sensor.clone(), v.unit.clone())),
        }
    }
    for (v, g) in vectors.iter().zip(&assign) {
        if g.is_some() && !runs.contains(&v.run) {
            runs.push(v.run.clone());
        }
    }
    let nspeed = speeds_rpm.len();
    let mut vector = vec![vec![None; runs.len()]; sensors.len() * nspeed];
    for (v, g) in vectors.iter().zip(&assign) {
        let Some(g) = *g else { continue };
        let s = sensors
            .iter()
            .position(|(n, _)| *n == v.sensor)
            .unwrap_or(0);
        let r = runs.iter().position(|n| *n == v.run).unwrap_or(0);
        let slot = &mut vector[s * nspeed + g][r];
        if slot.is_some() {
            return Err(BalanceError::Duplicate {
                run: v.run.clone(),
                sensor: v.sensor.clone(),
                speed_rpm: speeds_rpm[g],
            });
        }
        *slot = Some((v.value, v.covariance));
    }

    let mut planes: Vec<String> = Vec::new();
    let mut cal_names: Vec<String> = Vec::new();
    for m in masses {
        if !planes.contains(&m.plane) {
            planes.push(m.plane.clone());
        }
        if !cal_names.contains(&m.run) {
            cal_names.push(m.run.clone());
        }
    }
    let mut calibration = Vec::with_capacity(cal_names.len());
    for name in &cal_names {
        match runs.iter().position(|r| r == name) {
            Some(i) => calibration.push(i),
            None => {
                return Err(BalanceError::CalibrationWithoutVectors {
                    run: name.clone(),
                    at,
                })
            }
        }
    }
    let mut trial = vec![vec![Complex::new(0.0, 0.0); planes.len()]; cal_names.len()];
    let mut radii = vec![Vec::new(); planes.len()];
    for m in masses {
        let c = cal_names.iter().position(|n| *n == m.run).unwrap_or(0);
        let p = planes.iter().position(|n| *n == m.plane).unwrap_or(0);
        trial[c][p] += m.unbalance();
        if m.mass > 0.0 {
            radii[p].push(m.radius);
        }
    }
    for (p, name) in planes.iter().enumerate() {
        if trial.iter().all(|t| t[p].norm() == 0.0) {
            return Err(BalanceError::PlaneWithoutMass {
                plane: name.clone(),
            });
        }
    }
    Ok(Assembled {
        sensors,
        speeds_rpm,
        planes,
        runs,
        calibration,
        trial,
        radii,
        vector,
    })
}

/// The index of each of `names` in `known` (the option `option` names `what`s).
pub(crate) fn resolve<'a>(
    option: &'static str,
    what: &'static str,
    names: impl Iterator<Item = &'a str>,
    known: &[String],
) -> Result<Vec<usize>, BalanceError> {
    names
        .map(|n| {
            known
                .iter()
                .position(|k| k == n)
                .ok_or_else(|| BalanceError::UnknownName {
                    option,
                    what,
                    name: n.to_owned(),
                    known: quoted(known.iter()),
                })
        })
        .collect()
}

/// The known run names for a message.
pub(crate) fn run_list(a: &Assembled) -> String {
    quoted(a.runs.iter())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn speeds_within_one_percent_are_one_group() {
        let (g, a) = group_speeds(&[1200.0, 1203.0, 3000.0, 1198.9 + 0.1], None).unwrap();
        assert_eq!(g.len(), 2);
        assert!((g[0] - (1200.0 + 1203.0 + 1199.0) / 3.0).abs() < 1e-9);
        assert_eq!(a, vec![Some(0), Some(0), Some(1), Some(0)]);
        let (g, a) = group_speeds(&[1200.0, 1250.0, 3000.0], Some(&[3010.0, 1201.0])).unwrap();
        assert_eq!(g, vec![1201.0, 3010.0]);
        assert_eq!(a, vec![Some(0), None, Some(1)]);
        let e = group_speeds(&[1200.0], Some(&[1500.0])).unwrap_err();
        assert_eq!(
            e.to_string(),
            "no 1X vector at 1500 rpm (within 1 %): the vectors are at 1200 rpm"
        );
    }
}
