//! Stability over a speed range. A mode grows when Re lambda > 0, i.e. when its damping
//! ratio and logarithmic decrement are negative (modes module). For this model
//!
//! ```text
//! d/dt ( m |q'|^2 / 2 + q^T K1 q / 2 ) = -q'^T C1 q'      (C2 is skew: gyroscopic forces do no work)
//! ```
//!
//! so with cx, cz > 0 the rotor is stable at every speed: the model has no cross-coupled
//! stiffness (fluid-film bearings, seals, internal friction), the usual cause of a
//! stability threshold. A threshold therefore appears only when an identified damping is
//! negative; the analysis reports it rather than rejecting such a fit. The threshold speed
//! is the lowest speed of the range at which some mode's damping ratio is below
//! -[`UNSTABLE_ZETA`], refined by bisection between the grid speeds that bracket it (the
//! first speed of the range if the rotor is already unstable there).
//! Reference: API Standard 684, 2nd ed., 2005, sec. 2.8 (stability: logarithmic decrement
//! of the least damped mode); Genta, *Dynamics of rotating systems*, 2005, ch. 4.

use crate::model::RotorParams;

use super::error::{check_params, check_speeds, AnalysisError};
use super::modes::Quadratic;

/// Damping ratio below -this is growth rather than the rounding of a zero damping (the
/// eigenvalues are accurate to ~1e-13 of the natural frequency).
pub const UNSTABLE_ZETA: f64 = 1e-9;

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
}

impl Stability {
    /// True when no mode grows anywhere in the range.
    pub fn is_stable(&self) -> bool {
        self.threshold.is_none()
    }
}

/// The stability of `p` over `speeds` \[rad/s\] (finite, >= 0, strictly increasing, at
/// least one).
pub fn stability(p: &RotorParams, speeds: &[f64]) -> Result<Stability, AnalysisError> {
    check_params(p)?;
    check_speeds(speeds, 1)?;
    let zeta = |w: f64| {
        let [a, b] = Quadratic::new(p, w).modes();
        a.damping_ratio.min(b.damping_ratio)
    };
    let mut out = Stability {
        min_log_dec: None,
        min_log_dec_speed: None,
        min_log_dec_mode: None,
        min_damping_ratio: f64::INFINITY,
        threshold: None,
    };
    let mut last_stable: Option<f64> = None;
    for &w in speeds {
        let modes = Quadratic::new(p, w).modes();
        for (i, m) in modes.iter().enumerate() {
            out.min_damping_ratio = out.min_damping_ratio.min(m.damping_ratio);
            if let Some(d) = m.log_dec {
                if out.min_log_dec.is_none_or(|v| d < v) {
                    out.min_log_dec = Some(d);
                    out.min_log_dec_speed = Some(w);
                    out.min_log_dec_mode = Some(i);
                }
            }
        }
        let unstable = modes.iter().any(|m| m.damping_ratio < -UNSTABLE_ZETA);
        if out.threshold.is_none() && unstable {
            out.threshold = Some(match last_stable {
                None => w,
                Some(mut a) => {
                    let mut b = w;
                    while b - a > 1e-12 * b {
                        let mid = 0.5 * (a + b);
                        if mid <= a || mid >= b {
                            break;
                        }
                        if zeta(mid) < -UNSTABLE_ZETA {
                            b = mid;
                        } else {
                            a = mid;
                        }
                    }
                    b
                }
            });
        }
        if !unstable {
            last_stable = Some(w);
        }
    }
    Ok(out)
}
