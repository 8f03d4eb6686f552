//! Keyphasor -> shaft angle phi(t) \[rad\], speed w = phi' \[rad/s\] and acceleration
//! w' = phi'' \[rad/s^2\] (docs/acquisition.md section 3).
//!
//! 1. **Events.** A Schmitt trigger with hysteresis finds each pulse's edge: for a falling
//!    edge it is armed when the signal v rises above `th + h/2` and fires when it falls
//!    below `th - h/2`. The event time is the crossing of the threshold `th` itself, found
//!    between the last sample at or above `th` and the next one, by linear interpolation
//!    `t_e = t_i + (v_i - th) / (v_i - v_(i+1)) (t_(i+1) - t_i)` (exact on a straight edge
//!    spanning both samples). A rising edge is the same on -v. `threshold = "auto"` takes
//!    `th = (min + max) / 2`; the hysteresis is `h = min(max(0.1 (max - min), 5 s_n),
//!    0.4 (max - min))` with s_n the noise from first differences,
//!    `s_n = 1.4826 MAD(v_(i+1) - v_i) / sqrt 2`.
//! 2. **Revolution count.** With I_k = t_(k+1) - t_k and r_k = I_k / the interval
//!    expected at k from the nine around it (itself excluded; a robust straight line through
//!    them, a repeated-median line, so a fast run-up from a low speed is followed): a short interval whose sum with a neighbour is
//!    within 20 % of a revolution is a spurious pulse (removed); an interval within 0.2 of an
//!    integer n >= 2 is n - 1 missed pulses (the count advances by n); anything else outside
//!    0.8..1.2 is an error naming the time.
//! 3. **Smooth angle.** At each event k, phi(t_j) = 2 pi n_j + phi_kp is fitted by least
//!    squares with a quadratic in t over the 2 H + 1 events around k (H =
//!    [`KEYPHASOR_HALF_WINDOW`]; shifted to stay inside the record at its ends): this gives
//!    phi_k, w_k, w'_k at t_k, exact for constant speed and constant acceleration. Between
//!    two events phi is the quintic Hermite polynomial matching (phi, w, w') at both ends
//!    (C2, and exact for any quadratic phi(t)); w and w' are its derivatives.
//! 4. **Partial revolutions.** Before the first and after the last event phi continues
//!    with the constant acceleration of the nearest fit, bounded so that w changes by at
//!    most half its value over the extrapolated span.
//! 5. **Jitter.** The event-time residual of each local fit at its own event,
//!    `(2 pi n_k + phi_kp - phi_k) / w_k`, has variance sigma_j^2 (1 - h_kk) (h_kk the
//!    hat-matrix diagonal); the reported jitter is sqrt(mean(r_k^2 / (1 - h_kk))).
//!
//! Reference: A. Muszynska, *Rotordynamics*, CRC 2005, ch. 2 (keyphasor and slow-roll
//! conventions); F. N. Fritsch, R. E. Carlson, SIAM J. Numer. Anal. 17, 1980 (monotone
//! piecewise interpolation).

use std::f64::consts::PI;

use nalgebra::{Matrix3, Vector3};
use serde::Serialize;

use super::error::{AcquisitionError, Which};
use super::{Edge, Keyphasor, Threshold};

/// Half-width H of the local quadratic fits of phi(t), in events (2 H + 1 = 5 events).
pub const KEYPHASOR_HALF_WINDOW: usize = 2;
/// The fewest keyphasor events accepted (two whole revolutions).
pub const MIN_EVENTS: usize = 3;
/// The fewest samples per revolution accepted.
pub const MIN_SAMPLES_PER_REV: f64 = 8.0;
/// The fewest samples per pulse accepted (time the signal stays beyond the threshold).
pub const MIN_SAMPLES_PER_PULSE: f64 = 2.0;
/// A range (max - min) below this many times the noise is "no pulse".
const NO_PULSE_FACTOR: f64 = 20.0;

