//! The physical parameters rotorid identifies, by name and unit: one typed vocabulary
//! shared by the identifiers, the refinement, the pipeline's results and every caller (no
//! strings), and the models ([`ModelKind`]) that name their parameters from it.
//!
//! The algebraic and modulating identifiers estimate the mass separately from the x and
//! the z equation of eq. (1) ([`Parameter::MX`], [`Parameter::MZ`]); the refinement fits
//! one mass [`Parameter::M`] to both channels. The Jeffcott model names its bearing
//! coefficients cx, kx, cz, kz; the cross-coupled model cxx, cxz, czx, czz, kxx, kxz, kzx,
//! kzz (cxx is the Jeffcott model's cx, and so on; docs/method.md section 1.6).

use std::fmt;
use std::str::FromStr;

use serde::{Deserialize, Serialize};

/// A parameter of the rotor model (docs/method.md section 1), with its SI unit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum Parameter {
    /// Modal mass m \[kg\] (one value for both directions).
    #[serde(rename = "m")]
    M,
    /// Mass identified from the x equation \[kg\].
    #[serde(rename = "m_x")]
    MX,
    /// Mass identified from the z equation \[kg\].
    #[serde(rename = "m_z")]
    MZ,
    /// Support damping in x \[N s/m\].
    #[serde(rename = "cx")]
    Cx,
    /// Support stiffness in x \[N/m\].
    #[serde(rename = "kx")]
    Kx,
    /// Support damping in z \[N s/m\].
    #[serde(rename = "cz")]
    Cz,
    /// Support stiffness in z \[N/m\].
    #[serde(rename = "kz")]
    Kz,
    /// Gyroscopic coefficient a \[N s^2/m\].
    #[serde(rename = "a")]
    A,
    /// Unbalance m_u d \[kg m\].
    #[serde(rename = "mud")]
    Mud,
    /// Unbalance angle alpha \[rad\], in the frame of the shaft angle phi.
    #[serde(rename = "alpha")]
    Alpha,
    /// Direct damping in x of the cross-coupled model \[N s/m\] (the Jeffcott model's cx).
    #[serde(rename = "cxx")]
    Cxx,
    /// Damping force in x per unit velocity in z \[N s/m\].
    #[serde(rename = "cxz")]
    Cxz,
    /// Damping force in z per unit velocity in x \[N s/m\].
    #[serde(rename = "czx")]
    Czx,
    /// Direct damping in z of the cross-coupled model \[N s/m\] (the Jeffcott model's cz).
    #[serde(rename = "czz")]
    Czz,
    /// Direct stiffness in x of the cross-coupled model \[N/m\] (the Jeffcott model's kx).
    #[serde(rename = "kxx")]
    Kxx,
    /// Restoring force in x per unit displacement in z \[N/m\].
    #[serde(rename = "kxz")]
    Kxz,
    /// Restoring force in z per unit displacement in x \[N/m\].
    #[serde(rename = "kzx")]
    Kzx,
    /// Direct stiffness in z of the cross-coupled model \[N/m\] (the Jeffcott model's kz).
    #[serde(rename = "kzz")]
    Kzz,
}

/// What values a parameter may take in a physical rotor.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Sign {
    /// > 0 (a mass, a direct stiffness).
    Positive,
    /// >= 0 (a direct damping, the unbalance's size).
    NonNegative,
    /// Any finite value (a cross-coupled coefficient, a, an angle): whether it is
    /// determined is a question of information, never of its size against its standard
    /// error.
    Any,
}

/// A rotor model: which parameters it has (docs/method.md section 1.6).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ModelKind {
    /// The paper's rotor: m, cx, kx, cz, kz, a and the unbalance.
    #[default]
    Jeffcott,
    /// The same rotor on bearings with all eight coefficients: m, cxx, cxz, czx, czz, kxx,
    /// kxz, kzx, kzz, a and the unbalance.
    CrossCoupled,
}

impl ModelKind {
    /// Every model, simplest first.
    pub const ALL: [ModelKind; 2] = [ModelKind::Jeffcott, ModelKind::CrossCoupled];

