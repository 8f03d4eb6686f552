//! One transient analysis from its inputs (docs/transient.md): the order-tracked
//! revolutions of a run-up or coast-down's raw records (or the rows of a 1X table), the
//! slow-roll compensation chosen, the speed bins, the critical speeds of each sensor's
//! compensated 1X with their API 684 separation margins, the sweep's direction and
//! whether the probes are DC-coupled. Every caller (the `rotorid transient` command, the
//! Python package) reads its files and hands the records here; [`super::report`] turns the
//! [`Analysis`] into `transient.json` and the rows of `bode.csv`.
//!
//! Raw records: [`RawAnalysis::new`], then [`RawAnalysis::add_record`] for each record of
//! the event in time order (tracked at once, so a caller can drop each record's samples
//! before reading the next), then [`RawAnalysis::finish`] with the slow-roll choice.
//! Records whose shaft angle is known per sample (a recording as `rotorid publish` sends
//! it, `t, x, z, phi`): [`RawAnalysis::with_angles`] and [`RawAnalysis::add_angles`]. A
//! 1X table: [`analyse_table`]. Pure computation: no file is read here.

use serde::Serialize;

use super::critical::{criticals, separation_margin, Critical, CriticalSettings, Margin};
use super::error::TransientError;
use super::modes::{self, fit_modes, FitBasis, ModeFit, ModeSettings, SensorSeries};
use super::order::{bin, track, OrderSettings, Tracked, C64};
use super::record::{track_record, track_record_owned, RecordTrack};
use super::slow_roll::{self, SlowRoll, SlowRollSource};
use super::spectrum::{record_cascades, Cascade, CascadeSettings};
use super::synchronous::Sweep;
use crate::acquisition::{Acquisition, KeyphasorReport, Probe, RawRecord, Which};
use crate::model::{rad_per_s_to_rpm, rpm_to_rad_per_s, OutOfRange};

/// The least relative speed change (max - min over the mean) of a Bode record \[%\].
pub const MIN_SPEED_CHANGE_PCT: f64 = 10.0;

/// A probe whose mean voltage reaches this magnitude \[V\] is taken as DC-coupled (a gap
/// voltage; an AC-coupled channel averages to about 0 V).
pub const DC_COUPLED_V: f64 = 0.5;

/// What to compute, beyond the inputs.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Settings {
    /// The orders to track (raw records; a table is 1X) and the harmonics fitted.
    pub order: OrderSettings,
    /// Average the revolutions in speed bins of this width \[rev/min\] (raw records);
    /// `None`: one point per revolution.
    pub bin_rpm: Option<f64>,
    /// The machine's operating speed range (min, max) \[rev/min\], for the API 684
    /// separation margins; `None`: no margins.
    pub operating_rpm: Option<(f64, f64)>,
    /// How resonances are told from noise.
    pub critical: CriticalSettings,
    /// The mode fit's settings; `None`: no mode fit.
    pub modes: Option<ModeSettings>,
    /// The cascades of each raw record ([`Spectra`]), computed as it is added; `None`:
    /// none.
    pub cascade: Option<CascadeSettings>,
}

impl Default for Settings {
    /// Orders 1 and 2, one point per revolution, no operating range.
    fn default() -> Self {
        Self {
            order: OrderSettings::default(),
            bin_rpm: None,
            operating_rpm: None,
            critical: CriticalSettings::default(),
            modes: Some(ModeSettings::default()),
            cascade: Some(CascadeSettings::default()),
        }
    }
}

impl Settings {
    /// Check every setting against its allowed range.
    pub fn validate(&self) -> Result<(), TransientError> {
        self.order.validate()?;
        if let Some(w) = self.bin_rpm {
            if !(w.is_finite() && w > 0.0) {
                return Err(OutOfRange {
                    field: "bin_rpm",
                    value: w,
                    allowed: "finite and > 0 (rev/min)",
                }
                .into());
            }
        }
        if let Some((lo, hi)) = self.operating_rpm {
            if !(lo.is_finite() && lo > 0.0) {
                return Err(OutOfRange {
                    field: "operating_rpm min",
                    value: lo,
                    allowed: "finite and > 0 (rev/min; the margin is relative to it)",
                }
                .into());
            }
            if !(hi.is_finite() && hi > lo) {
                return Err(OutOfRange {
                    field: "operating_rpm max",
                    value: hi,
                    allowed: "finite and > the minimum (rev/min)",
                }
                .into());
            }
        }
        Ok(())
    }
}

/// Where the runout subtracted from a raw record's vectors comes from
/// (docs/transient.md section 3).
#[derive(Debug, Clone, PartialEq)]
pub enum SlowRollChoice {
    /// The revolutions of a low speed range picked from the record
    /// ([`slow_roll::auto_range`]).
    Auto,
    /// No compensation.
    None,
    /// The revolutions of this speed range (min, max) \[rev/min\].
    Range(f64, f64),
    /// A slow-roll record of the same acquisition; `label` names it (the file as given).
    Record {
        /// The file as the user gave it.
        label: String,
        /// Its channels.
        record: RawRecord,
    },
}

/// Whether the speed rises or falls over the record.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Direction {
    /// The speed rises.
    RunUp,
    /// The speed falls.
    CoastDown,
    /// Neither clearly (a run-up and a coast-down, or a record that wanders).
    Mixed,
}

