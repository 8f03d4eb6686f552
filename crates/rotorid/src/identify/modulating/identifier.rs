//! The streaming modulating-function identifier: measurements in, window integrals
//! accumulated on the fly, the normal equations updated as each window completes.
//!
//! Per window j (start t_j, length L, u = 2 (t - t_j)/L - 1) and test function psi_i, the
//! sums over the window's samples (u-derivatives of psi, see `test_functions`)
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
use super::noise_estimate::DifferenceNoise;
use super::normal_equations::Gram;
use super::test_functions::TestFunctions;
use super::uncertainty::{add_pair, ClosedWindow, Meat, Overlaps};
use crate::identify::sampling::check_on_time;
use crate::identify::InputError;
use crate::identify::{Known, Measurement};
use crate::model::{check, OutOfRange};

/// Sums per test function in an open window (module docs).
const NSUM: usize = 11;

/// Fewest sampling intervals per test function in a window.
pub const MIN_INTERVALS_PER_FUNCTION: usize = 8;
/// Fewest sampling intervals in a window, whatever the number of functions.
pub const MIN_INTERVALS: usize = 24;
/// Largest (sampling intervals per window) * functions^2.
const MAX_TABLE: f64 = 1e7;

/// A window that has started and not yet ended.
#[derive(Debug, Clone)]
struct OpenWindow {
    /// Index of its first sample.
    start: u64,
    /// `NSUM` sums per test function.
    sums: Vec<[f64; NSUM]>,
    /// w \[rad/s\] and w' \[rad/s^2\] at the centre sample.
    w: f64,
    w_dot: f64,
}

/// The streaming modulating-function identifier (module docs of `modulating`). Feed it
/// measurements in time order with [`push`](Self::push); ask for the estimate from all
/// completed windows at any time with [`estimate`](Self::estimate).
#[derive(Debug, Clone)]
pub struct ModulatingIdentifier {
    known: Known,
    dt: f64,
    config: ModulatingConfig,
    tf: TestFunctions,
    /// Hop in samples.
    hop: u64,
    open: VecDeque<OpenWindow>,
    /// Completed windows that the next ones may overlap.
    closed: VecDeque<ClosedWindow>,
    overlaps: Overlaps,
    /// Normal equations, x and z.
    gram: [Gram; 2],
    /// Covariance sums, x and z.
    meat: [Meat; 2],
    windows: u64,
    /// Time of the last sample of the last completed window \[s\].
    t_window_end: f64,
    noise: [DifferenceNoise; 2],
    /// Samples accepted.
    n: u64,
    t_prev: f64,
}

impl ModulatingIdentifier {
    /// An identifier for data sampled every `dt` \[s\] (finite, > 0) with the known
    /// quantities `known` and `config` (validated; the window must span at least
    /// [`MIN_INTERVALS_PER_FUNCTION`] sampling intervals per test function and
    /// [`MIN_INTERVALS`], and at most 1e7 / functions^2).
    pub fn new(known: Known, dt: f64, config: ModulatingConfig) -> Result<Self, ModulatingError> {
        let known = known.validated()?;
        let dt = check("dt", dt, "finite and > 0 (s)", |v| v > 0.0)?;
        let config = config.validated()?;
        let intervals = (config.window_s / dt).round();
        let needed = (MIN_INTERVALS_PER_FUNCTION * config.functions).max(MIN_INTERVALS);
        if intervals < needed as f64 {
            return Err(ModulatingError::WindowTooShort {
                window_s: config.window_s,
                dt,
                intervals: intervals as usize,
                needed,
                functions: config.functions,
            });
        }
        // the tables grow as intervals * functions^2 (module `uncertainty`)
        if intervals * (config.functions * config.functions) as f64 > MAX_TABLE {
            return Err(OutOfRange {
                field: "window_s",
                value: config.window_s,
                allowed: "at most 1e7 / functions^2 sampling intervals (s)",
            }
            .into());
        }
        let hop = (config.hop_s / dt).round().max(1.0).min(intervals) as u64;
        let tf = TestFunctions::new(intervals as usize, config.functions);
        let overlaps = Overlaps::new(&tf, hop as usize);
        Ok(Self {
            known,
            dt,
            config,
            tf,
            hop,
            open: VecDeque::new(),
            closed: VecDeque::new(),
            overlaps,
            gram: [Gram::default(); 2],
            meat: [Meat::default(); 2],
            windows: 0,
            t_window_end: f64::NAN,
            noise: [DifferenceNoise::default(); 2],
            n: 0,
            t_prev: f64::NAN,
        })
    }

