//! Stability over a speed range and at the operating speed. A mode grows when
//! Re lambda > 0, i.e. when its damping ratio and logarithmic decrement are negative
//! (modes module). For the Jeffcott rotor (no cross-coupling)
//!
//! ```text
//! d/dt ( m |q'|^2 / 2 + q^T K1 q / 2 ) = -q'^T C1 q'      (C2 is skew: gyroscopic forces do no work)
//! ```
//!
//! so with cx, cz > 0 it is stable at every speed; a threshold appears only when an
//! identified damping is negative, and the analysis reports it rather than rejecting such
//! a fit. On cross-coupled bearings (docs/method.md section 1.6) the skew-symmetric part
//! of the stiffness, (kzx - kxz) / 2, does work on a whirling orbit: kzx > 0 > kxz feeds
//! forward whirl, and the forward mode grows once that work exceeds what the damping
//! dissipates. For the isotropic rotor (kx = kz = k, cx = cz = c, cxz = czx = 0,
//! kzx = -kxz = Q) the forward mode's eigenvalues solve m l^2 + c l + k = i (a W l + Q),
//! so at l = i w on the stability boundary
//!
//! ```text
//! m w^2 - a W w - k = 0   (the forward frequency)      and      c w = Q
//! ```
//!
//! the forward mode is unstable while Q > c w_f(W): at a = 0 from Q > c sqrt(k / m) at
//! every speed; with a != 0 above (a < 0) or below (a > 0) the speed
//! W = (m w^2 - k) / (a w), w = Q / c.
//!
//! Threshold speed. The least damped mode at speed W is the mode of smallest damping ratio
//! (equivalently, smallest logarithmic decrement). The rotor is unstable at W when that
//! damping ratio is below -[`UNSTABLE_ZETA`] (rounding of a zero damping is not growth).
//! The threshold is the lowest speed of the range where it becomes unstable: the grid
//! speeds bracket the first change from stable to unstable, and bisection on the sign of
//! the least damped mode's damping ratio refines it to 1e-13 relative (the first speed of
//! the range, [`Stability::unstable_at_start`], if the rotor is already unstable there).
//!
//! Uncertainty (delta method, covariance module; analytic eigenvalue derivatives
//! d lambda / d theta and d lambda / d W of the critical module). The logarithmic decrement
//! delta = -2 pi Re lambda / Im lambda of a mode at a fixed speed has
//!
//! ```text
//! d delta / d theta = -2 pi (Re(dl) Im l - Re l Im(dl)) / (Im l)^2
//! ```
//!
//! and the threshold W_th (Re lambda(W_th, theta) = 0), by the implicit function theorem,
//!
//! ```text
//! d W_th / d theta = -(d Re lambda / d theta) / (d Re lambda / d W)
//!                  = -(d delta / d theta) / (d delta / d W)          (equal at Re lambda = 0)
//! ```
//!
//! Reference: API Standard 684, 2nd ed., 2005, sec. 2.8 (stability: logarithmic decrement
//! of the least damped mode); Genta, *Dynamics of rotating systems*, 2005, ch. 4 and 5;
//! Vance, Zeidan & Murphy, *Machinery vibration and rotordynamics*, Wiley, 2010, ch. 5
//! (cross-coupled stiffness and the threshold of the forward mode).

use crate::model::{rad_per_s_to_rpm, RotorParams};

use super::covariance::{std_of, Gradient, ParameterCovariance};
use super::critical::eigenvalue_derivatives;
use super::error::{check_params, check_speed, check_speeds, AnalysisError};
use super::modes::{Mode, Quadratic, Whirl};

/// Damping ratio below -this is growth rather than the rounding of a zero damping (the
/// eigenvalues are accurate to ~1e-13 of the natural frequency).
pub const UNSTABLE_ZETA: f64 = 1e-9;

/// Bisection of the threshold stops when the bracket is narrower than this fraction of
/// the speed.
const BRACKET: f64 = 1e-13;

