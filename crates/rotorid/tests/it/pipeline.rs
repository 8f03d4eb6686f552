//! The pipeline against the identifiers and the refinement called directly (independent
//! paths to the same numbers), the streaming session against the batch, the time grid of
//! rounded stamps, and its diagnostics.

use rotorid::identify::algebraic::{identify_response, AlgebraicConfig, ConvergenceTracker};
use rotorid::identify::modulating::{identify_modulating_response, ModulatingConfig};
use rotorid::identify::Known;
use rotorid::model::InitialState;
use rotorid::pipeline::{
    identify, Finding, Knowledge, Method, PipelineError, Record, Sample, Session, Speed, Timing,
};
use rotorid::refine::{refine, RefineOptions};
use rotorid::test_models::{table1, table1_ramp};
use rotorid::Parameter;

#[test]
fn algebraic_equals_the_identifier_and_its_tracker() {
    for model in [table1(), table1_ramp(600.0).with_noise(40.0, 3)] {
        let rec = model.record();
        let id = identify(&rec, &model.knowledge(), &Method::algebraic()).unwrap();
        let direct = identify_response(
            &model.response,
            Known::from_rotor(&model.scenario.rotor),
            AlgebraicConfig::default(),
        )
        .unwrap();
        // bit for bit (NaN at the singular first samples included)
        let bits = |e: &[rotorid::identify::algebraic::AlgebraicEstimate]| -> Vec<u64> {
            e.iter()
                .flat_map(|e| {
                    let (x, z) = (e.x, e.z);
                    [e.t, x.m, x.c, x.k, x.rcond, z.m, z.c, z.k, z.rcond].map(f64::to_bits)
                })
                .collect()
        };
        let session_bits: Vec<u64> = id
            .estimates
            .iter()
            .flat_map(|e| {
                let v = e.values();
                [
                    e.t, v[0], v[1], v[2], e.rcond[0], v[3], v[4], v[5], e.rcond[1],
                ]
                .map(f64::to_bits)
            })
            .collect();
        assert!(session_bits == bits(&direct), "{}", model.name);
        let mut tr = ConvergenceTracker::new(0.01, AlgebraicConfig::default().rcond_min).unwrap();
        direct.iter().for_each(|e| tr.push(e));
        for r in tr.results() {
            let p = id.parameter(r.parameter).unwrap();
            assert_eq!(p.estimate, r.final_value, "{}", model.name);
            // reported where physical, withheld (and never converged) where not
            let physical = r.final_value.is_some_and(|v| {
                v >= 0.0 && (v > 0.0 || matches!(r.parameter, Parameter::Cx | Parameter::Cz))
            });
            if physical {
                assert_eq!(p.value, r.final_value, "{}", model.name);
                assert_eq!(p.identification_time_s, r.identification_time);
            } else {
                assert_eq!((p.value, p.identification_time_s), (None, None));
            }
        }
    }
}

#[test]
fn modulating_equals_the_identifier() {
    let model = table1().with_noise(40.0, 5);
    let id = identify(&model.record(), &model.knowledge(), &Method::modulating()).unwrap();
    let known = Known::from_rotor(&model.scenario.rotor);
    let e =
        identify_modulating_response(&model.response, known, ModulatingConfig::default()).unwrap();
    let values = e.values();
    let std = e.std_errors();
    for (i, p) in Parameter::PER_DIRECTION.into_iter().enumerate() {
        let r = id.parameter(p).unwrap();
        assert_eq!(r.value, Some(values[i]), "{p}");
        assert_eq!(r.std_error, Some(std[i]), "{p}");
    }
    let noise = id.noise.unwrap();
    assert_eq!((noise.sigma_x_m, noise.sigma_z_m), (e.sigma_x, e.sigma_z));
}