    /// The configuration.
    pub fn config(&self) -> ModulatingConfig {
        self.config
    }

    /// The window length used, L = whole sampling intervals * dt \[s\].
    pub fn window_s(&self) -> f64 {
        self.tf.intervals() as f64 * self.dt
    }

    /// The hop used \[s\].
    pub fn hop_s(&self) -> f64 {
        self.hop as f64 * self.dt
    }

    /// Samples in one window (intervals + 1).
    pub fn window_samples(&self) -> usize {
        self.tf.intervals() + 1
    }

    /// Samples accepted so far.
    pub fn samples(&self) -> u64 {
        self.n
    }

    /// Windows completed so far.
    pub fn windows(&self) -> u64 {
        self.windows
    }

    /// Take the next measurement. Errors (the identifier is left unchanged, so the
    /// caller may skip the sample): a non-finite field, or a time that is not the previous
    /// one plus dt within `1e-6 dt + 8 ulp(t)`.
    pub fn push(&mut self, m: &Measurement) -> Result<(), ModulatingError> {
        self.validate(m)?;
        let s = &m.speed;
        let (w, wd) = (s.omega, s.omega_dot);
        let (sn, cs) = (s.phi + self.known.alpha).sin_cos();
        let w2 = w * w;
        let (x, z) = (m.x, m.z);
        let q = [
            x,
            z,
            w * z,
            w * x,
            wd * x,
            w2 * sn - wd * cs,
            wd * sn + w2 * cs,
        ];
        if self.n.is_multiple_of(self.hop) {
            self.open.push_back(OpenWindow {
                start: self.n,
                sums: vec![[0.0; NSUM]; self.tf.functions()],
                w: f64::NAN,
                w_dot: f64::NAN,
            });
        }
        let centre = self.tf.intervals() / 2;
        for win in self.open.iter_mut() {
            let k = (self.n - win.start) as usize;
            if k == centre {
                (win.w, win.w_dot) = (w, wd);
            }
            for (s, &[p, p1, p2]) in win.sums.iter_mut().zip(self.tf.at(k)) {
                let [x, z, wz, wx, wdx, fx, fz] = q;
                s[0] += p2 * x;
                s[1] += p1 * x;
                s[2] += p * x;
                s[3] += p1 * wz;
                s[4] += p * fx;
                s[5] += p2 * z;
                s[6] += p1 * z;
                s[7] += p * z;
                s[8] += p1 * wx;
                s[9] += p * wdx;
                s[10] += p * fz;
            }
        }
        let intervals = self.tf.intervals() as u64;
        while let Some(front) = self.open.front() {
            if self.n - front.start < intervals {
                break;
            }
            let win = self.open.pop_front().expect("front exists");
            self.close(&win);
            self.t_window_end = m.t;
        }
        self.noise[0].push(x);
        self.noise[1].push(z);
        self.n += 1;
        self.t_prev = m.t;
        Ok(())
    }

