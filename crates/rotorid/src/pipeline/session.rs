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

use crate::identify::algebraic::{
    AlgebraicError, AlgebraicEstimate, ConvergenceTracker, CrossAlgebraicEstimate,
    CrossAlgebraicIdentifier, ParameterConvergence, RestartingIdentifier,
};
use crate::identify::modulating::{
    CrossModulatingIdentifier, ModulatingError, ModulatingIdentifier,
};
use crate::identify::Measurement;
use crate::model::{SpeedProfile, SpeedState};
use crate::parameter::{ModelKind, Parameter};

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
/// Fewest samples the cross-coupled algebraic identifier accepts: its 5x5 system is
/// singular before the sixth sample (A(t_0) = 0, one more integral per row).
pub const CROSS_ALGEBRAIC_MIN_SAMPLES: usize = 6;
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

/// An estimate of the algebraic identifier at one sample, of either model: the values of
/// [`ModelKind::per_direction`] (Jeffcott: m_x, cx, kx, m_z, cz, kz; cross-coupled: m_x,
/// cxx, cxz, kxx, kxz, m_z, czx, czz, kzx, kzz), the x direction's first half;
/// `well_conditioned` per direction (x, z): the values of an ill-conditioned direction
/// must not be used.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleEstimate {
    /// The sample's stamp \[s\].
    pub t: f64,
    /// The model whose parameters the values are.
    pub model: ModelKind,
    values: [f64; 10],
    /// Reciprocal condition number of each direction's system (x, z), in [0, 1].
    pub rcond: [f64; 2],
    /// Whether each direction's system is well conditioned.
    pub well_conditioned: [bool; 2],
    /// The restart window the estimate comes from (0 without restarts; see
    /// [`AlgebraicSettings::restart_s`](super::AlgebraicSettings::restart_s)).
    pub window: u64,
}

impl SampleEstimate {
    /// The Jeffcott identifier's estimate `e` at threshold `rcond_min`.
    pub fn jeffcott(e: &AlgebraicEstimate, rcond_min: f64, window: u64) -> Self {
        let v = e.values();
        Self {
            t: e.t,
            model: ModelKind::Jeffcott,
            values: std::array::from_fn(|i| v.get(i).copied().unwrap_or(f64::NAN)),
            rcond: [e.x.rcond, e.z.rcond],
            well_conditioned: e.well_conditioned(rcond_min),
            window,
        }
    }

    /// The cross-coupled identifier's estimate `e` at threshold `rcond_min`.
    pub fn cross(e: &CrossAlgebraicEstimate, rcond_min: f64, window: u64) -> Self {
        Self {
            t: e.t,
            model: ModelKind::CrossCoupled,
            values: e.values(),
            rcond: [e.x.rcond, e.z.rcond],
            well_conditioned: e.well_conditioned(rcond_min),
            window,
        }
    }

    /// The parameters of [`values`](Self::values), in order.
    pub fn parameters(&self) -> &'static [Parameter] {
        self.model.per_direction()
    }

    /// Every value, ill-conditioned or not (NaN where the system was singular), in the
    /// order of [`parameters`](Self::parameters) (kg, N s/m, N/m).
    pub fn values(&self) -> &[f64] {
        &self.values[..self.model.per_direction().len()]
    }

    /// Value `i` where its direction is well conditioned and it is finite: what the
    /// estimates table writes.
    pub fn usable(&self, i: usize) -> Option<f64> {
        let v = *self.values().get(i)?;
        let half = self.values().len() / 2;
        (self.well_conditioned[i / half] && v.is_finite()).then_some(v)
    }
}

/// The algebraic identifier and its convergence tracker, of the model identified.
enum AlgebraicEngine {
    Jeffcott(Box<RestartingIdentifier>, Box<ConvergenceTracker>),
    Cross(
        Box<RestartingIdentifier<CrossAlgebraicIdentifier>>,
        Box<ConvergenceTracker<10>>,
    ),
}

impl AlgebraicEngine {
    /// Take `m`; the estimate at stamp `t`, also noted by the tracker.
    #[inline]
    fn push(
        &mut self,
        m: &Measurement,
        t: f64,
        rcond_min: f64,
    ) -> Result<SampleEstimate, AlgebraicError> {
        Ok(match self {
            AlgebraicEngine::Jeffcott(id, tracker) => {
                let w = id.push(m)?;
                let mut e = w.estimate;
                e.t = t;
                tracker.push(&e);
                SampleEstimate::jeffcott(&e, rcond_min, w.window)
            }
            AlgebraicEngine::Cross(id, tracker) => {
                let w = id.push(m)?;
                let mut e = w.estimate;
                e.t = t;
                tracker.push_cross(&e);
                SampleEstimate::cross(&e, rcond_min, w.window)
            }
        })
    }

