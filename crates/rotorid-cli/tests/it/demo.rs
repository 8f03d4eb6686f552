//! End-to-end test of `rotorid demo`: it runs, prints every parameter in both settings, and
//! its JSON agrees with the accuracy the method promises on exact data.

use crate::common::rotorid;

#[test]
fn demo_prints_every_parameter_in_both_settings() {
    let out = rotorid().arg("demo").output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8(out.stdout).unwrap();
    for needle in [
        "m_x",
        "c_x",
        "k_x",
        "m_z",
        "c_z",
        "k_z",
        "constant speed 1200 rpm",
        "ramp 10 rad/s^2 from rest",
        "ramp 10 rad/s^2 from 1200 rpm",
        "exact + am5",
        "newmark + trapezoid",
        "< 0.2 s",
        "< 0.28 s",
        "< 0.1 s",
    ] {
        assert!(
            text.contains(needle),
            "demo output lacks {needle:?}:\n{text}"
        );
    }
}

#[test]
fn demo_json_is_complete_and_accurate() {
    let out = rotorid().args(["demo", "--json"]).output().unwrap();
    assert!(out.status.success());
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let blocks = v["blocks"].as_array().unwrap();
    assert_eq!(blocks.len(), 2);
    for b in blocks {
        let cases = b["cases"].as_array().unwrap();
        assert_eq!(cases.len(), 3);
        for c in cases {
            let params = c["parameters"].as_array().unwrap();
            let names: Vec<&str> = params
                .iter()
                .map(|p| p["parameter"].as_str().unwrap())
                .collect();
            assert_eq!(names, ["m_x", "c_x", "k_x", "m_z", "c_z", "k_z"]);
            for p in params {
                let e = p["relative_error"].as_f64().unwrap();
                let bound = match (
                    b["simulation"].as_str().unwrap(),
                    &p["parameter"].as_str().unwrap()[..1],
                ) {
                    // exact data, 5th-order quadrature: docs/method.md section 3.8: ~1e-8 (m, k), ~1e-6 (c)
                    ("exact", "c") => 1e-5,
                    ("exact", _) => 1e-6,
                    // Newmark data + trapezoid: biased by both (docs/method.md section 3.8)
                    _ => 1e-2,
                };
                assert!(
                    e.abs() < bound,
                    "{}: {} {e:e}",
                    b["setting"],
                    p["parameter"]
                );
                assert!(p["identification_time_s"].as_f64().is_some());
            }
        }
    }
}
