//! Model adequacy: records of rotors that eq. (1) does not describe (a cubic support
//! stiffness; an x support standing on a flexible foundation), simulated here by an
//! independent RK4 integrator, are flagged and their values withheld; records of the model
//! itself pass at 20, 40 and 60 dB. Refine tests its maximum-likelihood fit, the modulating
//! method the response of its own estimate (`pipeline::adequacy`); the modulating method's
//! correct models are hard ones too (anisotropic, heavily damped, supercritical, from a
//! non-zero state, run-up, run-down through the critical speed).
//! `cargo test --release -p rotorid --test it adequacy -- --ignored --nocapture` runs the
//! 100-seed studies and prints the rates.

use rotorid::model::{InitialState, Rotor, Sampling, SpeedProfile};
use rotorid::pipeline::{
    identify, AdequacyBasis, Finding, Identification, Knowledge, Method, Record, Severity, Speed,
    NOISE_RATIO_MAX, SMALL_RESIDUAL_MAX,
};
use rotorid::simulate::{add_noise, TimeResponse};
use rotorid::test_models::{table1, TestModel};
use rotorid::Scenario;

use super::defects::{simulate_defective, DEFECTS};

/// (adequacy flagged, every value withheld) for refine on `clean` with noise (`snr`, `seed`).
fn refine_flags(clean: &TimeResponse, snr: f64, seed: u64) -> (bool, bool) {
    let id = run(&Method::refine(), clean, &Scenario::table1(), snr, seed);
    let flagged = id
        .diagnostics
        .iter()
        .any(|d| matches!(d.finding, Finding::ModelInadequate { .. }));
    assert_eq!(flagged, !id.adequacy.unwrap().model_adequate);
    let withheld = id.parameters.iter().all(|p| p.value.is_none());
    (flagged, withheld)
}

/// `method` on `clean` (a record of `scenario`'s rotor) with noise (`snr`, `seed`).
fn run(
    method: &Method,
    clean: &TimeResponse,
    scenario: &Scenario,
    snr: f64,
    seed: u64,
) -> Identification {
    let mut r = clean.clone();
    add_noise(&mut r, snr, seed).unwrap();
    let rec = Record::new(
        r.t.clone(),
        r.x.clone(),
        r.z.clone(),
        Speed::Samples {
            phi: r.phi.clone(),
            omega: r.phi_dot.clone(),
            omega_dot: r.phi_ddot.clone(),
        },
        1e-6,
    )
    .unwrap();
    identify(&rec, &Knowledge::from_scenario(scenario), method).unwrap()
}

/// Rates over `seeds`: false alarms on the model itself per SNR, detections per defect.
fn rates(seeds: u64) -> ([f64; 3], [f64; 2]) {
    let clean = table1().clean;
    let alarms = [20.0, 40.0, 60.0].map(|snr| {
        (0..seeds)
            .filter(|&s| refine_flags(&clean, snr, 100 + s).0)
            .count() as f64
            / seeds as f64
    });
    let detections = DEFECTS.map(|d| {
        let c = simulate_defective(d);
        (0..seeds)
            .filter(|&s| {
                let (flagged, withheld) = refine_flags(&c, 40.0, 500 + s);
                assert_eq!(flagged, withheld, "{d:?}: flagged values are withheld");
                flagged
            })
            .count() as f64
            / seeds as f64
    });
    (alarms, detections)
}

#[test]
fn wrong_models_are_flagged_and_the_model_itself_is_not() {
    let (alarms, detections) = rates(8);
    for (snr, a) in [20, 40, 60].iter().zip(alarms) {
        assert!(a <= 0.125, "{snr} dB: {a} false alarms");
    }
    for (d, r) in DEFECTS.iter().zip(detections) {
        assert_eq!(r, 1.0, "{d:?}: detected in {r}");
    }
}

#[test]
fn a_ramp_of_the_model_itself_passes() {
    // the ramp is refined with RK4 on the per-sample speed: its model error must stay
    // invisible even at 60 dB
    let clean = rotorid::test_models::table1_ramp(600.0).clean;
    for seed in 0..4 {
        assert!(!refine_flags(&clean, 60.0, 900 + seed).0, "seed {seed}");
    }
}

