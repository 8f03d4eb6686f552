//! End-to-end tests of `rotorid analyze` and `rotorid balance`: the table1 Campbell
//! diagram's two critical speeds (closed form k / (m -/+ a)), the uncertainty carried from
//! a summary's covariance, the figures and the page, the correction mass from an
//! identified unbalance and from two simulated runs, and clear errors.

use std::path::Path;

use crate::common::{data, rotorid};
use predicates::prelude::PredicateBooleanExt;
use predicates::str::contains;
use serde_json::Value;

fn png_size(path: &Path) -> (u32, u32) {
    let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
    let reader = decoder.read_info().unwrap();
    let info = reader.info();
    (info.width, info.height)
}

fn read_json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Zero-damping critical speeds of table1 \[rpm\]: W^2 = k / (m + a), k / (m - a).
fn table1_critical_rpm() -> [f64; 2] {
    let (m, k, a) = (14.29f64, 1.195e6f64, 2.871f64);
    [(k / (m + a)).sqrt(), (k / (m - a)).sqrt()].map(|w| w * 60.0 / std::f64::consts::TAU)
}

#[test]
fn table1_campbell_has_two_critical_speeds_below_3500_rpm() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("a");
    rotorid()
        .args(["analyze", "--scenario", "table1", "--out"])
        .arg(&out)
        .assert()
        .success()
        .stdout(
            contains("backward")
                .and(contains("forward"))
                .and(contains("stable")),
        );
    let j = read_json(&out.join("analysis.json"));
    let cs = j["critical_speeds"].as_array().unwrap();
    assert_eq!(cs.len(), 2, "{cs:?}");
    let want = table1_critical_rpm();
    for (c, (w, whirl)) in cs.iter().zip(want.iter().zip(["backward", "forward"])) {
        let rpm = c["rpm"].as_f64().unwrap();
        // damping 1e-3 moves them by ~1e-6 relative
        assert!((rpm - w).abs() < 0.05, "{rpm} vs {w}");
        assert!(rpm < 3500.0);
        assert_eq!(c["whirl"], whirl);
        assert!(c["std_rpm"].is_null(), "no covariance, no std: {c}");
    }
    let camp = &j["campbell"];
    assert_eq!(camp["rpm"].as_array().unwrap().len(), 601);
    assert_eq!(camp["modes"][0]["whirl"], "backward");
    assert_eq!(camp["modes"][1]["whirl"], "forward");
    // sqrt(k/m) = 46.0 Hz at rest for both modes
    for m in 0..2 {
        let f0 = camp["modes"][m]["frequency_hz"][0].as_f64().unwrap();
        assert!((f0 - 46.03).abs() < 0.01, "{f0}");
    }
    assert_eq!(j["stability"]["stable"], true);
    assert!(j["stability"]["threshold_rpm"].is_null());
    let ld = j["stability"]["min_log_dec"].as_f64().unwrap();
    assert!(ld > 0.006 && ld < 0.009, "{ld}");
    // the unbalance excites the forward mode only (isotropic supports): one peak, there
    for ch in j["unbalance_response"]["channels"].as_array().unwrap() {
        let peak = ch["peak"]["rpm"].as_f64().unwrap();
        assert!((peak - want[1]).abs() < 1.0, "{peak}");
    }
    for stem in ["campbell", "bode", "polar"] {
        let (w, h) = png_size(&out.join(format!("{stem}.png")));
        assert!(w >= 1200 && h >= 800, "{stem}: {w} x {h}");
        let svg = std::fs::read_to_string(out.join(format!("{stem}.svg"))).unwrap();
        assert!(svg.starts_with("<svg"), "{stem}");
    }
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert_eq!(html.matches("data:image/png;base64,").count(), 3);
    assert!(html.contains("2519.9") && html.contains("3089.2"));
}

