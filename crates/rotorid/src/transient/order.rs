//! Order tracking: each probe's nX vectors, one per shaft revolution, by least squares on
//! the samples of that revolution (docs/transient.md section 2).
//!
//! The revolutions are the intervals between keyphasor events, where the shaft angle
//! measured from the event, `psi = phi - phi_kp`, passes a multiple of 2 pi. Over the
//! samples s_k of one revolution (psi_k its angle, psi_m the angle at its middle) the
//! signal is fitted by
//!
//! ```text
//! s_k = c + d (psi_k - psi_m) / (2 pi) + sum_{h=1..H} [ a_h cos(h psi_k) + b_h sin(h psi_k) ] + e_k
//! ```
//!
//! with H at least the highest order asked for (default 8: the harmonics a rig shows are
//! fitted, so that they do not count as noise), the constant c the probe's gap (its DC,
//! at mid-revolution) and d its drift over the revolution. The drift is not fitted with
//! the harmonics: a ramp over one revolution is nearly a sum of sines (its projection on
//! eight harmonics leaves 7 % of its variance), so fitting it would multiply the variance
//! of the sine coefficients by up to 10. It is the change of the neighbouring
//! revolutions' constants, `d_k = (c_(k+1) - c_(k-1)) / 2`, and its effect on the
//! coefficients, `d (A^T A)^-1 A^T u`, is subtracted after the fit. The nX vector is
//! `V_n = a_n - i b_n`: the nX part of the signal is `Re(V_n e^{i n psi})`, its amplitude
//! `|V_n|` zero-to-peak, its phase lag `-arg V_n` the angle (in degrees of the nX cycle)
//! from the keyphasor event to the positive peak, the convention of machinery-protection
//! systems. The covariance of the coefficients is `sigma^2 (A^T A)^-1` with
//! `sigma^2 = RSS / (N - p)` (N samples, p = 1 + 2 H unknowns, RSS after the drift): the noise is that
//! revolution's own residual, not a constant. The standard deviation reported per vector
//! is `sqrt((var Re V + var Im V) / 2)`, the deviation of either component for white
//! noise.
//!
//! Over one revolution the fit treats the vector as constant; on a run-up through a
//! resonance the vector turns by a fraction of a degree per revolution at sweep rates of
//! some rad/s^2 (docs/transient.md section 5 gives the figures).
//! Reference: order tracking by least squares, R. B. Randall, *Vibration-based condition
//! monitoring*, Wiley, 2011, sec. 3.6.

use std::f64::consts::TAU;

use nalgebra::{Complex, DMatrix, DVector};
use serde::Serialize;

use super::error::{check_finite, same_length, TransientError};
use crate::model::{rad_per_s_to_rpm, OutOfRange};

/// A complex vector \[signal unit\].
pub type C64 = Complex<f64>;

/// Default harmonics fitted per revolution.
pub const DEFAULT_HARMONICS: usize = 8;
/// The highest order that can be tracked.
pub const MAX_ORDER: u32 = 32;

/// What to track.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct OrderSettings {
    /// The orders n (1 = 1X), each from 1 to [`MAX_ORDER`], distinct.
    pub orders: Vec<u32>,
    /// Harmonics H fitted per revolution (at least the highest order; fewer are used on a
    /// revolution with too few samples for them, never fewer than the highest order).
    pub harmonics: usize,
}

impl Default for OrderSettings {
    /// Orders 1 and 2, [`DEFAULT_HARMONICS`] harmonics.
    fn default() -> Self {
        Self {
            orders: vec![1, 2],
            harmonics: DEFAULT_HARMONICS,
        }
    }
}

impl OrderSettings {
    /// Check the orders and harmonics.
    pub fn validate(&self) -> Result<(), TransientError> {
        if self.orders.is_empty() {
            return Err(OutOfRange {
                field: "orders",
                value: 0.0,
                allowed: "at least one order from 1 to 32",
            }
            .into());
        }
        for (i, &n) in self.orders.iter().enumerate() {
            if !(1..=MAX_ORDER).contains(&n) || self.orders[..i].contains(&n) {
                return Err(OutOfRange {
                    field: "orders",
                    value: f64::from(n),
                    allowed: "distinct whole numbers from 1 to 32",
                }
                .into());
            }
        }
        if !(1..=64).contains(&self.harmonics) {
            return Err(OutOfRange {
                field: "harmonics",
                value: self.harmonics as f64,
                allowed: "a whole number from 1 to 64",
            }
            .into());
        }
        Ok(())
    }

