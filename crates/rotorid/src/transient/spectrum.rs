//! Cascades (waterfalls) of amplitude spectra over a run-up or coast-down: one probe's
//! spectra ([`cascade`]), or the full spectra of an XY probe pair ([`full_cascade`]),
//! each spectrum tagged with the shaft speed over its block.
//!
//! # Blocks and amplitudes
//!
//! The record must be uniformly sampled: the step is the median of `t`'s steps, and a
//! record with a step more than [`MAX_DT_DEVIATION`] (1 %) away from it is refused
//! ([`TransientError::NonUniformSampling`]; a non-uniform record is not supported:
//! resample it first). Up to [`CascadeSettings::spectra`] blocks of
//! [`CascadeSettings::lines`] samples are spread evenly over the record (first block at
//! the start, last at the end; they overlap when the record is short). A record shorter
//! than `lines` samples uses the longest power of two it holds, down to [`MIN_LINES`].
//!
//! Each block has its (window-weighted) mean removed and is weighted by the periodic Hann window
//! w\[i\] = (1 - cos(2 pi i / N)) / 2. Amplitudes are zero-to-peak in the signal's unit,
//! corrected for the window's coherent gain (sum of w = N / 2): a sinusoid of amplitude A
//! whose frequency falls on a line shows A on that line. Between two lines the Hann window
//! shows down to 0.85 A (scalloping) on each of the two nearest lines;
//! [`Cascade::peak`] interpolates the true amplitude and frequency of a line from its
//! neighbours. Lines are df = 1 / (N dt) apart; white noise of standard deviation sigma
//! shows a mean square of 6 sigma^2 / N per line.
//!
//! Each spectrum's speed is the mean of `omega` over its block, in rpm; its time is the
//! centre of the block. The frequency axis runs up to [`CascadeSettings::max_order`] times
//! the highest of those speeds (never beyond the Nyquist frequency 1 / (2 dt)).
//!
//! # Full spectrum: sign convention
//!
//! The full spectrum of the pair x (horizontal), z (vertical, up) is the spectrum of the
//! complex signal p = z + i x. The shaft turns from +z towards +x (docs/method.md 1.1), so
//! a point whirling in the direction of rotation, (x, z) = r (sin theta, cos theta) with
//! theta growing, is p = r e^(i theta): **positive frequencies are forward whirl** (in the
//! direction of rotation), **negative frequencies backward whirl**. A line's amplitude is
//! the radius of that circular component: a forward circular orbit of radius r shows r at
//! +f and nothing at -f; an elliptical orbit of semi-axes a >= b, whatever its tilt, shows
//! (a + b) / 2 at +f and (a - b) / 2 at -f when it whirls forward (the other way round
//! backward); a straight-line orbit of half-length a shows a / 2 on both sides. The sense
//! is fixed by the axes, not by the sign of `omega`.

use realfft::num_complex::Complex;
use realfft::RealFftPlanner;
use serde::{Deserialize, Serialize};

use super::error::{check_finite, same_length, TransientError};
use crate::model::{check, rad_per_s_to_rpm};

/// The shortest block a spectrum is computed from \[samples\].
pub const MIN_LINES: usize = 256;

/// The longest block \[samples\] (2^20).
pub const MAX_LINES: usize = 1 << 20;

/// The most spectra a cascade may hold.
pub const MAX_SPECTRA: usize = 10_000;

/// The highest `max_order` accepted.
pub const MAX_ORDER: f64 = 1000.0;

/// The largest relative deviation of a time step from the record's median step (1 %).
pub const MAX_DT_DEVIATION: f64 = 0.01;

/// Hann window's equivalent noise bandwidth \[lines\] (sum w^2 N / (sum w)^2).
pub const HANN_ENBW: f64 = 1.5;

/// Spectra against speed: a cascade (waterfall) of one probe or the full spectra of an XY
/// pair.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Cascade {
    /// Shaft speed of each spectrum: the mean of `omega` over its block \[rev/min\].
    pub rpm: Vec<f64>,
    /// Centre time of each spectrum's block \[s\].
    pub t: Vec<f64>,
    /// Frequency of each line \[Hz\], increasing, df apart: 0 to f_max for one probe;
    /// -f_max to +f_max for a full spectrum (positive = forward whirl).
    pub freq_hz: Vec<f64>,
    /// Amplitude \[spectrum\]\[line\], zero-to-peak, in the signal's unit \[m\] (full
    /// spectrum: the radius of the circular component at that frequency).
    pub amplitude: Vec<Vec<f64>>,
    /// Samples per block (the FFT length) \[samples\].
    pub lines: usize,
    /// True for the full spectrum of an XY pair (negative frequencies = backward whirl).
    pub full: bool,
}

/// A spectral line located between the FFT lines (Hann interpolation).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Peak {
    /// Its frequency \[Hz\] (negative: backward whirl, in a full spectrum).
    pub freq_hz: f64,
    /// Its amplitude, zero-to-peak, corrected for scalloping \[m\].
    pub amplitude: f64,
    /// Index of the largest FFT line in the spectrum's `freq_hz`.
    pub line: usize,
}