/// What the keyphasor conditioning found.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct KeyphasorReport {
    /// The keyphasor column.
    pub column: String,
    /// Threshold used \[V\].
    pub threshold_v: f64,
    /// Hysteresis (full width) \[V\].
    pub hysteresis_v: f64,
    /// Noise of the keyphasor channel from first differences \[V\].
    pub noise_v: f64,
    /// Events used (after removing spurious ones).
    pub events: usize,
    /// Whole revolutions between the first and the last event.
    pub revolutions: u64,
    /// Times \[s\] of the events that end an interval with missed pulses.
    pub missed_pulses_before_s: Vec<f64>,
    /// Times \[s\] of the events removed as spurious.
    pub spurious_pulses_s: Vec<f64>,
    /// First and last event times \[s\].
    pub first_event_s: f64,
    /// Last event time \[s\].
    pub last_event_s: f64,
    /// Estimated RMS timing jitter of the events \[s\] (None with fewer than 2 H + 2 events).
    pub jitter_s: Option<f64>,
    /// The same as an angle at the mean speed \[rad\].
    pub jitter_rad: Option<f64>,
    /// Mean speed between the first and last event \[rev/min\].
    pub mean_speed_rpm: f64,
    /// Median samples per revolution.
    pub samples_per_revolution: f64,
    /// Median samples per pulse.
    pub samples_per_pulse: f64,
    /// Time \[s\] before the first event and after the last one, where phi is extrapolated.
    pub extrapolated_s: [f64; 2],
}

/// The shaft angle per sample and its report.
#[derive(Debug, Clone, PartialEq)]
pub struct ShaftAngle {
    /// phi \[rad\] per sample, phi = phi_kp + 2 pi n at the n-th event after the first.
    pub phi: Vec<f64>,
    /// w = phi' \[rad/s\].
    pub omega: Vec<f64>,
    /// w' = phi'' \[rad/s^2\].
    pub omega_dot: Vec<f64>,
    /// Events, revolutions, jitter.
    pub report: KeyphasorReport,
}

/// One event, with its revolution count.
#[derive(Debug, Clone, Copy)]
struct Event {
    t: f64,
    n: u64,
}

/// Median of a non-empty slice (copied).
pub(crate) fn median(v: &[f64]) -> f64 {
    median_in_place(&mut v.to_vec())
}

/// Median of a non-empty slice, reordering it: the middle element (the mean of the two
/// middle ones for an even length) of the values ordered by `total_cmp`, as a full sort
/// gives them, found by selection (linear, not n log n).
pub(crate) fn median_in_place(s: &mut [f64]) -> f64 {
    let n = s.len();
    let (lower, mid, _) = s.select_nth_unstable_by(n / 2, f64::total_cmp);
    let mid = *mid;
    if n % 2 == 1 {
        mid
    } else {
        // the largest of the lower half: the element a sort puts at n / 2 - 1
        let below = lower
            .iter()
            .copied()
            .max_by(f64::total_cmp)
            .expect("an even length >= 2 has a lower half");
        0.5 * (below + mid)
    }
}

/// White-noise level of a signal from its first differences (robust: MAD).
pub(crate) fn noise_from_differences(v: &[f64]) -> f64 {
    if v.len() < 3 {
        return 0.0;
    }
    let mut d: Vec<f64> = v.windows(2).map(|w| w[1] - w[0]).collect();
    let med = median_in_place(&mut d);
    // the absolute deviations in the same buffer (their order does not matter)
    for x in &mut d {
        *x = (*x - med).abs();
    }
    1.4826 * median_in_place(&mut d) / 2f64.sqrt()
}

/// Threshold crossings of `kp` at times `t`, as event times \[s\], with the threshold,
/// hysteresis, noise and the median pulse width in samples.
struct Detected {
    times: Vec<f64>,
    threshold: f64,
    hysteresis: f64,
    noise: f64,
    pulse_samples: f64,
}

