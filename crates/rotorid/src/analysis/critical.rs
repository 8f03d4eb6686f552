//! Critical speeds: the speeds at which a damped natural frequency meets the running
//! speed (the 1X line of the Campbell diagram), i.e. the roots of
//!
//! ```text
//! g_i(W) = w_d,i(W) - W,     w_d,i = Im lambda_i (mode i, see the modes module)
//! ```
//!
//! found as sign changes of g_i on the speed grid and refined by bisection to rounding.
//! Their standard deviation is linearised (implicit function theorem on g_i = 0):
//!
//! ```text
//! dW_c/dtheta = -(d w_d / d theta) / (d w_d / d W - 1),     std(W_c) = sqrt(grad^T Sigma grad)
//! ```
//!
//! with the derivative of a simple eigenvalue of the matrix polynomial Q (P. Lancaster,
//! *Lambda-matrices and vibrating systems*, Pergamon, 1966; F. Tisseur & K. Meerbergen,
//! "The quadratic eigenvalue problem", SIAM Review 43, 2001, sec. 3): for Q(lambda) u = 0
//! and r Q(lambda) = 0,
//!
//! ```text
//! d lambda / d theta = -r (dQ/dtheta) u / (r Q'(lambda) u),     Q'(lambda) = 2 lambda M + C1 + W C2
//! dQ/dm = lambda^2 I     dQ/dcx = lambda E_11   dQ/dkx = E_11   (cz, kz: E_22)
//! dQ/da = lambda W J     dQ/dW = lambda a J,    J = [[0, -1], [1, 0]]
//! dQ/dcxz = lambda E_12  dQ/dkxz = E_12         (czx, kzx: E_21)
//! ```
//!
//! The unbalance does not move the eigenvalues (its gradient entries are 0). At a double
//! eigenvalue (no defined mode shape) or a tangency of the frequency and the 1X line
//! (d w_d / d W = 1) the derivative does not exist and the standard deviation is `None`.

use nalgebra::{Complex, Matrix2};

use crate::model::{rad_per_s_to_rpm, RotorParams};

use super::covariance::{std_of, CovarianceParameter, Gradient, ParameterCovariance, NPARAM};
use super::error::{check_params, check_speeds, AnalysisError};
use super::modes::{Mode, Quadratic, Whirl, C64};
use super::stability::log_dec_gradient;

/// Bisection stops when the bracket is narrower than this fraction of the speed.
const BRACKET: f64 = 1e-13;

/// One critical speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CriticalSpeed {
    /// The critical speed W_c \[rad/s\].
    pub speed: f64,
    /// Its standard deviation \[rad/s\] propagated from the parameters' covariance (module
    /// doc); `None` without a covariance, or when W_c depends on an undetermined
    /// parameter, or at a double eigenvalue or a tangency.
    pub std: Option<f64>,
    /// Which mode crosses 1X: 0 (lower frequency) or 1 (higher), as in
    /// [`super::Campbell`].
    pub mode: usize,
    /// The mode at W_c (its damped natural frequency equals W_c).
    pub at: Mode,
    /// The standard deviation of its logarithmic decrement at W_c (dimensionless): the
    /// total derivative d delta / d theta + (d delta / d W) (d W_c / d theta) propagated
    /// under the covariance (the stability module's derivative of delta); `None` like
    /// `std`, or when the mode does not oscillate.
    pub log_dec_std: Option<f64>,
}

impl CriticalSpeed {
    /// The critical speed \[rev/min\].
    pub fn rpm(&self) -> f64 {
        rad_per_s_to_rpm(self.speed)
    }

    /// Its standard deviation \[rev/min\].
    pub fn std_rpm(&self) -> Option<f64> {
        self.std.map(rad_per_s_to_rpm)
    }

    /// The whirl of the crossing mode at W_c.
    pub fn whirl(&self) -> Option<Whirl> {
        self.at.whirl
    }
}

/// The critical speeds of `p` between the first and the last of `speeds` \[rad/s\]
/// (finite, >= 0, strictly increasing, at least two), by increasing speed, each with its
/// standard deviation under `cov` (module doc). The grid must be fine enough that no mode
/// crosses 1X twice between two neighbouring speeds (a Jeffcott rotor's modes cross it
/// once each, if at all).
pub fn critical_speeds(
    p: &RotorParams,
    cov: Option<&ParameterCovariance>,
    speeds: &[f64],
) -> Result<Vec<CriticalSpeed>, AnalysisError> {
    check_params(p)?;
    check_speeds(speeds, 2)?;
    let g = |i: usize, w: f64| Quadratic::new(p, w).modes()[i].frequency - w;
    let mut out = Vec::new();
    for i in 0..2 {
        let mut prev = (speeds[0], g(i, speeds[0]));
        for &w in &speeds[1..] {
            let next = (w, g(i, w));
            if (prev.1 > 0.0) != (next.1 > 0.0) {
                let wc = bisect(|w| g(i, w), prev, next);
                let at = Quadratic::new(p, wc).modes()[i];
                let std = gradient(p, wc, i).and_then(|grad| std_of(cov, &grad));
                let log_dec_std =
                    log_dec_gradient_at_critical(p, wc, i).and_then(|grad| std_of(cov, &grad));
                out.push(CriticalSpeed {
                    speed: wc,
                    std,
                    mode: i,
                    at,
                    log_dec_std,
                });
            }
            prev = next;
        }
    }
    out.sort_by(|a, b| a.speed.total_cmp(&b.speed));
    Ok(out)
}

