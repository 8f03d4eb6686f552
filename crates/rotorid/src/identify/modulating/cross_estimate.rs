//! What the cross-coupled modulating-function identifier reports: per row m and the four
//! bearing coefficients of that row from the least squares over every completed window,
//! with their standard errors and the figures to judge them by.

use serde::{Deserialize, Serialize};

/// The estimate for one row (x or z).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CrossModulatingDirection {
    /// x row: (m_x \[kg\], cxx \[N s/m\], cxz \[N s/m\], kxx \[N/m\], kxz \[N/m\]);
    /// z row: (m_z \[kg\], czx \[N s/m\], czz \[N s/m\], kzx \[N/m\], kzz \[N/m\])
    /// (NaN when the least squares is singular).
    pub values: [f64; 5],
    /// Standard errors of `values` (same units): first-order sandwich covariance of the
    /// least squares, with both channels' noise and the correlations of overlapping
    /// windows, for white noise of the estimated (or given) sigma_x, sigma_z. NaN when
    /// singular.
    pub std_errors: [f64; 5],
    /// Reciprocal 2-norm condition number of the equilibrated (and noise-compensated)
    /// normal matrix, in [0, 1]; 0 when singular.
    pub rcond: f64,
}

impl CrossModulatingDirection {
    /// The singular answer: NaN values and standard errors, rcond = 0.
    pub const SINGULAR: Self = Self {
        values: [f64::NAN; 5],
        std_errors: [f64::NAN; 5],
        rcond: 0.0,
    };

    /// True when rcond >= `rcond_min` and rcond > 0 (the values are finite).
    pub fn well_conditioned(&self, rcond_min: f64) -> bool {
        self.rcond >= rcond_min && self.rcond > 0.0
    }
}

/// Both rows' estimates from all windows completed so far.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CrossModulatingEstimate {
    /// Time of the last sample of the last completed window \[s\] (NaN before the first).
    pub t: f64,
    /// The x row: m_x, cxx, cxz, kxx, kxz.
    pub x: CrossModulatingDirection,
    /// The z row: m_z, czx, czz, kzx, kzz.
    pub z: CrossModulatingDirection,
    /// Windows completed (each gives `functions` rows per direction).
    pub windows: u64,
    /// The window length used, L = (whole sampling intervals) * dt \[s\].
    pub window_s: f64,
    /// The hop used between window starts \[s\].
    pub hop_s: f64,
    /// Noise standard deviation on x \[m\] used by the bias compensation (when
    /// `compensated`) and the standard errors: estimated from the data or as given.
    pub sigma_x: f64,
    /// Noise standard deviation on z \[m\] (as `sigma_x`).
    pub sigma_z: f64,
    /// True when the O(sigma^2) noise bias was compensated.
    pub compensated: bool,
}

/// x's five then z's five.
fn ten(x: &[f64; 5], z: &[f64; 5]) -> [f64; 10] {
    std::array::from_fn(|i| if i < 5 { x[i] } else { z[i - 5] })
}

impl CrossModulatingEstimate {
    /// The ten values in the order m_x, cxx, cxz, kxx, kxz, m_z, czx, czz, kzx, kzz
    /// ([`crate::identify::CROSS_NAMES`]).
    pub fn values(&self) -> [f64; 10] {
        ten(&self.x.values, &self.z.values)
    }

    /// Their standard errors, same order.
    pub fn std_errors(&self) -> [f64; 10] {
        ten(&self.x.std_errors, &self.z.std_errors)
    }

    /// [x well conditioned, z well conditioned] at `rcond_min`.
    pub fn well_conditioned(&self, rcond_min: f64) -> [bool; 2] {
        [
            self.x.well_conditioned(rcond_min),
            self.z.well_conditioned(rcond_min),
        ]
    }
}
