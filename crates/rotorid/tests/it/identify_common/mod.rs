//! Shared helpers of the identify_* integration tests.
#![allow(dead_code)]

use rotorid::identify::algebraic::{
    identify_response, AlgebraicConfig, AlgebraicEstimate, Quadrature,
};
use rotorid::identify::Known;
use rotorid::simulate::{simulate, Method, TimeResponse};
use rotorid::Parameter;
use rotorid::{InitialState, Sampling, Scenario};

/// The six true values in [`Parameter::ALL`] order.
pub fn truth(sc: &Scenario) -> [f64; 6] {
    let r = &sc.rotor;
    [r.m(), r.cx(), r.kx(), r.m(), r.cz(), r.kz()]
}

/// Relative errors of the six estimates.
pub fn rel_errors(e: &AlgebraicEstimate, truth: &[f64; 6]) -> [f64; 6] {
    let v = e.values();
    std::array::from_fn(|i| (v[i] - truth[i]) / truth[i])
}

/// The three table1 cases of the accuracy tests, `duration` s long at dt = 0.1 ms.
pub fn table1_cases(duration: f64) -> Vec<(&'static str, Scenario)> {
    let sampling = Sampling::new(1e-4, duration).unwrap();
    let mut cases = vec![
        ("1200 rpm", Scenario::table1()),
        ("ramp from rest", Scenario::table1_ramp(0.0).unwrap()),
        ("ramp from 1200 rpm", Scenario::table1_ramp(1200.0).unwrap()),
    ];
    for (_, sc) in &mut cases {
        sc.sampling = sampling;
    }
    cases
}

/// Non-zero initial displacement and velocity (the identifier must not depend on them).
pub fn with_initial_conditions(mut sc: Scenario) -> Scenario {
    sc.initial = InitialState {
        x: 2e-7,
        z: -1e-7,
        vx: 1e-4,
        vz: 5e-5,
    };
    sc
}

pub fn response(sc: &Scenario, method: Method) -> TimeResponse {
    simulate(sc, method).expect("simulation")
}

pub fn estimates(
    sc: &Scenario,
    resp: &TimeResponse,
    quadrature: Quadrature,
) -> Vec<AlgebraicEstimate> {
    let config = AlgebraicConfig {
        quadrature,
        ..AlgebraicConfig::default()
    };
    identify_response(resp, Known::from_rotor(&sc.rotor), config).expect("identification")
}

/// The estimate at time `t` (sample index round(t / dt)).
pub fn at(est: &[AlgebraicEstimate], dt: f64, t: f64) -> &AlgebraicEstimate {
    &est[(t / dt).round() as usize]
}

pub fn names() -> [&'static str; 6] {
    Parameter::PER_DIRECTION.map(Parameter::name)
}
