//! What the workers publish (JSON): one [`WindowResult`] per identified window, one
//! [`ErrorRecord`] per window that gives none, one [`AlertRecord`] per drift alert, one
//! [`ModelAlert`] when the model stops explaining a machine's windows. These structs are
//! the contract: `rotorid fleet status` and any consumer read them back.

use rotorid::pipeline::Identification;
use serde::{Deserialize, Serialize};

/// Version of the fleet messages below.
pub const FLEET_SCHEMA: u32 = 1;

/// One window's identification (subject `rotorid.ident.<ID>`, bucket `ROTORID_LATEST`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WindowResult {
    /// [`FLEET_SCHEMA`].
    pub fleet_schema: u32,
    /// Machine id.
    pub machine: String,
    /// Window sequence number.
    pub window: u64,
    /// Time of the window's first sample \[s\].
    pub t0_s: f64,
    /// Sampling period \[s\].
    pub dt_s: f64,
    /// Samples per channel.
    pub samples: u64,
    /// The pipeline's result (docs/summary.md, schema 2), exactly as `identify` returns it
    /// for the window's record.
    pub identification: Identification,
}

/// A window that gave no result (subject `rotorid.error.<ID>`): it was acknowledged, not
/// retried.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ErrorRecord {
    /// [`FLEET_SCHEMA`].
    pub fleet_schema: u32,
    /// Machine id (`_` when the frame had none readable).
    pub machine: String,
    /// Window number, when the frame was readable.
    pub window: Option<u64>,
    /// Sequence number of the raw message in `ROTORID_RAW`.
    pub stream_seq: u64,
    /// Times it had been delivered.
    pub delivered: u64,
    /// Why (the library's error message).
    pub error: String,
}

/// A drift alert (subject `rotorid.alert.<ID>`), see [`crate::drift`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AlertRecord {
    /// [`FLEET_SCHEMA`].
    pub fleet_schema: u32,
    /// Machine id.
    pub machine: String,
    /// The window that confirmed the change.
    pub window: u64,
    /// Its t0 \[s\].
    pub t0_s: f64,
    /// The parameter (`k_x`, ...).
    pub parameter: String,
    /// Its SI unit.
    pub unit: String,
    /// Baseline value.
    pub baseline: f64,
    /// Baseline standard error.
    pub baseline_std_error: f64,
    /// This window's value.
    pub value: f64,
    /// This window's standard error.
    pub std_error: f64,
    /// value - baseline.
    pub change: f64,
    /// change / baseline.
    pub relative_change: f64,
    /// change / sqrt(std_error^2 + baseline_std_error^2).
    pub z: f64,
    /// The z of the window before (the confirmation).
    pub previous_z: f64,
}

/// A model alert (subject `rotorid.alert.<ID>`, `Nats-Msg-Id` `<ID>/<window>/model`): two
/// consecutive windows whose identification found that eq. (1) does not explain them
/// (`MODEL INADEQUATE`: their values were withheld), raised on the later one (see
/// [`crate::drift`]). Tell it from an [`AlertRecord`] by its `kind`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelAlert {
    /// [`FLEET_SCHEMA`].
    pub fleet_schema: u32,
    /// `model_inadequate`.
    pub kind: String,
    /// Machine id.
    pub machine: String,
    /// The window that confirmed it.
    pub window: u64,
    /// Its t0 \[s\].
    pub t0_s: f64,
    /// The window before it, also inadequate.
    pub previous_window: u64,
    /// The window's `MODEL INADEQUATE` messages (per channel), joined by ` | `.
    pub message: String,
}

/// The `kind` of a [`ModelAlert`].
pub const MODEL_INADEQUATE: &str = "model_inadequate";
