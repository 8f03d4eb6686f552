//! Single-plane balancing, two ways (the forms `rotorid balance` had first). Angles on the rotor (the unbalance alpha, a trial
//! mass, the correction) are shaft angles measured from the keyphasor reference (phi = 0)
//! in the direction of rotation; an unbalance is the complex number m_u d e^{i angle}
//! \[kg m\], and masses at one plane add as such numbers.
//!
//! (a) From the identified unbalance U = u_c + i u_s (model-based). A mass m_c at radius
//! R and angle beta cancels it when
//!
//! ```text
//! m_c R e^{i beta} = -U:     m_c = |U| / R,     beta = arg U + pi  (= alpha + 180 deg)
//! std(m_c) = std(|U|) / R,   std(beta) = std(arg U)      (delta method on (u_c, u_s), as refine reports m_u d and alpha)
//! ```
//!
//! The estimate's error dU remains. Its expected size is
//! sqrt(E|dU|^2) = sqrt(var u_c + var u_s), and since the response is U h(W) (response
//! module) the predicted 1X amplitude after the correction is |n . h(W)| sqrt(var u_c +
//! var u_s) at every speed and probe: the 1X amplitude is reduced by the factor
//! |U| / sqrt(var u_c + var u_s).
//!
//! (b) Influence coefficients from two runs at one speed (for users who trust measurements
//! more than models): the reference run's 1X vectors V0_j (j = x, z) and those of a run
//! with a known trial unbalance T = m_t R_t e^{i beta_t} added, V1_j:
//!
//! ```text
//! H_j = (V1_j - V0_j) / T                                       [m / (kg m)]
//! C = argmin sum_j |V0_j + H_j C|^2 = -sum_j conj(H_j) V0_j / sum_j |H_j|^2
//! m_c = |C| / R,   beta = arg C,   predicted residual 1X vectors r_j = V0_j + H_j C
//! ```
//!
//! (least squares over both directions; the trial mass is removed before the correction
//! is fitted). This is the one-plane, two-sensor, one-speed case of the multi-plane
//! computation (parent module): the same fit, correction and delta-method standard
//! deviations, from the four 1X vectors' covariances (one_x module; the vectors
//! independent).
//! References: ISO 21940-11 (rigid-rotor balancing); Thearle, "Dynamic balancing of
//! rotating machinery in the field", Trans. ASME 56, 1934 (influence coefficients);
//! Lalanne & Ferraris (1998), ch. 7.

use nalgebra::{Complex, Matrix2};

use super::data::{MassInput, VectorInput};
use super::multi::{balance, BalanceOptions};

use crate::model::{check, RotorParams};

use crate::analysis::covariance::{
    values, CovarianceParameter, Gradient, ParameterCovariance, NPARAM,
};
use crate::analysis::error::{check_params, check_speed, AnalysisError};
use crate::analysis::modes::C64;
use crate::analysis::one_x::OneX;
use crate::analysis::response::{transfer, wrap, Probe};

/// A correction mass at one plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Correction {
    /// The mass m_c \[kg\].
    pub mass: f64,
    /// Its angle beta \[rad\] in \[0, 2 pi), a shaft angle from the keyphasor reference in
    /// the direction of rotation (the frame of alpha); 0 when the mass is 0.
    pub angle: f64,
    /// The radius R it is placed at \[m\].
    pub radius: f64,
    /// Standard deviation of the mass \[kg\]; `None` without a covariance or when it
    /// depends on an undetermined quantity.
    pub std_mass: Option<f64>,
    /// Standard deviation of the angle \[rad\]; `None` likewise or for a zero mass.
    pub std_angle: Option<f64>,
}

impl Correction {
    /// The correction unbalance m_c R e^{i beta} \[kg m\].
    pub fn unbalance(&self) -> C64 {
        Complex::from_polar(self.mass * self.radius, self.angle)
    }

    /// The correction for the unbalance `c` \[kg m\] at `radius` \[m\], with the covariance
    /// `cov` of (Re c, Im c) \[kg^2 m^2\] when known.
    pub(crate) fn new(c: C64, radius: f64, cov: Option<Matrix2<f64>>) -> Self {
        let size = c.norm();
        let angle = if size > 0.0 { wrap(c.arg()) } else { 0.0 };
        let quad = |g: [f64; 2], s: &Matrix2<f64>| {
            let v = g[0] * g[0] * s[(0, 0)]
                + g[0] * g[1] * (s[(0, 1)] + s[(1, 0)])
                + g[1] * g[1] * s[(1, 1)];
            v.is_finite().then(|| v.max(0.0).sqrt())
        };
        let (std_mass, std_angle) = match cov {
            Some(s) if size > 0.0 => (
                quad([c.re / size, c.im / size], &s).map(|v| v / radius),
                quad([-c.im / (size * size), c.re / (size * size)], &s),
            ),
            Some(s) => (
                quad([1.0, 0.0], &s)
                    .zip(quad([0.0, 1.0], &s))
                    .map(|(a, b)| a.max(b) / radius),
                None,
            ),
            None => (None, None),
        };
        Self {
            mass: size / radius,
            angle,
            radius,
            std_mass,
            std_angle,
        }
    }
}

