//! The rotor-bearing models. First the one of Barredo et al. (2024), eq. (1): a 2-DOF
//! Jeffcott rotor (Lalanne & Ferraris' "simple rotor") with gyroscopic coupling, driven
//! by unbalance; with cross-coupled bearings ([`CrossCoupling`]) its K and C gain
//! off-diagonal terms. Finite-element rotors are in [`finite_element`]; every rotor can be
//! written as a [`description::RotorDescription`] (matrices and their derivatives for a
//! parameter vector), which the transient's mode fit already uses.
//!
//! ```text
//! M q'' + C(w) q' + K(w') q = F(t),     q = (x, z)  [m]
//! M = m I
//! C(w)  = diag(cx, cz) + w  [[0, -a], [a, 0]]        (C1 + w C2)
//! K(w') = diag(kx, kz) + w' [[0, -a], [0, 0]]        (K1 + w' K2)
//! F     = m_u d ( w^2 sin(phi+alpha) - w' cos(phi+alpha),
//!                 w' sin(phi+alpha) + w^2 cos(phi+alpha) )
//! ```
//!
//! with phi(t) the rotor angle, w = phi' and w' = phi'' (see [`SpeedProfile`]).
//! Every quantity is in SI units: kg, N s/m, N/m, N s^2/m, m, rad, s.
//!
//! Reference: E. Barredo Hernández, J. G. Mendoza Larios, L. A. Baltazar Tadeo,
//! S. J. Landa Damas, "Identificación algebraica de los parámetros físicos de un sistema
//! rotor-cojinete simplificado de dos grados de libertad", 2024; M. Lalanne, G. Ferraris,
//! *Rotordynamics prediction in engineering*, 2nd ed., Wiley, 1998.

pub mod description;
mod error;
pub mod finite_element;
mod rotor;
mod scenario;
mod speed;

pub(crate) use error::check;
pub use error::{ModelError, OutOfRange};
pub use rotor::{unbalance_force_from, CrossCoupling, Rotor, RotorParams, Unbalance};
pub use scenario::{InitialState, Sampling, Scenario};
pub use speed::{SpeedProfile, SpeedState};

/// Revolutions per minute to rad/s: `w = rpm * 2 pi / 60`.
pub fn rpm_to_rad_per_s(rpm: f64) -> f64 {
    rpm * std::f64::consts::TAU / 60.0
}

/// rad/s to revolutions per minute.
pub fn rad_per_s_to_rpm(w: f64) -> f64 {
    w * 60.0 / std::f64::consts::TAU
}
