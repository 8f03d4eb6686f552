//! The identification pipeline every caller uses (the `rotorid` command, the Python
//! package, the fleet worker): a [`Record`], what is [`Knowledge`] besides it, and a
//! [`Method`] give one [`Identification`] with its [`Diagnostic`]s; a [`Session`] does the
//! same for samples that arrive as a stream. docs/method.md section 6 explains each step.
//!
//! ```
//! use rotorid::pipeline::{identify, Knowledge, Method, Record};
//! use rotorid::simulate::{add_noise, simulate, Method as Simulation};
//! use rotorid::{Parameter, Scenario};
//!
//! let scenario = Scenario::table1(); // the paper's rotor at 1200 rpm, 1 s at 10 kHz
//! let mut response = simulate(&scenario, Simulation::Exact)?;
//! add_noise(&mut response, 40.0, 1)?; // 40 dB SNR
//! let record = Record::from_response(&response)?;
//! let result = identify(&record, &Knowledge::from_scenario(&scenario), &Method::refine())?;
//! let m = result.parameter(Parameter::M).unwrap();
//! let (value, std) = (m.value.unwrap(), m.std_error.unwrap()); // ~6e-4 kg
//! assert!((value - 14.29).abs() < 5.0 * std);
//! assert!(result.diagnostics.is_empty());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

pub(crate) mod adequacy;
mod consistency;
mod diagnostic;
mod error;
mod grid;
mod identification;
mod knowledge;
mod limits;
mod method;
mod plausibility;
mod record;
mod refine_run;
mod session;
mod start;

pub use adequacy::{
    Adequacy, AdequacyBasis, ChannelAdequacy, Refit, ADEQUACY_P_MIN, LJUNG_BOX_LAGS,
    NOISE_RATIO_MAX, REFIT_MODEL_ERROR, REFIT_SAMPLES, REFIT_SAMPLES_PER_PERIOD, RESIDUAL_FLOOR,
    SMALL_RESIDUAL_MAX,
};
pub use consistency::SPEED_FACTOR_TOLERANCE;
pub use diagnostic::{Diagnostic, Direction, Directions, Finding, Severity};
pub use error::PipelineError;
pub use grid::{
    rounding_allowance, stamp_decimals, RunningGrid, TimeGrid, DEFAULT_TIME_TOLERANCE,
    MAX_ROUNDING_ALLOWANCE, MAX_STAMP_DECIMALS, SNAP_DT, SNAP_T0,
};
pub use identification::{
    AlgebraicDetail, Covariance, CrbAt, FinalEstimate, Identification, ModelCandidate,
    ModelSelection, ModulatingDetail, Noise, NoiseSource, ParameterResult, RecordInfo,
    RefineDetail, RotorSummary, Start, StartSource, StateResult, IDENTIFICATION_SCHEMA,
};
pub use knowledge::{Knowledge, RotorValues, Truth};
pub use limits::{DISPLACEMENT_MAX_M, DISPLACEMENT_MIN_M, NOISE_TO_SIGNAL_MAX};
pub use method::{
    AlgebraicSettings, Method, MethodName, ModelChoice, ModulatingSettings, RefineSettings,
    StartPolicy,
};
pub use record::{rebased, Record, Speed, SpeedSource, CONSTANT_PHI_TOLERANCE};
pub use refine_run::REFINE_MIN_SAMPLES;
pub use session::{
    Sample, SampleEstimate, Session, Timing, ALGEBRAIC_ADEQUACY_SAMPLES, ALGEBRAIC_MIN_SAMPLES,
    DEFAULT_GRID_HEAD, GRID_DRIFT_LIMIT, MODULATING_CRB_MAX_SAMPLES,
};
pub use start::ALGEBRAIC_START_S;

use crate::identify::algebraic::ParameterConvergence;
use crate::identify::modulating::{CrossModulatingEstimate, ModulatingEstimate};
use crate::parameter::{ModelKind, Parameter, Sign};

use identification::finite;
use refine_run::relative_error;

/// Above this fraction of ill-conditioned instants in a direction, the algebraic result
/// warns (a correct record of table1 over 1 s has none after the first milliseconds; a
/// 100 s record without restarts about half).
pub const ILL_CONDITIONED_FRACTION_MAX: f64 = 0.1;

/// MODULATING_STD_ERROR_BASIS: how the modulating identifier's standard errors are computed.
pub const MODULATING_STD_ERROR_BASIS: &str =
    "first-order sandwich covariance of the least squares, with the correlations of \
     overlapping windows, for white noise of the estimated sigma_x, sigma_z";

