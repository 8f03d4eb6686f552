//! Unbalance response against speed: the steady state at each constant speed W (the same
//! closed form as `simulate::steady_state`, here with its uncertainty). With the unbalance
//! as the complex number U = u_c + i u_s = m_u d e^{i alpha} \[kg m\],
//!
//! ```text
//! q(t) = Re( P e^{i phi} ),   P = U h(W),   h(W) = D^-1 W^2 (-i, 1)^T
//! D = K1 - W^2 M + i W (C1 + W C2)                       (complex 2x2)
//! C1 = [[cx, cxz], [czx, cz]],  K1 = [[kx, kxz], [kzx, kz]]  (cross terms 0: Jeffcott)
//! ```
//!
//! (D P = W^2 (-i, 1) U is eq. (1) with q = Re(P e^{i phi}), phi = W t + phi0.) A probe at
//! angle theta from +z (vertical up) in the direction of rotation reads
//! s = n . q, n = (sin theta, cos theta): theta = 0 is a vertical probe (z), theta = 90 deg a
//! horizontal one (x). Its 1X vector is V = n . P, s = Re(V e^{i phi}) = |V| cos(phi - beta):
//! amplitude |V| (peak; peak-to-peak is twice that) and phase lag beta = -arg V in
//! \[0, 2 pi), the shaft angle from the keyphasor (phi = 0) to the positive peak of the
//! signal (API 684 / Bently convention of phase lag). Well below the first critical speed
//! the response follows the force, beta = theta - alpha; through a critical speed the lag
//! grows by about 180 degrees.
//!
//! Uncertainty (delta method, covariance module), from the derivatives
//!
//! ```text
//! dP/dtheta = -D^-1 (dD/dtheta) P            (theta = m, cx, kx, cz, kz, a, cxz, czx, kxz, kzx)
//! dD/dm = -W^2 I   dD/dcx = i W E_11   dD/dkx = E_11   (cz, kz: E_22)   dD/da = i W^2 J
//! dD/dcxz = i W E_12   dD/dkxz = E_12   (czx, kzx: E_21)
//! dP/du_c = h,     dP/du_s = i h
//! d|V| = Re(conj(V) dV) / |V|,     d beta = -Im(conj(V) dV) / |V|^2
//! ```
//!
//! D is singular only for an undamped rotor exactly at a critical speed: then there is no
//! bounded response and the vector is `None`. References: Lalanne & Ferraris (1998),
//! ch. 2 (unbalance response of the simple rotor); API Standard 684, 2nd ed., 2005,
//! sec. 2.7 (Bode and polar plots).

use nalgebra::{Complex, Matrix2, Vector2};

use crate::model::{check, RotorParams};

use super::covariance::{
    std_of, values, CovarianceParameter, Gradient, ParameterCovariance, NPARAM,
};
use super::error::{check_params, check_speeds, AnalysisError};
use super::modes::C64;

/// A displacement probe in the x-z plane (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Probe {
    /// Angle theta \[rad\] from +z (vertical up) in the direction of rotation.
    pub angle: f64,
}

impl Probe {
    /// The vertical probe: it reads z.
    pub const Z: Probe = Probe { angle: 0.0 };
    /// The horizontal probe: it reads x.
    pub const X: Probe = Probe {
        angle: std::f64::consts::FRAC_PI_2,
    };

    /// The unit vector n = (sin theta, cos theta) in (x, z). x and z are exact (0, 1),
    /// (1, 0) rather than the rounding of sin and cos at pi/2.
    pub(crate) fn direction(&self) -> (f64, f64) {
        if *self == Probe::X {
            (1.0, 0.0)
        } else if *self == Probe::Z {
            (0.0, 1.0)
        } else {
            self.angle.sin_cos()
        }
    }
}

/// A 1X vector with its uncertainty.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResponseVector {
    /// V \[m\]: the signal is Re(V e^{i phi}).
    pub vector: C64,
    /// |V| \[m\], peak (zero-to-peak).
    pub amplitude: f64,
    /// Phase lag beta = -arg V \[rad\] in \[0, 2 pi); `None` when the amplitude is 0.
    pub phase_lag: Option<f64>,
    /// Standard deviation of the amplitude \[m\] (module doc); `None` without a covariance
    /// or when it depends on an undetermined parameter.
    pub std_amplitude: Option<f64>,
    /// Standard deviation of the phase lag \[rad\]; `None` likewise or at zero amplitude.
    pub std_phase_lag: Option<f64>,
}