#[test]
#[ignore = "100-seed study (~1 min in release): cargo test --release ... -- --ignored"]
fn hundred_seed_adequacy_rates() {
    let (alarms, detections) = rates(100);
    println!("false alarms on eq. (1) at 20/40/60 dB: {alarms:?}");
    println!("detections at 40 dB, 1 s (cubic stiffness, foundation): {detections:?}");
    assert!(alarms.iter().all(|&a| a <= 0.05));
    assert!(detections.iter().all(|&d| d >= 0.95));
}

/// For refine on `clean` + noise: per parameter m, cx, kx, cz, kz, whether the estimate is
/// within 1.96 standard errors of the truth by the Fisher and by the sandwich covariance,
/// and the ratio sandwich / Fisher.
fn interval_check(clean: &TimeResponse, snr: f64, seed: u64) -> Vec<(bool, bool, f64)> {
    let mut r = clean.clone();
    add_noise(&mut r, snr, seed).unwrap();
    let rec = Record::new(
        r.t.clone(),
        r.x.clone(),
        r.z.clone(),
        Speed::Samples {
            phi: r.phi.clone(),
            omega: r.phi_dot.clone(),
            omega_dot: r.phi_ddot.clone(),
        },
        1e-6,
    )
    .unwrap();
    let k = Knowledge::from_scenario(&Scenario::table1());
    let id = identify(&rec, &k, &Method::refine()).unwrap();
    id.parameters
        .iter()
        .map(|p| {
            let err = (p.estimate.unwrap() - p.truth.unwrap()).abs();
            let (se, robust) = (p.std_error.unwrap(), p.robust_std_error.unwrap());
            (err <= 1.96 * se, err <= 1.96 * robust, robust / se)
        })
        .collect()
}

/// Coverage of the 95 % intervals (Fisher, sandwich) and the median sandwich / Fisher
/// ratio over `seeds`, pooled over m, cx, kx, cz, kz.
fn coverage(clean: &TimeResponse, snr: f64, seeds: std::ops::Range<u64>) -> (f64, f64, f64) {
    let mut all = Vec::new();
    for s in seeds {
        all.extend(interval_check(clean, snr, s));
    }
    let n = all.len() as f64;
    let fisher = all.iter().filter(|c| c.0).count() as f64 / n;
    let robust = all.iter().filter(|c| c.1).count() as f64 / n;
    let mut ratios: Vec<f64> = all.iter().map(|c| c.2).collect();
    ratios.sort_by(f64::total_cmp);
    (fisher, robust, ratios[ratios.len() / 2])
}

#[test]
fn the_sandwich_agrees_with_fisher_on_the_model_and_widens_on_wrong_ones() {
    // eq. (1) itself: the residuals are white, the bandwidth ~0, the two agree
    let (f, r, ratio) = coverage(&table1().clean, 40.0, 300..308);
    eprintln!("model itself: coverage Fisher {f:.2}, sandwich {r:.2}, median ratio {ratio:.2}");
    assert!((0.8..1.25).contains(&ratio), "{ratio}");
    assert!(f >= 0.8 && r >= 0.8, "{f} {r}");
    for d in DEFECTS {
        let (f, r, ratio) = coverage(&simulate_defective(d), 40.0, 700..708);
        eprintln!("{d:?}: coverage Fisher {f:.2}, sandwich {r:.2}, median ratio {ratio:.2}");
        assert!(ratio > 1.5, "{d:?}: {ratio}");
        assert!(r >= f, "{d:?}");
    }
}

