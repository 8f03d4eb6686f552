//! The refinement as the pipeline runs it (docs/method.md section 5): the start
//! (module `start`), the maximum-likelihood fit, the Cramer-Rao bound where it is most
//! meaningful, and the rule that withholds what the record does not determine.
//!
//! A parameter is determined when its standard error is finite and no larger than its
//! value (alpha: no larger than 1 rad), and the data separate the unknowns (no not-identifiable or ill-conditioned
//! finding) and the model explains the record (module `adequacy`). The bound is evaluated at the truth when the caller knows all of m, c, k
//! (with the true initial state when the record starts at t = 0, else the fitted one),
//! otherwise at the estimate; always with the fitted noise.

use crate::model::{InitialState, RotorParams};
use crate::parameter::Parameter;
use crate::refine::{
    crb, model_response, refine, Discretisation, RefineOptions, Refined, Unknowns, ALPHA_STD_LIMIT,
};

use super::adequacy::Adequacy;
use super::diagnostic::{Diagnostic, Finding};
use super::error::PipelineError;
use super::identification::StartSource;
use super::identification::{
    finite, Covariance, CrbAt, Identification, Noise, NoiseSource, ParameterResult, RefineDetail,
    RotorSummary, StateResult, IDENTIFICATION_SCHEMA,
};
use super::knowledge::Knowledge;
use super::method::{MethodName, RefineSettings, StartPolicy};
use super::modulating_detail;
use super::record::Record;
use super::start::{self, check_known};

/// Fewest samples refine accepts: its algebraic fallback start needs 4.
pub const REFINE_MIN_SAMPLES: usize = 4;

