//! `rotorid simulate` of a finite-element scenario: the matrices file beside
//! the scenario, the response at every degree of freedom under `<node>.<dof>` columns,
//! checked end to end against an independent path: a one-node rotor is the cross-coupled
//! 2-DOF model under x = x, y = -z (docs/finite_element.md section 2), which `rotorid
//! simulate` integrates with its own simulators (exact discretisation, DoPri8 on a ramp).

use rotorid_io::FeMatricesFile;

use crate::common::{rotorid, simulate};

const A: f64 = 2.871;
const M: f64 = 14.29;

/// The one-node rotor's matrices (dofs 0.x, 0.y) in `dir/m.npz`.
fn matrices(dir: &std::path::Path) {
    rotorid_io::fe_matrices::write(
        dir.join("m.npz"),
        &FeMatricesFile {
            file: String::new(),
            dofs: vec!["0.x".into(), "0.y".into()],
            m: vec![M, 0.0, 0.0, M],
            k: vec![0.0; 4],
            g: vec![0.0, A, -A, 0.0],
            c: None,
            ka: Some(vec![0.0, A, 0.0, 0.0]),
        },
    )
    .unwrap();
}

/// The [speed] and [sampling] sections.
fn speed(ramp: bool) -> &'static str {
    if ramp {
        "[speed]\nkind = \"ramp\"\nrpm0 = 600.0\naccel = 40.0\n\n[sampling]\ndt = 1e-4\nduration = 0.3\n"
    } else {
        "[speed]\nkind = \"constant\"\nrpm = 1200.0\n\n[sampling]\ndt = 1e-4\nduration = 0.3\n"
    }
}

/// The same rotor as a finite-element scenario and as a cross-coupled one.
pub(crate) fn scenarios(dir: &std::path::Path, ramp: bool) -> (String, String) {
    matrices(dir);
    let fe = dir.join(format!("fe{ramp}.toml"));
    std::fs::write(
        &fe,
        format!(
            "[rotor]\nmodel = \"finite_element\"\nmatrices = \"m.npz\"\n\n[[rotor.bearing]]\n\
             node = 0\nkxx = 1.195e6\nkxy = 3.0e4\nkyx = -3.0e4\nkyy = 1.4e6\ncxx = 200.0\n\
             cxy = -20.0\ncyx = -20.0\ncyy = 200.0\n\n[[rotor.unbalance]]\nnode = 0\n\
             m_u = 1e-4\nd = 0.15\nalpha_deg = -45.0\n\n{}",
            speed(ramp)
        ),
    )
    .unwrap();
    let cross = dir.join(format!("cross{ramp}.toml"));
    std::fs::write(
        &cross,
        format!(
            "[rotor]\nmodel = \"cross_coupled\"\nm = {M}\na = {A}\nkxx = 1.195e6\n\
             kxz = -3.0e4\nkzx = 3.0e4\nkzz = 1.4e6\ncxx = 200.0\ncxz = 20.0\nczx = 20.0\n\
             czz = 200.0\nm_u = 1e-4\nd = 0.15\nalpha_deg = 45.0\n\n{}",
            speed(ramp)
        ),
    )
    .unwrap();
    (
        fe.to_str().unwrap().to_owned(),
        cross.to_str().unwrap().to_owned(),
    )
}