/// Records eq. (1) describes, with what makes identification hard, 1 s at 10 kHz: the
/// paper's rotor at 1200 rpm; anisotropic supports; heavy damping (damping ratio 0.05);
/// supercritical (4000 rpm, the critical speed ~2760 rpm); a non-zero initial state; the
/// run-up from 600 rpm at 10 rad/s^2; a run-down from 3000 rpm at -30 rad/s^2 (through
/// the critical speed).
fn correct_models() -> Vec<TestModel> {
    let base = Scenario::table1();
    let with = |name: &str, f: &dyn Fn(&mut rotorid::RotorParams, &mut Scenario)| {
        let mut s = base;
        let mut p = s.rotor.params();
        f(&mut p, &mut s);
        s.rotor = Rotor::new(p).unwrap();
        TestModel::clean(name, s)
    };
    vec![
        table1(),
        with("aniso", &|p, _| {
            p.kx = 1.0e6;
            p.kz = 1.6e6;
            p.cx = 8.0;
            p.cz = 30.0;
        }),
        with("heavy_damping", &|p, _| {
            p.cx = 400.0;
            p.cz = 400.0;
        }),
        with("supercritical", &|_, s| {
            s.speed = SpeedProfile::constant_rpm(4000.0, 0.0).unwrap();
        }),
        with("initial_state", &|_, s| {
            s.initial = InitialState {
                x: 5e-6,
                z: -3e-6,
                vx: 2e-3,
                vz: 0.0,
            };
        }),
        rotorid::test_models::table1_ramp(600.0),
        with("run_down", &|_, s| {
            s.speed = SpeedProfile::ramp(3000.0, -30.0, 0.0).unwrap();
            s.sampling = Sampling::new(1e-4, 1.0).unwrap();
        }),
    ]
}

/// Whether `id` says the model is inadequate; then every value must be withheld.
fn flagged(id: &Identification) -> bool {
    let f = id
        .diagnostics
        .iter()
        .any(|d| matches!(d.finding, Finding::ModelInadequate { .. }));
    if let Some(a) = &id.adequacy {
        assert_eq!(f, !a.model_adequate);
    }
    if f {
        assert!(id.parameters.iter().all(|p| p.value.is_none()), "withheld");
        assert!(id.rotor.is_none());
    }
    f
}

/// For `method`: false-alarm rates per correct model (rows) at 20, 40, 60 dB over
/// `seeds`, and detection rates of the two defects at 40 dB.
fn method_rates(method: &Method, seeds: u64) -> (Vec<(String, [f64; 3])>, [f64; 2]) {
    let alarms = correct_models()
        .iter()
        .enumerate()
        .map(|(i, m)| {
            // each model and SNR its own noise draws
            let rate = [20.0, 40.0, 60.0].map(|snr| {
                let first = 100 + 1000 * i as u64 + snr as u64 * 10_000;
                (first..first + seeds)
                    .filter(|&s| flagged(&run(method, &m.clean, &m.scenario, snr, s)))
                    .count() as f64
                    / seeds as f64
            });
            (m.name.clone(), rate)
        })
        .collect();
    let detections = DEFECTS.map(|d| {
        let c = simulate_defective(d);
        (0..seeds)
            .filter(|&s| flagged(&run(method, &c, &Scenario::table1(), 40.0, 500 + s)))
            .count() as f64
            / seeds as f64
    });
    (alarms, detections)
}

#[test]
fn the_modulating_method_flags_wrong_models_and_not_correct_ones() {
    // a few fixed seeds: deterministic; the ignored study below measures the rates
    let (alarms, detections) = method_rates(&Method::modulating(), 3);
    for (name, a) in &alarms {
        assert_eq!(*a, [0.0; 3], "{name}: false alarms at 20/40/60 dB");
    }
    for (d, r) in DEFECTS.iter().zip(detections) {
        assert_eq!(r, 1.0, "{d:?}: detected in {r}");
    }
}

#[test]
fn the_modulating_method_judges_its_own_fit() {
    // on the foundation rotor the modulating estimate's own response misses the record;
    // the same identification without that test would report m with a standard error
    let c = simulate_defective(DEFECTS[1]);
    let id = run(&Method::modulating(), &c, &Scenario::table1(), 40.0, 5);
    assert!(flagged(&id));
    let a = id.adequacy.unwrap();
    assert!(!a.x.adequate, "{a:?}");
    // the raw numbers stay in `estimate`
    assert!(id.parameters.iter().all(|p| p.estimate.is_some()));
    // and on the model itself at 40 dB: adequate, values reported
    let m = table1();
    let id = run(&Method::modulating(), &m.clean, &m.scenario, 40.0, 5);
    let a = id.adequacy.expect("judged");
    assert!(a.model_adequate, "{a:?}");
    assert!(id.parameters.iter().all(|p| p.value.is_some()));
}

