//! A finite-element rotor (docs/finite_element.md) as a [`RotorDescription`], in full
//! coordinates or reduced to a basis T (q_phys = T q): the shaft's matrices projected
//! once, the bearings and unbalances entering through their nodes' location vectors, so
//! the reduced description is exact in the bearing coefficients (module doc of `super`).

use nalgebra::{Complex, DMatrix, DVector};

use super::vocabulary::ModelParameter;
use super::{check_index, check_length, Derivative, DescriptionError, Matrices, RotorDescription};
use crate::model::finite_element::{
    BearingCoefficient, Dof, DofKind, FeParameter, FiniteElementError, FiniteElementRotor,
};

/// Where a parameter enters: a bearing's coefficient or an unbalance's size or angle.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Role {
    Bearing(usize, BearingCoefficient),
    Mud(usize),
    Alpha(usize),
}

/// A finite-element rotor's description (module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct FiniteElementDescription {
    parameters: Vec<ModelParameter>,
    roles: Vec<Role>,
    nominal: DVector<f64>,
    /// T, None for the full model.
    basis: Option<DMatrix<f64>>,
    m: DMatrix<f64>,
    /// The shaft's C (zero when the matrices have none).
    c: DMatrix<f64>,
    g: DMatrix<f64>,
    /// The shaft's K.
    k: DMatrix<f64>,
    /// Ka (zero when the matrices have none).
    ka: DMatrix<f64>,
    /// (b_x, b_y) of each bearing's node.
    bearing_at: Vec<[DVector<f64>; 2]>,
    /// (b_x, b_y) of each unbalance's node.
    unbalance_at: Vec<[DVector<f64>; 2]>,
    channels: Vec<String>,
    output: DMatrix<f64>,
}

impl FiniteElementDescription {
    /// The full model of `rotor` (q = the matrices' degrees of freedom) measured at
    /// `outputs`; th = [`FeParameter::all`] at the rotor's values.
    pub fn full(rotor: &FiniteElementRotor, outputs: &[Dof]) -> Result<Self, DescriptionError> {
        Self::build(rotor, None, outputs)
    }

    /// `rotor` reduced to `basis` (T: n x r, independent columns; e.g. a
    /// [`RitzBasis`](crate::model::finite_element::RitzBasis)'s matrix): every matrix
    /// T^T X T (M symmetrised), every location vector T^T b, H = the rows of T at
    /// `outputs`.
    pub fn reduced(
        rotor: &FiniteElementRotor,
        basis: &DMatrix<f64>,
        outputs: &[Dof],
    ) -> Result<Self, DescriptionError> {
        Self::build(rotor, Some(basis), outputs)
    }

    fn build(
        rotor: &FiniteElementRotor,
        basis: Option<&DMatrix<f64>>,
        outputs: &[Dof],
    ) -> Result<Self, DescriptionError> {
        let mats = &rotor.matrices;
        let n = mats.n();
        let index = |d: Dof| {
            mats.index(d).ok_or_else(|| FiniteElementError::UnknownDof {
                name: d.to_string(),
                n,
            })
        };
        // the location vector of physical degree of freedom i: e_i, or row i of T
        let at = |i: usize| match basis {
            None => {
                let mut e = DVector::zeros(n);
                e[i] = 1.0;
                e
            }
            Some(t) => t.row(i).transpose(),
        };
        let node = |node: u32| -> Result<[DVector<f64>; 2], DescriptionError> {
            Ok([
                at(index(Dof::new(node, DofKind::X))?),
                at(index(Dof::new(node, DofKind::Y))?),
            ])
        };
        let zero = DMatrix::zeros(n, n);
        let (m, c, g, k, ka) = (
            mats.m().clone(),
            mats.c().cloned().unwrap_or_else(|| zero.clone()),
            mats.g().clone(),
            mats.k().clone(),
            mats.ka().cloned().unwrap_or(zero),
        );
        let (m, c, g, k, ka) = match basis {
            None => (m, c, g, k, ka),
            Some(t) => {
                let bad = || DescriptionError::Basis {
                    rows: t.nrows(),
                    cols: t.ncols(),
                    n,
                };
                if t.nrows() != n || t.ncols() == 0 {
                    return Err(bad());
                }
                let tt = t.transpose();
                let proj = |a: &DMatrix<f64>| &tt * a * t;
                let mr = proj(&m);
                let mr = (&mr + mr.transpose()) * 0.5;
                if !independent(&mr) {
                    return Err(bad());
                }
                (mr, proj(&c), proj(&g), proj(&k), proj(&ka))
            }
        };
        let mut rows = Vec::with_capacity(outputs.len());
        for &d in outputs {
            rows.push(at(index(d)?).transpose());
        }
        let r = m.nrows();
        let output = if rows.is_empty() {
            DMatrix::zeros(0, r)
        } else {
            DMatrix::from_rows(&rows)
        };
        let all = FeParameter::all(rotor);
        let roles = all
            .iter()
            .map(|&p| match p {
                FeParameter::Bearing { index, coefficient } => Role::Bearing(index, coefficient),
                FeParameter::Mud { index } => Role::Mud(index),
                FeParameter::Alpha { index } => Role::Alpha(index),
            })
            .collect();
        let nominal = DVector::from_iterator(
            all.len(),
            all.iter().map(|p| {
                p.get(rotor)
                    .expect("FeParameter::all names the rotor's own")
            }),
        );
        Ok(Self {
            parameters: all.into_iter().map(ModelParameter::from).collect(),
            roles,
            nominal,
            basis: basis.cloned(),
            m,
            c,
            g,
            k,
            ka,
            bearing_at: rotor
                .bearings
                .iter()
                .map(|b| node(b.node))
                .collect::<Result<_, _>>()?,
            unbalance_at: rotor
                .unbalances
                .iter()
                .map(|u| node(u.node))
                .collect::<Result<_, _>>()?,
            channels: outputs.iter().map(Dof::to_string).collect(),
            output,
        })
    }