/// The correction of an identified unbalance (module doc, (a)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModelBalance {
    /// The correction mass and angle.
    pub correction: Correction,
    /// The predicted residual unbalance sqrt(var u_c + var u_s) \[kg m\]; `None` without
    /// a covariance of u_c, u_s or when they are undetermined.
    pub residual_unbalance: Option<f64>,
    /// The predicted reduction of the 1X amplitude, |U| / residual (dimensionless).
    pub reduction: Option<f64>,
}

/// The correction mass at `radius` \[m\] (finite, > 0) that cancels the unbalance of `p`,
/// with its uncertainty and the predicted residual under `cov` (module doc, (a)).
pub fn balance_from_unbalance(
    p: &RotorParams,
    cov: Option<&ParameterCovariance>,
    radius: f64,
) -> Result<ModelBalance, AnalysisError> {
    check_params(p)?;
    check("radius", radius, "finite and > 0 (m)", |v| v > 0.0)?;
    let v = values(p);
    let u = Complex::new(
        v[CovarianceParameter::MudCosAlpha.index()],
        v[CovarianceParameter::MudSinAlpha.index()],
    );
    let unit = |q: CovarianceParameter| {
        let mut g: Gradient = [0.0; NPARAM];
        g[q.index()] = 1.0;
        g
    };
    let (gc, gs) = (
        unit(CovarianceParameter::MudCosAlpha),
        unit(CovarianceParameter::MudSinAlpha),
    );
    let uu = cov.and_then(|c| {
        Some(Matrix2::new(
            c.propagate_pair(&gc, &gc)?,
            c.propagate_pair(&gc, &gs)?,
            c.propagate_pair(&gs, &gc)?,
            c.propagate_pair(&gs, &gs)?,
        ))
    });
    let residual_unbalance = uu.map(|s| s.trace().max(0.0).sqrt());
    let reduction = residual_unbalance
        .filter(|&r| r > 0.0)
        .map(|r| u.norm() / r);
    Ok(ModelBalance {
        correction: Correction::new(-u, radius, uu),
        residual_unbalance,
        reduction,
    })
}

/// The 1X vector \[m\] that a unit unbalance (1 kg m at angle 0) causes at `probe` at
/// speed `omega` \[rad/s\]: n . h(W) (response module); `None` when D is singular.
pub fn response_per_unbalance(
    p: &RotorParams,
    omega: f64,
    probe: Probe,
) -> Result<Option<C64>, AnalysisError> {
    check_params(p)?;
    check_speed(omega)?;
    let (nx, nz) = probe.direction();
    Ok(transfer(p, omega).map(|(h, _)| h[0] * nx + h[1] * nz))
}

/// The 1X vectors of x and z in one run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunVectors {
    /// Horizontal displacement x \[m\].
    pub x: OneX,
    /// Vertical displacement z \[m\].
    pub z: OneX,
}

/// A trial mass.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrialMass {
    /// Its mass m_t \[kg\], > 0.
    pub mass: f64,
    /// Its radius R_t \[m\], > 0.
    pub radius: f64,
    /// Its angle beta_t \[rad\] (shaft angle, the frame of alpha).
    pub angle: f64,
}

/// The influence-coefficient correction (module doc, (b)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InfluenceBalance {
    /// The correction mass and angle (standard deviations from the 1X vectors').
    pub correction: Correction,
    /// Influence coefficients (H_x, H_z) \[m / (kg m)\].
    pub influence: [C64; 2],
    /// Predicted residual 1X vectors after the correction (x, z) \[m\].
    pub residual: [C64; 2],
    /// The reference run's 1X vectors (x, z) \[m\], for comparison.
    pub before: [C64; 2],
}