impl Direction {
    /// `run_up`, `coast_down` or `mixed`, as in `transient.json`.
    pub fn as_str(self) -> &'static str {
        match self {
            Self::RunUp => "run_up",
            Self::CoastDown => "coast_down",
            Self::Mixed => "mixed",
        }
    }

    /// The direction of the speeds `rpm` in time order: a run-up when the mean of the last
    /// tenth exceeds that of the first by more than half the span, a coast-down the other
    /// way round, else mixed.
    pub fn of(rpm: &[f64]) -> Self {
        let n = rpm.len();
        if n < 2 {
            return Self::Mixed;
        }
        let k = (n / 10).max(1);
        let head = rpm[..k].iter().sum::<f64>() / k as f64;
        let tail = rpm[n - k..].iter().sum::<f64>() / k as f64;
        let (lo, hi) = min_max(rpm.iter().copied());
        let span = hi - lo;
        if tail - head > 0.5 * span {
            Self::RunUp
        } else if head - tail > 0.5 * span {
            Self::CoastDown
        } else {
            Self::Mixed
        }
    }
}

/// One point of a sensor's Bode data.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Point {
    /// Mid time of the revolution or bin \[s\] (None from a table).
    pub t: Option<f64>,
    /// The revolution's or bin's (start, end) \[s\] (None from a table).
    pub interval: Option<(f64, f64)>,
    /// Speed \[rev/min\].
    pub rpm: f64,
    /// Vectors per order as measured \[m\], zero-to-peak.
    pub raw: Vec<C64>,
    /// Vectors per order, runout subtracted \[m\], zero-to-peak.
    pub comp: Vec<C64>,
    /// Standard deviation of each of re and im of `comp` per order \[m\]; NaN unknown.
    pub std: Vec<f64>,
    /// The probe's gap (DC) \[m\], raw records only.
    pub dc: Option<f64>,
}

/// A critical speed of a sensor's compensated 1X with its separation margin.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SensorCritical {
    /// The critical (speeds \[rev/min\], amplitude \[m\]).
    pub critical: Critical,
    /// Its API 684 margin from the operating range, when one was given.
    pub margin: Option<Margin>,
}

/// One sensor's data and results.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Sensor {
    /// Its name (the probe's column, or the table's sensor).
    pub name: String,
    /// The probe's angle from +x towards +z \[deg\] (raw records).
    pub angle_deg: Option<f64>,
    /// The orders of each point's vectors.
    pub orders: Vec<u32>,
    /// The points, in time (or table) order.
    pub points: Vec<Point>,
    /// The runout subtracted \[m\].
    pub slow_roll: Option<SlowRoll>,
    /// Its criticals (1X), by speed, with their margins.
    pub criticals: Vec<SensorCritical>,
}

impl Sensor {
    /// The sweep rate \[rpm/s\] near `rpm`: the slope of speed against time over the
    /// points within 2 % of it; `None` without times (a table) or with fewer than 3 such
    /// points.
    pub fn sweep_rate(&self, rpm: f64) -> Option<f64> {
        let near: Vec<(f64, f64)> = self
            .points
            .iter()
            .filter(|p| (p.rpm - rpm).abs() <= 0.02 * rpm)
            .filter_map(|p| p.t.map(|t| (t, p.rpm)))
            .collect();
        if near.len() < 3 {
            return None;
        }
        let n = near.len() as f64;
        let (mt, mr) = near
            .iter()
            .fold((0.0, 0.0), |(a, b), (t, r)| (a + t / n, b + r / n));
        let (sxy, sxx) = near.iter().fold((0.0, 0.0), |(a, b), (t, r)| {
            (a + (t - mt) * (r - mr), b + (t - mt) * (t - mt))
        });
        (sxx > 0.0).then(|| sxy / sxx)
    }
}

/// The spectra of one raw record, computed when it is added (so that its samples are not
/// kept until the figures): each probe's cascade and, for an XY pair, the full-spectrum
/// cascade, or why one could not be computed (the figures report it).
#[derive(Debug, Clone, PartialEq)]
pub struct Spectra {
    /// Each probe's cascade ([`super::spectrum::cascade`]) of its displacement \[m\], in
    /// the order of the sensors.
    pub probes: Vec<Result<Cascade, TransientError>>,
    /// The full-spectrum cascade of the pair ([`super::spectrum::full_cascade`]) of x and z
    /// from the two displacements; `None` with one probe.
    pub full: Option<Result<Cascade, TransientError>>,
}

impl Spectra {
    /// The spectra of the record's samples: times `t` \[s\], shaft speed `omega`
    /// \[rad/s\], each probe's `displacement` \[m\]; the pair's angles `pair` \[rad\] for
    /// the full spectrum.
    pub fn of(
        t: &[f64],
        omega: &[f64],
        displacement: &[Vec<f64>],
        pair: Option<[f64; 2]>,
        settings: &CascadeSettings,
    ) -> Self {
        let signals: Vec<&[f64]> = displacement.iter().map(Vec::as_slice).collect();
        let pair = match (pair, displacement) {
            (Some(angles), [_, _]) => Some(
                crate::acquisition::probes::inverse_projection(angles)
                    .map_err(TransientError::from),
            ),
            _ => None,
        };
        // the blocks planned once for the record's cascades
        let (probes, full) = record_cascades(t, omega, &signals, pair, settings);
        Self { probes, full }
    }
}

