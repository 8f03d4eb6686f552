//! What both modulating-function identifiers (Jeffcott and cross-coupled) do with each
//! measurement before their rows are formed: validate it, open a window every hop,
//! accumulate the window sums of every open window, hand over the windows that complete,
//! and feed the noise estimate.
//!
//! Per window j (start t_j, length L, u = 2 (t - t_j)/L - 1) and test function psi_i, the
//! sums over the window's samples (u-derivatives of psi, module `test_functions`) are
//!
//! ```text
//! s0 = sum psi'' x   s1 = sum psi' x   s2 = sum psi x    s3 = sum psi' w z   s4 = sum psi fx
//! s5 = sum psi'' z   s6 = sum psi' z   s7 = sum psi z    s8 = sum psi' w x   s9 = sum psi w' x
//! s10 = sum psi fz,  fx = w^2 sin(phi+alpha) - w' cos(phi+alpha),  fz = w' sin + w^2 cos
//! ```
//!
//! With `NOISE_SUMS` (the cross-coupled identifier), each window also accumulates, summed
//! over its test functions, the four speed-weighted sums its noise compensation needs
//! (module `cross`): sum psi'^2 w, sum psi psi' w, sum psi psi' w', sum psi^2 w'.

use std::collections::VecDeque;

use super::config::{ModulatingConfig, NoiseCompensation};
use super::error::ModulatingError;
use super::noise_estimate::DifferenceNoise;
use super::test_functions::TestFunctions;
use super::uncertainty::Overlaps;
use crate::identify::sampling::check_on_time;
use crate::identify::{InputError, Known, Measurement};
use crate::model::{check, OutOfRange};

/// Fewest sampling intervals per test function in a window.
pub const MIN_INTERVALS_PER_FUNCTION: usize = 8;
/// Fewest sampling intervals in a window, whatever the number of functions.
pub const MIN_INTERVALS: usize = 24;
/// Largest (sampling intervals per window) * functions^2.
const MAX_TABLE: f64 = 1e7;

/// What a modulating identifier is built from, checked.
pub(crate) struct Setup {
    pub known: Known,
    pub dt: f64,
    pub config: ModulatingConfig,
    pub tf: TestFunctions,
    /// Hop in samples.
    pub hop: u64,
    pub overlaps: Overlaps,
}

/// Check `known`, `dt` \[s\] and `config` (the window must span at least
/// [`MIN_INTERVALS_PER_FUNCTION`] sampling intervals per test function and
/// [`MIN_INTERVALS`], and at most 1e7 / functions^2) and tabulate the test functions and
/// their overlaps.
pub(crate) fn setup(
    known: Known,
    dt: f64,
    config: ModulatingConfig,
) -> Result<Setup, ModulatingError> {
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
    Ok(Setup {
        known,
        dt,
        config,
        tf,
        hop,
        overlaps,
    })
}

/// Sums per test function in an open window (module docs).
pub(crate) const NSUM: usize = 11;

/// A window that has started and not yet ended (or has just completed).
#[derive(Debug, Clone)]
pub(crate) struct OpenWindow {
    /// Index of its first sample.
    pub start: u64,
    /// `NSUM` sums per test function.
    pub sums: Vec<[f64; NSUM]>,
    /// w \[rad/s\] and w' \[rad/s^2\] at the centre sample.
    pub w: f64,
    pub w_dot: f64,
    /// sum over functions and samples of psi'^2 w, psi psi' w, psi psi' w', psi^2 w'
    /// (only with `NOISE_SUMS`; zero otherwise).
    pub noise: [f64; 4],
}

/// The window machinery shared by the modulating identifiers (module docs).
#[derive(Debug, Clone)]
pub(crate) struct WindowStream<const NOISE_SUMS: bool> {
    /// The sampling period \[s\].
    pub dt: f64,
    pub tf: TestFunctions,
    /// Hop in samples.
    pub hop: u64,
    open: VecDeque<OpenWindow>,
    /// Per sample offset k: sum_i (psi_i^2, psi_i psi_i', psi_i'^2) (`NOISE_SUMS` only).
    squares: Vec<[f64; 3]>,
    noise: [DifferenceNoise; 2],
    /// Samples accepted.
    pub n: u64,
    t_prev: f64,
    /// Time of the last sample of the last completed window \[s\].
    pub t_window_end: f64,
}

