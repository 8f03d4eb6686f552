//! Are the record's magnitudes those of a proximity-probe measurement? (docs/method.md
//! section 6.4.) Unit slips show as absurd sizes before they show anywhere else:
//! micrometres read as metres make a shaft move tens of metres, metres labelled as
//! micrometres make it move picometres. The checks, per channel:
//!
//! - the peak |x| above [`DISPLACEMENT_MAX_M`] (1 cm: a probe's linear range is about
//!   2 mm) or below [`DISPLACEMENT_MIN_M`] (1 nm: below any probe's resolution);
//! - the white-noise level (fourth differences, independent of any model) above
//!   [`NOISE_TO_SIGNAL_MAX`] of the channel's RMS about its mean: the record is mostly
//!   noise (SNR under ~10 dB), or the channel is not the shaft's displacement.
//!
//! They warn and withhold nothing: a large machine or a quiet one may be genuine.

use crate::identify::modulating::noise_estimate::DifferenceNoise;

use super::diagnostic::{Diagnostic, Direction, Finding};
use super::limits::{DISPLACEMENT_MAX_M, DISPLACEMENT_MIN_M, NOISE_TO_SIGNAL_MAX};

/// Running magnitudes of x and z (module doc).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct Magnitudes {
    peak: [f64; 2],
    sum: [f64; 2],
    sumsq: [f64; 2],
    n: u64,
    noise: [DifferenceNoise; 2],
}

impl Magnitudes {
    /// The next sample's x and z \[m\].
    #[inline]
    pub(crate) fn push(&mut self, x: f64, z: f64) {
        for (i, v) in [x, z].into_iter().enumerate() {
            self.peak[i] = self.peak[i].max(v.abs());
            self.sum[i] += v;
            self.sumsq[i] += v * v;
            self.noise[i].push(v);
        }
        self.n += 1;
    }

    /// Every sample of `x` and `z`.
    pub(crate) fn of(x: &[f64], z: &[f64]) -> Self {
        let mut m = Self::default();
        x.iter().zip(z).for_each(|(&x, &z)| m.push(x, z));
        m
    }

    /// The findings (module doc).
    pub(crate) fn findings(&self) -> Vec<Diagnostic> {
        let mut out = Vec::new();
        if self.n == 0 {
            return out;
        }
        let n = self.n as f64;
        for (i, direction) in [Direction::X, Direction::Z].into_iter().enumerate() {
            let peak = self.peak[i];
            if !(DISPLACEMENT_MIN_M..=DISPLACEMENT_MAX_M).contains(&peak) {
                out.push(Diagnostic::new(Finding::ImplausibleDisplacement {
                    direction,
                    peak_m: peak,
                }));
                continue;
            }
            let mean = self.sum[i] / n;
            let rms = (self.sumsq[i] / n - mean * mean).max(0.0).sqrt();
            let noise = self.noise[i].sigma();
            if noise > NOISE_TO_SIGNAL_MAX * rms {
                out.push(Diagnostic::new(Finding::NoiseDominates {
                    direction,
                    noise_m: noise,
                    rms_m: rms,
                }));
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sine(amplitude: f64, n: usize) -> Vec<f64> {
        (0..n)
            .map(|k| amplitude * (k as f64 * 0.0125).sin())
            .collect()
    }

    #[test]
    fn probe_sized_signals_pass_and_unit_slips_do_not() {
        let um20 = sine(20e-6, 10_000);
        assert!(Magnitudes::of(&um20, &um20).findings().is_empty());
        // 20 um read as metres, and as "um" of metres
        for (scale, big) in [(1e6, true), (1e-6, false)] {
            let x: Vec<f64> = um20.iter().map(|v| v * scale).collect();
            let f = Magnitudes::of(&x, &um20).findings();
            assert_eq!(f.len(), 1, "{f:?}");
            let Finding::ImplausibleDisplacement { direction, peak_m } = f[0].finding else {
                panic!("{f:?}")
            };
            assert_eq!(direction, Direction::X);
            assert!((peak_m / (20e-6 * scale) - 1.0).abs() < 1e-3);
            assert!(f[0].message.contains("um"), "{}", f[0].message);
            assert_eq!(peak_m > DISPLACEMENT_MAX_M, big);
        }
    }

    #[test]
    fn a_channel_of_noise_is_flagged() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
        let signal = sine(20e-6, 10_000);
        // noise at 40 dB passes; noise at the signal's level does not
        for (level, flagged) in [(0.01, false), (1.0, true)] {
            let z: Vec<f64> = signal
                .iter()
                .map(|v| v + level * 20e-6 / 2f64.sqrt() * (rng.gen::<f64>() - 0.5) * 12f64.sqrt())
                .collect();
            let f = Magnitudes::of(&signal, &z).findings();
            assert_eq!(!f.is_empty(), flagged, "{level}: {f:?}");
        }
    }
}
