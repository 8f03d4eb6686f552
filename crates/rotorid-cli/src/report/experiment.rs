//! The paper's numerical experiments (Barredo et al. 2024, section "Resultados"), run in
//! two settings.
//!
//! Cases (table1 rotor, paper Table 1; dt = 0.1 ms):
//! - constant speed, 1200 rpm, phi(0) = 0 (paper figs. 2-5; identifier eqs. 2-8, the
//!   constant-speed form of docs/method.md section 3.3);
//! - linear ramp w(t) = w0 + 10 t rad/s from rest, w0 = 0 (paper figs. 6-9; the paper does
//!   not state w0; general identifier of docs/method.md section 3.3).
//!
//! Settings:
//! - "paper": response by average-acceleration Newmark, iterated integrals by the
//!   cumulative trapezoid rule (what the paper's transients point to,
//!   docs/method.md section 3.5);
//! - "ours": response by exact discretisation (constant speed) or DOP853 at tight
//!   tolerance (ramp), integrals by the identifier's default (5th-order Adams-Moulton);
//! - and, to attribute the paper's error to its data or to its rule, the two cross
//!   combinations: Newmark data with the default rule, exact data with the trapezoid rule.
//!
//! Each run is `simulate(scenario, method)` then `identify_response(response, known,
//! config)`: one estimate theta(t) = (m, c, k) per direction and sample, with its rcond.

use anyhow::Context;
use rotorid::identify::algebraic::{
    identify_response, AlgebraicConfig, AlgebraicEstimate, Quadrature,
};
use rotorid::identify::Known;
use rotorid::simulate::{simulate, Method, TimeResponse};
use rotorid::{Sampling, Scenario, SpeedProfile};

/// The paper's sampling period [s] (0.1 ms).
pub const PAPER_DT: f64 = 1.0e-4;
/// The ramp's angular acceleration [rad/s^2].
pub const RAMP_ACCEL: f64 = 10.0;
/// The constant speed [rev/min].
pub const CONSTANT_RPM: f64 = 1200.0;

/// A speed case of the paper.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Case {
    /// 1200 rpm, constant.
    Constant,
    /// 10 rad/s^2 from rest.
    Ramp,
}

impl Case {
    /// Both, in the paper's order.
    pub const ALL: [Case; 2] = [Case::Constant, Case::Ramp];

    /// Short name used in files and JSON: `constant`, `ramp`.
    pub fn name(self) -> &'static str {
        match self {
            Case::Constant => "constant",
            Case::Ramp => "ramp",
        }
    }

    /// Human description.
    pub fn describe(self) -> &'static str {
        match self {
            Case::Constant => "constant speed 1200 rpm",
            Case::Ramp => "linear ramp 10 rad/s\u{b2} from rest",
        }
    }

    /// The table1 scenario of this case over `duration` seconds at [`PAPER_DT`].
    pub fn scenario(self, duration: f64) -> anyhow::Result<Scenario> {
        let speed = match self {
            Case::Constant => SpeedProfile::constant_rpm(CONSTANT_RPM, 0.0)?,
            Case::Ramp => SpeedProfile::ramp(0.0, RAMP_ACCEL, 0.0)?,
        };
        Ok(Scenario {
            speed,
            sampling: Sampling::new(PAPER_DT, duration)
                .with_context(|| format!("--duration {duration}"))?,
            ..Scenario::table1()
        })
    }

    /// Paper's reported identification time for `symbol` (m, c or k) [s]: constant speed
    /// "< 0.2 s" for all; ramp "< 0.1 s" for m and k and "< 0.28 s" for c.
    pub fn paper_time(self, symbol: &str) -> f64 {
        match (self, symbol) {
            (Case::Constant, _) => 0.2,
            (Case::Ramp, "c") => 0.28,
            (Case::Ramp, _) => 0.1,
        }
    }
}

