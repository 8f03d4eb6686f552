//! What a user should read before trusting the numbers: one typed diagnostic per finding,
//! each with a message that says what was found and what to do about it. Every caller
//! prints them the same way (the CLI as `warning: ...` lines, Python as `res.warnings`).

use serde::{Deserialize, Serialize};

use crate::refine::Warning;

/// x (horizontal) or z (vertical).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Direction {
    /// Horizontal.
    X,
    /// Vertical.
    Z,
}

impl Direction {
    /// `x` or `z`.
    pub fn name(self) -> &'static str {
        match self {
            Direction::X => "x",
            Direction::Z => "z",
        }
    }
}

/// One value per direction.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct Directions<T> {
    /// x (horizontal).
    pub x: T,
    /// z (vertical).
    pub z: T,
}

/// How much a diagnostic matters.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Severity {
    /// The numbers it concerns must not be relied on as they stand.
    Warning,
    /// Worth knowing; the numbers stand.
    Note,
}

/// What was found (the data of a [`Diagnostic`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Finding {
    /// The data carry no information on these quantities (alone or in combination).
    NotIdentifiable {
        /// Their names (parameters and initial-state components).
        quantities: Vec<String>,
    },
    /// The unknowns are so strongly correlated that the standard errors are unreliable.
    IllConditioned {
        /// Condition number of the scaled Fisher information.
        condition_number: f64,
        /// The limit it exceeds.
        limit: f64,
        /// The unknowns of the least informed direction (its near-null space), largest
        /// share first.
        #[serde(default)]
        quantities: Vec<String>,
    },
    /// A standard error above the value itself (or 1 rad for alpha).
    PoorlyDetermined {
        /// The quantity.
        quantity: String,
        /// Standard error over |value| (for alpha: the standard error, rad).
        relative_std_error: f64,
    },
    /// The fit stopped at its iteration limit.
    NotConverged {
        /// Model passes made.
        iterations: usize,
        /// Last Gauss-Newton step in standard errors.
        last_step: f64,
    },
    /// Constant speed and no significant free transient: only the steady state informs
    /// the fit.
    NoSignificantTransient {
        /// The transient's size in standard errors.
        significance: f64,
    },
    /// An estimate outside the model's physical range.
    Unphysical {
        /// The quantity.
        quantity: String,
        /// Its value.
        value: f64,
    },
    /// A direction of the modulating least squares is ill-conditioned; its m, c, k are
    /// withheld.
    DirectionIllConditioned {
        /// The direction.
        direction: Direction,
        /// Its reciprocal condition number.
        rcond: f64,
        /// The threshold.
        rcond_min: f64,
    },
    /// A direction of the modulating least squares is singular; its m, c, k are withheld.
    DirectionSingular {
        /// The direction.
        direction: Direction,
    },
    /// A stream's grid, fitted over its first stamps, differs from the fit of all of them
    /// by more than 1e-6 dt: the estimates are biased by about twice that.
    TimeGridDrift {
        /// The period used \[s\].
        dt_used_s: f64,
        /// The period of all stamps \[s\].
        dt_all_s: f64,
        /// Stamps the used period was fitted over.
        fitted_over: usize,
        /// All stamps.
        samples: usize,
    },
    /// The model does not explain a channel of the record (see `adequacy`): its residuals
    /// are not white or exceed the data's noise level. The values are withheld.
    ModelInadequate {
        /// The channel.
        direction: Direction,
        /// Ljung-Box p-value of the residuals.
        ljung_box_p: f64,
        /// Lag-1 autocorrelation of the residuals.
        lag1_autocorrelation: f64,
        /// Residual level over the data's noise level.
        noise_ratio: f64,
        /// The residual's dominant frequency \[Hz\].
        dominant_frequency_hz: Option<f64>,
    },
    /// A channel whose residuals fail the adequacy tests but stay below 1e-4 of the
    /// signal's RMS (see `adequacy`): a record almost without noise, its values kept (a
    /// note).
    SmallResidual {
        /// The channel.
        direction: Direction,
        /// Residual RMS over the signal's RMS.
        relative_residual: f64,
        /// Residual RMS \[m\].
        residual_sigma_m: f64,
        /// The data's white-noise level from its fourth differences \[m\].
        noise_sigma_m: f64,
    },
    /// An estimate outside the model's physical range (m or k <= 0, c < 0): withheld.
    NotPhysical {
        /// The parameter.
        parameter: crate::Parameter,
        /// Its estimate \[its unit\].
        value: f64,
    },
    /// Algebraic estimates that settle only late in the record, never, or outside the
    /// physical range: the identifier's integrals amplify noise as the record grows.
    AlgebraicUnsettled {
        /// The parameters concerned.
        parameters: Vec<crate::Parameter>,
    },
    /// Many instants of the algebraic identifier are ill-conditioned: without restarts its
    /// 3x3 systems degrade as the record grows.
    AlgebraicIllConditioned {
        /// The direction.
        direction: Direction,
        /// Flagged instants over all instants.
        fraction: f64,
        /// The threshold.
        rcond_min: f64,
        /// Whether the integrals were restarted (restart_s).
        restarted: bool,
    },
    /// A speed column is not the derivative of the one before it (module `consistency`):
    /// a unit slip. The values are withheld.
    SpeedInconsistent {
        /// `phi_dot` or `phi_ddot`.
        column: String,
        /// The column over its reference, least squares over the record.
        factor: f64,
        /// `d(phi)/dt` or `d(phi_dot)/dt`.
        reference: String,
    },
    /// The data's phi_dot differs from the given speed profile (the scenario's `[speed]`)
    /// by more than 1 %: one of them is in other units or describes another run.
    SpeedDiffersFromProfile {
        /// phi_dot over the profile's speed, least squares over the record.
        factor: f64,
    },
    /// A displacement channel peaks outside what a proximity probe measures (module
    /// `plausibility`): a unit slip?
    ImplausibleDisplacement {
        /// The channel.
        direction: Direction,
        /// Its largest |value| \[m\].
        peak_m: f64,
    },
    /// The white-noise level of a channel is a large part of its RMS.
    NoiseDominates {
        /// The channel.
        direction: Direction,
        /// Noise level from fourth differences \[m\].
        noise_m: f64,
        /// The channel's RMS about its mean \[m\].
        rms_m: f64,
    },
    /// The Cramer-Rao bound could not be computed.
    CrbUnavailable {
        /// Why.
        reason: String,
    },
    /// Time stamps off the fitted grid by more than the time tolerance, within the
    /// rounding of the decimals they are printed with (module `grid`): accepted (a note).
    TimeStampsRounded {
        /// One unit of the stamps' last decimal \[s\].
        resolution_s: f64,
        /// The largest deviation of a stamp from the fitted grid \[s\].
        max_deviation_s: f64,
        /// The fitted sampling period \[s\].
        dt_s: f64,
    },
    /// `--model auto` chose this model (the summary's `model_selection` has the figures).
    ModelSelected {
        /// The model taken.
        model: crate::parameter::ModelKind,
        /// Why, in words.
        reason: String,
    },
    /// The model fitted leaves structure in its residuals that another model explains.
    OtherModelExplains {
        /// The model whose residuals pass the adequacy test.
        model: crate::parameter::ModelKind,
        /// BIC of the fitted model minus that of the other (positive: the other is
        /// better).
        bic_difference: f64,
    },
}

