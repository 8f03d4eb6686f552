//! The parameter vocabulary: one type, [`ModelParameter`], that names every quantity a
//! rotor model has or a fit estimates, with its published name, SI unit, kind (physical
//! or nuisance), description and allowed range.
//!
//! The published names are those of today's files and summaries (docs/summary.md): the
//! 2-DOF rotor's `m, m_x, m_z, cx, kx, cz, kz, a, mud, alpha, cxx, cxz, czx, czz, kxx, kxz,
//! kzx, kzz` ([`Parameter`]), the refinement's `mud_cos_alpha, mud_sin_alpha` and `x0, z0,
//! vx0, vz0`, the finite-element rotor's `bearing<i>.kxx` .. `bearing<i>.cyy`,
//! `unbalance<j>.mud`, `unbalance<j>.alpha` ([`FeParameter`]). The existing types map to
//! this one at the edge ([`From`] / [`TryFrom`]), names unchanged.

use std::borrow::Cow;
use std::fmt;
use std::str::FromStr;

use super::error::DescriptionError;
use crate::model::finite_element::{BearingCoefficient, Dof, FeParameter};
use crate::parameter::{Parameter, Sign};

/// A lateral direction of the 2-DOF rotor (docs/method.md section 1.1): x horizontal, z
/// vertical.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Direction {
    /// Horizontal, q\[0\].
    X,
    /// Vertical, q\[1\].
    Z,
}

impl Direction {
    /// `x` or `z`.
    pub fn name(self) -> &'static str {
        match self {
            Direction::X => "x",
            Direction::Z => "z",
        }
    }

    /// Its index in q = (x, z).
    pub fn index(self) -> usize {
        match self {
            Direction::X => 0,
            Direction::Z => 1,
        }
    }
}

/// Which bearing matrix a coefficient of the 2-DOF rotor is in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Support {
    /// The damping matrix C \[N s/m\].
    Damping,
    /// The stiffness matrix K \[N/m\].
    Stiffness,
}

impl Support {
    /// `c` or `k`, the first letter of the coefficient's name.
    fn letter(self) -> &'static str {
        match self {
            Support::Damping => "c",
            Support::Stiffness => "k",
        }
    }

    /// `N s/m` or `N/m`.
    pub fn unit(self) -> &'static str {
        match self {
            Support::Damping => "N s/m",
            Support::Stiffness => "N/m",
        }
    }
}

/// Whether a parameter is part of the rotor or of the experiment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ParameterKind {
    /// Enters M, C, K, G, Ka or the unbalance force: a property of the rotor.
    Physical,
    /// A property of one record (its initial state, a channel's offset): estimated beside
    /// the physical parameters, never reported as the rotor's.
    Nuisance,
}