#[test]
#[ignore = "100-seed study (a few minutes in release): cargo test --release ... -- --ignored"]
fn hundred_seed_modulating_adequacy_rates() {
    let (alarms, detections) = method_rates(&Method::modulating(), 100);
    println!("modulating: false alarms at 20/40/60 dB:");
    for (name, a) in &alarms {
        println!("  {name:14} {a:?}");
    }
    println!("modulating: detections at 40 dB, 1 s (cubic stiffness, foundation): {detections:?}");
    assert!(alarms.iter().all(|(_, a)| a.iter().all(|&v| v <= 0.05)));
    assert!(detections.iter().all(|&d| d >= 0.95));
}

/// For the algebraic method on `clean` + noise (`snr`, `seed`; no noise when `snr` is
/// infinite): (judged, flagged).
fn algebraic_verdict(
    clean: &TimeResponse,
    scenario: &Scenario,
    snr: f64,
    seed: u64,
) -> (bool, bool) {
    let id = if snr.is_finite() {
        run(&Method::algebraic(), clean, scenario, snr, seed)
    } else {
        let rec = Record::from_response(clean).unwrap();
        identify(
            &rec,
            &Knowledge::from_scenario(scenario),
            &Method::algebraic(),
        )
        .unwrap()
    };
    (id.adequacy.is_some(), flagged(&id))
}

#[test]
fn the_algebraic_method_is_judged_whether_its_estimates_settle_or_not() {
    // noise-free: the model itself passes (its residuals are at the model's own
    // accuracy); at 40 dB the algebraic estimates never settle (algebraic_unsettled) and
    // the refit starts from the early estimate refine's start policy takes: judged, passes
    let m = table1();
    assert_eq!(
        algebraic_verdict(&m.clean, &m.scenario, f64::INFINITY, 0),
        (true, false)
    );
    assert_eq!(
        algebraic_verdict(&m.clean, &m.scenario, 40.0, 1),
        (true, false)
    );
}

/// Whether `id` warns that the algebraic estimates did not settle.
fn unsettled(id: &Identification) -> bool {
    id.diagnostics
        .iter()
        .any(|d| matches!(d.finding, Finding::AlgebraicUnsettled { .. }))
}

#[test]
fn the_algebraic_method_calls_a_wrong_model_inadequate_though_its_estimates_never_settle() {
    // the rotor on a foundation eq. (1) lacks, clean: the algebraic estimates never
    // settle (m_x ~15.1 kg, kx ~7.5e5 N/m against 14.29 kg and 1.195e6 N/m) and were
    // reported as values with only that warning; the refit from the early estimate
    // rejects the model, as every other method does
    let c = simulate_defective(DEFECTS[1]);
    let k = Knowledge::from_scenario(&Scenario::table1());
    let id = identify(
        &Record::from_response(&c).unwrap(),
        &k,
        &Method::algebraic(),
    )
    .unwrap();
    assert!(unsettled(&id), "{:?}", id.diagnostics);
    assert!(flagged(&id), "{:?}", id.adequacy);
    assert!(matches!(
        id.diagnostics[0].finding,
        Finding::ModelInadequate { .. }
    ));
    // the raw numbers stay in `estimate`
    assert!(id.parameters.iter().all(|p| p.estimate.is_some()));
    // and with noise
    for seed in 0..3 {
        let id = run(
            &Method::algebraic(),
            &c,
            &Scenario::table1(),
            40.0,
            40 + seed,
        );
        assert!(
            unsettled(&id) && flagged(&id),
            "seed {seed}: {:?}",
            id.adequacy
        );
    }
}

