//! The modulating-function identifier on exact (noise-free) data: accuracy, independence
//! of the initial state, observed quadrature order, streaming = batch, input errors.

use rotorid::identify::algebraic::measurement;
use rotorid::identify::modulating::{
    identify_modulating, identify_modulating_response, ModulatingConfig, ModulatingDirection,
    ModulatingError, ModulatingEstimate, ModulatingIdentifier, NoiseCompensation,
};
use rotorid::identify::InputError;
use rotorid::identify::Known;
use rotorid::model::OutOfRange;
use rotorid::simulate::{simulate, Method, TimeResponse};
use rotorid::{InitialState, Sampling, Scenario};

fn scenario(ramp: bool, dt: f64, duration: f64) -> Scenario {
    let mut s = if ramp {
        Scenario::table1_ramp(600.0).unwrap()
    } else {
        Scenario::table1()
    };
    s.sampling = Sampling::new(dt, duration).unwrap();
    s
}

/// Largest relative error over m, c, k of both directions.
fn worst(s: &Scenario, e: &ModulatingEstimate) -> f64 {
    let r = &s.rotor;
    let truth = [r.m(), r.cx(), r.kx(), r.m(), r.cz(), r.kz()];
    e.values()
        .iter()
        .zip(truth)
        .map(|(v, t)| ((v - t) / t).abs())
        .fold(0.0, f64::max)
}

fn run(s: &Scenario, config: ModulatingConfig) -> (TimeResponse, ModulatingEstimate) {
    let resp = simulate(s, Method::Exact).unwrap();
    let e = identify_modulating_response(&resp, Known::from_rotor(&s.rotor), config).unwrap();
    (resp, e)
}

#[test]
fn exact_data_give_every_parameter_to_1e_9() {
    for ramp in [false, true] {
        let s = scenario(ramp, 1e-4, 0.3);
        let (resp, e) = run(&s, ModulatingConfig::default());
        let err = worst(&s, &e);
        println!("ramp {ramp}: worst relative error {err:e}");
        assert!(
            err < 1e-9,
            "ramp {ramp}: worst relative error {err:e}, {e:?}"
        );
        assert!(e.well_conditioned(1e-3) == [true, true], "{e:?}");
        // windows of 200 intervals every 25 samples in 3000 intervals
        assert_eq!(e.windows, (3000 - 200) / 25 + 1);
        assert_eq!(e.window_s, 200.0 * 1e-4);
        assert_eq!(e.hop_s, 25.0 * 1e-4);
        // no noise: the estimated sigma is at the signal's 1e-7 (140 dB) level and the
        // standard errors are as small
        let rms = (resp.x.iter().map(|v| v * v).sum::<f64>() / resp.len() as f64).sqrt();
        assert!(
            e.sigma_x < 1e-7 * rms,
            "sigma_x {:e}, rms {rms:e}",
            e.sigma_x
        );
        assert!(e.x.std_error_m < 1e-8 * s.rotor.m(), "{e:?}");
    }
}

#[test]
fn the_initial_state_does_not_matter() {
    // a free transient ten times the forced response, in every component
    let mut s = scenario(false, 1e-4, 0.3);
    s.initial = InitialState {
        x: 2e-6,
        z: -1.5e-6,
        vx: 1e-3,
        vz: -4e-4,
    };
    let (_, e) = run(&s, ModulatingConfig::default());
    assert!(worst(&s, &e) < 1e-9, "{:e}: {e:?}", worst(&s, &e));
    let mut r = scenario(true, 1e-4, 0.3);
    r.initial = s.initial;
    let (_, e) = run(&r, ModulatingConfig::default());
    assert!(worst(&r, &e) < 1e-9, "{:e}: {e:?}", worst(&r, &e));
}

#[test]
fn the_quadrature_is_sixth_order() {
    // the same windows in time (20 ms, hop 2.4 ms) sampled at 0.2 and 0.4 ms: the error
    // must fall by 2^6 = 64 when h halves (Euler-Maclaurin, module test_functions)
    let config = ModulatingConfig {
        window_s: 0.02,
        hop_s: 0.0024,
        ..ModulatingConfig::default()
    };
    let err = |dt: f64| {
        let s = scenario(false, dt, 0.5);
        let (_, e) = run(&s, config);
        worst(&s, &e)
    };
    let (coarse, fine) = (err(4e-4), err(2e-4));
    let ratio = coarse / fine;
    println!(
        "errors {coarse:e} at 0.4 ms, {fine:e} at 0.2 ms: order {:.2}",
        ratio.log2()
    );
    assert!(
        (45.0..90.0).contains(&ratio),
        "errors {coarse:e} at 0.4 ms, {fine:e} at 0.2 ms: ratio {ratio} (order {:.2})",
        ratio.log2()
    );
}

#[test]
fn streaming_gives_exactly_the_batch_estimate() {
    let s = scenario(true, 1e-4, 0.1);
    let resp = simulate(&s, Method::Exact).unwrap();
    let known = Known::from_rotor(&s.rotor);
    let config = ModulatingConfig::default();
    let batch = identify_modulating_response(&resp, known, config).unwrap();
    let mut id = ModulatingIdentifier::new(known, 1e-4, config).unwrap();
    assert_eq!(id.window_samples(), 201);
    for i in 0..resp.len() {
        id.push(&measurement(&resp, i)).unwrap();
        if i == 199 {
            // no window complete yet: the singular answer, not an error
            let e = id.estimate();
            assert_eq!(e.windows, 0);
            assert!(e.x.m.is_nan() && e.x.rcond == 0.0 && e.t.is_nan());
        }
        if i == 200 {
            assert_eq!(id.windows(), 1);
        }
    }
    let stream = id.estimate();
    assert_eq!(stream, batch);
    assert_eq!(stream.t, resp.t[resp.len() - 1]);
    // reset: the same again from a shifted time base
    id.reset();
    for i in 0..resp.len() {
        let mut m = measurement(&resp, i);
        m.t += 1000.0;
        id.push(&m).unwrap();
    }
    let again = id.estimate();
    assert_eq!(again.values(), batch.values());
}

