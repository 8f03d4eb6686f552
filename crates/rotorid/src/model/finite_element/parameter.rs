//! The parameters of a finite-element rotor, by name: `bearing<i>.kxx` ... `bearing<i>.cyy`
//! (i in the order of `[[rotor.bearing]]`), `unbalance<j>.mud` \[kg m\] and
//! `unbalance<j>.alpha` \[rad\] (j in the order of `[[rotor.unbalance]]`).

use std::fmt;

use super::error::FiniteElementError;
use super::rotor::FiniteElementRotor;

/// One of a bearing's eight coefficients.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum BearingCoefficient {
    /// Direct stiffness in x \[N/m\].
    Kxx,
    /// Restoring force in x per unit displacement in y \[N/m\].
    Kxy,
    /// Restoring force in y per unit displacement in x \[N/m\].
    Kyx,
    /// Direct stiffness in y \[N/m\].
    Kyy,
    /// Direct damping in x \[N s/m\].
    Cxx,
    /// Damping force in x per unit velocity in y \[N s/m\].
    Cxy,
    /// Damping force in y per unit velocity in x \[N s/m\].
    Cyx,
    /// Direct damping in y \[N s/m\].
    Cyy,
}

impl BearingCoefficient {
    /// All eight, stiffness first.
    pub const ALL: [BearingCoefficient; 8] = [
        BearingCoefficient::Kxx,
        BearingCoefficient::Kxy,
        BearingCoefficient::Kyx,
        BearingCoefficient::Kyy,
        BearingCoefficient::Cxx,
        BearingCoefficient::Cxy,
        BearingCoefficient::Cyx,
        BearingCoefficient::Cyy,
    ];

    /// The key: `kxx`, ..., `cyy`.
    pub fn name(self) -> &'static str {
        use BearingCoefficient::*;
        match self {
            Kxx => "kxx",
            Kxy => "kxy",
            Kyx => "kyx",
            Kyy => "kyy",
            Cxx => "cxx",
            Cxy => "cxy",
            Cyx => "cyx",
            Cyy => "cyy",
        }
    }

    /// N/m or N s/m.
    pub fn unit(self) -> &'static str {
        if self.is_stiffness() {
            "N/m"
        } else {
            "N s/m"
        }
    }

    /// True for kxx .. kyy.
    pub fn is_stiffness(self) -> bool {
        use BearingCoefficient::*;
        matches!(self, Kxx | Kxy | Kyx | Kyy)
    }

    /// True for the cross-coupled ones (kxy, kyx, cxy, cyx): any sign.
    pub fn is_cross(self) -> bool {
        use BearingCoefficient::*;
        matches!(self, Kxy | Kyx | Cxy | Cyx)
    }

    /// (row, column) in the bearing's 2x2 matrix, 0 = x, 1 = y.
    pub fn entry(self) -> (usize, usize) {
        use BearingCoefficient::*;
        match self {
            Kxx | Cxx => (0, 0),
            Kxy | Cxy => (0, 1),
            Kyx | Cyx => (1, 0),
            Kyy | Cyy => (1, 1),
        }
    }
}

/// A parameter of a finite-element rotor.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum FeParameter {
    /// A coefficient of bearing `index`.
    Bearing {
        /// The bearing's position in `[[rotor.bearing]]`.
        index: usize,
        /// Which coefficient.
        coefficient: BearingCoefficient,
    },
    /// m_u d of unbalance `index` \[kg m\].
    Mud {
        /// The unbalance's position in `[[rotor.unbalance]]`.
        index: usize,
    },
    /// The angle of unbalance `index` \[rad\].
    Alpha {
        /// The unbalance's position in `[[rotor.unbalance]]`.
        index: usize,
    },
}