impl Cascade {
    /// Spacing of the lines \[Hz\] (NaN with fewer than two lines).
    pub fn df(&self) -> f64 {
        match self.freq_hz.as_slice() {
            [a, b, ..] => b - a,
            _ => f64::NAN,
        }
    }

    /// The largest line of spectrum `spectrum` with a frequency in `f_lo..=f_hi` \[Hz\] and a
    /// line on each side, its frequency and amplitude interpolated from its larger
    /// neighbour as for a sinusoid under the Hann window (exact for a stationary sinusoid
    /// far from other lines; see the module doc). `None` when no such line exists or the
    /// spectrum index is out of range.
    pub fn peak(&self, spectrum: usize, f_lo: f64, f_hi: f64) -> Option<Peak> {
        let a = self.amplitude.get(spectrum)?;
        let n = a.len().min(self.freq_hz.len());
        let k = (1..n.saturating_sub(1))
            .filter(|&k| self.freq_hz[k] >= f_lo && self.freq_hz[k] <= f_hi)
            .max_by(|&i, &j| a[i].total_cmp(&a[j]))?;
        let (side, alpha) = if a[k + 1] >= a[k - 1] {
            (1.0, a[k + 1] / a[k])
        } else {
            (-1.0, a[k - 1] / a[k])
        };
        if a[k] <= 0.0 || a[k].is_nan() {
            return Some(Peak {
                freq_hz: self.freq_hz[k],
                amplitude: 0.0,
                line: k,
            });
        }
        // Hann: a[k+1] / a[k] = (1 + d) / (2 - d) for a sinusoid d lines above line k.
        let d = ((2.0 * alpha - 1.0) / (alpha + 1.0)).clamp(0.0, 0.5);
        let x = std::f64::consts::PI * d;
        let gain = if d > 1e-9 {
            x.sin() / x / (1.0 - d * d)
        } else {
            1.0
        };
        Some(Peak {
            freq_hz: self.freq_hz[k] + side * d * self.df(),
            amplitude: a[k] / gain,
            line: k,
        })
    }

    /// The peak of order `order` in spectrum `spectrum`: [`Cascade::peak`] within two
    /// lines of `order` x its speed (a negative order is backward whirl, in a full
    /// spectrum).
    pub fn order_peak(&self, spectrum: usize, order: f64) -> Option<Peak> {
        let f = order * self.rpm.get(spectrum)? / 60.0;
        let w = 2.0 * self.df();
        self.peak(spectrum, f - w, f + w)
    }
}

/// How a cascade is computed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CascadeSettings {
    /// Samples per spectrum (the FFT length): a power of two from [`MIN_LINES`] to
    /// [`MAX_LINES`] \[samples\]; the lines are 1 / (lines dt) apart. Default 4096 (0.41 s
    /// and 2.4 Hz at 10 kHz).
    pub lines: usize,
    /// The most spectra, spread evenly over the record (fewer when the record holds fewer
    /// distinct blocks): 1 to [`MAX_SPECTRA`]. Default 80.
    pub spectra: usize,
    /// The frequency axis runs up to this multiple of the highest spectrum speed
    /// \[orders of the running speed\]: finite, > 0 and at most [`MAX_ORDER`]. Default 10.
    pub max_order: f64,
}

impl Default for CascadeSettings {
    fn default() -> Self {
        Self {
            lines: 4096,
            spectra: 80,
            max_order: 10.0,
        }
    }
}

impl CascadeSettings {
    /// `Ok` when every setting is in its range, else [`TransientError::OutOfRange`] naming
    /// the first that is not.
    pub fn validate(&self) -> Result<(), TransientError> {
        check(
            "lines",
            self.lines as f64,
            "a power of two from 256 to 1048576 (samples)",
            |_| self.lines.is_power_of_two() && (MIN_LINES..=MAX_LINES).contains(&self.lines),
        )?;
        check(
            "spectra",
            self.spectra as f64,
            "an integer from 1 to 10000 (spectra)",
            |_| (1..=MAX_SPECTRA).contains(&self.spectra),
        )?;
        check(
            "max_order",
            self.max_order,
            "finite, > 0 and <= 1000 (orders of the running speed)",
            |v| v > 0.0 && v <= MAX_ORDER,
        )?;
        Ok(())
    }
}

/// The cascade of spectra of `signal` against speed (see the module doc).
///
/// - `t`: sample times \[s\], strictly increasing and uniform (every step within 1 % of
///   the median step; a non-uniform record is not supported and is refused);
/// - `omega`: the shaft speed at each sample \[rad/s\] (from the keyphasor);
/// - `signal`: the probe's displacement \[m\];
///
/// all of one length. Returns one spectrum per block, lines from 0 Hz up to `max_order`
/// times the highest block speed, zero-to-peak amplitudes in m.
///
/// # Errors
///
/// [`TransientError::OutOfRange`] for a setting out of range, `LengthMismatch`,
/// `NonFinite`, `NonUniformSampling`, and `TooFew` for a record of fewer than
/// [`MIN_LINES`] samples.
pub fn cascade(
    t: &[f64],
    omega: &[f64],
    signal: &[f64],
    settings: &CascadeSettings,
) -> Result<Cascade, TransientError> {
    same_length("signal", signal.len(), "t", t.len())?;
    check_finite("signal", signal)?;
    let plan = Plan::new(t, omega, settings)?;
    Ok(spectra_of(plan, signal))
}