#[test]
fn refine_from_the_same_start_equals_refine_called_directly() {
    let model = table1().with_noise(40.0, 9);
    let rec = model.record();
    let id = identify(&rec, &model.knowledge(), &Method::refine()).unwrap();
    let detail = id.refine.as_ref().unwrap();
    let s = &detail.start.values;
    let v = |p: Parameter| s.get(p).unwrap();
    let start = rotorid::RotorParams {
        m: v(Parameter::M),
        cx: v(Parameter::Cx),
        kx: v(Parameter::Kx),
        cz: v(Parameter::Cz),
        kz: v(Parameter::Kz),
        ..model.truth()
    };
    let direct = refine(
        &rec.for_refine(),
        &start,
        &InitialState::default(),
        &RefineOptions::default(),
    )
    .unwrap();
    for e in &direct.parameters {
        let p: Parameter = e.name.parse().unwrap();
        let r = id.parameter(p).unwrap();
        assert_eq!(r.estimate, Some(e.value), "{p}");
        assert_eq!(r.std_error, Some(e.std_error), "{p}");
        // within 4 standard errors of the truth, at the Cramer-Rao bound
        let truth = r.truth.unwrap();
        assert!((e.value - truth).abs() < 4.0 * e.std_error, "{p}");
        let crb = r.crb.unwrap();
        assert!(
            (crb / e.std_error - 1.0).abs() < 0.2,
            "{p}: crb {crb} std {}",
            e.std_error
        );
    }
    assert!(id.diagnostics.is_empty(), "{:?}", id.warnings());
}

/// Push every sample of `rec` into a session with `timing` and finish it.
fn stream(
    model: &rotorid::test_models::TestModel,
    method: &Method,
    timing: Timing,
) -> rotorid::pipeline::Identification {
    let r = &model.response;
    let mut s = Session::new(&model.knowledge(), method, None, timing).unwrap();
    let mut n = 0;
    for i in 0..r.t.len() {
        let sample = Sample {
            t: Some(r.t[i]),
            x: r.x[i],
            z: r.z[i],
            speed: Some(rotorid::SpeedState {
                phi: r.phi[i],
                omega: r.phi_dot[i],
                omega_dot: r.phi_ddot[i],
            }),
        };
        s.push(&sample, &mut |_| n += 1).unwrap();
    }
    let id = s.finish(&mut |_| n += 1).unwrap();
    if matches!(method, Method::Algebraic(_)) {
        assert_eq!(n, r.t.len(), "one estimate per sample");
    }
    id
}

#[test]
fn a_session_gives_the_batch_result() {
    let model = table1_ramp(600.0).with_noise(40.0, 11);
    for method in [Method::algebraic(), Method::modulating(), Method::refine()] {
        let batch = identify(&model.record(), &model.knowledge(), &method).unwrap();
        for timing in [
            Timing::default(),
            Timing::Fit {
                head: 2,
                tolerance: 1e-6,
            },
        ] {
            let streamed = stream(&model, &method, timing);
            for p in &batch.parameters {
                assert_eq!(
                    streamed.parameter(p.parameter).unwrap().value,
                    p.value,
                    "{:?} {timing:?} {}",
                    method.name(),
                    p.parameter
                );
            }
        }
    }
}