/// The stability of the rotor over a speed range.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stability {
    /// The smallest logarithmic decrement over the grid and both modes (dimensionless);
    /// `None` if no mode oscillates at any speed.
    pub min_log_dec: Option<f64>,
    /// The grid speed of that minimum \[rad/s\].
    pub min_log_dec_speed: Option<f64>,
    /// The mode of that minimum (0: lower frequency, 1: higher).
    pub min_log_dec_mode: Option<usize>,
    /// The smallest damping ratio over the grid and both modes (dimensionless).
    pub min_damping_ratio: f64,
    /// The threshold speed of instability \[rad/s\] (module doc); `None` when the rotor is
    /// stable over the whole range.
    pub threshold: Option<f64>,
    /// Its standard deviation \[rad/s\] (module doc); `None` without a covariance, when it
    /// depends on an undetermined parameter, when the rotor is unstable from the start of
    /// the range (no crossing) or when the least damped mode does not oscillate there.
    pub threshold_std: Option<f64>,
    /// The mode that goes unstable at the threshold (0: lower frequency, 1: higher).
    pub threshold_mode: Option<usize>,
    /// Its whirl just above the threshold; `None` without a threshold or for a straight-line
    /// orbit.
    pub threshold_whirl: Option<Whirl>,
    /// True when the rotor is already unstable at the first speed of the range (the
    /// threshold is then that speed, not a crossing).
    pub unstable_at_start: bool,
    /// After an instability, the speed \[rad/s\] from which the rotor is stable again to
    /// the end of the range (the last crossing from unstable to stable, refined as the
    /// threshold is); `None` when it is stable everywhere or unstable at the end. With
    /// constant bearing coefficients and a > 0 the gyroscopic stiffening of the forward
    /// mode can end an instability that starts at rest (module doc).
    pub stable_from: Option<f64>,
    /// Its standard deviation \[rad/s\] (as `threshold_std`).
    pub stable_from_std: Option<f64>,
}

impl Stability {
    /// Nothing seen yet: no mode, no threshold (the start of a scan over a grid).
    pub(crate) fn unscanned() -> Self {
        Stability {
            min_log_dec: None,
            min_log_dec_speed: None,
            min_log_dec_mode: None,
            min_damping_ratio: f64::INFINITY,
            threshold: None,
            threshold_std: None,
            threshold_mode: None,
            threshold_whirl: None,
            unstable_at_start: false,
            stable_from: None,
            stable_from_std: None,
        }
    }

    /// Takes the modes at the grid speed `w` \[rad/s\] into the smallest damping ratio
    /// and logarithmic decrement (the first of equal minima kept).
    pub(crate) fn note_modes<'a>(&mut self, w: f64, modes: impl Iterator<Item = &'a Mode>) {
        for (i, m) in modes.enumerate() {
            self.min_damping_ratio = self.min_damping_ratio.min(m.damping_ratio);
            if let Some(d) = m.log_dec {
                if self.min_log_dec.is_none_or(|v| d < v) {
                    self.min_log_dec = Some(d);
                    self.min_log_dec_speed = Some(w);
                    self.min_log_dec_mode = Some(i);
                }
            }
        }
    }

    /// True when no mode grows anywhere in the range.
    pub fn is_stable(&self) -> bool {
        self.threshold.is_none()
    }

    /// The threshold speed \[rev/min\].
    pub fn threshold_rpm(&self) -> Option<f64> {
        self.threshold.map(rad_per_s_to_rpm)
    }

    /// Its standard deviation \[rev/min\].
    pub fn threshold_std_rpm(&self) -> Option<f64> {
        self.threshold_std.map(rad_per_s_to_rpm)
    }
}

/// The least damped mode at one speed, with the uncertainty of its logarithmic decrement:
/// the stability margin at that speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StabilityMargin {
    /// The speed W \[rad/s\].
    pub speed: f64,
    /// Which mode is least damped (0: lower frequency, 1: higher).
    pub mode: usize,
    /// That mode.
    pub at: Mode,
    /// The standard deviation of its logarithmic decrement (dimensionless; module doc);
    /// `None` without a covariance, when it depends on an undetermined parameter or when
    /// the mode does not oscillate.
    pub log_dec_std: Option<f64>,
}

impl StabilityMargin {
    /// The logarithmic decrement of the least damped mode (dimensionless); `None` when it
    /// does not oscillate.
    pub fn log_dec(&self) -> Option<f64> {
        self.at.log_dec
    }

