//! Acquisition: from what a rig records (two proximity probes in volts at any two angles,
//! a keyphasor, optionally a slow-roll record) to the `t, x, z, phi, phi_dot, phi_ddot` the
//! identifiers take, and back (a raw acquisition simulated from a scenario, for tests and
//! demos). docs/acquisition.md states the equations, conventions and measured accuracy.
//!
//! Conventions (SI throughout; docs/method.md section 1.1): x horizontal, z vertical up;
//! a probe's angle theta is measured from +x towards +z and points from the shaft centre to
//! the probe; it reads the displacement towards it, `d = x cos theta + z sin theta`, as
//! `V = V_dc + s d` with s the signed sensitivity \[V/m\] (positive for the usual
//! negative-going probe, since moving towards it closes the gap). The keyphasor event is
//! where phi = phi_kp (mod 2 pi), phi_kp the keyphasor angle in the frame in which the
//! unbalance angle alpha is measured.
//!
//! [`condition`] does, in order:
//!
//! 1. keyphasor -> phi, w, w' per sample ([`keyphasor`]);
//! 2. DC per probe = mean over the samples between the first and the last keyphasor event
//!    (whole revolutions); d_i = (V_i - V_dc,i) / s_i ([`probes`]);
//! 3. with a slow-roll record: its runout r_i(phi), after removing the model's predicted
//!    slow-roll response when a rotor guess is given; d_i -= r_i(phi(t)) ([`runout`]);
//! 4. (x, z) = P^-1 (d_1, d_2) ([`probes`]);
//! 5. with a rotor guess: the model-assisted fit of `model_fit` removes the offset the
//!    transient's mean put into the DC and measures what is left locked to phi (1X-3X),
//!    reported as [`AcquisitionFinding::ResidualRunout`] when significant.
//!
//! Identification iterates ([`condition_iterated`], module `iterate`): condition with the
//! scenario's complete `[rotor]` (or none), identify, condition again with
//! [`ModelGuess::from_identification`] (the estimate and the fitted initial state),
//! identify again, until the estimates move by less than a tenth of their standard errors
//! (docs/acquisition.md section 6).
//!
//! Pure computation: no file I/O. The caller reads the raw record and the slow-roll file
//! (whose path `[acquisition.runout] slow_roll` names) into [`RawRecord`]s.

mod error;
pub mod finite_element;
mod iterate;
pub mod keyphasor;
pub mod model_fit;
pub mod probes;
pub mod raw;
pub mod runout;

use serde::Serialize;

pub use error::{AcquisitionError, Which};
pub use finite_element::{
    condition_fe_raw, simulate_fe_raw, FeAcquisition, FeConditioned, FeNodeProbes, FeRawSimulation,
};
pub use iterate::{
    change, condition_iterated, ChangeBasis, Iterated, IterationError, Passes, MAX_PASSES,
    SETTLED_RELATIVE, SETTLED_STD_ERRORS,
};
pub use keyphasor::{shaft_angle, KeyphasorReport, ShaftAngle};
pub use model_fit::ModelFit;
pub use raw::{simulate_raw, RawSettings, RawSimulation, RunoutHarmonic};
pub use runout::Harmonics;

use crate::model::{check, InitialState, Rotor, RotorParams};
use crate::parameter::Parameter;
use crate::pipeline::{Identification, Knowledge};

/// Default number of runout harmonics fitted to the slow-roll record.
pub const DEFAULT_RUNOUT_HARMONICS: usize = 8;
/// 1 mil = 25.4 um: sensitivity \[V/m\] = mV/mil / 1000 / 25.4e-6.
pub const METRES_PER_MIL: f64 = 25.4e-6;

/// Where time comes from.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub enum TimeBase {
    /// A column with time \[s\].
    Column(String),
    /// A sampling rate \[Hz\], the first sample at t = 0.
    RateHz(f64),
}

/// The keyphasor's active edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Edge {
    /// The signal falls through the threshold (a notch under a usual probe).
    Falling,
    /// The signal rises through the threshold (a key or a projection).
    Rising,
}

/// The keyphasor threshold.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub enum Threshold {
    /// Half-way between the signal's lowest and highest levels.
    Auto,
    /// A voltage \[V\].
    Volts(f64),
}

