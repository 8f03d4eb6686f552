//! `rotorid predict SUMMARY.json --scenario fe.toml --dofs ... --out ...`
//! on a one-node finite-element rotor with a hand-written summary (the contract of the
//! finite-element SUMMARY.json): the prediction is the identified rotor simulated by
//! `rotorid simulate`; its standard deviation is checked against the closed-form
//! steady state's (once the transient has died out) and a Monte Carlo over the covariance
//! (while it has not); zero covariance gives zero; bad input is refused by name.

use std::path::Path;
use std::sync::Arc;

use nalgebra::{Complex, DMatrix, DVector, Matrix2, Vector2};
use rotorid::model::finite_element::{
    Bearing, FeMatrices, FeSystem, FeUnbalance, FiniteElementRotor,
};
use rotorid::simulate::finite_element::{simulate_fe, FeInitialState, FeMethod};
use rotorid::{Sampling, SpeedProfile};
use rotorid_io::FeMatricesFile;
use serde_json::json;

use crate::common::{rotorid, simulate};

pub const M: f64 = 14.29;
pub const A: f64 = 2.871;
/// 1200 rpm \[rad/s\].
pub const W: f64 = 40.0 * std::f64::consts::PI;

/// The identified values (the summary's), in the covariance's order.
pub const NAMES: [&str; 6] = [
    "bearing0.kxx",
    "bearing0.kyy",
    "bearing0.cxx",
    "bearing0.cyy",
    "unbalance0.mud",
    "unbalance0.alpha",
];
pub const VALUES: [f64; 6] = [1.2e6, 1.4e6, 1700.0, 1500.0, 1.5e-5, 0.7];
/// Standard deviations: 1 % on stiffness, 3 % on damping, 2 % on mud, 0.02 rad.
pub const SD: [f64; 6] = [1.2e4, 1.4e4, 51.0, 45.0, 3e-7, 0.02];

/// The covariance, correlated.
pub fn covariance() -> Vec<Vec<f64>> {
    let corr = |i: usize, j: usize| {
        if i == j {
            1.0
        } else {
            0.25 * (((i * 3 + j * 3 + i * j) % 5) as f64 / 5.0 - 0.4)
        }
    };
    (0..6)
        .map(|i| (0..6).map(|j| corr(i, j) * SD[i] * SD[j]).collect())
        .collect()
}

/// The one-node rotor's matrices (dofs 0.x, 0.y; docs/finite_element.md section 2) in
/// `dir/m.npz`, the scenario `dir/fe.toml` with nominal values other than the summary's
/// (constant 1200 rpm, 0.6 s at 1 kHz), and `dir/identified.toml` with the summary's.
pub fn setup(dir: &Path) -> (String, String) {
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
    let scenario = |kxx: f64, kyy: f64, cxx: f64, cyy: f64, mud: f64, alpha: f64| {
        format!(
            "[rotor]\nmodel = \"finite_element\"\nmatrices = \"m.npz\"\n\n[[rotor.bearing]]\n\
             node = 0\nkxx = {kxx:e}\nkxy = 3.0e4\nkyx = -3.0e4\nkyy = {kyy:e}\ncxx = {cxx:e}\n\
             cyy = {cyy:e}\n\n[[rotor.unbalance]]\nnode = 0\nm_u = {mud:e}\nd = 1.0\n\
             alpha_deg = {}\n\n[speed]\nkind = \"constant\"\nrpm = 1200.0\n\n[sampling]\n\
             dt = 1e-3\nduration = 0.6\n",
            alpha.to_degrees()
        )
    };
    let fe = dir.join("fe.toml");
    std::fs::write(&fe, scenario(1.0e6, 1.1e6, 1000.0, 1000.0, 1e-5, 0.0)).unwrap();
    let v = VALUES;
    let id = dir.join("identified.toml");
    std::fs::write(&id, scenario(v[0], v[1], v[2], v[3], v[4], v[5])).unwrap();
    (
        fe.to_str().unwrap().to_owned(),
        id.to_str().unwrap().to_owned(),
    )
}