/// A parameter of a rotor model or of a fit, named once (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ModelParameter {
    /// `m`: modal mass of the 2-DOF rotor's disk \[kg\].
    Mass,
    /// `m_x`, `m_z`: the mass one direction's equation gives (the per-direction
    /// identifiers) \[kg\].
    DirectionMass(Direction),
    /// `cx`, `kx`, `cz`, `kz`: a direct bearing coefficient of the Jeffcott model.
    Direct {
        /// Damping or stiffness.
        support: Support,
        /// Its direction.
        direction: Direction,
    },
    /// `cxx` .. `kzz`: a bearing coefficient of the cross-coupled model, the force in
    /// `row` per unit motion in `column` (docs/method.md section 1.6).
    Coupled {
        /// Damping or stiffness.
        support: Support,
        /// The equation it stands in.
        row: Direction,
        /// The motion it multiplies.
        column: Direction,
    },
    /// `a`: gyroscopic coefficient of the 2-DOF rotor \[N s^2/m\].
    Gyroscopic,
    /// `mud`: the 2-DOF rotor's unbalance m_u d \[kg m\].
    Mud,
    /// `alpha`: the 2-DOF rotor's unbalance angle \[rad\].
    Alpha,
    /// `mud_cos_alpha`: u_c = m_u d cos(alpha) \[kg m\], the refinement's linear coordinate
    /// of the 2-DOF unbalance.
    MudCosAlpha,
    /// `mud_sin_alpha`: u_s = m_u d sin(alpha) \[kg m\].
    MudSinAlpha,
    /// `x0`, `z0`: the 2-DOF rotor's displacement at the first sample \[m\] (nuisance).
    InitialDisplacement(Direction),
    /// `vx0`, `vz0`: the 2-DOF rotor's velocity at the first sample \[m/s\] (nuisance).
    InitialVelocity(Direction),
    /// `bearing<i>.kxx` .. `bearing<i>.cyy`: a coefficient of a finite-element rotor's
    /// bearing.
    Bearing {
        /// The bearing's position in `[[rotor.bearing]]`.
        index: usize,
        /// Which coefficient.
        coefficient: BearingCoefficient,
    },
    /// `unbalance<j>.mud`: m_u d of a finite-element rotor's unbalance \[kg m\].
    UnbalanceMud {
        /// The unbalance's position in `[[rotor.unbalance]]`.
        index: usize,
    },
    /// `unbalance<j>.alpha`: the angle of a finite-element rotor's unbalance \[rad\].
    UnbalanceAlpha {
        /// The unbalance's position in `[[rotor.unbalance]]`.
        index: usize,
    },
    /// `initial_state.q[<i>]`: coordinate i of a finite-element system at the first sample
    /// (m or rad; a reduced system's coordinates are those of its basis) (nuisance).
    StateDisplacement {
        /// The coordinate.
        coordinate: usize,
    },
    /// `initial_state.v[<i>]`: the velocity of coordinate i at the first sample (m/s or
    /// rad/s) (nuisance).
    StateVelocity {
        /// The coordinate.
        coordinate: usize,
    },
    /// `offset.<node>.<dof>`: a measured channel's constant offset, data = response +
    /// offset (m or rad) (nuisance).
    Offset {
        /// The channel.
        channel: Dof,
    },
    /// `mode<j>.k`: w_j^2, the stiffness of mode j of a modal model per unit modal mass
    /// \[1/s^2\] (w_j its undamped natural frequency, rad/s).
    ModalStiffness {
        /// The mode's position in the model.
        mode: usize,
    },
    /// `mode<j>.c`: 2 zeta_j w_j, the damping of mode j of a modal model per unit modal mass
    /// \[1/s\] (zeta_j its damping ratio).
    ModalDamping {
        /// The mode's position in the model.
        mode: usize,
    },
}

/// The names [`ModelParameter::from_str`] accepts, in words (for errors).
pub const ACCEPTED_NAMES: &str = "m, m_x, m_z, cx, kx, cz, kz, a, mud, alpha, cxx, cxz, czx, \
     czz, kxx, kxz, kzx, kzz, mud_cos_alpha, mud_sin_alpha, x0, z0, vx0, vz0, \
     bearing<i>.<kxx|kxy|kyx|kyy|cxx|cxy|cyx|cyy>, unbalance<j>.<mud|alpha>, \
     initial_state.q[<i>], initial_state.v[<i>], offset.<node>.<x|y|rx|ry>, mode<j>.<k|c>";

impl ModelParameter {
    /// Every parameter without an index: the 2-DOF rotor's and the refinement's names, in
    /// the order of [`Parameter::ALL`] then u_c, u_s and the initial state.
    pub const TWO_DOF: [ModelParameter; 24] = {
        use Direction::{X, Z};
        use ModelParameter::*;
        use Support::{Damping as C, Stiffness as K};
        const fn d(support: Support, direction: Direction) -> ModelParameter {
            Direct { support, direction }
        }
        const fn c(support: Support, row: Direction, column: Direction) -> ModelParameter {
            Coupled {
                support,
                row,
                column,
            }
        }
        [
            Mass,
            DirectionMass(X),
            DirectionMass(Z),
            d(C, X),
            d(K, X),
            d(C, Z),
            d(K, Z),
            Gyroscopic,
            Mud,
            Alpha,
            c(C, X, X),
            c(C, X, Z),
            c(C, Z, X),
            c(C, Z, Z),
            c(K, X, X),
            c(K, X, Z),
            c(K, Z, X),
            c(K, Z, Z),
            MudCosAlpha,
            MudSinAlpha,
            InitialDisplacement(X),
            InitialDisplacement(Z),
            InitialVelocity(X),
            InitialVelocity(Z),
        ]
    };

