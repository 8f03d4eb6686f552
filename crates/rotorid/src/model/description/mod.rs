//! The rotor model as data: for a parameter vector theta, the matrices and the unbalance
//! load of the equation of motion, the measured degrees of freedom, and the derivative of
//! each with respect to each parameter ([`RotorDescription`]); and the one vocabulary that
//! names those parameters ([`ModelParameter`]).
//!
//! Every instance means the same equation:
//!
//! ```text
//! M(th) q'' + (C(th) + phi' G(th)) q' + (K(th) + phi'' Ka(th)) q = f(th; phi, phi', phi'')
//!
//! f = Re( (phi'^2 - i phi'') e^{i phi} P(th) )
//! y = H q
//! ```
//!
//! with q the coordinates (m on a displacement, rad on a rotation; a reduced system's
//! coordinates are its basis's, q_phys = T q), phi the shaft angle \[rad\], phi' = w
//! \[rad/s\], phi'' = w' \[rad/s^2\]; M \[kg\] (kg m^2 on rotations), C \[N s/m\], G \[N s^2/m =
//! kg\] (multiplied by phi'), K \[N/m\], Ka \[kg\] (multiplied by phi''), P the complex
//! unbalance load \[kg m\] (f per w^2 at w' = 0, in the phase of e^{i phi}), f \[N\], and H
//! the map from q to the measured channels y. Each matrix is affine in th, and P is linear
//! in each unbalance's m_u d; so the derivatives ([`Derivative`]) are constant matrices
//! and load vectors.
//!
//! The instances:
//!
//! - [`TwoDofRotor`], the paper's rotor (docs/method.md sections 1.2 and 1.6), q = (x, z)
//!   \[m\], th the parameters of its [`ModelKind`](crate::parameter::ModelKind) (Jeffcott:
//!   m, cx, kx, cz, kz, a, mud, alpha; cross-coupled: m, cxx, cxz, czx, czz, kxx, kxz, kzx,
//!   kzz, a, mud, alpha; or with u_c, u_s for mud, alpha, [`UnbalanceCoordinates`]):
//!
//!   ```text
//!   M = m I,   C = [[cx, cxz], [czx, cz]],   G = [[0, -a], [a, 0]],
//!   K = [[kx, kxz], [kzx, kz]],   Ka = [[0, -a], [0, 0]],
//!   P = m_u d e^{i alpha} (-i, 1),   H = I
//!   ```
//!
//!   so f = m_u d (w^2 sin(phi + alpha) - w' cos(phi + alpha), w' sin(phi + alpha) + w^2
//!   cos(phi + alpha)), eq. (1) of the paper as `Rotor::unbalance_force` computes it.
//! - [`FiniteElementDescription`], a finite-element rotor (docs/finite_element.md), full
//!   or reduced to a basis T: M, G, Ka and the shaft's C, K from the matrices file
//!   (projected, T^T X T), each bearing adding sum_rs k_rs b_r b_s^T to K and likewise to
//!   C, each unbalance mud e^{i alpha} (b_x - i b_y) to P, b_x, b_y the location vectors
//!   of its node's x and y (T^T e_x, T^T e_y when reduced); th the rotor's bearing
//!   coefficients then unbalances (`bearing<i>.kxx`, ..., `unbalance<j>.alpha`).
//!
//! - [`ModalDescription`], n uncoupled modes per unit modal mass (q_j'' + c_j q_j' + k_j q_j
//!   = Re((w^2 - i w') e^{i phi})), th = (mode0.k, mode0.c, ...) \[1/s^2, 1/s\]: the model
//!   the transient analysis fits to a run-up's order-tracked vectors.
//!
//! The form follows diffsol's `OdeEquations` (a problem states its right-hand side, mass
//! and parameter sensitivities once, and every solver uses them) and ROSS's
//! `rotor_assembly` (M, C, K, G assembled from elements and bearings at their nodes'
//! degrees of freedom).

mod error;
mod finite_element;
mod modal;
mod two_dof;
mod vocabulary;

use nalgebra::{Complex, DMatrix, DVector};

pub use error::DescriptionError;
pub use finite_element::FiniteElementDescription;
pub use modal::{ModalDescription, Mode};
pub use two_dof::{TwoDofRotor, UnbalanceCoordinates};
pub use vocabulary::{Direction, ModelParameter, ParameterKind, Support, ACCEPTED_NAMES};

use crate::model::SpeedState;

/// The matrices of the equation of motion at one th (module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct Matrices {
    /// M \[kg; kg m^2 on rotations\].
    pub mass: DMatrix<f64>,
    /// C, the speed-independent damping \[N s/m\].
    pub damping: DMatrix<f64>,
    /// G, multiplied by phi' \[N s^2/m\].
    pub gyroscopic: DMatrix<f64>,
    /// K, the stiffness at phi'' = 0 \[N/m\].
    pub stiffness: DMatrix<f64>,
    /// Ka, multiplied by phi'' \[kg\] (zero when the model has none).
    pub acceleration: DMatrix<f64>,
}