    fn windows(&self) -> u64 {
        match self {
            AlgebraicEngine::Jeffcott(id, _) => id.windows(),
            AlgebraicEngine::Cross(id, _) => id.windows(),
        }
    }

    fn results(&self) -> Vec<ParameterConvergence> {
        match self {
            AlgebraicEngine::Jeffcott(_, t) => t.results().to_vec(),
            AlgebraicEngine::Cross(_, t) => t.results().to_vec(),
        }
    }

    fn model(&self) -> ModelKind {
        match self {
            AlgebraicEngine::Jeffcott(..) => ModelKind::Jeffcott,
            AlgebraicEngine::Cross(..) => ModelKind::CrossCoupled,
        }
    }
}

/// The modulating identifier of the model identified.
enum ModulatingEngine {
    Jeffcott(Box<ModulatingIdentifier>),
    Cross(Box<CrossModulatingIdentifier>),
}

impl ModulatingEngine {
    #[inline]
    fn push(&mut self, m: &Measurement) -> Result<(), ModulatingError> {
        match self {
            ModulatingEngine::Jeffcott(id) => id.push(m),
            ModulatingEngine::Cross(id) => id.push(m),
        }
    }

    fn finish(&self) -> Result<super::ModulatingSummary, ModulatingError> {
        Ok(match self {
            ModulatingEngine::Jeffcott(id) => super::ModulatingSummary::jeffcott(&id.finish()?),
            ModulatingEngine::Cross(id) => super::ModulatingSummary::cross(&id.finish()?),
        })
    }
}

