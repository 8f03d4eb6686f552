//! The identifier's output at one instant: theta = (m, c, k) per direction (docs/method.md
//! section 3.4) and the conditioning of the 3x3 system it came from ([`super::system`]).

use serde::{Deserialize, Serialize};

/// The estimate for one direction (x or z) at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DirectionEstimate {
    /// Mass m \[kg\] (NaN when the system is singular).
    pub m: f64,
    /// Damping c \[N s/m\] (NaN when singular).
    pub c: f64,
    /// Stiffness k \[N/m\] (NaN when singular).
    pub k: f64,
    /// Reciprocal 1-norm condition number of the scaled 3x3 system, in [0, 1]
    /// (0 when singular); see [`super::scaled_solve`] for its exact definition.
    pub rcond: f64,
}

impl DirectionEstimate {
    /// The singular answer: NaN values, rcond = 0.
    pub const SINGULAR: Self = Self {
        m: f64::NAN,
        c: f64::NAN,
        k: f64::NAN,
        rcond: 0.0,
    };

    /// True when the system was solvable with `rcond >= rcond_min` (and so the values are
    /// finite). Instants that fail this are "flagged": their values must not be trusted.
    #[inline]
    pub fn well_conditioned(&self, rcond_min: f64) -> bool {
        self.rcond >= rcond_min && self.rcond > 0.0
    }

    /// (m, c, k) as an array.
    pub fn theta(&self) -> [f64; 3] {
        [self.m, self.c, self.k]
    }
}

/// Both directions' estimates at time t.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct AlgebraicEstimate {
    /// Time of the measurement the estimate is for \[s\].
    pub t: f64,
    /// Horizontal direction: m, cx, kx.
    pub x: DirectionEstimate,
    /// Vertical direction: m, cz, kz.
    pub z: DirectionEstimate,
}

impl AlgebraicEstimate {
    /// [x well conditioned, z well conditioned] at threshold `rcond_min`
    /// (see [`DirectionEstimate::well_conditioned`]).
    pub fn well_conditioned(&self, rcond_min: f64) -> [bool; 2] {
        [
            self.x.well_conditioned(rcond_min),
            self.z.well_conditioned(rcond_min),
        ]
    }

    /// The six values in the order m_x, c_x, k_x, m_z, c_z, k_z
    /// (see [`crate::Parameter::PER_DIRECTION`]).
    pub fn values(&self) -> [f64; 6] {
        [self.x.m, self.x.c, self.x.k, self.z.m, self.z.c, self.z.k]
    }
}
