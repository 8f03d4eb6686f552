//! One record of measured (or simulated) response: time stamps, displacements x, z and the
//! rotor's speed, checked once, on a uniform [`TimeGrid`].
//!
//! The speed comes either per sample (phi \[rad\], w = phi' \[rad/s\], w' = phi''
//! \[rad/s^2\]; e.g. from a keyphasor) or as a [`SpeedProfile`] in the record's own time
//! (the scenario's `[speed]`, evaluated at t0 + i dt). The identifiers and the refinement
//! see the samples on the grid; the stamps are kept for the estimates' times.

use crate::identify::Measurement;
use crate::model::{SpeedProfile, SpeedState};
use crate::refine::SpeedData;
use crate::simulate::TimeResponse;

use super::error::PipelineError;
use super::grid::TimeGrid;

/// Largest deviation \[rad\] of per-sample phi from phi_0 + W (t - t0) for which the speed
/// counts as exactly constant (the rounding of phi ~ 1e3 rad written in shortest
/// round-trip form is ~1e-13 rad); such a record is refined with the exact
/// (matrix-exponential) discretisation instead of RK4 on interpolated samples.
pub const CONSTANT_PHI_TOLERANCE: f64 = 1e-9;

/// Where the speed of a record comes from.
#[derive(Debug, Clone, PartialEq)]
pub enum Speed {
    /// A profile in the record's time: phi(t), w(t), w'(t) at each grid time.
    Profile(SpeedProfile),
    /// Per-sample values, one per sample.
    Samples {
        /// Rotor angle phi \[rad\].
        phi: Vec<f64>,
        /// Speed w = phi' \[rad/s\].
        omega: Vec<f64>,
        /// Acceleration w' = phi'' \[rad/s^2\].
        omega_dot: Vec<f64>,
    },
}

/// Where a sample's speed comes from, as reported: `profile`, `samples`, or `samples`
/// that describe an exactly constant speed (`constant_samples`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SpeedSource {
    /// A speed profile (the scenario's).
    Profile,
    /// Per-sample phi, phi_dot, phi_ddot.
    Samples,
    /// Per-sample values of an exactly constant speed (refined exactly).
    ConstantSamples,
}

/// A validated record on a uniform grid (module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct Record {
    t: Vec<f64>,
    grid: TimeGrid,
    x: Vec<f64>,
    z: Vec<f64>,
    speed: Speed,
}

impl Record {
    /// A record from columns: stamps `t` \[s\], displacements `x`, `z` \[m\] and the speed.
    /// Checks equal lengths, finite values, and fits the grid (each stamp within
    /// `time_tolerance dt` of it, see [`TimeGrid::fit`]).
    pub fn new(
        t: Vec<f64>,
        x: Vec<f64>,
        z: Vec<f64>,
        speed: Speed,
        time_tolerance: f64,
    ) -> Result<Self, PipelineError> {
        let grid = TimeGrid::fit(&t, time_tolerance)?;
        Self::on_grid(t, grid, x, z, speed)
    }

    /// A record sampled on the given `grid` (no stamps): t_i = t0 + i dt.
    pub fn uniform(
        grid: TimeGrid,
        x: Vec<f64>,
        z: Vec<f64>,
        speed: Speed,
    ) -> Result<Self, PipelineError> {
        let t = (0..x.len()).map(|i| grid.time(i)).collect();
        Self::on_grid(t, grid, x, z, speed)
    }

    /// A simulated response with its per-sample speed columns, as `rotorid simulate`
    /// writes it (stamps t_i = i dt exactly).
    pub fn from_response(resp: &TimeResponse) -> Result<Self, PipelineError> {
        Self::new(
            resp.t.clone(),
            resp.x.clone(),
            resp.z.clone(),
            Speed::Samples {
                phi: resp.phi.clone(),
                omega: resp.phi_dot.clone(),
                omega_dot: resp.phi_ddot.clone(),
            },
            0.0,
        )
    }

