//! What the identifier is given: the known quantities of the model
//! (docs/method.md section 3.3: a, m_u d, alpha) and one measurement per sampling instant.

use serde::{Deserialize, Serialize};

use super::error::InputError;
use crate::model::{check, Rotor, SpeedState};

/// The quantities the identifiers take as known (docs/method.md section 3.3).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Known {
    /// Gyroscopic coefficient a \[N s^2/m\], any finite value.
    pub a: f64,
    /// Unbalance m_u d \[kg m\], any finite value (a negative value is the same unbalance
    /// at alpha + pi).
    pub mud: f64,
    /// Angular position of the unbalance alpha \[rad\], finite.
    pub alpha: f64,
}

impl Known {
    /// a, m_u d and alpha of `rotor`.
    pub fn from_rotor(rotor: &Rotor) -> Self {
        let u = rotor.unbalance();
        Self {
            a: rotor.a(),
            mud: u.mud(),
            alpha: u.alpha,
        }
    }

    /// Every field finite.
    pub fn validated(self) -> Result<Self, InputError> {
        check("known.a", self.a, "finite (N s^2/m)", |_| true)?;
        check("known.mud", self.mud, "finite (kg m)", |_| true)?;
        check("known.alpha", self.alpha, "finite (rad)", |_| true)?;
        Ok(self)
    }
}

/// One sample of the measured signals.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
pub struct Measurement {
    /// Time t \[s\]; uniformly spaced by the identifier's dt.
    pub t: f64,
    /// Horizontal displacement x \[m\].
    pub x: f64,
    /// Vertical displacement z \[m\].
    pub z: f64,
    /// Rotor angle phi \[rad\], speed w = phi' \[rad/s\] and acceleration w' = phi'' \[rad/s^2\]
    /// at t (ignored, and not validated, by the constant-speed identifier).
    pub speed: SpeedState,
}
