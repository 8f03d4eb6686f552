//! The algebraic identifier restarted on overlapping windows (identify::algebraic::windows)
//! against fresh identifiers started at each window: restarts track a change of the rotor
//! that a single identifier averages away, every estimate says its window, and long records
//! whose systems are ill-conditioned are warned.

use rotorid::model::{Rotor, Sampling, Scenario, SpeedProfile};
use rotorid::pipeline::{identify, Finding, Knowledge, Method, Record};
use rotorid::simulate::{simulate, Method as SimMethod};
use rotorid::test_models::{table1, TestModel};
use rotorid::Parameter;

/// A run-up on the paper's 10 rad/s^2 ramp from 600 rpm, through both critical speeds.
fn long_ramp(seconds: f64) -> TestModel {
    let mut sc = Scenario::table1_ramp(600.0).unwrap();
    sc.sampling = Sampling::new(sc.sampling.dt(), seconds).unwrap();
    TestModel::clean("table1 ramp long", sc)
}

fn algebraic(restart_s: Option<f64>) -> Method {
    let Method::Algebraic(mut s) = Method::algebraic() else {
        unreachable!()
    };
    s.restart_s = restart_s;
    Method::Algebraic(s)
}

/// 2 s of table1, then 2 s of the same rotor with both stiffnesses 10 % higher, started
/// from rest (a bearing change between two runs, spliced into one stream).
fn stiffness_step() -> (Record, Knowledge, f64) {
    let first = table1();
    let dt = first.scenario.sampling.dt();
    let mut sc = Scenario::table1();
    sc.sampling = Sampling::new(dt, 2.0).unwrap();
    let mut a = simulate(&sc, SimMethod::Exact).unwrap();
    // the second run starts at sample 20000 (t = 2 s), where window 4 starts
    for v in [
        &mut a.t,
        &mut a.x,
        &mut a.z,
        &mut a.phi,
        &mut a.phi_dot,
        &mut a.phi_ddot,
    ] {
        v.pop();
    }
    let mut p = sc.rotor.params();
    p.kx *= 1.1;
    p.kz *= 1.1;
    let k2 = p.kx;
    let t0 = a.t.last().unwrap() + dt;
    let w = 1200.0 * std::f64::consts::PI / 30.0;
    let sc2 = Scenario {
        rotor: Rotor::new(p).unwrap(),
        speed: SpeedProfile::constant_rpm(1200.0, w * t0).unwrap(),
        ..sc
    };
    let b = simulate(&sc2, SimMethod::Exact).unwrap();
    let mut r = a.clone();
    r.t.extend(b.t.iter().map(|t| t + t0));
    r.x.extend(&b.x);
    r.z.extend(&b.z);
    r.phi.extend(&b.phi);
    r.phi_dot.extend(&b.phi_dot);
    r.phi_ddot.extend(&b.phi_ddot);
    (Record::from_response(&r).unwrap(), first.knowledge(), k2)
}

#[test]
fn restarts_track_a_change_the_single_identifier_averages_away() {
    let (rec, k, k2) = stiffness_step();
    let single = identify(&rec, &k, &algebraic(None)).unwrap();
    let kx = single.parameter(Parameter::Kx).unwrap().estimate.unwrap();
    eprintln!("single identifier: final kx {kx:e} (after the step: {k2:e})");
    assert!(
        (kx / k2 - 1.0).abs() > 0.01,
        "the single identifier mixes both runs"
    );

    // windows of 1 s, started every 0.5 s: those started at or after the step (2 s) report
    // from 2.5 s on, and see only the second run
    let restarted = identify(&rec, &k, &algebraic(Some(1.0))).unwrap();
    let mut worst = 0.0f64;
    let mut n = 0;
    for e in restarted.estimates.iter().filter(|e| e.t >= 2.5 + 1e-9) {
        if e.rcond[0] >= 1e-5 {
            worst = worst.max((e.values()[2] / k2 - 1.0).abs());
            n += 1;
        }
    }
    eprintln!("restart 1 s: {n} well-conditioned estimates after 2.5 s, worst kx error {worst:e}");
    assert!(n > 10_000, "{n}");
    assert!(worst < 1e-6, "{worst:e}");
    let r = restarted.parameter(Parameter::Kx).unwrap();
    // the truth the knowledge carries is the first run's: 10 % below
    assert!((r.relative_error.unwrap() - 0.1).abs() < 1e-6, "{r:?}");
    assert!((r.value.unwrap() / k2 - 1.0).abs() < 1e-6, "{r:?}");
}

#[test]
fn long_records_warn_when_their_estimates_are_ill_conditioned() {
    // a 30 s run-up through both critical speeds: beyond them the 3x3 systems are
    // ill-conditioned at most instants, with or without restarts
    let model = long_ramp(30.0);
    let rec = model.record();
    let k = model.knowledge();
    for restart in [None, Some(2.0)] {
        let id = identify(&rec, &k, &algebraic(restart)).unwrap();
        let d = id.algebraic.as_ref().unwrap();
        let n = id.record.samples as f64;
        eprintln!(
            "restart {restart:?}: flagged x {:.3}, z {:.3}, windows {}",
            d.flagged.x as f64 / n,
            d.flagged.z as f64 / n,
            d.windows
        );
        let fraction = d.flagged.x.max(d.flagged.z) as f64 / n;
        let warned = id
            .diagnostics
            .iter()
            .any(|d| matches!(d.finding, Finding::AlgebraicIllConditioned { .. }));
        assert_eq!(warned, fraction > 0.1, "{restart:?}: {fraction}");
        assert_eq!(d.restart_s, restart);
    }
    // a 1 s record of table1 has no such warning
    let short = table1();
    let id = identify(&short.record(), &short.knowledge(), &algebraic(None)).unwrap();
    assert!(id.diagnostics.is_empty(), "{:?}", id.diagnostics);
}

#[test]
fn every_estimate_says_its_window() {
    let model = long_ramp(0.05);
    let rec = model.record();
    let id = identify(&rec, &model.knowledge(), &algebraic(Some(0.01))).unwrap();
    // 0.01 s at 0.1 ms = 100 samples: windows of 100 start every 50
    assert_eq!(id.algebraic.as_ref().unwrap().windows, 11);
    assert_eq!(id.estimates.len(), rec.len());
}

#[test]
fn a_period_under_four_samples_is_refused_naming_the_field() {
    let model = long_ramp(0.01);
    let e = identify(&model.record(), &model.knowledge(), &algebraic(Some(2e-4))).unwrap_err();
    let msg = e.to_string();
    assert!(msg.contains("restart_s") && msg.contains("0.0002"), "{msg}");
}
