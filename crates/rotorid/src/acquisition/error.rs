//! Errors of the acquisition stage: each names the record, the channel, the time or the
//! field, the offending value and what is allowed, so an engineer can fix the input or the
//! `[acquisition]` table without reading code.

use crate::model::{ModelError, OutOfRange};
use crate::refine::RefineError;

/// Which record a message is about: the running record or its slow-roll companion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Which {
    /// The record being conditioned.
    Running,
    /// The slow-roll record of `[acquisition.runout]`.
    SlowRoll,
}

impl std::fmt::Display for Which {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Which::Running => "the record",
            Which::SlowRoll => "the slow-roll record",
        })
    }
}

/// An input to the acquisition stage that cannot be used.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum AcquisitionError {
    /// A scalar setting outside its allowed range (NaN and infinity included).
    #[error(transparent)]
    OutOfRange(#[from] OutOfRange),
    /// A column named by `[acquisition]` is not in the record.
    #[error("{which} has no column \"{column}\" ({role}); its columns are: {available}")]
    MissingColumn {
        /// Which record.
        which: Which,
        /// The missing column.
        column: String,
        /// What it was needed for (`probe 1`, `keyphasor`, `time`).
        role: &'static str,
        /// The columns the record has, comma-separated.
        available: String,
    },
    /// Columns of different lengths.
    #[error("{which}: column \"{column}\" has {len} samples but the record has {expected}")]
    LengthMismatch {
        /// Which record.
        which: Which,
        /// The column.
        column: String,
        /// Its length.
        len: usize,
        /// The length of the first column used.
        expected: usize,
    },
    /// One probe where two are needed (x and z).
    #[error("[acquisition] names one probe ({column}): x and z need two [[acquisition.probe]] at least 30 deg apart (one probe is enough for rotorid transient)")]
    SingleProbe {
        /// The probe's column.
        column: String,
    },
    /// A NaN or infinite sample.
    #[error("{which}: column \"{column}\" sample {index} (t = {t} s) is {value}: every sample must be a finite number")]
    NonFinite {
        /// Which record.
        which: Which,
        /// The column.
        column: String,
        /// Index of the first bad sample.
        index: usize,
        /// Its time \[s\] (NaN when the time column itself is bad).
        t: f64,
        /// Its value.
        value: f64,
    },
    /// Time stamps that do not increase.
    #[error("{which}: time stamp {index} (t = {t} s) does not exceed the one before ({previous} s): time must increase")]
    TimeNotIncreasing {
        /// Which record.
        which: Which,
        /// Index of the stamp.
        index: usize,
        /// Its value \[s\].
        t: f64,
        /// The stamp before \[s\].
        previous: f64,
    },
    /// Fewer samples than any conditioning needs.
    #[error("{which} has {samples} samples: at least {needed} are needed")]
    TooFewSamples {
        /// Which record.
        which: Which,
        /// Samples found.
        samples: usize,
        /// The minimum.
        needed: usize,
    },
    /// Two probes that do not span the plane well enough.
    #[error("probes at {angle1_deg} deg and {angle2_deg} deg are {separation_deg:.1} deg apart (as lines): two probes must be at least 30 deg apart to resolve x and z")]
    ProbesTooClose {
        /// Angle of probe 1 \[deg\].
        angle1_deg: f64,
        /// Angle of probe 2 \[deg\].
        angle2_deg: f64,
        /// The angle between their lines of sight, in \[0, 90\] deg.
        separation_deg: f64,
    },
    /// The keyphasor channel holds no pulse.
    #[error("{which}: keyphasor column \"{column}\" holds no pulse: its range {range_v:.4} V is within {factor} times its noise ({noise_v:.2e} V)")]
    NoPulse {
        /// Which record.
        which: Which,
        /// The keyphasor column.
        column: String,
        /// max - min \[V\].
        range_v: f64,
        /// Noise level from first differences \[V\].
        noise_v: f64,
        /// The factor the range must exceed.
        factor: f64,
    },
    /// A given threshold outside the signal's levels.
    #[error("{which}: keyphasor threshold {threshold_v} V is outside the signal's levels [{low_v}, {high_v}] V: choose a voltage between them or \"auto\"")]
    ThresholdOutsideSignal {
        /// Which record.
        which: Which,
        /// The threshold \[V\].
        threshold_v: f64,
        /// Lowest level \[V\].
        low_v: f64,
        /// Highest level \[V\].
        high_v: f64,
    },
    /// Too few keyphasor events to follow the shaft angle.
    #[error("{which}: keyphasor column \"{column}\" has {found} {edge} edges: at least {needed} are needed (two whole revolutions)")]
    TooFewPulses {
        /// Which record.
        which: Which,
        /// The keyphasor column.
        column: String,
        /// Edges found.
        found: usize,
        /// The minimum.
        needed: usize,
        /// `falling` or `rising`.
        edge: &'static str,
    },
    /// The keyphasor pulses come faster than the sampling resolves.
    #[error("{which}: the keyphasor is faster than the sampling can resolve: {what} (median {value:.2} samples, at least {needed} needed); sample faster or check the keyphasor column")]
    KeyphasorTooFast {
        /// Which record.
        which: Which,
        /// `samples per revolution` or `samples per pulse`.
        what: &'static str,
        /// The measured value \[samples\].
        value: f64,
        /// The minimum \[samples\].
        needed: f64,
    },
    /// An interval between pulses that is neither a revolution nor an unambiguous multiple.
    #[error("{which}: keyphasor interval of {interval_s:.6} s ending at t = {t:.6} s is {ratio:.3} times the neighbouring revolutions ({expected_s:.6} s): neither a missed nor a spurious pulse explains it")]
    IrregularPulse {
        /// Which record.
        which: Which,
        /// Time of the pulse that ends the interval \[s\].
        t: f64,
        /// The interval \[s\].
        interval_s: f64,
        /// The local revolution period \[s\].
        expected_s: f64,
        /// interval / expected.
        ratio: f64,
    },
    /// The fitted speed is not positive (the rotor stopped or turned back).
    #[error("{which}: the speed from the keyphasor is {omega} rad/s at t = {t} s: the shaft must turn forward throughout")]
    SpeedNotPositive {
        /// Which record.
        which: Which,
        /// Time \[s\].
        t: f64,
        /// The speed \[rad/s\].
        omega: f64,
    },
    /// The model response used for the slow-roll or DC correction failed.
    #[error("model response for the conditioning: {0}")]
    Model(#[from] RefineError),
    /// The rotor guess or a simulation setting is invalid.
    #[error(transparent)]
    Rotor(#[from] ModelError),
    /// The raw simulation failed.
    #[error("raw simulation: {0}")]
    Simulate(String),
}
