//! Input validation (errors name the input and the allowed range), measured speed data,
//! attaching the bound to a result, serialisability.

use rotorid::model::{InitialState, RotorParams, Scenario};
use rotorid::refine::{
    crb_at_snr, refine, Record, RefineError, RefineOptions, Refined, SpeedData, Unknowns,
};
use rotorid::simulate::{add_noise, simulate, Method};

fn table1_record_data() -> (Scenario, Vec<f64>, Vec<f64>) {
    let s = Scenario::table1();
    let r = simulate(&s, Method::Exact).unwrap();
    (s, r.x, r.z)
}

#[test]
fn bad_inputs_are_rejected_with_their_name_and_range() {
    let (s, x, z) = table1_record_data();
    let p = s.rotor.params();
    let y0 = InitialState::default();
    let opts = RefineOptions::default();
    let rec = |dt: f64, x: &'static [f64], z: &'static [f64]| Record {
        dt,
        x,
        z,
        speed: SpeedData::Profile(s.speed),
    };
    let x: &'static [f64] = Box::leak(x.into_boxed_slice());
    let z: &'static [f64] = Box::leak(z.into_boxed_slice());

    let e = refine(&rec(-1.0, x, z), &p, &y0, &opts).unwrap_err();
    assert_eq!(
        e.to_string(),
        "dt = -1 is out of range: must be finite and > 0 (s)"
    );

    let e = refine(&rec(1e-4, x, &z[1..]), &p, &y0, &opts).unwrap_err();
    assert!(
        matches!(e, RefineError::LengthMismatch { field: "z", .. }),
        "{e}"
    );

    let mut bad = x.to_vec();
    bad[17] = f64::NAN;
    let bad: &'static [f64] = Box::leak(bad.into_boxed_slice());
    let e = refine(&rec(1e-4, bad, z), &p, &y0, &opts).unwrap_err();
    assert_eq!(
        e.to_string(),
        "x[17] = NaN is not finite: every sample must be a finite number"
    );

    let e = refine(&rec(1e-4, x, z), &RotorParams { m: 0.0, ..p }, &y0, &opts).unwrap_err();
    assert_eq!(
        e.to_string(),
        "m = 0 is out of range: must be finite and > 0 (kg)"
    );

    let none = RefineOptions {
        unknowns: Unknowns {
            cxz: false,
            czx: false,
            kxz: false,
            kzx: false,
            m: false,
            cx: false,
            kx: false,
            cz: false,
            kz: false,
            a: false,
            unbalance: false,
            initial_state: false,
        },
        ..opts
    };
    assert_eq!(
        refine(&rec(1e-4, x, z), &p, &y0, &none).unwrap_err(),
        RefineError::NoUnknowns
    );

    let e = refine(&rec(1e-4, &x[..5], &z[..5]), &p, &y0, &opts).unwrap_err();
    assert!(
        matches!(
            e,
            RefineError::TooFewSamples {
                samples: 5,
                unknowns: 9,
                ..
            }
        ),
        "{e}"
    );

    let e = refine(
        &rec(1e-4, x, z),
        &p,
        &y0,
        &RefineOptions {
            tolerance: 0.0,
            ..opts
        },
    )
    .unwrap_err();
    assert!(
        e.to_string().starts_with("tolerance = 0 is out of range"),
        "{e}"
    );

    let omega = vec![1.0; 3];
    let e = refine(
        &Record {
            speed: SpeedData::Samples {
                phi: &omega,
                omega: &omega,
                omega_dot: &omega,
            },
            ..rec(1e-4, x, z)
        },
        &p,
        &y0,
        &opts,
    )
    .unwrap_err();
    assert!(
        matches!(
            e,
            RefineError::LengthMismatch {
                field: "phi",
                len: 3,
                ..
            }
        ),
        "{e}"
    );

    let e = crb_at_snr(&s, f64::NAN, &Unknowns::default()).unwrap_err();
    assert!(
        e.to_string().starts_with("snr_db = NaN is out of range"),
        "{e}"
    );
}

#[test]
fn measured_speed_samples_give_the_same_fit_as_the_profile() {
    let s = Scenario::table1_ramp(600.0).unwrap();
    let mut r = simulate(&s, Method::Exact).unwrap();
    add_noise(&mut r, 40.0, 3).unwrap();
    let start = RotorParams {
        m: s.rotor.m() * 1.01,
        ..s.rotor.params()
    };
    let y0 = InitialState::default();
    let opts = RefineOptions::default();
    let a = refine(&Record::from_simulation(&s, &r), &start, &y0, &opts).unwrap();
    let b = refine(&Record::from_simulation_samples(&s, &r), &start, &y0, &opts).unwrap();
    for (ea, eb) in a.parameters.iter().zip(&b.parameters) {
        assert!(
            (ea.value - eb.value).abs() < 1e-3 * ea.std_error,
            "{}: {} vs {}",
            ea.name,
            ea.value,
            eb.value
        );
    }
}

#[test]
fn the_bound_can_be_attached_and_the_result_serialised() {
    fn serialisable<T: serde::Serialize>(_: &T) {}
    let s = Scenario::table1();
    let mut r = simulate(&s, Method::Exact).unwrap();
    add_noise(&mut r, 40.0, 5).unwrap();
    let mut fit: Refined = refine(
        &Record::from_simulation(&s, &r),
        &s.rotor.params(),
        &InitialState::default(),
        &RefineOptions::default(),
    )
    .unwrap();
    let bound = crb_at_snr(&s, 40.0, &Unknowns::default()).unwrap();
    fit.attach_crb(&bound);
    let m = fit.get("m").unwrap();
    assert_eq!(m.crb, Some(bound.get("m").unwrap().std_dev));
    // the standard error at the estimate with the estimated sigma is close to the bound
    assert!((m.std_error / m.crb.unwrap() - 1.0).abs() < 0.05);
    assert!(fit.get("x0").unwrap().crb.is_some());
    assert_eq!(fit.covariance_names.len(), 9);
    assert_eq!(fit.covariance.len(), 9);
    serialisable(&fit);
    serialisable(&bound);
    // sigma is estimated from the residuals: close to the noise that was added
    let (nx, _) = (bound.sigma_x, bound.sigma_z);
    assert!(
        (fit.sigma_x / nx - 1.0).abs() < 0.03,
        "{} vs {nx}",
        fit.sigma_x
    );
}