    /// True when the least damped mode grows (damping ratio below -[`UNSTABLE_ZETA`]).
    pub fn is_unstable(&self) -> bool {
        self.at.damping_ratio < -UNSTABLE_ZETA
    }
}

/// The least damped of the two modes at speed `w`: (index, mode).
pub(crate) fn least_damped(p: &RotorParams, w: f64) -> (usize, Mode) {
    let modes = Quadratic::new(p, w).modes();
    if modes[1].damping_ratio < modes[0].damping_ratio {
        (1, modes[1])
    } else {
        (0, modes[0])
    }
}

/// The gradient of the logarithmic decrement of mode `i` at speed `w` over the
/// parameters, and its derivative with respect to the speed (module doc); `None` when the
/// mode does not oscillate or its eigenvalue is double.
pub(crate) fn log_dec_gradient(p: &RotorParams, w: f64, i: usize) -> Option<(Gradient, f64)> {
    let l = Quadratic::new(p, w).modes()[i].eigenvalue;
    if l.im <= 0.0 {
        return None;
    }
    let (dl, dl_dw) = eigenvalue_derivatives(p, w, l)?;
    let tau = std::f64::consts::TAU;
    let d = |d: super::modes::C64| -tau * (d.re * l.im - l.re * d.im) / (l.im * l.im);
    let grad = dl.map(d);
    let dw = d(dl_dw);
    (grad.iter().all(|g| g.is_finite()) && dw.is_finite()).then_some((grad, dw))
}

/// The stability margin of `p` at the speed `omega` \[rad/s\] (finite, >= 0): the least
/// damped mode there and the standard deviation of its logarithmic decrement under `cov`.
pub fn stability_margin(
    p: &RotorParams,
    cov: Option<&ParameterCovariance>,
    omega: f64,
) -> Result<StabilityMargin, AnalysisError> {
    check_params(p)?;
    check_speed(omega)?;
    let (mode, at) = least_damped(p, omega);
    let log_dec_std = log_dec_gradient(p, omega, mode).and_then(|(g, _)| std_of(cov, &g));
    Ok(StabilityMargin {
        speed: omega,
        mode,
        at,
        log_dec_std,
    })
}

/// The stability of `p` over `speeds` \[rad/s\] (finite, >= 0, strictly increasing, at
/// least one), without uncertainty: [`stability_with_covariance`] with no covariance.
pub fn stability(p: &RotorParams, speeds: &[f64]) -> Result<Stability, AnalysisError> {
    stability_with_covariance(p, None, speeds)
}

/// The stability of `p` over `speeds` \[rad/s\] (finite, >= 0, strictly increasing, at
/// least one), the threshold's standard deviation under `cov` (module doc).
pub fn stability_with_covariance(
    p: &RotorParams,
    cov: Option<&ParameterCovariance>,
    speeds: &[f64],
) -> Result<Stability, AnalysisError> {
    check_params(p)?;
    check_speeds(speeds, 1)?;
    let zeta = |w: f64| least_damped(p, w).1.damping_ratio;
    let mut out = Stability::unscanned();
    let mut last_stable: Option<(f64, f64)> = None;
    let mut last_unstable: Option<f64> = None;
    for &w in speeds {
        let modes = Quadratic::new(p, w).modes();
        out.note_modes(w, modes.iter());
        let z = modes[0].damping_ratio.min(modes[1].damping_ratio);
        let unstable = z < -UNSTABLE_ZETA;
        if out.threshold.is_none() && unstable {
            match last_stable {
                None => {
                    out.threshold = Some(w);
                    out.unstable_at_start = true;
                    let (i, m) = least_damped(p, w);
                    out.threshold_mode = Some(i);
                    out.threshold_whirl = m.whirl;
                }
                Some((a, za)) => {
                    // the sign change of zeta itself when the stable end is strictly damped;
                    // else (zeta within rounding of 0 there) that of zeta + UNSTABLE_ZETA
                    let shift = if za > 0.0 { 0.0 } else { UNSTABLE_ZETA };
                    let wt = bisect(|w| zeta(w) + shift < 0.0, a, w);
                    // the mode that grows: the least damped one just above the threshold
                    let above = (wt * (1.0 + 1e-9)).min(w);
                    let (i, m) = least_damped(p, above);
                    out.threshold = Some(wt);
                    out.threshold_mode = Some(i);
                    out.threshold_whirl = m.whirl;
                    out.threshold_std = threshold_gradient(p, wt, i).and_then(|g| std_of(cov, &g));
                }
            }
        }
        if unstable {
            out.stable_from = None;
            out.stable_from_std = None;
        } else {
            if let Some(a) = last_unstable.filter(|&a| last_stable.is_none_or(|(s, _)| s < a)) {
                let shift = if z > 0.0 { 0.0 } else { UNSTABLE_ZETA };
                let ws = bisect(|w| zeta(w) + shift >= 0.0, a, w);
                let below = (ws * (1.0 - 1e-9)).max(a);
                let (i, _) = least_damped(p, below);
                out.stable_from = Some(ws);
                out.stable_from_std = threshold_gradient(p, ws, i).and_then(|g| std_of(cov, &g));
            }
            last_stable = Some((w, z));
        }
        if unstable {
            last_unstable = Some(w);
        }
    }
    Ok(out)
}

