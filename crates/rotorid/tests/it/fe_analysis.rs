//! `fe_analysis` of the ROSS two-disk rotor WITH its proportional shaft damping C (the
//! fixture's): its high modes are overdamped pairs that rounding and the gyroscopic coupling
//! give tiny imaginary parts. Followed as modes, they crowded the candidates and produced
//! critical speeds near 0 rpm with log decrements of 1e10; the modes are now the
//! eigenvalues damped below `MAX_DAMPING_RATIO`. Checked against ROSS's own natural
//! frequencies at rest (`wn_at_rest` of the fixture, ross-rotordynamics 3.1.0, |lambda| of
//! its lowest modes) and the critical speeds against those of the same rotor without C.

use std::sync::Arc;

use rotorid::analysis::{fe_analysis, FeAnalysis, MAX_DAMPING_RATIO};
use rotorid::model::finite_element::{FeMatrices, FiniteElementRotor};

use crate::fe_common::{fixture, ross_rotor};

#[test]
fn the_modes_of_a_rotor_with_shaft_damping_are_rosss_and_no_overdamped_pair_is_followed() {
    let rotor = ross_rotor();
    let speeds: Vec<f64> = (0..=120).map(|i| i as f64 * 10.0).collect(); // 0 .. 1200 rad/s
    let a = fe_analysis(&rotor, None, &speeds, 6).unwrap();
    let wn: Vec<f64> = serde_json::from_value(fixture()["wn_at_rest"].clone()).unwrap();
    let at_rest: Vec<f64> = (0..6)
        .map(|j| a.campbell.modes[0][j].natural_frequency)
        .collect();
    println!("at rest: {at_rest:?}\nROSS:    {wn:?}");
    for (j, (got, want)) in at_rest.iter().zip(&wn).enumerate() {
        assert!(
            (got / want - 1.0).abs() < 1e-6,
            "mode {j}: {got} vs ROSS {want}"
        );
    }
    for row in &a.campbell.modes {
        for m in row {
            assert!(m.damping_ratio < MAX_DAMPING_RATIO, "{m:?}");
        }
    }
    // without C: the same rotor's critical speeds (light proportional damping moves them by
    // well under 1 %)
    let m = &rotor.matrices;
    let no_c = FiniteElementRotor::new(
        Arc::new(
            FeMatrices::new(
                m.dofs().to_vec(),
                m.m().clone(),
                m.k().clone(),
                m.g().clone(),
                None,
                m.ka().cloned(),
            )
            .unwrap(),
        ),
        rotor.bearings.clone(),
        rotor.unbalances.clone(),
    )
    .unwrap();
    let b = fe_analysis(&no_c, None, &speeds, 6).unwrap();
    let crit = |x: &FeAnalysis| -> Vec<f64> { x.critical.iter().map(|c| c.speed).collect() };
    let (with, without) = (crit(&a), crit(&b));
    println!("critical speeds with C {with:?}\nwithout C {without:?}");
    assert!(with.iter().all(|&w| w > 100.0), "{with:?}");
    assert_eq!(with.len(), without.len(), "{with:?} vs {without:?}");
    for (x, y) in with.iter().zip(&without) {
        assert!((x / y - 1.0).abs() < 0.01, "{x} vs {y}");
    }
}