    /// The name in scenarios, summaries and on the command line: `jeffcott`,
    /// `cross_coupled`.
    pub fn name(self) -> &'static str {
        match self {
            ModelKind::Jeffcott => "jeffcott",
            ModelKind::CrossCoupled => "cross_coupled",
        }
    }

    /// Every parameter of the model, in the order results list them.
    pub fn parameters(self) -> &'static [Parameter] {
        use Parameter::*;
        match self {
            ModelKind::Jeffcott => &[M, Cx, Kx, Cz, Kz, A, Mud, Alpha],
            ModelKind::CrossCoupled => &[M, Cxx, Cxz, Czx, Czz, Kxx, Kxz, Kzx, Kzz, A, Mud, Alpha],
        }
    }

    /// The parameters refine estimates by default: m and the bearing coefficients.
    pub fn default_unknowns(self) -> &'static [Parameter] {
        let all = self.parameters();
        &all[..all.len() - 3]
    }

    /// What the per-direction identifiers (algebraic, modulating) estimate, in the order
    /// of their values: x then z, each m and that row's coefficients.
    pub fn per_direction(self) -> &'static [Parameter] {
        use Parameter::*;
        match self {
            ModelKind::Jeffcott => &Parameter::PER_DIRECTION,
            ModelKind::CrossCoupled => &[MX, Cxx, Cxz, Kxx, Kxz, MZ, Czx, Czz, Kzx, Kzz],
        }
    }

    /// The model's own name for `p` where the two models name the same coefficient
    /// differently (cx in the Jeffcott model is cxx in the cross-coupled one); `None` when
    /// the model has no such parameter (m_x and m_z are the per-direction m).
    pub fn own(self, p: Parameter) -> Option<Parameter> {
        use Parameter::*;
        let q = match (self, p) {
            (ModelKind::Jeffcott, Cxx) => Cx,
            (ModelKind::Jeffcott, Czz) => Cz,
            (ModelKind::Jeffcott, Kxx) => Kx,
            (ModelKind::Jeffcott, Kzz) => Kz,
            (ModelKind::CrossCoupled, Cx) => Cxx,
            (ModelKind::CrossCoupled, Cz) => Czz,
            (ModelKind::CrossCoupled, Kx) => Kxx,
            (ModelKind::CrossCoupled, Kz) => Kzz,
            (_, MX | MZ) => return self.per_direction().contains(&p).then_some(p),
            _ => p,
        };
        self.parameters().contains(&q).then_some(q)
    }
}

impl fmt::Display for ModelKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A name that is not a model's.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown model {name:?}: expected jeffcott or cross_coupled")]
pub struct UnknownModel {
    /// The name as given.
    pub name: String,
}

impl FromStr for ModelKind {
    type Err = UnknownModel;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        ModelKind::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| UnknownModel { name: s.to_owned() })
    }
}

impl Parameter {
    /// Every parameter.
    pub const ALL: [Parameter; 18] = [
        Parameter::M,
        Parameter::MX,
        Parameter::MZ,
        Parameter::Cx,
        Parameter::Kx,
        Parameter::Cz,
        Parameter::Kz,
        Parameter::A,
        Parameter::Mud,
        Parameter::Alpha,
        Parameter::Cxx,
        Parameter::Cxz,
        Parameter::Czx,
        Parameter::Czz,
        Parameter::Kxx,
        Parameter::Kxz,
        Parameter::Kzx,
        Parameter::Kzz,
    ];

    /// What the per-direction identifiers estimate, in the order of their `values()`:
    /// m_x, cx, kx, m_z, cz, kz.
    pub const PER_DIRECTION: [Parameter; 6] = [
        Parameter::MX,
        Parameter::Cx,
        Parameter::Kx,
        Parameter::MZ,
        Parameter::Cz,
        Parameter::Kz,
    ];