/// A summary of the contract's layout with the identified values, `covariance` (JSON) and
/// the initial state, in `dir/NAME`.
pub fn summary(
    dir: &Path,
    name: &str,
    cov: serde_json::Value,
    initial: serde_json::Value,
) -> String {
    let parameters: Vec<serde_json::Value> = NAMES
        .iter()
        .zip(VALUES)
        .map(|(n, v)| json!({"parameter": n, "unit": "", "value": v, "estimate": v}))
        .collect();
    let (kind, state) = if initial.is_null() {
        ("rest", serde_json::Value::Null)
    } else {
        ("estimated", initial)
    };
    let s = json!({
        "schema": 3, "method": "refine", "model": "finite_element",
        "parameters": parameters,
        "rotor": {"bearings": [{"node": 0}], "unbalances": [{"node": 0}]},
        "covariance": cov,
        "initial": kind, "initial_state": state,
        "converged": true, "identifiable": true
    });
    let p = dir.join(name);
    std::fs::write(&p, serde_json::to_string_pretty(&s).unwrap()).unwrap();
    p.to_str().unwrap().to_owned()
}

pub fn cov_json(m: &[Vec<f64>]) -> serde_json::Value {
    json!({"names": NAMES, "matrix": m})
}

/// A CSV's header and rows (an empty cell: None).
type Table = (String, Vec<Vec<Option<f64>>>);

/// `rotorid predict ARGS --out -`: (header, rows), or the error text.
fn predict(args: &[&str]) -> Result<Table, String> {
    let out = rotorid()
        .arg("predict")
        .args(args)
        .args(["--out", "-", "-q"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!err.contains("panicked"), "{err}");
    if !out.status.success() {
        return Err(err);
    }
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().to_owned();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().ok()).collect())
        .collect();
    Ok((header, rows))
}

/// The identified rotor, built here from the same numbers.
fn identified_rotor() -> FiniteElementRotor {
    let d = ["0.x", "0.y"].map(|s| s.parse().unwrap()).to_vec();
    let mats = FeMatrices::new(
        d,
        DMatrix::from_row_slice(2, 2, &[M, 0.0, 0.0, M]),
        DMatrix::zeros(2, 2),
        DMatrix::from_row_slice(2, 2, &[0.0, A, -A, 0.0]),
        None,
        Some(DMatrix::from_row_slice(2, 2, &[0.0, A, 0.0, 0.0])),
    )
    .unwrap();
    let v = VALUES;
    let b = Bearing {
        node: 0,
        kxx: v[0],
        kxy: 3.0e4,
        kyx: -3.0e4,
        kyy: v[1],
        cxx: v[2],
        cxy: 0.0,
        cyx: 0.0,
        cyy: v[3],
    };
    let u = FeUnbalance {
        node: 0,
        mud: v[4],
        alpha: v[5],
    };
    FiniteElementRotor::new(Arc::new(mats), vec![b], vec![u]).unwrap()
}

#[test]
fn predict_is_the_identified_rotor_simulated() {
    let dir = tempfile::tempdir().unwrap();
    let (fe, identified) = setup(dir.path());
    let s = summary(
        dir.path(),
        "s.json",
        cov_json(&covariance()),
        serde_json::Value::Null,
    );
    let (header, rows) = predict(&[&s, "--scenario", &fe, "--dofs", "0.y,0.x"]).unwrap();
    assert_eq!(header, "t,0.y,0.x,0.y_std,0.x_std");
    let sim = simulate(&["--scenario", &identified]);
    let mut lines = sim.lines();
    assert_eq!(lines.next().unwrap(), "t,0.x,0.y,phi,phi_dot,phi_ddot");
    let sim: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 601);
    assert_eq!(sim.len(), rows.len());
    let amp = sim
        .iter()
        .fold(0.0f64, |a, r| a.max(r[1].abs()).max(r[2].abs()));
    for (p, q) in rows.iter().zip(&sim) {
        assert_eq!(p[0], Some(q[0]));
        assert!((p[1].unwrap() - q[2]).abs() <= 1e-12 * amp, "{p:?} {q:?}");
        assert!((p[2].unwrap() - q[1]).abs() <= 1e-12 * amp, "{p:?} {q:?}");
        // the scenario's own values would give another response
    }
    let (_, nominal) = columns_of(&simulate(&["--scenario", &fe]));
    let differs = nominal
        .iter()
        .zip(&sim)
        .any(|(a, b)| (a[1] - b[1]).abs() > 1e-3 * amp);
    assert!(
        differs,
        "the test must tell the identified values from the scenario's"
    );
}

fn columns_of(csv: &str) -> (String, Vec<Vec<f64>>) {
    let mut lines = csv.lines();
    let h = lines.next().unwrap().to_owned();
    (
        h,
        lines
            .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
            .collect(),
    )
}