#[test]
fn rounded_stamps_give_the_true_period_and_the_same_estimates() {
    // 25.6 kHz written with 6 decimals: the first two stamps say 3.9e-5 s (0.16 % off).
    let mut s = rotorid::Scenario::table1();
    s.sampling = rotorid::Sampling::new(1.0 / 25600.0, 0.5).unwrap();
    let model = rotorid::test_models::TestModel::clean("table1@25.6kHz", s).with_noise(40.0, 2);
    let exact = model.record();
    let rounded: Vec<f64> = model
        .response
        .t
        .iter()
        .map(|t| (t * 1e6).round() / 1e6)
        .collect();
    // accepted at the default tolerance: rounding to the stamps' 6th decimal explains
    // their deviation (the same grid as a tolerance wide enough to hide it)
    let rec = Record::new(
        rounded.clone(),
        model.response.x.clone(),
        model.response.z.clone(),
        Speed::Profile(s.speed),
        rotorid::pipeline::DEFAULT_TIME_TOLERANCE,
    )
    .unwrap();
    let wide = Record::new(
        rounded,
        model.response.x.clone(),
        model.response.z.clone(),
        Speed::Profile(s.speed),
        0.02,
    )
    .unwrap();
    assert_eq!(rec.grid().dt, wide.grid().dt);
    assert!(rec.grid().rounded && !wide.grid().rounded);
    let dt = 1.0 / 25600.0;
    assert!((rec.grid().dt - dt).abs() < 1e-7 * dt, "{}", rec.grid().dt);
    let k = Knowledge::from_scenario(&s);
    let a = identify(&exact, &k, &Method::refine()).unwrap();
    let b = identify(&rec, &k, &Method::refine()).unwrap();
    // the note, with the resolution and the largest deviation
    let note = b
        .diagnostics
        .iter()
        .find(|d| {
            matches!(
                d.finding,
                rotorid::pipeline::Finding::TimeStampsRounded { .. }
            )
        })
        .expect("a note");
    assert_eq!(note.severity, rotorid::pipeline::Severity::Note);
    assert!(
        note.message.contains("printed to 1e-6 s"),
        "{}",
        note.message
    );
    assert!(a
        .diagnostics
        .iter()
        .all(|d| d.severity != rotorid::pipeline::Severity::Note));
    for p in &a.parameters {
        let (va, vb) = (p.value.unwrap(), b.value(p.parameter).unwrap());
        // far below the statistical error (the old first-two-stamps dt moved k by 0.36 %)
        assert!(
            (va - vb).abs() < 0.05 * p.std_error.unwrap(),
            "{}: {va} vs {vb}",
            p.parameter
        );
    }
}

#[test]
fn a_stream_whose_first_stamps_mislead_is_warned() {
    // A grid fitted over the first 2 stamps of a record whose stamps are rounded: the
    // period of all stamps differs, and the result says so.
    let model = table1();
    let r = &model.response;
    let mut s = Session::new(
        &model.knowledge(),
        &Method::modulating(),
        Some(model.scenario.speed),
        Timing::Fit {
            head: 2,
            tolerance: 0.2,
        },
    )
    .unwrap();
    for i in 0..r.t.len() {
        let t = if i == 1 { r.t[1] * 1.05 } else { r.t[i] };
        let sample = Sample {
            t: Some(t),
            x: r.x[i],
            z: r.z[i],
            speed: None,
        };
        s.push(&sample, &mut |_| {}).unwrap();
    }
    let id = s.finish(&mut |_| {}).unwrap();
    assert!(
        id.diagnostics
            .iter()
            .any(|d| matches!(d.finding, Finding::TimeGridDrift { .. })),
        "{:?}",
        id.warnings()
    );
}

#[test]
fn stamps_on_a_given_grid_report_their_largest_deviation_and_refuse_one_too_far() {
    // Stamps jittered by up to 0.3 dt about a given grid: the summary's deviation is the
    // largest |t_i - (t0 + i dt)|, computed here directly; a stamp 0.5 dt off with a
    // tolerance of 0.4 is refused with its index, and the samples before it were taken.
    let model = table1();
    let r = &model.response;
    let (t0, dt) = (r.t[0], r.t[1] - r.t[0]);
    let jitter = |i: usize| 0.3 * dt * ((i as f64) * 0.7).sin();
    let session = || {
        let timing = Timing::Grid {
            grid: rotorid::pipeline::TimeGrid::given(t0, dt).unwrap(),
            tolerance: 0.4,
        };
        Session::new(
            &model.knowledge(),
            &Method::algebraic(),
            Some(model.scenario.speed),
            timing,
        )
        .unwrap()
    };
    let sample = |i: usize, t: f64| Sample {
        t: Some(t),
        x: r.x[i],
        z: r.z[i],
        speed: None,
    };
    let mut s = session();
    let mut worst = 0.0_f64;
    for i in 0..r.t.len() {
        let t = t0 + i as f64 * dt + jitter(i);
        worst = worst.max((t - (t0 + i as f64 * dt)).abs());
        s.push(&sample(i, t), &mut |_| {}).unwrap();
    }
    let id = s.finish(&mut |_| {}).unwrap();
    assert_eq!(id.record.max_time_deviation_s, worst);
    assert!(worst > 0.29 * dt, "{worst}");
    assert_eq!(id.record.grid_fitted_over, 0);

    let mut s = session();
    for i in 0..7 {
        s.push(&sample(i, t0 + i as f64 * dt), &mut |_| {}).unwrap();
    }
    match s.push(&sample(7, t0 + 7.5 * dt), &mut |_| {}) {
        Err(PipelineError::NonUniformSampling {
            index,
            deviation,
            tolerance,
            ..
        }) => {
            assert_eq!(index, 7);
            assert!((deviation / dt - 0.5).abs() < 1e-9, "{deviation}");
            assert_eq!(tolerance, 0.4);
        }
        other => panic!("{other:?}"),
    }
}

