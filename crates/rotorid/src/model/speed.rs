//! Speed profiles: the rotor angle phi(t) \[rad\], speed w = phi' \[rad/s\] and angular
//! acceleration w' = phi'' \[rad/s^2\] at any time t \[s\].
//!
//! ```text
//! constant:  phi = phi0 + W t,                w = W,           w' = 0
//! ramp:      phi = phi0 + w0 t + A t^2 / 2,   w = w0 + A t,    w' = A
//! ```

use serde::{Deserialize, Serialize};

use super::error::{check, ModelError};
use super::rpm_to_rad_per_s;

/// Rotor angle, speed and angular acceleration at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct SpeedState {
    /// Rotor angle phi \[rad\].
    pub phi: f64,
    /// Speed w = phi' \[rad/s\].
    pub omega: f64,
    /// Angular acceleration w' = phi'' \[rad/s^2\].
    pub omega_dot: f64,
}

/// How the rotor speed varies with time.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum SpeedProfile {
    /// Constant speed W \[rad/s\] from angle phi0 \[rad\].
    Constant {
        /// W \[rad/s\].
        omega: f64,
        /// phi(0) \[rad\].
        phi0: f64,
    },
    /// Linear ramp: w(t) = omega0 + accel t, from angle phi0.
    Ramp {
        /// w(0) \[rad/s\].
        omega0: f64,
        /// w' \[rad/s^2\], constant.
        accel: f64,
        /// phi(0) \[rad\].
        phi0: f64,
    },
}

impl SpeedProfile {
    /// Constant speed `rpm` \[rev/min\] (finite, >= 0) from angle `phi0` \[rad\].
    pub fn constant_rpm(rpm: f64, phi0: f64) -> Result<Self, ModelError> {
        check("rpm", rpm, "finite and >= 0 (rev/min)", |v| v >= 0.0)?;
        check("phi0", phi0, "finite (rad)", |_| true)?;
        Ok(Self::Constant {
            omega: rpm_to_rad_per_s(rpm),
            phi0,
        })
    }

    /// Linear ramp from `rpm0` \[rev/min\] (finite, >= 0) with angular acceleration `accel`
    /// \[rad/s^2\] (finite; negative for a run-down) from angle `phi0` \[rad\].
    pub fn ramp(rpm0: f64, accel: f64, phi0: f64) -> Result<Self, ModelError> {
        check("rpm0", rpm0, "finite and >= 0 (rev/min)", |v| v >= 0.0)?;
        check("accel", accel, "finite (rad/s^2)", |_| true)?;
        check("phi0", phi0, "finite (rad)", |_| true)?;
        Ok(Self::Ramp {
            omega0: rpm_to_rad_per_s(rpm0),
            accel,
            phi0,
        })
    }

    /// phi, w, w' at time `t` \[s\].
    #[inline]
    pub fn at(&self, t: f64) -> SpeedState {
        match *self {
            Self::Constant { omega, phi0 } => SpeedState {
                phi: phi0 + omega * t,
                omega,
                omega_dot: 0.0,
            },
            Self::Ramp {
                omega0,
                accel,
                phi0,
            } => SpeedState {
                phi: phi0 + (omega0 + 0.5 * accel * t) * t,
                omega: omega0 + accel * t,
                omega_dot: accel,
            },
        }
    }

    /// True when w' = 0 at all times.
    pub fn is_constant(&self) -> bool {
        match *self {
            Self::Constant { .. } => true,
            Self::Ramp { accel, .. } => accel == 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn constant_1200_rpm_is_40_pi() {
        let p = SpeedProfile::constant_rpm(1200.0, 0.0).unwrap();
        let s = p.at(0.5);
        assert!((s.omega - 40.0 * std::f64::consts::PI).abs() < 1e-12);
        assert!((s.phi - 20.0 * std::f64::consts::PI).abs() < 1e-12);
        assert_eq!(s.omega_dot, 0.0);
    }

    #[test]
    fn ramp_integrates_consistently() {
        let p = SpeedProfile::ramp(600.0, 10.0, 0.3).unwrap();
        let (t, h) = (0.7, 1e-5);
        let (a, b, c) = (p.at(t - h), p.at(t), p.at(t + h));
        assert!(((c.phi - a.phi) / (2.0 * h) - b.omega).abs() < 1e-6);
        assert!(((c.omega - a.omega) / (2.0 * h) - b.omega_dot).abs() < 1e-6);
        assert_eq!(p.at(0.0).phi, 0.3);
    }

    #[test]
    fn bad_speeds_are_rejected_with_their_name() {
        let e = SpeedProfile::constant_rpm(-1.0, 0.0).unwrap_err();
        assert!(e.to_string().starts_with("rpm = -1 is out of range"));
        let e = SpeedProfile::ramp(0.0, f64::NAN, 0.0).unwrap_err();
        assert!(e.to_string().starts_with("accel = NaN"));
    }
}