/// The cascade of `plan`'s blocks of `signal`.
fn spectra_of(plan: Plan, signal: &[f64]) -> Cascade {
    let n = plan.n;
    let kmax = plan.kmax.min(n / 2);
    let s1 = 0.5 * n as f64; // sum of the window: the coherent gain times N
    let mut fft = Fft::new(n);
    let amplitude = plan
        .starts
        .iter()
        .map(|&s| {
            let spec = fft.spectrum(&signal[s..s + n]);
            (0..=kmax)
                .map(|k| {
                    let one_sided = if k == 0 || 2 * k == n { 1.0 } else { 2.0 };
                    one_sided * spec[k].norm() / s1
                })
                .collect()
        })
        .collect();
    Cascade {
        rpm: plan.rpm,
        t: plan.t,
        freq_hz: (0..=kmax).map(|k| k as f64 * plan.df).collect(),
        amplitude,
        lines: n,
        full: false,
    }
}

/// Each probe's cascade, and the pair's full spectrum when asked for, each or its error.
pub type RecordCascades = (
    Vec<Result<Cascade, TransientError>>,
    Option<Result<Cascade, TransientError>>,
);

/// The cascades of one record: [`cascade`] of each of `signals` and, with `pair` (the
/// inverse of an XY pair's projection, the first two signals its probes),
/// [`full_cascade_of_pair`], each with the result (or error) those functions give, but
/// with the blocks planned once for all of them (the sampling's checks over every time
/// step were made three times for a pair).
pub fn record_cascades(
    t: &[f64],
    omega: &[f64],
    signals: &[&[f64]],
    pair: Option<Result<nalgebra::Matrix2<f64>, TransientError>>,
    settings: &CascadeSettings,
) -> RecordCascades {
    let mut plan = None;
    let mut plan = || -> Result<Plan, TransientError> {
        plan.get_or_insert_with(|| Plan::new(t, omega, settings))
            .clone()
    };
    let probes = signals
        .iter()
        .map(|signal| {
            same_length("signal", signal.len(), "t", t.len())?;
            check_finite("signal", signal)?;
            Ok(spectra_of(plan()?, signal))
        })
        .collect();
    let full = match (pair, signals) {
        (Some(inv), [d1, d2, ..]) => Some(inv.and_then(|inv| {
            same_length("probe 1", d1.len(), "t", t.len())?;
            same_length("probe 2", d2.len(), "t", t.len())?;
            check_finite("probe 1", d1)?;
            check_finite("probe 2", d2)?;
            Ok(full_spectra(plan()?, pair_block(d1, d2, &inv)))
        })),
        _ => None,
    };
    (probes, full)
}

/// The x and z of the block of `n` samples from `s` of an XY pair's displacements `d1`,
/// `d2` through the inverse of their projection `inv`.
fn pair_block<'a>(
    d1: &'a [f64],
    d2: &'a [f64],
    inv: &'a nalgebra::Matrix2<f64>,
) -> impl FnMut(usize, usize) -> (Vec<f64>, Vec<f64>) + 'a {
    move |s, n| {
        d1[s..s + n]
            .iter()
            .zip(&d2[s..s + n])
            .map(|(&a, &b)| {
                let q = inv * nalgebra::Vector2::new(a, b);
                (q[0], q[1])
            })
            .unzip()
    }
}

/// The full spectra of the probe pair `x` (horizontal) and `z` (vertical, up) \[m\]
/// against speed: frequencies from -f_max to +f_max, positive = forward whirl (in the
/// direction of rotation, +z towards +x), negative = backward; each line's amplitude is
/// the radius of that circular component \[m\] (see the module doc). `t` and `omega` as
/// for [`cascade`]. The lines stop one short of the Nyquist frequency, where forward and
/// backward cannot be told apart.
///
/// # Errors
///
/// As [`cascade`].
pub fn full_cascade(
    t: &[f64],
    omega: &[f64],
    x: &[f64],
    z: &[f64],
    settings: &CascadeSettings,
) -> Result<Cascade, TransientError> {
    same_length("x", x.len(), "t", t.len())?;
    same_length("z", z.len(), "t", t.len())?;
    check_finite("x", x)?;
    check_finite("z", z)?;
    let plan = Plan::new(t, omega, settings)?;
    Ok(full_spectra(plan, |s, n| {
        (x[s..s + n].to_vec(), z[s..s + n].to_vec())
    }))
}

/// [`full_cascade`] of the x and z of an XY probe pair, from the displacements `d1`, `d2`
/// \[m\] of its two probes and the inverse of their projection `inv`
/// (`acquisition::probes::inverse_projection`): (x, z) = inv (d1, d2) at each sample of
/// the blocks, computed block by block instead of for the whole record first (the same
/// values: the same product at each sample).
///
/// # Errors
///
/// As [`cascade`] (`probe 1`, `probe 2` for the displacements).
pub fn full_cascade_of_pair(
    t: &[f64],
    omega: &[f64],
    d1: &[f64],
    d2: &[f64],
    inv: &nalgebra::Matrix2<f64>,
    settings: &CascadeSettings,
) -> Result<Cascade, TransientError> {
    same_length("probe 1", d1.len(), "t", t.len())?;
    same_length("probe 2", d2.len(), "t", t.len())?;
    check_finite("probe 1", d1)?;
    check_finite("probe 2", d2)?;
    let plan = Plan::new(t, omega, settings)?;
    Ok(full_spectra(plan, pair_block(d1, d2, inv)))
}

