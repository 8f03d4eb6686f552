//! # rotorid
//!
//! Identification of the physical parameters of rotor-bearing systems (mass, damping,
//! stiffness, bearing coefficients, unbalance) from measured vibration, after Barredo et
//! al. (2024), and the analyses that use them.
//!
//! - [`model`]: the rotors: the paper's 2-DOF Jeffcott rotor (eq. (1)) and its
//!   cross-coupled-bearing case, finite-element rotors (matrices from ROSS or elsewhere,
//!   bearings and unbalances as data), modal descriptions; speed profiles, scenarios;
//!   `model::description`, the model as data (matrices and their derivatives for a
//!   parameter vector).
//! - [`parameter`]: one name, unit and sign for every identified parameter.
//! - [`simulate`]: Newmark (as in the paper) and exact/high-accuracy references, noise;
//!   finite-element rotors.
//! - [`acquisition`]: raw records (probe volts, keyphasor, slow roll) to displacement and
//!   shaft angle.
//! - [`identify`]: the algebraic and modulating-function identifiers, streaming and batch.
//! - [`refine`]: maximum-likelihood refinement with uncertainties, the Cramer-Rao bound;
//!   finite-element rotors.
//! - [`residual`]: whether a model's residuals are only the data's noise (the adequacy
//!   tests every method uses).
//! - [`pipeline`]: record -> identification with diagnostics, the entry point of every
//!   caller (batch [`pipeline::identify`] and streaming [`pipeline::Session`]).
//! - [`analysis`]: Campbell diagram, critical speeds, stability, unbalance response,
//!   balancing.
//! - [`transient`]: run-ups and coast-downs: order tracking, Bode and polar data, critical
//!   speeds with API 684 amplification factors and margins, modes fitted to the sweep.
//! - `scenario_file` (feature `toml`): scenario files parsed from TOML text, with errors
//!   naming file, line, key and allowed range.
//!
//! Pure computation: no file I/O (callers read files and hand over their text or
//! samples), no plotting (those live in the `rotorid` command).

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
