//! Critical speeds of a measured 1X curve, per API 684 (docs/transient.md section 4):
//! each resonance's peak speed Nc with its standard deviation, its amplitude and phase
//! lag, the half-power speeds N1 < Nc < N2 where the amplitude is the peak's / sqrt 2, the
//! amplification factor `AF = Nc / (N2 - N1)` with its standard deviation, and the
//! damping ratio it implies, `zeta = 1 / (2 AF)`; the separation margins from an
//! operating range.
//!
//! The vectors (one per revolution or bin, scattered by noise) are first smoothed by a
//! local quadratic regression in speed (tricube weights over the larger of
//! [`CriticalSettings::relative_bandwidth`] of the speed and the
//! [`CriticalSettings::neighbours`] nearest points, each point also weighted by its
//! inverse variance). The noise of each point is the larger of its stated standard
//! deviation and the scatter of the residuals about the smooth curve nearby (a running
//! median), so a table without standard deviations, or one whose revolutions scatter more
//! than their own noise says, is judged by its real scatter.
//!
//! A local maximum of the smooth amplitude is a resonance when its prominence (its height
//! above the higher of the lowest points between it and a higher maximum on either side,
//! or the record's end) exceeds [`CriticalSettings::sigmas`] times the noise of that
//! difference, [`CriticalSettings::min_relative_prominence`] of its height and
//! [`SCATTER_MULTIPLE`] times the scatter of single points there: a maximum made by noise
//! is not a critical, and two resonances close together (a split critical)
//! are two criticals when the dip between them is significant. A peak whose half-power
//! points lie closer to it than half the smoothing window is not resolved (ringing at the
//! start of a record, a glitch) and is not reported; nor is one that does not fall to half
//! power on either side (a bump, or a critically damped response, AF < 2.5), or whose
//! vector turns by less than [`MIN_PHASE_TURN_DEG`] between its half-power speeds (half
//! that from the peak to the only one found): a resonance turns the phase, by about 90 deg
//! between them for a single mode; a beat or a bump does not.
//!
//! Nc and the peak amplitude are the vertex of a weighted quadratic fitted to the
//! amplitudes within 90 % of the peak (at least 5 points); N1 and N2 are where a weighted
//! straight line fitted to the amplitudes near each crossing of `peak / sqrt 2` meets that
//! level. Their variances follow from the fits' covariances by first-order propagation;
//! AF's from those of Nc, N1 and N2, which come from disjoint points and are taken as
//! independent. A half-power speed the record does not reach (it ends, or the curve rises
//! to another resonance first) is absent, and so are AF and zeta then.
//!
//! Reference: API Standard 684, 2nd ed., 2005, sec. 2.8 (amplification factor by the
//! half-power method, separation margins); W. S. Cleveland, *J. Am. Stat. Assoc.* 74, 1979
//! (local regression).

use std::f64::consts::FRAC_1_SQRT_2;

use nalgebra::{Matrix3, Vector3};
use serde::Serialize;

use super::error::{check_finite, same_length, TransientError};
use super::order::C64;
use crate::model::OutOfRange;

/// A resonance's prominence must also exceed this many times the scatter of single
/// points at its peak and base (module doc).
pub const SCATTER_MULTIPLE: f64 = 3.0;

/// The least turn of the vector between the half-power speeds of a resonance \[deg\]
/// (about 90 for a single mode seen alone; a probe that also sees another mode's response
/// sees less).
pub const MIN_PHASE_TURN_DEG: f64 = 30.0;

/// How resonances are told from noise.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct CriticalSettings {
    /// Half-width of the smoothing window as a fraction of the speed (default 0.002).
    pub relative_bandwidth: f64,
    /// The fewest points in the smoothing window (default 7).
    pub neighbours: usize,
    /// A resonance's prominence must exceed this many standard deviations (default 6).
    pub sigmas: f64,
    /// ... and this fraction of its height (default 0.15: a bump of a few % on a
    /// smooth measured curve, real but no resonance, is not a critical).
    pub min_relative_prominence: f64,
}

impl Default for CriticalSettings {
    fn default() -> Self {
        Self {
            relative_bandwidth: 0.002,
            neighbours: 7,
            sigmas: 6.0,
            min_relative_prominence: 0.15,
        }
    }
}