/// The full spectra of the blocks of `plan`, `block(start, n)` giving the x and z of the
/// block of `n` samples from `start`.
fn full_spectra(
    plan: Plan,
    mut block: impl FnMut(usize, usize) -> (Vec<f64>, Vec<f64>),
) -> Cascade {
    let n = plan.n;
    let kmax = plan.kmax.min(n / 2 - 1);
    let s1 = 0.5 * n as f64;
    let mut fft = Fft::new(n);
    let i = Complex::new(0.0, 1.0);
    let amplitude = plan
        .starts
        .iter()
        .map(|&s| {
            let (x, z) = block(s, n);
            let zs = fft.spectrum(&z).to_vec();
            let xs = fft.spectrum(&x);
            // P = DFT(z + i x): P[k] = Z[k] + i X[k], P[-k] = conj(Z[k]) + i conj(X[k]).
            let backward = (1..=kmax)
                .rev()
                .map(|k| (zs[k].conj() + i * xs[k].conj()).norm() / s1);
            let forward = (0..=kmax).map(|k| (zs[k] + i * xs[k]).norm() / s1);
            backward.chain(forward).collect()
        })
        .collect();
    let kmax = kmax as i64;
    Cascade {
        rpm: plan.rpm,
        t: plan.t,
        freq_hz: (-kmax..=kmax).map(|k| k as f64 * plan.df).collect(),
        amplitude,
        lines: n,
        full: true,
    }
}

/// Where the blocks go and what they are tagged with.
#[derive(Clone)]
struct Plan {
    /// Block length \[samples\].
    n: usize,
    /// Line spacing \[Hz\].
    df: f64,
    /// The highest line wanted (before the Nyquist cap).
    kmax: usize,
    /// First sample of each block.
    starts: Vec<usize>,
    /// Mean speed per block \[rpm\].
    rpm: Vec<f64>,
    /// Centre time per block \[s\].
    t: Vec<f64>,
}

impl Plan {
    fn new(t: &[f64], omega: &[f64], settings: &CascadeSettings) -> Result<Self, TransientError> {
        settings.validate()?;
        same_length("omega", omega.len(), "t", t.len())?;
        check_finite("t", t)?;
        check_finite("omega", omega)?;
        let len = t.len();
        if len < MIN_LINES {
            return Err(TransientError::TooFew {
                what: format!(
                    "samples in the record (a spectrum needs a block of at least {MIN_LINES})"
                ),
                found: len,
                needed: MIN_LINES,
            });
        }
        let dt = uniform_step("t", t)?;
        let mut n = settings.lines;
        while n > len {
            n /= 2;
        }
        let count = settings.spectra.min(len - n + 1);
        let starts: Vec<usize> = if count == 1 {
            vec![(len - n) / 2]
        } else {
            (0..count)
                .map(|j| ((j * (len - n)) as f64 / (count - 1) as f64).round() as usize)
                .collect()
        };
        let rpm: Vec<f64> = starts
            .iter()
            .map(|&s| rad_per_s_to_rpm(omega[s..s + n].iter().sum::<f64>() / n as f64))
            .collect();
        let tc = starts
            .iter()
            .map(|&s| 0.5 * (t[s] + t[s + n - 1]))
            .collect();
        let df = 1.0 / (n as f64 * dt);
        let top_hz = rpm.iter().fold(0.0f64, |m, r| m.max(r.abs())) / 60.0;
        let kmax = if top_hz > 0.0 {
            ((settings.max_order * top_hz / df).ceil() as usize).clamp(1, n / 2)
        } else {
            n / 2
        };
        Ok(Self {
            n,
            df,
            kmax,
            starts,
            rpm,
            t: tc,
        })
    }
}

/// The median step of `t` \[s\], when every step is within [`MAX_DT_DEVIATION`] of it.
fn uniform_step(field: &'static str, t: &[f64]) -> Result<f64, TransientError> {
    let median = median_step(t);
    let bad = t
        .windows(2)
        .map(|w| w[1] - w[0])
        .position(|d| !(median > 0.0 && (d - median).abs() <= MAX_DT_DEVIATION * median));
    match bad {
        None => Ok(median),
        Some(i) => Err(TransientError::NonUniformSampling {
            field,
            index: i + 1,
            dt: t[i + 1] - t[i],
            median_dt: median,
            tolerance_pct: 100.0 * MAX_DT_DEVIATION,
        }),
    }
}

/// The most distinct steps [`median_step`] counts before it sorts a copy instead.
const MAX_DISTINCT_STEPS: usize = 256;