#[test]
fn too_short_records_name_what_they_need() {
    let model = table1();
    let r = &model.response;
    let rec = Record::new(
        r.t[..3].to_vec(),
        r.x[..3].to_vec(),
        r.z[..3].to_vec(),
        Speed::Profile(model.scenario.speed),
        1e-6,
    )
    .unwrap();
    for method in [Method::algebraic(), Method::refine()] {
        match identify(&rec, &model.knowledge(), &method) {
            Err(PipelineError::TooFewSamples {
                samples: 3,
                needed: 4,
                ..
            }) => {}
            other => panic!("{:?}: {other:?}", method.name()),
        }
    }
    assert!(matches!(
        identify(&rec, &model.knowledge(), &Method::modulating()),
        Err(PipelineError::Modulating(_))
    ));
}

/// `model`'s record with its speed columns transformed by `f(phi, phi_dot, phi_ddot)`.
fn with_speed(
    model: &rotorid::test_models::TestModel,
    f: impl Fn(f64, f64, f64) -> (f64, f64, f64),
) -> Record {
    let r = &model.response;
    let (mut phi, mut w, mut a) = (Vec::new(), Vec::new(), Vec::new());
    for i in 0..r.t.len() {
        let (p, v, c) = f(r.phi[i], r.phi_dot[i], r.phi_ddot[i]);
        phi.push(p);
        w.push(v);
        a.push(c);
    }
    let speed = Speed::Samples {
        phi,
        omega: w,
        omega_dot: a,
    };
    Record::new(r.t.clone(), r.x.clone(), r.z.clone(), speed, 1e-6).unwrap()
}

#[test]
fn speed_columns_in_other_units_are_named_and_every_value_withheld() {
    let ramp = table1_ramp(600.0).with_noise(40.0, 21);
    let k = ramp.knowledge();
    let rpm = 60.0 / std::f64::consts::TAU;
    for method in [Method::algebraic(), Method::modulating(), Method::refine()] {
        // phi_dot in rpm: refine reported m = 44 +- 2e-5 kg (truth 14.29) without a word
        let id = identify(&with_speed(&ramp, |p, w, a| (p, w * rpm, a)), &k, &method).unwrap();
        let d = &id.diagnostics[0];
        assert!(
            d.message.starts_with("phi_dot is 9.549") && d.message.contains("rpm given as rad/s"),
            "{:?}: {}",
            method.name(),
            d.message
        );
        assert!(id
            .parameters
            .iter()
            .all(|p| p.value.is_none() && !p.determined));
        assert!(id.rotor.is_none());
        // phi_ddot in rpm/s
        let id = identify(&with_speed(&ramp, |p, w, a| (p, w, a * rpm)), &k, &method).unwrap();
        assert!(
            id.diagnostics[0].message.starts_with("phi_ddot is 9.549"),
            "{:?}",
            id.warnings()
        );
        // the model's own columns, even with phi wrapped to [0, 2 pi): nothing to say
        let tau = std::f64::consts::TAU;
        let id = identify(
            &with_speed(&ramp, |p, w, a| (p.rem_euclid(tau), w, a)),
            &k,
            &method,
        )
        .unwrap();
        assert!(
            !id.diagnostics
                .iter()
                .any(|d| matches!(d.finding, Finding::SpeedInconsistent { .. })),
            "{:?}",
            id.warnings()
        );
    }
    // phi in degrees
    let c = table1().with_noise(40.0, 22);
    let id = identify(
        &with_speed(&c, |p, w, a| (p.to_degrees(), w, a)),
        &c.knowledge(),
        &Method::modulating(),
    )
    .unwrap();
    assert!(
        id.diagnostics[0].message.contains("phi in degrees?"),
        "{:?}",
        id.warnings()
    );
}

