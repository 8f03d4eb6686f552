//! The keyphasor's shaft angle smoothed over neighbouring revolutions for order tracking
//! (docs/transient.md section 2).
//!
//! A keyphasor event is timed where its pulse crosses the threshold, interpolated between
//! two samples: the time scatters by a fraction of a sample (the pulse's edge is not a
//! straight line between them, and it is quantised). At 5 kHz and 7000 rpm a tenth of a
//! sample is half a degree of shaft angle, so each revolution's 1X vector turned by
//! about 0.5 deg at random (measured on `rotorid simulate --raw` run-ups): noise
//! proportional to the amplitude, which the revolution's own residual does not see.
//! The speed of a run-up changes smoothly over a few tens of revolutions, so the events
//! are smoothed: around each event k, the angle 2 pi j of the events j = k - 15 .. k + 15
//! is fitted by a cubic in time, and the event's time and speed are read from that cubic
//! where it passes 2 pi k. Between two smoothed events the angle is the cubic Hermite
//! interpolant of their times, angles and speeds (continuous, with a continuous speed).
//! A constant acceleration, and any cubic angle history, is kept exactly.

use std::f64::consts::TAU;

use nalgebra::{Matrix4, Vector4};

/// Events on either side of an event in its cubic fit.
pub const EVENT_HALF_WINDOW: usize = 15;

/// The events of `psi` (the shaft angle from the keyphasor event \[rad\], increasing, at
/// the sample times `t` \[s\]): where it passes each multiple of 2 pi, linearly
/// interpolated between samples, as (time, multiple).
fn events(t: &[f64], psi: &[f64]) -> Vec<(f64, f64)> {
    let mut out = Vec::new();
    let Some(&first) = psi.first() else {
        return out;
    };
    let mut k = (first / TAU).ceil();
    for i in 0..psi.len() {
        while psi[i] >= k * TAU {
            let te = if i == 0 {
                t[0]
            } else {
                let (p0, p1) = (psi[i - 1], psi[i]);
                t[i - 1] + (k * TAU - p0) / (p1 - p0) * (t[i] - t[i - 1])
            };
            out.push((te, k));
            k += 1.0;
        }
    }
    out
}

/// The smoothed time and speed \[rad/s\] of event `k` of `ev` (module doc); `None` when
/// the fit is singular or its speed not positive.
fn smoothed_event(ev: &[(f64, f64)], k: usize) -> Option<(f64, f64)> {
    let lo = k.saturating_sub(EVENT_HALF_WINDOW);
    let hi = (k + EVENT_HALF_WINDOW + 1).min(ev.len());
    let (t0, m0) = ev[k];
    let scale = (ev[hi - 1].0 - ev[lo].0).max(f64::MIN_POSITIVE);
    let mut ata = Matrix4::<f64>::zeros();
    let mut aty = Vector4::<f64>::zeros();
    for &(t, m) in &ev[lo..hi] {
        let u = (t - t0) / scale;
        let x = Vector4::new(1.0, u, u * u, u * u * u);
        ata += x * x.transpose();
        aty += x * (TAU * (m - m0));
    }
    let c = ata.cholesky()?.solve(&aty);
    // Newton on c0 + c1 u + c2 u^2 + c3 u^3 = 0 from u = 0
    let mut u = 0.0;
    for _ in 0..4 {
        let f = c[0] + u * (c[1] + u * (c[2] + u * c[3]));
        let d = c[1] + u * (2.0 * c[2] + u * 3.0 * c[3]);
        if d <= 0.0 {
            return None;
        }
        u -= f / d;
    }
    let d = c[1] + u * (2.0 * c[2] + u * 3.0 * c[3]);
    (d > 0.0 && u.is_finite()).then(|| (t0 + u * scale, d / scale))
}

/// `psi` with its events smoothed (module doc): the same length, the same multiple of
/// 2 pi at each smoothed event. Unchanged with fewer than 5 events or where a fit fails
/// (then that stretch keeps the measured angle).
pub fn smooth(t: &[f64], psi: &[f64]) -> Vec<f64> {
    let mut out = psi.to_vec();
    smooth_in_place(t, &mut out);
    out
}