/// A critical speed (module doc).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Critical {
    /// Peak speed Nc \[rev/min\].
    pub rpm: f64,
    /// Its standard deviation \[rev/min\].
    pub rpm_std: f64,
    /// Peak amplitude \[signal unit\], as the vectors (zero-to-peak).
    pub amplitude: f64,
    /// Its standard deviation \[signal unit\].
    pub amplitude_std: f64,
    /// Phase lag of the smooth vector at the peak \[deg\], in \[0, 360).
    pub phase_lag_deg: f64,
    /// Lower half-power speed N1 \[rev/min\], when the record reaches it.
    pub n1_rpm: Option<f64>,
    /// Its standard deviation \[rev/min\].
    pub n1_std: Option<f64>,
    /// Upper half-power speed N2 \[rev/min\], when the record reaches it.
    pub n2_rpm: Option<f64>,
    /// Its standard deviation \[rev/min\].
    pub n2_std: Option<f64>,
    /// Amplification factor Nc / (N2 - N1) \[-\].
    pub amplification_factor: Option<f64>,
    /// Its standard deviation \[-\].
    pub amplification_factor_std: Option<f64>,
    /// Damping ratio 1 / (2 AF) \[-\].
    pub damping_ratio: Option<f64>,
    /// Its standard deviation \[-\].
    pub damping_ratio_std: Option<f64>,
    /// The prominence over the noise of that difference \[-\] (how clearly it is a peak).
    pub significance: f64,
}

/// The smooth curve of [`smooth`].
#[derive(Debug, Clone, PartialEq)]
pub struct Smooth {
    /// Speeds \[rev/min\], increasing (the input's, sorted).
    pub rpm: Vec<f64>,
    /// The input's indices in that order.
    pub order: Vec<usize>,
    /// The smooth vector at each speed \[signal unit\].
    pub vector: Vec<C64>,
    /// Standard deviation of the smooth amplitude \[signal unit\].
    pub std: Vec<f64>,
    /// Each point's noise, per component \[signal unit\] (module doc).
    pub noise: Vec<f64>,
    /// The points of each speed's window (indices into the sorted order).
    pub window: Vec<std::ops::Range<usize>>,
}

impl CriticalSettings {
    /// Check the settings.
    pub fn validate(&self) -> Result<(), TransientError> {
        let checks: [(&'static str, f64, &'static str, bool); 4] = [
            (
                "relative_bandwidth",
                self.relative_bandwidth,
                "finite and in [0, 0.2]",
                (0.0..=0.2).contains(&self.relative_bandwidth),
            ),
            (
                "neighbours",
                self.neighbours as f64,
                "a whole number from 3 to 1000",
                (3..=1000).contains(&self.neighbours),
            ),
            (
                "sigmas",
                self.sigmas,
                "finite and > 0",
                self.sigmas.is_finite() && self.sigmas > 0.0,
            ),
            (
                "min_relative_prominence",
                self.min_relative_prominence,
                "finite and in [0, 1)",
                (0.0..1.0).contains(&self.min_relative_prominence),
            ),
        ];
        for (field, value, allowed, ok) in checks {
            if !ok {
                return Err(OutOfRange {
                    field,
                    value,
                    allowed,
                }
                .into());
            }
        }
        Ok(())
    }
}

/// Running median of `v` over `2 half + 1` points (shorter at the ends).
fn running_median(v: &[f64], half: usize) -> Vec<f64> {
    let n = v.len();
    let mut buf = Vec::with_capacity(2 * half + 1);
    (0..n)
        .map(|i| {
            buf.clear();
            buf.extend_from_slice(&v[i.saturating_sub(half)..(i + half + 1).min(n)]);
            let m = buf.len() / 2;
            *buf.select_nth_unstable_by(m, f64::total_cmp).1
        })
        .collect()
}

/// The window of point `i` of the sorted speeds `s`: the points within the larger of
/// `rel s_i` and the distance to its `k`-th nearest neighbour.
fn window(s: &[f64], i: usize, rel: f64, k: usize) -> std::ops::Range<usize> {
    let n = s.len();
    let k = k.min(n);
    // the k nearest by growing a window around i
    let (mut a, mut b) = (i, i + 1);
    while b - a < k {
        let left = if a > 0 {
            s[i] - s[a - 1]
        } else {
            f64::INFINITY
        };
        let right = if b < n { s[b] - s[i] } else { f64::INFINITY };
        if left <= right {
            a -= 1;
        } else {
            b += 1;
        }
    }
    let h = (rel * s[i].abs()).max(s[i] - s[a]).max(s[b - 1] - s[i]);
    let a = s.partition_point(|&v| v < s[i] - h);
    let b = s.partition_point(|&v| v <= s[i] + h);
    a..b
}