#[test]
fn a_summary_carries_its_covariance_into_every_result() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("a");
    rotorid()
        .arg("analyze")
        .arg(data("identified_table1.json"))
        .args([
            "--rpm",
            "0:4000:20",
            "--probe",
            "45",
            "--unit",
            "mil",
            "--out",
        ])
        .arg(&out)
        .assert()
        .success()
        .stdout(contains("\u{b1}"));
    let j = read_json(&out.join("analysis.json"));
    let cs = j["critical_speeds"].as_array().unwrap();
    assert_eq!(cs.len(), 2);
    for c in cs {
        // m, k to ~5e-5 (40 dB): the critical speeds to ~0.015 rpm
        let s = c["std_rpm"].as_f64().unwrap();
        assert!(s > 1e-3 && s < 0.1, "{c}");
    }
    assert_eq!(
        j["rotor_std"]["a"], 0.0,
        "a is known: not in the covariance"
    );
    assert!(j["rotor_std"]["m"].as_f64().unwrap() > 0.0);
    let chs = j["unbalance_response"]["channels"].as_array().unwrap();
    assert_eq!(chs.len(), 3);
    assert_eq!(chs[2]["probe_deg"], 45.0);
    // a standard deviation wherever the response is defined above standstill
    let amp = chs[0]["std_amplitude_um_pp"].as_array().unwrap();
    assert!(amp[1..].iter().all(|v| v.as_f64().is_some_and(|s| s > 0.0)));
    let svg = std::fs::read_to_string(out.join("bode.svg")).unwrap();
    assert!(svg.contains("mil pk-pk"));
}

#[test]
fn analyze_names_what_is_wrong() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(data("identified_table1.json")).unwrap();
    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, text.replace("\"kz\": 1195022.02,", "")).unwrap();
    rotorid()
        .arg("analyze")
        .arg(&bad)
        .arg("--out")
        .arg(dir.path().join("a"))
        .assert()
        .failure()
        .stderr(contains("bad.json: missing field `rotor.kz` (N/m)"));
    rotorid()
        .args([
            "analyze",
            "--scenario",
            "table1",
            "--rpm",
            "0:6000:0",
            "--out",
        ])
        .arg(dir.path().join("b"))
        .assert()
        .failure()
        .stderr(contains("STEP = 0 must be > 0"));
    rotorid()
        .arg("analyze")
        .arg(data("identified_table1.json"))
        .args(["--scenario", "table1", "--out"])
        .arg(dir.path().join("c"))
        .assert()
        .failure()
        // (a scenario goes with a finite-element summary only: refused by name)
        .stderr(contains(
            "a scenario goes with a finite-element summary only",
        ));
    rotorid()
        .args(["analyze", "--scenario"])
        .arg(data("known_only.toml"))
        .arg("--out")
        .arg(dir.path().join("d"))
        .assert()
        .failure()
        .stderr(contains("missing key rotor.m"));
}

#[test]
fn balance_from_the_identified_unbalance() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("balance.json");
    rotorid()
        .arg("balance")
        .arg(data("identified_table1.json"))
        .args(["--radius", "0.15", "--rpm", "3000", "--out"])
        .arg(&out)
        .assert()
        .success()
        .stdout(contains("keyphasor"));
    let j = read_json(&out);
    // mud = 1.5000674e-5 kg m at alpha = 0.7853791 rad: mass mud / R opposite it
    let mass = j["mass_kg"].as_f64().unwrap();
    assert!((mass - 1.5000674e-5 / 0.15).abs() < 1e-12, "{mass}");
    let angle = j["angle_deg"].as_f64().unwrap();
    assert!(
        (angle - (0.7853791f64.to_degrees() + 180.0)).abs() < 1e-6,
        "{angle}"
    );
    let (sm, sa) = (
        j["std_mass_kg"].as_f64().unwrap(),
        j["std_angle_deg"].as_f64().unwrap(),
    );
    assert!(
        sm > 0.0 && sm < 1e-3 * mass && sa > 0.0 && sa < 0.1,
        "{sm} {sa}"
    );
    let reduction = j["predicted_reduction"].as_f64().unwrap();
    assert!(reduction > 1000.0, "{reduction}");
    let at = &j["at_speed"];
    let (before, after) = (
        at["before_um_pp"]["x"].as_f64().unwrap(),
        at["after_um_pp"]["x"].as_f64().unwrap(),
    );
    assert!((before / after / reduction - 1.0).abs() < 1e-9);
}

