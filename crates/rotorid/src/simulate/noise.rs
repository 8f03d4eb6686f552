//! Additive white Gaussian measurement noise at a given signal-to-noise ratio
//! (docs/method.md section 2.5). Per channel c in {x, z}:
//!
//! ```text
//! sigma_c = RMS(c) * 10^(-SNR/20),   RMS(c) = sqrt( (1/N) sum_i c_i^2 )   (whole record, not std)
//! c_i <- c_i + sigma_c n_i,           n_i ~ N(0, 1) independent
//! ```
//!
//! Reproducibility contract: the generator is `ChaCha8Rng::seed_from_u64(seed)` and the
//! standard normals are drawn with `rand_distr::StandardNormal` (Ziggurat), first all N
//! values for x (in sample order), then all N values for z. The same record, SNR and seed
//! give bit-identical output (for the same rand_chacha / rand_distr versions: a change of
//! their algorithms would change the draws).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

use super::error::SimulateError;
use super::TimeResponse;
use crate::model::check;

/// The standard deviations of the noise that was added.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NoiseLevel {
    /// sigma_x \[m\].
    pub sigma_x: f64,
    /// sigma_z \[m\].
    pub sigma_z: f64,
}

/// RMS of one channel, or an error naming it if it is empty or holds a non-finite value.
fn rms(channel: &'static str, v: &[f64]) -> Result<f64, SimulateError> {
    if v.is_empty() {
        return Err(SimulateError::EmptyChannel { channel });
    }
    if let Some(index) = v.iter().position(|x| !x.is_finite()) {
        return Err(SimulateError::NonFiniteChannel { channel, index });
    }
    // scale by the largest magnitude so that squares of tiny or huge values stay representable
    let big = v.iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if big == 0.0 {
        return Ok(0.0);
    }
    let mean_sq = v.iter().map(|x| (x / big) * (x / big)).sum::<f64>() / v.len() as f64;
    Ok(big * mean_sq.sqrt())
}

/// Add white Gaussian noise to `resp.x` and `resp.z` at `snr_db` \[dB\] (finite; RMS
/// definition, see the module doc), reproducibly from `seed`. Returns the sigmas used.
/// A channel that is identically zero gets no noise (sigma = 0).
pub fn add_noise(
    resp: &mut TimeResponse,
    snr_db: f64,
    seed: u64,
) -> Result<NoiseLevel, SimulateError> {
    let [sigma_x, sigma_z] = add_noise_to(
        &mut [("x", &mut resp.x[..]), ("z", &mut resp.z[..])],
        snr_db,
        seed,
    )?[..] else {
        unreachable!("one sigma per channel")
    };
    Ok(NoiseLevel { sigma_x, sigma_z })
}

/// Add white Gaussian noise to each of `channels` (name for errors, samples) at `snr_db`
/// \[dB\] of that channel's RMS, reproducibly from `seed`: the draws go to the channels
/// in the order given, each channel's in sample order (the module's contract; for x then
/// z it is [`add_noise`]). Returns the sigma of each channel, in its unit.
pub fn add_noise_to(
    channels: &mut [(&'static str, &mut [f64])],
    snr_db: f64,
    seed: u64,
) -> Result<Vec<f64>, SimulateError> {
    check("snr_db", snr_db, "finite (dB)", |_| true)?;
    let ratio = 10f64.powf(-snr_db / 20.0);
    let mut sigmas = Vec::with_capacity(channels.len());
    for (name, c) in channels.iter() {
        let s = rms(name, c)? * ratio;
        let (field, allowed) = match *name {
            "x" => ("sigma_x", "finite (m): snr_db is too low for this signal"),
            "z" => ("sigma_z", "finite (m): snr_db is too low for this signal"),
            _ => ("sigma", "finite: snr_db is too low for this signal"),
        };
        check(field, s, allowed, |_| true)?;
        sigmas.push(s);
    }
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    for ((_, c), &s) in channels.iter_mut().zip(&sigmas) {
        for v in c.iter_mut() {
            let n: f64 = rng.sample(StandardNormal);
            *v += s * n;
        }
    }
    Ok(sigmas)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rms_is_not_the_standard_deviation() {
        // a constant signal has std 0 but RMS = its value
        assert_eq!(rms("x", &[3.0, 3.0, 3.0, 3.0]).unwrap(), 3.0);
        assert!((rms("x", &[3.0, -4.0]).unwrap() - 12.5f64.sqrt()).abs() < 1e-15);
        assert!((rms("x", &[1e-200, 1e-200]).unwrap() - 1e-200).abs() < 1e-214);
        assert_eq!(rms("x", &[0.0, 0.0]).unwrap(), 0.0);
    }
}
