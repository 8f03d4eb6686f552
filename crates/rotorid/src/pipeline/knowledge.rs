//! What the caller knows besides the record: the quantities eq. (1) needs as known (the
//! gyroscopic coefficient a and the unbalance m_u d, alpha), nominal values of m, c, k
//! (the refinement's fallback start, and the values of parameters it leaves known), and
//! optionally the truth (simulation studies: errors and the Cramer-Rao bound at the truth).

use serde::{Deserialize, Serialize};

use crate::identify::Known;
use crate::model::{InitialState, RotorParams, Scenario, Unbalance};
use crate::parameter::{ModelKind, Parameter};

/// Values of m \[kg\], the damping \[N s/m\] and stiffness \[N/m\] coefficients, each
/// possibly unknown. The direct coefficients cx, kx, cz, kz are the cross-coupled model's
/// cxx, kxx, czz, kzz; the cross terms are `None` where not stated (a Jeffcott rotor's are
/// 0: [`RotorValues::of`] states them as such only for a cross-coupled rotor).
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct RotorValues {
    /// Mass m \[kg\].
    pub m: Option<f64>,
    /// Damping cx (cxx) \[N s/m\].
    pub cx: Option<f64>,
    /// Stiffness kx (kxx) \[N/m\].
    pub kx: Option<f64>,
    /// Damping cz (czz) \[N s/m\].
    pub cz: Option<f64>,
    /// Stiffness kz (kzz) \[N/m\].
    pub kz: Option<f64>,
    /// Cross-coupled damping cxz \[N s/m\].
    #[serde(default)]
    pub cxz: Option<f64>,
    /// Cross-coupled damping czx \[N s/m\].
    #[serde(default)]
    pub czx: Option<f64>,
    /// Cross-coupled stiffness kxz \[N/m\].
    #[serde(default)]
    pub kxz: Option<f64>,
    /// Cross-coupled stiffness kzx \[N/m\].
    #[serde(default)]
    pub kzx: Option<f64>,
}

impl RotorValues {
    /// The value of `p` (m_x and m_z are m; cxx is cx, ...); `None` for a, mud, alpha.
    pub fn get(&self, p: Parameter) -> Option<f64> {
        use Parameter::*;
        match p {
            M | MX | MZ => self.m,
            Cx | Cxx => self.cx,
            Kx | Kxx => self.kx,
            Cz | Czz => self.cz,
            Kz | Kzz => self.kz,
            Cxz => self.cxz,
            Czx => self.czx,
            Kxz => self.kxz,
            Kzx => self.kzx,
            A | Mud | Alpha => None,
        }
    }

    /// The values of a rotor: all five of a Jeffcott rotor, all nine of a cross-coupled one.
    pub fn of(p: &RotorParams) -> Self {
        let c = p.coupling;
        Self {
            m: Some(p.m),
            cx: Some(p.cx),
            kx: Some(p.kx),
            cz: Some(p.cz),
            kz: Some(p.kz),
            cxz: c.map(|c| c.cxz),
            czx: c.map(|c| c.czx),
            kxz: c.map(|c| c.kxz),
            kzx: c.map(|c| c.kzx),
        }
    }

    /// True when no value is known.
    pub fn is_empty(&self) -> bool {
        [
            self.m, self.cx, self.kx, self.cz, self.kz, self.cxz, self.czx, self.kxz, self.kzx,
        ]
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
    /// The rotor model the caller describes (the scenario's `rotor.model`): the model of
    /// an identification whose method names none.
    #[serde(default)]
    pub model: ModelKind,
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
            model: ModelKind::Jeffcott,
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
            model: p.model(),
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