/// The closed-form steady state's standard deviation at t (the 1X response Re(Q e^{i W t}),
/// (K0 - W^2 M + i W (C0 + W G)) Q = W^2 P, differentiated by hand over the six unknowns).
fn steady_std(t: f64, cov: &[Vec<f64>]) -> [f64; 2] {
    let v = VALUES;
    let i = Complex::new(0.0, 1.0);
    let c = |x: f64| Complex::new(x, 0.0);
    let d = Matrix2::new(
        c(v[0] - W * W * M) + i * W * v[2],
        c(3.0e4) + i * W * (W * A),
        c(-3.0e4) + i * W * (-W * A),
        c(v[1] - W * W * M) + i * W * v[3],
    );
    let p = Vector2::new(c(1.0), -i) * Complex::from_polar(v[4], v[5]);
    let dinv = d.try_inverse().unwrap();
    let w2 = c(W * W);
    let q = dinv * p * w2;
    let e = |r: usize, col: usize| {
        let mut m = Matrix2::zeros();
        m[(r, col)] = c(1.0);
        m
    };
    let dq = [
        -dinv * e(0, 0) * q,
        -dinv * e(1, 1) * q,
        -dinv * e(0, 0) * q * (i * W),
        -dinv * e(1, 1) * q * (i * W),
        dinv * p * (w2 / v[4]),
        dinv * p * (w2 * i),
    ];
    let ph = Complex::from_polar(1.0, W * t);
    let mut out = [0.0; 2];
    for (k, o) in out.iter_mut().enumerate() {
        let g: Vec<f64> = dq.iter().map(|x| (x[k] * ph).re).collect();
        let mut var = 0.0f64;
        for a in 0..6 {
            for b in 0..6 {
                var += g[a] * cov[a][b] * g[b];
            }
        }
        *o = var.sqrt();
    }
    out
}

#[test]
fn predict_std_is_the_closed_form_steady_state_std_after_the_transient() {
    let dir = tempfile::tempdir().unwrap();
    let (fe, _) = setup(dir.path());
    let cov = covariance();
    let s = summary(
        dir.path(),
        "s.json",
        cov_json(&cov),
        serde_json::Value::Null,
    );
    let (_, rows) = predict(&[&s, "--scenario", &fe, "--dofs", "0.x,0.y"]).unwrap();
    // the slowest decay rate is ~60 1/s (zeta ~ 0.2): from 0.45 s the transient is < 1e-11
    let mut worst = 0.0f64;
    for r in rows.iter().filter(|r| r[0].unwrap() >= 0.45) {
        let want = steady_std(r[0].unwrap(), &cov);
        for k in 0..2 {
            let got = r[3 + k].unwrap();
            worst = worst.max((got - want[k]).abs() / want[k]);
        }
    }
    println!("predict std against the closed form: worst relative difference {worst:.1e}");
    assert!(worst < 1e-6, "{worst:e}");
    // a zero covariance: zero band
    let zero = vec![vec![0.0; 6]; 6];
    let s0 = summary(
        dir.path(),
        "s0.json",
        cov_json(&zero),
        serde_json::Value::Null,
    );
    let (_, rows0) = predict(&[&s0, "--scenario", &fe, "--dofs", "0.x,0.y"]).unwrap();
    assert!(rows0.iter().all(|r| r[3] == Some(0.0) && r[4] == Some(0.0)));
    // no covariance: empty std cells, said on stderr
    let sn = summary(
        dir.path(),
        "sn.json",
        serde_json::Value::Null,
        serde_json::Value::Null,
    );
    let out = rotorid()
        .args([
            "predict",
            &sn,
            "--scenario",
            &fe,
            "--dofs",
            "0.x",
            "--out",
            "-",
        ])
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.lines().nth(1).unwrap().ends_with(','), "{text}");
    assert!(String::from_utf8_lossy(&out.stderr).contains("no covariance"));
}

/// A deterministic standard normal sequence (xorshift and Box-Muller).
struct Normal(u64);

