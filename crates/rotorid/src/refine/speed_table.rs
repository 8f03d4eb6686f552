//! The known forcing of the model, tabulated once per fit (it does not depend on the
//! parameters): at every time the integrator evaluates, the speed w, the acceleration w'
//! and the four unbalance "shape" functions, with which the force of eq. (1) is linear in
//! (u_c, u_s) = (m_u d cos alpha, m_u d sin alpha):
//!
//! ```text
//! F_x = u_c (w^2 sin phi - w' cos phi) + u_s (w^2 cos phi + w' sin phi) = u_c g_xc + u_s g_xs
//! F_z = u_c (w' sin phi + w^2 cos phi) + u_s (w' cos phi - w^2 sin phi) = u_c g_zc + u_s g_zs
//! ```
//!
//! Per-sample speed data is interpolated with the quintic Hermite polynomial matching
//! (phi, w, w') at both ends of the sample interval (h = dt, u = (t - t_k)/h):
//!
//! ```text
//! phi(u) = phi_k + (phi_k+1 - phi_k) H5 + h w_k H1 + h w_k+1 H4 + h^2 w'_k H2 + h^2 w'_k+1 H3
//! H1 = u - 6u^3 + 8u^4 - 3u^5        H2 = (u^2 - 3u^3 + 3u^4 - u^5) / 2
//! H3 = (u^3 - 2u^4 + u^5) / 2        H4 = -4u^3 + 7u^4 - 3u^5        H5 = 10u^3 - 15u^4 + 6u^5
//! ```

use std::f64::consts::TAU;

use super::record::{Experiment, SpeedData};

/// Speed, acceleration and unbalance shape functions at one instant.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct ForcePoint {
    /// w \[rad/s\].
    pub w: f64,
    /// w' \[rad/s^2\].
    pub wd: f64,
    /// g_xc = w^2 sin phi - w' cos phi \[1/s^2\].
    pub gxc: f64,
    /// g_xs = w^2 cos phi + w' sin phi \[1/s^2\].
    pub gxs: f64,
    /// g_zc = w' sin phi + w^2 cos phi \[1/s^2\].
    pub gzc: f64,
    /// g_zs = w' cos phi - w^2 sin phi \[1/s^2\].
    pub gzs: f64,
}

impl ForcePoint {
    pub(crate) fn new(phi: f64, w: f64, wd: f64) -> Self {
        let (s, c) = phi.sin_cos();
        let w2 = w * w;
        Self {
            w,
            wd,
            gxc: w2 * s - wd * c,
            gxs: w2 * c + wd * s,
            gzc: wd * s + w2 * c,
            gzs: wd * c - w2 * s,
        }
    }
}