#[test]
fn balance_from_a_reference_and_a_trial_run() {
    // table1 (1.5e-5 kg m at 45 deg) and the same rotor with 0.2 g at 0.1 m, 200 deg added
    let dir = tempfile::tempdir().unwrap();
    let (u0, t) = ((1.5e-5f64, 45f64), (2e-5f64, 200f64));
    let (re, im) = (
        u0.0 * u0.1.to_radians().cos() + t.0 * t.1.to_radians().cos(),
        u0.0 * u0.1.to_radians().sin() + t.0 * t.1.to_radians().sin(),
    );
    let scenario = std::fs::read_to_string(data("table1.toml"))
        .unwrap()
        .replace("m_u = 1.0e-4", &format!("m_u = {:e}", re.hypot(im) / 0.15))
        .replace(
            "alpha_deg = 45.0",
            &format!("alpha_deg = {:e}", im.atan2(re).to_degrees()),
        );
    let trial_toml = dir.path().join("trial.toml");
    std::fs::write(&trial_toml, scenario).unwrap();
    let run1 = dir.path().join("run1.csv");
    let run2 = dir.path().join("run2.csv");
    for (scenario, out) in [
        (data("table1.toml"), &run1),
        (trial_toml.display().to_string(), &run2),
    ] {
        rotorid()
            .args(["simulate", "-q", "--scenario", &scenario, "--out"])
            .arg(out)
            .assert()
            .success();
    }
    let out = dir.path().join("balance.json");
    rotorid()
        .args(["balance", "--reference"])
        .arg(&run1)
        .arg("--trial")
        .arg(&run2)
        .args([
            "--trial-mass",
            "2e-4",
            "--trial-angle",
            "200",
            "--trial-radius",
            "0.1",
            "--radius",
            "0.15",
            "--out",
        ])
        .arg(&out)
        .assert()
        .success();
    let j = read_json(&out);
    assert_eq!(j["method"], "influence_coefficients");
    // the correction cancels 1.5e-5 kg m at 45 deg: 1e-4 kg at 0.15 m, 225 deg
    let mass = j["mass_kg"].as_f64().unwrap();
    let angle = j["angle_deg"].as_f64().unwrap();
    assert!((mass / 1e-4 - 1.0).abs() < 0.01, "{mass}");
    assert!((angle - 225.0).abs() < 0.5, "{angle}");
    assert!(j["std_mass_kg"].as_f64().unwrap() > 0.0);
    let at = &j["at_speed"];
    assert!((at["rpm"].as_f64().unwrap() - 1200.0).abs() < 1e-6);
    for d in ["x", "z"] {
        let (b, a) = (
            at["before_um_pp"][d].as_f64().unwrap(),
            at["after_um_pp"][d].as_f64().unwrap(),
        );
        assert!(b / a > 20.0, "{d}: {b} -> {a}");
    }

    // without phi columns the shaft angle needs a scenario
    let text = std::fs::read_to_string(&run1).unwrap();
    let no_phi: String = text
        .lines()
        .map(|l| l.splitn(4, ',').take(3).collect::<Vec<_>>().join(",") + "\n")
        .collect();
    let bare = dir.path().join("bare.csv");
    std::fs::write(&bare, no_phi).unwrap();
    rotorid()
        .args(["balance", "--reference"])
        .arg(&bare)
        .arg("--trial")
        .arg(&run2)
        .args([
            "--trial-mass",
            "2e-4",
            "--trial-angle",
            "200",
            "--radius",
            "0.15",
        ])
        .assert()
        .failure()
        .stderr(contains("bare.csv has no phi, phi_dot, phi_ddot columns"));
    // --rpm selects samples by speed: none at 1500 rpm in a 1200 rpm run
    rotorid()
        .args(["balance", "--reference"])
        .arg(&run1)
        .arg("--trial")
        .arg(&run2)
        .args([
            "--trial-mass",
            "2e-4",
            "--trial-angle",
            "200",
            "--radius",
            "0.15",
            "--rpm",
            "1500",
        ])
        .assert()
        .failure()
        .stderr(contains("0 samples within 1 % of 1500 rpm"));
}