impl Normal {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        ((self.0 >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    fn next(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

#[test]
fn predict_std_matches_a_monte_carlo_during_the_transient_and_starts_from_the_estimated_state() {
    let dir = tempfile::tempdir().unwrap();
    let (fe, _) = setup(dir.path());
    let cov = covariance();
    // the estimated initial state, its dofs in another order than the matrices'
    let (q0, v0) = (
        DVector::from_vec(vec![2e-6, -1e-6]),
        DVector::from_vec(vec![3e-4, 1e-4]),
    );
    let state = json!({"dofs": ["0.y", "0.x"], "q": [q0[1], q0[0]], "v": [v0[1], v0[0]]});
    let s = summary(dir.path(), "s.json", cov_json(&cov), state);
    let (_, rows) = predict(&[&s, "--scenario", &fe, "--dofs", "0.x,0.y"]).unwrap();
    let rotor = identified_rotor();
    let speed = SpeedProfile::constant_rpm(1200.0, 0.0).unwrap();
    let sampling = Sampling::new(1e-3, 0.6).unwrap();
    let init = FeInitialState { q: q0, v: v0 };
    let run = |r: &FiniteElementRotor| {
        simulate_fe(
            &FeSystem::full(r),
            &speed,
            &sampling,
            Some(&init),
            None,
            FeMethod::Exact,
        )
        .unwrap()
    };
    let base = run(&rotor);
    for (r, k) in rows.iter().zip(0..) {
        for j in 0..2 {
            let want = base.q[j][k];
            assert!(
                (r[1 + j].unwrap() - want).abs() <= 1e-12 * 1e-4,
                "{r:?} {want}"
            );
        }
    }
    // Monte Carlo over the covariance (Cholesky factor), 400 draws
    let l = DMatrix::from_fn(6, 6, |i, j| cov[i][j])
        .cholesky()
        .unwrap()
        .l();
    let mut z = Normal(0x9e37_79b9_7f4a_7c15);
    let samples = [20usize, 50, 100, 200];
    let draws = 400;
    let mut sum2 = vec![[0.0f64; 2]; samples.len()];
    for _ in 0..draws {
        let e = &l * DVector::from_fn(6, |_, _| z.next());
        let mut r = rotor.clone();
        let b = &mut r.bearings[0];
        b.kxx += e[0];
        b.kyy += e[1];
        b.cxx += e[2];
        b.cyy += e[3];
        r.unbalances[0].mud += e[4];
        r.unbalances[0].alpha += e[5];
        let resp = run(&r);
        for (acc, &k) in sum2.iter_mut().zip(&samples) {
            for (j, a) in acc.iter_mut().enumerate() {
                *a += (resp.q[j][k] - base.q[j][k]).powi(2);
            }
        }
    }
    for (si, &k) in samples.iter().enumerate() {
        for j in 0..2 {
            let mc = (sum2[si][j] / draws as f64).sqrt();
            let got = rows[k][3 + j].unwrap();
            println!(
                "t = {:.3} s, dof {j}: predict std {got:.4e}, Monte Carlo {mc:.4e}",
                rows[k][0].unwrap()
            );
            // 400 draws: the Monte Carlo std is within ~3.5 % (1 sigma); 15 % is > 4 sigma
            assert!(
                (got / mc - 1.0).abs() < 0.15,
                "sample {k}, dof {j}: {got:e} vs {mc:e}"
            );
        }
    }
}

#[test]
fn bad_input_is_refused_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let (fe, _) = setup(dir.path());
    let s = summary(
        dir.path(),
        "s.json",
        cov_json(&covariance()),
        serde_json::Value::Null,
    );
    let e = predict(&[&s, "--scenario", &fe, "--dofs", "0.x,3.x"]).unwrap_err();
    assert!(
        e.contains("--dofs: \"3.x\"") && e.contains("allowed 0.x, 0.y"),
        "{e}"
    );
    let e = predict(&[&s, "--scenario", &fe, "--dofs", "0.z"]).unwrap_err();
    assert!(
        e.contains("\"0.z\"") && e.contains("allowed 0.x, 0.y"),
        "{e}"
    );
    let e = predict(&[&s, "--dofs", "0.x"]).unwrap_err();
    assert!(e.contains("--scenario is needed"), "{e}");
    // a 2-DOF summary
    let two = dir.path().join("two.json");
    std::fs::write(&two, r#"{"model": "cross_coupled", "rotor": {}}"#).unwrap();
    let e = predict(&[two.to_str().unwrap(), "--scenario", &fe, "--dofs", "0.x"]).unwrap_err();
    assert!(e.contains("\"finite_element\""), "{e}");
    // a parameter the scenario's rotor does not have
    let text = std::fs::read_to_string(&s)
        .unwrap()
        .replace("bearing0.kyy", "bearing1.kyy");
    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, text).unwrap();
    let e = predict(&[bad.to_str().unwrap(), "--scenario", &fe, "--dofs", "0.x"]).unwrap_err();
    assert!(
        e.contains("parameters[1].parameter") && e.contains("bearing1.kyy"),
        "{e}"
    );
}