impl ResponseVector {
    /// The vector `v` and its gradient `dv` (per parameter), under `cov`.
    fn new(v: C64, dv: &[C64; NPARAM], cov: Option<&ParameterCovariance>) -> Self {
        let amplitude = v.norm();
        let (phase_lag, std_amplitude, std_phase_lag) = if amplitude > 0.0 {
            let g_amp: Gradient = dv.map(|d| (v.conj() * d).re / amplitude);
            let g_lag: Gradient = dv.map(|d| -(v.conj() * d).im / (amplitude * amplitude));
            (Some(phase_lag(v)), std_of(cov, &g_amp), std_of(cov, &g_lag))
        } else {
            // |V| is not differentiable at 0: its spread is that of |dV|, first order
            let g_re: Gradient = dv.map(|d| d.re);
            let g_im: Gradient = dv.map(|d| d.im);
            let s = match (std_of(cov, &g_re), std_of(cov, &g_im)) {
                (Some(a), Some(b)) => Some(a.hypot(b)),
                _ => None,
            };
            (None, s, None)
        };
        Self {
            vector: v,
            amplitude,
            phase_lag,
            std_amplitude,
            std_phase_lag,
        }
    }
}

/// -arg v wrapped to \[0, 2 pi).
pub(crate) fn phase_lag(v: C64) -> f64 {
    wrap(-v.arg())
}

/// An angle \[rad\] wrapped to \[0, 2 pi) (a tiny negative angle goes to 0, not to 2 pi).
pub(crate) fn wrap(angle: f64) -> f64 {
    let b = angle.rem_euclid(std::f64::consts::TAU);
    if b >= std::f64::consts::TAU {
        0.0
    } else {
        b
    }
}

/// The response of one probe over the speeds.
#[derive(Debug, Clone, PartialEq)]
pub struct ResponseChannel {
    /// The probe.
    pub probe: Probe,
    /// Per speed, its 1X vector; `None` where there is no bounded steady state.
    pub points: Vec<Option<ResponseVector>>,
}

/// The unbalance response over a speed grid.
#[derive(Debug, Clone, PartialEq)]
pub struct UnbalanceResponse {
    /// The speeds W \[rad/s\].
    pub speeds: Vec<f64>,
    /// One channel per probe, in the order asked for.
    pub channels: Vec<ResponseChannel>,
}

/// The response per unit unbalance h(W) \[m / (kg m)\] and D^-1, or `None` when D is
/// singular.
pub(crate) fn transfer(p: &RotorParams, w: f64) -> Option<(Vector2<C64>, Matrix2<C64>)> {
    let i = Complex::new(0.0, 1.0);
    let c = |re: f64, im: f64| Complex::new(re, im);
    let x = p.cross();
    let d = Matrix2::new(
        c(p.kx - p.m * w * w, w * p.cx),
        c(x.kxz, w * x.cxz - p.a * w * w),
        c(x.kzx, w * x.czx + p.a * w * w),
        c(p.kz - p.m * w * w, w * p.cz),
    );
    let det = d[(0, 0)] * d[(1, 1)] - d[(0, 1)] * d[(1, 0)];
    if det.norm() == 0.0 || !det.norm().is_finite() {
        return None;
    }
    let inv = Matrix2::new(d[(1, 1)], -d[(0, 1)], -d[(1, 0)], d[(0, 0)]) / det;
    let f = Vector2::new(-i, c(1.0, 0.0)) * c(w * w, 0.0);
    let h = inv * f;
    h.iter()
        .all(|z| z.re.is_finite() && z.im.is_finite())
        .then_some((h, inv))
}

/// P = U h and its derivatives dP/dtheta at speed `w`, or `None` when D is singular.
pub(crate) fn response_and_gradient(
    p: &RotorParams,
    w: f64,
) -> Option<(Vector2<C64>, [Vector2<C64>; NPARAM])> {
    let (h, inv) = transfer(p, w)?;
    let v = values(p);
    let u = Complex::new(
        v[CovarianceParameter::MudCosAlpha.index()],
        v[CovarianceParameter::MudSinAlpha.index()],
    );
    let pv = h * u;
    let zero = Complex::new(0.0, 0.0);
    let i = Complex::new(0.0, 1.0);
    let e11 = Matrix2::new(Complex::new(1.0, 0.0), zero, zero, zero);
    let e22 = Matrix2::new(zero, zero, zero, Complex::new(1.0, 0.0));
    let j = Matrix2::new(zero, -Complex::new(1.0, 0.0), Complex::new(1.0, 0.0), zero);
    let dp = |dd: Matrix2<C64>| -(inv * dd * pv);
    let mut g = [Vector2::new(zero, zero); NPARAM];
    g[CovarianceParameter::M.index()] = dp(Matrix2::identity() * Complex::new(-w * w, 0.0));
    g[CovarianceParameter::Cx.index()] = dp(e11 * (i * w));
    g[CovarianceParameter::Kx.index()] = dp(e11);
    g[CovarianceParameter::Cz.index()] = dp(e22 * (i * w));
    g[CovarianceParameter::Kz.index()] = dp(e22);
    g[CovarianceParameter::A.index()] = dp(j * (i * w * w));
    let e12 = Matrix2::new(zero, Complex::new(1.0, 0.0), zero, zero);
    let e21 = Matrix2::new(zero, zero, Complex::new(1.0, 0.0), zero);
    g[CovarianceParameter::Cxz.index()] = dp(e12 * (i * w));
    g[CovarianceParameter::Czx.index()] = dp(e21 * (i * w));
    g[CovarianceParameter::Kxz.index()] = dp(e12);
    g[CovarianceParameter::Kzx.index()] = dp(e21);
    g[CovarianceParameter::MudCosAlpha.index()] = h;
    g[CovarianceParameter::MudSinAlpha.index()] = h * i;
    Some((pv, g))
}

