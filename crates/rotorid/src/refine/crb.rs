//! The Cramer-Rao bound of an experiment and the model response itself.
//!
//! For white Gaussian noise sigma_x on x and sigma_z on z the Fisher information of the
//! unknowns theta is F = J_x^T J_x / sigma_x^2 + J_z^T J_z / sigma_z^2 with J the exact
//! sensitivities of the discrete model at the true parameters, and every unbiased
//! estimator has Cov(theta_hat) >= F^-1 (Kay 1993, ch. 3; docs/method.md section 5.1.5).
//! With the initial state unknown its four components are nuisance parameters and the bound
//! on the rest is the corresponding block of F^-1 (which is larger than with the state
//! known).
//!
//! docs/method.md section 2.5 defines the noise by the signal-to-noise ratio of each
//! channel: sigma = RMS(clean channel) * 10^(-SNR/20), RMS over all samples of the record.

use crate::model::{check, InitialState, RotorParams, Scenario};

use super::discretisation::{Discrete, Discretisation};
use super::error::RefineError;
use super::fisher::Fisher;
use super::record::Experiment;
use super::result::{identifiability_warnings, rows, Bound, Crb};
use super::sweep::{Normal, NormalSink, ResponseSink};
use super::unknowns::{check_params, Columns, Theta, Unknowns};

/// The Cramer-Rao bound for estimating `unknowns` from the experiment `experiment` when
/// the truth is `rotor`, `initial` and the noise standard deviations are `sigma_x`,
/// `sigma_z` \[m\] (finite, > 0). Uses the exact discretisation at constant speed, RK4 (with
/// automatic sub-steps) otherwise.
pub fn crb(
    rotor: &RotorParams,
    initial: &InitialState,
    experiment: &Experiment,
    unknowns: &Unknowns,
    sigma_x: f64,
    sigma_z: f64,
) -> Result<Crb, RefineError> {
    experiment.validate()?;
    check_params(rotor)?;
    initial.validated()?;
    check("sigma_x", sigma_x, "finite and > 0 (m)", |v| v > 0.0)?;
    check("sigma_z", sigma_z, "finite and > 0 (m)", |v| v > 0.0)?;
    let cols = super::lm::columns(unknowns, rotor)?;
    let t = Theta::new(rotor, initial);
    let disc = Discrete::new(experiment, Discretisation::Auto, &t)?;
    let mut sink = NormalSink {
        data: None,
        acc: Normal::new(cols.n),
    };
    disc.run(&t, &cols, experiment.samples, &mut sink);
    let (f, _) = sink.acc.combine(sigma_x * sigma_x, sigma_z * sigma_z);
    let fi = Fisher::new(&f, cols.n);
    let rs = rows(&t, &cols, &fi);
    let identifiable = identifiability_warnings(&rs, fi.condition_number, Vec::new())
        .iter()
        .all(|w| matches!(w, super::result::Warning::PoorlyDetermined { .. }));
    let mut parameters = Vec::new();
    let mut initial_state = Vec::new();
    for r in rs {
        let b = Bound {
            name: r.name,
            unit: r.unit,
            value: r.value,
            std_dev: r.std,
            relative: r.relative,
        };
        if r.initial {
            initial_state.push(b);
        } else {
            parameters.push(b);
        }
    }
    Ok(Crb {
        parameters,
        initial_state,
        sigma_x,
        sigma_z,
        condition_number: fi.condition_number,
        identifiable,
        discretisation: disc.describe(),
    })
}

/// Root mean square of `v`.
fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|a| a * a).sum::<f64>() / v.len() as f64).sqrt()
}

/// The Cramer-Rao bound for a simulated scenario at a signal-to-noise ratio `snr_db`
/// \[dB\] per channel: sigma = RMS(clean channel) * 10^(-SNR/20)
/// (docs/method.md section 2.5).
pub fn crb_at_snr(
    scenario: &Scenario,
    snr_db: f64,
    unknowns: &Unknowns,
) -> Result<Crb, RefineError> {
    check("snr_db", snr_db, "finite (dB)", |_| true)?;
    let exp = Experiment::from_scenario(scenario);
    let rotor = scenario.rotor.params();
    let clean = model_response(&rotor, &scenario.initial, &exp, Discretisation::Auto)?;
    let factor = 10f64.powf(-snr_db / 20.0);
    crb(
        &rotor,
        &scenario.initial,
        &exp,
        unknowns,
        rms(&clean.x) * factor,
        rms(&clean.z) * factor,
    )
}

/// The response of the discrete model used by [`refine`](super::refine).
#[derive(Debug, Clone, PartialEq)]
pub struct ModelResponse {
    /// x_k \[m\] at t_k = k dt.
    pub x: Vec<f64>,
    /// z_k \[m\] at t_k = k dt.
    pub z: Vec<f64>,
    /// The discrete model used.
    pub discretisation: String,
}

/// The model response for `rotor` from `initial` over the experiment (e.g. the fitted
/// curve to overlay on the data).
pub fn model_response(
    rotor: &RotorParams,
    initial: &InitialState,
    experiment: &Experiment,
    discretisation: Discretisation,
) -> Result<ModelResponse, RefineError> {
    experiment.validate()?;
    check_params(rotor)?;
    initial.validated()?;
    let t = Theta::new(rotor, initial);
    let disc = Discrete::new(experiment, discretisation, &t)?;
    let cols = Columns::new(&Unknowns::from_parameters(&[], false), rotor.model());
    let mut sink = ResponseSink {
        x: Vec::with_capacity(experiment.samples),
        z: Vec::with_capacity(experiment.samples),
    };
    disc.run(&t, &cols, experiment.samples, &mut sink);
    Ok(ModelResponse {
        x: sink.x,
        z: sink.z,
        discretisation: disc.describe(),
    })
}