fn detect(
    t: &[f64],
    kp: &[f64],
    cfg: &Keyphasor,
    which: Which,
) -> Result<Detected, AcquisitionError> {
    let (lo, hi) = kp
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &v| {
            (a.min(v), b.max(v))
        });
    let noise = noise_from_differences(kp);
    let range = hi - lo;
    let resolved = range > NO_PULSE_FACTOR * noise && range > 0.0;
    if !resolved {
        return Err(AcquisitionError::NoPulse {
            which,
            column: cfg.column.clone(),
            range_v: range,
            noise_v: noise,
            factor: NO_PULSE_FACTOR,
        });
    }
    let threshold = match cfg.threshold {
        Threshold::Auto => 0.5 * (lo + hi),
        Threshold::Volts(v) => {
            if !(v > lo && v < hi) {
                return Err(AcquisitionError::ThresholdOutsideSignal {
                    which,
                    threshold_v: v,
                    low_v: lo,
                    high_v: hi,
                });
            }
            v
        }
    };
    let mut hyst = (0.1 * range).max(5.0 * noise).min(0.4 * range);
    // Keep both trigger levels inside the signal's levels.
    hyst = hyst
        .min(2.0 * (hi - threshold) * 0.9)
        .min(2.0 * (threshold - lo) * 0.9);
    // Work on a falling edge: s = v (falling) or -v (rising).
    let sign = match cfg.edge {
        Edge::Falling => 1.0,
        Edge::Rising => -1.0,
    };
    let th = sign * threshold;
    let (upper, lower) = (th + 0.5 * hyst, th - 0.5 * hyst);
    let s = |i: usize| sign * kp[i];
    let mut times = Vec::new();
    let mut widths = Vec::new();
    let mut armed = false;
    let mut i = 0;
    let n = kp.len();
    while i < n {
        let v = s(i);
        if !armed {
            if v > upper {
                armed = true;
            }
            i += 1;
            continue;
        }
        if v < lower {
            // Fired: the crossing of th is between the last sample >= th and the next.
            let mut j = i;
            while j > 0 && s(j - 1) < th {
                j -= 1;
            }
            // s(j - 1) >= th > s(j) (j >= 1 since the trigger was armed above th).
            let (a, b) = (s(j - 1), s(j));
            let frac = if a > b { (a - th) / (a - b) } else { 0.5 };
            let te = t[j - 1] + frac * (t[j] - t[j - 1]);
            times.push(te);
            // Width: samples until the signal is back above th.
            let mut k = i;
            while k < n && s(k) < th {
                k += 1;
            }
            if k < n {
                widths.push((k - j) as f64);
            }
            armed = false;
            i = k.max(i + 1);
            continue;
        }
        i += 1;
    }
    let pulse_samples = if widths.is_empty() {
        f64::NAN
    } else {
        median(&widths)
    };
    Ok(Detected {
        times,
        threshold,
        hysteresis: hyst,
        noise,
        pulse_samples,
    })
}

/// Local reference interval for interval k: from up to nine neighbours (k excluded), the
/// robust straight line through them (the repeated median of the pairwise slopes, then
/// the median of the intervals moved to k along it) evaluated at k. At a steady speed this
/// is their median; on a run-up from a low speed, where one revolution can be 20 % longer
/// than the next, it follows the trend that a plain median (of later, shorter revolutions
/// at the record's start) misses. A missed or spurious pulse among the neighbours moves
/// neither median.
fn reference_interval(iv: &[f64], k: usize) -> f64 {
    let lo = k.saturating_sub(4);
    let hi = (k + 5).min(iv.len());
    let neigh: Vec<usize> = (lo..hi).filter(|&j| j != k).collect();
    if neigh.is_empty() {
        return iv[k];
    }
    // the repeated median of the slopes (Siegel): robust to one bad interval even when
    // the neighbours lie on one side only (the record's first revolutions)
    let slope = if neigh.len() < 2 {
        0.0
    } else {
        let per: Vec<f64> = neigh
            .iter()
            .map(|&i| {
                let s: Vec<f64> = neigh
                    .iter()
                    .filter(|&&j| j != i)
                    .map(|&j| (iv[j] - iv[i]) / (j as f64 - i as f64))
                    .collect();
                median(&s)
            })
            .collect();
        median(&per)
    };
    let moved: Vec<f64> = neigh
        .iter()
        .map(|&j| iv[j] - slope * (j as f64 - k as f64))
        .collect();
    let r = median(&moved);
    if r > 0.0 {
        r
    } else {
        median(&neigh.iter().map(|&j| iv[j]).collect::<Vec<_>>())
    }
}

