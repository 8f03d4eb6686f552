//! The cross-coupled model's algebraic and modulating identifiers through the pipeline
//! (`--method algebraic|modulating --model cross_coupled`): the same estimates as the
//! identifiers called directly (which tests/it/cross_algebraic.rs and cross_modulating.rs
//! check against an independent reference), the values named by the model's parameters,
//! the required accuracy at 0.1 s on clean data, and at 40 dB values within their standard
//! errors, the Cramer-Rao bound of the cross-coupled model and an adequacy verdict.

use rotorid::identify::algebraic::{identify_cross_response, AlgebraicConfig};
use rotorid::identify::modulating::identify_cross_modulating_response;
use rotorid::identify::Known;
use rotorid::model::{Rotor, Sampling, Scenario};
use rotorid::parameter::{ModelKind, Parameter};
use rotorid::pipeline::{
    identify, AlgebraicSettings, CrbAt, Method, ModulatingSettings, Sample, Session, Severity,
    Timing,
};
use rotorid::test_models::{cross_coupled, cross_coupled_rotor, TestModel};

fn algebraic() -> Method {
    Method::Algebraic(AlgebraicSettings {
        model: Some(ModelKind::CrossCoupled),
        ..AlgebraicSettings::default()
    })
}

fn modulating() -> Method {
    Method::Modulating(ModulatingSettings {
        model: Some(ModelKind::CrossCoupled),
        ..ModulatingSettings::default()
    })
}

/// The cross-coupled test rotor at 1200 rpm from rest, `duration` s at 10 kHz, clean.
fn clean(duration: f64) -> TestModel {
    let s = Scenario {
        rotor: Rotor::new(cross_coupled_rotor()).unwrap(),
        sampling: Sampling::new(1e-4, duration).unwrap(),
        ..Scenario::table1()
    };
    TestModel::clean("cross_coupled_100ms", s)
}

#[test]
fn algebraic_is_the_cross_identifier_and_meets_1e_6_at_100_ms() {
    let tm = clean(0.1);
    let id = identify(&tm.record(), &tm.knowledge(), &algebraic()).unwrap();
    assert_eq!(id.model, ModelKind::CrossCoupled);
    let names: Vec<Parameter> = id.parameters.iter().map(|r| r.parameter).collect();
    assert_eq!(names, ModelKind::CrossCoupled.per_direction());
    // every sample's estimate bit for bit the identifier's, called directly
    let direct = identify_cross_response(
        &tm.response,
        Known::from_rotor(&tm.scenario.rotor),
        AlgebraicConfig::default(),
    )
    .unwrap();
    assert_eq!(id.estimates.len(), direct.len());
    for (s, d) in id.estimates.iter().zip(&direct) {
        assert_eq!(s.model, ModelKind::CrossCoupled);
        assert_eq!(s.t.to_bits(), d.t.to_bits());
        let bits = |v: &[f64]| v.iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(s.values()), bits(&d.values()));
        assert_eq!(s.rcond, [d.x.rcond, d.z.rcond]);
    }
    // the acceptance criterion at 0.1 s: every value within 1e-6 of its truth, or (a cross
    // damping of 20 N s/m, where am5's quadrature error is ~2e-5 N s/m) within 1e-7 of its
    // row's direct coefficient
    let truth = tm.truth();
    for r in &id.parameters {
        let v = r
            .value
            .unwrap_or_else(|| panic!("{} withheld: {id:#?}", r.parameter));
        let t = truth.get(r.parameter).unwrap();
        let direct = match r.parameter {
            Parameter::Cxz => truth.get(Parameter::Cxx).unwrap(),
            Parameter::Czx => truth.get(Parameter::Czz).unwrap(),
            _ => t,
        };
        let err = (v - t).abs();
        assert!(
            err <= 1e-6 * t.abs() || err <= 1e-7 * direct.abs(),
            "{}: {v} against {t}",
            r.parameter
        );
    }
    // the rotor summary in the model's names, m the mean of m_x and m_z
    let rotor = id.rotor.as_ref().expect("every value determined");
    assert_eq!(rotor.model(), ModelKind::CrossCoupled);
    assert!((rotor.get(Parameter::Kxz).unwrap() / -3.0e4 - 1.0).abs() < 1e-6);
    let m = 0.5 * (id.value(Parameter::MX).unwrap() + id.value(Parameter::MZ).unwrap());
    assert_eq!(rotor.get(Parameter::M), Some(m));
    let a = id.algebraic.as_ref().unwrap();
    assert_eq!(a.windows, 1);
    assert!(a.last_rcond.x > 0.0 && a.last_rcond.z > 0.0);
}