#[test]
fn a_scenario_speed_that_disagrees_with_the_data_is_said() {
    // the data at 1200 rpm, the scenario's profile at 1260 rpm: warned, values kept
    let model = table1().with_noise(40.0, 23);
    let r = &model.response;
    let wrong = rotorid::SpeedProfile::constant_rpm(1260.0, 0.0).unwrap();
    for method in [Method::modulating(), Method::refine()] {
        let mut s =
            Session::new(&model.knowledge(), &method, Some(wrong), Timing::default()).unwrap();
        for i in 0..r.t.len() {
            let speed = Some(rotorid::SpeedState {
                phi: r.phi[i],
                omega: r.phi_dot[i],
                omega_dot: r.phi_ddot[i],
            });
            s.push(
                &Sample {
                    t: Some(r.t[i]),
                    x: r.x[i],
                    z: r.z[i],
                    speed,
                },
                &mut |_| {},
            )
            .unwrap();
        }
        let id = s.finish(&mut |_| {}).unwrap();
        assert!(
            id.warnings()
                .iter()
                .any(|w| w.contains("0.9524x the speed of the scenario")),
            "{:?}",
            id.warnings()
        );
        assert!(id.value(Parameter::Kx).is_some());
    }
}

#[test]
fn displacements_in_the_wrong_unit_are_warned_by_every_method() {
    // "Micrometres given as metres": x and z a million times too large; and metres
    // labelled as micrometres (converted once too often): a million times too small
    let model = table1().with_noise(40.0, 31);
    let r = &model.response;
    let k = model.knowledge();
    let speed = |r: &rotorid::simulate::TimeResponse| Speed::Samples {
        phi: r.phi.clone(),
        omega: r.phi_dot.clone(),
        omega_dot: r.phi_ddot.clone(),
    };
    for (scale, says) in [
        (1e6, "more than a proximity probe"),
        (1e-6, "below any probe"),
    ] {
        let x: Vec<f64> = r.x.iter().map(|v| v * scale).collect();
        let z: Vec<f64> = r.z.iter().map(|v| v * scale).collect();
        let rec = Record::new(r.t.clone(), x, z, speed(r), 1e-6).unwrap();
        for method in [Method::algebraic(), Method::modulating(), Method::refine()] {
            let id = identify(&rec, &k, &method).unwrap();
            let found: Vec<_> = id
                .diagnostics
                .iter()
                .filter(|d| matches!(d.finding, Finding::ImplausibleDisplacement { .. }))
                .collect();
            assert_eq!(
                found.len(),
                2,
                "{:?} x{scale}: {:?}",
                method.name(),
                id.warnings()
            );
            assert!(found[0].message.contains(says), "{}", found[0].message);
        }
    }
    // the record as simulated (about 20 um): nothing of the kind
    let rec = Record::new(r.t.clone(), r.x.clone(), r.z.clone(), speed(r), 1e-6).unwrap();
    for method in [Method::algebraic(), Method::modulating(), Method::refine()] {
        let id = identify(&rec, &k, &method).unwrap();
        assert!(
            !id.diagnostics.iter().any(|d| matches!(
                d.finding,
                Finding::ImplausibleDisplacement { .. } | Finding::NoiseDominates { .. }
            )),
            "{:?}",
            id.warnings()
        );
    }
}

