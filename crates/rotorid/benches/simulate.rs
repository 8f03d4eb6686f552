//! Throughput of the simulators (steps per second), table1 rotor at dt = 0.1 ms:
//! Newmark (constant speed and 10 rad/s^2 ramp), the exact constant-speed discretisation
//! (matrix-exponential stepping) and the DoPri8 reference on the ramp. Each benchmark
//! runs a fixed number of steps; criterion reports elements (steps) per second.
//!
//! `CARGO_TARGET_DIR=/work/target-sim cargo bench -p rotorid --bench simulate`

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rotorid::model::Scenario;
use rotorid::simulate::{simulate, DoPri8Reference, ExactConstant, Integrator, Method, Newmark};

/// Step `integ` `n` times, folding the samples so nothing is optimised away.
fn drive<I: Integrator>(mut integ: I, n: usize) -> f64 {
    let mut acc = 0.0;
    for _ in 0..n {
        let s = integ.step().expect("step");
        acc += s.x + s.z;
    }
    acc
}

fn benches(c: &mut Criterion) {
    let constant = Scenario::table1();
    let ramp = Scenario::table1_ramp(600.0).expect("valid ramp");
    let dt = constant.sampling.dt();

    let mut g = c.benchmark_group("simulate");
    g.warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3))
        .sample_size(20);

    let n = 100_000;
    g.throughput(Throughput::Elements(n as u64));
    for (name, sc) in [("newmark_constant", &constant), ("newmark_ramp", &ramp)] {
        g.bench_function(name, |b| {
            b.iter(|| {
                let nm = Newmark::new(&sc.rotor, &sc.speed, dt, sc.initial).expect("valid");
                black_box(drive(nm, n))
            })
        });
    }
    g.bench_function("exact_constant", |b| {
        b.iter(|| {
            let ex = ExactConstant::new(&constant.rotor, &constant.speed, dt, constant.initial)
                .expect("valid");
            black_box(drive(ex, n))
        })
    });

    // Whole records through the public entry point (boxed integrator + column storage).
    let steps = constant.sampling.steps();
    g.throughput(Throughput::Elements(steps as u64));
    for (name, method) in [
        ("simulate_newmark_constant_1s", Method::Newmark),
        ("simulate_exact_constant_1s", Method::Exact),
    ] {
        g.bench_function(name, |b| {
            b.iter(|| black_box(simulate(&constant, method).expect("simulate")))
        });
    }

    let n_ref = 5_000;
    g.throughput(Throughput::Elements(n_ref as u64));
    g.bench_function("exact_ramp_dopri8", |b| {
        b.iter(|| {
            let r =
                DoPri8Reference::new(&ramp.rotor, &ramp.speed, dt, ramp.initial).expect("valid");
            black_box(drive(r, n_ref))
        })
    });
    g.finish();
}

criterion_group!(simulate_benches, benches);
criterion_main!(simulate_benches);
