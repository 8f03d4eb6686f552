//! Benchmarks for `refine`: the maximum-likelihood fit of m, cx, kx, cz, kz and the
//! initial state on 1 s at 10 kHz (two channels, SNR 40 dB), from a start 1 % off and end
//! to end through the pipeline (its own start, the fit, the bound); constant 1200 rpm (exact
//! discretisation) and the 10 rad/s^2 ramp from 600 rpm (RK4, 2 sub-steps). Also one
//! model pass with sensitivities (`crb`) and without (`model_response`).
//!
//! The cross-coupled model (docs/method.md section 5.6): m and its eight bearing
//! coefficients with the initial state, on its test rotor at 1200 rpm and on the same
//! ramp, from a start 2-20 % off with zero cross terms (target: at most 3x the Jeffcott
//! fit's time).
//!
//! Run: `cargo bench -p rotorid --bench refine`

use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use rotorid::model::InitialState;
use rotorid::parameter::ModelKind;
use rotorid::pipeline::{identify, Method as IdMethod};
use rotorid::refine::{
    crb_at_snr, model_response, refine, Discretisation, Experiment, Record, RefineOptions, Unknowns,
};
use rotorid::test_models::{
    cross_coupled, cross_coupled_ramp, perturbed_start, table1, table1_ramp, TestModel,
};

/// The pipeline's refinement with its own start (modulating estimate) on `m`: what a
/// caller gets end to end.
fn pipeline_refine(m: &TestModel) -> rotorid::pipeline::Identification {
    identify(&m.record(), &m.knowledge(), &IdMethod::refine()).expect("identify")
}

fn bench_refine(c: &mut Criterion) {
    let mut g = c.benchmark_group("refine");
    g.sample_size(20)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2));
    for (label, model) in [("1200rpm", table1()), ("ramp600", table1_ramp(600.0))] {
        let m = model.with_noise(40.0, 42);
        let s = m.scenario;
        let rec = Record::from_simulation(&s, &m.response);
        let opts = RefineOptions::default();
        let start = perturbed_start(&m.truth());
        let fit = refine(&rec, &start, &InitialState::default(), &opts).expect("refine");
        assert!(fit.converged && fit.identifiable, "{:?}", fit.warnings);
        println!(
            "{label}/1pct_start: {} model passes, m = {:.6} +- {:.2e} kg, {}",
            fit.iterations,
            fit.get("m").expect("m").value,
            fit.get("m").expect("m").std_error,
            fit.discretisation
        );
        g.bench_function(format!("{label}_40dB_1s_10kHz/1pct_start"), |b| {
            b.iter(|| refine(&rec, &start, &InitialState::default(), &opts).expect("refine"))
        });
        // end to end: the pipeline's start (modulating over the record), fit, bound
        g.bench_function(format!("{label}_40dB_1s_10kHz/pipeline"), |b| {
            b.iter(|| pipeline_refine(&m))
        });
        // one model pass with the 9 sensitivity columns (plus the Fisher analysis)
        g.bench_function(format!("{label}_one_pass_with_sensitivities/crb"), |b| {
            b.iter(|| crb_at_snr(&s, 40.0, &Unknowns::default()).expect("crb"))
        });
        let exp = Experiment::from_scenario(&s);
        let p = s.rotor.params();
        g.bench_function(format!("{label}_one_pass_response_only"), |b| {
            b.iter(|| model_response(&p, &s.initial, &exp, Discretisation::Auto).expect("response"))
        });
    }
    g.finish();
}

/// The cross-coupled start of the tests (tests/it/refine_cross.rs).
fn cross_start(truth: &rotorid::RotorParams) -> rotorid::RotorParams {
    let mut p = *truth;
    p.m *= 1.02;
    p.kx *= 0.97;
    p.kz *= 1.03;
    p.cx *= 1.2;
    p.cz *= 0.8;
    p.coupling = Some(Default::default());
    p
}

fn bench_refine_cross(c: &mut Criterion) {
    let mut g = c.benchmark_group("refine_cross");
    g.sample_size(20)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2));
    for (label, model) in [
        ("1200rpm", cross_coupled()),
        ("ramp600", cross_coupled_ramp(600.0)),
    ] {
        let m = model.with_noise(40.0, 42);
        let rec = Record::from_simulation(&m.scenario, &m.response);
        let opts = RefineOptions {
            unknowns: Unknowns::for_model(ModelKind::CrossCoupled),
            ..RefineOptions::default()
        };
        let start = cross_start(&m.truth());
        let fit = refine(&rec, &start, &InitialState::default(), &opts).expect("refine");
        assert!(fit.converged && fit.identifiable, "{:?}", fit.warnings);
        println!(
            "cross {label}: {} model passes, kxz = {:.1} +- {:.1} N/m, {}",
            fit.iterations,
            fit.get("kxz").expect("kxz").value,
            fit.get("kxz").expect("kxz").std_error,
            fit.discretisation
        );
        g.bench_function(format!("{label}_40dB_1s_10kHz/start_off"), |b| {
            b.iter(|| refine(&rec, &start, &InitialState::default(), &opts).expect("refine"))
        });
    }
    g.finish();
}

criterion_group!(benches, bench_refine, bench_refine_cross);
criterion_main!(benches);