#[test]
fn a_stream_gives_the_cross_estimates_as_they_come_and_needs_six_samples() {
    let tm = clean(0.02);
    let rec = tm.record();
    let timing = Timing::Grid {
        grid: rec.grid(),
        tolerance: 0.01,
    };
    let mut session = Session::new(&tm.knowledge(), &algebraic(), None, timing).unwrap();
    assert_eq!(session.model(), ModelKind::CrossCoupled);
    let mut seen = Vec::new();
    for i in 0..rec.len() {
        let s = Sample {
            t: Some(rec.t()[i]),
            x: rec.x()[i],
            z: rec.z()[i],
            speed: Some(rec.speed_at(i)),
        };
        session.push(&s, &mut |e| seen.push(*e)).unwrap();
    }
    let id = session.finish(&mut |e| seen.push(*e)).unwrap();
    assert_eq!(seen.len(), rec.len());
    let last = seen.last().unwrap();
    assert_eq!(last.parameters(), ModelKind::CrossCoupled.per_direction());
    // the last estimate is what the summary reports (all determined on clean data)
    for (i, r) in id.parameters.iter().enumerate() {
        assert_eq!(r.estimate, last.usable(i), "{}", r.parameter);
    }
    // five samples cannot give the cross-coupled 5x5 system
    let mut short = Session::new(&tm.knowledge(), &algebraic(), None, timing).unwrap();
    for i in 0..5 {
        let s = Sample {
            t: Some(rec.t()[i]),
            x: rec.x()[i],
            z: rec.z()[i],
            speed: Some(rec.speed_at(i)),
        };
        short.push(&s, &mut |_| {}).unwrap();
    }
    let e = short.finish(&mut |_| {}).unwrap_err().to_string();
    assert!(e.contains('6') && e.contains("5x5"), "{e}");
}

#[test]
fn modulating_at_40_db_is_the_cross_identifier_with_its_bound_and_adequacy() {
    let tm = cross_coupled().with_noise(40.0, 3);
    let Method::Modulating(settings) = modulating() else {
        unreachable!()
    };
    let id = identify(&tm.record(), &tm.knowledge(), &modulating()).unwrap();
    assert_eq!(id.model, ModelKind::CrossCoupled);
    let direct = identify_cross_modulating_response(
        &tm.response,
        Known::from_rotor(&tm.scenario.rotor),
        settings.config,
    )
    .unwrap();
    let (values, std) = (direct.values(), direct.std_errors());
    let truth = tm.truth();
    for (i, r) in id.parameters.iter().enumerate() {
        assert_eq!(r.parameter, ModelKind::CrossCoupled.per_direction()[i]);
        assert_eq!(r.estimate, Some(values[i]), "{}", r.parameter);
        assert_eq!(r.std_error, Some(std[i]), "{}", r.parameter);
        let t = truth.get(r.parameter).unwrap();
        let z = (r.value.unwrap() - t) / std[i];
        assert!(z.abs() < 4.0, "{}: z = {z}", r.parameter);
        // the bound of the cross-coupled model (one mass) at the truth: below the
        // identifier's standard error, within a factor 4
        let crb = r.crb.unwrap_or_else(|| panic!("{}: no bound", r.parameter));
        assert!(
            crb <= std[i] * 1.05 && crb * 4.0 > std[i],
            "{}: crb {crb:e}, std {:e}",
            r.parameter,
            std[i]
        );
    }
    let detail = id.modulating.as_ref().unwrap();
    assert_eq!(detail.crb_at, Some(CrbAt::Truth));
    assert_eq!(detail.windows, direct.windows);
    let adequacy = id.adequacy.expect("judged: every value determined");
    assert!(adequacy.model_adequate, "{adequacy:?}");
    assert!(
        id.diagnostics
            .iter()
            .all(|d| d.severity != Severity::Warning),
        "{:?}",
        id.warnings()
    );
    // the batch row of the estimates table in the model's order, m per direction
    let f = id.final_estimate().unwrap();
    assert_eq!(f.model, ModelKind::CrossCoupled);
    assert_eq!(f.values.len(), 10);
    assert_eq!(f.values[2], Some(values[2]));
}