/// Local weighted quadratic regression of `v` against `s` at `s0` over `range`, with
/// per-point weights `w`: the value at s0 and the weights l_j of its linear form
/// (value = sum l_j v_j).
fn local_fit(
    s: &[f64],
    v: &[C64],
    w: &[f64],
    range: std::ops::Range<usize>,
    s0: f64,
) -> (C64, Vec<f64>) {
    let h = range
        .clone()
        .map(|j| (s[j] - s0).abs())
        .fold(0.0f64, f64::max)
        * 1.0001
        + f64::MIN_POSITIVE;
    let mut ata = Matrix3::<f64>::zeros();
    let kern: Vec<f64> = range
        .clone()
        .map(|j| {
            let u = ((s[j] - s0) / h).abs();
            (1.0 - u * u * u).powi(3) * w[j]
        })
        .collect();
    for (jj, j) in range.clone().enumerate() {
        let u = (s[j] - s0) / h;
        let x = Vector3::new(1.0, u, u * u);
        ata += x * x.transpose() * kern[jj];
    }
    let degree = if range.len() >= 5 {
        3
    } else {
        2.min(range.len())
    };
    let e0 = match degree {
        3 => ata.try_inverse().map(|inv| inv.row(0).transpose()),
        2 => ata
            .fixed_view::<2, 2>(0, 0)
            .into_owned()
            .try_inverse()
            .map(|inv| Vector3::new(inv[(0, 0)], inv[(0, 1)], 0.0)),
        _ => None,
    };
    let Some(e0) = e0 else {
        // degenerate window: the weighted mean
        let sw: f64 = kern.iter().sum::<f64>().max(f64::MIN_POSITIVE);
        let l: Vec<f64> = kern.iter().map(|k| k / sw).collect();
        let val = range.zip(&l).map(|(j, &lj)| v[j] * lj).sum();
        return (val, l);
    };
    let l: Vec<f64> = range
        .clone()
        .enumerate()
        .map(|(jj, j)| {
            let u = (s[j] - s0) / h;
            (e0[0] + e0[1] * u + e0[2] * u * u) * kern[jj]
        })
        .collect();
    let val = range.zip(&l).map(|(j, &lj)| v[j] * lj).sum();
    (val, l)
}

/// The smooth curve of the vectors `vectors` at speeds `rpm` \[rev/min\] with standard
/// deviations `std` per component (NaN or 0 where unknown) (module doc).
pub fn smooth(
    rpm: &[f64],
    vectors: &[C64],
    std: &[f64],
    settings: &CriticalSettings,
) -> Result<Smooth, TransientError> {
    settings.validate()?;
    same_length("vectors", vectors.len(), "rpm", rpm.len())?;
    same_length("std", std.len(), "rpm", rpm.len())?;
    check_finite("rpm", rpm)?;
    let re: Vec<f64> = vectors.iter().map(|v| v.re).collect();
    let im: Vec<f64> = vectors.iter().map(|v| v.im).collect();
    check_finite("re", &re)?;
    check_finite("im", &im)?;
    let n = rpm.len();
    if n < 5 {
        return Err(TransientError::TooFew {
            what: "speeds of the 1X curve".into(),
            found: n,
            needed: 5,
        });
    }
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| rpm[a].total_cmp(&rpm[b]));
    let s: Vec<f64> = order.iter().map(|&i| rpm[i]).collect();
    let v: Vec<C64> = order.iter().map(|&i| vectors[i]).collect();
    let given: Vec<f64> = order
        .iter()
        .map(|&i| if std[i].is_finite() { std[i] } else { 0.0 })
        .collect();
    let windows: Vec<_> = (0..n)
        .map(|i| window(&s, i, settings.relative_bandwidth, settings.neighbours))
        .collect();
    // pass 1: equal weights, for the residual scatter
    let ones = vec![1.0; n];
    // each residual's variance is (1 - 2 l_ii + sum_j l_ij^2) times the noise's: scaled
    // back, so a narrow window does not make the noise look smaller than it is
    let resid2: Vec<f64> = (0..n)
        .map(|i| {
            let (val, l) = local_fit(&s, &v, &ones, windows[i].clone(), s[i]);
            let lii = l[i - windows[i].start];
            let shrink = (1.0 - 2.0 * lii + l.iter().map(|x| x * x).sum::<f64>()).max(0.05);
            (v[i] - val).norm_sqr() / 2.0 / std::f64::consts::LN_2 / shrink
        })
        .collect();
    let half = (2 * settings.neighbours).max(25);
    let scatter = running_median(&resid2, half);
    let noise: Vec<f64> = (0..n)
        .map(|i| given[i].max(scatter[i].sqrt()).max(f64::MIN_POSITIVE))
        .collect();
    let w: Vec<f64> = noise.iter().map(|s| 1.0 / (s * s)).collect();
    // pass 2: weighted by the noise
    let mut vector = Vec::with_capacity(n);
    let mut sd = Vec::with_capacity(n);
    for i in 0..n {
        let (val, l) = local_fit(&s, &v, &w, windows[i].clone(), s[i]);
        let var: f64 = windows[i]
            .clone()
            .zip(&l)
            .map(|(j, lj)| lj * lj * noise[j] * noise[j])
            .sum();
        vector.push(val);
        sd.push(var.sqrt());
    }
    Ok(Smooth {
        rpm: s,
        order,
        vector,
        std: sd,
        noise,
        window: windows,
    })
}

