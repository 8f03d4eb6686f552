//! The refinement as the pipeline runs it (docs/method.md section 5): the start
//! (module `start`), the maximum-likelihood fit, the Cramer-Rao bound where it is most
//! meaningful, and the rule that withholds what the record does not determine.
//!
//! A parameter is determined when its standard error is finite and no larger than its
//! value (alpha: no larger than 1 rad; a cross-coupled coefficient, which may be 0: no
//! larger than the direct coefficients it couples, `FittedValue::scale`), and the data
//! separate the unknowns (no not-identifiable or ill-conditioned finding) and the model
//! explains the record (module `adequacy`). The bound is evaluated at the truth when the
//! caller knows every mass, damping and stiffness value of the model (with the true initial
//! state when the record starts at t = 0, else the fitted one), otherwise at the estimate;
//! always with the fitted noise.
//!
//! The model is the settings' (docs/method.md section 6.6): one fixed model, or `auto`:
//! the Jeffcott and the cross-coupled model fitted in turn (the second started from the
//! first's estimate, the nested Jeffcott rotor), each judged by its residuals, and the
//! simplest adequate one taken by the Bayesian information criterion. A fixed Jeffcott fit
//! that its residuals reject is followed by a cross-coupled fit; when that one explains the
//! record, a note says so.

use crate::model::{InitialState, RotorParams};
use crate::parameter::{ModelKind, Parameter};
use crate::refine::{
    crb, model_response, refine, Discretisation, FittedValue, RefineOptions, Refined, Unknowns,
    ALPHA_STD_LIMIT,
};

use super::adequacy::Adequacy;
use super::diagnostic::{Diagnostic, Directions, Finding};
use super::error::PipelineError;
use super::identification::StartSource;
use super::identification::{
    finite, Covariance, CrbAt, Identification, ModelCandidate, ModelSelection, Noise, NoiseSource,
    ParameterResult, RefineDetail, RotorSummary, StateResult, IDENTIFICATION_SCHEMA,
};
use super::knowledge::Knowledge;
use super::method::{MethodName, ModelChoice, RefineSettings, StartPolicy};
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
    let choice = s.model.unwrap_or(ModelChoice::from(k.model));
    let model = match (choice, s.start) {
        (ModelChoice::Auto, StartPolicy::Given(p)) => {
            return Err(PipelineError::GivenStartNeedsModel {
                model: p.model().name(),
            })
        }
        (ModelChoice::Auto, StartPolicy::Auto) => return select(rec, k, s),
        (choice, _) => choice.fixed().expect("not auto"),
    };
    let u = unknowns(s, model, false);
    let (mut ident, _) = fit(rec, k, s, model, &u, None)?;
    if model == ModelKind::Jeffcott && inadequate(&ident) && !u.any_cross() {
        // does the cross-coupled model explain what the Jeffcott one cannot?
        let cu = cross_unknowns(&u);
        let start = ident_rotor(&ident);
        if let Ok((alt, _)) = fit(rec, k, s, ModelKind::CrossCoupled, &cu, start.as_ref()) {
            if alt.adequacy.is_some_and(|a| a.model_adequate) {
                ident
                    .diagnostics
                    .push(Diagnostic::note(Finding::OtherModelExplains {
                        model: ModelKind::CrossCoupled,
                        bic_difference: bic(&ident) - bic(&alt),
                    }));
            }
        }
    }
    Ok(ident)
}

/// The unknowns of `model` under settings `s` (module doc of [`RefineSettings::unknowns`]);
/// `auto` when the model is a candidate of `--model auto`.
fn unknowns(s: &RefineSettings, model: ModelKind, auto: bool) -> Unknowns {
    match (s.unknowns, model) {
        (None, m) => Unknowns::for_model(m),
        (Some(u), ModelKind::Jeffcott) if auto => Unknowns {
            cxz: false,
            czx: false,
            kxz: false,
            kzx: false,
            ..u
        },
        (Some(u), ModelKind::CrossCoupled) if auto => cross_unknowns(&u),
        (Some(u), _) => u,
    }
}

/// `u` with the four cross-coupled coefficients when it has none.
fn cross_unknowns(u: &Unknowns) -> Unknowns {
    if u.any_cross() {
        *u
    } else {
        Unknowns {
            cxz: true,
            czx: true,
            kxz: true,
            kzx: true,
            ..*u
        }
    }
}

/// True when the residual tests rejected the fit.
fn inadequate(ident: &Identification) -> bool {
    ident.adequacy.is_some_and(|a| !a.model_adequate)
}

/// The fitted rotor of an identification (estimates whether determined or not), for the
/// start of a larger model.
fn ident_rotor(ident: &Identification) -> Option<RotorParams> {
    let start = ident.refine.as_ref()?.start.values.params();
    let mut p = start;
    for r in &ident.parameters {
        if let Some(v) = r.estimate {
            if r.parameter != Parameter::Alpha && r.parameter != Parameter::Mud {
                p.set(r.parameter, v);
            }
        }
    }
    Some(p)
}