/// How the data are made and integrated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Setting {
    /// Newmark data, trapezoid integrals (as the paper).
    Paper,
    /// Exact data, default (5th-order) quadrature.
    Ours,
    /// Newmark data, default quadrature (attribution: the data's share of the error).
    NewmarkData,
    /// Exact data, trapezoid integrals (attribution: the rule's share of the error).
    TrapezoidRule,
}

impl Setting {
    /// The two settings of the figures and tables, paper first.
    pub const ALL: [Setting; 2] = [Setting::Paper, Setting::Ours];
    /// The four combinations of data (Newmark, exact) and rule (trapezoid, default).
    pub const COMBINATIONS: [Setting; 4] = [
        Setting::Paper,
        Setting::TrapezoidRule,
        Setting::NewmarkData,
        Setting::Ours,
    ];

    /// Short name: `paper`, `ours`, `newmark-data`, `trapezoid-rule`.
    pub fn name(self) -> &'static str {
        match self {
            Setting::Paper => "paper",
            Setting::Ours => "ours",
            Setting::NewmarkData => "newmark-data",
            Setting::TrapezoidRule => "trapezoid-rule",
        }
    }

    /// The simulation method.
    pub fn method(self) -> Method {
        match self {
            Setting::Paper | Setting::NewmarkData => Method::Newmark,
            Setting::Ours | Setting::TrapezoidRule => Method::Exact,
        }
    }

    /// The quadrature rule of the iterated integrals.
    pub fn quadrature(self) -> Quadrature {
        match self {
            Setting::Paper | Setting::TrapezoidRule => Quadrature::Trapezoid,
            Setting::Ours | Setting::NewmarkData => Quadrature::default(),
        }
    }

    /// Human description, e.g. for a panel caption.
    pub fn describe(self) -> String {
        let rule = |q: Quadrature| match q {
            Quadrature::Trapezoid => "trapezoid integrals".to_string(),
            q => format!("{} integrals (order {})", q.name(), q.order()),
        };
        let data = match self.method() {
            Method::Newmark => "Newmark data",
            Method::Exact => "exact data",
        };
        let who = match self {
            Setting::Paper => "paper's setting: ",
            Setting::Ours => "ours: ",
            _ => "",
        };
        format!("{who}{data}, {}", rule(self.quadrature()))
    }

    /// The identifier configuration for `scenario` (the constant-speed identifier at
    /// constant speed, the general one otherwise).
    pub fn config(self, scenario: &Scenario) -> anyhow::Result<AlgebraicConfig> {
        let base = match scenario.speed {
            SpeedProfile::Constant { omega, phi0 } => AlgebraicConfig::constant_speed(omega, phi0)?,
            _ => AlgebraicConfig::default(),
        };
        Ok(AlgebraicConfig {
            quadrature: self.quadrature(),
            ..base
        })
    }
}

/// One simulated and identified record.
#[derive(Debug, Clone)]
pub struct Run {
    /// Which speed case.
    pub case: Case,
    /// Which setting.
    pub setting: Setting,
    /// The scenario simulated (its rotor holds the true values).
    pub scenario: Scenario,
    /// The identifier's settings.
    pub config: AlgebraicConfig,
    /// The simulated response (t [s], x, z [m], phi [rad], w [rad/s], w' [rad/s^2]).
    pub response: TimeResponse,
    /// One estimate per sample.
    pub estimates: Vec<AlgebraicEstimate>,
}

/// Simulate and identify `case` in `setting` over `duration` seconds.
pub fn run(case: Case, setting: Setting, duration: f64) -> anyhow::Result<Run> {
    let scenario = case.scenario(duration)?;
    let response = simulate(&scenario, setting.method())
        .with_context(|| format!("simulating the {} case ({})", case.name(), setting.method()))?;
    let config = setting.config(&scenario)?;
    let estimates = identify_response(&response, Known::from_rotor(&scenario.rotor), config)
        .with_context(|| {
            format!(
                "identifying the {} case ({} setting)",
                case.name(),
                setting.name()
            )
        })?;
    Ok(Run {
        case,
        setting,
        scenario,
        config,
        response,
        estimates,
    })
}
