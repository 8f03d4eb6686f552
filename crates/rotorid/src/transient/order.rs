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
///
/// The regressors are kept column by column (each harmonic's cos and sin over the
/// samples), so that every sum over the samples is a dot product of two contiguous
/// columns. A^T A is not summed entry by entry (p (p + 1) / 2 = 153 products a sample for
/// H = 8): its entries are sums of products of harmonics, which are harmonics again,
/// `cos a cos b = (cos (a - b) + cos (a + b)) / 2` and the like, so it is assembled from
/// the 2 (2 H) + 1 sums of cos(m psi) and sin(m psi), m = 0 .. 2 H ([`normal_from_sums`]).
/// The same matrix to rounding (each entry is now a sum of two rounded sums instead of one
/// sum of rounded products): the coefficients move by a few units of their last digits.
#[derive(Default)]
struct Normal {
    /// The columns cos(psi), sin(psi), ..., cos(H psi), sin(H psi), each of the
    /// revolution's samples, one after the other (2 H n values).
    cols: Vec<f64>,
    /// u = (psi - psi_m) / 2 pi of each sample.
    u: Vec<f64>,
    /// Scratch: cos(m psi), sin(m psi) for m > H (their sums only are needed).
    high: [Vec<f64>; 2],
    /// Scratch: one signal about its first sample, then its residuals.
    y: Vec<f64>,
    /// Samples of the current revolution.
    n: usize,
    /// Unknowns of the current revolution.
    p: usize,
    /// The factorisation of the current revolution's A^T A.
    chol: Option<nalgebra::linalg::Cholesky<f64, nalgebra::Dyn>>,
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

/// Sum of `a` (four running sums, so that the additions of neighbouring samples do not
/// wait for each other and can go two or four at a time).
#[inline]
fn sum(a: &[f64]) -> f64 {
    let mut acc = [0.0f64; 4];
    let mut chunks = a.chunks_exact(4);
    for c in &mut chunks {
        for l in 0..4 {
            acc[l] += c[l];
        }
    }
    let tail: f64 = chunks.remainder().iter().sum();
    (acc[0] + acc[2]) + (acc[1] + acc[3]) + tail
}

/// The dot product of `a` and `b` (same length), four running sums as [`sum`].
#[inline]
fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut acc = [0.0f64; 4];
    let mut ca = a.chunks_exact(4);
    let mut cb = b.chunks_exact(4);
    for (x, y) in (&mut ca).zip(&mut cb) {
        for l in 0..4 {
            acc[l] += x[l] * y[l];
        }
    }
    let tail: f64 = ca
        .remainder()
        .iter()
        .zip(cb.remainder())
        .map(|(x, y)| x * y)
        .sum();
    (acc[0] + acc[2]) + (acc[1] + acc[3]) + tail
}

/// cos(m psi), sin(m psi) of each sample from those of (m - 1) psi and psi: one complex
/// multiplication a sample, as the rows were built before.
#[inline]
fn next_harmonic(prev: (&[f64], &[f64]), first: (&[f64], &[f64]), out: (&mut [f64], &mut [f64])) {
    let (pc, ps) = prev;
    let (c1, s1) = first;
    let (oc, os) = out;
    for k in 0..oc.len() {
        let (a, b, c, d) = (pc[k], ps[k], c1[k], s1[k]);
        oc[k] = a * c - b * d;
        os[k] = a * d + b * c;
    }
}

