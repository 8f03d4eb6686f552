//! Maximum-likelihood (output-error) refinement of the rotor parameters, with standard
//! errors, the Cramer-Rao bound and identifiability diagnostics.
//!
//! Model: eq. (1) of Barredo et al. (2024) (see [`crate::model`]),
//!
//! ```text
//! m x'' + cx x' - a w z' - a w' z + kx x = m_u d ( w^2 sin(phi+alpha) - w' cos(phi+alpha) )
//! m z'' + cz z' + a w x'          + kz z = m_u d ( w' sin(phi+alpha) + w^2 cos(phi+alpha) )
//! ```
//!
//! Measurements: x_k = x(t_k) + e_x,k, z_k = z(t_k) + e_z,k, t_k = k dt, with white
//! Gaussian noise of unknown standard deviations sigma_x, sigma_z. [`refine`] maximises
//! the likelihood over the unknowns (default m, cx, kx, cz, kz, plus the unknown initial
//! state as four nuisance parameters; optionally a and the unbalance), by Gauss-Newton
//! with Levenberg-Marquardt damping on the exact sensitivities of the discrete model.
//! Standard errors come from the Fisher information at the estimate; [`crb()`] gives the
//! Cramer-Rao bound at the truth (docs/method.md sections 5.1.5 and 5.4).
//!
//! The model must be far more accurate than the noise (the relative bound on m is ~4e-5
//! at 40 dB): at constant speed it is discretised exactly (matrix exponential of the state
//! augmented with the forcing oscillator, module `exact_step`); for ramps and measured
//! speed, RK4 on state and sensitivities with sub-steps keeping the relative frequency
//! error below 1e-9 (module `rk4_step`).
//!
//! A fit starts on a short leading window of the record and extends it as the estimate
//! firms up (continuation, see `lm`), so starts several per cent off, such as the
//! algebraic identifier's early estimate, reach the global optimum. When the data cannot
//! separate the unknowns the result says so (`identifiable == false`, [`Warning`]s,
//! infinite standard errors) rather than giving a confident number: singular Fisher
//! information (e.g. m, c, k, a and m_u d all unknown: eq. (1) is homogeneous in them;
//! no excitation), or, at constant speed, a record without a significant free transient
//! (steady state only: four numbers, amplitude and phase per channel).
//!
//! ```
//! use rotorid::model::{InitialState, Scenario};
//! use rotorid::refine::{refine, Record, RefineOptions};
//! use rotorid::simulate::{add_noise, simulate, Method};
//!
//! let s = Scenario::table1(); // 1200 rpm, 1 s at 10 kHz
//! let mut resp = simulate(&s, Method::Exact)?;
//! add_noise(&mut resp, 40.0, 1)?;
//! let mut start = s.rotor.params();
//! start.m *= 1.01;
//! start.kx *= 0.99;
//! let rec = Record::from_simulation(&s, &resp);
//! let fit = refine(&rec, &start, &InitialState::default(), &RefineOptions::default())?;
//! assert!(fit.converged && fit.identifiable);
//! let m = fit.get("m").unwrap();
//! assert!((m.value - 14.29).abs() < 5.0 * m.std_error); // std_error ~ 6e-4 kg
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! Files: `record` (data and speed), `unknowns` (selection, internal parameters),
//! `speed_table` (tabulated forcing, Hermite interpolation of measured speed),
//! `exact_step`, `rk4_step`, `steady` (steady-state initial state, significance of the
//! free transient), `discretisation` (choice of discrete model), `sweep` (one
//! pass, normal equations), `fisher` (information, covariance, LM step), `lm` (the fit),
//! `crb` (bound, model response), `result` (reported structures, warnings).

mod crb;
mod discretisation;
mod error;
mod exact_step;
pub mod finite_element;
mod fisher;
mod lm;
mod record;
mod result;
mod rk4_step;
mod robust;
mod speed_table;
mod steady;
mod sweep;
mod unknowns;

pub use crb::{crb, crb_at_snr, model_response, ModelResponse};
pub use discretisation::Discretisation;
pub use error::RefineError;
pub(crate) use lm::{fit, Continuation, Fit};
pub use lm::{refine, RefineOptions};
pub use record::{Experiment, Record, SpeedData};
pub use result::{
    Bound, Crb, FittedValue, Refined, RobustCovariance, Warning, ALPHA_STD_LIMIT, CONDITION_LIMIT,
    STD_ERROR_BASIS,
};
pub(crate) use rk4_step::FREQ_TOL;
pub use unknowns::Unknowns;