/// [`smooth`] in place: `psi` becomes the smoothed angle (no second copy of the record's
/// angle). The same values: each sample's new angle depends on the events, found before
/// anything is changed, and on its own time.
pub fn smooth_in_place(t: &[f64], psi: &mut [f64]) {
    let ev = events(t, psi);
    if ev.len() < 5 || t.len() != psi.len() {
        return;
    }
    let smooth: Vec<Option<(f64, f64)>> = (0..ev.len()).map(|k| smoothed_event(&ev, k)).collect();
    let out = psi;
    // the samples between consecutive events, by the measured angle
    let mut j = 0;
    for (i, o) in out.iter_mut().enumerate() {
        while j + 1 < ev.len() && t[i] >= ev[j + 1].0 {
            j += 1;
        }
        if t[i] < ev[0].0 || j + 1 >= ev.len() {
            continue; // before the first or after the last event: as measured
        }
        let (Some((ta, wa)), Some((tb, wb))) = (smooth[j], smooth[j + 1]) else {
            continue;
        };
        let h = tb - ta;
        if h <= 0.0 {
            continue;
        }
        // cubic Hermite on [ta, tb] through (ta, 2 pi m_a, wa) and (tb, 2 pi m_b, wb)
        let (pa, pb) = (TAU * ev[j].1, TAU * ev[j + 1].1);
        let s = (t[i] - ta) / h;
        let (s2, s3) = (s * s, s * s * s);
        let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
        let h10 = s3 - 2.0 * s2 + s;
        let h01 = -2.0 * s3 + 3.0 * s2;
        let h11 = s3 - s2;
        *o = h00 * pa + h10 * h * wa + h01 * pb + h11 * h * wb;
    }
    // keep the angle increasing where a smoothed and a measured stretch meet
    for i in 1..out.len() {
        if out[i] < out[i - 1] {
            out[i] = out[i - 1];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};

    /// psi of a run-up w0 t + a t^2 / 2 as a keyphasor gives it: events timed with an
    /// error (std `jitter` s), the angle linear in time between them.
    fn jittered(w0: f64, a: f64, fs: f64, dur: f64, jitter: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let n = (dur * fs) as usize;
        let t: Vec<f64> = (0..n).map(|i| i as f64 / fs).collect();
        let truth: Vec<f64> = t.iter().map(|&t| w0 * t + 0.5 * a * t * t).collect();
        let mut rng = rand::rngs::StdRng::seed_from_u64(3);
        let noise = Normal::new(0.0, jitter).unwrap();
        let ev: Vec<f64> = (0..)
            .map(|k| (-w0 + (w0 * w0 + 2.0 * a * TAU * k as f64).sqrt()) / a)
            .take_while(|&te| te < dur + 1.0)
            .map(|te| te + noise.sample(&mut rng))
            .collect();
        let psi = t
            .iter()
            .map(|&ti| {
                let k = ev.partition_point(|&e| e <= ti).max(1) - 1;
                let (ea, eb) = (ev[k], ev[k + 1]);
                TAU * (k as f64 + (ti - ea) / (eb - ea))
            })
            .collect();
        (t, truth, psi)
    }

    #[test]
    fn jittered_events_come_back_to_the_true_angle() {
        // 5 kHz, a run-up 100 -> 800 rad/s, events off by 20 us (0.1 sample) at random
        let (t, truth, psi) = jittered(100.0, 50.0, 5000.0, 14.0, 20e-6);
        let s = smooth(&t, &psi);
        let err = |p: &[f64]| {
            let k0 = t.iter().position(|&x| x > 0.5).unwrap();
            let k1 = t.iter().position(|&x| x > 13.0).unwrap();
            let e: Vec<f64> = (k0..k1).map(|i| p[i] - truth[i]).collect();
            (e.iter().map(|v| v * v).sum::<f64>() / e.len() as f64).sqrt()
        };
        let (before, after) = (err(&psi), err(&s));
        // the angle error falls by 3 and more (a cubic over 31 events)
        assert!(after < before / 3.0, "{before:e} -> {after:e}");
        assert!(s.windows(2).all(|w| w[1] >= w[0]));
    }

    #[test]
    fn an_exact_run_up_is_kept() {
        let (t, truth, psi) = jittered(100.0, 50.0, 5000.0, 6.0, 0.0);
        let s = smooth(&t, &psi);
        // the measured angle is linear between events, the smoothed one the true curve;
        // the events are read back from the sampled angle, whose kink at each event moves
        // them by up to 1e-4 rad (0.006 deg) here
        let k0 = t.iter().position(|&x| x > 0.5).unwrap();
        let k1 = t.iter().position(|&x| x > 5.0).unwrap();
        let worst = (k0..k1)
            .map(|i| (s[i] - truth[i]).abs())
            .fold(0.0, f64::max);
        let measured = (k0..k1)
            .map(|i| (psi[i] - truth[i]).abs())
            .fold(0.0, f64::max);
        assert!(
            worst < 2e-4 && worst < measured / 10.0,
            "{worst:e} (measured {measured:e})"
        );
    }
}
