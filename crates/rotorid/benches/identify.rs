//! Streaming throughput of the identifiers, in one run so that they can be compared:
//!
//! - `identify`: the algebraic identifier (both directions, one estimate per sample),
//!   general (variable speed) and constant-speed mode, default (am5) and trapezoid
//!   quadrature (goal: >= 20 million samples/s on one core), and the cross-coupled
//!   algebraic identifier (5x5 systems from I1..I6) in the same settings;
//! - `modulating`: the modulating-function identifier, Jeffcott and cross-coupled (default
//!   window, hop and functions; the estimate at the end included).
//!
//! Every identifier runs on the same record (table1 data: the work per sample does not
//! depend on the values, the 5x5 solve has no data-dependent branch).
//!
//! Run: `cargo bench -p rotorid --bench identify`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rotorid::identify::algebraic::{
    measurement, AlgebraicConfig, AlgebraicIdentifier, CrossAlgebraicIdentifier, Quadrature,
    SpeedModel,
};
use rotorid::identify::modulating::{
    CrossModulatingIdentifier, ModulatingConfig, ModulatingIdentifier,
};
use rotorid::identify::{Known, Measurement};
use rotorid::simulate::{simulate, Method};
use rotorid::{Sampling, Scenario};

/// One second of table1 data at dt = 0.1 ms (10 001 samples), simulated outside the timing.
fn data(scenario: Scenario) -> Vec<Measurement> {
    let mut sc = scenario;
    sc.sampling = Sampling::new(1e-4, 1.0).expect("valid sampling");
    let resp = simulate(&sc, Method::Newmark).expect("simulation");
    (0..resp.len()).map(|i| measurement(&resp, i)).collect()
}

fn run(id: &AlgebraicIdentifier, data: &[Measurement]) -> f64 {
    let mut id = id.clone();
    let mut acc = 0.0;
    for m in data {
        let e = id.push(black_box(m)).expect("valid data");
        acc += e.x.k + e.z.k;
    }
    acc
}

fn run_cross(id: &CrossAlgebraicIdentifier, data: &[Measurement]) -> f64 {
    let mut id = id.clone();
    let mut acc = 0.0;
    for m in data {
        let e = id.push(black_box(m)).expect("valid data");
        acc += e.x.values[3] + e.z.values[4];
    }
    acc
}

fn bench(c: &mut Criterion) {
    let ramp = Scenario::table1_ramp(0.0).expect("valid ramp");
    let constant = Scenario::table1();
    let known = Known::from_rotor(&constant.rotor);
    let ramp_data = data(ramp);
    let const_data = data(constant);
    let w = rotorid::model::rpm_to_rad_per_s(1200.0);

    let mut g = c.benchmark_group("identify");
    g.throughput(Throughput::Elements(const_data.len() as u64))
        .sample_size(20)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(3));
    for q in [Quadrature::AdamsMoulton5, Quadrature::Trapezoid] {
        let general = AlgebraicConfig {
            quadrature: q,
            ..AlgebraicConfig::default()
        };
        let constant = AlgebraicConfig {
            speed_model: SpeedModel::Constant {
                omega: w,
                phi0: 0.0,
            },
            ..general
        };
        let id_g = AlgebraicIdentifier::new(known, 1e-4, general).expect("valid");
        let id_c = AlgebraicIdentifier::new(known, 1e-4, constant).expect("valid");
        g.bench_function(format!("general/{q}"), |b| {
            b.iter(|| run(&id_g, &ramp_data))
        });
        g.bench_function(format!("constant/{q}"), |b| {
            b.iter(|| run(&id_c, &const_data))
        });
        let cross_g = CrossAlgebraicIdentifier::new(known, 1e-4, general).expect("valid");
        let cross_c = CrossAlgebraicIdentifier::new(known, 1e-4, constant).expect("valid");
        g.bench_function(format!("cross_general/{q}"), |b| {
            b.iter(|| run_cross(&cross_g, &ramp_data))
        });
        g.bench_function(format!("cross_constant/{q}"), |b| {
            b.iter(|| run_cross(&cross_c, &const_data))
        });
    }
    g.finish();

    let mut g = c.benchmark_group("modulating");
    g.throughput(Throughput::Elements(ramp_data.len() as u64))
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(4));
    let config = ModulatingConfig::default();
    g.bench_function("jeffcott", |b| {
        b.iter(|| {
            let mut id = ModulatingIdentifier::new(known, 1e-4, config).expect("valid");
            for m in &ramp_data {
                id.push(black_box(m)).expect("valid data");
            }
            id.finish().expect("one window").x.k
        })
    });
    g.bench_function("cross", |b| {
        b.iter(|| {
            let mut id = CrossModulatingIdentifier::new(known, 1e-4, config).expect("valid");
            for m in &ramp_data {
                id.push(black_box(m)).expect("valid data");
            }
            id.finish().expect("one window").x.values[3]
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