impl Matrices {
    /// C + w G at speed `w` \[rad/s\].
    pub fn damping_at(&self, w: f64) -> DMatrix<f64> {
        &self.damping + &self.gyroscopic * w
    }

    /// K + w' Ka at angular acceleration `w_dot` \[rad/s^2\].
    pub fn stiffness_at(&self, w_dot: f64) -> DMatrix<f64> {
        &self.stiffness + &self.acceleration * w_dot
    }
}

/// The derivative of the equation of motion with respect to one parameter: each matrix's
/// and the load's, `None` where it does not depend on the parameter (module doc; units:
/// the matrix's or the load's per unit of the parameter).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Derivative {
    /// dM / dth_j.
    pub mass: Option<DMatrix<f64>>,
    /// dC / dth_j.
    pub damping: Option<DMatrix<f64>>,
    /// dG / dth_j.
    pub gyroscopic: Option<DMatrix<f64>>,
    /// dK / dth_j.
    pub stiffness: Option<DMatrix<f64>>,
    /// dKa / dth_j.
    pub acceleration: Option<DMatrix<f64>>,
    /// dP / dth_j: the force's derivative is `unbalance_force(dP, s)`.
    pub load: Option<DVector<Complex<f64>>>,
}

/// f = Re((w^2 - i w') e^{i phi} P) \[N\] for the load `load` \[kg m\] at the rotor state `s`.
pub fn unbalance_force(load: &DVector<Complex<f64>>, s: &SpeedState) -> DVector<f64> {
    let z = Complex::new(s.omega * s.omega, -s.omega_dot) * Complex::from_polar(1.0, s.phi);
    load.map(|p| (p * z).re)
}

/// A rotor model as data (module doc): its parameters th, the matrices and the unbalance
/// load at any th, the measured channels, and the derivatives.
pub trait RotorDescription {
    /// The parameters th, in the order of its entries.
    fn parameters(&self) -> &[ModelParameter];

    /// th of the rotor the description was made from.
    fn nominal(&self) -> &DVector<f64>;

    /// The number of coordinates q.
    fn coordinates(&self) -> usize;

    /// The measured channels' names (`x`, `z`; `<node>.<dof>`), one per row of
    /// [`RotorDescription::output_map`].
    fn channels(&self) -> &[String];

    /// H: y = H q, one row per channel.
    fn output_map(&self) -> &DMatrix<f64>;

    /// M, C, G, K, Ka at `theta`.
    fn matrices(&self, theta: &DVector<f64>) -> Result<Matrices, DescriptionError>;

    /// The unbalance load P at `theta` \[kg m\].
    fn load(&self, theta: &DVector<f64>) -> Result<DVector<Complex<f64>>, DescriptionError>;

    /// The derivative of the matrices and the load with respect to parameter `j` at
    /// `theta`.
    fn derivative(&self, theta: &DVector<f64>, j: usize) -> Result<Derivative, DescriptionError>;

    /// The unbalance force f at `theta` and the rotor state `s` \[N\].
    fn force(
        &self,
        theta: &DVector<f64>,
        s: &SpeedState,
    ) -> Result<DVector<f64>, DescriptionError> {
        Ok(unbalance_force(&self.load(theta)?, s))
    }

    /// The position of `p` in th, if the model has it.
    fn index_of(&self, p: ModelParameter) -> Option<usize> {
        self.parameters().iter().position(|&q| q == p)
    }

    /// The position in th of the parameter called `name`; an error naming what the model
    /// has when it has no such parameter.
    fn index_by_name(&self, name: &str) -> Result<usize, DescriptionError> {
        let p: ModelParameter = name.parse()?;
        self.index_of(p)
            .ok_or_else(|| DescriptionError::NotInModel {
                name: name.to_owned(),
                allowed: self
                    .parameters()
                    .iter()
                    .map(|p| p.name())
                    .collect::<Vec<_>>()
                    .join(", "),
            })
    }

    /// `theta` if it has one entry per parameter, each in its allowed range
    /// ([`ModelParameter::check`]), else the first error.
    fn validate(&self, theta: &DVector<f64>) -> Result<(), DescriptionError> {
        check_length(theta, self.parameters().len())?;
        for (p, &v) in self.parameters().iter().zip(theta.iter()) {
            p.check(v)?;
        }
        Ok(())
    }
}

/// An error unless `theta` has `n` entries.
fn check_length(theta: &DVector<f64>, n: usize) -> Result<(), DescriptionError> {
    if theta.len() == n {
        Ok(())
    } else {
        Err(DescriptionError::ThetaLength {
            expected: n,
            got: theta.len(),
        })
    }
}

/// An error unless `j` < `n`.
fn check_index(j: usize, n: usize) -> Result<(), DescriptionError> {
    if j < n {
        Ok(())
    } else {
        Err(DescriptionError::ParameterIndex { index: j, len: n })
    }
}

#[cfg(test)]
mod tests;