/// The root of `f` in the bracket `(a, fa)`, `(b, fb)` (fa, fb of opposite signs, or one 0).
fn bisect(f: impl Fn(f64) -> f64, (mut a, mut fa): (f64, f64), (mut b, fb): (f64, f64)) -> f64 {
    if fa == 0.0 {
        return a;
    }
    if fb == 0.0 {
        return b;
    }
    for _ in 0..200 {
        let mid = 0.5 * (a + b);
        if b - a <= BRACKET * b.abs() || mid <= a || mid >= b {
            break;
        }
        let fm = f(mid);
        if fm == 0.0 {
            return mid;
        }
        if (fm > 0.0) == (fa > 0.0) {
            (a, fa) = (mid, fm);
        } else {
            b = mid;
        }
    }
    0.5 * (a + b)
}

/// d lambda / d theta for the root `l` of Q at speed `w`, per parameter and for the speed
/// itself (last entry); `None` at a double eigenvalue.
pub(crate) fn eigenvalue_derivatives(
    p: &RotorParams,
    w: f64,
    l: C64,
) -> Option<([C64; NPARAM], C64)> {
    let q = Quadratic::new(p, w);
    let (u, r) = q.null_vectors(l)?;
    let denom = (r * q.derivative(l) * u)[(0, 0)];
    if denom.norm() == 0.0 {
        return None;
    }
    let zero = Complex::new(0.0, 0.0);
    let one = Complex::new(1.0, 0.0);
    let j = Matrix2::new(zero, -one, one, zero);
    let e11 = Matrix2::new(one, zero, zero, zero);
    let e22 = Matrix2::new(zero, zero, zero, one);
    let e12 = Matrix2::new(zero, one, zero, zero);
    let e21 = Matrix2::new(zero, zero, one, zero);
    let d = |dq: Matrix2<C64>| -(r * dq * u)[(0, 0)] / denom;
    let mut out = [zero; NPARAM];
    out[CovarianceParameter::M.index()] = d(Matrix2::identity() * (l * l));
    out[CovarianceParameter::Cx.index()] = d(e11 * l);
    out[CovarianceParameter::Kx.index()] = d(e11);
    out[CovarianceParameter::Cz.index()] = d(e22 * l);
    out[CovarianceParameter::Kz.index()] = d(e22);
    out[CovarianceParameter::A.index()] = d(j * (l * w));
    out[CovarianceParameter::Cxz.index()] = d(e12 * l);
    out[CovarianceParameter::Czx.index()] = d(e21 * l);
    out[CovarianceParameter::Kxz.index()] = d(e12);
    out[CovarianceParameter::Kzx.index()] = d(e21);
    Some((out, d(j * (l * p.a))))
}

/// The gradient of the critical speed `wc` of mode `i` over the parameters (module doc).
pub(crate) fn gradient(p: &RotorParams, wc: f64, i: usize) -> Option<Gradient> {
    let l = Quadratic::new(p, wc).modes()[i].eigenvalue;
    let (dl, dl_dw) = eigenvalue_derivatives(p, wc, l)?;
    let slope = dl_dw.im - 1.0;
    if slope == 0.0 || !slope.is_finite() {
        return None;
    }
    let grad = dl.map(|d| -d.im / slope);
    grad.iter().all(|g| g.is_finite()).then_some(grad)
}

