//! What the caller knows besides the record: the quantities eq. (1) needs as known (the
//! gyroscopic coefficient a and the unbalance m_u d, alpha), nominal values of m, c, k
//! (the refinement's fallback start, and the values of parameters it leaves known), and
//! optionally the truth (simulation studies: errors and the Cramer-Rao bound at the truth).

use serde::{Deserialize, Serialize};

use crate::identify::Known;
use crate::model::{InitialState, RotorParams, Scenario, Unbalance};
use crate::parameter::Parameter;

/// Values of m \[kg\], cx, cz \[N s/m\], kx, kz \[N/m\], each possibly unknown.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct RotorValues {
    /// Mass m \[kg\].
    pub m: Option<f64>,
    /// Damping cx \[N s/m\].
    pub cx: Option<f64>,
    /// Stiffness kx \[N/m\].
    pub kx: Option<f64>,
    /// Damping cz \[N s/m\].
    pub cz: Option<f64>,
    /// Stiffness kz \[N/m\].
    pub kz: Option<f64>,
}

impl RotorValues {
    /// The values of `p` (m_x and m_z are m); `None` for a, mud, alpha.
    pub fn get(&self, p: Parameter) -> Option<f64> {
        match p.physical() {
            Parameter::M => self.m,
            Parameter::Cx => self.cx,
            Parameter::Kx => self.kx,
            Parameter::Cz => self.cz,
            Parameter::Kz => self.kz,
            _ => None,
        }
    }

    /// All five of a rotor.
    pub fn of(p: &RotorParams) -> Self {
        Self {
            m: Some(p.m),
            cx: Some(p.cx),
            kx: Some(p.kx),
            cz: Some(p.cz),
            kz: Some(p.kz),
        }
    }

    /// True when no value is known.
    pub fn is_empty(&self) -> bool {
        [self.m, self.cx, self.kx, self.cz, self.kz]
            .iter()
            .all(Option::is_none)
    }
}

/// The true rotor of a simulation (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Truth {
    /// The true m, c, k (those the caller knows).
    pub values: RotorValues,
    /// The true state at t = 0, when the record is a simulation from t = 0.
    pub initial: Option<InitialState>,
}

/// What is known besides the record (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Knowledge {
    /// Gyroscopic coefficient a \[N s^2/m\].
    pub a: f64,
    /// The unbalance m_u \[kg\], d \[m\], alpha \[rad\] (only m_u d and alpha matter).
    pub unbalance: Unbalance,
    /// Nominal m, c, k: the refinement's last-resort start and the values of the
    /// parameters it leaves known.
    pub nominal: RotorValues,
    /// The truth, for errors and the Cramer-Rao bound at the truth.
    pub truth: Option<Truth>,
}

impl Knowledge {
    /// Only what eq. (1) needs as known: a, the unbalance; no nominal values, no truth.
    pub fn known(a: f64, unbalance: Unbalance) -> Self {
        Self {
            a,
            unbalance,
            nominal: RotorValues::default(),
            truth: None,
        }
    }

    /// A simulated scenario: its rotor is the nominal and the true rotor, its initial
    /// state the true state at t = 0.
    pub fn from_scenario(s: &Scenario) -> Self {
        let p = s.rotor.params();
        Self {
            a: p.a,
            unbalance: p.unbalance,
            nominal: RotorValues::of(&p),
            truth: Some(Truth {
                values: RotorValues::of(&p),
                initial: Some(s.initial),
            }),
        }
    }

    /// a, m_u d, alpha as the identifiers take them.
    pub fn identify_known(&self) -> Known {
        Known {
            a: self.a,
            mud: self.unbalance.mud(),
            alpha: self.unbalance.alpha,
        }
    }

    /// The truth of `p` when known.
    pub fn truth_of(&self, p: Parameter) -> Option<f64> {
        let t = self.truth.as_ref()?;
        match p {
            Parameter::A => Some(self.a),
            Parameter::Mud => Some(self.unbalance.mud()),
            Parameter::Alpha => Some(self.unbalance.alpha),
            _ => t.values.get(p),
        }
    }
}