#[test]
fn a_known_zero_noise_is_plain_least_squares() {
    let s = scenario(false, 1e-4, 0.1);
    let resp = simulate(&s, Method::Exact).unwrap();
    let known = Known::from_rotor(&s.rotor);
    let with = |noise| {
        identify_modulating_response(
            &resp,
            known,
            ModulatingConfig {
                noise,
                ..ModulatingConfig::default()
            },
        )
        .unwrap()
    };
    let plain = with(NoiseCompensation::None);
    let zero = with(NoiseCompensation::Known {
        sigma_x: 0.0,
        sigma_z: 0.0,
    });
    assert_eq!(plain.values(), zero.values());
    assert!(!plain.compensated && zero.compensated);
}

#[test]
fn bad_inputs_are_reported_with_their_values() {
    let s = scenario(false, 1e-4, 0.05);
    let r = simulate(&s, Method::Exact).unwrap();
    let known = Known::from_rotor(&s.rotor);
    let cfg = ModulatingConfig::default();
    let call = |t: &[f64], x: &[f64], cfg: ModulatingConfig| {
        identify_modulating(t, x, &r.z, &r.phi, &r.phi_dot, &r.phi_ddot, known, cfg)
    };

    // a window of 10 intervals
    let e = call(&r.t, &r.x, ModulatingConfig::with_window(1e-3)).unwrap_err();
    assert!(
        matches!(
            e,
            ModulatingError::WindowTooShort {
                intervals: 10,
                needed: 24,
                ..
            }
        ),
        "{e}"
    );
    assert!(e.to_string().contains("at least 24 intervals"), "{e}");

    // a record shorter than one window
    let e = identify_modulating(
        &r.t[..150],
        &r.x[..150],
        &r.z[..150],
        &r.phi[..150],
        &r.phi_dot[..150],
        &r.phi_ddot[..150],
        known,
        cfg,
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            ModulatingError::RecordShorterThanWindow {
                samples: 150,
                needed: 201,
                ..
            }
        ),
        "{e}"
    );

    // unequal columns, a NaN, a gap in time
    let e = call(&r.t, &r.x[1..], cfg).unwrap_err();
    assert!(
        matches!(
            e,
            ModulatingError::Input(InputError::ColumnLength { column: "x", .. })
        ),
        "{e}"
    );
    let mut x = r.x.clone();
    x[321] = f64::NAN;
    let e = call(&r.t, &x, cfg).unwrap_err();
    assert!(
        matches!(
            e,
            ModulatingError::Input(InputError::NotFinite {
                index: 321,
                field: "x",
                ..
            })
        ),
        "{e}"
    );
    let mut t = r.t.clone();
    t[400] += 0.5e-4;
    let e = call(&t, &r.x, cfg).unwrap_err();
    assert!(
        matches!(
            e,
            ModulatingError::Input(InputError::NonUniformSampling { index: 400, .. })
        ),
        "{e}"
    );

    // configuration ranges
    for (bad, field) in [
        (ModulatingConfig { hop_s: 0.03, ..cfg }, "hop_s"),
        (
            ModulatingConfig {
                hop_s: 0.02 / 65.0,
                ..cfg
            },
            "hop_s",
        ),
        (
            ModulatingConfig {
                window_s: 2e3,
                hop_s: 1e3,
                ..cfg
            },
            "window_s",
        ),
        (
            ModulatingConfig {
                window_s: -0.02,
                ..cfg
            },
            "window_s",
        ),
        (
            ModulatingConfig {
                functions: 0,
                ..cfg
            },
            "functions",
        ),
        (
            ModulatingConfig {
                functions: 33,
                ..cfg
            },
            "functions",
        ),
        (
            ModulatingConfig {
                rcond_min: 2.0,
                ..cfg
            },
            "rcond_min",
        ),
        (
            ModulatingConfig {
                noise: NoiseCompensation::Known {
                    sigma_x: -1.0,
                    sigma_z: 0.0,
                },
                ..cfg
            },
            "sigma_x",
        ),
    ] {
        match call(&r.t, &r.x, bad).unwrap_err() {
            ModulatingError::Input(InputError::OutOfRange(OutOfRange {
                field: f,
                allowed,
                ..
            })) => {
                assert_eq!(f, field);
                assert!(!allowed.is_empty());
            }
            other => panic!("{field}: {other}"),
        }
    }
    let e = ModulatingConfig::for_natural_frequency(-3.0).unwrap_err();
    assert_eq!(
        e.to_string(),
        "omega_n = -3 is out of range: must be finite and > 0 (rad/s)"
    );
    let c = ModulatingConfig::for_natural_frequency(std::f64::consts::TAU / 0.025).unwrap();
    assert!((c.window_s - 0.025).abs() < 1e-15 && (c.hop_s - 0.025 / 8.0).abs() < 1e-15);
    assert_eq!(ModulatingDirection::SINGULAR.rcond, 0.0);
}