/// Everything a transient analysis computes.
#[derive(Debug, Clone, PartialEq)]
pub struct Analysis {
    /// The inputs as given (file names).
    pub sources: Vec<String>,
    /// Whether the speed rises or falls.
    pub direction: Direction,
    /// The sensors, at least one.
    pub sensors: Vec<Sensor>,
    /// The keyphasor reports per record (raw records).
    pub keyphasor: Vec<KeyphasorReport>,
    /// The spectra of each raw record (none from a table, or when not asked for).
    pub spectra: Vec<Spectra>,
    /// Notes for the reader.
    pub notes: Vec<String>,
    /// The operating range \[rev/min\].
    pub operating_rpm: Option<(f64, f64)>,
    /// The bin width \[rev/min\].
    pub bin_rpm: Option<f64>,
    /// The probe angles \[rad\] of the XY pair, when two probes.
    pub pair_angles: Option<[f64; 2]>,
    /// Whether the probes are DC-coupled (their mean voltage is a gap voltage: at least
    /// [`DC_COUPLED_V`] in magnitude on each).
    pub dc_coupled: bool,
    /// The modes fitted to the sensors' compensated 1X (None when not asked for, without
    /// a critical, or when the fit failed: the notes say which).
    pub modes: Option<Modes>,
}

/// The mode fit of an analysis.
#[derive(Debug, Clone, PartialEq)]
pub struct Modes {
    /// The fit.
    pub fit: ModeFit,
    /// The sensors fitted (indices into [`Analysis::sensors`], in the order of
    /// `fit.model`).
    pub sensors: Vec<usize>,
}

impl Analysis {
    /// The speed range of all points (min, max) \[rev/min\].
    pub fn speed_range(&self) -> (f64, f64) {
        min_max(
            self.sensors
                .iter()
                .flat_map(|s| s.points.iter().map(|p| p.rpm)),
        )
    }
}

fn min_max(v: impl Iterator<Item = f64>) -> (f64, f64) {
    v.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
        (a.min(x), b.max(x))
    })
}

/// The speed d phi / dt \[rad/s\] at each sample: central differences inside, one-sided at
/// the ends (0 for fewer than two samples).
fn angular_speed(t: &[f64], phi: &[f64]) -> Vec<f64> {
    let n = t.len().min(phi.len());
    (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(1), (i + 1).min(n.saturating_sub(1)));
            if b > a {
                (phi[b] - phi[a]) / (t[b] - t[a])
            } else {
                0.0
            }
        })
        .collect()
}

/// `Ok` when the speeds `rpm` change by at least [`MIN_SPEED_CHANGE_PCT`] of their mean.
pub fn speed_check(rpm: impl Iterator<Item = f64>) -> Result<(), TransientError> {
    let (mut lo, mut hi, mut sum, mut n) = (f64::INFINITY, f64::NEG_INFINITY, 0.0, 0usize);
    for r in rpm {
        lo = lo.min(r);
        hi = hi.max(r);
        sum += r;
        n += 1;
    }
    let mean = sum / n.max(1) as f64;
    let change = (hi - lo) / mean * 100.0;
    if n == 0 || change.is_nan() || change < MIN_SPEED_CHANGE_PCT {
        return Err(TransientError::SpeedTooSteady {
            min_rpm: lo,
            max_rpm: hi,
            change_pct: if change.is_finite() { change } else { 0.0 },
            needed_pct: MIN_SPEED_CHANGE_PCT,
        });
    }
    Ok(())
}

/// `e` as an error of `input` (a record, a sensor, a step), whose name comes first.
fn within(input: impl Into<String>) -> impl FnOnce(TransientError) -> TransientError {
    let input = input.into();
    move |e| TransientError::Within {
        input,
        source: Box::new(e),
    }
}

/// A run-up or coast-down's records, order-tracked as they are added (module doc).
#[derive(Debug, Clone)]
pub struct RawAnalysis<'a> {
    /// The acquisition of raw records (None: records whose shaft angle is given).
    acq: Option<&'a Acquisition>,
    /// The probes tracked (one or two), in the order of the sensors.
    probes: Vec<Probe>,
    settings: Settings,
    sources: Vec<String>,
    tracked: Vec<Tracked>,
    keyphasor: Vec<KeyphasorReport>,
    spectra: Vec<Spectra>,
}

impl<'a> RawAnalysis<'a> {
    /// An analysis of raw records described by `acq` (one or two probes), `settings`
    /// checked; records are added by [`RawAnalysis::add_record`].
    pub fn new(acq: &'a Acquisition, settings: Settings) -> Result<Self, TransientError> {
        settings.validate()?;
        let probes = if acq.single_probe {
            vec![acq.probes[0].clone()]
        } else {
            acq.probes.to_vec()
        };
        Ok(Self {
            acq: Some(acq),
            probes,
            settings,
            sources: Vec::new(),
            tracked: Vec::new(),
            keyphasor: Vec::new(),
            spectra: Vec::new(),
        })
    }

    /// An analysis of records whose shaft angle is known per sample (an encoder, a
    /// simulation, a recording as `rotorid publish` sends it: `t, x, z, phi`), the
    /// displacement of each of `probes` given in m (their sensitivities are not used),
    /// `settings` checked; records are added by [`RawAnalysis::add_angles`]. The x and z
    /// of a response recording are probes at 0 and 90 deg: [`RawAnalysis::xz_probes`].
    pub fn with_angles(probes: Vec<Probe>, settings: Settings) -> Result<Self, TransientError> {
        settings.validate()?;
        if !(1..=2).contains(&probes.len()) {
            return Err(TransientError::TooFew {
                what: "probes (one, or an XY pair)".into(),
                found: probes.len(),
                needed: 1,
            });
        }
        Ok(Self {
            acq: None,
            probes,
            settings,
            sources: Vec::new(),
            tracked: Vec::new(),
            keyphasor: Vec::new(),
            spectra: Vec::new(),
        })
    }