    fn on_grid(
        t: Vec<f64>,
        grid: TimeGrid,
        x: Vec<f64>,
        z: Vec<f64>,
        speed: Speed,
    ) -> Result<Self, PipelineError> {
        let n = t.len();
        let mut columns: Vec<(&'static str, &[f64])> = vec![("x", &x), ("z", &z)];
        if let Speed::Samples {
            phi,
            omega,
            omega_dot,
        } = &speed
        {
            columns.extend([
                ("phi", &phi[..]),
                ("phi_dot", omega),
                ("phi_ddot", omega_dot),
            ]);
        }
        for (column, v) in &columns {
            if v.len() != n {
                return Err(PipelineError::ColumnLength {
                    column,
                    len: v.len(),
                    expected: n,
                });
            }
            if let Some(i) = v.iter().position(|v| !v.is_finite()) {
                return Err(PipelineError::NotFinite {
                    index: i,
                    field: column,
                    value: v[i],
                });
            }
        }
        Ok(Self {
            t,
            grid,
            x,
            z,
            speed,
        })
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.t.len()
    }

    /// True when the record has no sample.
    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }

    /// The grid the identifiers see.
    pub fn grid(&self) -> TimeGrid {
        self.grid
    }

    /// The stamps as given \[s\].
    pub fn t(&self) -> &[f64] {
        &self.t
    }

    /// Horizontal displacement \[m\].
    pub fn x(&self) -> &[f64] {
        &self.x
    }

    /// Vertical displacement \[m\].
    pub fn z(&self) -> &[f64] {
        &self.z
    }

    /// The speed.
    pub fn speed(&self) -> &Speed {
        &self.speed
    }

    /// phi, w, w' at sample `i` (the profile at the grid time).
    pub fn speed_at(&self, i: usize) -> SpeedState {
        match &self.speed {
            Speed::Profile(p) => p.at(self.grid.time(i)),
            Speed::Samples {
                phi,
                omega,
                omega_dot,
            } => SpeedState {
                phi: phi[i],
                omega: omega[i],
                omega_dot: omega_dot[i],
            },
        }
    }

    /// Sample `i` as the identifiers take it: on the grid.
    pub fn measurement(&self, i: usize) -> Measurement {
        Measurement {
            t: self.grid.time(i),
            x: self.x[i],
            z: self.z[i],
            speed: self.speed_at(i),
        }
    }

    /// How the speed was given, as reported.
    pub fn speed_source(&self) -> SpeedSource {
        match (&self.speed, self.constant_samples()) {
            (Speed::Profile(_), _) => SpeedSource::Profile,
            (Speed::Samples { .. }, Some(_)) => SpeedSource::ConstantSamples,
            (Speed::Samples { .. }, None) => SpeedSource::Samples,
        }
    }

    /// The record as the refinement takes it (its time starts at sample 0): the profile
    /// re-based to t0, the constant profile per-sample values describe exactly, or the
    /// samples.
    pub fn for_refine(&self) -> crate::refine::Record<'_> {
        let speed = match (&self.speed, self.constant_samples()) {
            (Speed::Profile(p), _) => SpeedData::Profile(rebased(*p, self.grid.t0)),
            (_, Some(p)) => SpeedData::Profile(p),
            (
                Speed::Samples {
                    phi,
                    omega,
                    omega_dot,
                },
                None,
            ) => SpeedData::Samples {
                phi,
                omega,
                omega_dot,
            },
        };
        crate::refine::Record {
            dt: self.grid.dt,
            x: &self.x,
            z: &self.z,
            speed,
        }
    }

    /// The constant profile (from sample 0) that per-sample values describe exactly:
    /// w' = 0 and w = W at every sample, phi = phi_0 + W (t_i - t_0) within
    /// [`CONSTANT_PHI_TOLERANCE`]; `None` otherwise.
    fn constant_samples(&self) -> Option<SpeedProfile> {
        let Speed::Samples {
            phi,
            omega,
            omega_dot,
        } = &self.speed
        else {
            return None;
        };
        let (&w, &phi0) = (omega.first()?, phi.first()?);
        let constant = omega.iter().all(|&v| v == w)
            && omega_dot.iter().all(|&v| v == 0.0)
            && phi.iter().enumerate().all(|(i, &p)| {
                (p - (phi0 + w * (self.grid.time(i) - self.grid.t0))).abs()
                    <= CONSTANT_PHI_TOLERANCE
            });
        constant.then_some(SpeedProfile::Constant { omega: w, phi0 })
    }
}