/// The Gaussian log-likelihood of x and z at the fit's noise levels (module doc of
/// [`ModelCandidate`]): -N/2 (ln(2 pi sigma_x^2) + 1) - N/2 (ln(2 pi sigma_z^2) + 1).
fn log_likelihood(ident: &Identification) -> f64 {
    let n = ident.record.samples as f64;
    let Some(noise) = ident.noise else {
        return f64::NAN;
    };
    let term = |s: f64| {
        let v = (s * s).max(f64::MIN_POSITIVE);
        -0.5 * n * ((std::f64::consts::TAU * v).ln() + 1.0)
    };
    term(noise.sigma_x_m) + term(noise.sigma_z_m)
}

/// Quantities a fit estimated: its covariance's rows and the two noise levels.
fn estimated(ident: &Identification) -> u64 {
    ident
        .covariance
        .as_ref()
        .map_or(0, |c| c.names.len() as u64)
        + 2
}

/// BIC = -2 ln L + (estimated) ln(2 N).
fn bic(ident: &Identification) -> f64 {
    let n = 2.0 * ident.record.samples as f64;
    -2.0 * log_likelihood(ident) + estimated(ident) as f64 * n.ln()
}

/// `--model auto` (module doc).
fn select(
    rec: &Record,
    k: &Knowledge,
    s: &RefineSettings,
) -> Result<Identification, PipelineError> {
    let uj = unknowns(s, ModelKind::Jeffcott, true);
    let (jeffcott, _) = fit(rec, k, s, ModelKind::Jeffcott, &uj, None)?;
    let uc = unknowns(s, ModelKind::CrossCoupled, true);
    let start = ident_rotor(&jeffcott).filter(|p| {
        p.m > 0.0 && p.kx > 0.0 && p.kz > 0.0 && [p.cx, p.cz].iter().all(|c| c.is_finite())
    });
    let cross = fit(rec, k, s, ModelKind::CrossCoupled, &uc, start.as_ref()).map(|(i, _)| i);
    let mut fits = vec![jeffcott];
    let mut notes = Vec::new();
    match cross {
        Ok(c) => fits.push(c),
        Err(e) => notes.push(format!("the cross-coupled model could not be fitted: {e}")),
    }
    let candidates: Vec<ModelCandidate> = fits
        .iter()
        .map(|f| ModelCandidate {
            model: f.model,
            estimated: estimated(f),
            log_likelihood: log_likelihood(f),
            bic: bic(f),
            adequate: f.adequacy.map(|a| a.model_adequate),
            noise_ratio: Directions {
                x: f.adequacy.map_or(f64::NAN, |a| a.x.noise_ratio),
                z: f.adequacy.map_or(f64::NAN, |a| a.z.noise_ratio),
            },
            converged: f.refine.as_ref().is_some_and(|r| r.converged),
            identifiable: f.identifiable(),
        })
        .collect();
    let ok = |c: &ModelCandidate| c.adequate == Some(true) && c.converged;
    let pool: Vec<usize> = if candidates.iter().any(ok) {
        (0..candidates.len())
            .filter(|&i| ok(&candidates[i]))
            .collect()
    } else {
        (0..candidates.len()).collect()
    };
    let best = pool
        .iter()
        .copied()
        .min_by(|&a, &b| candidates[a].bic.total_cmp(&candidates[b].bic))
        .expect("the Jeffcott candidate is always there");
    let reason = selection_reason(&candidates, best, &notes);
    let mut ident = fits.swap_remove(best);
    ident
        .diagnostics
        .push(Diagnostic::note(Finding::ModelSelected {
            model: ident.model,
            reason: reason.clone(),
        }));
    ident.model_selection = Some(ModelSelection {
        criterion: "among the candidates whose residuals pass the adequacy test (all when none \
                    does), the lowest BIC = -2 ln L + k ln(2 N)"
            .to_owned(),
        chosen: candidates[best].model,
        candidates,
        reason,
    });
    Ok(ident)
}

/// The selection in words.
fn selection_reason(c: &[ModelCandidate], best: usize, notes: &[String]) -> String {
    let name = |m: ModelKind| match m {
        ModelKind::Jeffcott => "the Jeffcott model",
        ModelKind::CrossCoupled => "the cross-coupled model",
    };
    let judged = |x: &ModelCandidate| {
        match x.adequate {
        Some(true) => "its residuals look like the data's noise".to_owned(),
        Some(false) => format!(
            "its residuals fail the adequacy test (residual {:.2}x / {:.2}x the noise level in x / z)",
            x.noise_ratio.x, x.noise_ratio.z
        ),
        None => "its residuals could not be tested".to_owned(),
    }
    };
    let b = &c[best];
    let mut out = String::new();
    if b.model == ModelKind::CrossCoupled
        && c[0].adequate == Some(false)
        && b.adequate == Some(true)
    {
        out.push_str("cross-coupled bearings explain these data: ");
    }
    if b.adequate != Some(true) {
        out.push_str("no candidate model explains these data (its values are withheld): ");
    }
    out.push_str(&format!("{} was taken, {}", name(b.model), judged(b)));
    for (i, x) in c.iter().enumerate().filter(|&(i, _)| i != best) {
        let _ = i;
        out.push_str(&format!(
            "; {} {}, BIC {} by {:.1}",
            name(x.model),
            judged(x),
            if x.bic > b.bic { "higher" } else { "lower" },
            (x.bic - b.bic).abs()
        ));
    }
    for n in notes {
        out.push_str("; ");
        out.push_str(n);
    }
    out
}