    /// The highest order.
    pub fn max_order(&self) -> u32 {
        self.orders.iter().copied().max().unwrap_or(1)
    }
}

/// One revolution (or one speed bin) of one signal.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Revolution {
    /// The keyphasor event that starts it \[s\].
    pub t_start: f64,
    /// The event that ends it \[s\].
    pub t_end: f64,
    /// Its mean speed 2 pi / (t_end - t_start) \[rad/s\], smoothed over the revolutions
    /// around it ([`SPEED_HALF_WINDOW`]; a bin: the mean of its revolutions').
    pub speed: f64,
    /// The constant c at mid-revolution (the probe's gap) \[signal unit\].
    pub dc: f64,
    /// RMS of the residuals e_k \[signal unit\].
    pub noise: f64,
    /// The nX vector per order of [`Tracked::orders`] \[signal unit\], zero-to-peak.
    pub vectors: Vec<C64>,
    /// Standard deviation of Re V and of Im V per order \[signal unit\].
    pub std: Vec<f64>,
    /// Revolutions averaged (1 per revolution; a bin's count).
    pub count: usize,
}

impl Revolution {
    /// The speed \[rev/min\].
    pub fn rpm(&self) -> f64 {
        rad_per_s_to_rpm(self.speed)
    }
}

/// The order-tracked vectors of one signal.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Tracked {
    /// The orders, in the order of each revolution's `vectors`.
    pub orders: Vec<u32>,
    /// The revolutions in time order.
    pub revolutions: Vec<Revolution>,
}

impl Tracked {
    /// The position of order `n` in [`Tracked::orders`].
    pub fn index_of(&self, n: u32) -> Option<usize> {
        self.orders.iter().position(|&o| o == n)
    }
}

/// The whole revolutions of `psi` \[rad\] (the shaft angle from the keyphasor event,
/// increasing): for each, the samples `a..b` and the times of the events at its ends
/// (where psi passes the multiples of 2 pi, linearly interpolated between samples).
pub fn revolutions(t: &[f64], psi: &[f64]) -> Vec<(std::ops::Range<usize>, f64, f64)> {
    let mut edges: Vec<(usize, f64)> = Vec::new();
    let Some(&first) = psi.first() else {
        return Vec::new();
    };
    let mut next = (first / TAU).ceil() * TAU;
    for i in 0..psi.len() {
        if psi[i] >= next {
            let te = if i == 0 {
                t[0]
            } else {
                let (p0, p1) = (psi[i - 1], psi[i]);
                t[i - 1] + (next - p0) / (p1 - p0) * (t[i] - t[i - 1])
            };
            edges.push((i, te));
            next += TAU;
            while psi[i] >= next {
                // more than a revolution between two samples: not a usable record here
                next += TAU;
                edges.push((i, te));
            }
        }
    }
    edges
        .windows(2)
        .filter(|w| w[1].0 > w[0].0)
        .map(|w| (w[0].0..w[1].0, w[0].1, w[1].1))
        .collect()
}

/// Track `signal` (same length as `t` \[s\] and `psi` \[rad\], the shaft angle from the
/// keyphasor event, increasing) per revolution (module doc).
pub fn track(
    t: &[f64],
    psi: &[f64],
    signal: &[f64],
    settings: &OrderSettings,
) -> Result<Tracked, TransientError> {
    let mut one = track_signals(t, psi, &[signal], settings)?;
    Ok(one.pop().expect("one signal tracked"))
}