/// Remove spurious events and count revolutions across missed ones.
/// Events with their revolution counts, times \[s\] after which pulses were missed, and
/// times of the spurious pulses removed.
type Counted = (Vec<Event>, Vec<f64>, Vec<f64>);

fn count_revolutions(mut times: Vec<f64>, which: Which) -> Result<Counted, AcquisitionError> {
    let mut spurious = Vec::new();
    // Spurious pulses: an interval much shorter than its neighbours whose sum with the next
    // (or previous) one is a revolution.
    'outer: loop {
        if times.len() < 4 {
            break;
        }
        let iv: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
        for k in 0..iv.len() {
            let r = reference_interval(&iv, k);
            if iv[k] / r < 0.8 {
                let next = (k + 1 < iv.len()).then(|| (iv[k] + iv[k + 1]) / r);
                let prev = (k > 0).then(|| (iv[k - 1] + iv[k]) / r);
                // Remove the event shared by the two intervals that sum to one revolution.
                let remove = match (prev, next) {
                    (_, Some(s)) if (s - 1.0).abs() < 0.2 => k + 1,
                    (Some(s), _) if (s - 1.0).abs() < 0.2 => k,
                    _ => {
                        return Err(AcquisitionError::IrregularPulse {
                            which,
                            t: times[k + 1],
                            interval_s: iv[k],
                            expected_s: r,
                            ratio: iv[k] / r,
                        })
                    }
                };
                spurious.push(times.remove(remove));
                continue 'outer;
            }
        }
        break;
    }
    let mut events = Vec::with_capacity(times.len());
    let mut missed = Vec::new();
    if times.is_empty() {
        return Ok((events, missed, spurious));
    }
    events.push(Event { t: times[0], n: 0 });
    let iv: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
    for k in 0..iv.len() {
        let r = reference_interval(&iv, k);
        let ratio = iv[k] / r;
        let whole = ratio.round();
        let step = if (ratio - 1.0).abs() < 0.2 {
            1
        } else if whole >= 2.0 && (ratio - whole).abs() < 0.2 {
            missed.push(times[k + 1]);
            whole as u64
        } else {
            return Err(AcquisitionError::IrregularPulse {
                which,
                t: times[k + 1],
                interval_s: iv[k],
                expected_s: r,
                ratio,
            });
        };
        let n = events.last().map_or(0, |e| e.n) + step;
        events.push(Event { t: times[k + 1], n });
    }
    Ok((events, missed, spurious))
}

/// (phi, w, w') at an event from the quadratic least-squares fit of phi over the events
/// `lo..hi`, centred on `t0`, and the hat-matrix diagonal of the event at `t0`.
fn local_fit(ev: &[Event], lo: usize, hi: usize, t0: f64, phi_kp: f64, scale: f64) -> Node {
    let mut a = Matrix3::zeros();
    let mut b = Vector3::zeros();
    for e in &ev[lo..hi] {
        let u = (e.t - t0) / scale;
        let row = Vector3::new(1.0, u, u * u);
        a += row * row.transpose();
        b += row * (2.0 * PI * e.n as f64 + phi_kp);
    }
    let inv = a.try_inverse().unwrap_or_else(Matrix3::zeros);
    let c = inv * b;
    Node {
        t: t0,
        phi: c[0],
        omega: c[1] / scale,
        omega_dot: 2.0 * c[2] / (scale * scale),
        hat: inv[(0, 0)],
    }
}

