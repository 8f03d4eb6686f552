//! `rotorid balance` multi-plane and `rotorid onex` end to end: the worked example of
//! docs/balancing.md (a synthetic two-disk rig with four probes at two speeds whose answer
//! is known), min-max with limits, the phase conventions, holes and mass sets, trial
//! planning (from the influence estimate, and from an identified rotor against a simulated
//! trial run), raw records reduced to 1X vectors, and the errors of bad inputs.

use std::path::{Path, PathBuf};

use crate::common::{data, rotorid};
use predicates::prelude::PredicateBooleanExt;
use predicates::str::contains;
use serde_json::Value;

fn example(name: &str) -> String {
    format!(
        "{}/../../docs/examples/balance/{name}",
        env!("CARGO_MANIFEST_DIR")
    )
}

fn read_json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

fn f(v: &Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

/// The example's correction: 2.00 g at 225 deg on disk1, 1.50 g at 60 deg on disk2.
const WANT: [(&str, f64, f64); 2] = [("disk1", 2.0e-3, 225.0), ("disk2", 1.5e-3, 60.0)];

fn angle_diff(a: f64, b: f64) -> f64 {
    (a - b + 180.0).rem_euclid(360.0) - 180.0
}

fn run_balance(args: &[&str], out: &Path) -> Value {
    rotorid()
        .arg("balance")
        .args([
            "--vectors",
            &example("vectors.csv"),
            "--masses",
            &example("masses.csv"),
        ])
        .args(args)
        .arg("--out")
        .arg(out)
        .assert()
        .success();
    read_json(out)
}

#[test]
fn the_worked_example_recovers_the_known_correction_with_its_std() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("balance.json");
    let assert = rotorid()
        .arg("balance")
        .args([
            "--vectors",
            &example("vectors.csv"),
            "--masses",
            &example("masses.csv"),
        ])
        .args([
            "--current",
            "asfound",
            "--holes",
            "disk1=12",
            "--holes",
            "disk2=8@22.5",
        ])
        .arg("--out")
        .arg(&out)
        .assert()
        .success()
        .stderr(
            contains("corrections (angles from the keyphasor mark")
                .and(contains("condition number of the influence matrix"))
                .and(contains("split:")),
        );
    // the report goes to stderr, nothing to stdout
    assert!(assert.get_output().stdout.is_empty());
    let j = read_json(&out);
    assert_eq!(j["schema"], 1);
    assert_eq!(j["method"], "least_squares");
    assert_eq!(j["current_run"], "asfound");
    let cs = j["corrections"].as_array().unwrap();
    assert_eq!(cs.len(), 2);
    for (c, (plane, mass, angle)) in cs.iter().zip(WANT) {
        assert_eq!(c["plane"], plane);
        assert_eq!(f(&c["radius_m"]), 0.08);
        let (m, sm) = (f(&c["mass_kg"]), f(&c["mass_kg_std"]));
        let (a, sa) = (f(&c["angle_deg"]), f(&c["angle_deg_std"]));
        // within 4 standard deviations and a few percent of the truth
        assert!(
            (m - mass).abs() < 4.0 * sm && (m / mass - 1.0).abs() < 0.05,
            "{c}"
        );
        assert!(
            angle_diff(a, angle).abs() < 4.0 * sa && angle_diff(a, angle).abs() < 3.0,
            "{c}"
        );
        assert!(sm > 0.0 && sm < 0.05 * mass && sa > 0.0 && sa < 3.0, "{c}");
        // the split places the correction exactly (any mass)
        let s = &c["split"];
        assert!(f(&s["residual_kg_m"]) < 1e-12, "{s}");
        let placed: (f64, f64) =
            s["masses"]
                .as_array()
                .unwrap()
                .iter()
                .fold((0.0, 0.0), |acc, mm| {
                    let (r, t) = (f(&mm["mass_kg"]) * 0.08, f(&mm["angle_deg"]).to_radians());
                    (acc.0 + r * t.cos(), acc.1 + r * t.sin())
                });
        assert!((placed.0 - f(&c["unbalance_re_kg_m"])).abs() < 1e-12);
        assert!((placed.1 - f(&c["unbalance_im_kg_m"])).abs() < 1e-12);
    }
    let res = j["residual"].as_array().unwrap();
    assert_eq!(res.len(), 8);
    for r in res {
        // ~30 um before, within the noise (0.3 um) after
        assert!(f(&r["before_amplitude"]) > 5.0, "{r}");
        assert!(f(&r["amplitude"]) < 3.0 * f(&r["std"]) + 0.5, "{r}");
        assert_eq!(r["unit"], "um");
    }
    let inf = j["influence"].as_array().unwrap();
    assert_eq!(inf.len(), 16);
    assert!(inf
        .iter()
        .all(|i| f(&i["std"]) > 0.0 && i["unit"] == "um/(kg m)"));
    assert!(f(&j["condition_number"]) < 10.0);
    assert!(
        j["warnings"].as_array().unwrap().is_empty(),
        "{}",
        j["warnings"]
    );
}