/// Identify `record` by `method`, knowing `knowledge` (module doc). The algebraic
/// method's estimate at every sample is in [`Identification::estimates`].
pub fn identify(
    record: &Record,
    knowledge: &Knowledge,
    method: &Method,
) -> Result<Identification, PipelineError> {
    let rounded = record.grid().rounding_note();
    if let Method::Refine(s) = method {
        let mut ident = refine_run::run(record, knowledge, s)?;
        ident.diagnostics.extend(rounded);
        return Ok(ident);
    }
    let profile = match record.speed() {
        Speed::Profile(p) => Some(*p),
        Speed::Samples { .. } => None,
    };
    // The record's stamps were checked against its grid when it was built.
    let timing = Timing::Grid {
        grid: record.grid(),
        tolerance: f64::MAX,
    };
    let mut session = Session::new(knowledge, method, profile, timing)?;
    session.keep_estimates();
    let samples = matches!(record.speed(), Speed::Samples { .. });
    let mut ignore = |_: &SampleEstimate| {};
    for (i, &t) in record.t().iter().enumerate() {
        let s = Sample {
            t: Some(t),
            x: record.x()[i],
            z: record.z()[i],
            speed: samples.then(|| record.speed_at(i)),
        };
        session.push(&s, &mut ignore)?;
    }
    let mut ident = session.finish(&mut ignore)?;
    ident.diagnostics.extend(rounded);
    ident.record = RecordInfo {
        max_time_deviation_s: record.grid().max_deviation,
        speed: record.speed_source(),
        ..ident.record
    };
    Ok(ident)
}

/// Whether eq. (1) explains `record`, judged as the modulating and algebraic methods judge
/// their estimates (docs/method.md section 6.4): the model refitted by maximum likelihood
/// from `rotor` (m, the direct and cross-coupled coefficients and the initial state
/// unknown; a and the unbalance as given) over every `stride`-th sample
/// ([`REFIT_SAMPLES`]), its residuals through the whiteness and level tests.
pub fn adequacy_of(
    record: &Record,
    rotor: &crate::model::RotorParams,
) -> Result<Adequacy, PipelineError> {
    adequacy::of_model(record, rotor)
}

/// The note of a record whose stamps were accepted because rounding to `resolution` \[s\]
/// explains their largest deviation `max_deviation` \[s\] from the grid of period `dt`.
pub(crate) fn rounded_stamps_note(resolution: f64, max_deviation: f64, dt: f64) -> Diagnostic {
    Diagnostic::note(Finding::TimeStampsRounded {
        resolution_s: resolution,
        max_deviation_s: max_deviation,
        dt_s: dt,
    })
}

/// Withhold every value of `ident` (after a finding that invalidates the input).
pub(crate) fn withhold_all(ident: &mut Identification) {
    for p in &mut ident.parameters {
        p.value = None;
        p.determined = false;
        p.relative_error = None;
        p.identification_time_s = None;
    }
    ident.rotor = None;
}

/// Add the speed-consistency findings of `check` to `ident`, withholding its values when
/// there are any.
pub(crate) fn apply_speed_check(ident: &mut Identification, check: &consistency::SpeedConsistency) {
    let found = check.findings();
    if !found.is_empty() {
        withhold_all(ident);
        for d in found.into_iter().rev() {
            ident.diagnostics.insert(0, d);
        }
    }
}

/// The record as reported.
pub(crate) fn record_info(rec: &Record) -> RecordInfo {
    let g = rec.grid();
    let t = rec.t();
    RecordInfo {
        samples: rec.len() as u64,
        t_first_s: t.first().copied().unwrap_or(f64::NAN),
        t_last_s: t.last().copied().unwrap_or(f64::NAN),
        dt_s: g.dt,
        t0_s: g.t0,
        grid_fitted_over: g.fitted_over as u64,
        max_time_deviation_s: g.max_deviation,
        speed: rec.speed_source(),
    }
}

/// The per-direction parameters of an estimate of `model` with `values` (in the order of
/// [`ModelKind::per_direction`]: Jeffcott m_x, cx, kx, m_z, cz, kz), kept where `ok`
/// (x, z).
fn per_direction(
    k: &Knowledge,
    model: ModelKind,
    values: &[f64],
    ok: [bool; 2],
    fill: impl Fn(usize, &mut ParameterResult),
) -> Vec<ParameterResult> {
    let half = model.per_direction().len() / 2;
    model
        .per_direction()
        .iter()
        .enumerate()
        .map(|(i, &p)| {
            let determined = ok[i / half] && values[i].is_finite() && physical(p, values[i]);
            let value = determined.then_some(values[i]);
            let truth = k.truth_of(p);
            let mut r = ParameterResult {
                value,
                estimate: finite(values[i]),
                truth,
                relative_error: relative_error(value, truth),
                determined,
                ..ParameterResult::new(p)
            };
            fill(i, &mut r);
            r
        })
        .collect()
}