    /// Add the rows of a completed window to the normal equations and its pairs with the
    /// completed windows it overlaps to the covariance sums.
    fn close(&mut self, win: &OpenWindow) {
        let two_l = 2.0 / self.tf.intervals() as f64 / self.dt;
        let (a, mud) = (self.known.a, self.known.mud);
        let f = self.tf.functions();
        let mut done = ClosedWindow {
            start: win.start,
            phi: [Vec::with_capacity(f), Vec::with_capacity(f)],
            w: win.w,
            w_dot: win.w_dot,
        };
        for s in &win.sums {
            let (px, pz) = ([s[0], -s[1], s[2]], [s[5], -s[6], s[7]]);
            self.gram[0].add([px[0], px[1], px[2], -a * two_l * s[3] + mud * s[4]]);
            self.gram[1].add([
                pz[0],
                pz[1],
                pz[2],
                a * two_l * s[8] + a * s[9] + mud * s[10],
            ]);
            done.phi[0].push(px);
            done.phi[1].push(pz);
        }
        // pairs with the earlier windows that overlap this one, and with itself
        let reach = self.tf.intervals() as u64;
        while self
            .closed
            .front()
            .is_some_and(|c| done.start - c.start > reach)
        {
            self.closed.pop_front();
        }
        for early in &self.closed {
            let lag = ((done.start - early.start) / self.hop) as usize;
            if lag < self.overlaps.lags() {
                add_pair(&mut self.meat, &self.overlaps, early, &done, lag, a, two_l);
            }
        }
        add_pair(&mut self.meat, &self.overlaps, &done, &done, 0, a, two_l);
        self.closed.push_back(done);
        self.windows += 1;
    }

    /// The noise standard deviations (sigma_x, sigma_z) \[m\] used for the standard
    /// errors: the given ones for [`NoiseCompensation::Known`], else the fourth-difference
    /// estimate (0 before five samples).
    pub fn noise_sigmas(&self) -> (f64, f64) {
        match self.config.noise {
            NoiseCompensation::Known { sigma_x, sigma_z } => (sigma_x, sigma_z),
            NoiseCompensation::None | NoiseCompensation::Estimated => {
                let s = |d: &DifferenceNoise| {
                    let v = d.sigma();
                    if v.is_finite() {
                        v
                    } else {
                        0.0
                    }
                };
                (s(&self.noise[0]), s(&self.noise[1]))
            }
        }
    }

    /// The least-squares estimate from every window completed so far (singular, NaN, with
    /// rcond = 0 before enough rows exist).
    pub fn estimate(&self) -> ModulatingEstimate {
        let half_l = 0.5 * self.window_s();
        let (sx, sz) = self.noise_sigmas();
        let compensate = !matches!(self.config.noise, NoiseCompensation::None);
        let n0 = self.tf.noise_gram();
        // unscaling of theta_s = (m (2/L)^2, c (2/L), k)
        let unscale = [half_l * half_l, half_l, 1.0];
        let dir = |d: usize, own: f64, other: f64| {
            let f = if compensate {
                own * own * self.windows as f64
            } else {
                0.0
            };
            let s = self.gram[d].solve(&n0.map(|r| r.map(|v| v * f)));
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
            t: self.t_window_end,
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
        if self.windows == 0 {
            return Err(ModulatingError::RecordShorterThanWindow {
                samples: self.samples() as usize,
                needed: self.window_samples(),
                window_s: self.window_s(),
                dt: self.dt,
            });
        }
        Ok(self.estimate())
    }

    /// Restart from nothing (the next measurement is the first; its time may be anything).
    pub fn reset(&mut self) {
        self.open.clear();
        self.closed.clear();
        self.gram = [Gram::default(); 2];
        self.meat = [Meat::default(); 2];
        self.windows = 0;
        self.t_window_end = f64::NAN;
        self.noise = [DifferenceNoise::default(); 2];
        self.n = 0;
        self.t_prev = f64::NAN;
    }

    fn validate(&self, m: &Measurement) -> Result<(), InputError> {
        let s = &m.speed;
        let fields = [
            ("t", m.t),
            ("x", m.x),
            ("z", m.z),
            ("phi", s.phi),
            ("phi_dot", s.omega),
            ("phi_ddot", s.omega_dot),
        ];
        if let Some(&(field, value)) = fields.iter().find(|(_, v)| !v.is_finite()) {
            return Err(InputError::NotFinite {
                index: self.n,
                field,
                value,
            });
        }
        if self.n > 0 {
            check_on_time(self.n, m.t, self.t_prev, self.dt)?;
        }
        Ok(())
    }
}