impl FeParameter {
    /// Its unit.
    pub fn unit(self) -> &'static str {
        match self {
            FeParameter::Bearing { coefficient, .. } => coefficient.unit(),
            FeParameter::Mud { .. } => "kg m",
            FeParameter::Alpha { .. } => "rad",
        }
    }

    /// Its value in `rotor`, if the rotor has it.
    pub fn get(self, rotor: &FiniteElementRotor) -> Option<f64> {
        match self {
            FeParameter::Bearing { index, coefficient } => {
                let b = rotor.bearings.get(index)?;
                let (r, c) = coefficient.entry();
                Some(if coefficient.is_stiffness() {
                    b.stiffness()[r][c]
                } else {
                    b.damping()[r][c]
                })
            }
            FeParameter::Mud { index } => rotor.unbalances.get(index).map(|u| u.mud),
            FeParameter::Alpha { index } => rotor.unbalances.get(index).map(|u| u.alpha),
        }
    }

    /// Set its value in `rotor` (unchecked); false when the rotor has no such parameter.
    pub fn set(self, rotor: &mut FiniteElementRotor, v: f64) -> bool {
        use BearingCoefficient::*;
        match self {
            FeParameter::Bearing { index, coefficient } => {
                let Some(b) = rotor.bearings.get_mut(index) else {
                    return false;
                };
                *match coefficient {
                    Kxx => &mut b.kxx,
                    Kxy => &mut b.kxy,
                    Kyx => &mut b.kyx,
                    Kyy => &mut b.kyy,
                    Cxx => &mut b.cxx,
                    Cxy => &mut b.cxy,
                    Cyx => &mut b.cyx,
                    Cyy => &mut b.cyy,
                } = v;
            }
            FeParameter::Mud { index } => match rotor.unbalances.get_mut(index) {
                Some(u) => u.mud = v,
                None => return false,
            },
            FeParameter::Alpha { index } => match rotor.unbalances.get_mut(index) {
                Some(u) => u.alpha = v,
                None => return false,
            },
        }
        true
    }

    /// Every parameter of `rotor`: each bearing's eight coefficients, then each
    /// unbalance's mud and alpha.
    pub fn all(rotor: &FiniteElementRotor) -> Vec<FeParameter> {
        let mut all: Vec<FeParameter> = (0..rotor.bearings.len())
            .flat_map(|index| {
                BearingCoefficient::ALL
                    .map(|coefficient| FeParameter::Bearing { index, coefficient })
            })
            .collect();
        for index in 0..rotor.unbalances.len() {
            all.push(FeParameter::Mud { index });
            all.push(FeParameter::Alpha { index });
        }
        all
    }

    /// The default unknowns of refine: every bearing's direct coefficients (kxx, kyy, cxx,
    /// cyy) and every unbalance.
    pub fn default_unknowns(rotor: &FiniteElementRotor) -> Vec<FeParameter> {
        Self::all(rotor)
            .into_iter()
            .filter(|p| !matches!(p, FeParameter::Bearing { coefficient, .. } if coefficient.is_cross()))
            .collect()
    }

    /// The parameters `list` names in `rotor`: comma-separated names (`bearing0.kxx`,
    /// `unbalance1.alpha`) or groups: `bearings` (every bearing's direct coefficients),
    /// `bearing<i>` (its eight), `unbalances` or `unbalance` (every unbalance's mud and
    /// alpha), `unbalance<j>` (its two). Without repeats, in the order of [`Self::all`].
    pub fn parse_list(
        list: &str,
        rotor: &FiniteElementRotor,
    ) -> Result<Vec<FeParameter>, FiniteElementError> {
        let all = Self::all(rotor);
        let mut chosen = Vec::new();
        for name in list.split(',').map(str::trim).filter(|s| !s.is_empty()) {
            let group: Vec<FeParameter> = match name {
                "bearings" => all
                    .iter()
                    .copied()
                    .filter(|p| matches!(p, FeParameter::Bearing { coefficient, .. } if !coefficient.is_cross()))
                    .collect(),
                "unbalances" | "unbalance" => all
                    .iter()
                    .copied()
                    .filter(|p| !matches!(p, FeParameter::Bearing { .. }))
                    .collect(),
                _ => {
                    let of = |prefix: &str| {
                        name.strip_prefix(prefix)
                            .filter(|i| !i.is_empty() && i.bytes().all(|b| b.is_ascii_digit()))
                            .and_then(|i| i.parse::<usize>().ok())
                    };
                    if let Some(i) = of("bearing").filter(|&i| i < rotor.bearings.len()) {
                        all.iter()
                            .copied()
                            .filter(|p| matches!(p, FeParameter::Bearing { index, .. } if *index == i))
                            .collect()
                    } else if let Some(j) = of("unbalance").filter(|&j| j < rotor.unbalances.len()) {
                        vec![FeParameter::Mud { index: j }, FeParameter::Alpha { index: j }]
                    } else {
                        match all.iter().find(|p| p.to_string() == name) {
                            Some(&p) => vec![p],
                            None => {
                                return Err(FiniteElementError::UnknownParameter {
                                    name: name.to_owned(),
                                    allowed: Self::allowed(rotor),
                                })
                            }
                        }
                    }
                }
            };
            for p in group {
                if !chosen.contains(&p) {
                    chosen.push(p);
                }
            }
        }
        chosen.sort_by_key(|p| all.iter().position(|q| q == p));
        Ok(chosen)
    }

    /// What `rotor` has, in words (for errors).
    fn allowed(rotor: &FiniteElementRotor) -> String {
        let nb = rotor.bearings.len();
        let nu = rotor.unbalances.len();
        let bearings = match nb {
            0 => "no bearing".to_owned(),
            _ => format!(
                "bearing0 .. bearing{}, each with kxx, kxy, kyx, kyy, cxx, cxy, cyx, cyy",
                nb - 1
            ),
        };
        let unbalances = match nu {
            0 => "no unbalance".to_owned(),
            _ => format!("unbalance0 .. unbalance{} with mud, alpha", nu - 1),
        };
        format!(
            "the rotor has {bearings}; {unbalances}; groups: bearings, unbalances, bearing<i>, \
             unbalance<j>"
        )
    }
}