#[test]
fn a_noise_free_record_keeps_its_values_with_a_note_on_what_the_test_cannot_tell() {
    // the paper's rotor through the paper's Newmark integrator, noise-free: eq. (1) misses
    // the record by the integrator's period error (~1e-5 of the signal), hundreds of times
    // the noise the fourth differences see (rounding), which the tests alone would reject
    let s = Scenario::table1();
    let r = rotorid::simulate::simulate(&s, rotorid::simulate::Method::Newmark).unwrap();
    let rec = Record::from_response(&r).unwrap();
    let k = Knowledge::from_scenario(&s);
    for method in [Method::algebraic(), Method::modulating(), Method::refine()] {
        let id = identify(&rec, &k, &method).unwrap();
        let name = format!("{:?}", method.name());
        let a = id.adequacy.unwrap_or_else(|| panic!("{name}: not judged"));
        assert!(a.model_adequate, "{name}: {a:?}");
        for c in [a.x, a.z] {
            assert_eq!(c.basis, AdequacyBasis::SmallResidual, "{name}: {c:?}");
            assert!(
                c.noise_ratio > NOISE_RATIO_MAX,
                "{name}: the tests alone fail"
            );
            assert!(
                (1e-7..SMALL_RESIDUAL_MAX).contains(&c.relative_residual),
                "{name}: {c:?}"
            );
        }
        let notes: Vec<_> = id
            .diagnostics
            .iter()
            .filter(|d| matches!(d.finding, Finding::SmallResidual { .. }))
            .collect();
        assert_eq!(notes.len(), 2, "{name}: {:?}", id.diagnostics);
        assert!(notes.iter().all(|d| d.severity == Severity::Note));
        assert!(
            notes[0].message.contains("cannot tell"),
            "{}",
            notes[0].message
        );
        assert!(!id
            .diagnostics
            .iter()
            .any(|d| matches!(d.finding, Finding::ModelInadequate { .. })));
        // the values, within the integrator's error of the truth
        for p in &id.parameters {
            let v = p
                .value
                .unwrap_or_else(|| panic!("{name}: {:?} withheld", p.parameter));
            let e = (v - p.truth.unwrap()).abs() / p.truth.unwrap();
            assert!(e < 1e-2, "{name}: {:?} off by {e:e}", p.parameter);
        }
    }
    // the same record with a wrong model's share of 3e-4 of the signal is still rejected
    let mut bad = r.clone();
    let rms = (r.x.iter().map(|v| v * v).sum::<f64>() / r.x.len() as f64).sqrt();
    for (i, x) in bad.x.iter_mut().enumerate() {
        *x += 3e-4 * rms * std::f64::consts::SQRT_2 * (700.0 * i as f64 * 1e-4).sin();
    }
    let id = identify(&Record::from_response(&bad).unwrap(), &k, &Method::refine()).unwrap();
    assert!(flagged(&id), "{:?}", id.adequacy);
}

#[test]
#[ignore = "100-seed study: cargo test --release ... -- --ignored"]
fn hundred_seed_algebraic_adequacy_rates() {
    let seeds = 100;
    println!("algebraic: (judged, false alarms) at 20/40/60 dB and noise-free:");
    for (i, m) in correct_models().iter().enumerate() {
        let rates = [20.0, 40.0, 60.0, f64::INFINITY].map(|snr| {
            let runs: Vec<(bool, bool)> = (0..if snr.is_finite() { seeds } else { 1 })
                .map(|s| algebraic_verdict(&m.clean, &m.scenario, snr, 3000 + 1000 * i as u64 + s))
                .collect();
            let n = runs.len() as f64;
            (
                runs.iter().filter(|r| r.0).count() as f64 / n,
                runs.iter().filter(|r| r.1).count() as f64 / n,
            )
        });
        println!("  {:14} {rates:?}", m.name);
        assert!(rates.iter().all(|r| r.1 <= 0.05));
    }
    for d in DEFECTS {
        let c = simulate_defective(d);
        let rates = [40.0, f64::INFINITY].map(|snr| {
            let runs: Vec<(bool, bool)> = (0..if snr.is_finite() { seeds } else { 1 })
                .map(|s| algebraic_verdict(&c, &Scenario::table1(), snr, 600 + s))
                .collect();
            let n = runs.len() as f64;
            (
                runs.iter().filter(|r| r.0).count() as f64 / n,
                runs.iter().filter(|r| r.1).count() as f64 / n,
            )
        });
        println!("  {d:?}: (judged, flagged) at 40 dB and noise-free {rates:?}");
        assert!(rates.iter().all(|r| r.1 >= 0.95), "{d:?}: {rates:?}");
    }
}
