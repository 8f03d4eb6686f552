//! The choice of discrete model: exact (matrix exponential) at constant speed, RK4 on
//! state and sensitivities otherwise (see `exact_step` and `rk4_step`). The discrete
//! model is fixed for a whole fit (same sub-step count at every iteration) so that costs
//! at different parameters are comparable.

use serde::{Deserialize, Serialize};

use super::error::RefineError;
use super::exact_step::ExactStep;
use super::record::Experiment;
use super::rk4_step::{substeps_within, Rk4Step, FREQ_TOL};
use super::speed_table::{max_speed, oscillator_table, rk4_table, ForcePoint};
use super::sweep::{sweep, Sink};
use super::unknowns::{Columns, Theta};

/// How the model is discretised.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Discretisation {
    /// Exact discretisation when the speed is an analytic constant profile, else RK4 with
    /// the automatic number of sub-steps.
    #[default]
    Auto,
    /// Exact discretisation (matrix exponential); constant-speed profiles only.
    Exact,
    /// RK4 with `substeps` steps per sample interval (0: automatic, relative frequency
    /// error (w h)^4/120 <= 1e-9).
    Rk4 {
        /// Sub-steps per sample interval; 0 chooses automatically.
        substeps: usize,
    },
}

/// A discrete model ready to run at any parameters.
pub(crate) enum Discrete {
    Exact {
        omega: f64,
        dt: f64,
        osc: Vec<[f64; 2]>,
        /// Whether the exponentials are taken on the balanced state
        /// (`exact_step::balancing`; the adequacy verdict's fit).
        balanced: bool,
    },
    Rk4 {
        dt: f64,
        substeps: usize,
        table: Vec<ForcePoint>,
    },
}

impl Discrete {
    /// Tabulate the forcing for `exp`; `t` sets the automatic RK4 sub-step count.
    pub(crate) fn new(
        exp: &Experiment,
        discretisation: Discretisation,
        t: &Theta,
    ) -> Result<Self, RefineError> {
        Self::within(exp, discretisation, t, FREQ_TOL)
    }

    /// [`Discrete::new`] with the automatic RK4 sub-step count bounding the relative
    /// frequency error by `freq_tol` instead of `FREQ_TOL` (the adequacy verdict's fit:
    /// its model error need only be small against the record's noise).
    pub(crate) fn within(
        exp: &Experiment,
        discretisation: Discretisation,
        t: &Theta,
        freq_tol: f64,
    ) -> Result<Self, RefineError> {
        let constant = exp.speed.constant();
        match (discretisation, constant) {
            (Discretisation::Auto | Discretisation::Exact, Some((omega, phi0))) => {
                Ok(Discrete::Exact {
                    omega,
                    dt: exp.dt,
                    osc: oscillator_table(omega, phi0, exp.dt, exp.samples),
                    balanced: false,
                })
            }
            (Discretisation::Exact, None) => {
                Err(RefineError::ExactNeedsConstantSpeed(exp.speed.describe()))
            }
            (Discretisation::Auto, None) => Ok(Self::rk4(exp, 0, t, freq_tol)),
            (Discretisation::Rk4 { substeps }, _) => Ok(Self::rk4(exp, substeps, t, freq_tol)),
        }
    }

    fn rk4(exp: &Experiment, substeps: usize, t: &Theta, freq_tol: f64) -> Self {
        let substeps = if substeps == 0 {
            substeps_within(t, max_speed(exp), exp.dt, freq_tol)
        } else {
            substeps
        };
        Discrete::Rk4 {
            dt: exp.dt,
            substeps,
            table: rk4_table(exp, substeps),
        }
    }

    /// Run the model at `t` over the first `n_used` samples with the columns `cols`.
    pub(crate) fn run<K: Sink>(&self, t: &Theta, cols: &Columns, n_used: usize, sink: &mut K) {
        match self {
            Discrete::Exact {
                omega,
                dt,
                osc,
                balanced,
            } => {
                let st = ExactStep::new(t, cols, *omega, *dt, osc, *balanced);
                sweep(&st, t.y0, cols, n_used, sink);
            }
            Discrete::Rk4 {
                dt,
                substeps,
                table,
            } => {
                let st = Rk4Step::new(t, cols, *dt, *substeps, table);
                sweep(&st, t.y0, cols, n_used, sink);
            }
        }
    }

    /// The same model with its exact steps' exponentials taken on the balanced state
    /// (`exact_step::balancing`): as accurate, cheaper on long steps; its results differ
    /// from the plain ones at the rounding level, so refine and its bounds keep the plain
    /// ones (their outputs stay byte for byte) and the adequacy verdict's fit, on every
    /// `stride`-th sample, takes this.
    pub(crate) fn balanced(self) -> Self {
        match self {
            Discrete::Exact { omega, dt, osc, .. } => Discrete::Exact {
                omega,
                dt,
                osc,
                balanced: true,
            },
            rk4 => rk4,
        }
    }

    /// A one-line description for results.
    pub(crate) fn describe(&self) -> String {
        match self {
            Discrete::Exact { .. } => {
                "exact (matrix exponential of the state augmented with the forcing oscillator)"
                    .into()
            }
            Discrete::Rk4 { substeps, .. } => {
                format!("RK4 on state and sensitivities, {substeps} sub-step(s) per sample")
            }
        }
    }
}