#[test]
fn balance_help_states_the_angle_convention() {
    rotorid()
        .args(["balance", "--help"])
        .assert()
        .success()
        .stdout(contains("keyphasor reference").and(contains("direction of rotation")));
    rotorid()
        .args(["balance", "--radius", "0.1"])
        .assert()
        .failure()
        .stderr(contains("give an identification summary"));
}

#[test]
fn analyze_and_balance_read_the_summary_identify_writes() {
    // identify (refine, unbalance unknown) -> SUMMARY.json -> analyze and balance
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("n.csv");
    let summary = dir.path().join("s.json");
    rotorid()
        .args(["simulate", "--scenario", "table1", "--duration", "0.3"])
        .args(["--snr-db", "40", "--seed", "4", "-q", "--out"])
        .arg(&csv)
        .assert()
        .success();
    rotorid()
        .arg("identify")
        .arg(&csv)
        .args(["--scenario", "table1", "--method", "refine", "-q"])
        .args([
            "--unknowns",
            "m,cx,kx,cz,kz,unbalance",
            "--out",
            "-",
            "--summary",
        ])
        .arg(&summary)
        .assert()
        .success();
    let s = read_json(&summary);
    assert_eq!(crate::common::param(&s, "alpha")["determined"], true, "{s}");
    assert!(s["rotor"].is_object() && s["covariance"].is_object(), "{s}");
    let out = dir.path().join("a");
    rotorid()
        .arg("analyze")
        .arg(&summary)
        .args(["--rpm", "0:4000:20", "--out"])
        .arg(&out)
        .assert()
        .success();
    let j = read_json(&out.join("analysis.json"));
    let want = table1_critical_rpm();
    let cs = j["critical_speeds"].as_array().unwrap();
    assert_eq!(cs.len(), 2);
    for (c, w) in cs.iter().zip(want) {
        let (rpm, std) = (c["rpm"].as_f64().unwrap(), c["std_rpm"].as_f64().unwrap());
        // the identified rotor, within a few of its propagated standard deviations
        assert!((rpm - w).abs() < 5.0 * std + 0.5, "{c} vs {w}");
    }
    let b = dir.path().join("b.json");
    rotorid()
        .arg("balance")
        .arg(&summary)
        .args(["--radius", "0.15", "--out"])
        .arg(&b)
        .assert()
        .success();
    let b = read_json(&b);
    // the true unbalance is 1e-4 kg at 0.15 m, 45 deg: the correction is opposite it
    let (mass, std) = (
        b["mass_kg"].as_f64().unwrap(),
        b["std_mass_kg"].as_f64().unwrap(),
    );
    assert!((mass - 1e-4).abs() < 5.0 * std, "{b}");
}

/// A cross-coupled summary as `rotorid identify --model cross_coupled` writes it (schema 3:
/// `model`, `rotor` in the model's names, covariance names cxx, kxx, ...): the rotor of
/// `rotorid::analysis`'s tests whose forward mode goes unstable at 3208.3 rpm (a < 0:
/// the forward frequency falls with speed, and with it the damping force opposing the
/// cross-coupling).
const CROSS_SUMMARY: &str = r#"{"schema": 3, "method": "refine", "model": "cross_coupled",
  "rotor": {"m": 14.29, "cxx": 200.0, "cxz": 10.0, "czx": -5.0, "czz": 180.0,
            "kxx": 1.195e6, "kxz": -4.5e4, "kzx": 5.5e4, "kzz": 1.25e6,
            "a": -2.871, "mud": 1.5e-5, "alpha": 0.7853981633974483},
  "covariance": {"names": ["m", "cxx", "cxz", "czx", "czz", "kxx", "kxz", "kzx", "kzz", "x0"],
    "matrix": [[1.8e-3, 0, 0, 0, 0, 1.2e2, 0, 0, 0, 0],
               [0, 4.0, 0, 0, 0, 0, 0, 0, 0, 0],
               [0, 0, 1.0, 0, 0, 0, 0, 0, 0, 0],
               [0, 0, 0, 1.0, 0, 0, 0, 0, 0, 0],
               [0, 0, 0, 0, 3.24, 0, 0, 0, 0, 0],
               [1.2e2, 0, 0, 0, 0, 1.3e7, 0, 0, 0, 0],
               [0, 0, 0, 0, 0, 0, 9.0e4, -4.5e4, 0, 0],
               [0, 0, 0, 0, 0, 0, -4.5e4, 9.0e4, 0, 0],
               [0, 0, 0, 0, 0, 0, 0, 0, 1.4e7, 0],
               [0, 0, 0, 0, 0, 0, 0, 0, 0, 1e-12]]}}"#;