    /// The x and z of a response recording (`t, x, z[, phi, ...]`, docs/fleet.md) as
    /// probes: `x` at 0 deg (horizontal), `z` at 90 deg (vertical), in m.
    pub fn xz_probes() -> Vec<Probe> {
        [("x", 0.0), ("z", std::f64::consts::FRAC_PI_2)]
            .map(|(column, angle)| Probe {
                column: column.into(),
                angle,
                sensitivity: 1.0,
            })
            .to_vec()
    }

    /// The indices of the acquisition's probes tracked: both, or the one of a
    /// single-probe scenario.
    fn indices(&self) -> &'static [usize] {
        if self.probes.len() == 1 {
            &[0]
        } else {
            &[0, 1]
        }
    }

    /// The record's tracked vectors added, and its spectra computed from its samples
    /// (which the caller can then drop).
    fn push(
        &mut self,
        source: &str,
        tracked: Vec<Tracked>,
        t: &[f64],
        omega: &[f64],
        displacement: &[Vec<f64>],
    ) {
        for (k, t) in tracked.into_iter().enumerate() {
            match self.tracked.get_mut(k) {
                Some(all) => all.revolutions.extend(t.revolutions),
                None => self.tracked.push(t),
            }
        }
        self.sources.push(source.to_owned());
        if let Some(settings) = &self.settings.cascade {
            let pair =
                (self.probes.len() == 2).then(|| [self.probes[0].angle, self.probes[1].angle]);
            self.spectra
                .push(Spectra::of(t, omega, displacement, pair, settings));
        }
    }

    /// The record's track added ([`RawAnalysis::push`]).
    fn push_track(&mut self, source: &str, r: RecordTrack) {
        self.keyphasor.push(r.keyphasor);
        let tracked = r.probes.into_iter().map(|p| p.tracked).collect();
        self.push(source, tracked, &r.t, &r.omega, &r.displacement);
    }

    /// Order-track the next raw record of the event, `source` naming it (errors start
    /// with it: `runup.csv: order tracking: ...`).
    pub fn add_record(&mut self, source: &str, raw: &RawRecord) -> Result<(), TransientError> {
        let acq = self.raw_acquisition(source)?;
        let r = track_record(
            raw,
            acq,
            self.indices(),
            &self.settings.order,
            Which::Running,
        );
        self.push_tracked(source, r)
    }

    /// The scenario's `[acquisition]`, which a raw record needs.
    fn raw_acquisition(&self, source: &str) -> Result<&'a Acquisition, TransientError> {
        self.acq.ok_or_else(|| TransientError::Unusable {
            input: source.to_owned(),
            reason: "a raw record (probe volts and a keyphasor) needs the scenario's [acquisition]; this analysis takes records with a shaft angle",
        })
    }

    /// A raw record's tracking, or its error named by `source`.
    fn push_tracked(
        &mut self,
        source: &str,
        r: Result<RecordTrack, TransientError>,
    ) -> Result<(), TransientError> {
        let r = r.map_err(within(format!("{source}: order tracking")))?;
        self.push_track(source, r);
        Ok(())
    }

    /// [`RawAnalysis::add_record`] of a record the caller gives away: the same results,
    /// its columns moved out of it rather than copied (`record::track_record_owned`), so
    /// that the record is not held beside the tracking's own columns.
    pub fn add_record_owned(&mut self, source: &str, raw: RawRecord) -> Result<(), TransientError> {
        let acq = self.raw_acquisition(source)?;
        let r = track_record_owned(
            raw,
            acq,
            self.indices(),
            &self.settings.order,
            Which::Running,
        );
        self.push_tracked(source, r)
    }

    /// Order-track the next record of the event whose shaft angle `phi` \[rad\] is known
    /// at each time `t` \[s\] (increasing; the keyphasor events are where phi passes a
    /// multiple of 2 pi, so the phase lags are measured from phi = 0 mod 2 pi), with the
    /// displacement \[m\] of each probe of [`RawAnalysis::with_angles`]; `source` names it.
    pub fn add_angles(
        &mut self,
        source: &str,
        t: Vec<f64>,
        phi: &[f64],
        displacement: Vec<Vec<f64>>,
    ) -> Result<(), TransientError> {
        if self.acq.is_some() {
            return Err(TransientError::Unusable {
                input: source.to_owned(),
                reason: "this analysis takes raw records described by [acquisition], not records with a shaft angle",
            });
        }
        if displacement.len() != self.probes.len() {
            return Err(TransientError::LengthMismatch {
                field: "displacements",
                len: displacement.len(),
                other: "probes",
                expected: self.probes.len(),
            })
            .map_err(within(source));
        }
        let tracked = displacement
            .iter()
            .map(|d| track(&t, phi, d, &self.settings.order))
            .collect::<Result<Vec<_>, _>>()
            .map_err(within(format!("{source}: order tracking")))?;
        let omega = angular_speed(&t, phi);
        self.push(source, tracked, &t, &omega, &displacement);
        Ok(())
    }

    /// The runout of each probe per `choice` (docs/transient.md section 3), with the
    /// notes it makes.
    fn slow_roll(
        &self,
        choice: SlowRollChoice,
        notes: &mut Vec<String>,
    ) -> Result<Vec<Option<SlowRoll>>, TransientError> {
        let from_range = |a: f64, b: f64, source: SlowRollSource| {
            self.tracked
                .iter()
                .map(|t| slow_roll::from_revolutions(t, a, b, source.clone()).map(Some))
                .collect::<Result<Vec<_>, _>>()
        };
        match choice {
            SlowRollChoice::None => {
                notes.push(
                    "no slow-roll compensation (--slow-roll none): the vectors are as measured"
                        .into(),
                );
                Ok(vec![None; self.tracked.len()])
            }
            SlowRollChoice::Record { label, record } => {
                let acq = self.acq.ok_or_else(|| TransientError::Unusable {
                    input: label.clone(),
                    reason: "a slow-roll record is a raw record of the scenario's [acquisition]; for records with a shaft angle take the runout from a speed range (or auto)",
                })?;
                let r = track_record(
                    &record,
                    acq,
                    self.indices(),
                    &self.settings.order,
                    Which::SlowRoll,
                )
                .map_err(within(format!(
                    "{label}: order tracking of the slow-roll record"
                )))?;
                r.probes
                    .iter()
                    .map(|p| slow_roll::from_record(&p.tracked, &label).map(Some))
                    .collect::<Result<Vec<_>, _>>()
                    .map_err(within(format!("{label}: the slow-roll record")))
            }
            SlowRollChoice::Range(a, b) => from_range(
                a,
                b,
                SlowRollSource::Range {
                    min_rpm: a,
                    max_rpm: b,
                },
            )
            .map_err(within("--slow-roll")),
            SlowRollChoice::Auto => {
                let all_rpm: Vec<f64> = self.tracked[0]
                    .revolutions
                    .iter()
                    .map(|r| r.rpm())
                    .collect();
                let (a, b) = slow_roll::auto_range(&all_rpm).ok_or(TransientError::TooFew {
                    what: "revolutions for an automatic slow roll".into(),
                    found: 0,
                    needed: 2,
                })?;
                notes.push(format!(
                    "slow roll: the runout is taken from the revolutions from {a:.1} to {b:.1} rpm (the record's lowest speeds, picked automatically; --slow-roll FILE or RPM_MIN:RPM_MAX overrides)"
                ));
                from_range(
                    a,
                    b,
                    SlowRollSource::Auto {
                        min_rpm: a,
                        max_rpm: b,
                    },
                )
                .map_err(within("--slow-roll auto"))
            }
        }
    }

    /// The analysis of the records added, compensated per `slow_roll`: the speed checked
    /// (it must change by [`MIN_SPEED_CHANGE_PCT`]), the points binned when asked, the
    /// criticals with their margins.
    pub fn finish(self, slow_roll: SlowRollChoice) -> Result<Analysis, TransientError> {
        if self.tracked.is_empty() {
            return Err(TransientError::TooFew {
                what: "records of the transient".into(),
                found: 0,
                needed: 1,
            });
        }
        speed_check(self.tracked[0].revolutions.iter().map(|r| r.rpm()))
            .map_err(within(self.sources.join(", ")))?;
        let mut notes = Vec::new();
        if self.probes.len() == 1 {
            notes.push(format!(
                "one probe ({}): everything but the full spectrum and the shaft centreline (they need an XY pair)",
                self.probes[0].column
            ));
        }
        if self.acq.is_none() {
            notes.push(
                "the shaft angle is the record's phi (keyphasor events where phi passes a multiple of 2 pi): phase lags are measured from there".into(),
            );
        }
        let srs = self.slow_roll(slow_roll, &mut notes)?;
        let mut sensors = Vec::new();
        for (k, (t, sr)) in self.tracked.iter().zip(srs).enumerate() {
            let comp = match &sr {
                Some(s) => slow_roll::compensate(t, s),
                None => t.clone(),
            };
            let (raw, comp) = match self.settings.bin_rpm {
                Some(w) => (bin(t, w)?, bin(&comp, w)?),
                None => (t.clone(), comp),
            };
            let points = raw
                .revolutions
                .iter()
                .zip(&comp.revolutions)
                .map(|(r, c)| Point {
                    t: Some(0.5 * (r.t_start + r.t_end)),
                    interval: Some((r.t_start, r.t_end)),
                    rpm: rad_per_s_to_rpm(c.speed),
                    raw: r.vectors.clone(),
                    comp: c.vectors.clone(),
                    std: c.std.clone(),
                    dc: Some(r.dc),
                })
                .collect();
            let p = &self.probes[k];
            sensors.push(Sensor {
                name: p.column.clone(),
                angle_deg: Some(p.angle.to_degrees()),
                orders: self.settings.order.orders.clone(),
                points,
                slow_roll: sr,
                criticals: Vec::new(),
            });
        }
        let rpm: Vec<f64> = sensors[0].points.iter().map(|p| p.rpm).collect();
        // a gap voltage needs volts: raw records of an XY pair only
        let dc_coupled = self.acq.is_some()
            && self.probes.len() == 2
            && sensors.iter().zip(&self.probes).all(|(s, p)| {
                let n = s.points.len().max(1) as f64;
                let volts = s.points.iter().filter_map(|q| q.dc).sum::<f64>() / n * p.sensitivity;
                volts.abs() >= DC_COUPLED_V
            });
        let mut a = Analysis {
            sources: self.sources,
            direction: Direction::of(&rpm),
            sensors,
            keyphasor: self.keyphasor,
            spectra: self.spectra,
            notes,
            operating_rpm: self.settings.operating_rpm,
            bin_rpm: self.settings.bin_rpm,
            pair_angles: (self.probes.len() == 2)
                .then(|| [self.probes[0].angle, self.probes[1].angle]),
            dc_coupled,
            modes: None,
        };
        find_criticals(&mut a, &self.settings.critical)?;
        if let Some(m) = &self.settings.modes {
            find_modes(&mut a, m);
        }
        Ok(a)
    }
}