/// The correction at `radius` \[m\] (finite, > 0) from a reference run and a trial run
/// with `trial` added, at the same speed (module doc, (b)); `Ok(None)` when the trial
/// mass changed neither 1X vector (no influence coefficient). This is the one-plane,
/// two-sensor, one-speed case of [`balance`](super::balance): the influence coefficients
/// fitted to the two runs, the least-squares correction of the reference run, and its
/// standard deviations from the four vectors' covariances.
pub fn balance_from_runs(
    reference: &RunVectors,
    trial_run: &RunVectors,
    trial: &TrialMass,
    radius: f64,
) -> Result<Option<InfluenceBalance>, AnalysisError> {
    check("radius", radius, "finite and > 0 (m)", |v| v > 0.0)?;
    check("trial mass", trial.mass, "finite and > 0 (kg)", |v| v > 0.0)?;
    check("trial radius", trial.radius, "finite and > 0 (m)", |v| {
        v > 0.0
    })?;
    check("trial angle", trial.angle, "finite (rad)", |_| true)?;
    let t = Complex::from_polar(trial.mass * trial.radius, trial.angle);
    let h = [
        (trial_run.x.vector - reference.x.vector) / t,
        (trial_run.z.vector - reference.z.vector) / t,
    ];
    let s = h[0].norm_sqr() + h[1].norm_sqr();
    // NaN fails `s > 0.0`, so a NaN sum is rejected too
    if !(s.is_finite() && s > 0.0) {
        return Ok(None);
    }
    let mut vectors = Vec::with_capacity(4);
    for (run, rv) in [(REFERENCE, reference), (TRIAL, trial_run)] {
        for (sensor, o) in [("x", rv.x), ("z", rv.z)] {
            vectors.push(VectorInput {
                run: run.into(),
                speed_rpm: 1.0,
                sensor: sensor.into(),
                unit: "m".into(),
                value: o.vector,
                covariance: Some(o.covariance),
            });
        }
    }
    let masses = [
        MassInput {
            run: REFERENCE.into(),
            plane: PLANE.into(),
            mass: 0.0,
            radius: trial.radius,
            angle: 0.0,
        },
        MassInput {
            run: TRIAL.into(),
            plane: PLANE.into(),
            mass: trial.mass,
            radius: trial.radius,
            angle: trial.angle,
        },
    ];
    let opts = BalanceOptions {
        current: REFERENCE.into(),
        default_radius: Some(radius),
        ..BalanceOptions::default()
    };
    let b = balance(&vectors, &masses, &opts)?;
    let fit = |sensor: usize| {
        b.fits
            .iter()
            .find(|k| k.sensor == sensor)
            .map_or(h[sensor], |k| k.fit.h[0])
    };
    let residual = |sensor: usize| {
        b.residual
            .iter()
            .find(|r| r.sensor == sensor)
            .map_or(Complex::new(f64::NAN, f64::NAN), |r| r.after)
    };
    Ok(Some(InfluenceBalance {
        correction: b.corrections[0].correction,
        influence: [fit(0), fit(1)],
        residual: [residual(0), residual(1)],
        before: [reference.x.vector, reference.z.vector],
    }))
}

/// The run names, plane and speed of [`balance_from_runs`] as a multi-plane problem.
const REFERENCE: &str = "reference";
const TRIAL: &str = "trial";
const PLANE: &str = "1";

#[cfg(test)]
mod tests {
    use super::*;

    fn vec1x(v: C64) -> OneX {
        OneX {
            vector: v,
            amplitude: v.norm(),
            phase_lag: 0.0,
            offset: 0.0,
            covariance: Matrix2::identity() * 1e-20,
            residual_rms: 0.0,
            samples: 100,
        }
    }

    #[test]
    fn influence_coefficients_recover_a_known_unbalance() {
        // a linear rotor: V_j = H_j U with different H per direction
        let hx = Complex::new(2e-3, -1e-3);
        let hz = Complex::new(-5e-4, 3e-3);
        let u0 = Complex::from_polar(1.5e-5, 0.7);
        let trial = TrialMass {
            mass: 2e-4,
            radius: 0.1,
            angle: 2.0,
        };
        let t = Complex::from_polar(2e-5, 2.0);
        let run = |u: C64| RunVectors {
            x: vec1x(hx * u),
            z: vec1x(hz * u),
        };
        let b = balance_from_runs(&run(u0), &run(u0 + t), &trial, 0.15)
            .unwrap()
            .unwrap();
        let want = -u0;
        assert!((b.correction.unbalance() - want).norm() < 1e-12 * want.norm());
        assert!(b
            .residual
            .iter()
            .all(|r| r.norm() < 1e-12 * (hx * u0).norm()));
        assert!(b.correction.std_mass.is_some() && b.correction.std_angle.is_some());
        // a trial that changes nothing has no influence coefficient
        assert_eq!(
            balance_from_runs(&run(u0), &run(u0), &trial, 0.15).unwrap(),
            None
        );
    }
}
