//! When the data cannot separate the unknowns the fit says so (identifiable == false,
//! warnings, infinite or huge standard errors) instead of returning a confident number.

use rotorid::model::{InitialState, Rotor, RotorParams, Scenario, SpeedProfile};
use rotorid::refine::{refine, Record, RefineOptions, Refined, Unknowns, Warning};
use rotorid::simulate::{add_noise, simulate, steady_state, Method};
use rotorid::test_models::perturbed_start as perturbed;

fn fit(s: &Scenario, snr_db: Option<f64>, unknowns: Unknowns, start: &RotorParams) -> Refined {
    let mut resp = simulate(s, Method::Exact).unwrap();
    if let Some(snr) = snr_db {
        add_noise(&mut resp, snr, 7).unwrap();
    }
    let rec = Record::from_simulation(s, &resp);
    let opts = RefineOptions {
        unknowns,
        ..RefineOptions::default()
    };
    refine(&rec, start, &InitialState::default(), &opts).unwrap()
}

/// No reported model parameter may look determined: each has an infinite standard error
/// or one larger than its value.
fn assert_nothing_confident(r: &Refined, names: &[&str]) {
    assert!(!r.identifiable, "{:?}", r.warnings);
    for n in names {
        let e = r.get(n).unwrap();
        let undetermined =
            e.std_error.is_infinite() || e.relative_std_error.is_some_and(|x| x > 1.0);
        assert!(
            undetermined,
            "{n} = {} +- {} looks determined",
            e.value, e.std_error
        );
    }
}

#[test]
fn no_excitation_exact_zeros() {
    // zero unbalance, zero initial state: the record is identically zero
    let mut p = Rotor::table1().params();
    p.unbalance.m_u = 0.0;
    let s = Scenario {
        rotor: Rotor::new(p).unwrap(),
        ..Scenario::table1()
    };
    let r = fit(&s, Some(40.0), Unknowns::default(), &perturbed(&p));
    assert_eq!(r.sigma_x, 0.0);
    assert_nothing_confident(&r, &["m", "cx", "kx", "cz", "kz"]);
    let not_id = r.warnings.iter().find_map(|w| match w {
        Warning::NotIdentifiable { parameters, .. } => Some(parameters.clone()),
        _ => None,
    });
    assert_eq!(not_id.unwrap(), ["m", "cx", "kx", "cz", "kz"]);
    assert!(matches!(
        r.warnings[0],
        Warning::NoSignificantTransient { .. }
    ));
    for e in &r.parameters {
        assert!(e.std_error.is_infinite());
    }
}

#[test]
fn no_excitation_pure_noise() {
    // zero unbalance, zero initial state, but sensor noise: the data are noise alone
    let mut p = Rotor::table1().params();
    p.unbalance.m_u = 0.0;
    let s = Scenario {
        rotor: Rotor::new(p).unwrap(),
        ..Scenario::table1()
    };
    let mut resp = simulate(&s, Method::Exact).unwrap();
    resp.x
        .iter_mut()
        .enumerate()
        .for_each(|(i, v)| *v = 1e-9 * ((i * 7919 % 1000) as f64 / 500.0 - 1.0));
    resp.z
        .iter_mut()
        .enumerate()
        .for_each(|(i, v)| *v = 1e-9 * ((i * 104729 % 997) as f64 / 498.5 - 1.0));
    let rec = Record::from_simulation(&s, &resp);
    let r = refine(
        &rec,
        &perturbed(&p),
        &InitialState::default(),
        &RefineOptions::default(),
    )
    .unwrap();
    println!("{:#?}", r.warnings);
    assert_nothing_confident(&r, &["m", "cx", "kx", "cz", "kz"]);
}

#[test]
fn steady_state_only_with_mass_stiffness_damping_and_unbalance_unknown() {
    // Start on the steady state: the record is a single sinusoid per channel (4 numbers)
    // and cannot give m, cx, kx, cz, kz, m_u d, alpha (7 numbers).
    let rotor = Rotor::table1();
    let SpeedProfile::Constant { omega, phi0 } = Scenario::table1().speed else {
        unreachable!()
    };
    let ss = steady_state(&rotor, omega);
    let (q, v) = (ss.displacement(0.0, phi0), ss.velocity(0.0, phi0));
    let s = Scenario {
        initial: InitialState {
            x: q[0],
            z: q[1],
            vx: v[0],
            vz: v[1],
        },
        ..Scenario::table1()
    };
    let u = Unknowns {
        unbalance: true,
        ..Unknowns::default()
    };
    let mut start = perturbed(&rotor.params());
    start.unbalance.m_u *= 1.1;
    let r = fit(&s, Some(40.0), u, &start);
    println!("{:#?}", r.warnings);
    println!("cond {:e}", r.condition_number);
    for e in &r.parameters {
        println!("{} = {} +- {}", e.name, e.value, e.std_error);
    }
    assert_nothing_confident(&r, &["m", "cx", "kx", "cz", "kz", "mud"]);
    // with m, c, k alone unknown and the unbalance known, a steady state still leaves one
    // combination free (5 unknowns, 4 numbers)
    let r = fit(
        &s,
        Some(40.0),
        Unknowns::default(),
        &perturbed(&rotor.params()),
    );
    assert!(!r.identifiable, "{:?}", r.warnings);
}

#[test]
fn zero_speed_free_vibration_fixes_only_ratios() {
    // A tap test: no rotation, a non-zero initial state. The free response depends on k/m
    // and c/m only, so m, c, k together are not identifiable; with m known they are.
    let s = Scenario {
        speed: SpeedProfile::constant_rpm(0.0, 0.0).unwrap(),
        initial: InitialState {
            x: 1e-6,
            z: -5e-7,
            vx: 0.0,
            vz: 1e-4,
        },
        ..Scenario::table1()
    };
    let p = s.rotor.params();
    let r = fit(&s, Some(40.0), Unknowns::default(), &perturbed(&p));
    assert!(!r.identifiable);
    assert!(
        matches!(&r.warnings[..], [Warning::NotIdentifiable { .. }, ..]),
        "{:?}",
        r.warnings
    );
    let mut start = perturbed(&p);
    start.m = p.m;
    let u = Unknowns {
        m: false,
        ..Unknowns::default()
    };
    let r = fit(&s, Some(40.0), u, &start);
    assert!(r.identifiable && r.converged, "{:?}", r.warnings);
    let kx = r.get("kx").unwrap();
    assert!((kx.value - p.kx).abs() < 4.0 * kx.std_error, "{kx:?}");
}
