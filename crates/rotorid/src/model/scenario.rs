//! A scenario: a rotor, its speed profile, the initial state and the sampling grid.
//! Sample i is at t_i = i * dt (computed exactly so, never by accumulation).

use serde::Serialize;

use super::error::{check, ModelError};
use super::rotor::Rotor;
use super::speed::SpeedProfile;

/// The most samples a scenario may ask for (1e9), to fail fast instead of exhausting memory.
pub const MAX_SAMPLES: f64 = 1.0e9;

/// Uniform sampling: period `dt` \[s\] over `duration` \[s\].
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Sampling {
    dt: f64,
    duration: f64,
}

impl Sampling {
    /// `dt` finite and > 0, `duration` finite and >= dt, at most `MAX_SAMPLES` (1e9) samples.
    pub fn new(dt: f64, duration: f64) -> Result<Self, ModelError> {
        check("dt", dt, "finite and > 0 (s)", |v| v > 0.0)?;
        check("duration", duration, "finite and > 0 (s)", |v| v > 0.0)?;
        if duration < dt {
            return Err(ModelError::Inconsistent(format!(
                "duration = {duration} s is shorter than one sampling period dt = {dt} s"
            )));
        }
        if duration / dt > MAX_SAMPLES {
            return Err(ModelError::Inconsistent(format!(
                "duration / dt = {} samples exceeds the limit of {MAX_SAMPLES:e}",
                duration / dt
            )));
        }
        Ok(Self { dt, duration })
    }
    /// Sampling period \[s\].
    pub fn dt(&self) -> f64 {
        self.dt
    }
    /// Record length \[s\].
    pub fn duration(&self) -> f64 {
        self.duration
    }
    /// Number of steps N = floor(duration / dt) (with a relative slack of 1e-9 so that
    /// 1.0 / 1e-4 gives 10000); samples are t_0 = 0 ... t_N = N dt, N + 1 in all.
    pub fn steps(&self) -> usize {
        (self.duration / self.dt * (1.0 + 1e-9)).floor() as usize
    }
    /// Number of samples, `steps() + 1`.
    pub fn samples(&self) -> usize {
        self.steps() + 1
    }
    /// Time of sample `i` \[s\]: exactly `i as f64 * dt`.
    #[inline]
    pub fn time(&self, i: usize) -> f64 {
        i as f64 * self.dt
    }
}

/// Initial displacement \[m\] and velocity \[m/s\] of the disk.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, serde::Deserialize)]
pub struct InitialState {
    /// x(0) \[m\].
    pub x: f64,
    /// z(0) \[m\].
    pub z: f64,
    /// x'(0) \[m/s\].
    pub vx: f64,
    /// z'(0) \[m/s\].
    pub vz: f64,
}

impl InitialState {
    /// Every component finite.
    pub fn validated(self) -> Result<Self, ModelError> {
        check("x0", self.x, "finite (m)", |_| true)?;
        check("z0", self.z, "finite (m)", |_| true)?;
        check("vx0", self.vx, "finite (m/s)", |_| true)?;
        check("vz0", self.vz, "finite (m/s)", |_| true)?;
        Ok(self)
    }
}

/// Everything needed to simulate (and, for identification, the known quantities).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Scenario {
    /// The rotor (its m, c, k are the truth when identifying).
    pub rotor: Rotor,
    /// The speed profile.
    pub speed: SpeedProfile,
    /// The sampling grid.
    pub sampling: Sampling,
    /// Initial displacement and velocity (zero in the paper).
    pub initial: InitialState,
}

impl Scenario {
    /// The paper's Table 1 rotor at a constant 1200 rpm, phi(0) = 0, dt = 0.1 ms, 1 s,
    /// starting at rest.
    pub fn table1() -> Self {
        Self {
            rotor: Rotor::table1(),
            speed: SpeedProfile::constant_rpm(1200.0, 0.0).expect("valid"),
            sampling: Sampling::new(1.0e-4, 1.0).expect("valid"),
            initial: InitialState::default(),
        }
    }

    /// Table 1 on the paper's 10 rad/s^2 ramp starting at `rpm0` (0 for the paper's
    /// unstated start; 600 and 1200 rpm are useful variants), phi(0) = 0.
    pub fn table1_ramp(rpm0: f64) -> Result<Self, ModelError> {
        Ok(Self {
            speed: SpeedProfile::ramp(rpm0, 10.0, 0.0)?,
            ..Self::table1()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_second_at_a_tenth_of_a_millisecond_is_10001_samples() {
        let s = Sampling::new(1e-4, 1.0).unwrap();
        assert_eq!(s.steps(), 10_000);
        assert_eq!(s.samples(), 10_001);
        assert_eq!(s.time(3), 3.0 * 1e-4);
        let s = Sampling::new(1e-4, 0.3).unwrap();
        assert_eq!(s.steps(), 3000);
    }

    #[test]
    fn bad_sampling_is_rejected() {
        assert!(Sampling::new(0.0, 1.0).is_err());
        assert!(Sampling::new(1e-4, f64::NAN).is_err());
        assert!(Sampling::new(1.0, 0.5).is_err());
        assert!(Sampling::new(1e-12, 1e3).is_err());
        let e = InitialState {
            vx: f64::NAN,
            ..Default::default()
        }
        .validated()
        .unwrap_err();
        assert!(e.to_string().starts_with("vx0 = NaN"));
    }
}
