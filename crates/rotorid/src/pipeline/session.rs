//! A streaming identification: samples are pushed as they arrive (one by one or in
//! chunks) and [`Session::finish`] returns the [`Identification`]. The algebraic
//! identifier reports an estimate per sample as soon as it can, in bounded memory; the
//! modulating identifier updates its least squares window by window, in bounded memory;
//! the refinement holds the samples and fits them at the end.
//!
//! The time grid: given ([`Timing::Grid`]), or fitted by least squares over the first
//! `head` stamps ([`Timing::Fit`]), which are held back until then; [`Session::start_now`]
//! fits over what has arrived (a live acquisition that has run dry). Every later stamp is
//! checked against the least-squares fit of all stamps so far. At the end the grid of all
//! stamps is compared with the one used ([`Finding::TimeGridDrift`]).

use crate::identify::algebraic::{AlgebraicEstimate, ConvergenceTracker, RestartingIdentifier};
use crate::identify::modulating::ModulatingIdentifier;
use crate::identify::Measurement;
use crate::model::{SpeedProfile, SpeedState};

use super::diagnostic::{Diagnostic, Directions, Finding};
use super::error::PipelineError;
use super::grid::{check_tolerance, RunningGrid, TimeGrid, DEFAULT_TIME_TOLERANCE};
use super::identification::Identification;
use super::knowledge::Knowledge;
use super::method::{AlgebraicSettings, Method};
use super::record::{Record, Speed, SpeedSource};

/// Stamps over which a stream's grid is fitted by default (0.4 s at 10 kHz).
pub const DEFAULT_GRID_HEAD: usize = 4096;
/// Fewest samples the algebraic identifier accepts: its 3x3 system can first be well
/// conditioned at the 4th sample (tau = 3 dt) with every quadrature rule.
pub const ALGEBRAIC_MIN_SAMPLES: usize = 4;
/// Relative difference between the grid of all stamps and the one used above which a
/// stream warns ([`Finding::TimeGridDrift`]): estimates move by about twice it.
pub const GRID_DRIFT_LIMIT: f64 = 1e-6;

/// One sample as it arrives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Its time stamp \[s\]; `None` on a given grid (then t = t0 + i dt).
    pub t: Option<f64>,
    /// Horizontal displacement \[m\].
    pub x: f64,
    /// Vertical displacement \[m\].
    pub z: f64,
    /// phi \[rad\], w \[rad/s\], w' \[rad/s^2\]; `None` when the session's profile gives them.
    pub speed: Option<SpeedState>,
}

/// How a session knows its time grid (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Timing {
    /// Least squares over the first `head` stamps (>= 2); each stamp within `tolerance`
    /// dt of the fit.
    Fit {
        /// Stamps to fit over before the first estimate.
        head: usize,
        /// Allowed deviation from the grid, relative to dt.
        tolerance: f64,
    },
    /// This grid; stamps, when given, within `tolerance` dt of it.
    Grid {
        /// The grid.
        grid: TimeGrid,
        /// Allowed deviation from the grid, relative to dt.
        tolerance: f64,
    },
}

impl Default for Timing {
    fn default() -> Self {
        Timing::Fit {
            head: DEFAULT_GRID_HEAD,
            tolerance: DEFAULT_TIME_TOLERANCE,
        }
    }
}

/// An estimate of the algebraic identifier at one sample: `estimate.t` is the sample's
/// stamp; `well_conditioned` per direction (x, z): the values of an ill-conditioned
/// direction must not be used.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleEstimate {
    /// The estimate.
    pub estimate: AlgebraicEstimate,
    /// Whether each direction's 3x3 system is well conditioned.
    pub well_conditioned: [bool; 2],
    /// The restart window the estimate comes from (0 without restarts; see
    /// [`AlgebraicSettings::restart_s`](super::AlgebraicSettings::restart_s)).
    pub window: u64,
}

enum Engine {
    Algebraic {
        id: Box<RestartingIdentifier>,
        tracker: Box<ConvergenceTracker>,
        settings: AlgebraicSettings,
        flagged: Directions<u64>,
        last: Option<AlgebraicEstimate>,
        keep: Option<Vec<AlgebraicEstimate>>,
        /// The first [`ALGEBRAIC_ADEQUACY_SAMPLES`] samples, for the adequacy test.
        kept: Kept,
    },
    Modulating {
        id: Box<ModulatingIdentifier>,
        /// The samples, for the Cramer-Rao bound and the adequacy test; the first
        /// [`MODULATING_CRB_MAX_SAMPLES`] of a longer record.
        kept: Kept,
        /// Whether `kept` holds every sample.
        complete: bool,
    },
    Refine {
        kept: Kept,
    },
}