/// The median of the steps of `t` (at least two samples): the step at index `len / 2` of
/// the steps sorted, as `select_nth_unstable` gives it. A uniform grid's steps take a
/// handful of values a rounding apart, so they are counted per distinct value (no copy of
/// the record: 2 x 8 bytes a sample less at the peak, and no selection over millions of
/// steps); with more than [`MAX_DISTINCT_STEPS`] distinct values the steps are copied and
/// selected.
fn median_step(t: &[f64]) -> f64 {
    let steps = || t.windows(2).map(|w| w[1] - w[0]);
    let mid = (t.len() - 1) / 2;
    // (step, count), sorted by total_cmp (equal exactly when the bits are)
    let mut counts: Vec<(f64, usize)> = Vec::new();
    let mut last = 0usize;
    for d in steps() {
        if counts.get(last).is_some_and(|c| c.0.total_cmp(&d).is_eq()) {
            counts[last].1 += 1;
            continue;
        }
        match counts.binary_search_by(|c| c.0.total_cmp(&d)) {
            Ok(i) => {
                counts[i].1 += 1;
                last = i;
            }
            Err(_) if counts.len() == MAX_DISTINCT_STEPS => {
                let mut sorted: Vec<f64> = steps().collect();
                return *sorted.select_nth_unstable_by(mid, f64::total_cmp).1;
            }
            Err(i) => {
                counts.insert(i, (d, 1));
                last = i;
            }
        }
    }
    let mut seen = 0;
    for &(d, c) in &counts {
        seen += c;
        if seen > mid {
            return d;
        }
    }
    // fewer than two samples: no step (the callers hold at least MIN_LINES)
    f64::NAN
}

/// A planned real FFT of one block length with the Hann window and scratch buffers.
struct Fft {
    plan: std::sync::Arc<dyn realfft::RealToComplex<f64>>,
    window: Vec<f64>,
    input: Vec<f64>,
    output: Vec<Complex<f64>>,
    scratch: Vec<Complex<f64>>,
}

impl Fft {
    fn new(n: usize) -> Self {
        let plan = RealFftPlanner::<f64>::new().plan_fft_forward(n);
        let window = (0..n)
            .map(|i| 0.5 * (1.0 - (std::f64::consts::TAU * i as f64 / n as f64).cos()))
            .collect();
        Self {
            input: plan.make_input_vec(),
            output: plan.make_output_vec(),
            scratch: plan.make_scratch_vec(),
            window,
            plan,
        }
    }