    /// The name used in results, files and on the command line: `m`, `m_x`, `m_z`, `cx`,
    /// `kx`, `cz`, `kz`, `a`, `mud`, `alpha`.
    pub fn name(self) -> &'static str {
        match self {
            Parameter::M => "m",
            Parameter::MX => "m_x",
            Parameter::MZ => "m_z",
            Parameter::Cx => "cx",
            Parameter::Kx => "kx",
            Parameter::Cz => "cz",
            Parameter::Kz => "kz",
            Parameter::A => "a",
            Parameter::Mud => "mud",
            Parameter::Alpha => "alpha",
            Parameter::Cxx => "cxx",
            Parameter::Cxz => "cxz",
            Parameter::Czx => "czx",
            Parameter::Czz => "czz",
            Parameter::Kxx => "kxx",
            Parameter::Kxz => "kxz",
            Parameter::Kzx => "kzx",
            Parameter::Kzz => "kzz",
        }
    }

    /// Its column in the estimates CSV (`t,m_x,c_x,k_x,m_z,c_z,k_z,...`): `m_x`, `c_x`,
    /// `k_x`, `m_z`, `c_z`, `k_z` for the per-direction parameters, else its name.
    pub fn column(self) -> &'static str {
        match self {
            Parameter::Cx => "c_x",
            Parameter::Kx => "k_x",
            Parameter::Cz => "c_z",
            Parameter::Kz => "k_z",
            p => p.name(),
        }
    }

    /// The SI unit of its value and standard error.
    pub fn unit(self) -> &'static str {
        use Parameter::*;
        match self {
            M | MX | MZ => "kg",
            Cx | Cz | Cxx | Cxz | Czx | Czz => "N s/m",
            Kx | Kz | Kxx | Kxz | Kzx | Kzz => "N/m",
            A => "N s^2/m",
            Mud => "kg m",
            Alpha => "rad",
        }
    }

    /// What it is, in a few words (for help texts, reports and the Python package).
    pub fn description(self) -> &'static str {
        use Parameter::*;
        match self {
            M => "modal mass of the disk",
            MX => "mass from the x equation",
            MZ => "mass from the z equation",
            Cx | Cxx => "bearing damping in x",
            Cz | Czz => "bearing damping in z",
            Kx | Kxx => "bearing stiffness in x",
            Kz | Kzz => "bearing stiffness in z",
            Cxz => "damping force in x per velocity in z",
            Czx => "damping force in z per velocity in x",
            Kxz => "restoring force in x per displacement in z",
            Kzx => "restoring force in z per displacement in x",
            A => "gyroscopic coefficient",
            Mud => "unbalance m_u d",
            Alpha => "unbalance angle from the keyphasor, in the direction of rotation",
        }
    }

    /// The values it may take in a physical rotor.
    pub fn sign(self) -> Sign {
        use Parameter::*;
        match self {
            M | MX | MZ | Kx | Kz | Kxx | Kzz => Sign::Positive,
            Cx | Cz | Cxx | Czz | Mud => Sign::NonNegative,
            Cxz | Czx | Kxz | Kzx | A | Alpha => Sign::Any,
        }
    }

    /// True for an off-diagonal (cross-coupled) bearing coefficient.
    pub fn is_cross(self) -> bool {
        matches!(
            self,
            Parameter::Cxz | Parameter::Czx | Parameter::Kxz | Parameter::Kzx
        )
    }

    /// The rotor parameter it estimates: m for m_x and m_z, itself otherwise (cxx and cx
    /// stay apart: each model names its own, see [`ModelKind::own`]).
    pub fn physical(self) -> Parameter {
        match self {
            Parameter::MX | Parameter::MZ => Parameter::M,
            p => p,
        }
    }

    /// Position in [`Parameter::PER_DIRECTION`], for the per-direction parameters.
    pub fn direction_index(self) -> Option<usize> {
        Parameter::PER_DIRECTION.iter().position(|&p| p == self)
    }
}

impl fmt::Display for Parameter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A name that is not a parameter's.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown parameter {name:?}: expected one of m, m_x, m_z, cx, kx, cz, kz, a, mud, alpha, cxx, cxz, czx, czz, kxx, kxz, kzx, kzz")]
pub struct UnknownParameter {
    /// The name as given.
    pub name: String,
}

impl FromStr for Parameter {
    type Err = UnknownParameter;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Parameter::ALL
            .into_iter()
            .find(|p| p.name() == s)
            .ok_or_else(|| UnknownParameter { name: s.to_owned() })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip_through_text_and_json() {
        for p in Parameter::ALL {
            assert_eq!(p.name().parse::<Parameter>(), Ok(p));
            let json = serde_json::to_string(&p).unwrap();
            assert_eq!(json, format!("\"{}\"", p.name()));
            assert_eq!(serde_json::from_str::<Parameter>(&json).unwrap(), p);
        }
        assert!("c_x".parse::<Parameter>().is_err());
        assert_eq!(
            Parameter::PER_DIRECTION.map(Parameter::physical)[3],
            Parameter::M
        );
    }

    #[test]
    fn models_name_their_parameters_once() {
        for model in ModelKind::ALL {
            assert_eq!(model.name().parse::<ModelKind>(), Ok(model));
            let all = model.parameters();
            for (i, p) in all.iter().enumerate() {
                assert!(!all[..i].contains(p), "{model}: {p} twice");
                assert_eq!(model.own(*p), Some(*p));
            }
            for p in model.per_direction() {
                assert_eq!(model.own(*p), Some(*p));
                assert!(all.contains(&p.physical()));
            }
            assert!(model
                .default_unknowns()
                .iter()
                .all(|p| p.sign() != Sign::Any || p.is_cross()));
        }
        let (j, c) = (ModelKind::Jeffcott, ModelKind::CrossCoupled);
        assert_eq!(c.own(Parameter::Kx), Some(Parameter::Kxx));
        assert_eq!(j.own(Parameter::Kzz), Some(Parameter::Kz));
        assert_eq!(j.own(Parameter::Kxz), None);
        assert_eq!(c.default_unknowns().len(), 9);
        assert_eq!(j.default_unknowns().len(), 5);
        assert!("ross".parse::<ModelKind>().is_err());
    }
}
