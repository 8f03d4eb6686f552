//! The physical parameters rotorid identifies, by name and unit: one typed enum shared by
//! the identifiers, the refinement, the pipeline's results and every caller (no strings).
//!
//! The algebraic and modulating identifiers estimate the mass separately from the x and
//! the z equation of eq. (1) ([`Parameter::MX`], [`Parameter::MZ`]); the refinement fits
//! one mass [`Parameter::M`] to both channels.

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
}

impl Parameter {
    /// Every parameter, in the order results list them.
    pub const ALL: [Parameter; 10] = [
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
        match self {
            Parameter::M | Parameter::MX | Parameter::MZ => "kg",
            Parameter::Cx | Parameter::Cz => "N s/m",
            Parameter::Kx | Parameter::Kz => "N/m",
            Parameter::A => "N s^2/m",
            Parameter::Mud => "kg m",
            Parameter::Alpha => "rad",
        }
    }

    /// The rotor parameter it estimates: m for m_x and m_z, itself otherwise.
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
#[error("unknown parameter {name:?}: expected one of m, m_x, m_z, cx, kx, cz, kz, a, mud, alpha")]
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
}