/// Inside the model's physical range: m and the direct stiffness > 0, the direct damping
/// >= 0, a cross-coupled coefficient any value ([`Parameter::sign`]).
pub(crate) fn physical(p: Parameter, v: f64) -> bool {
    match p.sign() {
        Sign::Positive => v > 0.0,
        Sign::NonNegative => v >= 0.0,
        Sign::Any => true,
    }
}

/// One diagnostic per estimate outside the physical range (withheld).
fn unphysical(params: &[ParameterResult]) -> Vec<Diagnostic> {
    params
        .iter()
        .filter_map(|r| {
            let v = r.estimate?;
            (!physical(r.parameter, v)).then(|| {
                Diagnostic::new(Finding::NotPhysical {
                    parameter: r.parameter,
                    value: v,
                })
            })
        })
        .collect()
}

/// The rotor of per-direction results of `model`, when all are determined (m: mean of m_x,
/// m_z).
fn rotor_of(k: &Knowledge, model: ModelKind, params: &[ParameterResult]) -> Option<RotorSummary> {
    let mut p = crate::model::RotorParams {
        m: f64::NAN,
        cx: f64::NAN,
        kx: f64::NAN,
        cz: f64::NAN,
        kz: f64::NAN,
        a: k.a,
        unbalance: k.unbalance,
        coupling: (model == ModelKind::CrossCoupled).then(Default::default),
    };
    let mut masses = 0.0;
    for r in params {
        let v = r.value?;
        match r.parameter {
            Parameter::MX | Parameter::MZ => masses += 0.5 * v,
            q => p.set(q, v),
        }
    }
    p.m = masses;
    Some(RotorSummary::of(&p))
}

/// The modulating identifier's result, of either model: values and standard errors in the
/// order of [`ModelKind::per_direction`].
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct ModulatingSummary {
    pub model: ModelKind,
    pub values: Vec<f64>,
    pub std_errors: Vec<f64>,
    pub rcond: [f64; 2],
    pub t: f64,
    pub window_s: f64,
    pub hop_s: f64,
    pub windows: u64,
    pub sigma_x: f64,
    pub sigma_z: f64,
    pub compensated: bool,
}

impl ModulatingSummary {
    pub(crate) fn jeffcott(e: &ModulatingEstimate) -> Self {
        Self {
            model: ModelKind::Jeffcott,
            values: e.values().to_vec(),
            std_errors: e.std_errors().to_vec(),
            rcond: [e.x.rcond, e.z.rcond],
            t: e.t,
            window_s: e.window_s,
            hop_s: e.hop_s,
            windows: e.windows,
            sigma_x: e.sigma_x,
            sigma_z: e.sigma_z,
            compensated: e.compensated,
        }
    }

    pub(crate) fn cross(e: &CrossModulatingEstimate) -> Self {
        Self {
            model: ModelKind::CrossCoupled,
            values: e.values().to_vec(),
            std_errors: e.std_errors().to_vec(),
            rcond: [e.x.rcond, e.z.rcond],
            t: e.t,
            window_s: e.window_s,
            hop_s: e.hop_s,
            windows: e.windows,
            sigma_x: e.sigma_x,
            sigma_z: e.sigma_z,
            compensated: e.compensated,
        }
    }

    /// Whether each direction is well conditioned at `rcond_min`.
    fn well_conditioned(&self, rcond_min: f64) -> [bool; 2] {
        self.rcond.map(|r| r >= rcond_min && r > 0.0)
    }
}

