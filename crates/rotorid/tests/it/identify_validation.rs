//! Input validation of the identifier: every rejected input names itself and states the
//! allowed range; a rejected measurement leaves the identifier unchanged; singular systems
//! are not errors.

use rotorid::identify::algebraic::{
    identify_batch, identify_response, AlgebraicConfig, AlgebraicError, AlgebraicIdentifier,
    ConvergenceTracker, Quadrature, SpeedModel,
};
use rotorid::identify::{InputError, Known, Measurement};
use rotorid::simulate::TimeResponse;
use rotorid::{Rotor, SpeedState};

fn known() -> Known {
    Known::from_rotor(&Rotor::table1())
}

fn sample(i: u64) -> Measurement {
    let t = i as f64 * 1e-4;
    Measurement {
        t,
        x: 1e-7 * (300.0 * t).sin(),
        z: 1e-7 * (300.0 * t).cos(),
        speed: SpeedState {
            phi: 125.0 * t,
            omega: 125.0,
            omega_dot: 0.0,
        },
    }
}

#[test]
fn known_comes_from_the_rotor() {
    let k = known();
    assert_eq!(k.a, 2.871);
    assert!((k.mud - 1.5e-5).abs() < 1e-20);
    assert_eq!(k.alpha, 45f64.to_radians());
}

#[test]
fn bad_construction_inputs_name_the_field() {
    let cases: Vec<(Result<AlgebraicIdentifier, AlgebraicError>, &str)> = vec![
        (
            AlgebraicIdentifier::new(known(), 0.0, AlgebraicConfig::default()),
            "dt = 0 is out of range: must be finite and > 0 (s)",
        ),
        (
            AlgebraicIdentifier::new(known(), f64::NAN, AlgebraicConfig::default()),
            "dt = NaN",
        ),
        (
            AlgebraicIdentifier::new(
                Known {
                    a: f64::INFINITY,
                    ..known()
                },
                1e-4,
                AlgebraicConfig::default(),
            ),
            "known.a = inf",
        ),
        (
            AlgebraicIdentifier::new(
                Known {
                    mud: f64::NAN,
                    ..known()
                },
                1e-4,
                AlgebraicConfig::default(),
            ),
            "known.mud = NaN",
        ),
        (
            AlgebraicIdentifier::new(
                Known {
                    alpha: f64::NAN,
                    ..known()
                },
                1e-4,
                AlgebraicConfig::default(),
            ),
            "known.alpha",
        ),
        (
            AlgebraicIdentifier::new(
                known(),
                1e-4,
                AlgebraicConfig {
                    rcond_min: 2.0,
                    ..Default::default()
                },
            ),
            "rcond_min = 2 is out of range: must be finite and in [0, 1]",
        ),
        (
            AlgebraicIdentifier::new(
                known(),
                1e-4,
                AlgebraicConfig {
                    speed_model: SpeedModel::Constant {
                        omega: f64::NAN,
                        phi0: 0.0,
                    },
                    ..Default::default()
                },
            ),
            "omega = NaN",
        ),
    ];
    for (result, want) in cases {
        let msg = result.unwrap_err().to_string();
        assert!(
            msg.starts_with(want),
            "{msg:?} does not start with {want:?}"
        );
    }
    assert!(AlgebraicConfig::new(Quadrature::Trapezoid, -1e-3, SpeedModel::General).is_err());
    assert!(AlgebraicConfig::constant_speed(125.0, f64::INFINITY).is_err());
    assert!(ConvergenceTracker::new(-0.1, 1e-5).is_err());
    assert!(ConvergenceTracker::new(0.01, f64::NAN).is_err());
    assert!(ConvergenceTracker::with_capacity(0.01, 1e-5, 1).is_err());
}

#[test]
fn non_finite_measurements_name_the_field_and_change_nothing() {
    let mut id = AlgebraicIdentifier::new(known(), 1e-4, AlgebraicConfig::default()).unwrap();
    let mut reference = id.clone();
    for i in 0..10 {
        id.push(&sample(i)).unwrap();
        reference.push(&sample(i)).unwrap();
    }
    type Poison = fn(&mut Measurement);
    let cases: [(&str, Poison); 6] = [
        ("t", |m| m.t = f64::NAN),
        ("x", |m| m.x = f64::INFINITY),
        ("z", |m| m.z = f64::NAN),
        ("phi", |m| m.speed.phi = f64::NAN),
        ("phi_dot", |m| m.speed.omega = f64::NEG_INFINITY),
        ("phi_ddot", |m| m.speed.omega_dot = f64::NAN),
    ];
    for (name, poison) in cases {
        let mut m = sample(10);
        poison(&mut m);
        match id.push(&m) {
            Err(AlgebraicError::Input(InputError::NotFinite { index, field, .. })) => {
                assert_eq!(field, name);
                assert_eq!(index, 10);
            }
            other => panic!("{name}: {other:?}"),
        }
    }
    let msg = {
        let mut m = sample(10);
        m.x = f64::NAN;
        id.push(&m).unwrap_err().to_string()
    };
    assert_eq!(
        msg,
        "sample 10: x = NaN is not finite (the identifier needs finite measurements)"
    );
    // the rejections left no trace
    assert_eq!(id.samples(), 10);
    let (a, b) = (
        id.push(&sample(10)).unwrap(),
        reference.push(&sample(10)).unwrap(),
    );
    assert_eq!(a.values().map(f64::to_bits), b.values().map(f64::to_bits));
}