/// Track each of `signals` (the probes of one record: each the same length as `t` and
/// `psi`) per revolution, as [`track`] does one, with the same results bit for bit. The
/// regressors of a revolution, its normal equations and their factorisation depend on
/// the angle alone, so they are computed once for all the signals, and the regressors once
/// per sample instead of twice per signal.
pub fn track_signals(
    t: &[f64],
    psi: &[f64],
    signals: &[&[f64]],
    settings: &OrderSettings,
) -> Result<Vec<Tracked>, TransientError> {
    settings.validate()?;
    same_length("psi", psi.len(), "t", t.len())?;
    for s in signals {
        same_length("signal", s.len(), "t", t.len())?;
    }
    check_finite("t", t)?;
    check_finite("psi", psi)?;
    for s in signals {
        check_finite("signal", s)?;
    }
    let top = settings.max_order() as usize;
    let wanted = settings.harmonics.max(top);
    let revs = revolutions(t, psi);
    if revs.len() < 2 {
        return Err(TransientError::TooFew {
            what: "whole revolutions between keyphasor events".into(),
            found: revs.len(),
            needed: 2,
        });
    }
    let mut shared = Vec::with_capacity(revs.len());
    let mut fits: Vec<Vec<SignalFit>> = signals
        .iter()
        .map(|_| Vec::with_capacity(revs.len()))
        .collect();
    let mut normal = Normal::default();
    for (k, (range, t0, _)) in revs.iter().enumerate() {
        let n = range.len();
        // unknowns p = 1 + 2 H, at least as many residual degrees of freedom as unknowns
        let h = wanted.min((n / 2).saturating_sub(1) / 2);
        if h < top {
            return Err(TransientError::TooFewSamplesPerRevolution {
                revolution: k,
                t: *t0,
                samples: n,
                order: top as u32,
                needed: 2 * (1 + 2 * top),
            });
        }
        shared.push(normal.build(&psi[range.clone()], h, &settings.orders, k, *t0)?);
        for (s, out) in signals.iter().zip(&mut fits) {
            out.push(normal.fit(&s[range.clone()]));
        }
    }
    Ok(fits
        .into_iter()
        .map(|f| finish(&revs, &shared, f, settings))
        .collect())
}

/// One signal's revolutions from their fits: the gap's drift per revolution from the
/// neighbours' constants, and its effect on each revolution's coefficients removed (module
/// doc); the vectors, their standard deviations, the speeds smoothed.
fn finish(
    revs: &[(std::ops::Range<usize>, f64, f64)],
    shared: &[RevolutionFit],
    fits: Vec<SignalFit>,
    settings: &OrderSettings,
) -> Tracked {
    let c: Vec<f64> = fits.iter().map(|f| f.theta[0]).collect();
    let m = c.len();
    let mut out = Vec::with_capacity(m);
    for (k, (((_, t0, t1), r), f)) in revs.iter().zip(shared).zip(fits).enumerate() {
        let (t0, t1) = (*t0, *t1);
        let d = match k {
            0 => c[1] - c[0],
            _ if k == m - 1 => c[m - 1] - c[m - 2],
            _ => 0.5 * (c[k + 1] - c[k - 1]),
        };
        let theta: Vec<f64> = f.theta.iter().zip(&r.g).map(|(th, g)| th - d * g).collect();
        let rss = (f.rss - 2.0 * d * f.eu + d * d * r.uu).max(0.0);
        let sigma2 = rss / (r.n - r.p) as f64;
        let (vectors, std) = settings
            .orders
            .iter()
            .zip(&r.inv_diag)
            .map(|(&o, &(ia, ib))| {
                let j = o as usize;
                let (a, b) = (theta[2 * j - 1], theta[2 * j]);
                let var = 0.5 * sigma2 * (ia + ib);
                (C64::new(a, -b), var.max(0.0).sqrt())
            })
            .unzip();
        out.push(Revolution {
            t_start: t0,
            t_end: t1,
            speed: TAU / (t1 - t0),
            dc: theta[0],
            noise: (rss / r.n as f64).sqrt(),
            vectors,
            std,
            count: 1,
        });
    }
    smooth_speeds(&mut out);
    Tracked {
        orders: settings.orders.clone(),
        revolutions: out,
    }
}