/// The 1X vector of `probe` at speed `w` \[rad/s\], with its uncertainty under `cov`.
pub(crate) fn probe_response(
    p: &RotorParams,
    cov: Option<&ParameterCovariance>,
    w: f64,
    probe: Probe,
) -> Option<ResponseVector> {
    let (pv, g) = response_and_gradient(p, w)?;
    let (nx, nz) = probe.direction();
    let v = pv[0] * nx + pv[1] * nz;
    let dv = g.map(|d| d[0] * nx + d[1] * nz);
    Some(ResponseVector::new(v, &dv, cov))
}

/// The unbalance response of `p` at every speed of `speeds` \[rad/s\] (finite, >= 0,
/// strictly increasing, at least one) for each probe (angles finite), with standard
/// deviations under `cov` (module doc).
pub fn unbalance_response(
    p: &RotorParams,
    cov: Option<&ParameterCovariance>,
    speeds: &[f64],
    probes: &[Probe],
) -> Result<UnbalanceResponse, AnalysisError> {
    check_params(p)?;
    check_speeds(speeds, 1)?;
    for pr in probes {
        check("probe angle", pr.angle, "finite (rad)", |_| true)?;
    }
    let channels = probes
        .iter()
        .map(|&probe| ResponseChannel {
            probe,
            points: speeds
                .iter()
                .map(|&w| probe_response(p, cov, w, probe))
                .collect(),
        })
        .collect();
    Ok(UnbalanceResponse {
        speeds: speeds.to_vec(),
        channels,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::{Rotor, Unbalance};

    fn from_values(p: &RotorParams, v: &Gradient) -> RotorParams {
        let mud = v[6].hypot(v[7]);
        RotorParams {
            coupling: None,
            m: v[0],
            cx: v[1],
            kx: v[2],
            cz: v[3],
            kz: v[4],
            a: v[5],
            unbalance: Unbalance {
                m_u: mud / p.unbalance.d,
                d: p.unbalance.d,
                alpha: v[7].atan2(v[6]),
            },
        }
    }

    #[test]
    fn derivatives_match_central_differences() {
        let mut p = Rotor::table1().params();
        p.kz *= 1.2;
        p.cx = 300.0;
        let w = 280.0;
        let (_, g) = response_and_gradient(&p, w).unwrap();
        let v = values(&p);
        // the Jeffcott parameters (the cross terms: the next test)
        for k in 0..8 {
            let h = 1e-6 * v[k].abs();
            let (mut up, mut dn) = (v, v);
            up[k] += h;
            dn[k] -= h;
            let pu = response_and_gradient(&from_values(&p, &up), w).unwrap().0;
            let pd = response_and_gradient(&from_values(&p, &dn), w).unwrap().0;
            let fd = (pu - pd) / Complex::new(2.0 * h, 0.0);
            assert!(
                (fd - g[k]).norm() < 1e-6 * g[k].norm(),
                "parameter {k}: {fd} vs {}",
                g[k]
            );
        }
    }

    #[test]
    fn cross_coupled_derivatives_match_central_differences() {
        let mut p = crate::test_models::cross_coupled_rotor();
        p.coupling = Some(crate::model::CrossCoupling {
            cxz: 20.0,
            czx: -12.0,
            kxz: -3.0e4,
            kzx: 4.0e4,
        });
        for w in [150.0, 280.0, 320.0] {
            let (_, g) = response_and_gradient(&p, w).unwrap();
            let v = values(&p);
            for k in 0..NPARAM {
                let h = 1e-6 * v[k].abs();
                let (mut up, mut dn) = (v, v);
                up[k] += h;
                dn[k] -= h;
                let at =
                    |v| response_and_gradient(&super::super::covariance::with_values(&p, v), w);
                let fd = (at(&up).unwrap().0 - at(&dn).unwrap().0) / Complex::new(2.0 * h, 0.0);
                assert!(
                    (fd - g[k]).norm() < 1e-6 * g[k].norm(),
                    "W {w} parameter {k}: {fd} vs {}",
                    g[k]
                );
            }
        }
    }

    #[test]
    fn undamped_rotor_at_resonance_has_no_vector() {
        let mut p = Rotor::table1().params();
        (p.cx, p.cz, p.a) = (0.0, 0.0, 0.0);
        p.kx = p.m * 300.0 * 300.0;
        assert_eq!(probe_response(&p, None, 300.0, Probe::X), None);
        assert!(probe_response(&p, None, 299.0, Probe::X).is_some());
    }
}