/// A^T A (p x p, p = 1 + 2 h; regressors 1, cos psi, sin psi, ..., cos h psi, sin h psi)
/// from the sums `c[m]` of cos(m psi) and `s[m]` of sin(m psi) over the samples,
/// m = 0 .. 2 h (c\[0\] the count, s\[0\] = 0): with C_-m = C_m and S_-m = -S_m,
///
/// ```text
/// sum cos(a psi) cos(b psi) = (C_(a-b) + C_(a+b)) / 2
/// sum sin(a psi) sin(b psi) = (C_(a-b) - C_(a+b)) / 2
/// sum cos(a psi) sin(b psi) = (S_(a+b) - S_(a-b)) / 2
/// ```
fn normal_from_sums(c: &[f64], s: &[f64], h: usize) -> DMatrix<f64> {
    let p = 1 + 2 * h;
    let cm = |m: isize| c[m.unsigned_abs()];
    let sm = |m: isize| {
        if m < 0 {
            -s[m.unsigned_abs()]
        } else {
            s[m as usize]
        }
    };
    DMatrix::<f64>::from_fn(p, p, |i, j| {
        // regressor i: 0 the constant, 2 a - 1 cos(a psi), 2 a sin(a psi)
        let kind = |i: usize| -> (isize, bool) { (i.div_ceil(2) as isize, i.is_multiple_of(2)) };
        if i == 0 && j == 0 {
            return c[0];
        }
        if i == 0 || j == 0 {
            let (m, sine) = kind(i.max(j));
            return if sine { sm(m) } else { cm(m) };
        }
        let ((a, sa), (b, sb)) = (kind(i), kind(j));
        match (sa, sb) {
            (false, false) => 0.5 * (cm(a - b) + cm(a + b)),
            (true, true) => 0.5 * (cm(a - b) - cm(a + b)),
            // cos(a psi) sin(b psi)
            (false, true) => 0.5 * (sm(a + b) - sm(a - b)),
            (true, false) => 0.5 * (sm(a + b) - sm(b - a)),
        }
    })
}

impl Normal {
    /// The column of cos(m psi) (`sine` false) or sin(m psi), m = 1 .. H.
    fn col(&self, m: usize, sine: bool) -> &[f64] {
        let at = (2 * (m - 1) + usize::from(sine)) * self.n;
        &self.cols[at..at + self.n]
    }

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
        self.n = n;
        let mid = 0.5 * (psi[0] + psi[n - 1]);
        self.u.clear();
        self.u.extend(psi.iter().map(|&pk| (pk - mid) / TAU));
        self.cols.clear();
        self.cols.resize(2 * h * n, 0.0);
        {
            let (c1, rest) = self.cols.split_at_mut(n);
            for ((c, s), &pk) in c1.iter_mut().zip(&mut rest[..n]).zip(psi) {
                (*s, *c) = pk.sin_cos();
            }
        }
        // the sums of cos(m psi), sin(m psi), m = 0 .. 2 h
        let mut cs = vec![0.0; 2 * h + 1];
        let mut ss = vec![0.0; 2 * h + 1];
        cs[0] = n as f64;
        for m in 1..=h {
            if m > 1 {
                let (done, out) = self.cols.split_at_mut(2 * (m - 1) * n);
                let (oc, os) = out[..2 * n].split_at_mut(n);
                let first = (&done[..n], &done[n..2 * n]);
                let prev = &done[2 * (m - 2) * n..];
                next_harmonic((&prev[..n], &prev[n..2 * n]), first, (oc, os));
            }
            cs[m] = sum(self.col(m, false));
            ss[m] = sum(self.col(m, true));
        }
        for m in h + 1..=2 * h {
            let [hc, hs] = &mut self.high;
            hc.resize(n, 0.0);
            hs.resize(n, 0.0);
            let first = (&self.cols[..n], &self.cols[n..2 * n]);
            if m == h + 1 {
                let at = 2 * (h - 1) * n;
                let prev = (&self.cols[at..at + n], &self.cols[at + n..at + 2 * n]);
                next_harmonic(prev, first, (&mut hc[..], &mut hs[..]));
            } else {
                // in place: each sample's new value depends on its own old one only
                for k in 0..n {
                    let (a, b, c, d) = (hc[k], hs[k], first.0[k], first.1[k]);
                    hc[k] = a * c - b * d;
                    hs[k] = a * d + b * c;
                }
            }
            cs[m] = sum(&hc[..]);
            ss[m] = sum(&hs[..]);
        }
        let ata = normal_from_sums(&cs, &ss, h);
        let mut atu = DVector::<f64>::zeros(p);
        atu[0] = sum(&self.u);
        for m in 1..=h {
            atu[2 * m - 1] = dot(self.col(m, false), &self.u);
            atu[2 * m] = dot(self.col(m, true), &self.u);
        }
        let uu = dot(&self.u, &self.u);
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
        let (p, n) = (self.p, self.n);
        let h = (p - 1) / 2;
        // the signal about its first sample, so the sums of squares keep their digits
        let s0 = s[0];
        let mut y = std::mem::take(&mut self.y);
        y.clear();
        y.extend(s[..n].iter().map(|&sk| sk - s0));
        let mut theta = DVector::<f64>::zeros(p);
        theta[0] = sum(&y);
        for m in 1..=h {
            theta[2 * m - 1] = dot(self.col(m, false), &y);
            theta[2 * m] = dot(self.col(m, true), &y);
        }
        self.chol
            .as_ref()
            .expect("a revolution built before its fits")
            .solve_mut(&mut theta);
        // the residuals in place of y: e = y - c - sum a_m cos(m psi) + b_m sin(m psi)
        let c = theta[0];
        for v in y.iter_mut() {
            *v -= c;
        }
        for m in 1..=h {
            let (a, b) = (theta[2 * m - 1], theta[2 * m]);
            for ((v, &cm), &sm) in y.iter_mut().zip(self.col(m, false)).zip(self.col(m, true)) {
                *v -= a * cm + b * sm;
            }
        }
        let rss = dot(&y, &y);
        let eu = dot(&y, &self.u);
        self.y = y;
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

