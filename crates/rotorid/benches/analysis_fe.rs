//! Speed of the analysis of a finite-element rotor (`fe_analysis`: Campbell diagram of the
//! lowest 6 modes followed across speeds, critical speeds, stability, standard deviations
//! by the delta method): the ROSS two-disk rotor (44 DOF), 0-12000 rpm in steps of 20 rpm
//! (601 speeds, `rotorid analyze --rpm 0:12000:20`), with a covariance over its 16 bearing
//! coefficients. Per speed: the eigenvalues of the 88 x 88 state matrix (real Schur form)
//! and 10 candidates polished by Newton, one complex 44 x 44 LU a step.
//! One thread.
//!
//! `cargo bench -p rotorid --bench analysis_fe`

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use rotorid::analysis::{fe_analysis, FeCovariance};
use rotorid::model::finite_element::FeParameter;

#[allow(dead_code)]
#[path = "../tests/it/fe_common/mod.rs"]
mod fe_common;

fn benches(c: &mut Criterion) {
    let rotor = fe_common::ross_rotor();
    let names: Vec<String> = FeParameter::all(&rotor)
        .iter()
        .filter(|p| matches!(p, FeParameter::Bearing { .. }))
        .map(|p| p.to_string())
        .collect();
    let n = names.len();
    // 1 % standard deviations (10 N s/m for the zero cross-coupled damping), correlated
    let sd: Vec<f64> = FeParameter::all(&rotor)
        .iter()
        .filter(|p| matches!(p, FeParameter::Bearing { .. }))
        .map(|p| (0.01 * p.get(&rotor).unwrap().abs()).max(10.0))
        .collect();
    let matrix: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| if i == j { 1.0 } else { 0.1 } * sd[i] * sd[j])
                .collect()
        })
        .collect();
    let cov = FeCovariance::new(&rotor, names, matrix).expect("a valid covariance");
    let speeds: Vec<f64> = (0..=600)
        .map(|k| rotorid::model::rpm_to_rad_per_s(20.0 * k as f64))
        .collect();
    let mut g = c.benchmark_group("fe_analysis_ross_two_disk");
    g.warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(15))
        .sample_size(10);
    g.bench_function("601_speeds_6_modes_covariance", |b| {
        b.iter(|| black_box(fe_analysis(&rotor, Some(&cov), &speeds, 6).expect("analyses")))
    });
    g.finish();
}

criterion_group!(analysis, benches);
criterion_main!(analysis);
