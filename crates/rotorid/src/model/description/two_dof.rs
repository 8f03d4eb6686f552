//! The 2-DOF rotor (docs/method.md sections 1.2 and 1.6) as a [`RotorDescription`]: the
//! Jeffcott and the cross-coupled model are its two cases, told apart by their parameters
//! (the Jeffcott model has no cross terms; they are zero in its matrices).

use nalgebra::{Complex, DMatrix, DVector};

use super::vocabulary::{Direction, ModelParameter, Support};
use super::{check_index, check_length, Derivative, DescriptionError, Matrices, RotorDescription};
use crate::model::{Rotor, RotorParams};
use crate::parameter::{ModelKind, Parameter};

/// How th holds the unbalance.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UnbalanceCoordinates {
    /// `mud`, `alpha`: m_u d \[kg m\] and its angle \[rad\], the published pair (the load
    /// does not depend on alpha at m_u d = 0).
    #[default]
    Polar,
    /// `mud_cos_alpha`, `mud_sin_alpha`: u_c, u_s \[kg m\], in which the load is linear and
    /// regular at m_u d = 0 (the refinement's pair).
    Cartesian,
}

/// Where a parameter enters the 2-DOF equation.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Role {
    Mass,
    /// Entry (row, column) of C or K.
    Support(Support, usize, usize),
    Gyroscopic,
    Mud,
    Alpha,
    CosPart,
    SinPart,
}

fn role(p: ModelParameter) -> Option<Role> {
    Some(match p {
        ModelParameter::Mass => Role::Mass,
        ModelParameter::Direct { support, direction } => {
            Role::Support(support, direction.index(), direction.index())
        }
        ModelParameter::Coupled {
            support,
            row,
            column,
        } => Role::Support(support, row.index(), column.index()),
        ModelParameter::Gyroscopic => Role::Gyroscopic,
        ModelParameter::Mud => Role::Mud,
        ModelParameter::Alpha => Role::Alpha,
        ModelParameter::MudCosAlpha => Role::CosPart,
        ModelParameter::MudSinAlpha => Role::SinPart,
        _ => return None,
    })
}

/// The 2-DOF rotor's description (module doc of `super`): q = (x, z) \[m\], both measured.
#[derive(Debug, Clone, PartialEq)]
pub struct TwoDofRotor {
    model: ModelKind,
    unbalance: UnbalanceCoordinates,
    parameters: Vec<ModelParameter>,
    roles: Vec<Role>,
    /// The rotor the description was made from: th's values, and d for m_u d.
    params: RotorParams,
    nominal: DVector<f64>,
    channels: Vec<String>,
    output: DMatrix<f64>,
}

/// The unbalance's direction vector (-i, 1): P = m_u d e^{i alpha} (-i, 1).
fn shape() -> DVector<Complex<f64>> {
    DVector::from_vec(vec![Complex::new(0.0, -1.0), Complex::new(1.0, 0.0)])
}

/// The matrix with a single 1 at (r, c).
fn unit(r: usize, c: usize) -> DMatrix<f64> {
    let mut e = DMatrix::zeros(2, 2);
    e[(r, c)] = 1.0;
    e
}

impl TwoDofRotor {
    /// The description of `rotor`'s model (Jeffcott or cross-coupled,
    /// [`Rotor::model`]), th = its parameters in [`ModelKind::parameters`]' order.
    pub fn new(rotor: &Rotor) -> Self {
        Self::with_unbalance(rotor, UnbalanceCoordinates::Polar)
    }

    /// As [`TwoDofRotor::new`] with the unbalance in `unbalance`'s coordinates.
    pub fn with_unbalance(rotor: &Rotor, unbalance: UnbalanceCoordinates) -> Self {
        let model = rotor.model();
        let parameters: Vec<ModelParameter> = model
            .parameters()
            .iter()
            .map(|&p| match (unbalance, p) {
                (UnbalanceCoordinates::Cartesian, Parameter::Mud) => ModelParameter::MudCosAlpha,
                (UnbalanceCoordinates::Cartesian, Parameter::Alpha) => ModelParameter::MudSinAlpha,
                _ => ModelParameter::from(p),
            })
            .collect();
        let roles = parameters
            .iter()
            .map(|&p| role(p).expect("every parameter of a ModelKind has a role"))
            .collect();
        let mut s = Self {
            model,
            unbalance,
            parameters,
            roles,
            params: rotor.params(),
            nominal: DVector::zeros(0),
            channels: vec![
                Direction::X.name().to_owned(),
                Direction::Z.name().to_owned(),
            ],
            output: DMatrix::identity(2, 2),
        };
        s.nominal = s.theta(&rotor.params());
        s
    }

    /// The model: Jeffcott or cross-coupled.
    pub fn model(&self) -> ModelKind {
        self.model
    }

    /// How th holds the unbalance.
    pub fn unbalance(&self) -> UnbalanceCoordinates {
        self.unbalance
    }

    /// th of `p` (m_u d and alpha, or u_c and u_s, from its unbalance; cross terms 0 for a
    /// Jeffcott `p` in the cross-coupled model).
    pub fn theta(&self, p: &RotorParams) -> DVector<f64> {
        let (mud, alpha) = (p.unbalance.mud(), p.unbalance.alpha);
        DVector::from_iterator(
            self.parameters.len(),
            self.parameters.iter().map(|&q| match q {
                ModelParameter::MudCosAlpha => mud * alpha.cos(),
                ModelParameter::MudSinAlpha => mud * alpha.sin(),
                ModelParameter::Coupled { row, column, .. } if row != column => {
                    let q = Parameter::try_from(q).expect("a 2-DOF parameter");
                    p.get(q).unwrap_or(0.0)
                }
                _ => {
                    let q = Parameter::try_from(q).expect("a 2-DOF parameter");
                    p.get(q)
                        .expect("every model parameter but a cross term is in RotorParams")
                }
            }),
        )
    }