/// Weighted least squares of y on the columns of x (rows), weights w: coefficients and
/// their covariance (scaled by the reduced chi-square when it exceeds 1).
fn wls<const P: usize>(
    x: &[[f64; P]],
    y: &[f64],
    w: &[f64],
) -> Option<(nalgebra::SVector<f64, P>, nalgebra::SMatrix<f64, P, P>)> {
    let mut ata = nalgebra::SMatrix::<f64, P, P>::zeros();
    let mut aty = nalgebra::SVector::<f64, P>::zeros();
    for ((row, &yi), &wi) in x.iter().zip(y).zip(w) {
        let r = nalgebra::SVector::<f64, P>::from_row_slice(row);
        ata += r * r.transpose() * wi;
        aty += r * (yi * wi);
    }
    let inv = ata.try_inverse()?;
    let beta = inv * aty;
    let dof = x.len().saturating_sub(P);
    let chi2: f64 = x
        .iter()
        .zip(y)
        .zip(w)
        .map(|((row, &yi), &wi)| {
            let f: f64 = row.iter().zip(beta.iter()).map(|(a, b)| a * b).sum();
            wi * (yi - f) * (yi - f)
        })
        .sum();
    let scale = if dof > 0 {
        (chi2 / dof as f64).max(1.0)
    } else {
        1.0
    };
    Some((beta, inv * scale))
}

/// The critical speeds of the vectors `vectors` at speeds `rpm` \[rev/min\], standard
/// deviations `std` per component (NaN where unknown), in order of speed (module doc).
pub fn criticals(
    rpm: &[f64],
    vectors: &[C64],
    std: &[f64],
    settings: &CriticalSettings,
) -> Result<Vec<Critical>, TransientError> {
    let sm = smooth(rpm, vectors, std, settings)?;
    let n = sm.rpm.len();
    let amp: Vec<f64> = sm.vector.iter().map(|v| v.norm()).collect();
    let raw_amp: Vec<f64> = sm.order.iter().map(|&i| vectors[i].norm()).collect();
    let mut out = Vec::new();
    let mut i = 1;
    while i + 1 < n {
        // a maximum, plateaus included (the plateau's middle)
        if !(amp[i] >= amp[i - 1] && amp[i] > amp[i + 1]) {
            i += 1;
            continue;
        }
        let mut p0 = i;
        while p0 > 0 && amp[p0 - 1] == amp[i] {
            p0 -= 1;
        }
        if p0 == 0 {
            i += 1;
            continue;
        }
        let j = (p0 + i) / 2;
        i += 1;
        let a = amp[j];
        // the lowest points between the peak and a higher one (or the end) on each side
        let base = |dir: isize| -> (f64, usize) {
            let mut k = j as isize;
            let mut low = (a, j);
            while k + dir >= 0 && ((k + dir) as usize) < n {
                k += dir;
                let ak = amp[k as usize];
                if ak > a {
                    break;
                }
                if ak < low.0 {
                    low = (ak, k as usize);
                }
            }
            low
        };
        let (left, right) = (base(-1), base(1));
        let (b, bi) = if left.0 >= right.0 { left } else { right };
        let prominence = a - b;
        let noise = sm.std[j].hypot(sm.std[bi]);
        let significance = prominence / noise.max(f64::MIN_POSITIVE);
        // a dense, noisy stretch makes smooth maxima that stand out of the smooth curve's
        // own error but not out of the points' scatter: a resonance rises above both
        let scatter = sm.noise[j].max(sm.noise[bi]);
        if significance < settings.sigmas
            || prominence < settings.min_relative_prominence * a
            || prominence < SCATTER_MULTIPLE * scatter
        {
            continue;
        }
        if let Some(c) = one_critical(&sm, &amp, &raw_amp, j, significance) {
            // a peak narrower than the smoothing window is not resolved: ringing at a
            // record's start, a glitch (a resonance that sharp needs denser speeds)
            let w = &sm.window[j];
            let width = sm.rpm[w.end - 1] - sm.rpm[w.start];
            let half_widths = [c.n1_rpm.map(|n| c.rpm - n), c.n2_rpm.map(|n| n - c.rpm)];
            let resolved = half_widths.iter().flatten().all(|&h| h >= 0.5 * width);
            if resolved {
                out.push(c);
            }
        }
    }
    Ok(out)
}

