//! The standard deviation of white measurement noise, estimated from the data's fourth
//! differences (von Neumann's idea, 1941, at a higher difference order):
//!
//! ```text
//! d_k = y_k - 4 y_(k+1) + 6 y_(k+2) - 4 y_(k+3) + y_(k+4),
//! E[d_k^2] = 70 sigma^2 + (signal part),       sigma_hat^2 = sum_k d_k^2 / (70 K)
//! ```
//!
//! (70 = 1 + 16 + 36 + 16 + 1). The fourth difference multiplies a sinusoid of frequency w
//! by (2 sin(w h / 2))^4 ~ (w h)^4, so for a signal well resolved by the sampling (w h
//! small) the signal part is negligible: at table1's natural frequency (289 rad/s) and
//! h = 0.1 ms, (w h)^8 / 70 ~ 1e-14 of the signal power (the noise floor of a 140 dB SNR).
//! Coloured (non-white) noise is not what this measures: it sees only the noise's
//! high-frequency part.

/// Running fourth-difference estimate of sigma for one channel.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub(crate) struct DifferenceNoise {
    /// The last four samples, oldest first.
    last: [f64; 4],
    /// Samples seen.
    seen: u64,
    /// Sum of d_k^2.
    sum: f64,
}

/// sum of the squared fourth-difference coefficients (1, -4, 6, -4, 1).
const GAIN: f64 = 70.0;

impl DifferenceNoise {
    /// Take the next sample.
    #[inline]
    pub(crate) fn push(&mut self, y: f64) {
        if self.seen >= 4 {
            let [a, b, c, d] = self.last;
            let diff = a - 4.0 * b + 6.0 * c - 4.0 * d + y;
            self.sum += diff * diff;
        }
        self.last = [self.last[1], self.last[2], self.last[3], y];
        self.seen += 1;
    }

    /// sigma_hat \[unit of the samples\]; NaN before five samples.
    pub(crate) fn sigma(&self) -> f64 {
        if self.seen < 5 {
            return f64::NAN;
        }
        (self.sum / (GAIN * (self.seen - 4) as f64)).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cubic_signals_are_invisible_and_white_noise_is_measured() {
        let mut d = DifferenceNoise::default();
        for k in 0..100 {
            let t = k as f64 * 0.01;
            d.push(3.0 - 2.0 * t + t * t - 0.5 * t * t * t);
        }
        assert!(d.sigma() < 1e-12, "{}", d.sigma());
        assert!(DifferenceNoise::default().sigma().is_nan());

        // white Gaussian noise of sigma 0.3 on a slow sinusoid: 1e5 samples estimate sigma
        // to ~0.4 % (the relative sd of a mean of squares of correlated differences)
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let mut d = DifferenceNoise::default();
        for k in 0..100_000 {
            let n: f64 = rng.sample(rand_distr::StandardNormal);
            d.push(5.0 * (k as f64 * 0.01).sin() + 0.3 * n);
        }
        assert!((d.sigma() / 0.3 - 1.0).abs() < 0.015, "{}", d.sigma());
    }
}