    /// The DFT (lines 0 to n/2) of `block` with its window-weighted mean removed,
    /// Hann-windowed. Removing the plain mean would leave the mean of a non-whole number
    /// of cycles as a spurious 0 Hz line (A / (2 pi cycles)); the weighted mean makes line
    /// 0 exactly zero and leaves a sinusoid's leakage there as the window gives it.
    fn spectrum(&mut self, block: &[f64]) -> &[Complex<f64>] {
        let mean = block
            .iter()
            .zip(&self.window)
            .map(|(v, w)| v * w)
            .sum::<f64>()
            / self.window.iter().sum::<f64>();
        for ((o, &v), &w) in self.input.iter_mut().zip(block).zip(&self.window) {
            *o = (v - mean) * w;
        }
        self.plan
            .process_with_scratch(&mut self.input, &mut self.output, &mut self.scratch)
            .expect("buffers made by the plan have its lengths");
        &self.output
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_distr::{Distribution, Normal};
    use std::f64::consts::{PI, TAU};

    /// A run-up at 10 kHz: omega from `w0` rising by `accel` rad/s^2, for `secs` s;
    /// returns (t, omega, phi).
    fn run_up(w0: f64, accel: f64, secs: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
        let dt = 1e-4;
        let n = (secs / dt).round() as usize;
        let t: Vec<f64> = (0..n).map(|i| i as f64 * dt).collect();
        let omega = t.iter().map(|&t| w0 + accel * t).collect();
        let phi = t.iter().map(|&t| w0 * t + 0.5 * accel * t * t).collect();
        (t, omega, phi)
    }

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    #[test]
    fn orders_of_a_run_up_show_their_amplitudes_at_their_frequencies() {
        // 150 -> 350 rad/s at 10 rad/s^2; 1X of 20 um, 2X of 7 um
        let (t, omega, phi) = run_up(150.0, 10.0, 20.0);
        let (a1, a2) = (20e-6, 7e-6);
        let y: Vec<f64> = phi
            .iter()
            .map(|&p| a1 * (p + 0.3).cos() + a2 * (2.0 * p + 1.1).cos() + 3e-6)
            .collect();
        let settings = CascadeSettings {
            lines: 2048,
            spectra: 40,
            max_order: 4.0,
        };
        let c = cascade(&t, &omega, &y, &settings).unwrap();
        assert_eq!(c.amplitude.len(), 40);
        assert!(!c.full && c.lines == 2048);
        let df = c.df();
        assert!(rel(df, 1e4 / 2048.0) < 1e-9, "df = {df}");
        let top = c.rpm.iter().cloned().fold(0.0, f64::max);
        // the axis covers 4 x the highest speed, to the next line
        let f_end = *c.freq_hz.last().unwrap();
        assert!(f_end >= 4.0 * top / 60.0 && f_end < 4.0 * top / 60.0 + df);
        let mut worst = (0.0f64, 0.0f64);
        for s in 0..c.rpm.len() {
            // speed: the mean of a linear ramp over the block is its value at the centre
            let expect_rpm = rad_per_s_to_rpm(150.0 + 10.0 * c.t[s]);
            assert!(
                rel(c.rpm[s], expect_rpm) < 1e-6,
                "{} {}",
                c.rpm[s],
                expect_rpm
            );
            // the offset of 3 um and the mean of the part-cycles are gone: 0 Hz is zero
            assert!(c.amplitude[s][0] < 1e-12 * a1, "{s}: {}", c.amplitude[s][0]);
            for (order, amp) in [(1.0, a1), (2.0, a2)] {
                let f = order * c.rpm[s] / 60.0;
                let p = c.order_peak(s, order).unwrap();
                worst.0 = worst.0.max(rel(p.amplitude, amp));
                worst.1 = worst.1.max((p.freq_hz - f).abs() / df);
                assert!(
                    rel(p.amplitude, amp) < 0.01,
                    "spectrum {s} order {order}: {p:?}"
                );
                assert!(
                    (p.freq_hz - f).abs() < 0.05 * df,
                    "{s} {order}: {p:?} f = {f}"
                );
                // the raw line: one of the two nearest f (either when f is half-way),
                // between the Hann scalloping bound sinc(1/2) / (1 - 1/4) = 0.8488 and 1
                // times the amplitude
                assert!(
                    (c.freq_hz[p.line] - f).abs() < 0.6 * df,
                    "{s}: {p:?} f = {f}"
                );
                let raw = c.amplitude[s][p.line];
                assert!(raw > 0.8488 * amp * 0.99 && raw < amp * 1.01, "{s}: {raw}");
            }
        }
        eprintln!(
            "run-up orders: worst amplitude error {:.2e}, frequency {:.3} lines",
            worst.0, worst.1
        );
    }

    #[test]
    fn a_sinusoid_on_a_line_shows_its_amplitude_there() {
        // 64 lines x 10 kHz / 4096 = 156.25 Hz, constant speed
        let n = 8192;
        let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-4).collect();
        let f = 64.0 * 1e4 / 4096.0;
        let omega = vec![TAU * f; n];
        let y: Vec<f64> = t
            .iter()
            .map(|&t| 5e-6 * (TAU * f * t + 0.7).sin())
            .collect();
        let c = cascade(&t, &omega, &y, &CascadeSettings::default()).unwrap();
        for a in &c.amplitude {
            assert!(rel(a[64], 5e-6) < 1e-9, "{}", a[64]);
            assert!(rel(a[63], 2.5e-6) < 1e-9 && rel(a[65], 2.5e-6) < 1e-9);
            assert!(a[62] < 1e-15 && a[66] < 1e-15);
        }
        assert!(rel(c.rpm[0], 60.0 * f) < 1e-12);
    }

    /// Orbit (x, z) of semi-axes `a` along the direction at `tilt` from +z towards +x
    /// and `b` across it, traced at angle `theta` (forward when theta grows).
    fn ellipse(a: f64, b: f64, tilt: f64, theta: f64) -> (f64, f64) {
        let (u, v) = (a * theta.cos(), b * theta.sin());
        // u along (sin tilt, cos tilt), v along (cos tilt, -sin tilt) rotated +90 deg
        // from u in the +z -> +x sense
        let x = u * tilt.sin() + v * tilt.cos();
        let z = u * tilt.cos() - v * tilt.sin();
        (x, z)
    }

    fn full_of(a: f64, b: f64, tilt: f64, sense: f64) -> Cascade {
        let (t, omega, phi) = run_up(150.0, 10.0, 10.0);
        let (x, z): (Vec<f64>, Vec<f64>) = phi
            .iter()
            .map(|&p| ellipse(a, b, tilt, sense * p + 0.4))
            .unzip();
        let settings = CascadeSettings {
            lines: 2048,
            spectra: 20,
            max_order: 3.0,
        };
        full_cascade(&t, &omega, &x, &z, &settings).unwrap()
    }

    fn check_full(c: &Cascade, forward: f64, backward: f64) {
        assert!(c.full);
        let df = c.df();
        let n = c.freq_hz.len();
        assert_eq!(n % 2, 1);
        assert_eq!(c.freq_hz[n / 2], 0.0);
        assert!(rel(c.freq_hz[0], -c.freq_hz[n - 1]) < 1e-12);
        let mut worst = 0.0f64;
        for s in 0..c.rpm.len() {
            let f = c.rpm[s] / 60.0;
            let fw = c.order_peak(s, 1.0).unwrap();
            let bw = c.order_peak(s, -1.0).unwrap();
            worst = worst.max(rel(fw.amplitude, forward));
            if backward > 0.0 {
                worst = worst.max(rel(bw.amplitude, backward));
            }
            assert!(rel(fw.amplitude, forward) < 0.01, "{s} forward {fw:?}");
            assert!((fw.freq_hz - f).abs() < 0.05 * df);
            if backward > 0.0 {
                assert!(rel(bw.amplitude, backward) < 0.01, "{s} backward {bw:?}");
                assert!((bw.freq_hz + f).abs() < 0.05 * df);
            } else {
                assert!(bw.amplitude < 0.01 * forward, "{s} backward {bw:?}");
            }
        }
        eprintln!("full spectrum {forward:e} / {backward:e}: worst amplitude error {worst:.2e}");
    }