/// Revolutions on each side of one whose speeds smooth its own.
pub const SPEED_HALF_WINDOW: usize = 10;

/// Each revolution's speed replaced by a local quadratic in time fitted to the speeds of
/// the 2 [`SPEED_HALF_WINDOW`] + 1 revolutions around it, at its own mid time. Keyphasor
/// events timed between samples scatter by a fraction of a sample: at 5 kHz and 7700 rpm
/// that scatters the speeds of single revolutions by about 20 rpm, which shuffles
/// neighbouring revolutions along the speed axis and makes dips in a Bode curve that are
/// not there. The speed of a run-up changes smoothly over 21 revolutions; the fit keeps
/// a constant acceleration exactly.
fn smooth_speeds(revs: &mut [Revolution]) {
    let n = revs.len();
    if n < 5 {
        return;
    }
    let mid: Vec<f64> = revs.iter().map(|r| 0.5 * (r.t_start + r.t_end)).collect();
    let speed: Vec<f64> = revs.iter().map(|r| r.speed).collect();
    for k in 0..n {
        let lo = k.saturating_sub(SPEED_HALF_WINDOW);
        let hi = (k + SPEED_HALF_WINDOW + 1).min(n);
        let scale = (mid[hi - 1] - mid[lo]).max(f64::MIN_POSITIVE);
        let mut ata = nalgebra::Matrix3::<f64>::zeros();
        let mut aty = nalgebra::Vector3::<f64>::zeros();
        for j in lo..hi {
            let u = (mid[j] - mid[k]) / scale;
            let x = nalgebra::Vector3::new(1.0, u, u * u);
            ata += x * x.transpose();
            aty += x * speed[j];
        }
        if let Some(inv) = ata.try_inverse() {
            let w = (inv * aty)[0];
            if w.is_finite() && w > 0.0 {
                revs[k].speed = w;
            }
        }
    }
}

/// The least squares of one revolution, the part common to every signal: the regressors
/// of each sample, the normal matrix A^T A factorised, and what a drift d u
/// (u = (psi - psi_m) / 2 pi) changes (module doc). Its buffers are reused from one
/// revolution to the next.
#[derive(Default)]
struct Normal {
    /// The regressors (1, cos psi, sin psi, ..., cos H psi, sin H psi) of each sample,
    /// row after row.
    rows: Vec<f64>,
    /// psi - psi_m of each sample (u times 2 pi).
    dpsi: Vec<f64>,
    /// The upper triangle of A^T A, row-major p x p.
    ata: Vec<f64>,
    /// Unknowns of the current revolution.
    p: usize,
    /// The factorisation of the current revolution's A^T A.
    chol: Option<nalgebra::linalg::Cholesky<f64, nalgebra::Dyn>>,
    /// Scratch for one signal's A^T (s - s_0).
    atb: Vec<f64>,
}

/// A revolution's fit without drift, the part common to every signal: g = (A^T A)^-1
/// A^T u (a drift d moves the coefficients by -d g), |u - A g|^2, the diagonal of
/// (A^T A)^-1 at (a_n, b_n) of each order, N and p.
struct RevolutionFit {
    g: Vec<f64>,
    uu: f64,
    inv_diag: Vec<(f64, f64)>,
    n: usize,
    p: usize,
}

/// A revolution's fit of one signal without drift: the coefficients
/// (c, a_1, b_1, ..., a_H, b_H), the residual sum of squares, and e.u with e the residual.
struct SignalFit {
    theta: Vec<f64>,
    rss: f64,
    eu: f64,
}