/// Run the refinement on `rec` (module doc).
pub(crate) fn run(
    rec: &Record,
    k: &Knowledge,
    s: &RefineSettings,
) -> Result<Identification, PipelineError> {
    if rec.len() < REFINE_MIN_SAMPLES {
        return Err(PipelineError::TooFewSamples {
            samples: rec.len(),
            needed: REFINE_MIN_SAMPLES,
            method: "refine",
            why: "the algebraic identifier that may give the start needs them",
        });
    }
    let u = s.unknowns;
    check_known(k, &u)?;
    let found = match s.start {
        StartPolicy::Auto => start::find(rec, k, s)?,
        StartPolicy::Given(p) => start::Found {
            start: start::start(StartSource::Given, None, &p, None),
            params: p,
            modulating: None,
        },
    };
    let record = rec.for_refine();
    let options = RefineOptions {
        unknowns: u,
        ..s.options
    };
    let fit = refine(&record, &found.params, &InitialState::default(), &options)?;
    let mut diagnostics: Vec<Diagnostic> = fit.warnings.iter().map(Diagnostic::from).collect();
    let bound = match bound(rec, k, &fit, &u) {
        Ok(b) => Some(b),
        Err(e) => {
            diagnostics.push(Diagnostic::new(Finding::CrbUnavailable {
                reason: e.to_string(),
            }));
            None
        }
    };
    let adequacy = adequacy(rec, &fit);
    if let Some(a) = &adequacy {
        for d in a.findings() {
            diagnostics.insert(0, d);
        }
    }
    diagnostics.extend(super::plausibility::Magnitudes::of(rec.x(), rec.z()).findings());
    let inadequate = adequacy.is_some_and(|a| !a.model_adequate);
    let inseparable = diagnostics.iter().any(Diagnostic::inseparable) || inadequate;
    let t_last = *rec.t().last().unwrap_or(&f64::NAN);
    let parameters: Vec<ParameterResult> = fit
        .parameters
        .iter()
        .filter_map(|e| {
            let p: Parameter = e.name.parse().ok()?;
            let rel = e.relative_std_error;
            // an angle has no relative error: alpha is determined to within 1 rad
            let small = match p {
                Parameter::Alpha => e.std_error <= ALPHA_STD_LIMIT,
                _ => rel.is_some_and(|r| r <= 1.0),
            };
            let determined = e.std_error.is_finite() && small && !inseparable;
            let truth = k.truth_of(p);
            let value = determined.then_some(e.value);
            Some(ParameterResult {
                value,
                estimate: finite(e.value),
                std_error: finite(e.std_error),
                relative_std_error: rel.and_then(finite),
                robust_std_error: e.robust_std_error.and_then(finite),
                crb: bound
                    .as_ref()
                    .and_then(|(b, _)| b.get(e.name))
                    .and_then(|b| finite(b.std_dev)),
                truth,
                relative_error: relative_error(value, truth),
                determined,
                t_s: value.map(|_| t_last),
                ..ParameterResult::new(p)
            })
        })
        .collect();
    let rotor = parameters
        .iter()
        .all(|r| r.determined)
        .then(|| RotorSummary::of(&fit.rotor));
    let mut check = super::consistency::SpeedConsistency::default();
    if let super::record::Speed::Samples { .. } = rec.speed() {
        for i in 0..rec.len() {
            let v = rec.speed_at(i);
            check.push(v.phi, v.omega, v.omega_dot, rec.grid().dt);
        }
    }
    let mut ident = Identification {
        schema: IDENTIFICATION_SCHEMA,
        method: MethodName::Refine,
        input: None,
        scenario: None,
        record: super::record_info(rec),
        parameters,
        rotor,
        covariance: Some(covariance(&fit)),
        noise: Some(Noise {
            sigma_x_m: fit.sigma_x,
            sigma_z_m: fit.sigma_z,
            source: NoiseSource::Residuals,
        }),
        adequacy,
        diagnostics,
        algebraic: None,
        modulating: found
            .modulating
            .as_ref()
            .map(|e| modulating_detail(e, s.modulating.config.rcond_min)),
        refine: Some(RefineDetail {
            unknowns: unknown_parameters(&u),
            start: found.start,
            initial_state: fit
                .initial_state
                .iter()
                .map(|e| StateResult {
                    name: e.name.to_owned(),
                    unit: e.unit.to_owned(),
                    value: e.value,
                    std_error: finite(e.std_error),
                })
                .collect(),
            converged: fit.converged,
            iterations: fit.iterations as u64,
            identifiable: fit.identifiable,
            condition_number: finite(fit.condition_number),
            discretisation: fit.discretisation.clone(),
            std_error_basis: fit.std_error_basis.to_owned(),
            crb_at: bound.map(|(_, at)| at),
            hac_bandwidth: fit.robust.as_ref().map(|r| r.bandwidth as u64),
            residual_lag1_autocorrelation: fit
                .robust
                .as_ref()
                .and_then(|r| finite(r.residual_lag1_autocorrelation)),
        }),
        estimates: Vec::new(),
    };
    super::apply_speed_check(&mut ident, &check);
    Ok(ident)
}

/// The residual tests of the fit (module `adequacy`); `None` when the model response
/// cannot be computed.
fn adequacy(rec: &Record, fit: &Refined) -> Option<Adequacy> {
    let record = rec.for_refine();
    let model = model_response(
        &fit.rotor,
        &fit.initial,
        &record.experiment(),
        Discretisation::Auto,
    )
    .ok()?;
    Some(Adequacy::of_response(rec, &model.x, &model.z))
}

/// Signed (value - truth) / truth.
pub(crate) fn relative_error(value: Option<f64>, truth: Option<f64>) -> Option<f64> {
    match (value, truth) {
        (Some(v), Some(t)) if t != 0.0 => Some((v - t) / t),
        _ => None,
    }
}

/// The unknowns as parameters (the unbalance as mud and alpha).
fn unknown_parameters(u: &Unknowns) -> Vec<Parameter> {
    [
        (u.m, Parameter::M),
        (u.cx, Parameter::Cx),
        (u.kx, Parameter::Kx),
        (u.cz, Parameter::Cz),
        (u.kz, Parameter::Kz),
        (u.a, Parameter::A),
        (u.unbalance, Parameter::Mud),
        (u.unbalance, Parameter::Alpha),
    ]
    .into_iter()
    .filter_map(|(on, p)| on.then_some(p))
    .collect()
}