/// One row of a 1X table, in SI (the readers' `BodeRow` without its line).
#[derive(Debug, Clone, PartialEq)]
pub struct TableRow {
    /// Speed \[rev/min\].
    pub speed_rpm: f64,
    /// The sensor that measured it.
    pub sensor: String,
    /// Re V \[m\], zero-to-peak.
    pub re: f64,
    /// Im V \[m\], zero-to-peak.
    pub im: f64,
    /// Standard deviations of re and im \[m\], when the table gives them.
    pub std: Option<(f64, f64)>,
}

/// The analysis of a 1X table's `rows` (read from `source`), taken as compensated
/// (docs/transient.md section 7): each sensor's speed checked, its criticals with their
/// margins from `settings` (orders and bins do not apply).
pub fn analyse_table(
    source: &str,
    rows: Vec<TableRow>,
    settings: &Settings,
) -> Result<Analysis, TransientError> {
    settings.validate()?;
    let mut sensors: Vec<Sensor> = Vec::new();
    for r in rows {
        let v = C64::new(r.re, r.im);
        let std = r
            .std
            .map_or(f64::NAN, |(a, b)| (0.5 * (a * a + b * b)).sqrt());
        let point = Point {
            t: None,
            interval: None,
            rpm: r.speed_rpm,
            raw: vec![v],
            comp: vec![v],
            std: vec![std],
            dc: None,
        };
        match sensors.iter_mut().find(|s| s.name == r.sensor) {
            Some(s) => s.points.push(point),
            None => sensors.push(Sensor {
                name: r.sensor,
                angle_deg: None,
                orders: vec![1],
                points: vec![point],
                slow_roll: None,
                criticals: Vec::new(),
            }),
        }
    }
    if sensors.is_empty() {
        return Err(TransientError::Within {
            input: source.to_owned(),
            source: Box::new(TransientError::TooFew {
                what: "rows of the 1X table".into(),
                found: 0,
                needed: 5,
            }),
        });
    }
    for s in &sensors {
        speed_check(s.points.iter().map(|p| p.rpm))
            .map_err(within(format!("{source}: sensor {:?}", s.name)))?;
    }
    let mut notes = vec![format!(
        "{source}: a 1X table: its vectors are taken as compensated (subtract the slow-roll vector before exporting if the system did not); no cascade or full spectrum without the raw signals"
    )];
    if sensors.len() == 1 {
        notes
            .push("one sensor: no full spectrum or shaft centreline (they need an XY pair)".into());
    }
    let rpm: Vec<f64> = sensors[0].points.iter().map(|p| p.rpm).collect();
    let mut a = Analysis {
        sources: vec![source.to_owned()],
        direction: Direction::of(&rpm),
        sensors,
        keyphasor: Vec::new(),
        spectra: Vec::new(),
        notes,
        operating_rpm: settings.operating_rpm,
        bin_rpm: None,
        pair_angles: None,
        dc_coupled: false,
        modes: None,
    };
    find_criticals(&mut a, &settings.critical)?;
    if let Some(m) = &settings.modes {
        find_modes(&mut a, m);
    }
    Ok(a)
}