/// A finding with its severity and message (module doc).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Diagnostic {
    /// What was found.
    #[serde(flatten)]
    pub finding: Finding,
    /// How much it matters.
    pub severity: Severity,
    /// One sentence: what, and what to do about it.
    pub message: String,
}

impl Diagnostic {
    /// The diagnostic of one of the pipeline's own findings, with its message.
    pub(crate) fn new(finding: Finding) -> Self {
        let message = message(&finding);
        Self {
            finding,
            severity: Severity::Warning,
            message,
        }
    }

    /// A finding worth knowing that leaves the numbers standing ([`Severity::Note`]).
    pub(crate) fn note(finding: Finding) -> Self {
        Self {
            severity: Severity::Note,
            ..Self::new(finding)
        }
    }

    /// True for findings that say the data cannot separate the unknowns.
    pub fn inseparable(&self) -> bool {
        matches!(
            self.finding,
            Finding::NotIdentifiable { .. } | Finding::IllConditioned { .. }
        )
    }

    /// True for findings after which no value may be reported (wrong inputs).
    pub fn withholds_all(&self) -> bool {
        matches!(self.finding, Finding::SpeedInconsistent { .. })
    }
}

impl std::fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl From<&Warning> for Diagnostic {
    fn from(w: &Warning) -> Self {
        let finding = match w {
            Warning::NotIdentifiable { parameters, .. } => Finding::NotIdentifiable {
                quantities: parameters.iter().map(|s| (*s).to_owned()).collect(),
            },
            Warning::IllConditioned {
                condition_number,
                limit,
                parameters,
            } => Finding::IllConditioned {
                condition_number: *condition_number,
                limit: *limit,
                quantities: parameters.iter().map(|s| (*s).to_owned()).collect(),
            },
            Warning::PoorlyDetermined {
                parameter,
                relative_std_error,
            } => Finding::PoorlyDetermined {
                quantity: (*parameter).to_owned(),
                relative_std_error: *relative_std_error,
            },
            Warning::NotConverged {
                iterations,
                last_step,
            } => Finding::NotConverged {
                iterations: *iterations,
                last_step: *last_step,
            },
            Warning::NoSignificantTransient { significance } => Finding::NoSignificantTransient {
                significance: *significance,
            },
            Warning::Unphysical { parameter, value } => Finding::Unphysical {
                quantity: (*parameter).to_owned(),
                value: *value,
            },
        };
        Self {
            finding,
            severity: Severity::Warning,
            message: w.to_string(),
        }
    }
}

