//! What the modulating-function identifier reports: theta = (m, c, k) per direction from
//! the least squares over every completed window, and the figures to judge it by.

use serde::{Deserialize, Serialize};

/// The estimate for one direction (x or z).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ModulatingDirection {
    /// Mass m \[kg\] (NaN when the least squares is singular).
    pub m: f64,
    /// Damping c \[N s/m\] (NaN when singular).
    pub c: f64,
    /// Stiffness k \[N/m\] (NaN when singular).
    pub k: f64,
    /// Standard error of m \[kg\]: first-order sandwich covariance of the least squares with
    /// the correlations of overlapping windows, for white noise of the estimated (or
    /// given) sigma (module `uncertainty`). NaN when singular.
    pub std_error_m: f64,
    /// Standard error of c \[N s/m\] (as `std_error_m`).
    pub std_error_c: f64,
    /// Standard error of k \[N/m\] (as `std_error_m`).
    pub std_error_k: f64,
    /// Reciprocal 2-norm condition number of the equilibrated (and noise-compensated)
    /// normal matrix, in [0, 1]; 0 when singular (module `normal_equations`).
    pub rcond: f64,
}

impl ModulatingDirection {
    /// The singular answer: NaN values, rcond = 0.
    pub const SINGULAR: Self = Self {
        m: f64::NAN,
        c: f64::NAN,
        k: f64::NAN,
        std_error_m: f64::NAN,
        std_error_c: f64::NAN,
        std_error_k: f64::NAN,
        rcond: 0.0,
    };

    /// True when rcond >= `rcond_min` and rcond > 0 (the values are finite).
    pub fn well_conditioned(&self, rcond_min: f64) -> bool {
        self.rcond >= rcond_min && self.rcond > 0.0
    }

    /// (m, c, k).
    pub fn theta(&self) -> [f64; 3] {
        [self.m, self.c, self.k]
    }

    /// The standard errors of (m, c, k).
    pub fn std_errors(&self) -> [f64; 3] {
        [self.std_error_m, self.std_error_c, self.std_error_k]
    }
}

/// Both directions' estimates from all windows completed so far.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ModulatingEstimate {
    /// Time of the last sample of the last completed window \[s\] (NaN before the first).
    pub t: f64,
    /// Horizontal direction: m, cx, kx.
    pub x: ModulatingDirection,
    /// Vertical direction: m, cz, kz.
    pub z: ModulatingDirection,
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

impl ModulatingEstimate {
    /// The six values in the order m_x, c_x, k_x, m_z, c_z, k_z.
    pub fn values(&self) -> [f64; 6] {
        [self.x.m, self.x.c, self.x.k, self.z.m, self.z.c, self.z.k]
    }

    /// Their standard errors, same order.
    pub fn std_errors(&self) -> [f64; 6] {
        let (x, z) = (self.x.std_errors(), self.z.std_errors());
        [x[0], x[1], x[2], z[0], z[1], z[2]]
    }

    /// [x well conditioned, z well conditioned] at `rcond_min`.
    pub fn well_conditioned(&self, rcond_min: f64) -> [bool; 2] {
        [
            self.x.well_conditioned(rcond_min),
            self.z.well_conditioned(rcond_min),
        ]
    }
}