#[test]
fn min_max_meets_a_limit_and_says_when_limits_cannot_be_met() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("b.json");
    // a current run that is not balanced by the calibration runs' own correction: trial1
    let ls = run_balance(&["--current", "trial1"], &out);
    let b1x = |j: &Value| {
        j["residual"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|r| r["sensor"] == "B1X")
            .map(|r| f(&r["amplitude"]))
            .fold(0.0, f64::max)
    };
    let peak = |j: &Value| {
        j["residual"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| f(&r["amplitude"]))
            .fold(0.0, f64::max)
    };
    let mm = run_balance(&["--current", "trial1", "--method", "minmax"], &out);
    assert_eq!(mm["method"], "min_max");
    assert!(
        peak(&mm) <= peak(&ls) * (1.0 + 1e-6),
        "{} {}",
        peak(&mm),
        peak(&ls)
    );
    let limit = 0.5 * b1x(&mm);
    let lim = run_balance(
        &[
            "--current",
            "trial1",
            "--method",
            "minmax",
            "--limit",
            &format!("B1X={limit}"),
        ],
        &out,
    );
    assert!(b1x(&lim) <= limit * (1.0 + 1e-6), "{} > {limit}", b1x(&lim));
    assert_eq!(f(&lim["sensors"].as_array().unwrap()[0]["limit"]), limit);
    rotorid()
        .arg("balance")
        .args([
            "--vectors",
            &example("vectors.csv"),
            "--masses",
            &example("masses.csv"),
        ])
        .args(["--current", "trial1", "--method", "minmax"])
        .args([
            "--limit", "B1X=1e-6", "--limit", "B2Y=1e-6", "--limit", "B1Y=1e-6",
        ])
        .assert()
        .failure()
        .stderr(contains(
            "the limits cannot all be met: the best correction still exceeds them by a factor",
        ));
}

/// The example's vectors as amp,phase_deg in the lag convention.
fn polar_lag(dir: &Path) -> PathBuf {
    let text = std::fs::read_to_string(example("vectors.csv")).unwrap();
    let mut out = String::from("run,speed_rpm,sensor,amp,phase_deg,unit\n");
    for l in text.lines().skip(1) {
        let v: Vec<&str> = l.split(',').collect();
        let (re, im): (f64, f64) = (v[3].parse().unwrap(), v[4].parse().unwrap());
        out.push_str(&format!(
            "{},{},{},{},{},{}\n",
            v[0],
            v[1],
            v[2],
            re.hypot(im),
            (-im.atan2(re)).to_degrees(),
            v[5]
        ));
    }
    let p = dir.join("polar.csv");
    std::fs::write(&p, out).unwrap();
    p
}

