//! Finite-element rotors: the shaft and disks come as matrices, the bearings and
//! the unbalances as parameters. The equation of motion, in the frame of the matrices file
//! (nodes along +z, the shaft turning from +x towards +y; docs/finite_element.md):
//!
//! ```text
//! M q'' + (C + C_b + phi' G) q' + (K + K_b + phi'' Ka) q = F(phi, phi', phi'')
//! ```
//!
//! with q the degrees of freedom named by [`Dof`] (`<node>.<dof>`, dof one of x, y, rx,
//! ry), each bearing adding `[[kxx, kxy], [kyx, kyy]]` to K_b and `[[cxx, cxy], [cyx,
//! cyy]]` to C_b at its node's (x, y) (its restoring force is `-K_b q - C_b q'`, as in
//! ROSS), and each unbalance the force at its node's (x, y)
//!
//! ```text
//! m_u d (phi'^2 cos(phi + alpha) + phi'' sin(phi + alpha),
//!        phi'^2 sin(phi + alpha) - phi'' cos(phi + alpha))
//! ```
//!
//! This module holds the vocabulary every part of the finite-element work shares: the
//! degrees of freedom, the matrices, the bearings, the unbalances and the parameters that
//! name them (`bearing<i>.kxx`, `unbalance<j>.mud`, ...); the assembled equation of motion
//! in full or reduced coordinates with its derivatives and closed-form steady state
//! ([`FeSystem`]); and the reduction ([`RitzBasis`]). Every quantity is SI.

mod error;
mod parameter;
mod reduction;
mod rotor;
mod rows;
mod system;

pub use error::FiniteElementError;
pub use parameter::{BearingCoefficient, FeParameter};
pub use reduction::RitzBasis;
pub use rotor::{Bearing, Dof, DofKind, FeMatrices, FeUnbalance, FiniteElementRotor};
pub(crate) use system::force_of;
pub use system::{FeDerivative, FeSystem};