/// One proximity probe.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Probe {
    /// Column in the raw record.
    pub column: String,
    /// Direction from the shaft centre to the probe, from +x towards +z \[rad\].
    pub angle: f64,
    /// Sensitivity s \[V/m\], signed: output minus its DC = s x displacement towards the
    /// probe.
    pub sensitivity: f64,
}

/// The keyphasor channel.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Keyphasor {
    /// Column in the raw record \[V\].
    pub column: String,
    /// The active edge.
    pub edge: Edge,
    /// The threshold.
    pub threshold: Threshold,
    /// Shaft angle phi at the event \[rad\], in the frame of the unbalance angle alpha.
    pub angle: f64,
}

/// The `[acquisition]` table (module doc).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Acquisition {
    /// Time column or sampling rate.
    pub time: TimeBase,
    /// Exactly two probes.
    pub probes: [Probe; 2],
    /// The keyphasor.
    pub keyphasor: Keyphasor,
    /// `[acquisition.runout] slow_roll`: the slow-roll file as written (relative to the
    /// scenario file; the caller reads it).
    pub slow_roll: Option<String>,
    /// Runout harmonics H fitted to the slow-roll record (>= 1).
    pub runout_harmonics: usize,
    /// Settings of the raw simulation (`[acquisition.simulate]`).
    pub simulate: RawSettings,
    /// The scenario names one probe only (`probes` holds it twice): enough for the
    /// transient analysis of that probe, refused by [`Acquisition::validate`] (x and z need
    /// two).
    #[serde(skip)]
    pub single_probe: bool,
}

impl Acquisition {
    /// The probes at 135 deg and 45 deg (45 deg left and right of vertical), 7874 V/m,
    /// columns `probe_L`, `probe_R`; keyphasor `kp`, falling edge, automatic threshold,
    /// at phi = 0; time column `t`; default raw-simulation settings. The contract's example.
    pub fn example() -> Self {
        Self {
            time: TimeBase::Column("t".into()),
            probes: [
                Probe {
                    column: "probe_L".into(),
                    angle: 135f64.to_radians(),
                    sensitivity: 7874.0,
                },
                Probe {
                    column: "probe_R".into(),
                    angle: 45f64.to_radians(),
                    sensitivity: 7874.0,
                },
            ],
            keyphasor: Keyphasor {
                column: "kp".into(),
                edge: Edge::Falling,
                threshold: Threshold::Auto,
                angle: 0.0,
            },
            slow_roll: None,
            runout_harmonics: DEFAULT_RUNOUT_HARMONICS,
            simulate: RawSettings::default(),
            single_probe: false,
        }
    }

    /// The columns a raw record must have: time (if a column), probe 1, probe 2, keyphasor.
    pub fn columns(&self) -> Vec<(&str, &'static str)> {
        let mut v = Vec::new();
        if let TimeBase::Column(c) = &self.time {
            v.push((c.as_str(), "time"));
        }
        v.push((self.probes[0].column.as_str(), "probe 1"));
        v.push((self.probes[1].column.as_str(), "probe 2"));
        v.push((self.keyphasor.column.as_str(), "keyphasor"));
        v
    }

    /// Check the settings that do not depend on data: probe separation, sensitivities,
    /// angles, rate, harmonics.
    pub fn validate(&self) -> Result<(), AcquisitionError> {
        if self.single_probe {
            return Err(AcquisitionError::SingleProbe {
                column: self.probes[0].column.clone(),
            });
        }
        if let TimeBase::RateHz(r) = self.time {
            check("acquisition.rate_hz", r, "finite and > 0 (Hz)", |v| v > 0.0)?;
        }
        for p in &self.probes {
            check(
                "acquisition.probe.angle_deg",
                p.angle,
                "finite (deg)",
                |_| true,
            )?;
            check(
                "acquisition.probe.sensitivity",
                p.sensitivity,
                "finite and non-zero (V/m)",
                |v| v != 0.0,
            )?;
        }
        check(
            "acquisition.keyphasor.angle_deg",
            self.keyphasor.angle,
            "finite (deg)",
            |_| true,
        )?;
        if let Threshold::Volts(v) = self.keyphasor.threshold {
            check("acquisition.keyphasor.threshold", v, "finite (V)", |_| true)?;
        }
        check(
            "acquisition.runout.harmonics",
            self.runout_harmonics as f64,
            "an integer from 1 to 64",
            |v| (1.0..=64.0).contains(&v),
        )?;
        probes::inverse_projection([self.probes[0].angle, self.probes[1].angle])?;
        Ok(())
    }
}

