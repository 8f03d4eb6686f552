//! The cross-coupled algebraic identifier's output at one instant: per direction m and
//! the four coefficients of that row (docs/method.md section 3.10), and the conditioning
//! of the 5x5 system they came from.

use serde::{Deserialize, Serialize};

use crate::identify::coupled::ten;

/// The estimate for one direction (row) at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CrossDirectionEstimate {
    /// x row: (m_x \[kg\], cxx \[N s/m\], cxz \[N s/m\], kxx \[N/m\], kxz \[N/m\]);
    /// z row: (m_z \[kg\], czx \[N s/m\], czz \[N s/m\], kzx \[N/m\], kzz \[N/m\]).
    /// NaN when the system is singular.
    pub values: [f64; 5],
    /// Reciprocal 1-norm condition number of the scaled 5x5 system, in [0, 1] (0 when
    /// singular); see [`super::solve_scaled5`] for its exact definition.
    pub rcond: f64,
}

impl CrossDirectionEstimate {
    /// The singular answer: NaN values, rcond = 0.
    pub const SINGULAR: Self = Self {
        values: [f64::NAN; 5],
        rcond: 0.0,
    };

    /// True when the system was solvable with `rcond >= rcond_min` (and so the values are
    /// finite). Instants that fail this are flagged: their values must not be trusted.
    #[inline]
    pub fn well_conditioned(&self, rcond_min: f64) -> bool {
        self.rcond >= rcond_min && self.rcond > 0.0
    }
}

/// Both rows' estimates at time t.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CrossAlgebraicEstimate {
    /// Time of the measurement the estimate is for \[s\].
    pub t: f64,
    /// The x row: m_x, cxx, cxz, kxx, kxz.
    pub x: CrossDirectionEstimate,
    /// The z row: m_z, czx, czz, kzx, kzz.
    pub z: CrossDirectionEstimate,
}

impl CrossAlgebraicEstimate {
    /// [x well conditioned, z well conditioned] at threshold `rcond_min`
    /// (see [`CrossDirectionEstimate::well_conditioned`]).
    pub fn well_conditioned(&self, rcond_min: f64) -> [bool; 2] {
        [
            self.x.well_conditioned(rcond_min),
            self.z.well_conditioned(rcond_min),
        ]
    }

    /// The ten values in the order of [`CROSS_NAMES`](crate::identify::CROSS_NAMES):
    /// m_x, cxx, cxz, kxx, kxz, m_z, czx, czz, kzx, kzz.
    pub fn values(&self) -> [f64; 10] {
        ten(&self.x.values, &self.z.values)
    }
}