/// The criticals of each sensor's compensated 1X, with their margins.
fn find_criticals(a: &mut Analysis, settings: &CriticalSettings) -> Result<(), TransientError> {
    for s in &mut a.sensors {
        let Some(o) = s.orders.iter().position(|&n| n == 1) else {
            continue;
        };
        let rpm: Vec<f64> = s.points.iter().map(|p| p.rpm).collect();
        let v: Vec<C64> = s.points.iter().map(|p| p.comp[o]).collect();
        let std: Vec<f64> = s.points.iter().map(|p| p.std[o]).collect();
        let found = criticals(&rpm, &v, &std, settings)
            .map_err(within(format!("the critical speeds of {}", s.name)))?;
        s.criticals = found
            .into_iter()
            .map(|c| {
                let margin = a
                    .operating_rpm
                    .map(|(lo, hi)| separation_margin(c.rpm, c.amplification_factor, lo, hi));
                SensorCritical {
                    critical: c,
                    margin,
                }
            })
            .collect();
    }
    Ok(())
}

/// The modes of the sensors' compensated 1X ([`super::modes`]), started from their
/// criticals; what was fitted, or why nothing was, in the notes.
fn find_modes(a: &mut Analysis, settings: &ModeSettings) {
    let all: Vec<Critical> = a
        .sensors
        .iter()
        .flat_map(|s| s.criticals.iter().map(|c| c.critical.clone()))
        .collect();
    let guesses = modes::guesses(&all);
    if guesses.is_empty() {
        a.notes
            .push("no mode fit: no critical speed was found to start it from".into());
        return;
    }
    let one_x = |s: &Sensor| s.orders.iter().position(|&n| n == 1);
    let Some(first) = a.sensors.iter().position(|s| one_x(s).is_some()) else {
        return;
    };
    let key = |s: &Sensor| -> Vec<(u64, Option<(u64, u64)>)> {
        s.points
            .iter()
            .map(|p| {
                (
                    p.rpm.to_bits(),
                    p.interval.map(|(a, b)| (a.to_bits(), b.to_bits())),
                )
            })
            .collect()
    };
    let reference = key(&a.sensors[first]);
    let (fitted, left): (Vec<usize>, Vec<usize>) = (0..a.sensors.len())
        .filter(|&k| one_x(&a.sensors[k]).is_some())
        .partition(|&k| key(&a.sensors[k]) == reference);
    if !left.is_empty() {
        let names: Vec<&str> = left.iter().map(|&k| a.sensors[k].name.as_str()).collect();
        a.notes.push(format!(
            "mode fit: {} left out (its speeds differ from {}'s; the fit takes sensors measured at the same points)",
            names.join(", "),
            a.sensors[first].name
        ));
    }
    let points = &a.sensors[first].points;
    let speed: Vec<f64> = points.iter().map(|p| rpm_to_rad_per_s(p.rpm)).collect();
    let sweep = match points
        .iter()
        .map(|p| p.interval)
        .collect::<Option<Vec<_>>>()
    {
        Some(intervals) => Sweep::Transient { intervals, speed },
        None => Sweep::Steady { speed },
    };
    let data: Vec<(Vec<C64>, Vec<f64>)> = fitted
        .iter()
        .map(|&k| {
            let s = &a.sensors[k];
            let o = one_x(s).expect("filtered");
            (
                s.points.iter().map(|p| p.comp[o]).collect(),
                s.points.iter().map(|p| p.std[o]).collect(),
            )
        })
        .collect();
    let series: Vec<SensorSeries> = data
        .iter()
        .map(|(v, s)| SensorSeries { vectors: v, std: s })
        .collect();
    match fit_modes(&sweep, &series, &guesses, settings) {
        Ok(fit) => {
            let names: Vec<&str> = fitted.iter().map(|&k| a.sensors[k].name.as_str()).collect();
            let list: Vec<String> = fit
                .modes
                .iter()
                .map(|m| {
                    format!(
                        "{:.1} +- {:.1} rpm (damping ratio {:.4} +- {:.4})",
                        m.rpm, m.rpm_std, m.damping_ratio, m.damping_ratio_std
                    )
                })
                .collect();
            a.notes.push(format!(
                "mode fit ({}, {}, {:.0} to {:.0} rpm): {} mode{} chosen by BIC: {}",
                match fit.basis {
                    FitBasis::Transient => "the transient response along the measured speed",
                    FitBasis::SteadyState => "steady-state response: a table has no times, so these modes carry the sweep's bias as the half-power figures do",
                },
                names.join(", "),
                fit.window_rpm.0,
                fit.window_rpm.1,
                fit.modes.len(),
                if fit.modes.len() == 1 { "" } else { "s" },
                list.join("; ")
            ));
            if !fit.converged {
                a.notes.push(format!(
                    "mode fit: the iteration stopped after {} trials without converging: its modes are approximate",
                    fit.iterations
                ));
            }
            if !fit.adequate {
                a.notes.push(format!(
                    "mode fit: the residuals show what the model misses (level {:.2} of the noise, whiteness p {}): its standard deviations understate the error (unmodelled modes, speed-dependent modes, a nonlinearity, or a runout the slow roll did not remove)",
                    fit.noise_ratio,
                    fit.ljung_box_p
                        .iter()
                        .map(|p| format!("{p:.1e}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                ));
            }
            a.modes = Some(Modes {
                fit,
                sensors: fitted,
            });
        }
        Err(e) => a.notes.push(format!("no mode fit: {e}")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn direction_of_a_sweep() {
        let up: Vec<f64> = (0..100).map(f64::from).collect();
        let down: Vec<f64> = up.iter().rev().copied().collect();
        assert_eq!(Direction::of(&up), Direction::RunUp);
        assert_eq!(Direction::of(&down), Direction::CoastDown);
        assert_eq!(Direction::of(&[1.0, 5.0, 1.0]), Direction::Mixed);
        assert_eq!(Direction::RunUp.as_str(), "run_up");
    }

    #[test]
    fn a_steady_speed_is_refused_with_its_change() {
        let e = speed_check([1000.0, 1010.0, 1020.0].into_iter()).unwrap_err();
        let m = e.to_string();
        assert!(
            m.contains("1000.0 to 1020.0 rpm") && m.contains("1.98 %"),
            "{m}"
        );
        assert!(speed_check([1000.0, 1500.0].into_iter()).is_ok());
    }

    #[test]
    fn settings_out_of_range_name_the_field() {
        let s = Settings {
            bin_rpm: Some(0.0),
            ..Settings::default()
        };
        assert!(s.validate().unwrap_err().to_string().contains("bin_rpm"));
        let s = Settings {
            operating_rpm: Some((3600.0, 3000.0)),
            ..Settings::default()
        };
        assert!(s
            .validate()
            .unwrap_err()
            .to_string()
            .contains("operating_rpm max"));
    }

    /// A single-mode 1X curve, A / (1 - r^2 + 2 i zeta r) at r = rpm / nc: the table form
    /// finds its critical at the closed form's peak, nc / sqrt(1 - 2 zeta^2), and the
    /// margin API 684 gives from the reported AF.
    #[test]
    fn a_table_of_one_mode_gives_its_critical_and_margin() {
        let (nc, zeta, a0) = (3000.0, 0.05, 1e-5);
        let rows: Vec<TableRow> = (0..400)
            .map(|i| {
                let rpm = 1500.0 + 5.0 * f64::from(i);
                let r = rpm / nc;
                let v = C64::new(a0 * r * r, 0.0) / C64::new(1.0 - r * r, 2.0 * zeta * r);
                TableRow {
                    speed_rpm: rpm,
                    sensor: "x".into(),
                    re: v.re,
                    im: v.im,
                    std: None,
                }
            })
            .collect();
        let settings = Settings {
            operating_rpm: Some((3600.0, 4000.0)),
            ..Settings::default()
        };
        let a = analyse_table("t.csv", rows, &settings).unwrap();
        assert_eq!(a.direction, Direction::RunUp);
        let c = &a.sensors[0].criticals;
        assert_eq!(c.len(), 1, "{c:?}");
        // the peak of r^2 / |1 - r^2 + 2 i zeta r| is at r = 1 / sqrt(1 - 2 zeta^2)
        let peak = nc / (1.0 - 2.0 * zeta * zeta).sqrt();
        assert!((c[0].critical.rpm / peak - 1.0).abs() < 2e-3, "{c:?}");
        let af = c[0].critical.amplification_factor.unwrap();
        assert!((af * 2.0 * zeta - 1.0).abs() < 0.05, "AF {af}");
        let m = c[0].margin.as_ref().unwrap();
        let want = separation_margin(c[0].critical.rpm, Some(af), 3600.0, 4000.0);
        assert_eq!(m, &want);
        assert!((m.separation_pct - (3600.0 - c[0].critical.rpm) / 36.0).abs() < 1e-9);
    }

    #[test]
    fn an_empty_table_is_refused_by_name() {
        let e = analyse_table("t.csv", Vec::new(), &Settings::default()).unwrap_err();
        assert!(e.to_string().starts_with("t.csv: "), "{e}");
    }

    /// A record with its shaft angle (as `rotorid publish` sends one: t, x, z, phi): x and
    /// z each the quasi-steady response of one mode, Re(V(w) e^{i phi}) with
    /// V = A r^2 / (1 - r^2 + 2 i zeta r), r = w / wn, plus noise, on a slow sweep. Each
    /// has its one critical at the closed form's peak, wn / sqrt(1 - 2 zeta^2).
    #[test]
    fn a_record_with_its_shaft_angle_gives_each_modes_critical() {
        use rand::SeedableRng as _;
        use rand_distr::Distribution as _;
        let (rate, seconds) = (5000.0, 40.0);
        let (w0, w1) = (
            crate::model::rpm_to_rad_per_s(1000.0),
            crate::model::rpm_to_rad_per_s(5000.0),
        );
        let acc = (w1 - w0) / seconds;
        let n = (rate * seconds) as usize;
        let t: Vec<f64> = (0..n).map(|i| i as f64 / rate).collect();
        let phi: Vec<f64> = t
            .iter()
            .map(|&t| 0.3 + w0 * t + 0.5 * acc * t * t)
            .collect();
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let noise = rand_distr::Normal::new(0.0, 2e-7).unwrap();
        let modes = [(3000.0, 0.05), (3600.0, 0.04)];
        let displacement: Vec<Vec<f64>> = modes
            .iter()
            .map(|&(nc, zeta)| {
                t.iter()
                    .zip(&phi)
                    .map(|(&t, &p)| {
                        let r = rad_per_s_to_rpm(w0 + acc * t) / nc;
                        let v = C64::new(1e-5 * r * r, 0.0) / C64::new(1.0 - r * r, 2.0 * zeta * r);
                        (v * C64::from_polar(1.0, p)).re + noise.sample(&mut rng)
                    })
                    .collect()
            })
            .collect();
        let settings = Settings {
            order: OrderSettings {
                orders: vec![1],
                ..OrderSettings::default()
            },
            ..Settings::default()
        };
        let mut a = RawAnalysis::with_angles(RawAnalysis::xz_probes(), settings).unwrap();
        let raw = RawRecord {
            columns: vec![("t".into(), t.clone())],
        };
        assert!(a
            .add_record("r.csv", &raw)
            .unwrap_err()
            .to_string()
            .starts_with("r.csv: "));
        a.add_angles("r.csv", t, &phi, displacement).unwrap();
        let out = a.finish(SlowRollChoice::None).unwrap();
        assert_eq!(out.direction, Direction::RunUp);
        assert_eq!(out.pair_angles, Some([0.0, std::f64::consts::FRAC_PI_2]));
        assert!(!out.dc_coupled);
        assert!(
            out.notes.iter().any(|n| n.contains("phi")),
            "{:?}",
            out.notes
        );
        for (s, &(nc, zeta)) in out.sensors.iter().zip(&modes) {
            let c = &s.criticals;
            assert_eq!(c.len(), 1, "{}: {c:?}", s.name);
            let peak = nc / (1.0 - 2.0 * zeta * zeta).sqrt();
            assert!(
                (c[0].critical.rpm / peak - 1.0).abs() < 3e-3,
                "{}: {} rpm, closed form {peak}",
                s.name,
                c[0].critical.rpm
            );
            let af = c[0].critical.amplification_factor.unwrap();
            assert!((af * 2.0 * zeta - 1.0).abs() < 0.1, "{}: AF {af}", s.name);
        }
        assert_eq!(
            out.sensors
                .iter()
                .map(|s| s.name.as_str())
                .collect::<Vec<_>>(),
            ["x", "z"]
        );
    }
}