    #[test]
    fn a_forward_circle_is_a_positive_line_only() {
        // (x, z) = r (sin phi, cos phi): the sense of rotation
        let c = full_of(10e-6, 10e-6, 0.0, 1.0);
        check_full(&c, 10e-6, 0.0);
    }

    #[test]
    fn a_backward_circle_is_a_negative_line_only() {
        let c = full_of(10e-6, 10e-6, 0.0, -1.0);
        let (mut err, mut leak) = (0.0f64, 0.0f64);
        for s in 0..c.rpm.len() {
            let bw = c.order_peak(s, -1.0).unwrap();
            let fw = c.order_peak(s, 1.0).unwrap();
            assert!(rel(bw.amplitude, 10e-6) < 0.01, "{bw:?}");
            assert!(fw.amplitude < 0.01 * 10e-6, "{fw:?}");
            err = err.max(rel(bw.amplitude, 10e-6));
            leak = leak.max(fw.amplitude / 10e-6);
        }
        eprintln!("backward circle: worst amplitude error {err:.2e}, forward leak {leak:.2e} of r");
    }

    #[test]
    fn an_ellipse_splits_into_half_sum_forward_and_half_difference_backward() {
        for tilt in [0.0, 0.6, PI / 2.0] {
            let c = full_of(12e-6, 4e-6, tilt, 1.0);
            check_full(&c, 8e-6, 4e-6);
        }
        // a straight line (b = 0): half its length each way
        check_full(&full_of(6e-6, 0.0, 1.0, 1.0), 3e-6, 3e-6);
    }

    #[test]
    fn noise_alone_stays_under_its_derived_bound() {
        // White noise sigma: with the Hann window (sum w = N/2, sum w^2 = 3N/8) a line's
        // amplitude a = 2 |X| / (N/2) has a^2 exponential of mean 4 sigma^2 (3N/8) /
        // (N/2)^2 = 6 sigma^2 / N, so P(a > b) = exp(-b^2 N / (6 sigma^2)); for M lines
        // in all, b = sigma sqrt(6 ln(M / p) / N) is exceeded anywhere with probability p.
        let sigma = 2e-6;
        let n = 40_000;
        let t: Vec<f64> = (0..n).map(|i| i as f64 * 1e-4).collect();
        let omega: Vec<f64> = t.iter().map(|&t| 100.0 + 20.0 * t).collect();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let normal = Normal::new(0.0, sigma).unwrap();
        let y: Vec<f64> = (0..n).map(|_| normal.sample(&mut rng)).collect();
        let settings = CascadeSettings {
            lines: 4096,
            spectra: 30,
            max_order: 50.0,
        };
        let c = cascade(&t, &omega, &y, &settings).unwrap();
        // skip DC and its neighbour (the mean removal) and the Nyquist line (one-sided)
        let lines: Vec<f64> = c
            .amplitude
            .iter()
            .flat_map(|a| a[2..a.len() - 1].iter().copied())
            .collect();
        let m = lines.len() as f64;
        let bound = sigma * (6.0 * (m / 1e-3).ln() / 4096.0).sqrt();
        let top = lines.iter().cloned().fold(0.0, f64::max);
        assert!(top < bound, "largest noise line {top:e} above {bound:e}");
        // and the floor itself: mean square 6 sigma^2 / N (blocks overlap, so the lines
        // are not all independent: 5 % is many standard errors of ~M/2 effective lines)
        let ms = lines.iter().map(|a| a * a).sum::<f64>() / m;
        let expect = 6.0 * sigma * sigma / 4096.0;
        assert!(
            rel(ms, expect) < 0.05,
            "mean square {ms:e}, expected {expect:e}"
        );
        eprintln!(
            "noise: top line {top:e} < bound {bound:e}; mean square {:.4} of 6 sigma^2/N",
            ms / expect
        );
    }

    #[test]
    fn short_records_use_shorter_blocks_and_too_short_ones_are_refused() {
        let t: Vec<f64> = (0..1000).map(|i| i as f64 * 1e-3).collect();
        let w = vec![100.0; 1000];
        let y: Vec<f64> = t.iter().map(|&t| (TAU * 50.0 * t).sin()).collect();
        let c = cascade(&t, &w, &y, &CascadeSettings::default()).unwrap();
        assert_eq!(c.lines, 512);
        let e = cascade(&t[..255], &w[..255], &y[..255], &CascadeSettings::default());
        assert!(
            matches!(
                e,
                Err(TransientError::TooFew {
                    found: 255,
                    needed: 256,
                    ..
                })
            ),
            "{e:?}"
        );
    }