/// The figures of the resonance whose smooth maximum is at sorted index `j`.
fn one_critical(
    sm: &Smooth,
    amp: &[f64],
    raw_amp: &[f64],
    j: usize,
    significance: f64,
) -> Option<Critical> {
    let n = amp.len();
    let a = amp[j];
    // points within 90 % of the peak, contiguous around it; at least 5
    let (mut lo, mut hi) = (j, j + 1);
    while lo > 0 && amp[lo - 1] >= 0.9 * a {
        lo -= 1;
    }
    while hi < n && amp[hi] >= 0.9 * a {
        hi += 1;
    }
    while hi - lo < 5 && (lo > 0 || hi < n) {
        lo = lo.saturating_sub(1);
        if hi - lo < 5 && hi < n {
            hi += 1;
        }
    }
    let s0 = sm.rpm[j];
    let scale = (sm.rpm[hi - 1] - sm.rpm[lo]).max(f64::MIN_POSITIVE);
    let rows: Vec<[f64; 3]> = (lo..hi)
        .map(|k| {
            let u = (sm.rpm[k] - s0) / scale;
            [1.0, u, u * u]
        })
        .collect();
    let w: Vec<f64> = (lo..hi).map(|k| 1.0 / sm.noise[k].powi(2)).collect();
    let (beta, cov) = wls(&rows, &raw_amp[lo..hi], &w)?;
    let (c0, c1, c2) = (beta[0], beta[1], beta[2]);
    let (u, var_u) = if c2 < 0.0 {
        let u = -c1 / (2.0 * c2);
        let g = Vector3::new(0.0, -1.0 / (2.0 * c2), c1 / (2.0 * c2 * c2));
        let u_lim = 0.5;
        if u.abs() <= u_lim {
            (u, (g.transpose() * cov * g)[(0, 0)])
        } else {
            (0.0, cov[(0, 0)] / (c1 * c1).max(f64::MIN_POSITIVE))
        }
    } else {
        (0.0, 0.25)
    };
    let rpm = s0 + u * scale;
    let rpm_std = var_u.max(0.0).sqrt() * scale;
    let gx = Vector3::new(1.0, u, u * u);
    let peak = c0 + c1 * u + c2 * u * u;
    let peak_var = (gx.transpose() * cov * gx)[(0, 0)].max(0.0);
    let level = peak * FRAC_1_SQRT_2;
    let level_var = peak_var / 2.0;
    let half = |dir: isize| -> Option<(f64, f64)> {
        let mut k = j as isize;
        loop {
            let next = k + dir;
            if next < 0 || next as usize >= n {
                return None;
            }
            if amp[next as usize] > a {
                return None;
            }
            if amp[next as usize] < level {
                break;
            }
            k = next;
        }
        // the crossing lies between k and k + dir: a line through the raw amplitudes of
        // the smoothing window there
        let (k0, k1) = (k as usize, (k + dir) as usize);
        let mid = if dir < 0 { k1 } else { k0 };
        let win = sm.window[mid].clone();
        let (mut a0, mut b0) = (win.start, win.end);
        while b0 - a0 < 5 && (a0 > 0 || b0 < n) {
            a0 = a0.saturating_sub(1);
            if b0 - a0 < 5 && b0 < n {
                b0 += 1;
            }
        }
        // a first guess by interpolating the smooth curve
        let (sa, sb) = (sm.rpm[k0], sm.rpm[k1]);
        let guess = sa + (level - amp[k0]) / (amp[k1] - amp[k0]) * (sb - sa);
        let sc = (sm.rpm[b0 - 1] - sm.rpm[a0]).max(f64::MIN_POSITIVE);
        let rows: Vec<[f64; 2]> = (a0..b0).map(|q| [1.0, (sm.rpm[q] - guess) / sc]).collect();
        let w: Vec<f64> = (a0..b0).map(|q| 1.0 / sm.noise[q].powi(2)).collect();
        let (beta, cov) = wls(&rows, &raw_amp[a0..b0], &w)?;
        let slope = beta[1];
        // the line must fall away from the peak, or the crossing is not resolved
        if slope * dir as f64 >= 0.0 {
            return Some((guess, (sb - sa).abs()));
        }
        let x = (level - beta[0]) / slope;
        if x.abs() > 1.0 {
            return Some((guess, (sb - sa).abs()));
        }
        let g = nalgebra::Vector2::new(1.0, x);
        let var_line = (g.transpose() * cov * g)[(0, 0)];
        let var_x = (var_line + level_var) / (slope * slope);
        Some((guess + x * sc, var_x.sqrt() * sc))
    };
    let n1 = half(-1);
    let n2 = half(1);
    // a resonance falls to half power on at least one side and turns the vector between
    // its half-power speeds (by about 90 deg for a single mode, 45 from the peak to either);
    // a maximum that does neither is a bump or a beat (or critically damped: AF < 2.5)
    let at = |r: f64| sm.vector[sm.rpm.partition_point(|&x| x < r).min(n - 1)];
    let turn = |a: C64, b: C64| (b / a).arg().abs().to_degrees();
    let turned = match (n1, n2) {
        (Some((a1, _)), Some((a2, _))) => turn(at(a1), at(a2)) >= MIN_PHASE_TURN_DEG,
        (Some((a, _)), None) | (None, Some((a, _))) => {
            turn(sm.vector[j], at(a)) >= 0.5 * MIN_PHASE_TURN_DEG
        }
        (None, None) => false,
    };
    if !turned {
        return None;
    }
    let (af, af_std) = match (n1, n2) {
        (Some((n1, s1)), Some((n2, s2))) if n2 > n1 => {
            let d = n2 - n1;
            let af = rpm / d;
            let rel2 = (rpm_std / rpm).powi(2) + (s1 * s1 + s2 * s2) / (d * d);
            (Some(af), Some(af * rel2.sqrt()))
        }
        _ => (None, None),
    };
    let v = sm.vector[j];
    let lag = (-v.arg()).to_degrees().rem_euclid(360.0);
    Some(Critical {
        rpm,
        rpm_std,
        amplitude: peak,
        amplitude_std: peak_var.sqrt(),
        phase_lag_deg: lag,
        n1_rpm: n1.map(|x| x.0),
        n1_std: n1.map(|x| x.1),
        n2_rpm: n2.map(|x| x.0),
        n2_std: n2.map(|x| x.1),
        amplification_factor: af,
        amplification_factor_std: af_std,
        damping_ratio: af.map(|af| 0.5 / af),
        damping_ratio_std: af.zip(af_std).map(|(af, s)| 0.5 / af * s / af),
        significance,
    })
}

