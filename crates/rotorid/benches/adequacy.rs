//! What the adequacy verdict of the modulating and algebraic methods costs against the
//! identification it judges (docs/method.md section 6.4, docs/performance.md "The adequacy
//! verdict"): `identify/CASE/METHOD` is the whole pipeline identification, verdict
//! included; `adequacy/CASE/METHOD` the verdict alone ([`adequacy_of`] from the
//! identification's own estimate). The identification without the verdict costs the
//! difference. Records of 1 s and 10 s at 10 kHz at 40 dB with per-sample speed columns,
//! as a CSV gives them: the paper's rotor at 1200 rpm, its 600 rpm + 10 rad/s^2 run-up
//! (1 s and 10 s), and the wrong model of an x support on a foundation (1 s).
//!
//! Run: `cargo bench -p rotorid --bench adequacy`.

use std::hint::black_box;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use rotorid::model::RotorParams;
use rotorid::pipeline::{
    adequacy_of, identify, Finding, Identification, Knowledge, Method, Record, Speed,
    ALGEBRAIC_ADEQUACY_SAMPLES, ALGEBRAIC_START_S,
};
use rotorid::simulate::{add_noise, simulate, Method as SimMethod, TimeResponse};
use rotorid::{Parameter, Sampling, Scenario};

#[path = "../tests/it/defects.rs"]
mod defects;

/// `clean` with 40 dB of noise as a record with per-sample speed.
fn record(clean: &TimeResponse) -> Record {
    let mut r = clean.clone();
    add_noise(&mut r, 40.0, 1).expect("valid noise");
    Record::from_response(&r).expect("valid record")
}

/// The first `n` samples of `clean` + 40 dB of noise: the record an algebraic session
/// keeps for its verdict.
fn head(clean: &TimeResponse, n: usize) -> Record {
    let mut r = clean.clone();
    for v in [
        &mut r.t,
        &mut r.x,
        &mut r.z,
        &mut r.phi,
        &mut r.phi_dot,
        &mut r.phi_ddot,
    ] {
        v.truncate(n);
    }
    let full = record(clean);
    Record::new(
        r.t,
        full.x()[..n.min(full.len())].to_vec(),
        full.z()[..n.min(full.len())].to_vec(),
        Speed::Samples {
            phi: r.phi,
            omega: r.phi_dot,
            omega_dot: r.phi_ddot,
        },
        1e-6,
    )
    .expect("valid record")
}

/// The start the verdict refits from, as the pipeline takes it: the per-direction
/// estimates, each direction's c/m and k/m kept, m their mean; for algebraic estimates
/// that did not settle, each direction's last well-conditioned estimate in the first
/// `ALGEBRAIC_START_S`.
fn start_of(id: &Identification, k: &Knowledge) -> RotorParams {
    let unsettled = id
        .diagnostics
        .iter()
        .any(|d| matches!(d.finding, Finding::AlgebraicUnsettled { .. }));
    let v: [f64; 6] = if unsettled {
        let t0 = id.record.t_first_s;
        let mut v = [f64::NAN; 6];
        for e in id
            .estimates
            .iter()
            .take_while(|e| e.t - t0 <= ALGEBRAIC_START_S)
        {
            for d in 0..2 {
                if e.well_conditioned[d] {
                    v[3 * d..3 * d + 3].copy_from_slice(&e.values()[3 * d..3 * d + 3]);
                }
            }
        }
        v
    } else {
        [
            Parameter::MX,
            Parameter::Cx,
            Parameter::Kx,
            Parameter::MZ,
            Parameter::Cz,
            Parameter::Kz,
        ]
        .map(|p| {
            id.parameter(p)
                .and_then(|r| r.estimate)
                .expect("an estimate")
        })
    };
    let m = 0.5 * (v[0] + v[3]);
    RotorParams {
        m,
        cx: v[1] * m / v[0],
        kx: v[2] * m / v[0],
        cz: v[4] * m / v[3],
        kz: v[5] * m / v[3],
        a: k.a,
        unbalance: k.unbalance,
        coupling: None,
    }
}

fn bench(c: &mut Criterion) {
    let table1 = Scenario::table1();
    let long = {
        let mut s = table1;
        s.sampling = Sampling::new(1e-4, 10.0).expect("valid sampling");
        s
    };
    let ramp = Scenario::table1_ramp(600.0).expect("valid ramp");
    let long_ramp = {
        let mut s = ramp;
        s.sampling = Sampling::new(1e-4, 10.0).expect("valid sampling");
        s
    };
    let sim = |s: &Scenario| simulate(s, SimMethod::Exact).expect("simulation");
    let cases = [
        ("table1_1s", table1, sim(&table1)),
        ("ramp600_1s", ramp, sim(&ramp)),
        (
            "foundation_1s",
            table1,
            defects::simulate_defective(defects::DEFECTS[1]),
        ),
        ("table1_10s", long, sim(&long)),
        ("ramp600_10s", long_ramp, sim(&long_ramp)),
    ];
    let mut g = c.benchmark_group("adequacy");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(2));
    for (name, scenario, clean) in &cases {
        let rec = record(clean);
        let k = Knowledge::from_scenario(scenario);
        for (mname, method) in [
            ("algebraic", Method::algebraic()),
            ("modulating", Method::modulating()),
        ] {
            let id = identify(&rec, &k, &method).expect("identified");
            g.bench_function(format!("identify/{name}/{mname}"), |b| {
                b.iter(|| identify(black_box(&rec), &k, &method).expect("identified"))
            });
            if id.adequacy.is_none() {
                continue;
            }
            let start = start_of(&id, &k);
            // the algebraic session judges its first ALGEBRAIC_ADEQUACY_SAMPLES
            let judged = if mname == "algebraic" {
                head(clean, ALGEBRAIC_ADEQUACY_SAMPLES)
            } else {
                rec.clone()
            };
            g.bench_function(format!("adequacy/{name}/{mname}"), |b| {
                b.iter(|| adequacy_of(black_box(&judged), &start).expect("judged"))
            });
        }
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