impl fmt::Display for FeParameter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            FeParameter::Bearing { index, coefficient } => {
                write!(f, "bearing{index}.{}", coefficient.name())
            }
            FeParameter::Mud { index } => write!(f, "unbalance{index}.mud"),
            FeParameter::Alpha { index } => write!(f, "unbalance{index}.alpha"),
        }
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use nalgebra::DMatrix;

    use super::super::rotor::{Bearing, Dof, FeMatrices, FeUnbalance};
    use super::*;

    fn rotor() -> FiniteElementRotor {
        let dofs: Vec<Dof> = ["0.x", "0.y", "1.x", "1.y"]
            .iter()
            .map(|s| s.parse().unwrap())
            .collect();
        let eye = DMatrix::<f64>::identity(4, 4);
        let mats =
            FeMatrices::new(dofs, eye.clone(), eye, DMatrix::zeros(4, 4), None, None).unwrap();
        let b = Bearing {
            node: 0,
            kxx: 1e6,
            kxy: 0.0,
            kyx: 0.0,
            kyy: 1.2e6,
            cxx: 300.0,
            cxy: 0.0,
            cyx: 0.0,
            cyy: 310.0,
        };
        let u = FeUnbalance {
            node: 1,
            mud: 1e-5,
            alpha: 0.5,
        };
        FiniteElementRotor::new(Arc::new(mats), vec![b, Bearing { node: 1, ..b }], vec![u]).unwrap()
    }

    #[test]
    fn names_get_set_and_groups() {
        let mut r = rotor();
        let all = FeParameter::all(&r);
        assert_eq!(all.len(), 18);
        assert_eq!(all[9].to_string(), "bearing1.kxy");
        assert_eq!(all[16].to_string(), "unbalance0.mud");
        let p = FeParameter::parse_list("bearing1.cyy", &r).unwrap()[0];
        assert_eq!(p.get(&r), Some(310.0));
        assert!(p.set(&mut r, 42.0));
        assert_eq!(r.bearings[1].cyy, 42.0);
        let d = FeParameter::default_unknowns(&r);
        assert_eq!(
            d.iter()
                .map(|p| p.to_string())
                .collect::<Vec<_>>()
                .join(","),
            "bearing0.kxx,bearing0.kyy,bearing0.cxx,bearing0.cyy,bearing1.kxx,bearing1.kyy,\
             bearing1.cxx,bearing1.cyy,unbalance0.mud,unbalance0.alpha"
        );
        assert_eq!(
            FeParameter::parse_list("bearings,unbalance", &r).unwrap(),
            d
        );
        assert_eq!(FeParameter::parse_list("bearing0", &r).unwrap().len(), 8);
        let both =
            FeParameter::parse_list("unbalance0.alpha, bearing0.kxx,bearing0.kxx", &r).unwrap();
        assert_eq!(both, vec![all[0], all[17]]);
        for bad in [
            "bearing2.kxx",
            "bearing2",
            "unbalance1",
            "kxx",
            "bearing0.kzz",
        ] {
            let e = FeParameter::parse_list(bad, &r).unwrap_err().to_string();
            assert!(e.contains(bad) && e.contains("bearing0 .. bearing1"), "{e}");
        }
    }
}