pub(crate) fn columns(csv: &str) -> (String, Vec<Vec<f64>>) {
    let mut lines = csv.lines();
    let header = lines.next().unwrap().to_owned();
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

#[test]
fn a_one_node_rotor_simulates_as_the_cross_coupled_model() {
    let dir = tempfile::tempdir().unwrap();
    for ramp in [false, true] {
        let (fe, cross) = scenarios(dir.path(), ramp);
        let (header, f) = columns(&simulate(&["--scenario", &fe]));
        assert_eq!(header, "t,0.x,0.y,phi,phi_dot,phi_ddot");
        let (_, c) = columns(&simulate(&["--scenario", &cross]));
        assert_eq!(f.len(), 3001);
        let amplitude = c
            .iter()
            .fold(0.0f64, |a, r| a.max(r[1].abs()).max(r[2].abs()));
        let mut worst = 0.0f64;
        for (a, b) in f.iter().zip(&c) {
            assert_eq!(a[0], b[0]);
            // x = x, y = -z; the speed columns equal
            worst = worst.max((a[1] - b[1]).abs()).max((a[2] + b[2]).abs());
            for k in 3..6 {
                assert!(
                    (a[k] - b[k]).abs() <= 1e-12 * b[k].abs().max(1.0),
                    "{a:?} {b:?}"
                );
            }
        }
        println!(
            "ramp {ramp}: worst difference {:.1e} of the amplitude",
            worst / amplitude
        );
        assert!(
            worst < 1e-9 * amplitude,
            "ramp {ramp}: {worst:e} of {amplitude:e}"
        );
    }
}

#[test]
fn noise_is_reproducible_and_two_dof_options_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let (fe, _) = scenarios(dir.path(), false);
    let a = simulate(&["--scenario", &fe, "--snr-db", "40", "--seed", "3"]);
    assert_eq!(
        a,
        simulate(&["--scenario", &fe, "--snr-db", "40", "--seed", "3"])
    );
    assert_ne!(
        a,
        simulate(&["--scenario", &fe, "--snr-db", "40", "--seed", "4"])
    );
    let (_, clean) = columns(&simulate(&["--scenario", &fe]));
    let (_, noisy) = columns(&a);
    // sigma = RMS * 10^(-40/20): the residual's RMS within 10 % of it on 3001 samples
    for col in [1, 2] {
        let rms = |v: &dyn Fn(&Vec<f64>) -> f64| {
            (clean.iter().map(v).map(|x| x * x).sum::<f64>() / clean.len() as f64).sqrt()
        };
        let signal = rms(&|r| r[col]);
        let residual = (noisy
            .iter()
            .zip(&clean)
            .map(|(n, c)| (n[col] - c[col]).powi(2))
            .sum::<f64>()
            / clean.len() as f64)
            .sqrt();
        assert!(
            (residual / (0.01 * signal) - 1.0).abs() < 0.1,
            "{residual:e} {signal:e}"
        );
    }
    let out = rotorid()
        .args([
            "simulate",
            "--scenario",
            &fe,
            "--initial-x",
            "1e-5",
            "--out",
            "-",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let e = String::from_utf8_lossy(&out.stderr);
    assert!(
        e.contains("--initial-x") && e.contains("finite-element"),
        "{e}"
    );
}

/// The value of `name` in a summary's parameters.
pub(crate) fn param<'a>(s: &'a serde_json::Value, name: &str) -> &'a serde_json::Value {
    s["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["parameter"] == name)
        .unwrap_or_else(|| panic!("{name} in {s}"))
}

#[test]
fn identify_of_a_one_node_rotor_equals_the_cross_coupled_refine_on_the_same_data() {
    // the same noisy record identified twice: as a finite-element rotor (refine_fe: the
    // reduced model, unit responses and finite differences) and as the cross-coupled 2-DOF
    // model (rotorid's 2-DOF refine, another code) under x = x, y = -z: the same maximum-
    // likelihood problem, so the same estimates and standard errors
    let dir = tempfile::tempdir().unwrap();
    let (fe, cross) = scenarios(dir.path(), false);
    let rec = simulate(&["--scenario", &cross, "--snr-db", "40", "--seed", "3"]);
    let (header, rows) = columns(&rec);
    assert!(header.starts_with("t,x,z,"), "{header}");
    let mut fe_csv = String::from("t,0.x,0.y\n");
    for r in &rows {
        fe_csv.push_str(&format!("{:e},{:e},{:e}\n", r[0], r[1], -r[2]));
    }
    let (fe_rec, cross_rec) = (dir.path().join("fe.csv"), dir.path().join("cross.csv"));
    std::fs::write(&fe_rec, fe_csv).unwrap();
    std::fs::write(&cross_rec, &rec).unwrap();
    let (est, s) =
        crate::common::identify_outputs(dir.path(), fe_rec.to_str().unwrap(), &fe, "refine", &[]);
    let (_, c) = crate::common::identify_outputs(
        dir.path(),
        cross_rec.to_str().unwrap(),
        &cross,
        "refine",
        &["--unknowns", "cxx,czz,kxx,kzz,unbalance"],
    );
    assert_eq!(s["model"], "finite_element");
    assert_eq!(s["schema"], 3);
    assert_eq!(s["initial"], "estimated");
    assert_eq!(s["record"]["channels"], serde_json::json!(["0.x", "0.y"]));
    assert_eq!(s["converged"], true);
    assert_eq!(s["adequacy"]["model_adequate"], true);
    let names: Vec<&str> = s["covariance"]["names"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_str().unwrap())
        .collect();
    assert_eq!(
        names,
        [
            "bearing0.kxx",
            "bearing0.kyy",
            "bearing0.cxx",
            "bearing0.cyy",
            "unbalance0.mud",
            "unbalance0.alpha"
        ]
    );
    let two_dof = |n: &str| -> serde_json::Value {
        c["parameters"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["parameter"] == n)
            .unwrap_or_else(|| panic!("{n} in {c}"))
            .clone()
    };
    for (f, x, shift) in [
        ("bearing0.kxx", "kxx", 0.0),
        ("bearing0.kyy", "kzz", 0.0),
        ("bearing0.cxx", "cxx", 0.0),
        ("bearing0.cyy", "czz", 0.0),
        ("unbalance0.mud", "mud", 0.0),
        ("unbalance0.alpha", "alpha", -std::f64::consts::FRAC_PI_2),
    ] {
        let (a, b) = (param(&s, f), &two_dof(x));
        let (va, vb) = (
            a["value"].as_f64().unwrap(),
            b["estimate"].as_f64().unwrap() + shift,
        );
        let (sa, sb) = (
            a["std_error"].as_f64().unwrap(),
            b["std_error"].as_f64().unwrap(),
        );
        println!("{f}: {va:.9e} +- {sa:.3e}   2-DOF {x}: {vb:.9e} +- {sb:.3e}");
        assert!((va - vb).abs() < 0.01 * sa, "{f}: {va} vs {vb} (std {sa})");
        assert!((sa / sb - 1.0).abs() < 0.01, "{f}: std {sa} vs {sb}");
    }
    // the estimates table: one row, each unknown and its standard error, units in the header
    let est = String::from_utf8(est).unwrap();
    let mut lines = est.lines();
    let h = lines.next().unwrap();
    assert!(
        h.starts_with("t,bearing0.kxx [N/m],bearing0.kxx_std [N/m],"),
        "{h}"
    );
    assert_eq!(lines.count(), 1);
}

#[test]
fn identify_of_a_finite_element_rotor_refuses_what_does_not_apply_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let (fe, cross) = scenarios(dir.path(), false);
    let rec = dir.path().join("r.csv");
    std::fs::write(&rec, "t,0.x,0.y\n0,0,0\n0.0001,0,0\n").unwrap();
    let run = |args: &[&str]| {
        let out = rotorid().arg("identify").args(args).output().unwrap();
        assert!(!out.status.success());
        String::from_utf8_lossy(&out.stderr).into_owned()
    };
    let r = rec.to_str().unwrap();
    let e = run(&[r, "--scenario", &fe, "--method", "algebraic", "--out", "-"]);
    assert!(e.contains("--method refine"), "{e}");
    let e = run(&[
        r,
        "--scenario",
        &fe,
        "--method",
        "refine",
        "--unknowns",
        "bearing3.kxx",
        "--out",
        "-",
    ]);
    assert!(
        e.contains("bearing3.kxx") && e.contains("bearing0 .. bearing0"),
        "{e}"
    );
    let e = run(&[
        r,
        "--scenario",
        &fe,
        "--method",
        "refine",
        "--initial",
        "moving",
        "--out",
        "-",
    ]);
    assert!(e.contains("moving") && e.contains("rest"), "{e}");
    let e = run(&[
        r,
        "--scenario",
        &fe,
        "--method",
        "refine",
        "--modes",
        "3",
        "--out",
        "-",
    ]);
    assert!(e.contains("--modes = 3") && e.contains("1 ..= 2"), "{e}");
    // and the finite-element flags on a 2-DOF scenario
    let e = run(&[
        r,
        "--scenario",
        &cross,
        "--method",
        "refine",
        "--initial",
        "rest",
        "--out",
        "-",
    ]);
    assert!(
        e.contains("--initial applies to a finite-element rotor only"),
        "{e}"
    );
    let e = run(&[
        r,
        "--scenario",
        &cross,
        "--method",
        "refine",
        "--offsets",
        "--out",
        "-",
    ]);
    assert!(
        e.contains("--offsets applies to a finite-element rotor only"),
        "{e}"
    );
    let e = run(&[
        r,
        "--scenario",
        &cross,
        "--method",
        "refine",
        "--unknowns",
        "bearing0.kxx",
        "--out",
        "-",
    ]);
    assert!(
        e.contains("invalid value 'bearing0.kxx'") && e.contains("finite_element"),
        "{e}"
    );
}