impl Normal {
    /// The regressors, normal equations and factorisation of the revolution with angles
    /// `psi` and `h` harmonics; `orders` the orders whose variances are wanted; `k`, `t0`
    /// name the revolution in an error.
    fn build(
        &mut self,
        psi: &[f64],
        h: usize,
        orders: &[u32],
        k: usize,
        t0: f64,
    ) -> Result<RevolutionFit, TransientError> {
        let p = 1 + 2 * h;
        let n = psi.len();
        self.p = p;
        let mid = 0.5 * (psi[0] + psi[n - 1]);
        self.rows.clear();
        self.dpsi.clear();
        self.ata.clear();
        self.ata.resize(p * p, 0.0);
        let mut atu = DVector::<f64>::zeros(p);
        let mut uu = 0.0;
        for &pk in psi {
            let start = self.rows.len();
            self.rows.push(1.0);
            let (s1, c1) = pk.sin_cos();
            let base = C64::new(c1, s1);
            let mut e = base;
            for _ in 0..h {
                self.rows.push(e.re);
                self.rows.push(e.im);
                e *= base;
            }
            let row = &self.rows[start..];
            let u = (pk - mid) / TAU;
            self.dpsi.push(pk - mid);
            uu += u * u;
            for i in 0..p {
                let ri = row[i];
                atu[i] += ri * u;
                // each entry summed over the samples in their order, as a plain loop does
                for (a, &rj) in self.ata[i * p + i..(i + 1) * p].iter_mut().zip(&row[i..]) {
                    *a += ri * rj;
                }
            }
        }
        let ata = DMatrix::<f64>::from_fn(p, p, |i, j| {
            let (i, j) = if i <= j { (i, j) } else { (j, i) };
            self.ata[i * p + j]
        });
        let chol = ata
            .cholesky()
            .ok_or(TransientError::TooFewSamplesPerRevolution {
                revolution: k,
                t: t0,
                samples: n,
                order: h as u32,
                needed: 2 * p,
            })?;
        let g = chol.solve(&atu);
        // the diagonal of (A^T A)^-1 where it is needed: column by column, as the whole
        // inverse is computed
        let inv = |i: usize| {
            let mut e = DVector::<f64>::zeros(p);
            e[i] = 1.0;
            chol.solve_mut(&mut e);
            e[i]
        };
        let inv_diag = orders
            .iter()
            .map(|&o| {
                let j = o as usize;
                (inv(2 * j - 1), inv(2 * j))
            })
            .collect();
        let uu = uu - g.dot(&atu);
        self.chol = Some(chol);
        Ok(RevolutionFit {
            g: g.iter().copied().collect(),
            uu,
            inv_diag,
            n,
            p,
        })
    }

    /// The fit of the signal `s` over the revolution last built.
    fn fit(&mut self, s: &[f64]) -> SignalFit {
        let p = self.p;
        let chol = self
            .chol
            .as_ref()
            .expect("a revolution built before its fits");
        // the signal about its first sample, so the sums of squares keep their digits
        let s0 = s[0];
        self.atb.clear();
        self.atb.resize(p, 0.0);
        for (row, &sk) in self.rows.chunks_exact(p).zip(s) {
            let y = sk - s0;
            for (a, &ri) in self.atb.iter_mut().zip(row) {
                *a += ri * y;
            }
        }
        let mut theta = DVector::from_column_slice(&self.atb);
        chol.solve_mut(&mut theta);
        let mut rss = 0.0;
        let mut eu = 0.0;
        for ((row, &sk), &dpsi) in self.rows.chunks_exact(p).zip(s).zip(&self.dpsi) {
            let f: f64 = row.iter().zip(theta.iter()).map(|(r, c)| r * c).sum();
            let e = sk - s0 - f;
            rss += e * e;
            eu += e * dpsi / TAU;
        }
        theta[0] += s0;
        SignalFit {
            theta: theta.iter().copied().collect(),
            rss,
            eu,
        }
    }
}