enum Engine {
    Algebraic {
        id: AlgebraicEngine,
        settings: AlgebraicSettings,
        flagged: Directions<u64>,
        last: Option<Box<SampleEstimate>>,
        keep: Option<Vec<SampleEstimate>>,
        /// The first [`ALGEBRAIC_ADEQUACY_SAMPLES`] samples, for the adequacy test.
        kept: Kept,
        /// Each direction's last usable estimate in the record's first
        /// [`ALGEBRAIC_START_S`](super::ALGEBRAIC_START_S): the adequacy refit's start when
        /// the estimates do not settle.
        early: Box<EarlyEstimate>,
    },
    Modulating {
        id: ModulatingEngine,
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

/// Each direction's last well-conditioned, finite algebraic estimate among the samples
/// up to `last` (the record's first [`ALGEBRAIC_START_S`](super::ALGEBRAIC_START_S)), as
/// refine's algebraic start takes it (docs/method.md section 5.2).
#[derive(Debug)]
struct EarlyEstimate {
    last: usize,
    values: [Option<[f64; 10]>; 2],
}

impl EarlyEstimate {
    fn new(dt: f64) -> Self {
        Self {
            last: (super::ALGEBRAIC_START_S / dt)
                .floor()
                .min(usize::MAX as f64) as usize,
            values: [None, None],
        }
    }

    #[inline]
    fn push(&mut self, i: usize, e: &SampleEstimate) {
        if i > self.last {
            return;
        }
        let v = e.values();
        let half = v.len() / 2;
        for d in 0..2 {
            let row = &v[d * half..(d + 1) * half];
            if e.well_conditioned[d] && row.iter().all(|x| x.is_finite()) {
                self.values[d] = Some(e.values);
            }
        }
    }

    /// The per-direction values (x's row from x's estimate, z's from z's), when both
    /// directions had one.
    fn values(&self, n: usize) -> Option<Vec<f64>> {
        let [Some(x), Some(z)] = self.values else {
            return None;
        };
        let half = n / 2;
        Some(x[..half].iter().chain(&z[half..n]).copied().collect())
    }
}

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
    /// The model identified (algebraic and modulating; refine chooses its own).
    model: ModelKind,
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
            Method::Refine(s) => s.model.and_then(super::ModelChoice::fixed),
        }
        .unwrap_or(knowledge.model);
        let grid = match timing {
            Timing::Grid { grid, .. } => Some(grid),
            Timing::Fit { .. } => None,
        };
        Ok(Self {
            knowledge: *knowledge,
            method: *method,
            model,
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

    /// The model identified: the method's `model`, else the knowledge's (refine with
    /// `model: auto` chooses at the end, see [`Identification::model`]).
    pub fn model(&self) -> ModelKind {
        self.model
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
                let period = s.restart_samples(grid.dt)?;
                let id = match self.model {
                    ModelKind::Jeffcott => AlgebraicEngine::Jeffcott(
                        Box::new(RestartingIdentifier::new(known, grid.dt, config, period)?),
                        Box::new(ConvergenceTracker::new(s.tol, s.rcond_min)?),
                    ),
                    ModelKind::CrossCoupled => AlgebraicEngine::Cross(
                        Box::new(RestartingIdentifier::cross(known, grid.dt, config, period)?),
                        Box::new(ConvergenceTracker::cross(s.tol, s.rcond_min)?),
                    ),
                };
                Engine::Algebraic {
                    id,
                    settings: *s,
                    flagged: Directions::default(),
                    last: None,
                    keep: self.keep.then(Vec::new),
                    kept: Kept::default(),
                    early: Box::new(EarlyEstimate::new(grid.dt)),
                }
            }
            Method::Modulating(s) => Engine::Modulating {
                id: match self.model {
                    ModelKind::Jeffcott => ModulatingEngine::Jeffcott(Box::new(
                        ModulatingIdentifier::new(known, grid.dt, s.config)?,
                    )),
                    ModelKind::CrossCoupled => ModulatingEngine::Cross(Box::new(
                        CrossModulatingIdentifier::new(known, grid.dt, s.config)?,
                    )),
                },
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
                settings,
                flagged,
                last,
                keep,
                kept,
                early,
            } => {
                let e = id.push(&m, s.t.unwrap_or(tg), settings.rcond_min)?;
                if kept.t.len() < ALGEBRAIC_ADEQUACY_SAMPLES {
                    kept.push(s.t.unwrap_or(tg), s);
                    early.push(i, &e);
                }
                let ok = e.well_conditioned;
                flagged.x += u64::from(!ok[0]);
                flagged.z += u64::from(!ok[1]);
                match last {
                    Some(l) => **l = e,
                    None => *last = Some(Box::new(e)),
                }
                if let Some(k) = keep {
                    k.push(e);
                }
                on_estimate(&e);
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
                settings,
                flagged,
                last,
                keep,
                kept,
                early,
            } => {
                if self.done < self.least() {
                    return Err(self.too_few(self.done));
                }
                let mut ident = super::algebraic_identification(
                    info,
                    &self.knowledge,
                    &settings,
                    id.model(),
                    &id.results(),
                    flagged,
                    last.map(|l| *l),
                    id.windows(),
                );
                ident.estimates = keep.unwrap_or_default();
                // refitted from the settled values; when they did not settle (on noisy
                // records the late values are noise), from the early estimate refine's
                // start policy takes (module `adequacy`)
                let settled = !ident
                    .diagnostics
                    .iter()
                    .any(|d| matches!(d.finding, Finding::AlgebraicUnsettled { .. }));
                let model = ident.model;
                let start = if settled && ident.rotor.is_some() {
                    model
                        .per_direction()
                        .iter()
                        .map(|&p| ident.value(p))
                        .collect::<Option<Vec<f64>>>()
                } else {
                    early.values(model.per_direction().len())
                }
                .and_then(|v| super::adequacy::start_from(&self.knowledge, model, &v));
                if let (Some(start), Ok(rec)) = (start, self.record(kept, grid)) {
                    super::adequacy::judge_from(&mut ident, &rec, &start);
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
                        est.model,
                        &est.values,
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
    /// identifier (6 for the cross-coupled one), else 2 (the sampling period).
    fn least(&self) -> usize {
        match (self.method, self.model) {
            (Method::Algebraic(_), ModelKind::Jeffcott) => ALGEBRAIC_MIN_SAMPLES,
            (Method::Algebraic(_), ModelKind::CrossCoupled) => CROSS_ALGEBRAIC_MIN_SAMPLES,
            _ if self.grid.is_some() => 1,
            _ => 2,
        }
    }

    fn too_few(&self, samples: usize) -> PipelineError {
        let (needed, why) = match (self.method, self.model) {
            (Method::Algebraic(_), ModelKind::Jeffcott) => (
                ALGEBRAIC_MIN_SAMPLES,
                "the 4th sample is the first at which the 3x3 system can be well conditioned",
            ),
            (Method::Algebraic(_), ModelKind::CrossCoupled) => (
                CROSS_ALGEBRAIC_MIN_SAMPLES,
                "the cross-coupled identifier's 5x5 system needs six samples",
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
