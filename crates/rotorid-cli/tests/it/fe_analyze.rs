//! `rotorid analyze` of a finite-element rotor, end to end: the one-node
//! rotor of `predict.rs` analysed from a hand-written finite-element summary on its
//! scenario equals `rotorid analyze` of the same rotor written as a cross-coupled 2-DOF
//! summary (x = x, y = -z: kxz = -kxy, kzx = -kyx, alpha + 90 deg; docs/finite_element.md
//! section 2): critical speeds, whirl, logarithmic decrements and their standard
//! deviations; the unbalance per plane carries the summary's standard deviations; bad
//! combinations are refused by name.

use serde_json::{json, Value};

use crate::common::rotorid;
use crate::predict::{cov_json, covariance, setup, summary, A, M, VALUES};

fn analyze(args: &[&str]) -> Result<Value, String> {
    let dir = tempfile::tempdir().unwrap();
    let out = rotorid()
        .arg("analyze")
        .args(args)
        .args(["--out", dir.path().to_str().unwrap()])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!err.contains("panicked"), "{err}");
    if !out.status.success() {
        return Err(err);
    }
    assert!(dir.path().join("campbell.png").exists());
    let text = std::fs::read_to_string(dir.path().join("analysis.json")).unwrap();
    Ok(serde_json::from_str(&text).unwrap())
}

fn rel(a: &Value, b: &Value) -> f64 {
    let (a, b) = (a.as_f64().unwrap(), b.as_f64().unwrap());
    (a - b).abs() / b.abs()
}

#[test]
fn a_finite_element_summary_analyses_as_its_cross_coupled_twin() {
    let dir = tempfile::tempdir().unwrap();
    let (fe, identified) = setup(dir.path());
    let cov = covariance();
    let s = summary(dir.path(), "s.json", cov_json(&cov), Value::Null);
    let grid = "0:6000:20";
    let f = analyze(&[&s, "--scenario", &fe, "--rpm", grid]).unwrap();
    // the twin: bearing block of the covariance (kxx, kyy, cxx, cyy -> kxx, kzz, cxx, czz)
    let v = VALUES;
    let block: Vec<Vec<f64>> = (0..4).map(|i| cov[i][..4].to_vec()).collect();
    let twin = json!({
        "model": "cross_coupled",
        "rotor": {"m": M, "a": A, "kxx": v[0], "kxz": -3.0e4, "kzx": 3.0e4, "kzz": v[1],
                  "cxx": v[2], "cxz": 0.0, "czx": 0.0, "czz": v[3],
                  "mud": v[4], "alpha": v[5] + std::f64::consts::FRAC_PI_2},
        "covariance": {"names": ["kxx", "kzz", "cxx", "czz"], "matrix": block}
    });
    let t = dir.path().join("twin.json");
    std::fs::write(&t, twin.to_string()).unwrap();
    let c = analyze(&[t.to_str().unwrap(), "--rpm", grid]).unwrap();
    assert_eq!(f["model"], "finite_element");
    let (fc, cc) = (
        f["critical_speeds"].as_array().unwrap(),
        c["critical_speeds"].as_array().unwrap(),
    );
    assert_eq!(fc.len(), 2, "{f}");
    assert_eq!(cc.len(), 2);
    for (a, b) in fc.iter().zip(cc) {
        assert!(rel(&a["rpm"], &b["rpm"]) < 1e-9, "{a} {b}");
        assert_eq!(a["whirl"], b["whirl"]);
        assert!(rel(&a["log_dec"], &b["log_dec"]) < 1e-9, "{a} {b}");
        assert!(rel(&a["std_rpm"], &b["std_rpm"]) < 1e-6, "{a} {b}");
        assert!(rel(&a["log_dec_std"], &b["log_dec_std"]) < 1e-6, "{a} {b}");
        println!(
            "critical {} +- {} rpm ({}), 2-DOF {} +- {}",
            a["rpm"], a["std_rpm"], a["whirl"], b["rpm"], b["std_rpm"]
        );
    }
    assert!(
        rel(
            &f["stability"]["min_log_dec"],
            &c["stability"]["min_log_dec"]
        ) < 1e-9
    );
    assert_eq!(f["campbell"]["modes"].as_array().unwrap().len(), 2);
    // the unbalance per plane, with the summary's standard deviations
    let u = &f["unbalances"][0];
    assert_eq!(u["node"], 0);
    assert_eq!(u["mud_kg_m"], v[4]);
    assert!((u["mud_std_kg_m"].as_f64().unwrap() - 3e-7).abs() < 1e-20);
    assert!((u["angle_deg"].as_f64().unwrap() - v[5].to_degrees()).abs() < 1e-12);
    assert!((u["angle_std_deg"].as_f64().unwrap() - 0.02f64.to_degrees()).abs() < 1e-12);
    assert_eq!(f["rotor"]["bearings"][0]["kxx"], v[0]);
    assert_eq!(f["rotor_std"]["bearings"][0]["kxy"], 0.0);
    // the scenario written with the identified values: the same numbers, no uncertainty
    let sc = analyze(&["--scenario", &identified, "--rpm", grid]).unwrap();
    for (a, b) in sc["critical_speeds"].as_array().unwrap().iter().zip(fc) {
        assert_eq!(a["rpm"], b["rpm"]);
        assert!(a["std_rpm"].is_null());
    }
    // its constant speed is the operating speed
    assert_eq!(sc["stability"]["operating"]["source"], "scenario");
}

#[test]
fn finite_element_inputs_are_checked_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let (fe, _) = setup(dir.path());
    let s = summary(dir.path(), "s.json", cov_json(&covariance()), Value::Null);
    let e = analyze(&[&s]).unwrap_err();
    assert!(
        e.contains("is a finite-element summary") && e.contains("--scenario"),
        "{e}"
    );
    let e = analyze(&[&s, "--scenario", &fe, "--modes", "3"]).unwrap_err();
    assert!(
        e.contains("--modes 3 is out of range: must be 1 ..= 2"),
        "{e}"
    );
    let two = dir.path().join("two.json");
    std::fs::write(
        &two,
        r#"{"rotor": {"m": 14.29, "cx": 10, "kx": 1.195e6, "cz": 10, "kz": 1.195e6, "a": 2.871, "mud": 1.5e-5, "alpha": 0.0}, "covariance": null}"#,
    )
    .unwrap();
    let e = analyze(&[two.to_str().unwrap(), "--scenario", &fe]).unwrap_err();
    assert!(
        e.contains("a scenario goes with a finite-element summary only"),
        "{e}"
    );
    let e = analyze(&["--scenario", &fe, "--probe", "45"]).unwrap_err();
    assert!(e.contains("--probe"), "{e}");
    // --unit converts amplitudes the finite-element analysis does not draw: refused by
    // name, whichever unit, rather than ignored
    for unit in ["mil", "um"] {
        let e = analyze(&[&s, "--scenario", &fe, "--unit", unit]).unwrap_err();
        assert!(
            e.contains(&format!("--unit {unit}")) && e.contains("no amplitude figure"),
            "{e}"
        );
    }
    // the 2-DOF analysis takes it
    let two_mil = analyze(&[
        two.to_str().unwrap(),
        "--unit",
        "mil",
        "--rpm",
        "0:3000:100",
    ]);
    assert!(two_mil.is_ok(), "{two_mil:?}");
}