/// The gradient of the threshold speed `wt` of mode `i` over the parameters (module doc).
pub(crate) fn threshold_gradient(p: &RotorParams, wt: f64, i: usize) -> Option<Gradient> {
    let l = Quadratic::new(p, wt).modes()[i].eigenvalue;
    let (dl, dl_dw) = eigenvalue_derivatives(p, wt, l)?;
    let slope = dl_dw.re;
    if slope == 0.0 || !slope.is_finite() {
        return None;
    }
    let grad = dl.map(|d| -d.re / slope);
    grad.iter().all(|g| g.is_finite()).then_some(grad)
}

/// The speed in (a, b] where `unstable` turns true (false at a, true at b).
fn bisect(unstable: impl Fn(f64) -> bool, mut a: f64, mut b: f64) -> f64 {
    for _ in 0..200 {
        let mid = 0.5 * (a + b);
        if b - a <= BRACKET * b || mid <= a || mid >= b {
            break;
        }
        if unstable(mid) {
            b = mid;
        } else {
            a = mid;
        }
    }
    0.5 * (a + b)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::covariance::{values, with_values, CovarianceParameter, NPARAM};
    use crate::model::{CrossCoupling, RotorParams, Unbalance};

    /// The isotropic rotor of the module doc: m, k, c, a, kzx = -kxz = q.
    fn isotropic(a: f64, q: f64) -> RotorParams {
        RotorParams {
            m: 14.29,
            cx: 200.0,
            cz: 200.0,
            kx: 1.195e6,
            kz: 1.195e6,
            a,
            unbalance: Unbalance {
                m_u: 0.0,
                d: 0.0,
                alpha: 0.0,
            },
            coupling: Some(CrossCoupling {
                cxz: 0.0,
                czx: 0.0,
                kxz: -q,
                kzx: q,
            }),
        }
    }

    fn grid(max: f64, step: f64) -> Vec<f64> {
        (0..=(max / step) as usize)
            .map(|k| k as f64 * step)
            .collect()
    }

    #[test]
    fn without_gyroscopic_coupling_the_threshold_is_q_equal_c_omega_n() {
        let p = isotropic(0.0, 0.0);
        let qc = p.cx * (p.kx / p.m).sqrt();
        let speeds = grid(600.0, 10.0);
        let below = stability(&isotropic(0.0, qc * (1.0 - 1e-6)), &speeds).unwrap();
        assert!(below.is_stable(), "{below:?}");
        assert!(below.min_log_dec.unwrap() > 0.0);
        let above = stability(&isotropic(0.0, qc * (1.0 + 1e-6)), &speeds).unwrap();
        assert_eq!(above.threshold, Some(0.0));
        assert!(above.unstable_at_start);
        assert_eq!(above.threshold_whirl, Some(Whirl::Forward));
        assert_eq!(above.threshold_std, None);
    }

    #[test]
    fn gyroscopic_rotor_threshold_matches_the_closed_form() {
        // a < 0: the forward frequency falls with speed, and the forward mode is unstable
        // above W = (m w^2 - k) / (a w), w = q / c
        let (a, q) = (-2.871, 5.0e4);
        let p = isotropic(a, q);
        let w = q / p.cx;
        let want = (p.m * w * w - p.kx) / (a * w);
        let s = stability(&p, &grid(700.0, 10.0)).unwrap();
        let got = s.threshold.unwrap();
        assert!((got / want - 1.0).abs() < 1e-9, "{got} vs {want}");
        assert!(!s.unstable_at_start);
        assert_eq!(s.threshold_whirl, Some(Whirl::Forward));
        // the forward mode is the higher one below the crossing of the frequencies
        let m = least_damped(&p, want * 1.001);
        assert_eq!(m.1.whirl, Some(Whirl::Forward));
        assert_eq!(s.threshold_mode, Some(m.0));
        // and the margin changes sign there
        assert!(
            stability_margin(&p, None, want * 0.999)
                .unwrap()
                .log_dec()
                .unwrap()
                > 0.0
        );
        assert!(stability_margin(&p, None, want * 1.001)
            .unwrap()
            .is_unstable());
        // a > 0: unstable from rest (q > c w_n) up to the same formula's speed
        let p = isotropic(2.871, 6.0e4);
        let s = stability(&p, &grid(700.0, 10.0)).unwrap();
        assert!(s.unstable_at_start);
        let w = 6.0e4 / p.cx;
        let stable_from = (p.m * w * w - p.kx) / (2.871 * w);
        assert!(stability_margin(&p, None, stable_from * 0.999)
            .unwrap()
            .is_unstable());
        assert!(!stability_margin(&p, None, stable_from * 1.001)
            .unwrap()
            .is_unstable());
        let got = s.stable_from.unwrap();
        assert!(
            (got / stable_from - 1.0).abs() < 1e-9,
            "{got} vs {stable_from}"
        );
        // the range ending inside the instability: not stable again
        let s = stability(&p, &grid(stable_from * 0.9, 10.0)).unwrap();
        assert_eq!(s.stable_from, None);
    }

    #[test]
    fn threshold_and_log_dec_gradients_match_central_differences() {
        let mut p = isotropic(-2.871, 5.0e4);
        p.kz = 1.25e6;
        p.cz = 180.0;
        p.coupling = Some(CrossCoupling {
            cxz: 10.0,
            czx: -5.0,
            kxz: -4.5e4,
            kzx: 5.5e4,
        });
        let speeds = grid(900.0, 10.0);
        let s = stability(&p, &speeds).unwrap();
        let wt = s.threshold.unwrap();
        assert!(!s.unstable_at_start && wt > 100.0, "{s:?}");
        let i = s.threshold_mode.unwrap();
        let grad = threshold_gradient(&p, wt, i).unwrap();
        let w_op = 0.8 * wt;
        let (mode, _) = least_damped(&p, w_op);
        let (gd, dw) = log_dec_gradient(&p, w_op, mode).unwrap();
        let v = values(&p);
        let delta = |q: &RotorParams, w: f64| least_damped(q, w).1.log_dec.unwrap();
        let h = 1e-3;
        let fd_w = (delta(&p, w_op + h) - delta(&p, w_op - h)) / (2.0 * h);
        assert!((fd_w - dw).abs() < 1e-6 * dw.abs(), "{fd_w} vs {dw}");
        for k in (0..NPARAM).filter(|&k| {
            k != CovarianceParameter::MudCosAlpha.index()
                && k != CovarianceParameter::MudSinAlpha.index()
        }) {
            let h = 1e-6 * v[k].abs().max(1.0);
            let at = |x: f64| {
                let mut vv = v;
                vv[k] = x;
                with_values(&p, &vv)
            };
            let (up, dn) = (at(v[k] + h), at(v[k] - h));
            let th = |q: &RotorParams| stability(q, &speeds).unwrap().threshold.unwrap();
            let fd = (th(&up) - th(&dn)) / (2.0 * h);
            assert!(
                (fd - grad[k]).abs() <= 1e-4 * grad[k].abs() + 1e-11 * wt / h,
                "threshold, parameter {k}: {fd} vs {}",
                grad[k]
            );
            let fd = (delta(&up, w_op) - delta(&dn, w_op)) / (2.0 * h);
            assert!(
                (fd - gd[k]).abs() <= 1e-5 * gd[k].abs() + 1e-12 / h,
                "log dec, parameter {k}: {fd} vs {}",
                gd[k]
            );
        }
    }
}