#[derive(Debug, Clone, Copy)]
struct Node {
    t: f64,
    phi: f64,
    omega: f64,
    omega_dot: f64,
    hat: f64,
}

/// Quintic Hermite between two nodes at `t`: (phi, w, w').
fn hermite(a: &Node, b: &Node, t: f64) -> (f64, f64, f64) {
    let h = b.t - a.t;
    let s = (t - a.t) / h;
    let dp = b.phi - a.phi;
    let (v0, v1) = (a.omega * h, b.omega * h);
    let (a0, a1) = (a.omega_dot * h * h, b.omega_dot * h * h);
    let c3 = 10.0 * dp - 6.0 * v0 - 4.0 * v1 - 1.5 * a0 + 0.5 * a1;
    let c4 = -15.0 * dp + 8.0 * v0 + 7.0 * v1 + 1.5 * a0 - a1;
    let c5 = 6.0 * dp - 3.0 * v0 - 3.0 * v1 - 0.5 * a0 + 0.5 * a1;
    let p = a.phi + s * (v0 + s * (0.5 * a0 + s * (c3 + s * (c4 + s * c5))));
    let d1 = v0 + s * (a0 + s * (3.0 * c3 + s * (4.0 * c4 + s * 5.0 * c5)));
    let d2 = a0 + s * (6.0 * c3 + s * (12.0 * c4 + s * 20.0 * c5));
    (p, d1 / h, d2 / (h * h))
}

