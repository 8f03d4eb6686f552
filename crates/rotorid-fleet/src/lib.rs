//! Fleet-scale on-line identification on NATS JetStream (docs/fleet.md).
//!
//! A machine's probe data travel as windows ([`frame::Frame`], a documented binary frame)
//! on `rotorid.raw.<ID>` in the stream [`RAW_STREAM`]; any number of workers share one
//! durable pull consumer on it, identify each window through [`rotorid::pipeline`], publish
//! the result ([`WindowResult`], JSON) on `rotorid.ident.<ID>` into [`IDENT_STREAM`],
//! update the key `<ID>` of the bucket [`LATEST_BUCKET`], compare it with the machine's
//! baseline ([`drift`]), and only then acknowledge the window. Every message carries a
//! `Nats-Msg-Id`, so a window re-sent by a publisher or re-processed after a worker died
//! is stored once.
//!
//! Units: times in s, displacements in m, angles in rad, parameters in SI (kg, N s/m, N/m).

pub mod drift;
pub mod error;
pub mod frame;
#[cfg(feature = "nats")]
pub mod nats;
#[cfg(feature = "nats")]
pub mod publish;
pub mod result;
#[cfg(feature = "nats")]
pub mod status;
#[cfg(feature = "test-server")]
pub mod test_server;
pub mod window;
#[cfg(feature = "nats")]
pub mod worker;

pub use error::FleetError;
pub use frame::{Channel, Frame, FrameError};
pub use result::{
    AlertRecord, ErrorRecord, ModelAlert, WindowResult, FLEET_SCHEMA, MODEL_INADEQUATE,
};

/// The stream of raw windows (subjects `rotorid.raw.>`).
pub const RAW_STREAM: &str = "ROTORID_RAW";
/// The stream of results (`rotorid.ident.>`) and per-window failures (`rotorid.error.>`).
pub const IDENT_STREAM: &str = "ROTORID_IDENT";
/// The stream of drift alerts (`rotorid.alert.>`).
pub const ALERT_STREAM: &str = "ROTORID_ALERT";
/// Key-value bucket: key `<ID>` holds the machine's newest [`WindowResult`].
pub const LATEST_BUCKET: &str = "ROTORID_LATEST";
/// Key-value bucket: key `<ID>` holds the machine's drift state ([`drift::DriftState`]).
pub const DRIFT_BUCKET: &str = "ROTORID_DRIFT";
/// The workers' durable consumer on [`RAW_STREAM`] unless `--durable` says otherwise.
pub const DEFAULT_DURABLE: &str = "rotorid-workers";

/// Subject of machine `id`'s raw windows.
pub fn raw_subject(id: &str) -> String {
    format!("rotorid.raw.{id}")
}
/// Subject of machine `id`'s results.
pub fn ident_subject(id: &str) -> String {
    format!("rotorid.ident.{id}")
}
/// Subject of machine `id`'s windows that gave no result (or `_` for frames without a
/// readable machine).
pub fn error_subject(id: &str) -> String {
    format!("rotorid.error.{id}")
}
/// Subject of machine `id`'s drift alerts.
pub fn alert_subject(id: &str) -> String {
    format!("rotorid.alert.{id}")
}
/// The `Nats-Msg-Id` of window `window` of machine `id` (raw and result alike: they are in
/// different streams).
pub fn message_id(id: &str, window: u64) -> String {
    format!("{id}/{window}")
}