fn covariance(fit: &Refined) -> Covariance {
    Covariance {
        names: fit
            .covariance_names
            .iter()
            .map(|s| (*s).to_owned())
            .collect(),
        matrix: fit
            .covariance
            .iter()
            .map(|row| row.iter().map(|&v| finite(v)).collect())
            .collect(),
    }
}

/// The Cramer-Rao bound and where it was evaluated (module doc).
fn bound(
    rec: &Record,
    k: &Knowledge,
    fit: &Refined,
    u: &Unknowns,
) -> Result<(crate::refine::Crb, CrbAt), PipelineError> {
    let (rotor, initial, at) = match true_rotor(k) {
        Some((r, Some(ic))) if rec.grid().t0 == 0.0 => (r, ic, CrbAt::Truth),
        Some((r, _)) => (r, fit.initial, CrbAt::TruthParameters),
        None => (fit.rotor, fit.initial, CrbAt::Estimate),
    };
    let b = crb(
        &rotor,
        &initial,
        &rec.for_refine().experiment(),
        u,
        fit.sigma_x,
        fit.sigma_z,
    )?;
    Ok((b, at))
}

/// The Cramer-Rao bound that applies to the modulating identifier's estimates `values`
/// (m_x, c_x, k_x, m_z, c_z, k_z) with its noise levels `sigma_x`, `sigma_z` \[m\]
/// (docs/method.md section 4.6): the bound of the model with one mass m, cx, kx, cz, kz
/// and the initial state unknown, evaluated at the truth when it is known, else at the
/// estimate (m the mean of m_x and m_z) with the initial state fitted to the record for
/// that rotor (the response is linear in it). Because m_x = m_z = m is a special case of
/// the modulating method's model, the bound on m is a lower bound on the variance of any
/// unbiased m_x or m_z (not necessarily attainable by them); likewise for c and k.
pub(crate) fn modulating_bound(
    rec: &Record,
    k: &Knowledge,
    values: [f64; 6],
    sigma_x: f64,
    sigma_z: f64,
) -> Result<(crate::refine::Crb, CrbAt), PipelineError> {
    let (rotor, known_ic, at) = match true_rotor(k) {
        Some((r, Some(ic))) if rec.grid().t0 == 0.0 => (r, Some(ic), CrbAt::Truth),
        Some((r, _)) => (r, None, CrbAt::TruthParameters),
        None => (
            RotorParams {
                m: 0.5 * (values[0] + values[3]),
                cx: values[1],
                kx: values[2],
                cz: values[4],
                kz: values[5],
                a: k.a,
                unbalance: k.unbalance,
            },
            None,
            CrbAt::Estimate,
        ),
    };
    let record = rec.for_refine();
    let initial = match known_ic {
        Some(ic) => ic,
        None => {
            let only_initial_state = Unknowns {
                m: false,
                cx: false,
                kx: false,
                cz: false,
                kz: false,
                a: false,
                unbalance: false,
                initial_state: true,
            };
            let options = RefineOptions {
                unknowns: only_initial_state,
                ..RefineOptions::default()
            };
            refine(&record, &rotor, &InitialState::default(), &options)?.initial
        }
    };
    let b = crb(
        &rotor,
        &initial,
        &record.experiment(),
        &Unknowns::default(),
        sigma_x,
        sigma_z,
    )?;
    Ok((b, at))
}

/// The true rotor and (when known) initial state, when the knowledge has all of m, c, k.
fn true_rotor(k: &Knowledge) -> Option<(RotorParams, Option<InitialState>)> {
    k.truth.as_ref().and_then(|t| {
        let v = &t.values;
        Some((
            RotorParams {
                m: v.m?,
                cx: v.cx?,
                kx: v.kx?,
                cz: v.cz?,
                kz: v.kz?,
                a: k.a,
                unbalance: k.unbalance,
            },
            t.initial,
        ))
    })
}
