//! Balancing: the correction masses that cancel a rotor's 1X vibration, with their
//! uncertainty. docs/balancing.md of this repository states the method, the conventions,
//! the file formats and a worked two-plane, four-probe example.
//!
//! Conventions. Angles on the rotor (masses, corrections, holes) are shaft angles from the
//! keyphasor mark in the direction of rotation; an unbalance is the complex number
//! m R e^{i angle} \[kg m\] and unbalances on one plane add as such numbers. A 1X vector
//! V means the sensor's 1X component is Re(V e^{i phi}), phi the shaft angle (amplitude
//! |V|, phase lag -arg V); vectors are kept in the sensor's own unit.
//!
//! The model of influence-coefficient balancing is linearity: for each sensor s at each
//! speed W (a "key" k),
//!
//! ```text
//! V_k = A_k + sum_p H_kp U_p
//! ```
//!
//! with U_p the unbalance added on plane p, A_k the vector as found and H_kp the influence
//! coefficient \[sensor unit / (kg m)\]. The steps:
//!
//! 1. [`balance`]: the influence coefficients of every key fitted by least squares over
//!    every calibration run (`influence`: runs beyond the minimum are used, weighted by the
//!    vectors' own noise when given, with covariances from the residuals otherwise);
//! 2. the correction C of the current run's vectors V: least squares or min-max with limits
//!    (`correction`, `minmax`: a second-order cone program solved by Clarabel), its
//!    covariance by the delta method from the coefficients' and the vectors' uncertainty,
//!    the predicted residual V + H C with its covariance, the condition number of H;
//! 3. the split of each plane's correction into the holes it has (`split`);
//! 4. [`plan_from_influence`] / [`plan_from_model`]: trial masses that change the response
//!    by a stated fraction at the most sensitive sensor (`plan`).
//!
//! The single-plane forms (`single`): [`balance_from_unbalance`] (the identified unbalance
//! of a model) and [`balance_from_runs`] (two runs, the one-plane case of [`balance`]).

mod correction;
mod data;
mod error;
mod influence;
mod minmax;
mod multi;
mod plan;
mod report;
mod single;
mod split;

pub use data::{MassInput, VectorInput, SPEED_TOLERANCE};
pub use error::BalanceError;
pub use influence::{KeyFit, NoiseSource};
pub use multi::{
    balance, BalanceMethod, BalanceOptions, KeyResult, MultiPlaneBalance, PlaneCorrection,
    PredictedResidual, SensorInfo, CONDITION_WARNING, MISFIT_WARNING,
};
pub use plan::{plan_from_influence, plan_from_model, Trial, TrialPlan, DEFAULT_FRACTION};
pub use report::{
    angle_deg, BalanceReport, CorrectionJson, FitJson, InfluenceJson, PlanReport, ResidualJson,
    SensorJson, SplitJson, SplitMassJson, TrialJson, ANGLE_REFERENCE, BALANCE_SCHEMA,
    VECTOR_CONVENTION,
};
pub use single::{
    balance_from_runs, balance_from_unbalance, response_per_unbalance, Correction,
    InfluenceBalance, ModelBalance, RunVectors, TrialMass,
};
pub use split::{split, Holes, MassSet, Split, SplitMass};