    #[test]
    fn bad_settings_are_refused_by_name() {
        let ok = CascadeSettings::default();
        assert!(ok.validate().is_ok());
        let cases = [
            (CascadeSettings { lines: 3000, ..ok }, "lines", 3000.0),
            (CascadeSettings { lines: 128, ..ok }, "lines", 128.0),
            (
                CascadeSettings {
                    lines: 1 << 21,
                    ..ok
                },
                "lines",
                (1 << 21) as f64,
            ),
            (CascadeSettings { spectra: 0, ..ok }, "spectra", 0.0),
            (
                CascadeSettings {
                    spectra: 10_001,
                    ..ok
                },
                "spectra",
                10_001.0,
            ),
            (
                CascadeSettings {
                    max_order: 0.0,
                    ..ok
                },
                "max_order",
                0.0,
            ),
            (
                CascadeSettings {
                    max_order: 1e4,
                    ..ok
                },
                "max_order",
                1e4,
            ),
        ];
        for (s, field, value) in cases {
            match s.validate() {
                Err(TransientError::OutOfRange(e)) => {
                    assert_eq!((e.field, e.value), (field, value));
                    assert!(e.to_string().starts_with(&format!("{field} = ")), "{e}");
                }
                other => panic!("{s:?}: {other:?}"),
            }
        }
        let nan = CascadeSettings {
            max_order: f64::NAN,
            ..ok
        };
        assert!(
            matches!(nan.validate(), Err(TransientError::OutOfRange(e)) if e.field == "max_order")
        );
        // and cascade() checks them too
        let t: Vec<f64> = (0..1000).map(|i| i as f64 * 1e-3).collect();
        let e = cascade(&t, &t, &t, &CascadeSettings { spectra: 0, ..ok }).unwrap_err();
        assert!(e.to_string().contains("spectra = 0"), "{e}");
    }

    #[test]
    fn bad_records_are_refused_with_the_offending_values() {
        let mut t: Vec<f64> = (0..1000).map(|i| i as f64 * 1e-3).collect();
        let w = vec![100.0; 1000];
        let y = vec![0.0; 1000];
        let s = CascadeSettings::default();
        let e = cascade(&t, &w[..999], &y, &s).unwrap_err();
        assert!(
            matches!(
                e,
                TransientError::LengthMismatch {
                    field: "omega",
                    len: 999,
                    ..
                }
            ),
            "{e:?}"
        );
        let e = full_cascade(&t, &w, &y, &y[..10], &s).unwrap_err();
        assert!(
            matches!(
                e,
                TransientError::LengthMismatch {
                    field: "z",
                    len: 10,
                    ..
                }
            ),
            "{e:?}"
        );
        let mut bad = y.clone();
        bad[5] = f64::NAN;
        let e = cascade(&t, &w, &bad, &s).unwrap_err();
        assert!(
            matches!(
                e,
                TransientError::NonFinite {
                    field: "signal",
                    index: 5,
                    ..
                }
            ),
            "{e:?}"
        );
        // a 2 % longer step at sample 400
        for v in &mut t[400..] {
            *v += 2e-5;
        }
        let e = cascade(&t, &w, &y, &s).unwrap_err();
        match &e {
            TransientError::NonUniformSampling {
                field: "t",
                index: 400,
                dt,
                median_dt,
                ..
            } => {
                assert!(rel(*dt, 1.02e-3) < 1e-9 && rel(*median_dt, 1e-3) < 1e-9)
            }
            other => panic!("{other:?}"),
        }
        assert!(e.to_string().contains("uniform sampling"), "{e}");
        // times that go back
        let mut back: Vec<f64> = (0..1000).map(|i| i as f64 * 1e-3).collect();
        back.swap(10, 11);
        let e = cascade(&back, &w, &y, &s).unwrap_err();
        assert!(
            matches!(e, TransientError::NonUniformSampling { index: 10, .. }),
            "{e:?}"
        );
        // a 0.5 % jitter is accepted
        let jitter: Vec<f64> = (0..1000)
            .map(|i| i as f64 * 1e-3 + if i % 2 == 0 { 2e-6 } else { 0.0 })
            .collect();
        assert!(cascade(&jitter, &w, &y, &s).is_ok());
    }

    #[test]
    fn median_step_counted_is_the_selected_one() {
        // the selection over a copy is the reference: grids with a few distinct steps
        // (rounded stamps, one binade and several), and jittered stamps with thousands
        let select = |t: &[f64]| {
            let mut s: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
            let mid = s.len() / 2;
            *s.select_nth_unstable_by(mid, f64::total_cmp).1
        };
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let jitter = Normal::new(0.0, 1e-7).unwrap();
        let grids: Vec<Vec<f64>> = vec![
            (0..1000).map(|i| i as f64 / 25_600.0).collect(),
            (0..100_001)
                .map(|i| 100.0 + i as f64 * 3.90625e-5)
                .collect(),
            (0..2001).map(|i| i as f64 * 1e-4).collect(),
            (0..2000)
                .map(|i| i as f64 * 1e-4 + jitter.sample(&mut rng))
                .collect(),
            vec![0.0, 1.0],
            vec![0.0, 1.0, 3.0],
            vec![0.0, 2.0, 3.0, 5.0],
        ];
        for t in &grids {
            assert_eq!(median_step(t).to_bits(), select(t).to_bits(), "{}", t.len());
        }
    }
}