#[test]
fn modulating_reports_the_cramer_rao_bound() {
    use rotorid::pipeline::CrbAt;
    use rotorid::refine::Unknowns;
    for model in [
        table1().with_noise(40.0, 41),
        table1_ramp(600.0).with_noise(40.0, 42),
    ] {
        let rec = model.record();
        // reference: the bound at the truth for the noise actually added (crb_at_snr)
        let reference = model.crb(&Unknowns::default()).unwrap();
        let sigma_ratio = |id: &rotorid::pipeline::Identification| {
            let n = id.noise.unwrap();
            (
                n.sigma_x_m / reference.sigma_x,
                n.sigma_z_m / reference.sigma_z,
            )
        };
        let with_truth = identify(&rec, &model.knowledge(), &Method::modulating()).unwrap();
        assert_eq!(
            with_truth.modulating.as_ref().unwrap().crb_at,
            Some(CrbAt::Truth)
        );
        let (rx, rz) = sigma_ratio(&with_truth);
        // the bound scales with sigma; both noise levels are within a few % of the truth's
        assert!(
            (rx - 1.0).abs() < 0.05 && (rz - 1.0).abs() < 0.05,
            "{rx} {rz}"
        );
        let mut blind = model.knowledge();
        blind.truth = None;
        let at_estimate = identify(&rec, &blind, &Method::modulating()).unwrap();
        assert_eq!(
            at_estimate.modulating.as_ref().unwrap().crb_at,
            Some(CrbAt::Estimate)
        );
        for p in Parameter::PER_DIRECTION {
            let want = reference.get(p.physical().name()).unwrap().std_dev;
            let got = with_truth.parameter(p).unwrap().crb.unwrap();
            assert!(
                (got / want - 1.0).abs() < 0.1,
                "{} {p}: {got:e} vs {want:e}",
                model.name
            );
            // at the estimate, with the initial state fitted: close to the truth's bound
            let est = at_estimate.parameter(p).unwrap().crb.unwrap();
            assert!(
                (est / got - 1.0).abs() < 0.1,
                "{} {p}: {est:e} vs {got:e}",
                model.name
            );
            // no unbiased estimator beats it: the modulating standard errors are above
            let se = with_truth.parameter(p).unwrap().std_error.unwrap();
            assert!(
                se >= 0.9 * got,
                "{} {p}: se {se:e} < crb {got:e}",
                model.name
            );
            eprintln!("{} {p}: modulating se / crb = {:.2}", model.name, se / got);
        }
    }
}

#[test]
fn the_algebraic_identifier_under_noise_says_it_has_not_settled() {
    // the paper's identifier at 40 dB: its late estimates are noise (docs/method.md 3.8)
    let model = table1().with_noise(40.0, 51);
    let id = identify(&model.record(), &model.knowledge(), &Method::algebraic()).unwrap();
    let unsettled = id.diagnostics.iter().find_map(|d| match &d.finding {
        Finding::AlgebraicUnsettled { parameters } => Some(parameters.clone()),
        _ => None,
    });
    let unsettled = unsettled.expect("warned");
    assert!(!unsettled.is_empty());
    // whatever is reported is physical, and every unsettled one is named in the message
    for p in &id.parameters {
        if let Some(v) = p.value {
            let c = matches!(p.parameter, Parameter::Cx | Parameter::Cz);
            assert!(if c { v >= 0.0 } else { v > 0.0 }, "{p:?}");
        }
    }
    let msg = &id
        .diagnostics
        .iter()
        .find(|d| matches!(d.finding, Finding::AlgebraicUnsettled { .. }))
        .unwrap()
        .message;
    assert!(msg.contains("--method modulating or refine"), "{msg}");
    for p in unsettled {
        assert!(msg.contains(p.name()), "{msg}");
    }
}
