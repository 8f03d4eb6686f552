//! Simulation of finite-element rotors against independent references:
//! - the closed-form steady state against ROSS's own unbalance response;
//! - the exact constant-speed discretisation (closed-form particular + expm) against the
//!   closed form after the transient and against the Magnus integrator (augmented
//!   oscillator, a different construction) including the transient;
//! - Newmark converging at second order and Magnus at fourth order to independent
//!   references.

use nalgebra::Complex;
use rotorid::model::finite_element::{FeSystem, RitzBasis};
use rotorid::model::{Sampling, SpeedProfile};
use rotorid::simulate::finite_element::{
    simulate_fe, FeExactConstant, FeInitialState, FeIntegrator, FeMethod, FeResponse,
};

use crate::fe_common::{max_rel, probes, ross_rotor, ross_steady_state};

#[test]
fn closed_form_steady_state_equals_ross_unbalance_response() {
    let rotor = ross_rotor();
    let sys = FeSystem::full(&rotor);
    for (w, x) in ross_steady_state() {
        let q = sys.steady_state(w).unwrap();
        let amp = x.iter().fold(0.0f64, |m, z| m.max(z.norm()));
        let err = q
            .iter()
            .zip(x.iter())
            .fold(0.0f64, |m, (a, b)| m.max((a - b).norm()));
        eprintln!(
            "w = {w} rad/s: max |Q - X_ross| / max |X_ross| = {:.1e}",
            err / amp
        );
        assert!(err < 1e-9 * amp, "w = {w}: {:e}", err / amp);
    }
}

/// Every k-th sample of `r` (a finer record on the coarser grid).
fn every(r: &FeResponse, k: usize) -> FeResponse {
    let pick = |v: &Vec<f64>| v.iter().step_by(k).copied().collect();
    FeResponse {
        t: pick(&r.t),
        q: r.q.iter().map(pick).collect(),
        phi: pick(&r.phi),
        phi_dot: pick(&r.phi_dot),
        phi_ddot: pick(&r.phi_ddot),
        dofs: r.dofs.clone(),
    }
}

/// The response sampled by an integrator, every degree of freedom.
fn all_dofs(r: &FeResponse) -> usize {
    r.dofs.len()
}

#[test]
fn exact_constant_speed_response_settles_on_the_closed_form_1x_response() {
    let rotor = ross_rotor();
    let sys = FeSystem::full(&rotor);
    let w = 200.0;
    let speed = SpeedProfile::Constant {
        omega: w,
        phi0: 0.4,
    };
    // exact at any dt: 1 ms steps over 20 s (the slowest mode, 1.23 1/s, decays by 1e-9
    // in 17 s)
    let dt = 1e-3;
    let mut ex = FeExactConstant::new(&sys, &speed, dt, &FeInitialState::rest(44)).unwrap();
    for _ in 0..20_000 {
        ex.step().unwrap();
    }
    let q = sys.steady_state(w).unwrap();
    let e = Complex::from_polar(1.0, ex.speed().phi);
    let amp = q.iter().fold(0.0f64, |m, z| m.max(z.norm()));
    let err = ex
        .q()
        .iter()
        .zip(q.iter())
        .fold(0.0f64, |m, (a, z)| m.max((a - (z * e).re).abs()));
    eprintln!(
        "exact after 20 s: max |q - Re(Q e^(i phi))| / |Q| = {:.1e}",
        err / amp
    );
    assert!(err < 1e-9 * amp, "{:e}", err / amp);
    assert_eq!(ex.index(), 20_000);
}

#[test]
fn exact_and_magnus_agree_at_constant_speed_including_the_transient() {
    // two constructions: closed-form particular + expm of the 2n state matrix, and expm
    // of the (2n + 6) system augmented with the forcing oscillators
    let rotor = ross_rotor();
    let sys = FeSystem::full(&rotor);
    let sampling = Sampling::new(1e-4, 0.2).unwrap();
    for w in [150.0, 320.0] {
        let speed = SpeedProfile::Constant {
            omega: w,
            phi0: 1.0,
        };
        let a = simulate_fe(&sys, &speed, &sampling, None, None, FeMethod::Exact).unwrap();
        let b = simulate_fe(&sys, &speed, &sampling, None, None, FeMethod::Magnus).unwrap();
        assert_eq!(all_dofs(&a), 44);
        let d = max_rel(&a, &b);
        eprintln!("w = {w}: exact vs magnus max rel {d:.1e}");
        assert!(d < 1e-9, "w = {w}: {d:e}");
    }
}

#[test]
fn newmark_converges_at_second_order_to_the_exact_solution() {
    let rotor = ross_rotor();
    let sys = RitzBasis::new(&rotor, 8).unwrap().system(&rotor).unwrap();
    let speed = SpeedProfile::Constant {
        omega: 300.0,
        phi0: 0.0,
    };
    let out = probes();
    let exact = simulate_fe(
        &sys,
        &speed,
        &Sampling::new(1e-4, 0.1).unwrap(),
        None,
        Some(&out),
        FeMethod::Exact,
    )
    .unwrap();
    let mut errs = Vec::new();
    for k in [1usize, 2, 4] {
        let dt = 1e-4 / k as f64;
        let nm = simulate_fe(
            &sys,
            &speed,
            &Sampling::new(dt, 0.1).unwrap(),
            None,
            Some(&out),
            FeMethod::Newmark,
        )
        .unwrap();
        errs.push(max_rel(&exact, &every(&nm, k)));
    }
    eprintln!("newmark errors at dt = 1e-4, 5e-5, 2.5e-5: {errs:?}");
    for p in errs.windows(2) {
        let ratio = p[0] / p[1];
        assert!((3.6..4.4).contains(&ratio), "{errs:?}");
    }
}

