//! Speed of the finite-element identification (target: 1 s at 10 kHz of four probes
//! identified in at most 5 s on one core): the ROSS two-disk rotor (44 DOF), its response at
//! both bearings (x, y) simulated with the full model, 40 dB, the fit started from the
//! engineering guess of the tests (bearing coefficients 30-70 % off, unbalance angles 40
//! deg off), the default unknowns (8 direct bearing coefficients, 2 unbalances),
//! reduced to 6 modes + static shapes (the default). Each iteration is a whole `refine_fe` (including
//! the reduction's bias check, one full-model simulation). One thread.
//!
//! `cargo bench -p rotorid --bench refine_fe`

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use rotorid::model::SpeedProfile;
use rotorid::refine::finite_element::{refine_fe, FeData, FeInitial, FeRefineOptions};

#[allow(dead_code)]
#[path = "../tests/it/fe_common/mod.rs"]
mod fe_common;

fn benches(c: &mut Criterion) {
    let truth = fe_common::ross_rotor();
    let start = fe_common::guess(&truth);
    let constant = SpeedProfile::Constant {
        omega: 200.0,
        phi0: 0.0,
    };
    let ramp = SpeedProfile::Ramp {
        omega0: 0.0,
        accel: 450.0,
        phi0: 0.0,
    };
    let mut g = c.benchmark_group("refine_fe_1s_10kHz_4_probes");
    g.warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(20))
        .sample_size(10);
    let cases = [
        ("constant_rest", constant, FeInitial::Rest),
        ("constant_initial_estimated", constant, FeInitial::Estimated),
        ("runup_rest", ramp, FeInitial::Rest),
    ];
    for (name, speed, initial) in cases {
        let (rec, _) = fe_common::record(&truth, &speed, 1.0, 40.0, 3);
        let mut options = FeRefineOptions::new(&truth);
        options.initial = initial;
        g.bench_function(name, |b| {
            b.iter(|| {
                let data = FeData {
                    response: &rec,
                    speed,
                };
                let fit = refine_fe(&data, &start, &options).expect("fits");
                assert!(fit.converged);
                black_box(fit)
            })
        });
    }
    g.finish();
}

criterion_group!(fe, benches);
criterion_main!(fe);
