//! Machine transients from measurement: a run-up or a coast-down (probes in volts and a
//! keyphasor) reduced to order-tracked vectors (Bode and polar data), slow-roll
//! compensated, with the critical speeds, their API 684 amplification factors and
//! separation margins, and cascades of spectra (docs/transient.md).
//!
//! - [`order`]: the keyphasor's shaft angle and each probe's nX vector per revolution
//!   (or per speed bin), with its standard deviation from the noise of that revolution;
//! - [`slow_roll`]: the runout vector (from a slow-roll record or a low-speed range) and
//!   its subtraction;
//! - [`critical`]: resonances of a 1X amplitude curve, half-power speeds, amplification
//!   factors and separation margins (API 684);
//! - [`modes`]: a modal model fitted to the transient 1X vectors themselves (the
//!   [`synchronous`] response of a [`crate::model::description`] along the measured speed),
//!   free of the sweep's bias, with the number of modes chosen by BIC;
//! - [`spectrum`]: cascades (waterfalls) of spectra of one probe and full spectra of an
//!   XY pair against speed.
//!
//! Pure computation, as the rest of the library: the caller reads the records.

pub mod analysis;
pub mod angle;
pub mod critical;
mod error;
pub mod modes;
pub mod order;
pub mod record;
pub mod report;
pub mod slow_roll;
pub mod spectrum;
pub mod synchronous;

pub use analysis::{Analysis, RawAnalysis, SlowRollChoice};
pub use critical::{criticals, separation_margin, Critical, CriticalSettings, Margin, Position};
pub use error::TransientError;
pub use modes::{fit_modes, FitBasis, FittedMode, ModeFit, ModeGuess, ModeSettings};
pub use order::{track, OrderSettings, Revolution, Tracked};
pub use record::{track_record, track_record_owned, ProbeTrack, RecordTrack};
pub use report::{transient_json, TransientJson};
pub use slow_roll::{compensate, SlowRoll, SlowRollSource};
pub use spectrum::{cascade, full_cascade, full_cascade_of_pair, Cascade, CascadeSettings, Peak};