/// Whether `e` counts as determined by its standard error (module doc).
pub(crate) fn small_enough(p: Parameter, e: &FittedValue) -> bool {
    match (p, e.scale) {
        (Parameter::Alpha, _) => e.std_error <= ALPHA_STD_LIMIT,
        (_, Some(scale)) => e.std_error <= scale,
        _ => e.relative_std_error.is_some_and(|r| r <= 1.0),
    }
}

/// One fit of `model` with unknowns `u`, started from `start` when given (else by the
/// start policy), as a whole identification.
fn fit(
    rec: &Record,
    k: &Knowledge,
    s: &RefineSettings,
    model: ModelKind,
    u: &Unknowns,
    start: Option<&RotorParams>,
) -> Result<(Identification, Refined), PipelineError> {
    let u = *u;
    check_known(k, &u, model)?;
    let found = match (start, s.start) {
        (Some(p), _) => start::Found {
            start: start::start(
                StartSource::Nominal,
                None,
                &start::with_cross(p, k, &u),
                None,
            ),
            params: if model == ModelKind::CrossCoupled {
                start::with_cross(p, k, &u)
            } else {
                RotorParams {
                    coupling: None,
                    ..*p
                }
            },
            modulating: None,
        },
        (None, StartPolicy::Auto) => start::find(rec, k, s, &u, model)?,
        (None, StartPolicy::Given(p)) => {
            let p = match model {
                ModelKind::CrossCoupled => start::with_cross(&p, k, &u),
                ModelKind::Jeffcott => RotorParams {
                    coupling: None,
                    ..p
                },
            };
            start::Found {
                start: start::start(StartSource::Given, None, &p, None),
                params: p,
                modulating: None,
            }
        }
    };
    let mut found = found;
    if start.is_some() {
        // the nested model's estimate
        found.start.source = StartSource::NestedModel;
        found.start.values = RotorSummary::of(&found.params);
    }
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
    diagnostics.extend(adequacy.iter().flat_map(Adequacy::notes));
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
            let determined = e.std_error.is_finite() && small_enough(p, e) && !inseparable;
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
        model,
        model_selection: None,
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
        modulating: found.modulating.as_ref().map(|e| {
            modulating_detail(
                &super::ModulatingSummary::jeffcott(e),
                s.modulating.config.rcond_min,
            )
        }),
        refine: Some(RefineDetail {
            unknowns: u.parameters(model),
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
            fisher_rank: Some(fit.fisher_rank as u64),
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
    Ok((ident, fit))
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
    let (rotor, initial, at) = match true_rotor(k, fit.rotor.model()) {
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
    model: ModelKind,
    values: &[f64],
    sigma_x: f64,
    sigma_z: f64,
) -> Result<(crate::refine::Crb, CrbAt), PipelineError> {
    let (rotor, known_ic, at) = match true_rotor(k, model) {
        Some((r, Some(ic))) if rec.grid().t0 == 0.0 => (r, Some(ic), CrbAt::Truth),
        Some((r, _)) => (r, None, CrbAt::TruthParameters),
        None => {
            let mut r = RotorParams {
                coupling: (model == ModelKind::CrossCoupled).then(Default::default),
                m: 0.0,
                cx: f64::NAN,
                kx: f64::NAN,
                cz: f64::NAN,
                kz: f64::NAN,
                a: k.a,
                unbalance: k.unbalance,
            };
            for (&p, &v) in model.per_direction().iter().zip(values) {
                match p {
                    // one mass: the mean of the two directions'
                    Parameter::MX | Parameter::MZ => r.m += 0.5 * v,
                    q => r.set(q, v),
                }
            }
            (r, None, CrbAt::Estimate)
        }
    };
    let record = rec.for_refine();
    let initial = match known_ic {
        Some(ic) => ic,
        None => {
            let only_initial_state = Unknowns::initial_state_only();
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
        &Unknowns::for_model(model),
        sigma_x,
        sigma_z,
    )?;
    Ok((b, at))
}

/// The true rotor of `model` and (when known) initial state, when the knowledge has every
/// mass, damping and stiffness value of the model.
fn true_rotor(k: &Knowledge, model: ModelKind) -> Option<(RotorParams, Option<InitialState>)> {
    let t = k.truth.as_ref()?;
    let mut p = RotorParams {
        m: 0.0,
        cx: 0.0,
        kx: 0.0,
        cz: 0.0,
        kz: 0.0,
        a: k.a,
        unbalance: k.unbalance,
        coupling: (model == ModelKind::CrossCoupled).then(Default::default),
    };
    for &q in model.default_unknowns() {
        p.set(q, t.values.get(q)?);
    }
    Some((p, t.initial))
}