/// The gradient of the logarithmic decrement of mode `i` at its critical speed `wc` over
/// the parameters: d delta / d theta + (d delta / d W) (d W_c / d theta).
pub(crate) fn log_dec_gradient_at_critical(p: &RotorParams, wc: f64, i: usize) -> Option<Gradient> {
    let gw = gradient(p, wc, i)?;
    let (gd, dw) = log_dec_gradient(p, wc, i)?;
    Some(std::array::from_fn(|k| gd[k] + dw * gw[k]))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::covariance::values;
    use crate::model::Rotor;

    /// Rotor parameters with the values `v` (m, cx, kx, cz, kz, a; unbalance unchanged).
    fn with_values(p: &RotorParams, v: &Gradient) -> RotorParams {
        RotorParams {
            coupling: None,
            m: v[0],
            cx: v[1],
            kx: v[2],
            cz: v[3],
            kz: v[4],
            a: v[5],
            unbalance: p.unbalance,
        }
    }

    fn anisotropic() -> RotorParams {
        let mut p = Rotor::table1().params();
        p.kz *= 1.3;
        p.cx = 40.0;
        p.cz = 15.0;
        p
    }

    #[test]
    fn eigenvalue_derivatives_match_central_differences() {
        let p = anisotropic();
        let w = 180.0;
        for i in 0..2 {
            let l = Quadratic::new(&p, w).modes()[i].eigenvalue;
            let (dl, dl_dw) = eigenvalue_derivatives(&p, w, l).unwrap();
            let v = values(&p);
            for k in 0..6 {
                let h = 1e-6 * v[k].abs();
                let (mut up, mut dn) = (v, v);
                up[k] += h;
                dn[k] -= h;
                let lu = Quadratic::new(&with_values(&p, &up), w).modes()[i].eigenvalue;
                let ld = Quadratic::new(&with_values(&p, &dn), w).modes()[i].eigenvalue;
                let fd = (lu - ld) / (2.0 * h);
                assert!(
                    (fd - dl[k]).norm() <= 1e-6 * dl[k].norm().max(1e-12 / h),
                    "mode {i} parameter {k}: {fd} vs {}",
                    dl[k]
                );
            }
            let h = 1e-4;
            let fd = (Quadratic::new(&p, w + h).modes()[i].eigenvalue
                - Quadratic::new(&p, w - h).modes()[i].eigenvalue)
                / (2.0 * h);
            assert!((fd - dl_dw).norm() < 1e-6 * dl_dw.norm(), "{fd} vs {dl_dw}");
        }
    }

    #[test]
    fn critical_speed_gradient_matches_central_differences() {
        let p = anisotropic();
        let grid: Vec<f64> = (0..=60).map(|k| 10.0 * k as f64).collect();
        let cs = critical_speeds(&p, None, &grid).unwrap();
        assert_eq!(cs.len(), 2);
        for c in &cs {
            let grad = gradient(&p, c.speed, c.mode).unwrap();
            let v = values(&p);
            for k in 0..6 {
                let h = 1e-5 * v[k].abs();
                let at = |x: f64| {
                    let mut vv = v;
                    vv[k] = x;
                    let cs = critical_speeds(&with_values(&p, &vv), None, &grid).unwrap();
                    cs.iter().find(|d| d.mode == c.mode).unwrap().speed
                };
                let fd = (at(v[k] + h) - at(v[k] - h)) / (2.0 * h);
                assert!(
                    (fd - grad[k]).abs() <= 1e-5 * grad[k].abs() + 4.0 * BRACKET * c.speed / h,
                    "mode {} parameter {k}: {fd} vs {}",
                    c.mode,
                    grad[k]
                );
            }
        }
    }

    #[test]
    fn cross_coupled_critical_log_dec_gradient_matches_central_differences() {
        let mut p = crate::test_models::cross_coupled_rotor();
        p.coupling = Some(crate::model::CrossCoupling {
            cxz: 20.0,
            czx: -12.0,
            kxz: -3.0e4,
            kzx: 4.0e4,
        });
        p.cz = 120.0;
        let grid: Vec<f64> = (0..=60).map(|k| 10.0 * k as f64).collect();
        let cs = critical_speeds(&p, None, &grid).unwrap();
        assert_eq!(cs.len(), 2);
        let v = values(&p);
        for c in &cs {
            let grad = log_dec_gradient_at_critical(&p, c.speed, c.mode).unwrap();
            let wgrad = gradient(&p, c.speed, c.mode).unwrap();
            for k in (0..NPARAM).filter(|&k| k != 6 && k != 7) {
                let h = 1e-5 * v[k].abs();
                let at = |x: f64| {
                    let mut vv = v;
                    vv[k] = x;
                    let q = crate::analysis::covariance::with_values(&p, &vv);
                    let cs = critical_speeds(&q, None, &grid).unwrap();
                    let d = cs.iter().find(|d| d.mode == c.mode).unwrap();
                    (d.at.log_dec.unwrap(), d.speed)
                };
                let (up, dn) = (at(v[k] + h), at(v[k] - h));
                let fd = (up.0 - dn.0) / (2.0 * h);
                assert!(
                    (fd - grad[k]).abs() <= 1e-5 * grad[k].abs() + 1e-12 / h,
                    "mode {} parameter {k}: {fd} vs {}",
                    c.mode,
                    grad[k]
                );
                let fd = (up.1 - dn.1) / (2.0 * h);
                assert!(
                    (fd - wgrad[k]).abs() <= 1e-5 * wgrad[k].abs() + 4.0 * BRACKET * c.speed / h,
                    "critical speed, mode {} parameter {k}: {fd} vs {}",
                    c.mode,
                    wgrad[k]
                );
            }
        }
    }
}
