//! Clean data (simulate::Exact, accurate to ~1e-10): the fit recovers the truth from a
//! start 1 % off, to ~1e-8 (the discrete model's own error: zero at constant speed, RK4's
//! ~1e-9 frequency error on ramps).

use rotorid::model::{InitialState, RotorParams, Scenario};
use rotorid::refine::{refine, Record, RefineOptions, Unknowns, Warning};
use rotorid::simulate::{simulate, Method};

/// m, c, k each 1 % off (alternating signs).
fn perturbed(p: &RotorParams, frac: f64) -> RotorParams {
    RotorParams {
        m: p.m * (1.0 + frac),
        cx: p.cx * (1.0 - frac),
        kx: p.kx * (1.0 - frac),
        cz: p.cz * (1.0 + frac),
        kz: p.kz * (1.0 + frac),
        ..*p
    }
}

/// Fit and return the worst relative error over (m, k, a, mud, alpha) and over (cx, cz).
fn fit(label: &str, s: &Scenario, unknowns: Unknowns, start: &RotorParams) -> (f64, f64) {
    let resp = simulate(s, Method::Exact).unwrap();
    let rec = Record::from_simulation(s, &resp);
    let opts = RefineOptions {
        unknowns,
        ..RefineOptions::default()
    };
    let r = refine(&rec, start, &InitialState::default(), &opts).unwrap();
    assert!(r.converged, "{label}: {:?}", r.warnings);
    assert!(r.identifiable, "{label}: {:?}", r.warnings);
    let t = s.rotor.params();
    let (mut worst, mut worst_c) = (0.0f64, 0.0f64);
    for (name, want) in [
        ("m", t.m),
        ("cx", t.cx),
        ("kx", t.kx),
        ("cz", t.cz),
        ("kz", t.kz),
        ("a", t.a),
        ("mud", t.unbalance.mud()),
        ("alpha", t.unbalance.alpha),
    ] {
        if let Some(e) = r.get(name) {
            let rel = (e.value - want).abs() / want.abs();
            println!("{label} {name}: relative error {rel:.2e}");
            if name.starts_with('c') {
                worst_c = worst_c.max(rel);
            } else {
                worst = worst.max(rel);
            }
        }
    }
    // the initial state is recovered too (it is zero in these scenarios)
    let y0 = r.initial;
    assert!(y0.x.abs() < 1e-15 && y0.z.abs() < 1e-15, "{y0:?}");
    assert!(y0.vx.abs() < 1e-12 && y0.vz.abs() < 1e-12, "{y0:?}");
    println!("{label}: {} iterations, {}", r.iterations, r.discretisation);
    (worst, worst_c)
}

#[test]
fn constant_speed_from_one_percent_off() {
    let s = Scenario::table1();
    let (e, ec) = fit(
        "1200 rpm",
        &s,
        Unknowns::default(),
        &perturbed(&s.rotor.params(), 0.01),
    );
    assert!(e < 1e-10 && ec < 1e-9, "{e:e} {ec:e}");
}

#[test]
fn ramp_from_one_percent_off() {
    let s = Scenario::table1_ramp(600.0).unwrap();
    let (e, ec) = fit(
        "ramp",
        &s,
        Unknowns::default(),
        &perturbed(&s.rotor.params(), 0.01),
    );
    // RK4 (2 sub-steps) model error: ~1e-9 on m, k; c is 100x less well determined by
    // the data (Cramer-Rao 6e-3 vs 6e-5), so the same model error moves it ~100x more.
    assert!(e < 1e-8 && ec < 3e-8, "{e:e} {ec:e}");
}

#[test]
fn unbalance_and_gyroscopic_coefficient_with_m_known() {
    let s = Scenario::table1();
    let mut start = perturbed(&s.rotor.params(), 0.01);
    start.m = s.rotor.m();
    start.a *= 1.1;
    start.unbalance.m_u *= 0.9;
    start.unbalance.alpha += 0.2;
    let u = Unknowns {
        m: false,
        ..Unknowns::all()
    };
    let (e, ec) = fit("1200 rpm, all but m", &s, u, &start);
    assert!(e < 1e-9 && ec < 1e-9, "{e:e} {ec:e}");
}

#[test]
fn unbalance_on_a_ramp() {
    let s = Scenario::table1_ramp(600.0).unwrap();
    let mut start = perturbed(&s.rotor.params(), 0.01);
    start.unbalance.m_u *= 1.2;
    start.unbalance.alpha -= 0.3;
    let u = Unknowns {
        unbalance: true,
        ..Unknowns::default()
    };
    let (e, ec) = fit("ramp, unbalance unknown", &s, u, &start);
    assert!(e < 1e-8 && ec < 3e-8, "{e:e} {ec:e}");
}

#[test]
fn everything_unknown_is_reported_unidentifiable() {
    // Eq. (1) is homogeneous in (m, c, k, a, m_u d): scaling them all leaves the response
    // unchanged, so with all of them unknown no record can fix the scale.
    let s = Scenario::table1();
    let resp = simulate(&s, Method::Exact).unwrap();
    let rec = Record::from_simulation(&s, &resp);
    let opts = RefineOptions {
        unknowns: Unknowns::all(),
        ..RefineOptions::default()
    };
    let start = perturbed(&s.rotor.params(), 0.01);
    let r = refine(&rec, &start, &InitialState::default(), &opts).unwrap();
    assert!(!r.identifiable);
    match &r.warnings[..] {
        [Warning::NotIdentifiable { parameters, .. }, ..] => {
            assert_eq!(
                parameters,
                &["m", "cx", "kx", "cz", "kz", "a", "mud", "alpha"]
            )
        }
        w => panic!("{w:?}"),
    }
    for e in &r.parameters {
        assert!(e.std_error.is_infinite(), "{}", e.name);
    }
    // the initial state is still determined
    for e in &r.initial_state {
        assert!(e.std_error.is_finite(), "{}", e.name);
    }
}