impl<const NOISE_SUMS: bool> WindowStream<NOISE_SUMS> {
    /// The stream of windows of `tf` every `hop` samples of period `dt` \[s\].
    pub(crate) fn new(dt: f64, tf: TestFunctions, hop: u64) -> Self {
        let squares = if NOISE_SUMS {
            (0..=tf.intervals())
                .map(|k| {
                    tf.at(k).iter().fold([0.0; 3], |acc, &[p, p1, _]| {
                        [acc[0] + p * p, acc[1] + p * p1, acc[2] + p1 * p1]
                    })
                })
                .collect()
        } else {
            Vec::new()
        };
        Self {
            dt,
            tf,
            hop,
            open: VecDeque::new(),
            squares,
            noise: [DifferenceNoise::default(); 2],
            n: 0,
            t_prev: f64::NAN,
            t_window_end: f64::NAN,
        }
    }

    /// The window length, L = whole sampling intervals * dt \[s\].
    pub(crate) fn window_s(&self) -> f64 {
        self.tf.intervals() as f64 * self.dt
    }

    /// 2 / L \[1/s\].
    pub(crate) fn two_l(&self) -> f64 {
        2.0 / self.tf.intervals() as f64 / self.dt
    }

    /// The hop \[s\].
    pub(crate) fn hop_s(&self) -> f64 {
        self.hop as f64 * self.dt
    }

    /// Samples in one window (intervals + 1).
    pub(crate) fn window_samples(&self) -> usize {
        self.tf.intervals() + 1
    }

    /// [`ModulatingError::RecordShorterThanWindow`] when not one of the `windows` has
    /// completed.
    pub(crate) fn require_window(&self, windows: u64) -> Result<(), ModulatingError> {
        if windows == 0 {
            return Err(ModulatingError::RecordShorterThanWindow {
                samples: self.n as usize,
                needed: self.window_samples(),
                window_s: self.window_s(),
                dt: self.dt,
            });
        }
        Ok(())
    }

    /// Check the next measurement: every field finite, on the uniform grid.
    pub(crate) fn validate(&self, m: &Measurement) -> Result<(), InputError> {
        let dt = self.dt;
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
            check_on_time(self.n, m.t, self.t_prev, dt)?;
        }
        Ok(())
    }

    /// Add the (validated) measurement `m` to every open window, opening one first when a
    /// hop begins at it; `alpha` \[rad\] is the unbalance angle.
    pub(crate) fn accumulate(&mut self, m: &Measurement, alpha: f64) {
        let s = &m.speed;
        let (w, wd) = (s.omega, s.omega_dot);
        let (sn, cs) = (s.phi + alpha).sin_cos();
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
                noise: [0.0; 4],
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
            if NOISE_SUMS {
                let [pp, pp1, p1p1] = self.squares[k];
                win.noise[0] += p1p1 * w;
                win.noise[1] += pp1 * w;
                win.noise[2] += pp1 * wd;
                win.noise[3] += pp * wd;
            }
        }
    }

    /// The oldest open window if it has completed with the current sample (call until
    /// `None` after [`accumulate`](Self::accumulate), before [`advance`](Self::advance)).
    pub(crate) fn pop_complete(&mut self, t: f64) -> Option<OpenWindow> {
        let front = self.open.front()?;
        if self.n - front.start < self.tf.intervals() as u64 {
            return None;
        }
        self.t_window_end = t;
        self.open.pop_front()
    }

    /// Finish the sample `m`: the noise estimate takes it, the count advances.
    pub(crate) fn advance(&mut self, m: &Measurement) {
        self.noise[0].push(m.x);
        self.noise[1].push(m.z);
        self.n += 1;
        self.t_prev = m.t;
    }

    /// The noise standard deviations (sigma_x, sigma_z) \[m\] under `noise`: the given
    /// ones for [`NoiseCompensation::Known`], else the fourth-difference estimate so far (0
    /// before five samples).
    pub(crate) fn noise_sigmas(&self, noise: NoiseCompensation) -> (f64, f64) {
        if let NoiseCompensation::Known { sigma_x, sigma_z } = noise {
            return (sigma_x, sigma_z);
        }
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

    /// Forget every sample.
    pub(crate) fn reset(&mut self) {
        self.open.clear();
        self.noise = [DifferenceNoise::default(); 2];
        self.n = 0;
        self.t_prev = f64::NAN;
        self.t_window_end = f64::NAN;
    }
}