/// The shaft angle from the keyphasor channel `kp` \[V\] sampled at times `t` \[s\]
/// (strictly increasing, finite; checked by the caller), per the module doc.
pub fn shaft_angle(
    t: &[f64],
    kp: &[f64],
    cfg: &Keyphasor,
    which: Which,
) -> Result<ShaftAngle, AcquisitionError> {
    let n = t.len();
    if n < 2 * MIN_SAMPLES_PER_REV as usize {
        return Err(AcquisitionError::TooFewSamples {
            which,
            samples: n,
            needed: 2 * MIN_SAMPLES_PER_REV as usize,
        });
    }
    let dt = (t[n - 1] - t[0]) / (n - 1) as f64;
    let det = detect(t, kp, cfg, which)?;
    let edge = match cfg.edge {
        Edge::Falling => "falling",
        Edge::Rising => "rising",
    };
    if det.pulse_samples < MIN_SAMPLES_PER_PULSE {
        return Err(AcquisitionError::KeyphasorTooFast {
            which,
            what: "samples per pulse",
            value: det.pulse_samples,
            needed: MIN_SAMPLES_PER_PULSE,
        });
    }
    if det.times.len() < MIN_EVENTS {
        return Err(AcquisitionError::TooFewPulses {
            which,
            column: cfg.column.clone(),
            found: det.times.len(),
            needed: MIN_EVENTS,
            edge,
        });
    }
    let iv: Vec<f64> = det.times.windows(2).map(|w| w[1] - w[0]).collect();
    let per_rev = median(&iv) / dt;
    if per_rev < MIN_SAMPLES_PER_REV {
        return Err(AcquisitionError::KeyphasorTooFast {
            which,
            what: "samples per revolution",
            value: per_rev,
            needed: MIN_SAMPLES_PER_REV,
        });
    }
    let (events, missed, spurious) = count_revolutions(det.times, which)?;
    if events.len() < MIN_EVENTS {
        return Err(AcquisitionError::TooFewPulses {
            which,
            column: cfg.column.clone(),
            found: events.len(),
            needed: MIN_EVENTS,
            edge,
        });
    }
    let ne = events.len();
    let w = (2 * KEYPHASOR_HALF_WINDOW + 1).min(ne);
    let scale = median(&iv);
    let phi_kp = cfg.angle;
    let nodes: Vec<Node> = (0..ne)
        .map(|k| {
            let lo = k.saturating_sub(KEYPHASOR_HALF_WINDOW).min(ne - w);
            local_fit(&events, lo, lo + w, events[k].t, phi_kp, scale)
        })
        .collect();
    for nd in &nodes {
        if nd.omega.is_nan() || nd.omega <= 0.0 {
            return Err(AcquisitionError::SpeedNotPositive {
                which,
                t: nd.t,
                omega: nd.omega,
            });
        }
    }
    // Jitter from the residuals at each event.
    let jitter_s = (w > 3).then(|| {
        let s: f64 = events
            .iter()
            .zip(&nodes)
            .map(|(e, nd)| {
                let r = (2.0 * PI * e.n as f64 + phi_kp - nd.phi) / nd.omega;
                r * r / (1.0 - nd.hat).max(1e-3)
            })
            .sum();
        (s / ne as f64).sqrt()
    });
    let (first, last) = (nodes[0], nodes[ne - 1]);
    let mean_omega = 2.0 * PI * events[ne - 1].n as f64 / (last.t - first.t);
    // Extrapolation beyond the first and last events, acceleration bounded.
    let bounded = |nd: &Node, span: f64| {
        let lim = if span > 0.0 {
            0.5 * nd.omega / span
        } else {
            f64::INFINITY
        };
        nd.omega_dot.clamp(-lim, lim)
    };
    let acc0 = bounded(&first, first.t - t[0]);
    let acc1 = bounded(&last, t[n - 1] - last.t);
    let mut phi = Vec::with_capacity(n);
    let mut omega = Vec::with_capacity(n);
    let mut omega_dot = Vec::with_capacity(n);
    let mut seg = 0usize;
    for &ti in t {
        let (p, v, a) = if ti < first.t {
            let u = ti - first.t;
            (
                first.phi + first.omega * u + 0.5 * acc0 * u * u,
                first.omega + acc0 * u,
                acc0,
            )
        } else if ti >= last.t {
            let u = ti - last.t;
            (
                last.phi + last.omega * u + 0.5 * acc1 * u * u,
                last.omega + acc1 * u,
                acc1,
            )
        } else {
            while seg + 1 < ne && nodes[seg + 1].t <= ti {
                seg += 1;
            }
            hermite(&nodes[seg], &nodes[seg + 1], ti)
        };
        phi.push(p);
        omega.push(v);
        omega_dot.push(a);
    }
    if let Some((i, &v)) = omega
        .iter()
        .enumerate()
        .find(|(_, &v)| v.is_nan() || v <= 0.0)
    {
        return Err(AcquisitionError::SpeedNotPositive {
            which,
            t: t[i],
            omega: v,
        });
    }
    let report = KeyphasorReport {
        column: cfg.column.clone(),
        threshold_v: det.threshold,
        hysteresis_v: det.hysteresis,
        noise_v: det.noise,
        events: ne,
        revolutions: events[ne - 1].n,
        missed_pulses_before_s: missed,
        spurious_pulses_s: spurious,
        first_event_s: first.t,
        last_event_s: last.t,
        jitter_s,
        jitter_rad: jitter_s.map(|j| j * mean_omega),
        mean_speed_rpm: mean_omega * 60.0 / (2.0 * PI),
        samples_per_revolution: per_rev,
        samples_per_pulse: det.pulse_samples,
        extrapolated_s: [first.t - t[0], t[n - 1] - last.t],
    };
    Ok(ShaftAngle {
        phi,
        omega,
        omega_dot,
        report,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn node(t: f64, p: impl Fn(f64) -> (f64, f64, f64)) -> Node {
        let (phi, omega, omega_dot) = p(t);
        Node {
            t,
            phi,
            omega,
            omega_dot,
            hat: 0.0,
        }
    }

    /// The quintic Hermite reproduces any quintic exactly (value and two derivatives).
    #[test]
    fn hermite_reproduces_a_quintic() {
        let p = |t: f64| {
            (
                1.0 + 2.0 * t - 0.5 * t * t + 0.3 * t.powi(3) - 0.2 * t.powi(4) + 0.1 * t.powi(5),
                2.0 - t + 0.9 * t * t - 0.8 * t.powi(3) + 0.5 * t.powi(4),
                -1.0 + 1.8 * t - 2.4 * t * t + 2.0 * t.powi(3),
            )
        };
        let (a, b) = (node(0.3, p), node(1.1, p));
        for k in 0..=10 {
            let t = 0.3 + 0.08 * k as f64;
            let (x, v, w) = hermite(&a, &b, t);
            let (xe, ve, we) = p(t);
            assert!((x - xe).abs() < 1e-13 && (v - ve).abs() < 1e-12 && (w - we).abs() < 1e-11);
        }
    }

    #[test]
    fn a_fast_run_up_from_slow_roll_is_counted_and_its_missed_pulse_found() {
        // 300 rpm + 30 rad/s^2: the first revolution is 23 % longer than the third, which
        // the median of the later neighbours took for an irregular pulse
        let (w0, a) = (300.0 * std::f64::consts::TAU / 60.0, 30.0);
        let mut times: Vec<f64> = (0..60)
            .map(|n| {
                let phi = std::f64::consts::TAU * f64::from(n);
                (-w0 + (w0 * w0 + 2.0 * a * phi).sqrt()) / a
            })
            .collect();
        let (events, missed, spurious) = count_revolutions(times.clone(), Which::Running).unwrap();
        assert_eq!((events.len(), missed.len(), spurious.len()), (60, 0, 0));
        for k in 0..59 {
            let iv: Vec<f64> = times.windows(2).map(|w| w[1] - w[0]).collect();
            let r = iv[k] / reference_interval(&iv, k);
            // (the intervals' curvature, extrapolated at the record's start: 8 % there,
            // where the plain median gave 26 %; a pulse is irregular beyond 20 %)
            assert!((r - 1.0).abs() < 0.1, "interval {k}: ratio {r}");
        }
        // a missed pulse is still one (from the tenth revolution on: among the first few,
        // where a revolution is 10-25 % longer than the next and the neighbours lie on one
        // side only, a missed pulse is beyond what nine neighbours can tell)
        let dropped = times.remove(10);
        let (events, missed, _) = count_revolutions(times, Which::Running).unwrap();
        assert_eq!(missed.len(), 1);
        assert_eq!(events.last().unwrap().n, 59);
        assert!(dropped > 0.0);
    }

    #[test]
    fn missed_and_spurious_pulses_are_repaired_and_irregular_ones_named() {
        let mut t: Vec<f64> = (0..20).map(|k| 0.05 * k as f64).collect();
        t.remove(7); // missed
        t.insert(12, 0.05 * 12.0 + 0.013); // spurious, after the true event at index 12 (0.6 s)
        let (ev, missed, spurious) = count_revolutions(t, Which::Running).unwrap();
        assert_eq!(ev.len(), 19);
        assert_eq!(ev.last().unwrap().n, 19);
        assert_eq!(missed.len(), 1);
        assert!((missed[0] - 0.4).abs() < 1e-12);
        assert_eq!(spurious.len(), 1);
        assert!((spurious[0] - 0.613).abs() < 1e-12);
        // An interval of 1.5 revolutions is ambiguous.
        let mut t: Vec<f64> = (0..20).map(|k| 0.05 * k as f64).collect();
        for v in t.iter_mut().skip(10) {
            *v += 0.025;
        }
        match count_revolutions(t, Which::Running) {
            Err(AcquisitionError::IrregularPulse { t, ratio, .. }) => {
                assert!((t - 0.525).abs() < 1e-12 && (ratio - 1.5).abs() < 1e-9)
            }
            other => panic!("{other:?}"),
        }
    }
}
