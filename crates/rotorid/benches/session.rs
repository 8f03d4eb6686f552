//! Throughput of a streaming identification as every caller runs it: a `Session` with the
//! algebraic method fed sample by sample, with time stamps and per-sample speed columns
//! (the checks of the time grid, the speed columns and the magnitudes, the identifier, the
//! convergence tracker), against the identifier alone on the same samples. The difference
//! is what the pipeline's checks cost.
//!
//! Run: `cargo bench -p rotorid --bench session`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rotorid::identify::algebraic::{measurement, AlgebraicConfig, AlgebraicIdentifier};
use rotorid::identify::Known;
use rotorid::pipeline::{Knowledge, Method, Sample, Session, Timing};
use rotorid::simulate::{simulate, Method as SimMethod, TimeResponse};
use rotorid::{Sampling, Scenario, SpeedState};

/// Ten seconds of table1 at dt = 0.1 ms (100 001 samples), simulated outside the timing.
fn response() -> (Scenario, TimeResponse) {
    let mut sc = Scenario::table1();
    sc.sampling = Sampling::new(1e-4, 10.0).expect("valid sampling");
    let resp = simulate(&sc, SimMethod::Newmark).expect("simulation");
    (sc, resp)
}

fn bench(c: &mut Criterion) {
    let (sc, resp) = response();
    let knowledge = Knowledge::from_scenario(&sc);
    let samples: Vec<Sample> = (0..resp.len())
        .map(|i| Sample {
            t: Some(resp.t[i]),
            x: resp.x[i],
            z: resp.z[i],
            speed: Some(SpeedState {
                phi: resp.phi[i],
                omega: resp.phi_dot[i],
                omega_dot: resp.phi_ddot[i],
            }),
        })
        .collect();
    let measurements: Vec<_> = (0..resp.len()).map(|i| measurement(&resp, i)).collect();

    let mut g = c.benchmark_group("session");
    g.throughput(Throughput::Elements(samples.len() as u64))
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(4));
    g.bench_function("algebraic/session", |b| {
        b.iter(|| {
            let mut s = Session::new(&knowledge, &Method::algebraic(), None, Timing::default())
                .expect("valid session");
            let mut acc = 0.0;
            for x in &samples {
                s.push(black_box(x), &mut |e| acc += e.values()[2])
                    .expect("valid samples");
            }
            let ident = s.finish(&mut |e| acc += e.values()[2]).expect("identified");
            (acc, ident.record.samples)
        })
    });
    let id = AlgebraicIdentifier::new(
        Known::from_rotor(&sc.rotor),
        1e-4,
        AlgebraicConfig::default(),
    )
    .expect("valid identifier");
    g.bench_function("algebraic/identifier", |b| {
        b.iter(|| {
            let mut id = id.clone();
            let mut acc = 0.0;
            for m in &measurements {
                acc += id.push(black_box(m)).expect("valid data").x.k;
            }
            acc
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
