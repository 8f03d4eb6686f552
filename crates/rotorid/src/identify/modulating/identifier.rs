//! The streaming modulating-function identifier: measurements in, window integrals
//! accumulated on the fly, the normal equations updated as each window completes.
//!
//! Per window j (start t_j, length L, u = 2 (t - t_j)/L - 1) and test function psi_i, the
//! sums over the window's samples (u-derivatives of psi, see `test_functions`; accumulated
//! by module `stream`, which the cross-coupled identifier shares)
//!
//! ```text
//! Sxx'' = sum psi'' x   Sx' = sum psi' x   Sx = sum psi x   Swz' = sum psi' w z   Sfx = sum psi fx
//! Szz'' = sum psi'' z   Sz' = sum psi' z   Sz = sum psi z   Swx' = sum psi' w x   Sw'x = sum psi w' x
//! Sfz = sum psi fz,     fx = w^2 sin(phi+alpha) - w' cos(phi+alpha),  fz = w' sin + w^2 cos
//! ```
//!
//! give one row per direction (the common factor h of the quadrature cancels):
//!
//! ```text
//! x: (m (2/L)^2) Sxx'' - (cx (2/L)) Sx' + kx Sx = -a (2/L) Swz' + mud Sfx
//! z: (m (2/L)^2) Szz'' - (cz (2/L)) Sz' + kz Sz =  a (2/L) Swx' + a Sw'x + mud Sfz
//! ```
//!
//! in the scaled unknowns theta_s = (m (2/L)^2, c (2/L), k), which keeps the three columns
//! of comparable size. As each window completes, its rows enter the normal equations and,
//! paired with the rows of the completed windows it overlaps, the covariance sums of
//! `uncertainty`. Memory: the open windows (at most ceil(L / hop) + 1, each 11 sums per
//! test function), as many completed ones, and the tabulated test functions; nothing
//! grows with the record.

use std::collections::VecDeque;

use super::config::{ModulatingConfig, NoiseCompensation};
use super::error::ModulatingError;
use super::estimate::{ModulatingDirection, ModulatingEstimate};
use super::normal_equations::Gram;
use super::stream::{setup, OpenWindow, WindowStream};
use super::uncertainty::{add_pair, pair_overlapping, ClosedWindow, Meat, Overlaps};
use crate::identify::{Known, Measurement};

/// The streaming modulating-function identifier (module docs of `modulating`). Feed it
/// measurements in time order with [`push`](Self::push); ask for the estimate from all
/// completed windows at any time with [`estimate`](Self::estimate).
#[derive(Debug, Clone)]
pub struct ModulatingIdentifier {
    known: Known,
    config: ModulatingConfig,
    stream: WindowStream<false>,
    /// Completed windows that the next ones may overlap.
    closed: VecDeque<ClosedWindow<3>>,
    overlaps: Overlaps,
    /// Normal equations, x and z.
    gram: [Gram<3>; 2],
    /// Covariance sums, x and z.
    meat: [Meat; 2],
    windows: u64,
}

impl ModulatingIdentifier {
    /// An identifier for data sampled every `dt` \[s\] (finite, > 0) with the known
    /// quantities `known` and `config` (validated; the window must span at least
    /// [`MIN_INTERVALS_PER_FUNCTION`](super::MIN_INTERVALS_PER_FUNCTION) sampling intervals
    /// per test function and [`MIN_INTERVALS`](super::MIN_INTERVALS), and at most
    /// 1e7 / functions^2).
    pub fn new(known: Known, dt: f64, config: ModulatingConfig) -> Result<Self, ModulatingError> {
        let s = setup(known, dt, config)?;
        Ok(Self {
            known: s.known,
            config: s.config,
            stream: WindowStream::new(s.dt, s.tf, s.hop),
            closed: VecDeque::new(),
            overlaps: s.overlaps,
            gram: [Gram::default(); 2],
            meat: [Meat::default(); 2],
            windows: 0,
        })
    }

    /// The configuration.
    pub fn config(&self) -> ModulatingConfig {
        self.config
    }

    /// The window length used, L = whole sampling intervals * dt \[s\].
    pub fn window_s(&self) -> f64 {
        self.stream.window_s()
    }

    /// The hop used \[s\].
    pub fn hop_s(&self) -> f64 {
        self.stream.hop_s()
    }

    /// Samples in one window (intervals + 1).
    pub fn window_samples(&self) -> usize {
        self.stream.window_samples()
    }

    /// Samples accepted so far.
    pub fn samples(&self) -> u64 {
        self.stream.n
    }

    /// Windows completed so far.
    pub fn windows(&self) -> u64 {
        self.windows
    }