/// Longest record whose samples a modulating session keeps for its Cramer-Rao bound and
/// its adequacy test (5 columns of 8 bytes: 80 MB); longer ones report the bound
/// unavailable, and their adequacy is tested over their first this many samples.
pub const MODULATING_CRB_MAX_SAMPLES: usize = 2_000_000;

/// Samples an algebraic session keeps for its adequacy test, which it makes over the
/// record's first this many samples (5 columns of 8 bytes: 0.66 MB; 1.6 s at 10 kHz): its
/// memory stays bounded (a streamed identify of any length peaks under 16 MiB).
pub const ALGEBRAIC_ADEQUACY_SAMPLES: usize = 1 << 14;

/// Samples kept for a computation over the whole record.
#[derive(Debug, Default)]
struct Kept {
    t: Vec<f64>,
    x: Vec<f64>,
    z: Vec<f64>,
    speed: [Vec<f64>; 3],
}

impl Kept {
    fn push(&mut self, t: f64, s: &Sample) {
        self.t.push(t);
        self.x.push(s.x);
        self.z.push(s.z);
        if let Some(sp) = s.speed {
            self.speed[0].push(sp.phi);
            self.speed[1].push(sp.omega);
            self.speed[2].push(sp.omega_dot);
        }
    }
}

/// A streaming identification (module doc).
pub struct Session {
    knowledge: Knowledge,
    method: Method,
    profile: Option<SpeedProfile>,
    timing: Timing,
    /// The grid in use, once known.
    grid: Option<TimeGrid>,
    /// The least-squares fit of every stamp so far.
    running: RunningGrid,
    head: Vec<Sample>,
    engine: Option<Engine>,
    /// Samples pushed (including the held-back head).
    pushed: usize,
    /// Samples the engine has seen.
    done: usize,
    stamped: Option<bool>,
    has_speed: Option<bool>,
    t_first: f64,
    t_last: f64,
    max_deviation: f64,
    /// Whether a stamp needed the rounding allowance (module `grid`).
    rounded: bool,
    keep: bool,
    speed_check: super::consistency::SpeedConsistency,
    magnitudes: super::plausibility::Magnitudes,
}

impl Session {
    /// A session for `method`, with `profile` as the speed when the samples carry none.
    pub fn new(
        knowledge: &Knowledge,
        method: &Method,
        profile: Option<SpeedProfile>,
        timing: Timing,
    ) -> Result<Self, PipelineError> {
        let (Timing::Fit { tolerance, .. } | Timing::Grid { tolerance, .. }) = timing;
        check_tolerance(tolerance)?;
        if let Timing::Fit { head, .. } = timing {
            crate::model::check("head", head as f64, "an integer >= 2 (stamps)", |v| {
                v >= 2.0
            })?;
        }
        knowledge
            .identify_known()
            .validated()
            .map_err(crate::identify::algebraic::AlgebraicError::from)?;
        if let Method::Algebraic(s) = method {
            s.config()?;
        }
        let model = match method {
            Method::Algebraic(s) => s.model,
            Method::Modulating(s) => s.model,
            Method::Refine(_) => None,
        }
        .unwrap_or(knowledge.model);
        if model != crate::parameter::ModelKind::Jeffcott && !matches!(method, Method::Refine(_)) {
            return Err(PipelineError::ModelNotAvailable {
                method: method.name().as_str(),
                model: model.name(),
            });
        }
        let grid = match timing {
            Timing::Grid { grid, .. } => Some(grid),
            Timing::Fit { .. } => None,
        };
        Ok(Self {
            knowledge: *knowledge,
            method: *method,
            profile,
            timing,
            grid,
            running: RunningGrid::default(),
            head: Vec::new(),
            engine: None,
            pushed: 0,
            done: 0,
            stamped: None,
            has_speed: None,
            t_first: f64::NAN,
            t_last: f64::NAN,
            max_deviation: 0.0,
            rounded: false,
            keep: false,
            speed_check: Default::default(),
            magnitudes: Default::default(),
        })
    }

    /// Keep every algebraic estimate for [`Identification::estimates`] (memory grows with
    /// the record; off by default).
    pub fn keep_estimates(&mut self) {
        if let Some(Engine::Algebraic { keep, .. }) = &mut self.engine {
            keep.get_or_insert_with(Vec::new);
        }
        self.keep = true;
    }

    /// Samples pushed so far.
    pub fn samples(&self) -> usize {
        self.pushed
    }