/// A raw record: named columns of equal length (volts, and time in s if a column).
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct RawRecord {
    /// (name, values), in file order.
    pub columns: Vec<(String, Vec<f64>)>,
}

impl RawRecord {
    /// The column `name`, if present.
    pub fn column(&self, name: &str) -> Option<&[f64]> {
        self.columns
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_slice())
    }

    /// The column names, comma-separated (for messages).
    pub fn names(&self) -> String {
        let v: Vec<&str> = self.columns.iter().map(|(n, _)| n.as_str()).collect();
        if v.is_empty() {
            "(none)".into()
        } else {
            v.join(", ")
        }
    }

    /// Number of samples (length of the first column).
    pub fn len(&self) -> usize {
        self.columns.first().map_or(0, |(_, v)| v.len())
    }

    /// True when there is no sample.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Where a rotor guess comes from (reported).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum GuessSource {
    /// The scenario's `[rotor]` values.
    Scenario,
    /// A previous identification (the second pass).
    Identification,
    /// Given by the caller otherwise.
    Given,
}

/// A rotor (and optionally the state at the record's first sample) the conditioning may
/// use to remove the predicted slow-roll response and the DC bias of the transient.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ModelGuess {
    /// The rotor, SI units.
    pub rotor: RotorParams,
    /// The state at the first sample of the running record (fitted when `None`).
    pub initial: Option<InitialState>,
    /// Where it comes from.
    pub source: GuessSource,
}

impl ModelGuess {
    /// The guess from an identification: each refined or identified parameter's estimate
    /// (refine: m; algebraic/modulating: the mean of m_x and m_z) over `known` (a, the
    /// unbalance, nominal values), and refine's fitted initial state. An estimate outside
    /// the model's range (m, kx or kz not > 0, an unbalance not >= 0: an algebraic estimate
    /// on a record that cannot determine it, say) is not used: the nominal value stands
    /// in. `None` when m, cx, kx, cz or kz then has neither, or the rotor is still not one
    /// [`Rotor::new`] accepts.
    pub fn from_identification(id: &Identification, known: &Knowledge) -> Option<Self> {
        let est = |p: Parameter| id.parameter(p).and_then(|r| r.estimate.or(r.value));
        let positive = |v: &f64| v.is_finite() && *v > 0.0;
        let nominal = |p: Parameter| known.nominal.get(p);
        let m = est(Parameter::M)
            .or_else(|| Some(0.5 * (est(Parameter::MX)? + est(Parameter::MZ)?)))
            .filter(positive)
            .or_else(|| nominal(Parameter::M))?;
        let get = |p: Parameter| est(p).filter(|v| v.is_finite()).or_else(|| nominal(p));
        let stiffness = |p: Parameter| est(p).filter(positive).or_else(|| nominal(p));
        let mut unbalance = known.unbalance;
        if let (Some(mud), Some(alpha)) = (est(Parameter::Mud), est(Parameter::Alpha)) {
            if mud.is_finite() && mud >= 0.0 && alpha.is_finite() {
                unbalance.alpha = alpha;
                if unbalance.d > 0.0 {
                    unbalance.m_u = mud / unbalance.d;
                } else {
                    unbalance.m_u = mud;
                    unbalance.d = 1.0;
                }
            }
        }
        let rotor = RotorParams {
            coupling: None,
            m,
            cx: get(Parameter::Cx)?.max(0.0),
            kx: stiffness(Parameter::Kx)?,
            cz: get(Parameter::Cz)?.max(0.0),
            kz: stiffness(Parameter::Kz)?,
            a: est(Parameter::A)
                .filter(|v| v.is_finite())
                .unwrap_or(known.a),
            unbalance,
        };
        Rotor::new(rotor).ok()?;
        let initial = id.refine.as_ref().and_then(|r| {
            let v = |n: &str| {
                r.initial_state
                    .iter()
                    .find(|s| s.name == n)
                    .map(|s| s.value)
            };
            Some(InitialState {
                x: v("x0")?,
                z: v("z0")?,
                vx: v("vx0")?,
                vz: v("vz0")?,
            })
        });
        Some(Self {
            rotor,
            initial,
            source: GuessSource::Identification,
        })
    }
}

