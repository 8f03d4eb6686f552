//! Where the rotor angle phi [rad], speed w = phi' [rad/s] and acceleration w' = phi''
//! [rad/s^2] come from: the response CSV's phi, phi_dot, phi_ddot columns when it has
//! them, else the scenario's `[speed]` profile evaluated at each row's t
//! (`constant: phi = phi0 + W t`; `ramp: phi = phi0 + w0 t + A t^2 / 2`, method.md
//! section 1).
//!
//! For the refinement (whose record starts at its own t = 0) the profile is shifted to the
//! first sample t_1: `w0' = w(t_1)`, `phi0' = phi(t_1)`, same acceleration. Measured
//! speed columns that describe an exactly constant speed (w' = 0 and w = W at every row,
//! phi = phi_1 + W (t - t_1) to 1e-9 rad) are handed over as that constant profile, which
//! lets `rotorid::refine` use its exact (matrix-exponential) discretisation instead of RK4
//! on the interpolated samples; any other speed data is used sample by sample.

use rotorid::refine::SpeedData;
use rotorid::{SpeedProfile, SpeedState};

use super::Context;
use crate::io::ResponseRow;

/// The speed of the streaming methods: from the row or from the scenario's profile.
pub(crate) struct SpeedSource {
    profile: Option<SpeedProfile>,
}

impl SpeedSource {
    /// From the data when `has_phi`, else the scenario's profile (an error names both
    /// remedies when there is neither).
    pub fn new(ctx: &Context, has_phi: bool) -> anyhow::Result<Self> {
        if has_phi {
            return Ok(Self { profile: None });
        }
        match ctx.view.speed {
            Some(p) => Ok(Self { profile: Some(p) }),
            None => anyhow::bail!(
                "{} has no phi, phi_dot, phi_ddot columns and the scenario {} has no \
                 [speed] section: give the rotor angle in the data or the speed profile in \
                 the scenario",
                ctx.name,
                ctx.spec.origin()
            ),
        }
    }

    /// The scenario's profile, when the speed comes from it.
    pub fn profile(&self) -> Option<SpeedProfile> {
        self.profile
    }

    /// phi, w, w' at `row`.
    pub fn at(&self, row: &ResponseRow) -> SpeedState {
        match (row.speed, self.profile) {
            (Some(s), _) => s,
            (None, Some(p)) => p.at(row.t),
            (None, None) => SpeedState::default(),
        }
    }
}

/// `p` re-based so that its t = 0 is `t1` [s].
pub(crate) fn shifted(p: SpeedProfile, t1: f64) -> SpeedProfile {
    let s = p.at(t1);
    match p {
        SpeedProfile::Constant { omega, .. } => SpeedProfile::Constant { omega, phi0: s.phi },
        SpeedProfile::Ramp { accel, .. } => SpeedProfile::Ramp {
            omega0: s.omega,
            accel,
            phi0: s.phi,
        },
    }
}

/// Largest deviation [rad] of measured phi from phi_1 + W (t - t_1) for which per-sample
/// data still counts as an exactly constant speed (the rounding of phi ~ 1e3 rad written
/// in shortest round-trip form is ~1e-13 rad).
pub(crate) const CONSTANT_PHI_TOLERANCE: f64 = 1e-9;

/// Measured speed columns of a whole record, each as long as the record [rad, rad/s,
/// rad/s^2].
#[derive(Debug, Default)]
pub(crate) struct SpeedColumns {
    pub phi: Vec<f64>,
    pub omega: Vec<f64>,
    pub omega_dot: Vec<f64>,
}

impl SpeedColumns {
    /// The record's speed: the constant profile when the columns are exactly constant
    /// speed (module doc), else the samples. `t` are the rows' times [s].
    pub fn speed_data<'a>(&'a self, t: &[f64]) -> SpeedData<'a> {
        match self.constant(t) {
            Some(p) => SpeedData::Profile(p),
            None => SpeedData::Samples {
                phi: &self.phi,
                omega: &self.omega,
                omega_dot: &self.omega_dot,
            },
        }
    }

    /// The constant profile the columns describe, if they do (module doc).
    fn constant(&self, t: &[f64]) -> Option<SpeedProfile> {
        let (&w, &phi1, &t1) = (self.omega.first()?, self.phi.first()?, t.first()?);
        let constant = self.omega.iter().all(|&v| v == w)
            && self.omega_dot.iter().all(|&v| v == 0.0)
            && self
                .phi
                .iter()
                .zip(t)
                .all(|(&p, &ti)| (p - (phi1 + w * (ti - t1))).abs() <= CONSTANT_PHI_TOLERANCE);
        constant.then_some(SpeedProfile::Constant {
            omega: w,
            phi0: phi1,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shifted_profiles_agree_with_the_original() {
        for p in [
            SpeedProfile::constant_rpm(1200.0, 0.3).unwrap(),
            SpeedProfile::ramp(600.0, 10.0, 0.5).unwrap(),
        ] {
            let q = shifted(p, 0.7);
            for t in [0.0, 0.1, 1.3] {
                let (a, b) = (p.at(0.7 + t), q.at(t));
                assert!((a.phi - b.phi).abs() < 1e-12 * a.phi.abs());
                assert!((a.omega - b.omega).abs() < 1e-12 * a.omega.abs());
                assert_eq!(a.omega_dot, b.omega_dot);
            }
        }
    }

    #[test]
    fn only_exactly_constant_columns_become_a_profile() {
        let t: Vec<f64> = (0..5).map(|i| 0.2 + f64::from(i) * 1e-4).collect();
        let w = 125.66370614359172;
        let mut c = SpeedColumns {
            phi: t.iter().map(|ti| 1.0 + w * (ti - 0.2)).collect(),
            omega: vec![w; 5],
            omega_dot: vec![0.0; 5],
        };
        assert_eq!(
            c.speed_data(&t),
            SpeedData::Profile(SpeedProfile::Constant {
                omega: w,
                phi0: 1.0
            })
        );
        c.phi[3] += 1e-6; // an angle that does not follow the constant speed
        assert!(matches!(c.speed_data(&t), SpeedData::Samples { .. }));
        c.phi[3] -= 1e-6;
        c.omega_dot[2] = 1e-3;
        assert!(matches!(c.speed_data(&t), SpeedData::Samples { .. }));
    }
}