/// The revolutions of `tracked` averaged per speed bin of `width_rpm` \[rev/min\] (bin j
/// holds speeds in \[j w, (j + 1) w)): each vector the mean of its revolutions' weighted
/// by their inverse variances, with the standard deviation of that mean; speed, gap and
/// noise the plain means; bins in the order of their first revolution.
pub fn bin(tracked: &Tracked, width_rpm: f64) -> Result<Tracked, TransientError> {
    if !(width_rpm.is_finite() && width_rpm > 0.0) {
        return Err(OutOfRange {
            field: "bin-rpm",
            value: width_rpm,
            allowed: "finite and > 0 (rev/min)",
        }
        .into());
    }
    let m = tracked.orders.len();
    // each bin's place in `groups` by its key: a narrow bin on a long record makes
    // thousands of bins, and a search through them per revolution grew as their product
    let mut index: std::collections::HashMap<i64, usize> = std::collections::HashMap::new();
    let mut groups: Vec<Vec<&Revolution>> = Vec::new();
    for r in &tracked.revolutions {
        let key = (r.rpm() / width_rpm).floor() as i64;
        let i = *index.entry(key).or_insert_with(|| {
            groups.push(Vec::new());
            groups.len() - 1
        });
        groups[i].push(r);
    }
    let revolutions = groups
        .into_iter()
        .map(|g| {
            let n = g.len() as f64;
            let mut vectors = Vec::with_capacity(m);
            let mut std = Vec::with_capacity(m);
            for o in 0..m {
                let (mut sw, mut sv) = (0.0, C64::new(0.0, 0.0));
                for r in &g {
                    let w = 1.0 / r.std[o].max(f64::MIN_POSITIVE).powi(2);
                    sw += w;
                    sv += r.vectors[o] * w;
                }
                vectors.push(sv / sw);
                std.push((1.0 / sw).sqrt());
            }
            Revolution {
                t_start: g.iter().map(|r| r.t_start).fold(f64::INFINITY, f64::min),
                t_end: g.iter().map(|r| r.t_end).fold(f64::NEG_INFINITY, f64::max),
                speed: g.iter().map(|r| r.speed).sum::<f64>() / n,
                dc: g.iter().map(|r| r.dc).sum::<f64>() / n,
                noise: g.iter().map(|r| r.noise).sum::<f64>() / n,
                vectors,
                std,
                count: g.iter().map(|r| r.count).sum(),
            }
        })
        .collect();
    Ok(Tracked {
        orders: tracked.orders.clone(),
        revolutions,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    /// A run-up psi(t) = w0 t + a t^2 / 2 sampled at `fs`.
    fn run_up(w0: f64, a: f64, fs: f64, dur: f64) -> (Vec<f64>, Vec<f64>) {
        let n = (dur * fs) as usize;
        let t: Vec<f64> = (0..n).map(|i| i as f64 / fs).collect();
        let psi = t.iter().map(|&t| w0 * t + 0.5 * a * t * t).collect();
        (t, psi)
    }

    #[test]
    fn vectors_of_a_known_signal_with_gap_drift_and_harmonics() {
        // 1X = 3e-5 at lag 40 deg, 2X = 1e-5 at lag 250 deg, 3X present, the gap drifting
        let (t, psi) = run_up(100.0, 20.0, 5000.0, 2.5);
        let v1 = C64::from_polar(3e-5, -40f64.to_radians());
        let v2 = C64::from_polar(1e-5, -250f64.to_radians());
        let s: Vec<f64> = t
            .iter()
            .zip(&psi)
            .map(|(&t, &p)| {
                -1e-3
                    + 2e-6 * t
                    + (v1 * C64::from_polar(1.0, p)).re
                    + (v2 * C64::from_polar(1.0, 2.0 * p)).re
                    + 4e-6 * (3.0 * p + 1.0).cos()
            })
            .collect();
        let tr = track(&t, &psi, &s, &OrderSettings::default()).unwrap();
        assert!(tr.revolutions.len() > 40);
        for r in &tr.revolutions {
            // the drift (1e-7 m per revolution, linear in time) is removed as linear in
            // angle: what is left is its 1 % curvature over a revolution of this run-up
            // (3e-10 m; uncorrected it leaks 3e-8 m into the 1X)
            assert!(
                (r.vectors[0] - v1).norm() < 1e-9,
                "{:e}",
                (r.vectors[0] - v1).norm()
            );
            assert!((r.vectors[1] - v2).norm() < 1e-9);
            let tm = 0.5 * (r.t_start + r.t_end);
            // the gap at mid-revolution (mid angle, not mid time: within the drift of one
            // revolution's time skew)
            assert!((r.dc - (-1e-3 + 2e-6 * tm)).abs() < 1e-9);
            // the speed of a revolution of a constant acceleration is its mean speed
            let w_mid = 100.0 + 20.0 * tm;
            // (the events interpolated linearly between samples: 1e-8 relative here)
            assert!(
                (r.speed - w_mid).abs() < 1e-7 * w_mid,
                "{} {}",
                r.speed,
                w_mid
            );
        }
    }

    #[test]
    fn standard_deviations_match_the_scatter_of_white_noise() {
        // a constant speed, white noise sigma: each component's std is sigma sqrt(2 / N)
        let (t, psi) = run_up(2.0 * TAU * 25.0, 0.0, 10_000.0, 8.0);
        let sigma = 1e-6;
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let nd = Normal::new(0.0, sigma).unwrap();
        let s: Vec<f64> = psi
            .iter()
            .map(|&p| 5e-6 * p.cos() + nd.sample(&mut rng))
            .collect();
        let tr = track(&t, &psi, &s, &OrderSettings::default()).unwrap();
        let n_per: f64 = 10_000.0 / 50.0;
        let expect = sigma * (2.0 / n_per).sqrt();
        let k = tr.revolutions.len() as f64;
        let mean_std = tr.revolutions.iter().map(|r| r.std[0]).sum::<f64>() / k;
        assert!(
            (mean_std / expect - 1.0).abs() < 0.05,
            "{mean_std} {expect}"
        );
        // the scatter of the vectors about the truth agrees with their stated std
        let scatter = (tr
            .revolutions
            .iter()
            .map(|r| (r.vectors[0] - C64::new(5e-6, 0.0)).norm_sqr() / 2.0)
            .sum::<f64>()
            / k)
            .sqrt();
        assert!(
            (scatter / mean_std - 1.0).abs() < 0.15,
            "{scatter} {mean_std}"
        );
        let noise = tr.revolutions.iter().map(|r| r.noise).sum::<f64>() / k;
        assert!((noise / sigma - 1.0).abs() < 0.1, "{noise}");
    }

    #[test]
    fn bins_average_with_their_weights() {
        let (t, psi) = run_up(200.0, 40.0, 8000.0, 3.0);
        let s: Vec<f64> = psi.iter().map(|&p| 1e-5 * p.sin()).collect();
        let tr = track(&t, &psi, &s, &OrderSettings::default()).unwrap();
        let b = bin(&tr, 100.0).unwrap();
        assert!(b.revolutions.len() < tr.revolutions.len());
        assert_eq!(
            b.revolutions.iter().map(|r| r.count).sum::<usize>(),
            tr.revolutions.len()
        );
        for r in &b.revolutions {
            assert!((r.vectors[0] - C64::new(0.0, -1e-5)).norm() < 1e-12);
            let j = (r.rpm() / 100.0).floor();
            assert!(r.rpm() >= j * 100.0 && r.rpm() < (j + 1.0) * 100.0);
        }
        assert!(matches!(
            bin(&tr, 0.0),
            Err(TransientError::OutOfRange(OutOfRange {
                field: "bin-rpm",
                ..
            }))
        ));
    }

    #[test]
    fn too_few_samples_and_bad_orders_are_refused_by_name() {
        let (t, psi) = run_up(2.0 * TAU * 100.0, 0.0, 1000.0, 1.0);
        let s = vec![0.0; t.len()];
        // 10 samples per revolution: order 3 needs 14
        let e = track(
            &t,
            &psi,
            &s,
            &OrderSettings {
                orders: vec![1, 3],
                harmonics: 8,
            },
        )
        .unwrap_err();
        assert!(
            matches!(
                e,
                TransientError::TooFewSamplesPerRevolution {
                    order: 3,
                    needed: 14,
                    ..
                }
            ),
            "{e}"
        );
        let e = OrderSettings {
            orders: vec![1, 1],
            harmonics: 8,
        }
        .validate()
        .unwrap_err();
        assert!(e.to_string().contains("orders"), "{e}");
        let mut bad = s.clone();
        bad[5] = f64::NAN;
        let e = track(&t, &psi, &bad, &OrderSettings::default()).unwrap_err();
        assert!(matches!(e, TransientError::NonFinite { index: 5, .. }));
    }
}