    /// The rotor parameters at `theta` (the unbalance's radius d of the nominal rotor
    /// kept, [`RotorParams::set`]); unchecked: [`Rotor::new`] validates them.
    pub fn rotor_params(&self, theta: &DVector<f64>) -> Result<RotorParams, DescriptionError> {
        check_length(theta, self.parameters.len())?;
        let mut p = self.params;
        let (mut uc, mut us) = (0.0, 0.0);
        for (&q, &v) in self.parameters.iter().zip(theta.iter()) {
            match q {
                ModelParameter::MudCosAlpha => uc = v,
                ModelParameter::MudSinAlpha => us = v,
                _ => p.set(Parameter::try_from(q)?, v),
            }
        }
        if self.unbalance == UnbalanceCoordinates::Cartesian {
            p.set(Parameter::Mud, uc.hypot(us));
            p.set(Parameter::Alpha, us.atan2(uc));
        }
        Ok(p)
    }
}

/// The values of the 2-DOF equation at one th.
struct Values {
    m: f64,
    c: [[f64; 2]; 2],
    k: [[f64; 2]; 2],
    a: f64,
    /// m_u d e^{i alpha}.
    u: Complex<f64>,
    /// alpha \[rad\] (th's own entry in polar coordinates: u has no angle at m_u d = 0).
    alpha: f64,
}

impl TwoDofRotor {
    fn values(&self, theta: &DVector<f64>) -> Result<Values, DescriptionError> {
        check_length(theta, self.parameters.len())?;
        let mut v = Values {
            m: 0.0,
            c: [[0.0; 2]; 2],
            k: [[0.0; 2]; 2],
            a: 0.0,
            u: Complex::new(0.0, 0.0),
            alpha: 0.0,
        };
        let mut mud = 0.0;
        for (&r, &x) in self.roles.iter().zip(theta.iter()) {
            match r {
                Role::Mass => v.m = x,
                Role::Support(Support::Damping, i, j) => v.c[i][j] = x,
                Role::Support(Support::Stiffness, i, j) => v.k[i][j] = x,
                Role::Gyroscopic => v.a = x,
                Role::Mud => mud = x,
                Role::Alpha => v.alpha = x,
                Role::CosPart => v.u.re = x,
                Role::SinPart => v.u.im = x,
            }
        }
        match self.unbalance {
            UnbalanceCoordinates::Polar => v.u = Complex::from_polar(mud, v.alpha),
            UnbalanceCoordinates::Cartesian => v.alpha = v.u.arg(),
        }
        Ok(v)
    }
}

impl RotorDescription for TwoDofRotor {
    fn parameters(&self) -> &[ModelParameter] {
        &self.parameters
    }

    fn nominal(&self) -> &DVector<f64> {
        &self.nominal
    }

    fn coordinates(&self) -> usize {
        2
    }

    fn channels(&self) -> &[String] {
        &self.channels
    }

    fn output_map(&self) -> &DMatrix<f64> {
        &self.output
    }

    fn matrices(&self, theta: &DVector<f64>) -> Result<Matrices, DescriptionError> {
        let v = self.values(theta)?;
        let m2 =
            |a: [[f64; 2]; 2]| DMatrix::from_row_slice(2, 2, &[a[0][0], a[0][1], a[1][0], a[1][1]]);
        Ok(Matrices {
            mass: DMatrix::identity(2, 2) * v.m,
            damping: m2(v.c),
            gyroscopic: m2([[0.0, -v.a], [v.a, 0.0]]),
            stiffness: m2(v.k),
            acceleration: m2([[0.0, -v.a], [0.0, 0.0]]),
        })
    }

    fn load(&self, theta: &DVector<f64>) -> Result<DVector<Complex<f64>>, DescriptionError> {
        let u = self.values(theta)?.u;
        Ok(shape() * u)
    }

    fn derivative(&self, theta: &DVector<f64>, j: usize) -> Result<Derivative, DescriptionError> {
        check_index(j, self.parameters.len())?;
        let v = self.values(theta)?;
        let mut d = Derivative::default();
        match self.roles[j] {
            Role::Mass => d.mass = Some(DMatrix::identity(2, 2)),
            Role::Support(Support::Damping, r, c) => d.damping = Some(unit(r, c)),
            Role::Support(Support::Stiffness, r, c) => d.stiffness = Some(unit(r, c)),
            Role::Gyroscopic => {
                d.gyroscopic = Some(unit(1, 0) - unit(0, 1));
                d.acceleration = Some(-unit(0, 1));
            }
            // P = mud e^{i alpha} (-i, 1)
            Role::Mud => d.load = Some(shape() * Complex::from_polar(1.0, v.alpha)),
            Role::Alpha => d.load = Some(shape() * (Complex::<f64>::i() * v.u)),
            // P = (u_c + i u_s) (-i, 1)
            Role::CosPart => d.load = Some(shape()),
            Role::SinPart => d.load = Some(shape() * Complex::<f64>::i()),
        }
        Ok(d)
    }
}
