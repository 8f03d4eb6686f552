//! Accuracy of refine's discrete model against the simulate::Exact reference: the model
//! error must be far below the noise (relative Cramer-Rao bound ~4e-5 for m at 40 dB).

use rotorid::model::{InitialState, Rotor, Sampling, Scenario, SpeedProfile};
use rotorid::refine::{model_response, Discretisation, Experiment, SpeedData};
use rotorid::simulate::{simulate, Method};

fn max_abs(v: &[f64]) -> f64 {
    v.iter().fold(0.0, |a, b| a.max(b.abs()))
}

/// max |model - reference| / max |reference| over both channels.
fn rel_err(a: (&[f64], &[f64]), b: (&[f64], &[f64])) -> f64 {
    let ex =
        a.0.iter()
            .zip(b.0)
            .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
    let ez =
        a.1.iter()
            .zip(b.1)
            .fold(0.0f64, |m, (p, q)| m.max((p - q).abs()));
    ex.max(ez) / max_abs(b.0).max(max_abs(b.1))
}

fn scenario_with_initial(s: Scenario) -> Scenario {
    Scenario {
        initial: InitialState {
            x: 2e-7,
            z: -1e-7,
            vx: 3e-5,
            vz: 1e-5,
        },
        ..s
    }
}

#[test]
fn exact_discretisation_matches_the_reference_at_constant_speed() {
    let s = scenario_with_initial(Scenario::table1());
    let reference = simulate(&s, Method::Exact).unwrap();
    let exp = Experiment::from_scenario(&s);
    let m = model_response(&s.rotor.params(), &s.initial, &exp, Discretisation::Auto).unwrap();
    assert!(m.discretisation.starts_with("exact"));
    let e = rel_err((&m.x, &m.z), (&reference.x, &reference.z));
    println!("exact vs simulate::Exact, 1200 rpm, 1 s: {e:.2e}");
    assert!(e < 1e-10, "{e:e}");
}

#[test]
fn rk4_matches_the_reference_on_a_ramp() {
    for rpm0 in [0.0, 600.0] {
        let s = scenario_with_initial(Scenario::table1_ramp(rpm0).unwrap());
        let reference = simulate(&s, Method::Exact).unwrap();
        let exp = Experiment::from_scenario(&s);
        let p = s.rotor.params();
        let auto = model_response(&p, &s.initial, &exp, Discretisation::Auto).unwrap();
        let e_auto = rel_err((&auto.x, &auto.z), (&reference.x, &reference.z));
        let one =
            model_response(&p, &s.initial, &exp, Discretisation::Rk4 { substeps: 1 }).unwrap();
        let e_one = rel_err((&one.x, &one.z), (&reference.x, &reference.z));
        println!(
            "ramp from {rpm0} rpm, 1 s: {} -> {e_auto:.2e}; 1 sub-step -> {e_one:.2e}",
            auto.discretisation
        );
        assert!(auto.discretisation.contains("2 sub-step"));
        // The relative frequency error (w h)^4/120 ~ 4e-10 accumulates over w T ~ 290 rad
        // of phase: ~1e-7 of the amplitude at the end. RK4 error ~ h^4: halving h gains ~16.
        assert!(e_auto < 1e-7, "{e_auto:e}");
        assert!(e_one > 10.0 * e_auto && e_one < 2e-6, "{e_one:e}");
    }
}

#[test]
fn rk4_and_exact_agree_at_constant_speed() {
    let s = scenario_with_initial(Scenario::table1());
    let exp = Experiment::from_scenario(&s);
    let p = s.rotor.params();
    let exact = model_response(&p, &s.initial, &exp, Discretisation::Exact).unwrap();
    let rk4 = model_response(&p, &s.initial, &exp, Discretisation::Rk4 { substeps: 0 }).unwrap();
    let e = rel_err((&rk4.x, &rk4.z), (&exact.x, &exact.z));
    println!("RK4 (auto) vs exact at 1200 rpm: {e:.2e}");
    assert!(e < 1e-7, "{e:e}");
}

#[test]
fn measured_speed_samples_give_the_profile_response() {
    // Per-sample phi, w, w' (wrapped to [0, 2 pi)) through the Hermite interpolation
    // reproduce the analytic ramp exactly (phi is quadratic).
    let s = Scenario::table1_ramp(600.0).unwrap();
    let exp = Experiment::from_scenario(&s);
    let n = exp.samples;
    let st: Vec<_> = (0..n).map(|i| s.speed.at(s.sampling.time(i))).collect();
    let phi: Vec<f64> = st
        .iter()
        .map(|v| v.phi.rem_euclid(std::f64::consts::TAU))
        .collect();
    let w: Vec<f64> = st.iter().map(|v| v.omega).collect();
    let wd: Vec<f64> = st.iter().map(|v| v.omega_dot).collect();
    let sampled = Experiment {
        speed: SpeedData::Samples {
            phi: &phi,
            omega: &w,
            omega_dot: &wd,
        },
        ..exp
    };
    let p = s.rotor.params();
    let a = model_response(&p, &s.initial, &exp, Discretisation::Auto).unwrap();
    let b = model_response(&p, &s.initial, &sampled, Discretisation::Auto).unwrap();
    let e = rel_err((&b.x, &b.z), (&a.x, &a.z));
    assert!(e < 1e-10, "{e:e}");
}

#[test]
fn exact_is_refused_for_a_ramp() {
    let s = Scenario::table1_ramp(600.0).unwrap();
    let exp = Experiment::from_scenario(&s);
    let e = model_response(&s.rotor.params(), &s.initial, &exp, Discretisation::Exact).unwrap_err();
    assert!(e.to_string().contains("constant speed"), "{e}");
}

#[test]
fn coarse_sampling_uses_more_substeps_and_stays_accurate() {
    // 1 kHz sampling: RK4 needs ~20 sub-steps per sample; compare with the exact model.
    let s = Scenario {
        sampling: Sampling::new(1e-3, 0.5).unwrap(),
        speed: SpeedProfile::constant_rpm(1200.0, 0.3).unwrap(),
        rotor: Rotor::table1(),
        ..scenario_with_initial(Scenario::table1())
    };
    let exp = Experiment::from_scenario(&s);
    let p = s.rotor.params();
    let exact = model_response(&p, &s.initial, &exp, Discretisation::Exact).unwrap();
    let rk4 = model_response(&p, &s.initial, &exp, Discretisation::Rk4 { substeps: 0 }).unwrap();
    let e = rel_err((&rk4.x, &rk4.z), (&exact.x, &exact.z));
    println!("{} at 1 kHz: {e:.2e}", rk4.discretisation);
    assert!(rk4.discretisation.contains("17 sub-step"));
    assert!(e < 1e-7, "{e:e}");
}