/// Quintic Hermite interpolation of phi on one interval of length `h` \[s\] at fraction
/// `u` in [0, 1]: returns (phi, phi', phi'') \[rad, rad/s, rad/s^2\].
#[allow(clippy::too_many_arguments)]
pub(crate) fn hermite5(
    p0: f64,
    d0: f64,
    dd0: f64,
    p1: f64,
    d1: f64,
    dd1: f64,
    h: f64,
    u: f64,
) -> (f64, f64, f64) {
    let (u2, u3, u4, u5) = (u * u, u * u * u, u * u * u * u, u * u * u * u * u);
    // values
    let h1 = u - 6.0 * u3 + 8.0 * u4 - 3.0 * u5;
    let h2 = 0.5 * (u2 - 3.0 * u3 + 3.0 * u4 - u5);
    let h3 = 0.5 * (u3 - 2.0 * u4 + u5);
    let h4 = -4.0 * u3 + 7.0 * u4 - 3.0 * u5;
    let h5 = 10.0 * u3 - 15.0 * u4 + 6.0 * u5;
    // first derivatives d/du
    let h1d = 1.0 - 18.0 * u2 + 32.0 * u3 - 15.0 * u4;
    let h2d = 0.5 * (2.0 * u - 9.0 * u2 + 12.0 * u3 - 5.0 * u4);
    let h3d = 0.5 * (3.0 * u2 - 8.0 * u3 + 5.0 * u4);
    let h4d = -12.0 * u2 + 28.0 * u3 - 15.0 * u4;
    let h5d = 30.0 * u2 - 60.0 * u3 + 30.0 * u4;
    // second derivatives d2/du2
    let h1dd = -36.0 * u + 96.0 * u2 - 60.0 * u3;
    let h2dd = 0.5 * (2.0 - 18.0 * u + 36.0 * u2 - 20.0 * u3);
    let h3dd = 0.5 * (6.0 * u - 24.0 * u2 + 20.0 * u3);
    let h4dd = -24.0 * u + 84.0 * u2 - 60.0 * u3;
    let h5dd = 60.0 * u - 180.0 * u2 + 120.0 * u3;
    let dp = p1 - p0;
    let hh = h * h;
    let p = p0 + dp * h5 + h * (d0 * h1 + d1 * h4) + hh * (dd0 * h2 + dd1 * h3);
    let v = dp * h5d / h + d0 * h1d + d1 * h4d + h * (dd0 * h2d + dd1 * h3d);
    let a = dp * h5dd / hh + (d0 * h1dd + d1 * h4dd) / h + dd0 * h2dd + dd1 * h3dd;
    (p, v, a)
}

/// phi with the 2 pi jumps of a wrapped angle removed: each increment is moved by a
/// multiple of 2 pi to the one closest to the trapezoidal estimate dt (w_k + w_k+1) / 2.
pub(crate) fn unwrap_phase(phi: &[f64], omega: &[f64], dt: f64) -> Vec<f64> {
    let mut out = Vec::with_capacity(phi.len());
    let mut shift = 0.0;
    for (k, &p) in phi.iter().enumerate() {
        if k > 0 {
            let expected = 0.5 * dt * (omega[k - 1] + omega[k]);
            let step = p - phi[k - 1];
            shift += ((expected - step) / TAU).round() * TAU;
        }
        out.push(p + shift);
    }
    out
}

/// The forcing at t_k + (i / (2 n)) dt for k = 0 .. samples - 1 and i = 0 .. 2n (shared
/// end points): 2 n (samples - 1) + 1 points, index 2 n k + i. These are the stage times
/// of `n` RK4 sub-steps per sample interval.
pub(crate) fn rk4_table(exp: &Experiment, substeps: usize) -> Vec<ForcePoint> {
    let n2 = 2 * substeps;
    let intervals = exp.samples - 1;
    let mut out = Vec::with_capacity(n2 * intervals + 1);
    let dt = exp.dt;
    match exp.speed {
        SpeedData::Profile(p) => {
            for k in 0..intervals {
                for i in 0..n2 {
                    let t = k as f64 * dt + (i as f64 / n2 as f64) * dt;
                    let s = p.at(t);
                    out.push(ForcePoint::new(s.phi, s.omega, s.omega_dot));
                }
            }
            let s = p.at(intervals as f64 * dt);
            out.push(ForcePoint::new(s.phi, s.omega, s.omega_dot));
        }
        SpeedData::Samples {
            phi,
            omega,
            omega_dot,
        } => {
            let phi = unwrap_phase(phi, omega, dt);
            for k in 0..intervals {
                out.push(ForcePoint::new(phi[k], omega[k], omega_dot[k]));
                for i in 1..n2 {
                    let u = i as f64 / n2 as f64;
                    let (p, w, wd) = hermite5(
                        phi[k],
                        omega[k],
                        omega_dot[k],
                        phi[k + 1],
                        omega[k + 1],
                        omega_dot[k + 1],
                        dt,
                        u,
                    );
                    out.push(ForcePoint::new(p, w, wd));
                }
            }
            out.push(ForcePoint::new(
                phi[intervals],
                omega[intervals],
                omega_dot[intervals],
            ));
        }
    }
    out
}

