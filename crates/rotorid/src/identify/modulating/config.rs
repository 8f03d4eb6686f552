//! Settings of the modulating-function identifier: window length and hop, test functions
//! per window, and how the noise bias of the least squares is compensated.

use serde::{Deserialize, Serialize};

use crate::identify::InputError;
use crate::model::check;

/// Default window length L \[s\]: 20 ms, about one period of table1's natural frequency
/// (sqrt(k/m) = 289 rad/s, 21.7 ms). See [`ModulatingConfig::window_s`] for the reasoning;
/// for another rotor use [`ModulatingConfig::for_natural_frequency`].
pub const DEFAULT_WINDOW_S: f64 = 0.02;
/// Default number of test functions per window.
pub const DEFAULT_FUNCTIONS: usize = 3;
/// Default hop as a fraction of the window (1/8).
pub const DEFAULT_HOP_FRACTION: f64 = 0.125;
/// Most test functions per window.
pub const MAX_FUNCTIONS: usize = 32;
/// Default [`ModulatingConfig::rcond_min`]: flags a normal matrix whose condition number
/// exceeds 1e8 (1e4 for the equilibrated design matrix). On table1 the default window
/// gives rcond 0.1 - 0.4; a 0.1 s window, too long for the free vibration, 5e-5.
pub const DEFAULT_MODULATING_RCOND_MIN: f64 = 1e-8;
/// Most windows that may overlap one window: hop_s >= window_s / MAX_OVERLAP.
pub const MAX_OVERLAP: f64 = 64.0;

/// How the O(sigma^2) bias that noise in the regressors gives plain least squares is
/// removed (module docs of `normal_equations`).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub enum NoiseCompensation {
    /// Plain least squares (no compensation).
    None,
    /// Compensate with sigma_x, sigma_z estimated from the data's fourth differences
    /// (white noise assumed; the default).
    #[default]
    Estimated,
    /// Compensate with these noise standard deviations.
    Known {
        /// sigma_x \[m\], finite and >= 0.
        sigma_x: f64,
        /// sigma_z \[m\], finite and >= 0.
        sigma_z: f64,
    },
}

/// Settings of [`super::ModulatingIdentifier`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ModulatingConfig {
    /// Window length L \[s\], finite and > 0; rounded to a whole number of sampling
    /// intervals, which must be at least 8 per test function (and 24).
    ///
    /// Choose about one period of the first natural frequency, 2 pi / w_n (the default,
    /// 20 ms, is table1's; [`ModulatingConfig::for_natural_frequency`] sets it). Why: the
    /// test functions (1 - u^2)^6 P_i(u), i < 3, are low-pass filters whose gain falls to
    /// one half between 9 / L and 15 / L rad/s and to 1 % near 22 / L rad/s, and the
    /// information is at the natural frequency (the free vibration) and at the running
    /// speed (the forced response): both must lie in the pass band. A window much
    /// longer than the natural period no longer passes the free vibration well (table1,
    /// 1200 rpm, SNR 40 dB, 1 s, 3 functions, hop L/8: RMS error in m 1.1e-4 at
    /// L = 20 ms, 7.6e-3 at L = 0.1 s, where the normal matrix's rcond falls from 0.15 to
    /// 5e-5); a much shorter one passes more noise and its quadrature error, ~(h / L)^6,
    /// grows (L = 10 ms: 1.9e-4 in m, clean-data error 1e-8). From 15 to 30 ms the RMS
    /// errors in m and k stay at 1.1e-4 (kz 1.5e-4) and those in c within 25 % of their
    /// best (3e-2); at 50 ms m and k are unchanged but c is 2.5x worse.
    pub window_s: f64,
    /// Hop between the starts of consecutive windows \[s\], finite, in
    /// [`window_s` / [`MAX_OVERLAP`], `window_s`]; rounded to a whole number of sampling intervals (at least one). Default L / 8:
    /// with L / 2 the errors were 2.5x larger, with L / 4 up to 1.8x (depending on the
    /// number of functions), with L / 8 and L / 16 the same (table1, 40 dB).
    pub hop_s: f64,
    /// Test functions per window, 1 ..= [`MAX_FUNCTIONS`]: (1 - u^2)^6 P_i(u),
    /// i = 0 .. functions - 1 (module `test_functions`). 2 to 5 perform alike at the
    /// default window and hop; the default is 3.
    pub functions: usize,
    /// Noise-bias compensation.
    pub noise: NoiseCompensation,
    /// Estimates whose rcond (reciprocal condition number of the equilibrated normal
    /// matrix, in [0, 1]) is below this are flagged as ill-conditioned (dimensionless).
    pub rcond_min: f64,
}

impl Default for ModulatingConfig {
    fn default() -> Self {
        Self {
            window_s: DEFAULT_WINDOW_S,
            hop_s: DEFAULT_WINDOW_S * DEFAULT_HOP_FRACTION,
            functions: DEFAULT_FUNCTIONS,
            noise: NoiseCompensation::Estimated,
            rcond_min: DEFAULT_MODULATING_RCOND_MIN,
        }
    }
}

impl ModulatingConfig {
    /// The default configuration with window length `window_s` \[s\] and hop
    /// [`DEFAULT_HOP_FRACTION`] of it (not validated: see [`validated`](Self::validated)).
    pub fn with_window(window_s: f64) -> Self {
        Self {
            window_s,
            hop_s: window_s * DEFAULT_HOP_FRACTION,
            ..Self::default()
        }
    }

    /// The default configuration with the window set to one period of the natural
    /// frequency `omega_n` \[rad/s\] (finite, > 0; e.g. sqrt(k/m) from a rough guess, a
    /// rap test or the plain algebraic identifier's early estimate): L = 2 pi / omega_n,
    /// hop L / 8.
    pub fn for_natural_frequency(omega_n: f64) -> Result<Self, InputError> {
        check("omega_n", omega_n, "finite and > 0 (rad/s)", |v| v > 0.0)?;
        Self::with_window(std::f64::consts::TAU / omega_n).validated()
    }

    /// Check every field (ranges in the field docs; the sample counts are checked against
    /// dt when the identifier is built).
    pub fn validated(self) -> Result<Self, InputError> {
        check("window_s", self.window_s, "finite and > 0 (s)", |v| v > 0.0)?;
        check(
            "hop_s",
            self.hop_s,
            "finite, >= window_s / 64 and <= window_s (s)",
            |v| v >= self.window_s / MAX_OVERLAP * (1.0 - 1e-12) && v <= self.window_s,
        )?;
        check(
            "functions",
            self.functions as f64,
            "an integer in 1 ..= 32",
            |v| (1.0..=MAX_FUNCTIONS as f64).contains(&v),
        )?;
        check("rcond_min", self.rcond_min, "finite and in [0, 1]", |v| {
            (0.0..=1.0).contains(&v)
        })?;
        if let NoiseCompensation::Known { sigma_x, sigma_z } = self.noise {
            check("sigma_x", sigma_x, "finite and >= 0 (m)", |v| v >= 0.0)?;
            check("sigma_z", sigma_z, "finite and >= 0 (m)", |v| v >= 0.0)?;
        }
        Ok(self)
    }
}
