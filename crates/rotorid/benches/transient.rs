//! Throughput of the transient analysis's order tracking (docs/transient.md section 2):
//! a run-up of the Table 1 rotor simulated as a raw record (two probes and a keyphasor,
//! `acquisition::simulate_raw`) at 25.6 kHz, 600 rpm + 100 rad/s^2 for 5 s (128,001
//! samples, 600 to 5375 rpm: 2,560 samples a revolution at the start, 286 at the end,
//! about 250 revolutions), tracked once outside the timing to check it works, then:
//!
//! - `record`: `transient::track_record` of both probes, as `rotorid transient` runs it
//!   (time stamps, keyphasor to shaft angle, each probe's displacement and vectors);
//! - `keyphasor`: `acquisition::shaft_angle` alone (the part of `record` that is not order
//!   tracking);
//! - `track_two_probes`: `transient::order::track` of each probe given the shaft angle;
//! - `track_signals`: `transient::order::track_signals` of both probes at once (one set
//!   of normal equations per revolution for both, as `track_record` runs it).
//!
//! Throughput is in samples of the record (one sample = a time stamp, two probes and the
//! keyphasor). Run: `cargo bench --workspace --bench transient` (docs/performance.md,
//! "Transient (order tracking)", has the figures).

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use rotorid::acquisition::{shaft_angle, simulate_raw, Acquisition, RawRecord, Which};
use rotorid::transient::order::track_signals;
use rotorid::transient::{track, track_record, OrderSettings};
use rotorid::{Sampling, Scenario, SpeedProfile};

/// The sampling rate of the benchmark's record \[Hz\].
const RATE_HZ: f64 = 25_600.0;

/// The run-up's raw record and its acquisition, simulated outside the timing.
fn record() -> (Acquisition, RawRecord) {
    let sc = Scenario {
        speed: SpeedProfile::ramp(600.0, 100.0, 0.0).expect("valid ramp"),
        sampling: Sampling::new(1.0 / RATE_HZ, 5.0).expect("valid sampling"),
        ..Scenario::table1()
    };
    let acq = Acquisition::example();
    let sim = simulate_raw(&sc, &acq).expect("raw simulation");
    (acq, sim.running)
}

fn bench(c: &mut Criterion) {
    let (acq, raw) = record();
    let settings = OrderSettings::default();
    let col = |name: &str| raw.column(name).expect("simulated column");
    let t = col("t").to_vec();
    let kp = col("kp");
    let d: Vec<Vec<f64>> = acq
        .probes
        .iter()
        .map(|p| col(&p.column).iter().map(|v| v / p.sensitivity).collect())
        .collect();
    let sa = shaft_angle(&t, kp, &acq.keyphasor, Which::Running).expect("keyphasor");
    let psi: Vec<f64> = sa.phi.iter().map(|p| p - acq.keyphasor.angle).collect();
    let once = track_record(&raw, &acq, &[0, 1], &settings, Which::Running).expect("tracked");
    assert!(once.probes[0].tracked.revolutions.len() > 100);

    let mut g = c.benchmark_group("transient");
    g.throughput(Throughput::Elements(t.len() as u64))
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(4));
    g.bench_function("record", |b| {
        b.iter(|| {
            track_record(black_box(&raw), &acq, &[0, 1], &settings, Which::Running)
                .expect("tracked")
                .probes
                .len()
        })
    });
    g.bench_function("keyphasor", |b| {
        b.iter(|| {
            shaft_angle(black_box(&t), kp, &acq.keyphasor, Which::Running)
                .expect("keyphasor")
                .phi
                .len()
        })
    });
    g.bench_function("track_two_probes", |b| {
        b.iter(|| {
            d.iter()
                .map(|s| {
                    track(&t, &psi, black_box(s), &settings)
                        .expect("tracked")
                        .revolutions
                        .len()
                })
                .sum::<usize>()
        })
    });
    let both: Vec<&[f64]> = d.iter().map(Vec::as_slice).collect();
    g.bench_function("track_signals", |b| {
        b.iter(|| {
            track_signals(&t, &psi, black_box(&both), &settings)
                .expect("tracked")
                .len()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