    /// T (q_phys = T q), None for the full model.
    pub fn basis(&self) -> Option<&DMatrix<f64>> {
        self.basis.as_ref()
    }

    /// b_x - i b_y of unbalance `j`'s node: P = sum_j mud_j e^{i alpha_j} (b_x - i b_y).
    fn unbalance_shape(&self, j: usize) -> DVector<Complex<f64>> {
        let [bx, by] = &self.unbalance_at[j];
        DVector::from_fn(bx.len(), |i, _| Complex::new(bx[i], -by[i]))
    }
}

impl RotorDescription for FiniteElementDescription {
    fn parameters(&self) -> &[ModelParameter] {
        &self.parameters
    }

    fn nominal(&self) -> &DVector<f64> {
        &self.nominal
    }

    fn coordinates(&self) -> usize {
        self.m.nrows()
    }

    fn channels(&self) -> &[String] {
        &self.channels
    }

    fn output_map(&self) -> &DMatrix<f64> {
        &self.output
    }

    fn matrices(&self, theta: &DVector<f64>) -> Result<Matrices, DescriptionError> {
        check_length(theta, self.parameters.len())?;
        let (mut c, mut k) = (self.c.clone(), self.k.clone());
        for (&role, &v) in self.roles.iter().zip(theta.iter()) {
            if let Role::Bearing(b, coefficient) = role {
                let (i, j) = coefficient.entry();
                let at = &self.bearing_at[b];
                let target = if coefficient.is_stiffness() {
                    &mut k
                } else {
                    &mut c
                };
                target.ger(v, &at[i], &at[j], 1.0);
            }
        }
        Ok(Matrices {
            mass: self.m.clone(),
            damping: c,
            gyroscopic: self.g.clone(),
            stiffness: k,
            acceleration: self.ka.clone(),
        })
    }

    fn load(&self, theta: &DVector<f64>) -> Result<DVector<Complex<f64>>, DescriptionError> {
        check_length(theta, self.parameters.len())?;
        let mut p = DVector::zeros(self.coordinates());
        for u in 0..self.unbalance_at.len() {
            let a = Complex::from_polar(theta[self.mud_index(u)], theta[self.alpha_index(u)]);
            p += self.unbalance_shape(u) * a;
        }
        Ok(p)
    }

    fn derivative(&self, theta: &DVector<f64>, j: usize) -> Result<Derivative, DescriptionError> {
        check_length(theta, self.parameters.len())?;
        check_index(j, self.parameters.len())?;
        let mut d = Derivative::default();
        match self.roles[j] {
            Role::Bearing(b, coefficient) => {
                let (r, c) = coefficient.entry();
                let at = &self.bearing_at[b];
                let e = &at[r] * at[c].transpose();
                if coefficient.is_stiffness() {
                    d.stiffness = Some(e);
                } else {
                    d.damping = Some(e);
                }
            }
            Role::Mud(u) => {
                let alpha = theta[self.alpha_index(u)];
                d.load = Some(self.unbalance_shape(u) * Complex::from_polar(1.0, alpha));
            }
            Role::Alpha(u) => {
                let mud = theta[self.mud_index(u)];
                let a = Complex::<f64>::i() * Complex::from_polar(mud, theta[j]);
                d.load = Some(self.unbalance_shape(u) * a);
            }
        }
        Ok(d)
    }
}

/// Smallest over largest diagonal entry of the Cholesky factor below which T^T M T counts
/// as singular (its condition number above about 1e12): the basis has (nearly) dependent
/// columns. Above rounding: a factor of exactly dependent columns has its entry at about
/// sqrt(machine epsilon) = 1.5e-8 or fails.
const DEPENDENT: f64 = 1e-6;

/// True when the symmetric `m` is positive definite with condition number below about
/// 1e12 ([`DEPENDENT`]).
fn independent(m: &DMatrix<f64>) -> bool {
    m.clone().cholesky().is_some_and(|c| {
        let d = c.l_dirty().diagonal();
        d.min() > DEPENDENT * d.max()
    })
}

impl FiniteElementDescription {
    fn mud_index(&self, u: usize) -> usize {
        self.roles
            .iter()
            .position(|&r| r == Role::Mud(u))
            .expect("every unbalance has its mud")
    }

    fn alpha_index(&self, u: usize) -> usize {
        self.roles
            .iter()
            .position(|&r| r == Role::Alpha(u))
            .expect("every unbalance has its alpha")
    }
}