/// One component locked to phi left in the conditioned signal.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LockedComponent {
    /// `x` or `z`.
    pub channel: &'static str,
    /// Harmonic order (1 = 1X).
    pub harmonic: usize,
    /// Amplitude \[m\].
    pub amplitude_m: f64,
    /// Its standard error from the residual noise, sigma sqrt(2 / N) \[m\].
    pub std_error_m: f64,
}

/// What the conditioning found that the identification should warn about.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum AcquisitionFinding {
    /// Content locked to the shaft angle that the model does not explain: runout not
    /// removed (no slow-roll record, or a wrong one), or a model far from the truth.
    ResidualRunout {
        /// Whether a slow-roll record was used.
        slow_roll_given: bool,
        /// The significant components.
        components: Vec<LockedComponent>,
    },
    /// The iterated conditioning (`condition_iterated`) stopped at its last pass with the
    /// rotor guess still moving: the runout and DC corrections may still bias m, c, k.
    NotSettled {
        /// Passes made.
        passes: usize,
        /// The largest change of an estimate in the last pass, in its standard errors (or
        /// relative, when `relative`).
        last_change: f64,
        /// The estimate that changed most.
        parameter: Option<String>,
        /// Whether `last_change` is relative (the method gives no standard errors).
        relative: bool,
    },
    /// The keyphasor needed repairs.
    KeyphasorRepaired {
        /// Events after which pulses were missing \[s\].
        missed_before_s: Vec<f64>,
        /// Spurious events removed \[s\].
        spurious_s: Vec<f64>,
    },
}

impl AcquisitionFinding {
    /// One sentence: what was found and what to do.
    pub fn message(&self) -> String {
        match self {
            Self::ResidualRunout {
                slow_roll_given,
                components,
            } => {
                let list: Vec<String> = components
                    .iter()
                    .map(|c| {
                        format!(
                            "{}X in {} {:.3} um",
                            c.harmonic,
                            c.channel,
                            c.amplitude_m * 1e6
                        )
                    })
                    .collect();
                if *slow_roll_given {
                    format!(
                        "the slow-roll runout compensation left content locked to the shaft angle that the model does not explain ({}): the slow-roll record may not be of this machine and these probes, or the rotor guess (the scenario's, or the first identification's) is far from the truth; either biases m, c, k",
                        list.join(", ")
                    )
                } else {
                    format!(
                        "without [acquisition.runout] the conditioned record holds content locked to the shaft angle that the model does not explain ({}): probe runout biases m, c, k; give a slow-roll record in [acquisition.runout]",
                        list.join(", ")
                    )
                }
            }
            Self::NotSettled {
                passes,
                last_change,
                parameter,
                relative,
            } => format!(
                "the conditioning did not settle in {passes} passes: in the last, {} still moved \
                 by {last_change:.2e} {} (the limit is {:e}); the runout and DC corrections \
                 that depend on the rotor guess may bias m, c, k by about that much",
                parameter.as_deref().unwrap_or("an estimate"),
                if *relative {
                    "of its value"
                } else {
                    "standard errors"
                },
                if *relative {
                    SETTLED_RELATIVE
                } else {
                    SETTLED_STD_ERRORS
                }
            ),
            Self::KeyphasorRepaired {
                missed_before_s,
                spurious_s,
            } => format!(
                "the keyphasor missed pulses before t = {missed_before_s:?} s and had spurious pulses at t = {spurious_s:?} s, repaired from the neighbouring revolutions; check the keyphasor probe"
            ),
        }
    }
}

/// What one probe showed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProbeReport {
    /// The column.
    pub column: String,
    /// Its angle \[deg\].
    pub angle_deg: f64,
    /// Its sensitivity \[V/m\].
    pub sensitivity_v_per_m: f64,
    /// Mean over whole revolutions \[V\].
    pub dc_v: f64,
    /// The DC after the model's offset correction \[V\] (= `dc_v` without a guess).
    pub dc_corrected_v: f64,
    /// Gap -V_dc / s \[m\], for a probe reading 0 V at zero gap.
    pub gap_m: f64,
    /// Noise of the channel from first differences, in displacement \[m\].
    pub noise_m: f64,
}

/// The slow-roll record's contribution.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SlowRollReport {
    /// Its keyphasor.
    pub keyphasor: KeyphasorReport,
    /// Mean slow-roll speed \[rev/min\].
    pub speed_rpm: f64,
    /// DC per probe over its whole revolutions \[V\].
    pub dc_v: [f64; 2],
    /// Runout of each probe as a function of phi.
    pub runout: [Harmonics; 2],
    /// Peak-to-peak runout per probe \[m\].
    pub runout_peak_to_peak_m: [f64; 2],
    /// Amplitude of the model's slow-roll response removed from each probe \[m\] (0 when
    /// no rotor guess was given).
    pub predicted_response_m: [f64; 2],
}

