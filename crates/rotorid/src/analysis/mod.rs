//! From identified parameters to engineering decisions: Campbell diagram, critical
//! speeds, stability, unbalance response and balancing, each with its uncertainty
//! propagated from the parameters' covariance (e.g. that of a maximum-likelihood fit,
//! [`ParameterCovariance::from_refined`]).
//!
//! The model is eq. (1) (see [`crate::model`]) at a constant speed W (w' = 0):
//!
//! ```text
//! M q'' + (C1 + W C2) q' + K1 q = F(t),    q = (x, z)
//! M = m I,  C1 = [[cx, cxz], [czx, cz]],  C2 = [[0, -a], [a, 0]],  K1 = [[kx, kxz], [kzx, kz]]
//! F = m_u d W^2 ( sin(phi + alpha), cos(phi + alpha) )
//! ```
//!
//! with the cross-coupled terms cxz, czx, kxz, kzx of [`crate::model::CrossCoupling`] (0
//! for the Jeffcott rotor, [`RotorParams::coupling`](crate::model::RotorParams) `None`).
//!
//! Conventions (those of ROSS and API 684): the shaft turns from +z (vertical up) toward
//! +x (horizontal), the sense in which the unbalance force turns; forward whirl is whirl
//! in that sense. Angles on the rotor (alpha, trial and correction masses) are shaft
//! angles from the keyphasor reference (phi = 0) in the direction of rotation; probe
//! angles are measured from +z in the direction of rotation (x is at 90 deg). A 1X vector
//! V gives the signal Re(V e^{i phi}): amplitude |V| (peak) and phase lag -arg V in
//! \[0, 2 pi). Every quantity is SI (rad/s, rad, m, kg); rpm, Hz, um peak-to-peak and
//! degrees are the command line's business.
//!
//! - `modes`: eigenvalues, damped natural frequencies, damping ratio, logarithmic
//!   decrement, whirl direction; [`campbell`] over a speed grid.
//! - `critical`: [`critical_speeds`] (1X crossings) with linearised standard deviations.
//! - `stability`: minimum logarithmic decrement, threshold speed with its standard
//!   deviation, and the stability margin (least damped mode) at an operating speed.
//! - `response`: [`unbalance_response`] (amplitude, phase lag per probe) with standard
//!   deviations.
//! - [`balance`]: correction from the identified unbalance; influence-coefficient
//!   balancing of many planes, sensors and speeds (least squares or min-max), with the
//!   corrections' uncertainty, their split into holes and trial-weight planning.
//! - `one_x`: the 1X vector of a sampled signal against the shaft angle.
//! - `covariance`: [`ParameterCovariance`] and the delta method.
//! - `finite_element`: the same for a finite-element rotor ([`fe_analysis`]: Campbell
//!   diagram of its lowest modes followed across speeds, critical speeds, stability;
//!   [`fe_unbalances`]; [`FeCovariance`] over its parameters' names).
//!
//! Conventions, the checks against independent references and the measured figures are in
//! `docs/analysis.md` of this repository.
//!
//! ```
//! use rotorid::analysis::{critical_speeds, Whirl};
//! use rotorid::model::{rpm_to_rad_per_s, Rotor};
//!
//! let grid: Vec<f64> = (0..=600).map(|k| rpm_to_rad_per_s(10.0 * k as f64)).collect();
//! let cs = critical_speeds(&Rotor::table1().params(), None, &grid)?;
//! // W^2 = k / (m + a) backward, k / (m - a) forward (zero damping): 2519.9, 3089.2 rpm
//! assert_eq!(cs.len(), 2);
//! assert_eq!(cs[0].whirl(), Some(Whirl::Backward));
//! assert!((cs[0].rpm() - 2519.9).abs() < 0.1 && (cs[1].rpm() - 3089.2).abs() < 0.1);
//! # Ok::<(), rotorid::analysis::AnalysisError>(())
//! ```

pub mod balance;
mod complex_lu;
mod covariance;
mod critical;
mod error;
mod finite_element;
mod modes;
mod one_x;
mod response;
mod stability;

pub use balance::{
    balance_from_runs, balance_from_unbalance, response_per_unbalance, BalanceError, Correction,
    InfluenceBalance, ModelBalance, RunVectors, TrialMass,
};
pub use covariance::{CovarianceParameter, ParameterCovariance, PARAMETER_NAMES};
pub use critical::{critical_speeds, CriticalSpeed};
pub use error::AnalysisError;
pub use finite_element::{
    fe_analysis, fe_stability_margin, fe_unbalances, FeAnalysis, FeCampbell, FeCovariance,
    FeUnbalanceEstimate, MAX_DAMPING_RATIO,
};
pub use modes::{campbell, modes, Campbell, Mode, Whirl, PLANAR_WHIRL};
pub use one_x::{one_x, synchronous_average, OneX};
pub use response::{unbalance_response, Probe, ResponseChannel, ResponseVector, UnbalanceResponse};
pub use stability::{
    stability, stability_margin, stability_with_covariance, Stability, StabilityMargin,
    UNSTABLE_ZETA,
};