#[test]
fn constant_speed_mode_ignores_the_speed_fields() {
    let config = AlgebraicConfig::constant_speed(125.0, 0.0).unwrap();
    let mut id = AlgebraicIdentifier::new(known(), 1e-4, config).unwrap();
    for i in 0..5 {
        let mut m = sample(i);
        m.speed = SpeedState {
            phi: f64::NAN,
            omega: f64::NAN,
            omega_dot: f64::NAN,
        };
        id.push(&m).unwrap();
    }
    let mut m = sample(5);
    m.z = f64::NAN;
    assert!(matches!(
        id.push(&m),
        Err(AlgebraicError::Input(InputError::NotFinite {
            field: "z",
            ..
        }))
    ));
}

#[test]
fn non_uniform_or_backward_time_is_rejected_with_the_tolerance() {
    let mut id = AlgebraicIdentifier::new(known(), 1e-4, AlgebraicConfig::default()).unwrap();
    for i in 0..3 {
        id.push(&sample(i)).unwrap();
    }
    // jitter well inside 1e-6 dt is accepted
    let mut m = sample(3);
    m.t += 1e-11;
    id.push(&m).unwrap();
    for bad_t in [5e-4, 4e-4 + 2e-10, 3e-4, 0.0, -1.0] {
        let mut m = sample(4);
        m.t = bad_t;
        match id.push(&m) {
            Err(AlgebraicError::Input(InputError::NonUniformSampling {
                index,
                t,
                expected,
                tolerance,
                dt,
            })) => {
                assert_eq!(index, 4);
                assert_eq!(t, bad_t);
                assert!((expected - (4e-4 + 1e-11)).abs() < 1e-15);
                assert!(tolerance > 1e-10 && tolerance < 1.1e-10, "{tolerance}");
                assert_eq!(dt, 1e-4);
            }
            other => panic!("t = {bad_t}: {other:?}"),
        }
    }
    let mut m = sample(4);
    m.t = 5e-4;
    let msg = id.push(&m).unwrap_err().to_string();
    assert!(
        msg.contains("sample 4 at t = 0.0005 s breaks uniform sampling"),
        "{msg}"
    );
    assert!(msg.contains("1e-6 dt + 8 ulp(t)"), "{msg}");
    // a large absolute time base is fine (tau is counted from the first sample)
    let mut id = AlgebraicIdentifier::new(known(), 1e-4, AlgebraicConfig::default()).unwrap();
    let t0 = 1.7e9;
    for i in 0..50 {
        let mut m = sample(i);
        m.t = t0 + i as f64 * 1e-4;
        id.push(&m).unwrap();
    }
}

#[test]
fn the_first_sample_and_singular_systems_are_nan_not_errors() {
    let mut id = AlgebraicIdentifier::new(known(), 1e-4, AlgebraicConfig::default()).unwrap();
    let e = id.push(&sample(0)).unwrap();
    assert!(e.x.m.is_nan() && e.z.k.is_nan());
    assert_eq!((e.x.rcond, e.z.rcond), (0.0, 0.0));
    assert_eq!(e.well_conditioned(0.0), [false, false]);
    // All-zero data: A = 0 forever; NaN, rcond = 0, no error, no panic.
    let mut id = AlgebraicIdentifier::new(known(), 1e-4, AlgebraicConfig::default()).unwrap();
    for i in 0..100 {
        let m = Measurement {
            t: i as f64 * 1e-4,
            ..Default::default()
        };
        let e = id.push(&m).unwrap();
        assert!(e.values().iter().all(|v| v.is_nan()));
        assert_eq!(e.x.rcond, 0.0);
    }
}

#[test]
fn records_are_checked() {
    let config = AlgebraicConfig::default();
    let mut r = TimeResponse::default();
    assert_eq!(
        identify_response(&r, known(), config).unwrap_err(),
        AlgebraicError::Input(InputError::TooFewSamples { samples: 0 })
    );
    r.t = vec![0.0, 1e-4];
    r.x = vec![0.0; 2];
    r.z = vec![0.0; 1];
    r.phi = vec![0.0; 2];
    r.phi_dot = vec![0.0; 2];
    r.phi_ddot = vec![0.0; 2];
    let e = identify_response(&r, known(), config).unwrap_err();
    assert_eq!(
        e,
        AlgebraicError::Input(InputError::ColumnLength {
            column: "z",
            len: 1,
            expected: 2
        })
    );
    r.z = vec![0.0; 2];
    assert_eq!(identify_response(&r, known(), config).unwrap().len(), 2);
    r.t = vec![0.0, 0.0];
    assert!(identify_response(&r, known(), config).is_err());
    let ms: Vec<Measurement> = (0..5).map(sample).collect();
    assert!(identify_batch(&ms, known(), -1.0, config).is_err());
    let mut bad = ms.clone();
    bad[3].t = 1.0;
    assert!(matches!(
        identify_batch(&bad, known(), 1e-4, config),
        Err(AlgebraicError::Input(InputError::NonUniformSampling {
            index: 3,
            ..
        }))
    ));
    assert!("simpson".parse::<Quadrature>().is_err());
}
