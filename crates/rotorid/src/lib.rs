//! # rotorid
//!
//! Identification of the physical parameters of rotor-bearing systems (mass, damping,
//! stiffness, unbalance) from measured vibration, after Barredo et al. (2024).
//!
//! - [`model`]: the 2-DOF Jeffcott rotor of the paper's eq. (1), speed profiles, scenarios.
//! - [`simulate`]: Newmark (as in the paper) and an exact/high-accuracy reference, noise.
//! - [`identify`]: running integrals and the algebraic identifiers, streaming and batch.
//! - [`refine`]: output-error (maximum-likelihood) refinement with uncertainties.
//! - [`pipeline`]: record -> identification with diagnostics, the entry point of every
//!   caller (batch [`pipeline::identify`] and streaming [`pipeline::Session`]).
//! - [`analysis`]: Campbell diagram, critical speeds, stability, unbalance response, balancing.
//! - `scenario_file` (feature `toml`): scenario files (rotor, speed, sampling, initial
//!   state) parsed from TOML text, with errors naming file, line, key and allowed range.
//!
//! Pure computation: no file I/O (callers read files and hand over their text), no
//! plotting (those live in the `rotorid` command).

pub mod acquisition;
pub mod analysis;
mod expm;
pub mod identify;
pub mod model;
pub mod parameter;
pub mod pipeline;
pub mod refine;
pub mod residual;
#[cfg(feature = "toml")]
pub mod scenario_file;
pub mod simulate;
#[cfg(feature = "test-models")]
pub mod test_models;
pub mod transient;

pub use model::{
    InitialState, Rotor, RotorParams, Sampling, Scenario, SpeedProfile, SpeedState, Unbalance,
};
pub use parameter::Parameter;

/// Version of the serialised identification summaries (the pipeline's and the
/// finite-element fit's); incremented on incompatible changes (3: `model`, the
/// cross-coupled model's parameter names, `rotor` keyed by the model's parameters,
/// `model_selection`).
pub const IDENTIFICATION_SCHEMA: u32 = 3;
