//! # rotorid
//!
//! Identification of the physical parameters of rotor-bearing systems (mass, damping,
//! stiffness, unbalance) from measured vibration, after Barredo et al. (2024).
//!
//! - [`model`]: the 2-DOF Jeffcott rotor of the paper's eq. (1), speed profiles, scenarios.
//! - [`simulate`]: Newmark (as in the paper) and an exact/high-accuracy reference, noise.
//! - [`identify`]: running integrals and the algebraic identifiers, streaming and batch.
//! - [`refine`]: output-error (maximum-likelihood) refinement with uncertainties.
//! - [`analysis`]: Campbell diagram, critical speeds, stability, unbalance response, balancing.
//!
//! Pure computation: no file I/O, no plotting (those live in the `rotorid` command).

pub mod analysis;
pub mod identify;
pub mod model;
pub mod refine;
pub mod simulate;

pub use model::{
    InitialState, Rotor, RotorParams, Sampling, Scenario, SpeedProfile, SpeedState, Unbalance,
};