#[test]
fn amplitude_and_phase_lag_give_the_same_correction_and_lead_does_not_fit() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("b.json");
    let cart = run_balance(&["--current", "asfound"], &out);
    let polar = polar_lag(dir.path());
    let run = |phase: &str| {
        rotorid()
            .arg("balance")
            .arg("--vectors")
            .arg(&polar)
            .args([
                "--masses",
                &example("masses.csv"),
                "--current",
                "asfound",
                "--phase",
                phase,
            ])
            .arg("--out")
            .arg(&out)
            .assert()
            .success();
        read_json(&out)
    };
    let lag = run("lag");
    for (a, b) in cart["corrections"]
        .as_array()
        .unwrap()
        .iter()
        .zip(lag["corrections"].as_array().unwrap())
    {
        assert!((f(&a["mass_kg"]) / f(&b["mass_kg"]) - 1.0).abs() < 1e-9);
        assert!(angle_diff(f(&a["angle_deg"]), f(&b["angle_deg"])).abs() < 1e-6);
    }
    // lead reads every phase mirrored while the masses' angles are not: the runs no longer
    // fit one set of influence coefficients, which the fit's residuals show
    let lead = run("lead");
    let rms = |j: &Value| {
        j["fit"]
            .as_array()
            .unwrap()
            .iter()
            .map(|k| f(&k["residual_rms"]))
            .fold(0.0, f64::max)
    };
    assert!(
        rms(&lead) > 20.0 * rms(&lag),
        "{} vs {}",
        rms(&lead),
        rms(&lag)
    );
    assert!(lag["warnings"].as_array().unwrap().is_empty());
    assert!(
        lead["warnings"][0]
            .as_str()
            .unwrap()
            .contains("do not fit one set of influence coefficients"),
        "{}",
        lead["warnings"]
    );
    let d = angle_diff(
        f(&cart["corrections"][0]["angle_deg"]),
        f(&lead["corrections"][0]["angle_deg"]),
    );
    assert!(d.abs() > 5.0, "{d}");
    // without --phase the convention is asked for
    rotorid()
        .arg("balance")
        .arg("--vectors")
        .arg(&polar)
        .args(["--masses", &example("masses.csv"), "--current", "asfound"])
        .assert()
        .failure()
        .stderr(contains(
            "polar.csv line 1: the vectors are given as amp,phase_deg: say which phase convention",
        ));
}

#[test]
fn a_mass_set_split_states_its_residual_and_its_effect() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("b.json");
    let j = run_balance(
        &[
            "--current",
            "asfound",
            "--holes",
            "disk1=0,40,80,120,160,200,240,280,320",
            "--mass-set",
            "0.0005,0.001,0.002",
            "--per-hole",
            "2",
        ],
        &out,
    );
    let c = &j["corrections"][0];
    let s = &c["split"];
    assert_eq!(s["holes_deg"].as_array().unwrap().len(), 9);
    let masses = s["masses"].as_array().unwrap();
    assert!(!masses.is_empty() && masses.len() <= 2, "{s}");
    let mut placed = (0.0, 0.0);
    for m in masses {
        let w: f64 = m["weights_kg"].as_array().unwrap().iter().map(f).sum();
        assert!((w - f(&m["mass_kg"])).abs() < 1e-15, "{m}");
        let (r, t) = (f(&m["mass_kg"]) * 0.08, f(&m["angle_deg"]).to_radians());
        placed.0 += r * t.cos();
        placed.1 += r * t.sin();
    }
    let e = (placed.0 - f(&c["unbalance_re_kg_m"])).hypot(placed.1 - f(&c["unbalance_im_kg_m"]));
    assert!((e - f(&s["residual_kg_m"])).abs() < 1e-12, "{e} vs {s}");
    assert!((f(&s["residual_mass_kg"]) - e / 0.08).abs() < 1e-12);
    // its effect on the vibration is in the residual entries
    for r in j["residual"].as_array().unwrap() {
        assert!(r["split_amplitude"].is_number(), "{r}");
    }
    // disk2 has no holes: no split
    assert!(j["corrections"][1]["split"].is_null());
}

#[test]
fn planned_trials_change_the_response_by_the_fraction() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("plan.json");
    let j = run_balance(
        &["--plan", "--current", "asfound", "--fraction", "0.25"],
        &out,
    );
    assert_eq!(j["method"], "plan");
    assert_eq!(j["source"], "influence");
    let t = j["trials"].as_array().unwrap();
    assert_eq!(t.len(), 2);
    for t in t {
        let r = f(&t["change_amplitude"]) / f(&t["current_amplitude"]);
        assert!((r - 0.25).abs() < 1e-9, "{t}");
        // a few grams at 0.08 m for this rig (the calibration trials were 4-5 g)
        assert!((1e-4..2e-2).contains(&f(&t["mass_kg"])), "{t}");
    }
}