    /// The published name (module doc); [`ModelParameter::from_str`] reads it back.
    pub fn name(self) -> Cow<'static, str> {
        use ModelParameter::*;
        match self {
            Mass => "m".into(),
            DirectionMass(d) => format!("m_{}", d.name()).into(),
            Direct { support, direction } => {
                format!("{}{}", support.letter(), direction.name()).into()
            }
            Coupled {
                support,
                row,
                column,
            } => format!("{}{}{}", support.letter(), row.name(), column.name()).into(),
            Gyroscopic => "a".into(),
            Mud => "mud".into(),
            Alpha => "alpha".into(),
            MudCosAlpha => "mud_cos_alpha".into(),
            MudSinAlpha => "mud_sin_alpha".into(),
            InitialDisplacement(d) => format!("{}0", d.name()).into(),
            InitialVelocity(d) => format!("v{}0", d.name()).into(),
            Bearing { index, coefficient } => {
                format!("bearing{index}.{}", coefficient.name()).into()
            }
            UnbalanceMud { index } => format!("unbalance{index}.mud").into(),
            UnbalanceAlpha { index } => format!("unbalance{index}.alpha").into(),
            StateDisplacement { coordinate } => format!("initial_state.q[{coordinate}]").into(),
            StateVelocity { coordinate } => format!("initial_state.v[{coordinate}]").into(),
            Offset { channel } => format!("offset.{channel}").into(),
            ModalStiffness { mode } => format!("mode{mode}.k").into(),
            ModalDamping { mode } => format!("mode{mode}.c").into(),
        }
    }

    /// The SI unit of its value and standard error.
    pub fn unit(self) -> &'static str {
        use ModelParameter::*;
        match self {
            Mass | DirectionMass(_) => "kg",
            Direct { support, .. } | Coupled { support, .. } => support.unit(),
            Gyroscopic => "N s^2/m",
            Mud | MudCosAlpha | MudSinAlpha | UnbalanceMud { .. } => "kg m",
            Alpha | UnbalanceAlpha { .. } => "rad",
            InitialDisplacement(_) => "m",
            InitialVelocity(_) => "m/s",
            Bearing { coefficient, .. } => coefficient.unit(),
            StateDisplacement { .. } => "m or rad",
            StateVelocity { .. } => "m/s or rad/s",
            Offset { channel } => channel.kind.unit(),
            ModalStiffness { .. } => "1/s^2",
            ModalDamping { .. } => "1/s",
        }
    }

    /// Physical (enters the equation of motion) or nuisance (a property of one record).
    pub fn kind(self) -> ParameterKind {
        use ModelParameter::*;
        match self {
            InitialDisplacement(_)
            | InitialVelocity(_)
            | StateDisplacement { .. }
            | StateVelocity { .. }
            | Offset { .. } => ParameterKind::Nuisance,
            _ => ParameterKind::Physical,
        }
    }

    /// What it is, in a few words (help texts, reports, the Python package).
    pub fn description(self) -> Cow<'static, str> {
        use ModelParameter::*;
        let cross = |support: Support, row: &str, column: &str| {
            let (what, motion) = match support {
                Support::Damping => ("damping", "velocity"),
                Support::Stiffness => ("restoring", "displacement"),
            };
            if row == column {
                let what = match support {
                    Support::Damping => "damping",
                    Support::Stiffness => "stiffness",
                };
                format!("bearing {what} in {row}")
            } else {
                format!("{what} force in {row} per {motion} in {column}")
            }
        };
        match self {
            Mass => "modal mass of the disk".into(),
            DirectionMass(d) => format!("mass from the {} equation", d.name()).into(),
            Direct { support, direction } => {
                cross(support, direction.name(), direction.name()).into()
            }
            Coupled {
                support,
                row,
                column,
            } => cross(support, row.name(), column.name()).into(),
            Gyroscopic => "gyroscopic coefficient".into(),
            Mud => "unbalance m_u d".into(),
            Alpha => "unbalance angle from the keyphasor, in the direction of rotation".into(),
            MudCosAlpha => "unbalance m_u d cos(alpha)".into(),
            MudSinAlpha => "unbalance m_u d sin(alpha)".into(),
            InitialDisplacement(d) => {
                format!("displacement {} at the first sample", d.name()).into()
            }
            InitialVelocity(d) => format!("velocity {}' at the first sample", d.name()).into(),
            Bearing { index, coefficient } => {
                let (r, c) = coefficient.entry();
                let xy = ["x", "y"];
                let s = if coefficient.is_stiffness() {
                    Support::Stiffness
                } else {
                    Support::Damping
                };
                format!("bearing {index}: {}", cross(s, xy[r], xy[c])).into()
            }
            UnbalanceMud { index } => format!("unbalance {index}: m_u d").into(),
            UnbalanceAlpha { index } => {
                format!("unbalance {index}: angle from +x towards +y at phi = 0").into()
            }
            StateDisplacement { coordinate } => {
                format!("coordinate {coordinate} at the first sample").into()
            }
            StateVelocity { coordinate } => {
                format!("velocity of coordinate {coordinate} at the first sample").into()
            }
            Offset { channel } => format!("constant offset of channel {channel}").into(),
            ModalStiffness { mode } => {
                format!("mode {mode}: w^2, stiffness per unit modal mass").into()
            }
            ModalDamping { mode } => {
                format!("mode {mode}: 2 zeta w, damping per unit modal mass").into()
            }
        }
    }

    /// The values it may take in a physical rotor (a direct stiffness > 0, a direct
    /// damping or an unbalance's size >= 0, anything finite otherwise).
    pub fn sign(self) -> Sign {
        use ModelParameter::*;
        match self {
            Mass | DirectionMass(_) => Sign::Positive,
            Direct { support, .. } => match support {
                Support::Stiffness => Sign::Positive,
                Support::Damping => Sign::NonNegative,
            },
            Coupled {
                support,
                row,
                column,
            } if row == column => match support {
                Support::Stiffness => Sign::Positive,
                Support::Damping => Sign::NonNegative,
            },
            Bearing { coefficient, .. } if !coefficient.is_cross() => {
                if coefficient.is_stiffness() {
                    Sign::Positive
                } else {
                    Sign::NonNegative
                }
            }
            Mud | UnbalanceMud { .. } | ModalDamping { .. } => Sign::NonNegative,
            ModalStiffness { .. } => Sign::Positive,
            _ => Sign::Any,
        }
    }

    /// The allowed range in words, with the unit: `finite and > 0 (N/m)`.
    pub fn allowed(self) -> String {
        let range = match self.sign() {
            Sign::Positive => "finite and > 0",
            Sign::NonNegative => "finite and >= 0",
            Sign::Any => "finite",
        };
        format!("{range} ({})", self.unit())
    }

    /// `value` if it is in the allowed range, else the error naming the parameter, the
    /// value and the range.
    pub fn check(self, value: f64) -> Result<f64, DescriptionError> {
        let ok = value.is_finite()
            && match self.sign() {
                Sign::Positive => value > 0.0,
                Sign::NonNegative => value >= 0.0,
                Sign::Any => true,
            };
        if ok {
            Ok(value)
        } else {
            Err(DescriptionError::OutOfRange {
                name: self.name().into_owned(),
                value,
                allowed: self.allowed(),
            })
        }
    }
}