/// (sin phi_k, cos phi_k) at every sample for a constant speed W \[rad/s\] from phi0 \[rad\]:
/// phi_k = phi0 + W k dt.
pub(crate) fn oscillator_table(omega: f64, phi0: f64, dt: f64, samples: usize) -> Vec<[f64; 2]> {
    (0..samples)
        .map(|k| {
            let (s, c) = (phi0 + omega * (k as f64 * dt)).sin_cos();
            [s, c]
        })
        .collect()
}

/// The largest |w| \[rad/s\] over the record (for the choice of the RK4 sub-step).
pub(crate) fn max_speed(exp: &Experiment) -> f64 {
    match exp.speed {
        SpeedData::Profile(p) => {
            let t_end = (exp.samples - 1) as f64 * exp.dt;
            p.at(0.0).omega.abs().max(p.at(t_end).omega.abs())
        }
        SpeedData::Samples { omega, .. } => omega.iter().fold(0.0, |a, &w| a.max(w.abs())),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hermite5_is_exact_for_quintics() {
        // p(t) = 1 + 2t - 3t^2 + 0.5t^3 + 4t^4 - 7t^5 on [0.3, 0.3 + h]
        let c = [1.0, 2.0, -3.0, 0.5, 4.0, -7.0];
        let p = |t: f64| c.iter().rev().fold(0.0, |a, &ci| a * t + ci);
        let dp = |t: f64| (1..6).rev().fold(0.0, |a, i| a * t + i as f64 * c[i]);
        let ddp = |t: f64| {
            (2..6)
                .rev()
                .fold(0.0, |a, i| a * t + (i * (i - 1)) as f64 * c[i])
        };
        let (t0, h) = (0.3, 0.05);
        for &u in &[0.0, 0.25, 0.5, 0.8, 1.0] {
            let t = t0 + u * h;
            let (a, b, cc) = hermite5(
                p(t0),
                dp(t0),
                ddp(t0),
                p(t0 + h),
                dp(t0 + h),
                ddp(t0 + h),
                h,
                u,
            );
            assert!((a - p(t)).abs() < 1e-13, "phi at u={u}");
            assert!((b - dp(t)).abs() < 1e-11, "w at u={u}");
            assert!(
                (cc - ddp(t)).abs() < 1e-8,
                "w' at u={u}: {cc} vs {}",
                ddp(t)
            );
        }
    }

    #[test]
    fn wrapped_phase_is_unwrapped() {
        let (w, dt) = (300.0, 1e-3);
        let truth: Vec<f64> = (0..50).map(|k| 0.1 + w * k as f64 * dt).collect();
        let wrapped: Vec<f64> = truth.iter().map(|p| p.rem_euclid(TAU)).collect();
        let omega = vec![w; 50];
        let un = unwrap_phase(&wrapped, &omega, dt);
        for (a, b) in un.iter().zip(&truth) {
            assert!((a - b).abs() < 1e-12);
        }
    }

    #[test]
    fn force_shapes_reproduce_eq_1() {
        use crate::model::{unbalance_force_from, Rotor, SpeedState};
        let r = Rotor::table1();
        let u = r.unbalance();
        let (uc, us) = (u.mud() * u.alpha.cos(), u.mud() * u.alpha.sin());
        let s = SpeedState {
            phi: 1.234,
            omega: 80.0,
            omega_dot: -7.0,
        };
        let f = ForcePoint::new(s.phi, s.omega, s.omega_dot);
        let (sn, cs) = (s.phi + u.alpha).sin_cos();
        let want = unbalance_force_from(u.mud(), s.omega, s.omega_dot, sn, cs);
        assert!((uc * f.gxc + us * f.gxs - want[0]).abs() < 1e-15);
        assert!((uc * f.gzc + us * f.gzs - want[1]).abs() < 1e-15);
    }
}