/// A copy of `toml` with the unbalance m_u d e^{i alpha} replaced by `u` \[kg m\] (d kept).
fn with_unbalance(toml: &str, d: f64, u: (f64, f64)) -> String {
    let (mud, alpha) = (u.0.hypot(u.1), u.1.atan2(u.0).to_degrees());
    toml.lines()
        .map(|l| {
            if l.trim_start().starts_with("m_u ") {
                format!("m_u = {:e}", mud / d)
            } else if l.trim_start().starts_with("alpha_deg ") {
                format!("alpha_deg = {alpha:e}")
            } else {
                l.to_owned()
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// The 1X vectors of x and z of a simulated response CSV (the last half second).
fn one_x_of(csv: &Path) -> [(f64, f64); 2] {
    let text = std::fs::read_to_string(csv).unwrap();
    let rows: Vec<Vec<f64>> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    let half = &rows[rows.len() / 2..];
    let phi: Vec<f64> = half.iter().map(|r| r[3]).collect();
    [1, 2].map(|c| {
        let s: Vec<f64> = half.iter().map(|r| r[c]).collect();
        let v = rotorid::analysis::one_x(&s, &phi).unwrap().unwrap().vector;
        (v.re, v.im)
    })
}

#[test]
fn a_trial_planned_from_the_identified_rotor_changes_the_simulated_response_as_planned() {
    // the identified table1 rotor (1.5e-5 kg m at 45 deg) plans a trial at 1200 rpm; the
    // rotor simulated with and without it gives the measured change at the probe the plan
    // names
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("plan.json");
    rotorid()
        .arg("balance")
        .arg(data("identified_table1.json"))
        .args([
            "--plan", "--speeds", "1200", "--radius", "0.15", "--holes", "disk=8",
        ])
        .arg("--out")
        .arg(&out)
        .assert()
        .success()
        .stderr(contains("trial masses changing the 1X response by 30 %"));
    let j = read_json(&out);
    assert_eq!(j["source"], "model");
    let t = &j["trials"][0];
    let (m, a) = (f(&t["mass_kg"]), f(&t["angle_deg"]));
    assert!((m * 0.15 / (0.3 * 1.5000674e-5) - 1.0).abs() < 1e-6, "{t}");
    assert!(angle_diff(a, 45.0 + 180.0).abs() < 0.01, "{t}");
    assert!(t["split"]["masses"].as_array().unwrap().len() == 2);
    // measure: table1 (1.5e-5 kg m at 45 deg, d = 0.15) with and without the trial
    let toml = std::fs::read_to_string(data("table1.toml")).unwrap();
    let u0 = (
        1.5e-5 * 45f64.to_radians().cos(),
        1.5e-5 * 45f64.to_radians().sin(),
    );
    let tr = (
        m * 0.15 * a.to_radians().cos(),
        m * 0.15 * a.to_radians().sin(),
    );
    let mut vectors = Vec::new();
    for (name, u) in [("before", u0), ("after", (u0.0 + tr.0, u0.1 + tr.1))] {
        let sc = dir.path().join(format!("{name}.toml"));
        std::fs::write(&sc, with_unbalance(&toml, 0.15, u)).unwrap();
        let csv = dir.path().join(format!("{name}.csv"));
        rotorid()
            .args(["simulate", "-q", "--duration", "3", "--scenario"])
            .arg(&sc)
            .arg("--out")
            .arg(&csv)
            .assert()
            .success();
        vectors.push(one_x_of(&csv));
    }
    let probe = if t["sensor"] == "x" { 0 } else { 1 };
    let norm = |v: (f64, f64)| v.0.hypot(v.1);
    let (b, a) = (vectors[0][probe], vectors[1][probe]);
    let measured = norm((a.0 - b.0, a.1 - b.1));
    let planned = f(&t["change_amplitude"]);
    let ratio = measured / planned;
    assert!(
        (0.5..=2.0).contains(&ratio),
        "measured {measured:e} planned {planned:e}"
    );
    // and the response fell by about the fraction: the trial opposes the unbalance
    let before = norm(b);
    assert!(((before - norm(a)) / before - 0.3).abs() < 0.05);
}

#[test]
fn raw_records_give_vectors_and_balance_a_simulated_rig() {
    // rig.toml (4e-3 kg at 0.15 m, 45 deg) as found and with a trial of 2e-3 kg at 0.15 m,
    // 200 deg: raw probe volts and keyphasor, reduced to 1X vectors by `rotorid onex` and
    // balanced; the correction cancels the as-found unbalance
    let dir = tempfile::tempdir().unwrap();
    let p = |n: &str| dir.path().join(n);
    let toml = std::fs::read_to_string(data("rig.toml")).unwrap();
    let u0 = (
        6e-4 * 45f64.to_radians().cos(),
        6e-4 * 45f64.to_radians().sin(),
    );
    let t = (
        3e-4 * 200f64.to_radians().cos(),
        3e-4 * 200f64.to_radians().sin(),
    );
    for (name, u) in [("asfound", u0), ("trial", (u0.0 + t.0, u0.1 + t.1))] {
        let sc = p(&format!("{name}.toml"));
        std::fs::write(&sc, with_unbalance(&toml, 0.15, u)).unwrap();
        rotorid()
            .args(["simulate", "-q", "--duration", "2", "--raw", "--scenario"])
            .arg(&sc)
            .arg("--out")
            .arg(p(&format!("{name}.csv")))
            .arg("--slow-roll-out")
            .arg(p("rig_slowroll.csv"))
            .assert()
            .success();
    }
    std::fs::write(p("rig.toml"), &toml).unwrap();
    let vectors = p("vectors.csv");
    rotorid()
        .arg("onex")
        .arg(p("asfound.csv"))
        .arg(p("trial.csv"))
        .arg("--scenario")
        .arg(p("rig.toml"))
        .arg("--out")
        .arg(&vectors)
        .assert()
        .success();
    let text = std::fs::read_to_string(&vectors).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines[0], "run,speed_rpm,sensor,re,im,unit,re_std,im_std");
    assert_eq!(lines.len(), 5, "{text}");
    assert!(
        lines[1].starts_with("asfound,") && lines[1].contains(",probe_L,"),
        "{text}"
    );
    let speed: f64 = lines[1].split(',').nth(1).unwrap().parse().unwrap();
    assert!((speed - 1200.0).abs() < 0.5, "{speed}");
    std::fs::write(
        p("masses.csv"),
        "run,plane,mass_kg,radius_m,angle_deg\nasfound,disk,0,0.15,0\ntrial,disk,0.002,0.15,200\n",
    )
    .unwrap();
    let out = p("b.json");
    rotorid()
        .args(["balance", "--vectors"])
        .arg(&vectors)
        .arg("--masses")
        .arg(p("masses.csv"))
        .args(["--current", "asfound", "--out"])
        .arg(&out)
        .assert()
        .success();
    let j = read_json(&out);
    let c = &j["corrections"][0];
    let (m, sm, a) = (f(&c["mass_kg"]), f(&c["mass_kg_std"]), f(&c["angle_deg"]));
    // 4e-3 kg at 225 deg, within a few percent (the free transient of the simulation from
    // rest is in the records) and within its standard deviations
    assert!(
        (m / 4e-3 - 1.0).abs() < 0.05 && (m - 4e-3).abs() < 5.0 * sm,
        "{c}"
    );
    assert!(angle_diff(a, 225.0).abs() < 3.0, "{c}");
    // --raw in balance reads the records the same way
    let out2 = p("b2.json");
    rotorid()
        .arg("balance")
        .arg("--raw")
        .arg(format!("asfound={}", p("asfound.csv").display()))
        .arg("--raw")
        .arg(format!("trial={}", p("trial.csv").display()))
        .arg("--scenario")
        .arg(p("rig.toml"))
        .arg("--masses")
        .arg(p("masses.csv"))
        .args(["--current", "asfound", "--out"])
        .arg(&out2)
        .assert()
        .success();
    let j2 = read_json(&out2);
    assert!((f(&j2["corrections"][0]["mass_kg"]) / m - 1.0).abs() < 1e-9);
}

#[test]
fn bad_inputs_are_named_by_file_line_column_and_range() {
    let dir = tempfile::tempdir().unwrap();
    let w = |name: &str, text: &str| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p.display().to_string()
    };
    let masses = example("masses.csv");
    let vectors = example("vectors.csv");
    let cases: Vec<(Vec<String>, String)> = vec![
        (
            vec!["--vectors".into(), w("v1.csv", "run,speed_rpm,sensor,re,im,unit\nasfound,1800,B1X,1,zz,um\n"), "--masses".into(), masses.clone(), "--current".into(), "asfound".into()],
            "v1.csv line 2, column 5 (im): im \"zz\" is not a number: expected a number".into(),
        ),
        (
            vec!["--vectors".into(), vectors.clone(), "--masses".into(), w("m1.csv", "run,plane,mass_kg,radius_m,angle_deg\nasfound,disk1,-0.1,0.08,0\n"), "--current".into(), "asfound".into()],
            "m1.csv line 2, column 3 (mass_kg): mass_kg = -0.1 is out of range: must be finite and >= 0 (kg)".into(),
        ),
        (
            vec!["--vectors".into(), vectors.clone(), "--masses".into(), w("m2.csv", "run,plane,mass_kg\n"), "--current".into(), "asfound".into()],
            "m2.csv line 1: the header lacks columns radius_m, angle_deg".into(),
        ),
        (
            vec!["--vectors".into(), vectors.clone(), "--masses".into(), masses.clone(), "--current".into(), "later".into()],
            "run \"later\" has no 1X vector: the runs with vectors are \"asfound\", \"trial1\", \"trial2\", \"trial12\"".into(),
        ),
        (
            vec!["--vectors".into(), vectors.clone(), "--masses".into(), masses.clone(), "--current".into(), "asfound".into(), "--holes".into(), "disk1=twelve".into()],
            "--holes \"disk1=twelve\": \"twelve\" is not a number of holes".into(),
        ),
        (
            vec!["--vectors".into(), vectors.clone(), "--masses".into(), masses.clone(), "--current".into(), "asfound".into(), "--limit".into(), "B1Z=3".into()],
            "limit names sensor \"B1Z\", which the data do not have: the sensors are \"B1X\", \"B1Y\", \"B2X\", \"B2Y\"".into(),
        ),
        (
            vec!["--vectors".into(), vectors.clone(), "--masses".into(), masses.clone(), "--current".into(), "asfound".into(), "--speeds".into(), "2400".into()],
            "no 1X vector at 2400 rpm (within 1 %): the vectors are at 1800, 3000 rpm".into(),
        ),
        (
            vec!["--vectors".into(), vectors.clone(), "--masses".into(), masses.clone()],
            "give --current RUN".into(),
        ),
        (
            vec!["--vectors".into(), vectors.clone(), "--current".into(), "asfound".into()],
            "give --masses masses.csv".into(),
        ),
    ];
    for (args, want) in cases {
        rotorid()
            .arg("balance")
            .args(&args)
            .assert()
            .failure()
            .stderr(contains(want.as_str()));
    }
}

#[test]
fn one_speed_subset_and_plane_subset_are_balanced_alone() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("b.json");
    let j = run_balance(
        &[
            "--current",
            "asfound",
            "--speeds",
            "3000",
            "--planes",
            "disk2",
        ],
        &out,
    );
    assert_eq!(j["speeds_rpm"].as_array().unwrap().len(), 1);
    assert_eq!(j["residual"].as_array().unwrap().len(), 4);
    let cs = j["corrections"].as_array().unwrap();
    assert_eq!(cs.len(), 1);
    assert_eq!(cs[0]["plane"], "disk2");
    // a radius per plane: the same unbalance, the mass scaled
    let j2 = run_balance(&["--current", "asfound", "--radius", "disk1=0.16"], &out);
    let j1 = run_balance(&["--current", "asfound"], &out);
    let (m1, m2) = (
        f(&j1["corrections"][0]["mass_kg"]),
        f(&j2["corrections"][0]["mass_kg"]),
    );
    assert!((m2 / m1 - 0.5).abs() < 1e-12);
    assert_eq!(f(&j2["corrections"][1]["radius_m"]), 0.08);
}