#[test]
fn magnus_is_fourth_order_on_a_run_up_and_matches_extrapolated_newmark() {
    let rotor = ross_rotor();
    let sys = RitzBasis::new(&rotor, 8).unwrap().system(&rotor).unwrap();
    let speed = SpeedProfile::Ramp {
        omega0: 250.0,
        accel: 400.0,
        phi0: 0.2,
    };
    let out = probes();
    let run = |dt: f64, method| {
        simulate_fe(
            &sys,
            &speed,
            &Sampling::new(dt, 0.2).unwrap(),
            None,
            Some(&out),
            method,
        )
        .unwrap()
    };
    let fine = run(2.5e-5, FeMethod::Magnus);
    let e4 = max_rel(&every(&fine, 16), &run(4e-4, FeMethod::Magnus));
    let e2 = max_rel(&every(&fine, 8), &run(2e-4, FeMethod::Magnus));
    let e1 = max_rel(&every(&fine, 4), &run(1e-4, FeMethod::Magnus));
    eprintln!("magnus errors at dt = 4e-4, 2e-4, 1e-4: {e4:.2e} {e2:.2e} {e1:.2e}");
    assert!(e4 / e2 > 12.0 && e2 / e1 > 12.0, "{e4:e} {e2:e} {e1:e}");
    assert!(e1 < 1e-8, "{e1:e}");
    // independent: Newmark at dt/4 and dt/8 extrapolated (Richardson, error O(dt^4))
    let n4 = every(&run(2.5e-5, FeMethod::Newmark), 4);
    let n8 = every(&run(1.25e-5, FeMethod::Newmark), 8);
    let mut rich = n8.clone();
    for (c, (a, b)) in rich.q.iter_mut().zip(n4.q.iter().zip(&n8.q)) {
        for (x, (p, q)) in c.iter_mut().zip(a.iter().zip(b)) {
            *x = (4.0 * q - p) / 3.0;
        }
    }
    let m1 = run(1e-4, FeMethod::Magnus);
    let d = max_rel(&rich, &m1);
    eprintln!("magnus dt = 1e-4 vs extrapolated newmark: {d:.2e}");
    assert!(d < 1e-7, "{d:e}");
}

#[test]
fn bad_inputs_are_refused_naming_what_is_wrong() {
    let rotor = ross_rotor();
    let sys = FeSystem::full(&rotor);
    let sampling = Sampling::new(1e-4, 0.01).unwrap();
    let constant = SpeedProfile::Constant {
        omega: 100.0,
        phi0: 0.0,
    };
    let ramp = SpeedProfile::Ramp {
        omega0: 0.0,
        accel: 10.0,
        phi0: 0.0,
    };
    let e = simulate_fe(&sys, &ramp, &sampling, None, None, FeMethod::Exact).unwrap_err();
    assert!(
        e.to_string().starts_with("accel = 10 is out of range"),
        "{e}"
    );
    let bad: Vec<_> = vec!["11.x".parse().unwrap()];
    let e = simulate_fe(
        &sys,
        &constant,
        &sampling,
        None,
        Some(&bad),
        FeMethod::Magnus,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("11.x"), "{e}");
    let short = FeInitialState::rest(40);
    let e = simulate_fe(
        &sys,
        &constant,
        &sampling,
        Some(&short),
        None,
        FeMethod::Newmark,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("q0 has 40 entries") && e.contains("(44)"), "{e}");
    let mut nan = FeInitialState::rest(44);
    nan.v[13] = f64::NAN;
    let e = simulate_fe(
        &sys,
        &constant,
        &sampling,
        Some(&nan),
        None,
        FeMethod::Exact,
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("v0 at 3.y = NaN"), "{e}");
    let e = "rk4".parse::<FeMethod>().unwrap_err().to_string();
    assert!(e.contains("\"rk4\""), "{e}");
    for m in [FeMethod::Newmark, FeMethod::Exact, FeMethod::Magnus] {
        assert_eq!(m.to_string().parse::<FeMethod>().unwrap(), m);
    }
}

#[test]
fn response_table_names_its_columns_as_docs_formats_does() {
    let rotor = ross_rotor();
    let sys = RitzBasis::new(&rotor, 4).unwrap().system(&rotor).unwrap();
    let speed = SpeedProfile::Constant {
        omega: 100.0,
        phi0: 0.5,
    };
    let r = simulate_fe(
        &sys,
        &speed,
        &Sampling::new(1e-3, 0.01).unwrap(),
        None,
        Some(&probes()),
        FeMethod::Exact,
    )
    .unwrap();
    assert_eq!(
        r.header().join(","),
        "t,0.x,0.y,10.x,10.y,phi,phi_dot,phi_ddot"
    );
    assert_eq!(r.len(), 11);
    assert_eq!(r.t[7], 7.0 * 1e-3);
    assert_eq!(r.phi[0], 0.5);
    assert_eq!(r.q[0][0], 0.0);
}