/// Everything the conditioning measured and assumed.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ConditionReport {
    /// Samples.
    pub samples: usize,
    /// Mean sampling period \[s\].
    pub dt_s: f64,
    /// The keyphasor of the running record.
    pub keyphasor: KeyphasorReport,
    /// The two probes.
    pub probes: [ProbeReport; 2],
    /// Shaft centreline P^-1 (V_dc,i / s_i) \[m\] (x, z): the static position relative to
    /// where both probes would read 0 V.
    pub centreline_m: [f64; 2],
    /// Centreline shift from slow roll to running (x, z) \[m\] (with a slow-roll record).
    pub centreline_shift_m: Option<[f64; 2]>,
    /// The slow-roll record's runout.
    pub slow_roll: Option<SlowRollReport>,
    /// The rotor guess used (if any).
    pub guess: Option<ModelGuess>,
    /// The model-assisted fit (with a guess).
    pub model: Option<ModelFit>,
    /// Findings to warn about.
    pub findings: Vec<AcquisitionFinding>,
    /// What was assumed, in words.
    pub notes: Vec<String>,
    /// The passes of the iterated conditioning ([`condition_iterated`]); `None` for one
    /// conditioning ([`condition`]).
    pub passes: Option<Passes>,
}

/// The conditioned record.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Conditioned {
    /// Time \[s\].
    pub t: Vec<f64>,
    /// Horizontal displacement \[m\].
    pub x: Vec<f64>,
    /// Vertical displacement (up) \[m\].
    pub z: Vec<f64>,
    /// Shaft angle \[rad\].
    pub phi: Vec<f64>,
    /// Speed \[rad/s\].
    pub phi_dot: Vec<f64>,
    /// Angular acceleration \[rad/s^2\].
    pub phi_ddot: Vec<f64>,
    /// What was measured and assumed.
    pub report: ConditionReport,
}

impl Conditioned {
    /// As a [`TimeResponse`](crate::simulate::TimeResponse) (the columns `rotorid
    /// condition` writes).
    pub fn response(&self) -> crate::simulate::TimeResponse {
        crate::simulate::TimeResponse {
            t: self.t.clone(),
            x: self.x.clone(),
            z: self.z.clone(),
            phi: self.phi.clone(),
            phi_dot: self.phi_dot.clone(),
            phi_ddot: self.phi_ddot.clone(),
        }
    }
}

/// A column of `raw`, checked for presence, length and finiteness.
fn column<'a>(
    raw: &'a RawRecord,
    name: &str,
    role: &'static str,
    which: Which,
    expected: Option<usize>,
    t: Option<&[f64]>,
) -> Result<&'a [f64], AcquisitionError> {
    let v = raw
        .column(name)
        .ok_or_else(|| AcquisitionError::MissingColumn {
            which,
            column: name.to_string(),
            role,
            available: raw.names(),
        })?;
    if let Some(n) = expected {
        if v.len() != n {
            return Err(AcquisitionError::LengthMismatch {
                which,
                column: name.to_string(),
                len: v.len(),
                expected: n,
            });
        }
    }
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Err(AcquisitionError::NonFinite {
            which,
            column: name.to_string(),
            index: i,
            t: t.map_or(f64::NAN, |t| t[i]),
            value: v[i],
        });
    }
    Ok(v)
}

/// Time stamps of `raw` per the time base, checked (finite, increasing).
pub fn time_of(
    raw: &RawRecord,
    acq: &Acquisition,
    which: Which,
) -> Result<Vec<f64>, AcquisitionError> {
    let n = check_time(raw, acq, which)?;
    Ok(match &acq.time {
        TimeBase::RateHz(r) => (0..n).map(|i| i as f64 / r).collect(),
        TimeBase::Column(c) => raw.column(c).map(<[f64]>::to_vec).unwrap_or_default(),
    })
}