impl fmt::Display for ModelParameter {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name())
    }
}

/// `<prefix><digits>` -> the number (digits only, no sign, no leading `+`).
fn indexed(s: &str, prefix: &str) -> Option<usize> {
    s.strip_prefix(prefix)
        .filter(|i| !i.is_empty() && i.bytes().all(|b| b.is_ascii_digit()))
        .and_then(|i| i.parse().ok())
}

impl FromStr for ModelParameter {
    type Err = DescriptionError;

    /// The parameter whose [`ModelParameter::name`] is `s`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let unknown = || DescriptionError::UnknownName {
            name: s.to_owned(),
            allowed: ACCEPTED_NAMES,
        };
        if let Some(p) = Self::TWO_DOF.into_iter().find(|p| p.name() == s) {
            return Ok(p);
        }
        if let Some((head, key)) = s.split_once('.') {
            if let Some(index) = indexed(head, "bearing") {
                let coefficient = BearingCoefficient::ALL
                    .into_iter()
                    .find(|c| c.name() == key)
                    .ok_or_else(unknown)?;
                return Ok(ModelParameter::Bearing { index, coefficient });
            }
            if let Some(index) = indexed(head, "unbalance") {
                return match key {
                    "mud" => Ok(ModelParameter::UnbalanceMud { index }),
                    "alpha" => Ok(ModelParameter::UnbalanceAlpha { index }),
                    _ => Err(unknown()),
                };
            }
            if let Some(mode) = indexed(head, "mode") {
                return match key {
                    "k" => Ok(ModelParameter::ModalStiffness { mode }),
                    "c" => Ok(ModelParameter::ModalDamping { mode }),
                    _ => Err(unknown()),
                };
            }
            if head == "offset" {
                let channel = key.parse::<Dof>().map_err(|_| unknown())?;
                return Ok(ModelParameter::Offset { channel });
            }
            if head == "initial_state" {
                let at = |prefix: &str| {
                    key.strip_prefix(prefix)
                        .and_then(|r| r.strip_suffix(']'))
                        .and_then(|i| indexed(i, ""))
                };
                if let Some(coordinate) = at("q[") {
                    return Ok(ModelParameter::StateDisplacement { coordinate });
                }
                if let Some(coordinate) = at("v[") {
                    return Ok(ModelParameter::StateVelocity { coordinate });
                }
            }
        }
        Err(unknown())
    }
}