#[test]
fn analyze_reports_the_threshold_of_a_cross_coupled_rotor() {
    let dir = tempfile::tempdir().unwrap();
    let summary = dir.path().join("cross.json");
    std::fs::write(&summary, CROSS_SUMMARY).unwrap();
    let out = dir.path().join("a");
    rotorid()
        .arg("analyze")
        .arg(&summary)
        .args(["--rpm", "0:6000:20", "--operating-rpm", "3600", "--out"])
        .arg(&out)
        .assert()
        .success()
        .stdout(contains("UNSTABLE above the threshold speed 32"))
        .stderr(
            contains("warning: UNSTABLE above the threshold speed")
                .and(contains("the forward whirl"))
                .and(contains("cross-coupled"))
                .and(contains("UNSTABLE at the operating speed 3600.0 rpm"))
                .and(contains("stable whenever").not()),
        );
    let j = read_json(&out.join("analysis.json"));
    assert_eq!(j["model"], "cross_coupled");
    assert_eq!(j["rotor"]["kzx"], 5.5e4);
    assert!(
        j["rotor_std"]["kzx"].as_f64().unwrap() == 300.0,
        "{}",
        j["rotor_std"]
    );
    let s = &j["stability"];
    assert_eq!(s["stable"], false);
    // the library's threshold (rotorid tests/it/analysis_cross.rs: 3208.334 rpm, checked
    // there against the exact simulator), whatever the grid step
    let t = s["threshold_rpm"].as_f64().unwrap();
    assert!((t - 3208.334).abs() < 1e-3, "{s}");
    let t_std = s["threshold_rpm_std"].as_f64().unwrap();
    assert!(t_std > 1.0 && t_std < 1000.0, "{s}");
    assert_eq!(s["threshold_whirl"], "forward");
    assert_eq!(s["unstable_at_start"], false);
    assert!(s["stable_from_rpm"].is_null());
    let op = &s["operating"];
    assert_eq!(
        (op["rpm"].as_f64(), op["source"].as_str()),
        (Some(3600.0), Some("given"))
    );
    assert_eq!(op["stable"], false);
    assert_eq!(op["whirl"], "forward");
    assert!(op["log_dec"].as_f64().unwrap() < 0.0);
    assert!(op["log_dec_std"].as_f64().unwrap() > 0.0);
    for c in j["critical_speeds"].as_array().unwrap() {
        assert!(c["log_dec_std"].as_f64().unwrap() > 0.0, "{c}");
        assert!(c["std_rpm"].as_f64().unwrap() > 0.1, "{c}");
    }
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(html.contains("Unstable above the threshold speed") && html.contains("kzx"));
    assert!(!html.contains("stable at every speed"));

    // below the threshold the margin at the operating speed is positive, with its std
    rotorid()
        .arg("analyze")
        .arg(&summary)
        .args(["--rpm", "0:3000:20", "--operating-rpm", "2800", "--out"])
        .arg(&out)
        .assert()
        .success()
        .stdout(contains("stable over the range").and(contains("stability margin at 2800.0 rpm")));
    let j = read_json(&out.join("analysis.json"));
    let s = &j["stability"];
    assert_eq!(s["stable"], true);
    assert!(s["threshold_rpm"].is_null() && s["threshold_rpm_std"].is_null());
    assert!(s["operating"]["log_dec"].as_f64().unwrap() > 0.0);
}