fn message(f: &Finding) -> String {
    match f {
        Finding::DirectionIllConditioned {
            direction,
            rcond,
            rcond_min,
        } => format!(
            "the {} direction is ill-conditioned (rcond {rcond:.2e} < rcond_min {rcond_min:e}): \
             its m, c, k are withheld",
            direction.name()
        ),
        Finding::DirectionSingular { direction } => format!(
            "the {} direction is singular (the least squares has no unique solution, or the \
             noise compensation exceeds the information in the data): its m, c, k are withheld",
            direction.name()
        ),
        Finding::TimeGridDrift {
            dt_used_s,
            dt_all_s,
            fitted_over,
            samples,
        } => format!(
            "the sampling period fitted over the first {fitted_over} time stamps, {dt_used_s:e} s, \
             differs from that of all {samples}, {dt_all_s:e} s, by {:.1e} (relative): the \
             estimates are biased by about twice that; identify the whole record as a file \
             (its grid is fitted over every stamp) or give the sampling period",
            (dt_all_s - dt_used_s).abs() / dt_used_s
        ),
        Finding::ModelInadequate {
            direction,
            ljung_box_p,
            lag1_autocorrelation,
            noise_ratio,
            dominant_frequency_hz,
        } => format!(
            "MODEL INADEQUATE for {}: the fit leaves structure in its residuals (Ljung-Box \
             p = {ljung_box_p:.1e} over {} lags, lag-1 autocorrelation {lag1_autocorrelation:.2}; \
             residual {noise_ratio:.2}x the noise level of the data{}): a nonlinear support, \
             an unmodelled mode or a wrong speed signal? The standard errors assume a correct \
             model, so every value is withheld (the raw numbers stay in `estimate`)",
            direction.name(),
            crate::residual::LJUNG_BOX_LAGS,
            dominant_frequency_hz.map_or(String::new(), |f| format!(
                "; dominant residual frequency {f:.1} Hz"
            ))
        ),
        Finding::SmallResidual {
            direction,
            relative_residual,
            residual_sigma_m,
            noise_sigma_m,
        } => format!(
            "{}: the model reproduces the record to {relative_residual:.1e} of its RMS \
             (residual {residual_sigma_m:.2e} m), though {:.0}x the data's noise level \
             ({noise_sigma_m:.1e} m): a record almost without noise (a simulation, or a \
             file's rounding). The values are kept: the test rules out any unmodelled effect \
             above about {relative_residual:.0e} of the signal, but without noise to compare \
             with it cannot tell a smaller one from the record's own numerical error (an \
             integrator's period error, rounding), and no standard error covers that residual",
            direction.name(),
            residual_sigma_m / noise_sigma_m,
        ),
        Finding::NotPhysical { parameter, value } => format!(
            "{parameter} = {value:.4e} {} is not physical (m and k must be > 0, c >= 0): \
             withheld",
            parameter.unit()
        ),
        Finding::AlgebraicUnsettled { parameters } => format!(
            "the algebraic estimates of {} never settled in the first half of the record (or \
             are not physical): its iterated integrals amplify noise as the record grows, so \
             on noisy data its late values are noise; use --method modulating or refine",
            parameters
                .iter()
                .map(|p| p.name())
                .collect::<Vec<_>>()
                .join(", ")
        ),
        Finding::AlgebraicIllConditioned {
            direction,
            fraction,
            rcond_min,
            restarted,
        } => {
            format!(
            "{:.0}% of the algebraic estimates of the {} direction are ill-conditioned (rcond < \
             {rcond_min:e}) and withheld: the data {} do not separate m, c and k (a steady \
             state at one speed, or far above a critical speed, cannot); {}",
            100.0 * fraction,
            direction.name(),
            if *restarted { "in those windows" } else { "there" },
            if *restarted {
                "use --method modulating or refine, which weigh the whole record"
            } else {
                "a single identifier's integrals also degrade as the record grows: restart \
                 them on a schedule (restart_s, --restart SECONDS) or use --method modulating \
                 or refine"
            }
        )
        }
        Finding::SpeedInconsistent {
            column,
            factor,
            reference,
        } => format!(
            "{column} is {factor:.4}x {reference}{}: the speed columns must be phi [rad], \
             phi_dot [rad/s], phi_ddot [rad/s^2]; every value is withheld",
            super::limits::unit_slip_hint(*factor)
        ),
        Finding::SpeedDiffersFromProfile { factor } => format!(
            "the data's phi_dot is {factor:.4}x the speed of the scenario's [speed] profile{}: \
             the identification used the data's columns; check the units of phi_dot or the \
             scenario",
            super::limits::unit_slip_hint(*factor)
        ),
        Finding::ImplausibleDisplacement { direction, peak_m } => {
            let d = direction.name();
            if *peak_m > super::limits::DISPLACEMENT_MAX_M {
                format!(
                    "{d} reaches {peak_m:.3e} m, more than a proximity probe measures (about \
                     2 mm): values in um or mm read as metres? Give the unit in the header \
                     ({d} [um]) or convert to metres"
                )
            } else {
                format!(
                    "{d} never exceeds {peak_m:.3e} m, below any probe's resolution (about \
                     0.1 um): metres labelled as um, or a dead channel?"
                )
            }
        }
        Finding::NoiseDominates {
            direction,
            noise_m,
            rms_m,
        } => format!(
            "the white-noise level of {} ({noise_m:.3e} m) is {:.0}% of its RMS ({rms_m:.3e} m): \
             the record is mostly noise, or the channel is not the shaft's displacement; \
             trust only values with small standard errors",
            direction.name(),
            100.0 * noise_m / rms_m
        ),
        Finding::CrbUnavailable { reason } => {
            format!("the Cramer-Rao bound was not computed: {reason}")
        }
        Finding::TimeStampsRounded {
            resolution_s,
            max_deviation_s,
            dt_s,
        } => format!(
            "the time stamps are printed to {resolution_s:e} s: they are up to \
             {max_deviation_s:.2e} s ({:.3} dt) off the uniform grid fitted over all of them \
             (dt = {dt_s:e} s), which that rounding explains; the identification uses the \
             grid",
            max_deviation_s / dt_s
        ),
        Finding::ModelSelected { model, reason } => {
            format!("model {model} (chosen by --model auto): {reason}")
        }
        Finding::OtherModelExplains {
            model,
            bic_difference,
        } => format!(
            "{} explain these data: the {model} model's residuals pass the adequacy test (BIC \
             lower by {bic_difference:.1}); identify with --model {model} or --model auto",
            match model {
                crate::parameter::ModelKind::CrossCoupled => "cross-coupled bearings",
                crate::parameter::ModelKind::Jeffcott => "a Jeffcott rotor",
            }
        ),
        // The refinement's findings are made from its warnings (`From<&Warning>`), which
        // carry their own sentences; this is only their fallback.
        other => format!("{other:?}"),
    }
}