impl From<Parameter> for ModelParameter {
    fn from(p: Parameter) -> Self {
        use Direction::{X, Z};
        use ModelParameter as P;
        use Support::{Damping as C, Stiffness as K};
        let d = |support, direction| P::Direct { support, direction };
        let c = |support, row, column| P::Coupled {
            support,
            row,
            column,
        };
        match p {
            Parameter::M => P::Mass,
            Parameter::MX => P::DirectionMass(X),
            Parameter::MZ => P::DirectionMass(Z),
            Parameter::Cx => d(C, X),
            Parameter::Kx => d(K, X),
            Parameter::Cz => d(C, Z),
            Parameter::Kz => d(K, Z),
            Parameter::A => P::Gyroscopic,
            Parameter::Mud => P::Mud,
            Parameter::Alpha => P::Alpha,
            Parameter::Cxx => c(C, X, X),
            Parameter::Cxz => c(C, X, Z),
            Parameter::Czx => c(C, Z, X),
            Parameter::Czz => c(C, Z, Z),
            Parameter::Kxx => c(K, X, X),
            Parameter::Kxz => c(K, X, Z),
            Parameter::Kzx => c(K, Z, X),
            Parameter::Kzz => c(K, Z, Z),
        }
    }
}

impl TryFrom<ModelParameter> for Parameter {
    type Error = DescriptionError;

    /// The [`Parameter`] of the same name; an error for the parameters it has no name for
    /// (the refinement's u_c, u_s, the initial state, the finite-element rotor's).
    fn try_from(p: ModelParameter) -> Result<Self, Self::Error> {
        Parameter::ALL
            .into_iter()
            .find(|&q| ModelParameter::from(q) == p)
            .ok_or_else(|| DescriptionError::NoCounterpart {
                name: p.name().into_owned(),
                vocabulary: "Parameter",
            })
    }
}

impl From<FeParameter> for ModelParameter {
    fn from(p: FeParameter) -> Self {
        match p {
            FeParameter::Bearing { index, coefficient } => {
                ModelParameter::Bearing { index, coefficient }
            }
            FeParameter::Mud { index } => ModelParameter::UnbalanceMud { index },
            FeParameter::Alpha { index } => ModelParameter::UnbalanceAlpha { index },
        }
    }
}

impl TryFrom<ModelParameter> for FeParameter {
    type Error = DescriptionError;