    /// The grid in use, once known.
    pub fn grid(&self) -> Option<TimeGrid> {
        self.grid
    }

    /// Push one sample; the algebraic identifier's new estimates go to `on_estimate`
    /// (none while the grid's head is held back, then all of them). Errors name the
    /// sample's index (0 for the first).
    pub fn push(
        &mut self,
        s: &Sample,
        on_estimate: &mut dyn FnMut(&SampleEstimate),
    ) -> Result<(), PipelineError> {
        let index = self.pushed;
        self.validate(index, s)?;
        self.pushed += 1;
        if self.engine.is_some() {
            return self.process(s, on_estimate);
        }
        self.head.push(*s);
        if let Timing::Fit { head, .. } = self.timing {
            if self.head.len() >= head {
                self.start(on_estimate)?;
            }
        } else {
            self.start(on_estimate)?;
        }
        Ok(())
    }

    /// Fit the grid over the samples held back so far and run the identifier over them;
    /// a no-op once started, and before the method could give anything (2 samples, 4 for
    /// the algebraic identifier).
    pub fn start_now(
        &mut self,
        on_estimate: &mut dyn FnMut(&SampleEstimate),
    ) -> Result<(), PipelineError> {
        if self.engine.is_some() || self.head.len() < self.least() {
            return Ok(());
        }
        self.start(on_estimate)
    }

    fn validate(&mut self, index: usize, s: &Sample) -> Result<(), PipelineError> {
        // v * 0 == 0 exactly when v is finite: one test for every field, the field named
        // on the cold path
        let speed_zero = s
            .speed
            .map_or(0.0, |v| v.phi * 0.0 + v.omega * 0.0 + v.omega_dot * 0.0);
        if s.x * 0.0 + s.z * 0.0 + speed_zero != 0.0 {
            return Err(Self::not_finite(index, s));
        }
        self.validate_presence_and_time(index, s)
    }