/// `p` re-based so that its t = 0 is `t0` \[s\].
pub fn rebased(p: SpeedProfile, t0: f64) -> SpeedProfile {
    let s = p.at(t0);
    match p {
        SpeedProfile::Constant { omega, .. } => SpeedProfile::Constant { omega, phi0: s.phi },
        SpeedProfile::Ramp { accel, .. } => SpeedProfile::Ramp {
            omega0: s.omega,
            accel,
            phi0: s.phi,
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rebased_profiles_agree_with_the_original() {
        for p in [
            SpeedProfile::constant_rpm(1200.0, 0.3).unwrap(),
            SpeedProfile::ramp(600.0, 10.0, 0.5).unwrap(),
        ] {
            let q = rebased(p, 0.7);
            for t in [0.0, 0.1, 1.3] {
                let (a, b) = (p.at(0.7 + t), q.at(t));
                assert!((a.phi - b.phi).abs() < 1e-12 * a.phi.abs());
                assert!((a.omega - b.omega).abs() < 1e-12 * a.omega.abs());
                assert_eq!(a.omega_dot, b.omega_dot);
            }
        }
    }

    #[test]
    fn only_exactly_constant_samples_become_a_profile() {
        let t: Vec<f64> = (0..5).map(|i| 0.2 + f64::from(i) * 1e-4).collect();
        let w = 125.66370614359172;
        let rec = |phi: Vec<f64>, omega_dot: Vec<f64>| {
            Record::new(
                t.clone(),
                vec![0.0; 5],
                vec![0.0; 5],
                Speed::Samples {
                    phi,
                    omega: vec![w; 5],
                    omega_dot,
                },
                1e-6,
            )
            .unwrap()
        };
        let phi: Vec<f64> = t.iter().map(|ti| 1.0 + w * (ti - 0.2)).collect();
        let r = rec(phi.clone(), vec![0.0; 5]);
        assert_eq!(r.speed_source(), SpeedSource::ConstantSamples);
        assert_eq!(
            r.for_refine().speed,
            SpeedData::Profile(SpeedProfile::Constant {
                omega: w,
                phi0: 1.0
            })
        );
        let mut off = phi.clone();
        off[3] += 1e-6; // an angle that does not follow the constant speed
        assert_eq!(rec(off, vec![0.0; 5]).speed_source(), SpeedSource::Samples);
        let mut acc = vec![0.0; 5];
        acc[2] = 1e-3;
        assert_eq!(rec(phi, acc).speed_source(), SpeedSource::Samples);
    }

    #[test]
    fn columns_are_checked() {
        let t = vec![0.0, 1e-4, 2e-4];
        let speed = Speed::Profile(SpeedProfile::constant_rpm(1200.0, 0.0).unwrap());
        assert!(matches!(
            Record::new(t.clone(), vec![0.0; 2], vec![0.0; 3], speed.clone(), 1e-6),
            Err(PipelineError::ColumnLength {
                column: "x",
                len: 2,
                expected: 3
            })
        ));
        assert!(matches!(
            Record::new(t, vec![0.0; 3], vec![0.0, f64::NAN, 0.0], speed, 1e-6),
            Err(PipelineError::NotFinite {
                index: 1,
                field: "z",
                ..
            })
        ));
    }
}