    /// The [`FeParameter`] of the same name; an error for every other parameter.
    fn try_from(p: ModelParameter) -> Result<Self, Self::Error> {
        match p {
            ModelParameter::Bearing { index, coefficient } => {
                Ok(FeParameter::Bearing { index, coefficient })
            }
            ModelParameter::UnbalanceMud { index } => Ok(FeParameter::Mud { index }),
            ModelParameter::UnbalanceAlpha { index } => Ok(FeParameter::Alpha { index }),
            _ => Err(DescriptionError::NoCounterpart {
                name: p.name().into_owned(),
                vocabulary: "FeParameter",
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::finite_element::DofKind;

    #[test]
    fn every_parameter_name_maps_and_round_trips() {
        for p in Parameter::ALL {
            let q = ModelParameter::from(p);
            assert_eq!(q.name(), p.name(), "{p:?}");
            assert_eq!(q.unit(), p.unit(), "{p}");
            assert_eq!(q.sign(), p.sign(), "{p}");
            assert_eq!(q.description(), p.description(), "{p}");
            assert_eq!(q.kind(), ParameterKind::Physical);
            assert_eq!(Parameter::try_from(q), Ok(p));
            assert_eq!(p.name().parse::<ModelParameter>(), Ok(q));
        }
        // distinct parameters stay distinct (cx and cxx are two names)
        let mut all: Vec<ModelParameter> = Parameter::ALL.map(ModelParameter::from).to_vec();
        all.sort();
        all.dedup();
        assert_eq!(all.len(), Parameter::ALL.len());
    }

    #[test]
    fn every_finite_element_name_maps_and_round_trips() {
        for index in [0, 1, 12] {
            let mut ps: Vec<FeParameter> = BearingCoefficient::ALL
                .map(|coefficient| FeParameter::Bearing { index, coefficient })
                .to_vec();
            ps.extend([FeParameter::Mud { index }, FeParameter::Alpha { index }]);
            for p in ps {
                let q = ModelParameter::from(p);
                assert_eq!(q.name(), p.to_string());
                assert_eq!(q.unit(), p.unit());
                assert_eq!(q.kind(), ParameterKind::Physical);
                assert_eq!(FeParameter::try_from(q), Ok(p));
                assert_eq!(p.to_string().parse::<ModelParameter>(), Ok(q));
                assert!(Parameter::try_from(q).is_err());
            }
        }
        // the ranges FiniteElementRotor::new enforces
        let b = |coefficient| ModelParameter::Bearing {
            index: 0,
            coefficient,
        };
        assert_eq!(b(BearingCoefficient::Kyy).sign(), Sign::Positive);
        assert_eq!(b(BearingCoefficient::Cxx).sign(), Sign::NonNegative);
        assert_eq!(b(BearingCoefficient::Kxy).sign(), Sign::Any);
        assert_eq!(
            ModelParameter::UnbalanceMud { index: 0 }.sign(),
            Sign::NonNegative
        );
    }

    #[test]
    fn refinement_and_nuisance_names_round_trip() {
        let names = [
            "mud_cos_alpha",
            "mud_sin_alpha",
            "x0",
            "z0",
            "vx0",
            "vz0",
            "initial_state.q[0]",
            "initial_state.v[17]",
            "offset.3.x",
            "offset.0.ry",
        ];
        for name in names {
            let p: ModelParameter = name.parse().unwrap();
            assert_eq!(p.name(), name);
            assert!(Parameter::try_from(p).is_err() && FeParameter::try_from(p).is_err());
        }
        assert_eq!(
            "vz0".parse(),
            Ok(ModelParameter::InitialVelocity(Direction::Z))
        );
        let off = ModelParameter::Offset {
            channel: Dof::new(0, DofKind::Ry),
        };
        assert_eq!((off.kind(), off.unit()), (ParameterKind::Nuisance, "rad"));
        assert_eq!(ModelParameter::MudCosAlpha.kind(), ParameterKind::Physical);
        // every name of TWO_DOF is distinct
        for (i, p) in ModelParameter::TWO_DOF.iter().enumerate() {
            assert!(!ModelParameter::TWO_DOF[..i]
                .iter()
                .any(|q| q.name() == p.name()));
        }
    }

    #[test]
    fn bad_names_are_refused_with_what_is_accepted() {
        for bad in [
            "k_x",
            "c_x",
            "kxy",
            "bearing.kxx",
            "bearing-1.kxx",
            "bearing0.kzz",
            "unbalance0.m_u",
            "unbalance+1.mud",
            "offset.3.z",
            "initial_state.q[]",
            "initial_state.q[1",
            "",
        ] {
            match bad.parse::<ModelParameter>() {
                Err(DescriptionError::UnknownName { name, allowed }) => {
                    assert_eq!(name, bad);
                    assert!(allowed.contains("bearing<i>"));
                }
                other => panic!("{bad:?} accepted: {other:?}"),
            }
        }
    }

    #[test]
    fn ranges_are_checked_by_name() {
        let kx: ModelParameter = "kx".parse().unwrap();
        assert_eq!(kx.check(1.0), Ok(1.0));
        let e = kx.check(0.0).unwrap_err();
        assert_eq!(
            e.to_string(),
            "kx = 0 is out of range: must be finite and > 0 (N/m)"
        );
        assert!(ModelParameter::Alpha.check(f64::NAN).is_err());
        assert!(ModelParameter::Alpha.check(-7.0).is_ok());
        assert!("bearing1.cyy"
            .parse::<ModelParameter>()
            .unwrap()
            .check(-1e-9)
            .is_err());
    }
}