/// Where a critical speed lies relative to the operating range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Position {
    /// Below the range's minimum speed.
    Below,
    /// Inside the range.
    Inside,
    /// Above the range's maximum speed.
    Above,
}

/// A separation margin per API 684.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Margin {
    /// Where the critical lies.
    pub position: Position,
    /// Actual margin \[%\]: (MIN - Nc) / MIN below the range, (Nc - MAX) / MAX above it;
    /// inside, minus the smaller distance to either end relative to that end.
    pub separation_pct: f64,
    /// Required margin \[%\] (0 for AF < 2.5; below: min(16, 17 (1 - 1 / (AF - 1.5)));
    /// above: min(26, 10 + 17 (1 - 1 / (AF - 1.5))); without AF the largest, 16 or 26).
    pub required_pct: f64,
    /// Whether the actual margin is at least the required one (always, for AF < 2.5).
    pub ok: bool,
}

/// The API 684 separation margin of a critical at `nc_rpm` with amplification factor
/// `af` (None when unknown) from the operating range `min_rpm`..`max_rpm` \[rev/min\].
pub fn separation_margin(nc_rpm: f64, af: Option<f64>, min_rpm: f64, max_rpm: f64) -> Margin {
    let required_below = match af {
        Some(af) if af < 2.5 => 0.0,
        Some(af) => 16f64.min(17.0 * (1.0 - 1.0 / (af - 1.5))),
        None => 16.0,
    };
    let required_above = match af {
        Some(af) if af < 2.5 => 0.0,
        Some(af) => 26f64.min(10.0 + 17.0 * (1.0 - 1.0 / (af - 1.5))),
        None => 26.0,
    };
    let (position, separation_pct, required_pct) = if nc_rpm < min_rpm {
        (
            Position::Below,
            (min_rpm - nc_rpm) / min_rpm * 100.0,
            required_below,
        )
    } else if nc_rpm > max_rpm {
        (
            Position::Above,
            (nc_rpm - max_rpm) / max_rpm * 100.0,
            required_above,
        )
    } else {
        let below = (nc_rpm - min_rpm) / min_rpm;
        let above = (max_rpm - nc_rpm) / max_rpm;
        if below <= above {
            (Position::Inside, -below * 100.0, required_below)
        } else {
            (Position::Inside, -above * 100.0, required_above)
        }
    };
    // API 684 requires no margin of a critically damped resonance (AF < 2.5)
    let damped = af.is_some_and(|af| af < 2.5);
    Margin {
        position,
        separation_pct,
        required_pct,
        ok: damped || separation_pct >= required_pct,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    /// The steady 1X of a single-degree-of-freedom resonance excited by unbalance,
    /// r^2 / (1 - r^2 + 2 i zeta r) with r = N / Nn, times `scale`.
    fn sdof(rpm: f64, nn: f64, zeta: f64, scale: f64) -> C64 {
        let r = rpm / nn;
        C64::new(r * r * scale, 0.0) / C64::new(1.0 - r * r, 2.0 * zeta * r)
    }

    /// Half-power figures of the closed form, by bisection on a fine grid.
    fn closed_form(nn: f64, zeta: f64) -> (f64, f64, f64) {
        let a = |n: f64| sdof(n, nn, zeta, 1.0).norm();
        // peak of r^2 / |1 - r^2 + 2 i zeta r|: r = 1 / sqrt(1 - 2 zeta^2)
        let np = nn / (1.0 - 2.0 * zeta * zeta).sqrt();
        let level = a(np) * FRAC_1_SQRT_2;
        let root = |mut lo: f64, mut hi: f64| {
            for _ in 0..200 {
                let m = 0.5 * (lo + hi);
                if (a(m) - level) * (a(lo) - level) > 0.0 {
                    lo = m;
                } else {
                    hi = m;
                }
            }
            0.5 * (lo + hi)
        };
        (np, root(0.5 * nn, np), root(np, 1.5 * nn))
    }

    fn curve(nn: f64, zeta: f64, sigma_rel: f64, step: f64, seed: u64) -> (Vec<f64>, Vec<C64>) {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let nd = Normal::new(0.0, 1.0).unwrap();
        let mut rpm = Vec::new();
        let mut v = Vec::new();
        let mut n = 0.3 * nn;
        while n < 2.0 * nn {
            let x = sdof(n, nn, zeta, 1e-5);
            let s = sigma_rel * 1e-5 / (2.0 * zeta);
            rpm.push(n);
            v.push(x + C64::new(nd.sample(&mut rng), nd.sample(&mut rng)) * s);
            n += step;
        }
        (rpm, v)
    }

    #[test]
    fn one_resonance_gives_its_half_power_figures() {
        let (nn, zeta) = (3000.0, 0.025);
        let (np, n1, n2) = closed_form(nn, zeta);
        let (rpm, v) = curve(nn, zeta, 0.0, 2.0, 1);
        let std = vec![f64::NAN; rpm.len()];
        let c = criticals(&rpm, &v, &std, &CriticalSettings::default()).unwrap();
        assert_eq!(c.len(), 1, "{c:?}");
        let c = &c[0];
        assert!((c.rpm - np).abs() < 0.5, "{} {np}", c.rpm);
        assert!((c.n1_rpm.unwrap() - n1).abs() < 0.5, "{:?} {n1}", c.n1_rpm);
        assert!((c.n2_rpm.unwrap() - n2).abs() < 0.5, "{:?} {n2}", c.n2_rpm);
        let af = np / (n2 - n1);
        assert!((c.amplification_factor.unwrap() / af - 1.0).abs() < 0.01);
        // the phase lag at the peak of an unbalance resonance is near 90 deg
        assert!((c.phase_lag_deg - 90.0).abs() < 3.0, "{}", c.phase_lag_deg);
    }

    #[test]
    fn noisy_single_revolution_vectors_give_one_critical_within_its_std() {
        let (nn, zeta) = (3000.0, 0.03);
        let (np, n1, n2) = closed_form(nn, zeta);
        let af_true = np / (n2 - n1);
        // 3 % scatter of the peak amplitude, a vector every 1 rpm
        let mut z_rpm = Vec::new();
        let mut z_af = Vec::new();
        for seed in 0..20 {
            let (rpm, v) = curve(nn, zeta, 0.03, 1.0, seed);
            let std = vec![f64::NAN; rpm.len()];
            let c = criticals(&rpm, &v, &std, &CriticalSettings::default()).unwrap();
            assert_eq!(c.len(), 1, "seed {seed}: {c:?}");
            let c = &c[0];
            z_rpm.push((c.rpm - np) / c.rpm_std);
            let af = c.amplification_factor.unwrap();
            z_af.push((af - af_true) / c.amplification_factor_std.unwrap());
            assert!((af / af_true - 1.0).abs() < 0.1, "{af} {af_true}");
        }
        // the stated deviations are of the right size: RMS z between 0.5 and 2
        let rms = |z: &[f64]| (z.iter().map(|v| v * v).sum::<f64>() / z.len() as f64).sqrt();
        assert!((0.4..2.0).contains(&rms(&z_rpm)), "{z_rpm:?}");
        assert!((0.4..2.0).contains(&rms(&z_af)), "{z_af:?}");
    }

    #[test]
    fn a_split_critical_reports_both_and_noise_alone_none() {
        let (rpm, v1) = curve(3000.0, 0.02, 0.0, 2.0, 0);
        let v: Vec<C64> = rpm
            .iter()
            .zip(&v1)
            .map(|(&n, &x)| x + sdof(n, 3400.0, 0.02, 1e-5) * C64::new(0.0, 1.0))
            .collect();
        let std = vec![1e-9; rpm.len()];
        let c = criticals(&rpm, &v, &std, &CriticalSettings::default()).unwrap();
        assert_eq!(c.len(), 2, "{c:?}");
        assert!((c[0].rpm / 3000.0 - 1.0).abs() < 0.02);
        assert!((c[1].rpm / 3400.0 - 1.0).abs() < 0.02);
        // a flat vector with noise: no critical
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let nd = Normal::new(0.0, 1e-7).unwrap();
        let flat: Vec<C64> = rpm
            .iter()
            .map(|_| C64::new(1e-5 + nd.sample(&mut rng), nd.sample(&mut rng)))
            .collect();
        let c = criticals(
            &rpm,
            &flat,
            &vec![1e-7; rpm.len()],
            &CriticalSettings::default(),
        )
        .unwrap();
        assert!(c.is_empty(), "{c:?}");
    }

    #[test]
    fn a_bump_that_does_not_turn_the_phase_is_no_critical() {
        // a bump of the amplitude to 3 times, the vector's direction fixed: a beat, no
        // resonance; the same bump turning the phase by 90 deg across it is one; a bump of
        // 40 %, which never falls to half power, is none either way
        let rpm: Vec<f64> = (0..2000).map(|i| 1000.0 + f64::from(i)).collect();
        let bump = |n: f64| 1e-5 * (1.0 + 2.0 * (-((n - 2000.0) / 60.0).powi(2)).exp());
        let flat: Vec<C64> = rpm.iter().map(|&n| C64::new(bump(n), 0.0)).collect();
        let std = vec![1e-9; rpm.len()];
        let c = criticals(&rpm, &flat, &std, &CriticalSettings::default()).unwrap();
        assert!(c.is_empty(), "{c:?}");
        let small: Vec<C64> = rpm
            .iter()
            .map(|&n| {
                let b = 1e-5 * (1.0 + 0.4 * (-((n - 2000.0) / 60.0).powi(2)).exp());
                C64::from_polar(b, -(1.0 + ((n - 2000.0) / 60.0).tanh()) * 0.785)
            })
            .collect();
        let c = criticals(&rpm, &small, &std, &CriticalSettings::default()).unwrap();
        assert!(c.is_empty(), "{c:?}");
        let turning: Vec<C64> = rpm
            .iter()
            .map(|&n| C64::from_polar(bump(n), -(1.0 + ((n - 2000.0) / 60.0).tanh()) * 0.785))
            .collect();
        let c = criticals(&rpm, &turning, &std, &CriticalSettings::default()).unwrap();
        assert_eq!(c.len(), 1, "{c:?}");
        assert!((c[0].rpm - 2000.0).abs() < 2.0);
    }

    #[test]
    fn separation_margins_follow_api_684() {
        // AF 10 below the range: required min(16, 17 (1 - 1 / 8.5)) = 15
        let m = separation_margin(3000.0, Some(10.0), 3600.0, 4000.0);
        assert_eq!(m.position, Position::Below);
        assert!((m.separation_pct - 16.666_666_666_666_668).abs() < 1e-9);
        assert!((m.required_pct - 17.0 * (1.0 - 1.0 / 8.5)).abs() < 1e-12);
        assert!(m.ok);
        // above: min(26, 10 + 15) = 25; 5000 vs 4000 is 25 %
        let m = separation_margin(5000.0, Some(10.0), 3600.0, 4000.0);
        assert_eq!(m.position, Position::Above);
        assert!((m.required_pct - (10.0 + 17.0 * (1.0 - 1.0 / 8.5))).abs() < 1e-12);
        assert!((m.separation_pct - 25.0).abs() < 1e-12);
        assert!(m.ok == (25.0 >= m.required_pct));
        // critically damped: no margin required, even inside the range
        let m = separation_margin(3800.0, Some(2.0), 3600.0, 4000.0);
        assert_eq!(
            (m.position, m.required_pct, m.ok),
            (Position::Inside, 0.0, true)
        );
        // inside with a high AF: not met
        let m = separation_margin(3800.0, Some(20.0), 3600.0, 4000.0);
        assert!(!m.ok && m.separation_pct < 0.0);
        // unknown AF: the largest requirement
        assert_eq!(
            separation_margin(1000.0, None, 3600.0, 4000.0).required_pct,
            16.0
        );
    }
}