    /// A^T A assembled from the sums of cos(m psi) and sin(m psi) is the sum of the
    /// products of the regressors to rounding, and the fit of a revolution the least
    /// squares solution of its samples (nalgebra's SVD of the whole design matrix).
    #[test]
    fn normal_equations_from_harmonic_sums_equal_the_products() {
        let (_, psi) = run_up(40.0, 30.0, 2000.0, 3.0);
        // one revolution from psi = 20 pi, unevenly spaced (a run-up)
        let a = psi
            .iter()
            .position(|&p| p >= 20.0 * std::f64::consts::PI)
            .unwrap();
        let b = psi
            .iter()
            .position(|&p| p >= 22.0 * std::f64::consts::PI)
            .unwrap();
        let psi = &psi[a..b];
        let h = 8;
        let p = 1 + 2 * h;
        let design = DMatrix::<f64>::from_fn(psi.len(), p, |k, j| match j {
            0 => 1.0,
            _ if j % 2 == 1 => (j.div_ceil(2) as f64 * psi[k]).cos(),
            _ => ((j / 2) as f64 * psi[k]).sin(),
        });
        let direct = design.transpose() * &design;
        let mut normal = super::Normal::default();
        normal.build(psi, h, &[1, 2], 0, 0.0).unwrap();
        let cs: Vec<f64> = (0..=2 * h)
            .map(|m| psi.iter().map(|&x| (m as f64 * x).cos()).sum())
            .collect();
        let ss: Vec<f64> = (0..=2 * h)
            .map(|m| psi.iter().map(|&x| (m as f64 * x).sin()).sum())
            .collect();
        let from_sums = normal_from_sums(&cs, &ss, h);
        let scale = psi.len() as f64;
        assert!(
            (&from_sums - &direct).amax() < 1e-12 * scale,
            "{}",
            (&from_sums - &direct).amax()
        );
        // a signal of the model plus noise: the coefficients of the least squares
        let mut rng = rand::rngs::StdRng::seed_from_u64(1);
        let noise = Normal::new(0.0, 0.1).unwrap();
        let y: Vec<f64> = psi
            .iter()
            .map(|&x| 3.0 + 2.0 * x.cos() - 0.5 * (2.0 * x).sin() + noise.sample(&mut rng))
            .collect();
        let fit = normal.fit(&y);
        let ls = design
            .clone()
            .svd(true, true)
            .solve(&DVector::from_column_slice(&y), 1e-14)
            .unwrap();
        for (j, (x, want)) in fit.theta.iter().zip(ls.iter()).enumerate() {
            assert!(
                (x - want).abs() < 1e-12,
                "coefficient {j}: {x} against {want}"
            );
        }
        let resid = DVector::from_column_slice(&y) - &design * &ls;
        let rss = resid.dot(&resid);
        assert!(
            (fit.rss / rss - 1.0).abs() < 1e-10,
            "{} against {rss}",
            fit.rss
        );
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
