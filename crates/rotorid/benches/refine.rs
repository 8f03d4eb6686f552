//! Benchmarks for `refine`: the maximum-likelihood fit of m, cx, kx, cz, kz and the
//! initial state on 1 s at 10 kHz (two channels, SNR 40 dB), from the algebraic
//! identifier's estimate at t = 0.05 s and from a start 1 % off; constant 1200 rpm (exact
//! discretisation) and the 10 rad/s^2 ramp from 600 rpm (RK4, 2 sub-steps). Also one
//! model pass with sensitivities (`crb`) and without (`model_response`).
//!
//! Run: `CARGO_TARGET_DIR=/work/target-refine cargo bench -p rotorid --bench refine`

use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use rotorid::identify::algebraic::{identify_response, AlgebraicConfig};
use rotorid::identify::Known;
use rotorid::model::{InitialState, RotorParams, Scenario};
use rotorid::refine::{
    crb_at_snr, model_response, refine, Discretisation, Experiment, Record, RefineOptions, Unknowns,
};
use rotorid::simulate::{add_noise, simulate, Method, TimeResponse};

fn noisy(s: &Scenario) -> TimeResponse {
    let mut r = simulate(s, Method::Exact).expect("simulate");
    add_noise(&mut r, 40.0, 42).expect("noise");
    r
}

/// The algebraic identifier's estimate at t = 0.05 s (before noise makes it drift).
fn algebraic_start(s: &Scenario, r: &TimeResponse) -> RotorParams {
    let est = identify_response(r, Known::from_rotor(&s.rotor), AlgebraicConfig::default())
        .expect("identify");
    let e = est[500];
    RotorParams {
        m: 0.5 * (e.x.m + e.z.m),
        cx: e.x.c,
        kx: e.x.k,
        cz: e.z.c,
        kz: e.z.k,
        ..s.rotor.params()
    }
}

fn one_percent_off(p: &RotorParams) -> RotorParams {
    RotorParams {
        m: p.m * 1.01,
        cx: p.cx * 0.99,
        kx: p.kx * 0.99,
        cz: p.cz * 1.01,
        kz: p.kz * 1.01,
        ..*p
    }
}

fn bench_refine(c: &mut Criterion) {
    let mut g = c.benchmark_group("refine");
    g.sample_size(20)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2));
    for (label, s) in [
        ("1200rpm", Scenario::table1()),
        ("ramp600", Scenario::table1_ramp(600.0).expect("ramp")),
    ] {
        let r = noisy(&s);
        let rec = Record::from_simulation(&s, &r);
        let opts = RefineOptions::default();
        for (start_label, start) in [
            ("algebraic_start", algebraic_start(&s, &r)),
            ("1pct_start", one_percent_off(&s.rotor.params())),
        ] {
            let fit = refine(&rec, &start, &InitialState::default(), &opts).expect("refine");
            assert!(fit.converged && fit.identifiable, "{:?}", fit.warnings);
            println!(
                "{label}/{start_label}: {} model passes, m = {:.6} +- {:.2e} kg, {}",
                fit.iterations,
                fit.get("m").expect("m").value,
                fit.get("m").expect("m").std_error,
                fit.discretisation
            );
            g.bench_function(format!("{label}_40dB_1s_10kHz/{start_label}"), |b| {
                b.iter(|| refine(&rec, &start, &InitialState::default(), &opts).expect("refine"))
            });
        }
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

criterion_group!(benches, bench_refine);
criterion_main!(benches);
