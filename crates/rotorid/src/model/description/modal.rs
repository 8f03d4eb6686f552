//! A modal model as a [`RotorDescription`]: n uncoupled modes, each a single degree of
//! freedom per unit modal mass, for what a transient record shows of a machine whose
//! matrices are not known (docs/transient.md section 6):
//!
//! ```text
//! q_j'' + c_j q_j' + k_j q_j = Re( (w^2 - i w') e^{i phi} ),     k_j = w_j^2,  c_j = 2 zeta_j w_j
//! ```
//!
//! so M = I, C = diag(c), K = diag(k), G = Ka = 0, P = (1, .., 1) and H = I: each mode's
//! response to a unit unbalance, its channel `mode<j>`. How much of each mode a probe
//! sees, and at which angle (the product of the mode's unbalance and its shape at the
//! probe), is not part of th: it enters the probe's signal linearly and a fit solves for
//! it (variable projection). th = (mode0.k, mode0.c, mode1.k, ...) \[1/s^2, 1/s\], in
//! which every matrix is affine, as the trait's module asks.
//!
//! The modes do not change with speed (no gyroscopic stiffening) and each whirls with the
//! unbalance's force: a rigid-bearing rotor's backward modes, which unbalance does not
//! excite, are not in it.

use nalgebra::{Complex, DMatrix, DVector};

use super::vocabulary::ModelParameter;
use super::{check_index, check_length, Derivative, DescriptionError, Matrices, RotorDescription};

/// One mode: its undamped natural frequency and damping ratio.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mode {
    /// Undamped natural frequency w \[rad/s\], finite and > 0.
    pub omega: f64,
    /// Damping ratio zeta \[-\], finite and >= 0.
    pub zeta: f64,
}

/// The modal description (module doc).
#[derive(Debug, Clone, PartialEq)]
pub struct ModalDescription {
    parameters: Vec<ModelParameter>,
    nominal: DVector<f64>,
    channels: Vec<String>,
    output: DMatrix<f64>,
}

impl ModalDescription {
    /// The description of `modes`, th their (k, c) in order; an error naming the first
    /// frequency or damping ratio out of its range, or no mode at all.
    pub fn new(modes: &[Mode]) -> Result<Self, DescriptionError> {
        if modes.is_empty() {
            return Err(DescriptionError::NoModes);
        }
        let n = modes.len();
        let parameters = (0..n)
            .flat_map(|mode| {
                [
                    ModelParameter::ModalStiffness { mode },
                    ModelParameter::ModalDamping { mode },
                ]
            })
            .collect();
        let s = Self {
            parameters,
            nominal: DVector::zeros(2 * n),
            channels: (0..n).map(|j| format!("mode{j}")).collect(),
            output: DMatrix::identity(n, n),
        };
        let nominal = Self::theta(modes);
        s.validate(&nominal)?;
        Ok(Self { nominal, ..s })
    }

    /// th = (w_0^2, 2 zeta_0 w_0, w_1^2, ...) of `modes`.
    pub fn theta(modes: &[Mode]) -> DVector<f64> {
        DVector::from_iterator(
            2 * modes.len(),
            modes
                .iter()
                .flat_map(|m| [m.omega * m.omega, 2.0 * m.zeta * m.omega]),
        )
    }

    /// The modes of th (w = sqrt(k), zeta = c / (2 w)); None where k <= 0.
    pub fn modes(theta: &DVector<f64>) -> Vec<Option<Mode>> {
        theta
            .as_slice()
            .chunks(2)
            .map(|kc| {
                (kc[0] > 0.0).then(|| {
                    let omega = kc[0].sqrt();
                    Mode {
                        omega,
                        zeta: kc[1] / (2.0 * omega),
                    }
                })
            })
            .collect()
    }

    /// The number of modes.
    pub fn len(&self) -> usize {
        self.channels.len()
    }

    /// Always false: a modal description has at least one mode.
    pub fn is_empty(&self) -> bool {
        false
    }
}

fn diagonal(theta: &DVector<f64>, offset: usize) -> DMatrix<f64> {
    let n = theta.len() / 2;
    DMatrix::from_diagonal(&DVector::from_iterator(
        n,
        (0..n).map(|j| theta[2 * j + offset]),
    ))
}

impl RotorDescription for ModalDescription {
    fn parameters(&self) -> &[ModelParameter] {
        &self.parameters
    }

    fn nominal(&self) -> &DVector<f64> {
        &self.nominal
    }

    fn coordinates(&self) -> usize {
        self.len()
    }

    fn channels(&self) -> &[String] {
        &self.channels
    }

    fn output_map(&self) -> &DMatrix<f64> {
        &self.output
    }

    fn matrices(&self, theta: &DVector<f64>) -> Result<Matrices, DescriptionError> {
        check_length(theta, self.parameters.len())?;
        let n = self.len();
        Ok(Matrices {
            mass: DMatrix::identity(n, n),
            damping: diagonal(theta, 1),
            gyroscopic: DMatrix::zeros(n, n),
            stiffness: diagonal(theta, 0),
            acceleration: DMatrix::zeros(n, n),
        })
    }

    fn load(&self, theta: &DVector<f64>) -> Result<DVector<Complex<f64>>, DescriptionError> {
        check_length(theta, self.parameters.len())?;
        Ok(DVector::from_element(self.len(), Complex::new(1.0, 0.0)))
    }

    fn derivative(&self, theta: &DVector<f64>, j: usize) -> Result<Derivative, DescriptionError> {
        check_length(theta, self.parameters.len())?;
        check_index(j, self.parameters.len())?;
        let n = self.len();
        let mut e = DMatrix::zeros(n, n);
        e[(j / 2, j / 2)] = 1.0;
        Ok(if j.is_multiple_of(2) {
            Derivative {
                stiffness: Some(e),
                ..Derivative::default()
            }
        } else {
            Derivative {
                damping: Some(e),
                ..Derivative::default()
            }
        })
    }
}