    /// The error naming the first non-finite field of `s`.
    #[cold]
    fn not_finite(index: usize, s: &Sample) -> PipelineError {
        let finite = |field: &'static str, value: f64| {
            if value.is_finite() {
                Ok(())
            } else {
                Err(PipelineError::NotFinite {
                    index,
                    field,
                    value,
                })
            }
        };
        let check = || {
            finite("x", s.x)?;
            finite("z", s.z)?;
            if let Some(v) = s.speed {
                finite("phi", v.phi)?;
                finite("phi_dot", v.omega)?;
                finite("phi_ddot", v.omega_dot)?;
            }
            Ok(())
        };
        // (only called when a field is not finite; x stands in otherwise)
        check().err().unwrap_or(PipelineError::NotFinite {
            index,
            field: "x",
            value: s.x,
        })
    }

    fn validate_presence_and_time(
        &mut self,
        index: usize,
        s: &Sample,
    ) -> Result<(), PipelineError> {
        if *self.has_speed.get_or_insert(s.speed.is_some()) != s.speed.is_some() {
            return Err(PipelineError::SpeedPresence { index });
        }
        if s.speed.is_none() && self.profile.is_none() {
            return Err(PipelineError::NoSpeed);
        }
        let stamped = *self.stamped.get_or_insert(s.t.is_some());
        if stamped != s.t.is_some() {
            return Err(PipelineError::NotFinite {
                index,
                field: "t",
                value: f64::NAN,
            });
        }
        let (Timing::Fit { tolerance, .. } | Timing::Grid { tolerance, .. }) = self.timing;
        let t = match s.t {
            Some(t) => {
                self.running.push(index, t)?;
                // Check against the given grid, or the fit of every stamp so far.
                let deviation = match self.timing {
                    Timing::Grid { grid, .. } => {
                        Some(grid.check_rounded(index, t, tolerance, self.running.resolution())?)
                    }
                    Timing::Fit { .. } => self.running.check_newest_rounded(tolerance)?,
                };
                if let Some((d, rounded)) = deviation {
                    self.max_deviation = self.max_deviation.max(d);
                    self.rounded |= rounded;
                }
                t
            }
            None => match self.grid {
                Some(g) => g.time(index),
                None => {
                    return Err(PipelineError::NotFinite {
                        index,
                        field: "t",
                        value: f64::NAN,
                    })
                }
            },
        };
        if index == 0 {
            self.t_first = t;
        }
        self.t_last = t;
        Ok(())
    }

    fn start(&mut self, on_estimate: &mut dyn FnMut(&SampleEstimate)) -> Result<(), PipelineError> {
        let grid = match self.grid {
            Some(g) => g,
            None => self.running.grid().ok_or(PipelineError::TooFewSamples {
                samples: self.head.len(),
                needed: 2,
                method: "the time grid",
                why: "two stamps give the sampling period",
            })?,
        };
        self.grid = Some(grid);
        let known = self.knowledge.identify_known();
        self.engine = Some(match &self.method {
            Method::Algebraic(s) => {
                let config = s.config()?;
                Engine::Algebraic {
                    id: Box::new(RestartingIdentifier::new(
                        known,
                        grid.dt,
                        config,
                        s.restart_samples(grid.dt)?,
                    )?),
                    tracker: Box::new(ConvergenceTracker::new(s.tol, s.rcond_min)?),
                    settings: *s,
                    flagged: Directions::default(),
                    last: None,
                    keep: self.keep.then(Vec::new),
                    kept: Kept::default(),
                }
            }
            Method::Modulating(s) => Engine::Modulating {
                id: Box::new(ModulatingIdentifier::new(known, grid.dt, s.config)?),
                kept: Kept::default(),
                complete: true,
            },
            Method::Refine(_) => Engine::Refine {
                kept: Kept::default(),
            },
        });
        for s in std::mem::take(&mut self.head) {
            self.process(&s, on_estimate)?;
        }
        Ok(())
    }

    fn process(
        &mut self,
        s: &Sample,
        on_estimate: &mut dyn FnMut(&SampleEstimate),
    ) -> Result<(), PipelineError> {
        let i = self.done;
        let grid = self.grid.expect("an engine runs on a grid");
        let tg = grid.time(i);
        let speed = match (s.speed, self.profile) {
            (Some(v), profile) => {
                self.speed_check.push(v.phi, v.omega, v.omega_dot, grid.dt);
                if let Some(p) = profile {
                    self.speed_check.push_profile(v.omega, p.at(tg).omega);
                }
                v
            }
            (None, Some(p)) => p.at(tg),
            (None, None) => return Err(PipelineError::NoSpeed),
        };
        self.magnitudes.push(s.x, s.z);
        let m = Measurement {
            t: tg,
            x: s.x,
            z: s.z,
            speed,
        };
        match self.engine.as_mut().expect("started") {
            Engine::Algebraic {
                id,
                tracker,
                settings,
                flagged,
                last,
                keep,
                kept,
            } => {
                let w = id.push(&m)?;
                if kept.t.len() < ALGEBRAIC_ADEQUACY_SAMPLES {
                    kept.push(s.t.unwrap_or(tg), s);
                }
                let mut e = w.estimate;
                e.t = s.t.unwrap_or(tg);
                tracker.push(&e);
                let ok = e.well_conditioned(settings.rcond_min);
                flagged.x += u64::from(!ok[0]);
                flagged.z += u64::from(!ok[1]);
                *last = Some(e);
                if let Some(k) = keep {
                    k.push(e);
                }
                on_estimate(&SampleEstimate {
                    estimate: e,
                    well_conditioned: ok,
                    window: w.window,
                });
            }
            Engine::Modulating { id, kept, complete } => {
                id.push(&m)?;
                if kept.t.len() < MODULATING_CRB_MAX_SAMPLES {
                    kept.push(s.t.unwrap_or(tg), s);
                } else {
                    *complete = false;
                }
            }
            Engine::Refine { kept } => kept.push(s.t.unwrap_or(tg), s),
        }
        self.done += 1;
        Ok(())
    }

    /// The identification of every sample pushed.
    pub fn finish(
        mut self,
        on_estimate: &mut dyn FnMut(&SampleEstimate),
    ) -> Result<Identification, PipelineError> {
        if self.engine.is_none() {
            if self.head.len() < self.least() {
                return Err(self.too_few(self.head.len()));
            }
            self.start(on_estimate)?;
        }
        let grid = self.grid.expect("started");
        let info = super::RecordInfo {
            samples: self.done as u64,
            t_first_s: self.t_first,
            t_last_s: self.t_last,
            dt_s: grid.dt,
            t0_s: grid.t0,
            grid_fitted_over: grid.fitted_over as u64,
            max_time_deviation_s: self.max_deviation,
            speed: if self.has_speed == Some(true) {
                SpeedSource::Samples
            } else {
                SpeedSource::Profile
            },
        };
        let drift = self.drift(grid);
        let rounded = self.rounded.then(|| {
            super::rounded_stamps_note(self.running.resolution(), self.max_deviation, grid.dt)
        });
        let mut ident = match self.engine.take().expect("started") {
            Engine::Algebraic {
                id,
                tracker,
                settings,
                flagged,
                last,
                keep,
                kept,
            } => {
                if self.done < ALGEBRAIC_MIN_SAMPLES {
                    return Err(self.too_few(self.done));
                }
                let mut ident = super::algebraic_identification(
                    info,
                    &self.knowledge,
                    &settings,
                    &tracker,
                    flagged,
                    last,
                    id.windows(),
                );
                ident.estimates = keep.unwrap_or_default();
                // judged only when its estimates settled: a refit from the late values of
                // a noisy record starts from noise (module `adequacy`)
                let settled = !ident
                    .diagnostics
                    .iter()
                    .any(|d| matches!(d.finding, Finding::AlgebraicUnsettled { .. }));
                if settled {
                    if let Ok(rec) = self.record(kept, grid) {
                        super::adequacy::judge(&mut ident, &rec, &self.knowledge);
                    }
                }
                ident
            }
            Engine::Modulating { id, kept, complete } => {
                let est = id.finish()?;
                let Method::Modulating(s) = &self.method else {
                    unreachable!("the engine follows the method")
                };
                let rec = self.record(kept, grid);
                let bound = match &rec {
                    Ok(rec) if complete => super::refine_run::modulating_bound(
                        rec,
                        &self.knowledge,
                        est.values(),
                        est.sigma_x,
                        est.sigma_z,
                    ),
                    Ok(_) => Err(PipelineError::CrbTooLong {
                        samples: self.done,
                        max: MODULATING_CRB_MAX_SAMPLES,
                    }),
                    Err(e) => Err(e.clone()),
                };
                let mut ident =
                    super::modulating_identification(info, &self.knowledge, s, &est, bound);
                if let Ok(rec) = &rec {
                    super::adequacy::judge(&mut ident, rec, &self.knowledge);
                }
                ident
            }
            Engine::Refine { kept } => {
                let Method::Refine(s) = &self.method else {
                    unreachable!("the engine follows the method")
                };
                let rec = self.record(kept, grid)?;
                let mut ident = super::refine_run::run(&rec, &self.knowledge, s)?;
                ident.diagnostics.extend(self.speed_check.profile_finding());
                ident.diagnostics.extend(rounded);
                return Ok(ident);
            }
        };
        ident.diagnostics.extend(drift);
        ident.diagnostics.extend(rounded);
        ident.diagnostics.extend(self.magnitudes.findings());
        super::apply_speed_check(&mut ident, &self.speed_check);
        ident.diagnostics.extend(self.speed_check.profile_finding());
        Ok(ident)
    }

    /// The record of the samples `kept` on `grid`.
    fn record(&self, kept: Kept, grid: TimeGrid) -> Result<Record, PipelineError> {
        let Kept { t, x, z, speed } = kept;
        let sp = match (self.has_speed, self.profile) {
            (Some(true), _) => {
                let [phi, omega, omega_dot] = speed;
                Speed::Samples {
                    phi,
                    omega,
                    omega_dot,
                }
            }
            (_, Some(p)) => Speed::Profile(p),
            _ => return Err(PipelineError::NoSpeed),
        };
        let (Timing::Fit { tolerance, .. } | Timing::Grid { tolerance, .. }) = self.timing;
        if self.stamped == Some(true) {
            Record::new(t, x, z, sp, tolerance)
        } else {
            Record::uniform(grid, x, z, sp)
        }
    }

    /// Fewest samples before the method can give anything: 4 for the algebraic
    /// identifier, else 2 (the sampling period).
    fn least(&self) -> usize {
        match self.method {
            Method::Algebraic(_) => ALGEBRAIC_MIN_SAMPLES,
            _ if self.grid.is_some() => 1,
            _ => 2,
        }
    }

    fn too_few(&self, samples: usize) -> PipelineError {
        let (needed, why) = match self.method {
            Method::Algebraic(_) => (
                ALGEBRAIC_MIN_SAMPLES,
                "the 4th sample is the first at which the 3x3 system can be well conditioned",
            ),
            _ => (2, "two give the sampling period"),
        };
        PipelineError::TooFewSamples {
            samples,
            needed,
            method: self.method.name().as_str(),
            why,
        }
    }

    /// A warning when the grid of all stamps differs from the one used.
    fn drift(&self, used: TimeGrid) -> Option<Diagnostic> {
        let all = self.running.grid()?;
        let relative = (all.dt - used.dt).abs() / used.dt;
        (relative > GRID_DRIFT_LIMIT).then(|| {
            Diagnostic::new(Finding::TimeGridDrift {
                dt_used_s: used.dt,
                dt_all_s: all.dt,
                fitted_over: used.fitted_over,
                samples: self.running.len(),
            })
        })
    }
}
