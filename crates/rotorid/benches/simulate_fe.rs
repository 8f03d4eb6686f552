//! Throughput of the finite-element simulators on the ROSS two-disk rotor (44 DOF,
//! `tests/it/fe_fixture`): 1 s at 10 kHz, response at four probes (x, y at both
//! bearings), the full model against the reduced one (8 modes + static shapes, r = 20),
//! at constant speed (exact discretisation) and on a run-up (Magnus; Newmark on the full
//! model for reference). Each iteration includes setting the integrator up (expm, steady
//! state, basis excluded: it is built once per bearing update).
//!
//! `cargo bench -p rotorid --bench simulate_fe`

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use rotorid::model::finite_element::{FeSystem, RitzBasis};
use rotorid::model::{Sampling, SpeedProfile};
use rotorid::simulate::finite_element::{simulate_fe, FeMethod};

#[allow(dead_code)]
#[path = "../tests/it/fe_common/mod.rs"]
mod fe_common;

fn benches(c: &mut Criterion) {
    let rotor = fe_common::ross_rotor();
    let probes = fe_common::probes();
    let full = FeSystem::full(&rotor);
    let reduced = RitzBasis::new(&rotor, 8)
        .expect("valid basis")
        .system(&rotor)
        .unwrap();
    let sampling = Sampling::new(1e-4, 1.0).expect("valid");
    let constant = SpeedProfile::Constant {
        omega: 300.0,
        phi0: 0.0,
    };
    let ramp = SpeedProfile::Ramp {
        omega0: 0.0,
        accel: 450.0,
        phi0: 0.0,
    };
    let mut g = c.benchmark_group("simulate_fe_1s_10kHz");
    g.warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(5))
        .sample_size(10);
    let cases = [
        ("full_exact_constant", &full, &constant, FeMethod::Exact),
        (
            "reduced_exact_constant",
            &reduced,
            &constant,
            FeMethod::Exact,
        ),
        ("full_magnus_runup", &full, &ramp, FeMethod::Magnus),
        ("reduced_magnus_runup", &reduced, &ramp, FeMethod::Magnus),
        ("full_newmark_runup", &full, &ramp, FeMethod::Newmark),
    ];
    for (name, sys, speed, method) in cases {
        g.bench_function(name, |b| {
            b.iter(|| {
                let r = simulate_fe(sys, speed, &sampling, None, Some(&probes), method)
                    .expect("simulates");
                black_box(r.q[0][r.len() - 1])
            })
        });
    }
    g.bench_function("ritz_basis_8_modes", |b| {
        b.iter(|| black_box(RitzBasis::new(&rotor, 8).expect("valid").len()))
    });
    g.finish();
}

criterion_group!(fe, benches);
criterion_main!(fe);