    /// Take the next measurement. Errors (the identifier is left unchanged, so the
    /// caller may skip the sample): a non-finite field, or a time that is not the previous
    /// one plus dt within `1e-6 dt + 8 ulp(t)`.
    pub fn push(&mut self, m: &Measurement) -> Result<(), ModulatingError> {
        self.stream.validate(m)?;
        self.stream.accumulate(m, self.known.alpha);
        while let Some(win) = self.stream.pop_complete(m.t) {
            self.close(&win);
        }
        self.stream.advance(m);
        Ok(())
    }

    /// Add the rows of a completed window to the normal equations and its pairs with the
    /// completed windows it overlaps to the covariance sums.
    fn close(&mut self, win: &OpenWindow) {
        let two_l = self.stream.two_l();
        let (a, mud) = (self.known.a, self.known.mud);
        let f = self.stream.tf.functions();
        let mut done = ClosedWindow {
            start: win.start,
            phi: [Vec::with_capacity(f), Vec::with_capacity(f)],
            w: win.w,
            w_dot: win.w_dot,
        };
        for s in &win.sums {
            let (px, pz) = ([s[0], -s[1], s[2]], [s[5], -s[6], s[7]]);
            self.gram[0].add(&px, -a * two_l * s[3] + mud * s[4]);
            self.gram[1].add(&pz, a * two_l * s[8] + a * s[9] + mud * s[10]);
            done.phi[0].push(px);
            done.phi[1].push(pz);
        }
        // pairs with the earlier windows that overlap this one, and with itself
        let meat = &mut self.meat;
        let overlaps = &self.overlaps;
        pair_overlapping(
            &mut self.closed,
            done,
            self.stream.tf.intervals() as u64,
            self.stream.hop,
            overlaps.lags(),
            |early, late, lag| add_pair(meat, overlaps, early, late, lag, a, two_l),
        );
        self.windows += 1;
    }

    /// The noise standard deviations (sigma_x, sigma_z) \[m\] used for the standard
    /// errors: the given ones for [`NoiseCompensation::Known`], else the fourth-difference
    /// estimate (0 before five samples).
    pub fn noise_sigmas(&self) -> (f64, f64) {
        self.stream.noise_sigmas(self.config.noise)
    }

    /// The least-squares estimate from every window completed so far (singular, NaN, with
    /// rcond = 0 before enough rows exist).
    pub fn estimate(&self) -> ModulatingEstimate {
        let half_l = 0.5 * self.window_s();
        let (sx, sz) = self.noise_sigmas();
        let compensate = !matches!(self.config.noise, NoiseCompensation::None);
        let n0 = self.stream.tf.noise_gram();
        // unscaling of theta_s = (m (2/L)^2, c (2/L), k)
        let unscale = [half_l * half_l, half_l, 1.0];
        let dir = |d: usize, own: f64, other: f64| {
            let f = if compensate {
                own * own * self.windows as f64
            } else {
                0.0
            };
            let s = self.gram[d].solve(&n0.map(|r| r.map(|v| v * f)), &[0.0; 3]);
            if s.rcond <= 0.0 {
                return ModulatingDirection::SINGULAR;
            }
            // Cov(theta_s) = H^-1 V H^-1 (module `uncertainty`)
            let v = self.meat[d].combine(&s.theta, own, other);
            let hi = &s.h_inv;
            let var = |i: usize| {
                let mut acc = 0.0;
                for r in 0..3 {
                    for c in 0..3 {
                        acc += hi[i][r] * v[r][c] * hi[c][i];
                    }
                }
                acc
            };
            let se = [0, 1, 2].map(|i| {
                let v = var(i);
                if v >= 0.0 {
                    v.sqrt() * unscale[i]
                } else {
                    f64::NAN
                }
            });
            ModulatingDirection {
                m: s.theta[0] * unscale[0],
                c: s.theta[1] * unscale[1],
                k: s.theta[2] * unscale[2],
                std_error_m: se[0],
                std_error_c: se[1],
                std_error_k: se[2],
                rcond: s.rcond,
            }
        };
        ModulatingEstimate {
            t: self.stream.t_window_end,
            x: dir(0, sx, sz),
            z: dir(1, sz, sx),
            windows: self.windows,
            window_s: self.window_s(),
            hop_s: self.hop_s(),
            sigma_x: sx,
            sigma_z: sz,
            compensated: compensate,
        }
    }

    /// The estimate once every sample is in: [`Self::estimate`], or
    /// [`ModulatingError::RecordShorterThanWindow`] when not one window was completed.
    pub fn finish(&self) -> Result<ModulatingEstimate, ModulatingError> {
        self.stream.require_window(self.windows)?;
        Ok(self.estimate())
    }

    /// Restart from nothing (the next measurement is the first; its time may be anything).
    pub fn reset(&mut self) {
        self.stream.reset();
        self.closed.clear();
        self.gram = [Gram::default(); 2];
        self.meat = [Meat::default(); 2];
        self.windows = 0;
    }
}