/// The checks of [`time_of`] without the copy of the stamps: every required column
/// present, the rate valid or the time column as long as the first probe's, finite and
/// increasing. Returns the number of samples (the first probe's length).
pub(crate) fn check_time(
    raw: &RawRecord,
    acq: &Acquisition,
    which: Which,
) -> Result<usize, AcquisitionError> {
    // Every required column must be present, whatever is checked first.
    for (name, role) in acq.columns() {
        if raw.column(name).is_none() {
            return Err(AcquisitionError::MissingColumn {
                which,
                column: name.to_string(),
                role,
                available: raw.names(),
            });
        }
    }
    let n = raw
        .column(acq.probes[0].column.as_str())
        .map_or(0, <[f64]>::len);
    match &acq.time {
        TimeBase::RateHz(r) => {
            check("acquisition.rate_hz", *r, "finite and > 0 (Hz)", |v| {
                v > 0.0
            })?;
        }
        TimeBase::Column(c) => {
            let t = column(raw, c, "time", which, Some(n), None)?;
            // the first step that does not increase (one pass, no early exit to test)
            if let Some(i) = t
                .windows(2)
                .position(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
            {
                return Err(AcquisitionError::TimeNotIncreasing {
                    which,
                    index: i + 1,
                    t: t[i + 1],
                    previous: t[i],
                });
            }
        }
    }
    Ok(n)
}

/// The times the keyphasor is timed on: the uniform grid fitted over the stamps `t` when
/// they are rounded (printed with few decimals: off that grid by more than the default
/// time tolerance, within their rounding; `pipeline::TimeGrid::fit`), with that grid; else
/// the stamps. Rounded stamps put each event up to half a unit of their last decimal off
/// (0.5 us with 6 decimals, 3e-5 rad at 650 rpm), the same way on every record: on a
/// 600 rpm + 10 rad/s^2 run-up that biased m and k by 1.4 Cramer-Rao bounds (measured,
/// docs/acquisition.md section 9).
pub(crate) fn keyphasor_times(t: Vec<f64>) -> (Vec<f64>, Option<crate::pipeline::TimeGrid>) {
    match crate::pipeline::TimeGrid::fit(&t, crate::pipeline::DEFAULT_TIME_TOLERANCE) {
        Ok(g) if g.rounded => ((0..t.len()).map(|i| g.time(i)).collect(), Some(g)),
        _ => (t, None),
    }
}

/// The probe voltages and keyphasor of `raw`, checked against its time stamps.
pub(crate) fn channels<'a>(
    raw: &'a RawRecord,
    acq: &Acquisition,
    t: &[f64],
    which: Which,
) -> Result<([&'a [f64]; 2], &'a [f64]), AcquisitionError> {
    let n = Some(t.len());
    let p1 = column(raw, &acq.probes[0].column, "probe 1", which, n, Some(t))?;
    let p2 = column(raw, &acq.probes[1].column, "probe 2", which, n, Some(t))?;
    let kp = column(raw, &acq.keyphasor.column, "keyphasor", which, n, Some(t))?;
    Ok(([p1, p2], kp))
}

/// Samples between the first and last keyphasor events (whole revolutions).
fn whole_revolutions(t: &[f64], kp: &KeyphasorReport) -> std::ops::Range<usize> {
    let a = t.partition_point(|&v| v < kp.first_event_s);
    let b = t.partition_point(|&v| v <= kp.last_event_s);
    a..b.max(a + 1)
}

fn mean(v: &[f64], r: std::ops::Range<usize>) -> f64 {
    let n = r.len() as f64;
    v[r].iter().sum::<f64>() / n
}

/// Slow-roll runout per probe (module doc, step 3).
fn slow_roll_runout(
    slow: &RawRecord,
    acq: &Acquisition,
    guess: Option<&ModelGuess>,
) -> Result<SlowRollReport, AcquisitionError> {
    let which = Which::SlowRoll;
    let t = time_of(slow, acq, which)?;
    let (v, kp) = channels(slow, acq, &t, which)?;
    let (t, _) = keyphasor_times(t);
    let sa = shaft_angle(&t, kp, &acq.keyphasor, which)?;
    let range = whole_revolutions(&t, &sa.report);
    let angles = [acq.probes[0].angle, acq.probes[1].angle];
    let pred = match guess {
        Some(g) => Some(runout::predicted_slow_roll(
            &g.rotor, &sa.phi, &sa.omega, angles,
        )?),
        None => None,
    };
    let mut dc = [0.0; 2];
    let mut harm = Vec::new();
    let mut pp = [0.0; 2];
    let mut amp = [0.0; 2];
    for k in 0..2 {
        let s = acq.probes[k].sensitivity;
        let mut d: Vec<f64> = v[k].iter().map(|&x| x / s).collect();
        if let Some(p) = &pred {
            for (di, pi) in d.iter_mut().zip(&p[k]) {
                *di -= pi;
            }
            amp[k] = p[k][range.clone()]
                .iter()
                .fold(0.0f64, |m, x| m.max(x.abs()));
        }
        let h = runout::fit_harmonics(&sa.phi, &d, acq.runout_harmonics, range.clone());
        dc[k] = h.mean * s;
        pp[k] = h.peak_to_peak();
        harm.push(h);
    }
    let runout: [Harmonics; 2] = [harm.remove(0), harm.remove(0)];
    Ok(SlowRollReport {
        speed_rpm: sa.report.mean_speed_rpm,
        keyphasor: sa.report,
        dc_v: dc,
        runout,
        runout_peak_to_peak_m: pp,
        predicted_response_m: amp,
    })
}

/// Floor of a significant locked component, as a fraction of the channel's RMS: 1X, then
/// 2X and above.
const LOCKED_FLOOR: [f64; 2] = [0.02, 0.005];
/// A locked component is significant above this many standard errors.
const LOCKED_SIGMAS: f64 = 6.0;

/// Condition a raw record (module doc): `raw` holds the columns `acq` names, `slow_roll`
/// the same columns at slow roll (when `[acquisition.runout]` is given, read by the
/// caller), `guess` a rotor for the slow-roll response and the DC correction (the
/// scenario's `[rotor]` when complete, or [`ModelGuess::from_identification`] on a second
/// pass).
pub fn condition(
    raw: &RawRecord,
    acq: &Acquisition,
    slow_roll: Option<&RawRecord>,
    guess: Option<&ModelGuess>,
) -> Result<Conditioned, AcquisitionError> {
    acq.validate()?;
    let which = Which::Running;
    let stamps = time_of(raw, acq, which)?;
    let (v, kp) = channels(raw, acq, &stamps, which)?;
    let angles = [acq.probes[0].angle, acq.probes[1].angle];
    let inv = probes::inverse_projection(angles)?;
    let (t, rounded) = keyphasor_times(stamps.clone());
    let sa = shaft_angle(&t, kp, &acq.keyphasor, which)?;
    let n = t.len();
    let range = whole_revolutions(&t, &sa.report);
    let mut notes = Vec::new();
    if let Some(g) = rounded {
        notes.push(format!(
            "the time stamps are printed to {:e} s (up to {:.2e} s off the uniform grid fitted \
             over them): the keyphasor is timed on that grid, dt = {:e} s (the stamps are kept)",
            g.resolution, g.max_deviation, g.dt
        ));
    }
    let r = probes::noise_correlation(angles)?;
    if r.abs() > 0.1 {
        notes.push(format!(
            "the probes are {:.0} deg apart: the conditioned x and z carry correlated noise \
             (correlation {r:+.2} for equal probe noise); identification weighs each channel \
             as independent, so its standard errors are approximate (probes at right angles \
             avoid it)",
            probes::separation_deg(angles[0], angles[1])
        ));
    }
    let mut findings = Vec::new();
    if !sa.report.missed_pulses_before_s.is_empty() || !sa.report.spurious_pulses_s.is_empty() {
        findings.push(AcquisitionFinding::KeyphasorRepaired {
            missed_before_s: sa.report.missed_pulses_before_s.clone(),
            spurious_s: sa.report.spurious_pulses_s.clone(),
        });
    }
    let slow = match slow_roll {
        Some(s) => Some(slow_roll_runout(s, acq, guess)?),
        None => None,
    };
    if slow.is_some() && guess.is_none() {
        notes.push("no rotor guess: the slow-roll record is taken as pure runout (its own 1X response, ~(slow-roll / running speed)^2 of the running 1X, is left in)".into());
    }
    let mut dc = [0.0; 2];
    let mut d: [Vec<f64>; 2] = [Vec::with_capacity(n), Vec::with_capacity(n)];
    for k in 0..2 {
        let s = acq.probes[k].sensitivity;
        dc[k] = mean(v[k], range.clone());
        for (vi, &phi) in v[k].iter().zip(&sa.phi) {
            let mut di = (vi - dc[k]) / s;
            if let Some(sr) = &slow {
                di -= sr.runout[k].eval(phi);
            }
            d[k].push(di);
        }
    }
    let mut x = Vec::with_capacity(n);
    let mut z = Vec::with_capacity(n);
    for (d0, d1) in d[0].iter().zip(&d[1]) {
        let q = inv * nalgebra::Vector2::new(*d0, *d1);
        x.push(q[0]);
        z.push(q[1]);
    }
    let dt = (t[n - 1] - t[0]) / (n - 1) as f64;
    let mut dc_corr = dc;
    let model = match guess {
        Some(g) => {
            let r = &g.rotor;
            notes.push(format!(
                "rotor guess ({}): m = {} kg, cx = {} N s/m, kx = {} N/m, cz = {} N s/m, \
                 kz = {} N/m",
                match g.source {
                    GuessSource::Scenario => "the scenario's [rotor]",
                    GuessSource::Identification => "the previous pass's estimate",
                    GuessSource::Given => "given",
                },
                r.m,
                r.cx,
                r.kx,
                r.cz,
                r.kz
            ));
            let fit = model_fit::fit(
                &g.rotor,
                g.initial,
                dt,
                &sa.phi,
                &sa.omega,
                &sa.omega_dot,
                &x,
                &z,
            )?;
            for i in 0..n {
                x[i] -= fit.offset[0];
                z[i] -= fit.offset[1];
            }
            for k in 0..2 {
                dc_corr[k] += acq.probes[k].sensitivity
                    * probes::toward(angles[k], fit.offset[0], fit.offset[1]);
            }
            let rms = |v: &[f64]| (v.iter().map(|a| a * a).sum::<f64>() / v.len() as f64).sqrt();
            let signal = [rms(&x), rms(&z)];
            let mut comps = Vec::new();
            for (c, name) in ["x", "z"].into_iter().enumerate() {
                for h in 1..=model_fit::RESIDUAL_HARMONICS {
                    let a = fit.harmonics[c].amplitude(h);
                    let se = fit.harmonic_std_error[c];
                    let floor = LOCKED_FLOOR[usize::from(h > 1)] * signal[c];
                    if a > (LOCKED_SIGMAS * se).max(floor) {
                        comps.push(LockedComponent {
                            channel: name,
                            harmonic: h,
                            amplitude_m: a,
                            std_error_m: se,
                        });
                    }
                }
            }
            if !comps.is_empty() {
                findings.push(AcquisitionFinding::ResidualRunout {
                    slow_roll_given: slow.is_some(),
                    components: comps,
                });
            }
            if fit.initial_fitted {
                notes.push(format!("rotor guess from the {:?} without an initial state: the initial state was fitted by linear least squares", g.source).to_lowercase());
            }
            Some(fit)
        }
        None => {
            notes.push("no rotor guess: DC is the mean over whole revolutions (it holds the mean of any free transient) and residual runout was not tested".into());
            None
        }
    };
    let centre = inv
        * nalgebra::Vector2::new(
            dc_corr[0] / acq.probes[0].sensitivity,
            dc_corr[1] / acq.probes[1].sensitivity,
        );
    let centreline_shift_m = slow.as_ref().map(|s| {
        let q = inv
            * nalgebra::Vector2::new(
                (dc_corr[0] - s.dc_v[0]) / acq.probes[0].sensitivity,
                (dc_corr[1] - s.dc_v[1]) / acq.probes[1].sensitivity,
            );
        [q[0], q[1]]
    });
    let probe_report = |k: usize| {
        let p = &acq.probes[k];
        ProbeReport {
            column: p.column.clone(),
            angle_deg: p.angle.to_degrees(),
            sensitivity_v_per_m: p.sensitivity,
            dc_v: dc[k],
            dc_corrected_v: dc_corr[k],
            gap_m: -dc_corr[k] / p.sensitivity,
            noise_m: keyphasor::noise_from_differences(v[k]) / p.sensitivity.abs(),
        }
    };
    let report = ConditionReport {
        samples: n,
        dt_s: dt,
        keyphasor: sa.report,
        probes: [probe_report(0), probe_report(1)],
        centreline_m: [centre[0], centre[1]],
        centreline_shift_m,
        slow_roll: slow,
        guess: guess.copied(),
        model,
        findings,
        notes,
        passes: None,
    };
    Ok(Conditioned {
        t: stamps,
        x,
        z,
        phi: sa.phi,
        phi_dot: sa.omega,
        phi_ddot: sa.omega_dot,
        report,
    })
}