#[allow(clippy::too_many_arguments)]
fn algebraic_identification(
    record: RecordInfo,
    k: &Knowledge,
    s: &AlgebraicSettings,
    model: ModelKind,
    results: &[ParameterConvergence],
    flagged: Directions<u64>,
    last: Option<SampleEstimate>,
    windows: u64,
) -> Identification {
    let values: Vec<f64> = results
        .iter()
        .map(|r| r.final_value.unwrap_or(f64::NAN))
        .collect();
    let half = results.len() / 2;
    let ok = [
        results[0].final_value.is_some(),
        results[half].final_value.is_some(),
    ];
    let parameters = per_direction(k, model, &values, ok, |i, r| {
        r.t_s = results[i].final_t;
        // an estimate outside the physical range never counts as converged
        r.identification_time_s = results[i].identification_time.filter(|_| r.determined);
    });
    let mut diagnostics = unphysical(&parameters);
    // Settled only in the last half of the record, or never: the iterated integrals amplify
    // the noise as the record grows (docs/method.md section 3.8).
    let middle = record.t_first_s + 0.5 * (record.t_last_s - record.t_first_s);
    let unsettled: Vec<Parameter> = parameters
        .iter()
        .filter(|r| {
            !r.determined && r.estimate.is_some()
                || r.determined && r.identification_time_s.is_none_or(|t| t > middle)
        })
        .map(|r| r.parameter)
        .collect();
    if !unsettled.is_empty() {
        diagnostics.push(Diagnostic::new(Finding::AlgebraicUnsettled {
            parameters: unsettled,
        }));
    }
    // Without restarts the 3x3 systems degrade as the record grows (module
    // identify::algebraic::windows): say so when many instants are flagged.
    let samples = record.samples.max(1) as f64;
    for (direction, n) in [(Direction::X, flagged.x), (Direction::Z, flagged.z)] {
        let fraction = n as f64 / samples;
        if fraction > ILL_CONDITIONED_FRACTION_MAX {
            diagnostics.push(Diagnostic::new(Finding::AlgebraicIllConditioned {
                direction,
                fraction,
                rcond_min: s.rcond_min,
                restarted: s.restart_s.is_some(),
            }));
        }
    }
    Identification {
        schema: IDENTIFICATION_SCHEMA,
        method: MethodName::Algebraic,
        model,
        model_selection: None,
        input: None,
        scenario: None,
        record,
        rotor: rotor_of(k, model, &parameters),
        parameters,
        covariance: None,
        noise: None,
        adequacy: None,
        diagnostics,
        algebraic: Some(AlgebraicDetail {
            quadrature: s.quadrature,
            rcond_min: s.rcond_min,
            tol: s.tol,
            restart_s: s.restart_s,
            windows,
            flagged,
            final_time_s: Directions {
                x: results[0].final_t,
                z: results[half].final_t,
            },
            last_rcond: Directions {
                x: last.map_or(0.0, |e| e.rcond[0]),
                z: last.map_or(0.0, |e| e.rcond[1]),
            },
        }),
        modulating: None,
        refine: None,
        estimates: Vec::new(),
    }
}

/// The modulating identifier's figures.
pub(crate) fn modulating_detail(e: &ModulatingSummary, rcond_min: f64) -> ModulatingDetail {
    ModulatingDetail {
        window_s: e.window_s,
        hop_s: e.hop_s,
        windows: e.windows,
        rcond_min,
        rcond: Directions {
            x: e.rcond[0],
            z: e.rcond[1],
        },
        t_s: e.t,
        compensated: e.compensated,
        std_error_basis: MODULATING_STD_ERROR_BASIS.to_owned(),
        crb_at: None,
    }
}

fn modulating_identification(
    record: RecordInfo,
    k: &Knowledge,
    s: &ModulatingSettings,
    e: &ModulatingSummary,
    bound: Result<(crate::refine::Crb, identification::CrbAt), PipelineError>,
) -> Identification {
    let rcond_min = s.config.rcond_min;
    let ok = e.well_conditioned(rcond_min);
    let std = &e.std_errors;
    let values = &e.values;
    let half = values.len() / 2;
    let crb_of = |p: Parameter| -> Option<f64> {
        let (b, _) = bound.as_ref().ok()?;
        finite(b.get(p.physical().name())?.std_dev)
    };
    let parameters = per_direction(k, e.model, values, ok, |i, r| {
        if ok[i / half] {
            r.std_error = finite(std[i]);
            r.relative_std_error = finite(std[i] / values[i].abs());
            r.t_s = Some(e.t);
        }
        r.crb = crb_of(r.parameter);
    });
    let mut diagnostics: Vec<Diagnostic> = [(Direction::X, e.rcond[0]), (Direction::Z, e.rcond[1])]
        .iter()
        .zip(ok)
        .filter(|(_, ok)| !ok)
        .map(|(&(direction, rcond), _)| {
            Diagnostic::new(if rcond > 0.0 {
                Finding::DirectionIllConditioned {
                    direction,
                    rcond,
                    rcond_min,
                }
            } else {
                Finding::DirectionSingular { direction }
            })
        })
        .collect();
    diagnostics.extend(unphysical(&parameters));
    if let Err(e) = &bound {
        diagnostics.push(Diagnostic::new(Finding::CrbUnavailable {
            reason: e.to_string(),
        }));
    }
    let mut detail = modulating_detail(e, rcond_min);
    detail.crb_at = bound.as_ref().ok().map(|(_, at)| *at);
    Identification {
        schema: IDENTIFICATION_SCHEMA,
        method: MethodName::Modulating,
        model: e.model,
        model_selection: None,
        input: None,
        scenario: None,
        record,
        rotor: rotor_of(k, e.model, &parameters),
        parameters,
        covariance: None,
        noise: Some(Noise {
            sigma_x_m: e.sigma_x,
            sigma_z_m: e.sigma_z,
            source: NoiseSource::FourthDifferences,
        }),
        adequacy: None,
        diagnostics,
        algebraic: None,
        modulating: Some(detail),
        refine: None,
        estimates: Vec::new(),
    }
}
