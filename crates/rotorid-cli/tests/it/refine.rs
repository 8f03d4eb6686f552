//! End-to-end tests of `rotorid identify --method refine`: on noisy simulated data the
//! maximum-likelihood fit recovers the paper's rotor within a few of its own standard
//! errors, which match the Cramer-Rao bound; a record without excitation is reported as not
//! identifiable (warning, huge or infinite standard errors, nothing in the estimates CSV),
//! never as a confident number; `--unknowns` selects what is estimated and refuses unknown
//! names with the list of allowed ones; the start falls back to the algebraic estimate on
//! a record shorter than one modulating window.

use std::sync::OnceLock;

use crate::common::{data, identify_with_summary, param, rotorid, simulate, state, Run};
use serde_json::Value;

/// table1, 0.3 s (3001 samples), clean.
fn table1_clean() -> &'static str {
    static CSV: OnceLock<String> = OnceLock::new();
    CSV.get_or_init(|| simulate(&["--scenario", "table1", "--duration", "0.3"]))
}

/// table1, 0.3 s, SNR 40 dB per channel (seed 11).
fn table1_noisy() -> &'static str {
    static CSV: OnceLock<String> = OnceLock::new();
    CSV.get_or_init(|| {
        simulate(&[
            "--scenario",
            "table1",
            "--duration",
            "0.3",
            "--snr-db",
            "40",
            "--seed",
            "11",
        ])
    })
}

/// `identify - --scenario SCENARIO --method refine --out - --summary S ARGS` on `input`.
fn refine(input: &str, scenario: &str, args: &[&str]) -> Run {
    let options = ["--scenario", scenario, "--method", "refine", "--out", "-"];
    identify_with_summary(input, &options, args)
}

/// Column `col` of a response CSV (after the header).
fn column(csv: &str, col: usize) -> Vec<f64> {
    csv.lines()
        .skip(1)
        .map(|l| l.split(',').nth(col).unwrap().parse().unwrap())
        .collect()
}

fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|a| a * a).sum::<f64>() / v.len() as f64).sqrt()
}

/// The fields of the single estimates row (after the header), `None` for empty fields.
fn estimates_row(csv: &str) -> Vec<Option<f64>> {
    let lines: Vec<&str> = csv.lines().collect();
    assert_eq!(lines.len(), 2, "a header and one row: {csv}");
    assert_eq!(lines[0], "t,m_x,c_x,k_x,m_z,c_z,k_z,rcond_x,rcond_z,window");
    lines[1]
        .split(',')
        .map(|f| (!f.is_empty()).then(|| f.parse().unwrap()))
        .collect()
}

/// A CSV value equals a JSON one (serde_json's reader may be 1 ulp off the written value).
fn same(csv: Option<f64>, json: &Value) {
    let (a, b) = (csv.unwrap(), json.as_f64().unwrap());
    assert!((a - b).abs() <= 2.0 * f64::EPSILON * a.abs(), "{a} vs {b}");
}

const TABLE1: [(&str, f64); 5] = [
    ("m", 14.29),
    ("cx", 10.0),
    ("kx", 1.195e6),
    ("cz", 10.0),
    ("kz", 1.195e6),
];

#[test]
fn recovers_table1_within_a_few_std_errors_at_the_cramer_rao_bound() {
    let r = refine(table1_noisy(), "table1", &[]);
    assert!(r.ok, "{}", r.stderr);
    let s = r.summary.unwrap();
    assert_eq!(s["method"], "refine");
    assert_eq!(s["record"]["samples"], 3001);
    assert_eq!(s["refine"]["start"]["source"], "modulating");
    assert_eq!(s["refine"]["crb_at"], "truth");
    assert_eq!(s["refine"]["identifiable"], true);
    assert_eq!(s["refine"]["converged"], true);
    assert_eq!(s["diagnostics"], Value::Array(vec![]));
    assert!(s["algebraic"].is_null());
    for (name, truth) in TABLE1 {
        let v = param(&s, name)["estimate"].as_f64().unwrap();
        let se = param(&s, name)["std_error"].as_f64().unwrap();
        let crb = param(&s, name)["crb"].as_f64().unwrap();
        let z = (v - truth) / se;
        assert!(
            z.abs() < 4.0,
            "{name} = {v}: {z:.2} standard errors from {truth}"
        );
        // The asymptotic ML standard error is the bound (evaluated at the estimate rather
        // than the truth: equal to first order).
        assert!(
            (se / crb - 1.0).abs() < 0.05,
            "{name}: std error {se:e}, CRB {crb:e}"
        );
        let rel = param(&s, name)["relative_std_error"].as_f64().unwrap();
        assert!((rel - se / v.abs()).abs() <= 1e-12 * rel);
    }
    // docs/method.md section 5.4 (state known, 0.3 s): m 9.9e-5, k 1.0e-4; estimating the initial
    // state too costs a little more.
    let rel_m = param(&s, "m")["relative_std_error"].as_f64().unwrap();
    assert!(
        (9.9e-5..3e-4).contains(&rel_m),
        "relative std error of m {rel_m:e}"
    );
    // The noise: sigma = RMS(clean channel) * 10^(-40/20).
    assert_eq!(s["noise"]["source"], "residuals");
    for (ch, col) in [("sigma_x_m", 1), ("sigma_z_m", 2)] {
        let want = rms(&column(table1_clean(), col)) * 1e-2;
        let got = s["noise"][ch].as_f64().unwrap();
        assert!((got / want - 1.0).abs() < 0.05, "{ch} {got:e} vs {want:e}");
    }
    for ic in ["x0", "z0", "vx0", "vz0"] {
        let v = state(&s, ic)["value"].as_f64().unwrap();
        let se = state(&s, ic)["std_error"].as_f64().unwrap();
        assert!(v.abs() < 4.0 * se, "{ic} = {v:e} +- {se:e}, truth 0");
    }
    // One row at the last sample, m in both directions, equal to the summary's final.
    let row = estimates_row(&r.csv);
    assert_eq!(row[0], Some(0.3));
    assert_eq!(row[1], row[4]);
    same(row[1], &param(&s, "m")["value"]);
    same(row[1], &param(&s, "m")["estimate"]);
    same(row[6], &param(&s, "kz")["estimate"]);
    // The table on stderr: value +- std error, relative std error, CRB; no warning.
    assert!(r.stderr.contains("+- std err") && r.stderr.contains("CRB"));
    assert!(!r.stderr.contains("warning:"), "{}", r.stderr);
}

/// Gaussian pseudo-random numbers (xorshift64* and Box-Muller), reproducible.
struct Gauss(u64);

impl Gauss {
    fn uniform(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let r = self.0.wrapping_mul(0x2545_F491_4F6C_DD1D);
        ((r >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    fn next(&mut self) -> f64 {
        let (u, v) = (self.uniform(), self.uniform());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }
}

/// A rotor at rest and without unbalance: x = z = 0 plus white noise of 1 nm.
const STILL: &str = r#"
[rotor]
m = 14.29
cx = 10.0
cz = 10.0
kx = 1.195e6
kz = 1.195e6
a = 2.871
m_u = 0.0
d = 0.15
alpha_deg = 45.0
[speed]
kind = "constant"
rpm = 1200.0
"#;

#[test]
fn a_record_without_excitation_is_not_identifiable_and_gives_no_confident_number() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = dir.path().join("still.toml");
    std::fs::write(&scenario, STILL).unwrap();
    let mut g = Gauss(0x9E37_79B9_7F4A_7C15);
    let mut csv = String::from("t,x,z\n");
    for i in 0..3001 {
        let (x, z) = (1e-9 * g.next(), 1e-9 * g.next());
        csv.push_str(&format!("{:?},{x:?},{z:?}\n", i as f64 * 1e-4));
    }
    let r = refine(&csv, scenario.to_str().unwrap(), &[]);
    assert!(r.ok, "reported, not refused: {}", r.stderr);
    assert!(
        r.stderr.contains("warning: NOT IDENTIFIABLE"),
        "{}",
        r.stderr
    );
    let s = r.summary.unwrap();
    assert_eq!(s["refine"]["identifiable"], false);
    assert!(!s["diagnostics"].as_array().unwrap().is_empty());
    for (name, _) in TABLE1 {
        // Infinite (null) or larger than the value itself: never a confident number.
        let rel = param(&s, name)["relative_std_error"].as_f64();
        assert!(
            rel.is_none_or(|r| r > 1.0),
            "{name}: relative std error {rel:?}"
        );
    }
    for p in ["m", "cx", "kx", "cz", "kz"] {
        let r = param(&s, p);
        assert!(
            r["value"].is_null() && r["determined"] == false,
            "{p} = {r}"
        );
    }
    assert!(s["rotor"].is_null());
    let row = estimates_row(&r.csv);
    assert!(row[1..7].iter().all(Option::is_none), "{}", r.csv);
}

#[test]
fn unknown_names_are_refused_with_the_allowed_ones() {
    let r = refine(table1_noisy(), "table1", &["--unknowns", "m,k"]);
    assert!(!r.ok);
    assert!(r.stderr.contains("'k'"), "{}", r.stderr);
    assert!(
        r.stderr
            .contains("[possible values: m, cx, kx, cz, kz, a, unbalance, cxx, cxz, czx, czz, kxx, kxz, kzx, kzz]"),
        "{}",
        r.stderr
    );
    assert!(r.csv.is_empty() && r.summary.is_none());
}

#[test]
fn flags_of_other_methods_are_refused() {
    let r = refine(table1_noisy(), "table1", &["--every", "10"]);
    assert!(!r.ok);
    assert!(
        r.stderr
            .contains("--every applies to --method algebraic only, not to --method refine"),
        "{}",
        r.stderr
    );
    let out = rotorid()
        .args(["identify", "-", "--scenario", "table1", "--out", "-"])
        .args(["--unknowns", "m"])
        .write_stdin(table1_noisy().to_owned())
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr)
        .contains("--unknowns applies to --method refine only, not to --method algebraic"));
}

#[test]
fn known_parameters_must_be_in_the_scenario() {
    let r = refine(
        table1_noisy(),
        &data("known_only.toml"),
        &["--unknowns", "m,kx,kz"],
    );
    assert!(!r.ok);
    assert!(
        r.stderr.contains(
            "--unknowns leaves cx, cz known, but the scenario {} does not state rotor.cx, rotor.cz"
                .replace("{}", &data("known_only.toml"))
                .as_str()
        ),
        "{}",
        r.stderr
    );
}

#[test]
fn without_truth_the_bound_is_at_the_estimate() {
    let r = refine(table1_noisy(), &data("known_only.toml"), &[]);
    assert!(r.ok, "{}", r.stderr);
    let s = r.summary.unwrap();
    assert_eq!(s["refine"]["crb_at"], "estimate");
    for (name, _) in TABLE1 {
        let r = param(&s, name);
        assert!(r["truth"].is_null() && r["relative_error"].is_null(), "{r}");
    }
    for (name, truth) in TABLE1 {
        let v = param(&s, name)["estimate"].as_f64().unwrap();
        let se = param(&s, name)["std_error"].as_f64().unwrap();
        assert!(((v - truth) / se).abs() < 4.0, "{name} = {v} +- {se}");
        // At the estimate the bound is the standard error itself.
        let crb = param(&s, name)["crb"].as_f64().unwrap();
        assert!((crb / se - 1.0).abs() < 1e-6, "{name}: {crb:e} vs {se:e}");
    }
}

#[test]
fn the_unbalance_can_be_estimated_with_cx_cz_known() {
    let r = refine(
        table1_noisy(),
        "table1",
        &["--unknowns", "m,kx,kz,unbalance"],
    );
    assert!(r.ok, "{}", r.stderr);
    let s = r.summary.unwrap();
    let mut names: Vec<&str> = s["parameters"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["parameter"].as_str().unwrap())
        .collect();
    names.sort_unstable();
    assert_eq!(names, ["alpha", "kx", "kz", "m", "mud"]);
    assert_eq!(
        s["refine"]["unknowns"],
        serde_json::json!(["m", "kx", "kz", "mud", "alpha"])
    );
    for (name, truth) in [
        ("m", 14.29),
        ("kx", 1.195e6),
        ("kz", 1.195e6),
        ("mud", 1e-4 * 0.15),
        ("alpha", std::f64::consts::FRAC_PI_4),
    ] {
        let v = param(&s, name)["estimate"].as_f64().unwrap();
        let se = param(&s, name)["std_error"].as_f64().unwrap();
        assert!(((v - truth) / se).abs() < 4.0, "{name} = {v} +- {se}");
    }
    // cx, cz were known: not identified, so not in `final` nor in the CSV.
    assert!(param(&s, "cx")["value"].is_null() && param(&s, "cz")["value"].is_null());
    let row = estimates_row(&r.csv);
    assert!(row[1].is_some() && row[2].is_none() && row[5].is_none());
}

/// The first `rows` data rows of `csv`, with its header.
fn head(csv: &str, rows: usize) -> String {
    csv.lines()
        .take(rows + 1)
        .map(|l| format!("{l}\n"))
        .collect()
}

#[test]
fn a_record_shorter_than_a_window_starts_from_the_algebraic_estimate_at_50_ms() {
    // 0.08 s against a 0.1 s window: no modulating estimate.
    let r = refine(&head(table1_noisy(), 801), "table1", &["--window", "0.1"]);
    assert!(r.ok, "{}", r.stderr);
    let s = r.summary.unwrap();
    assert_eq!(s["refine"]["start"]["source"], "algebraic");
    assert_eq!(s["refine"]["start"]["t_s"], 0.05);
    assert!(s["modulating"].is_null());
    let note = s["refine"]["start"]["note"].as_str().unwrap();
    assert!(
        note.contains("the record has 801 samples but one window needs 1001"),
        "{note}"
    );
    assert!(r
        .stderr
        .contains("start: algebraic estimate at t = 0.05000 s"));
    assert_eq!(s["refine"]["identifiable"], true);
    for (name, truth) in TABLE1 {
        let v = param(&s, name)["estimate"].as_f64().unwrap();
        let se = param(&s, name)["std_error"].as_f64().unwrap();
        assert!(((v - truth) / se).abs() < 4.0, "{name} = {v} +- {se}");
    }
}

#[test]
fn a_very_short_record_withholds_the_damping_it_cannot_determine() {
    // 15 ms: 0.7 periods of the natural frequency. m and k are found to ~1 %; the very light
    // damping (ratio 0.0012) is not: its standard error exceeds its value.
    let r = refine(&head(table1_noisy(), 151), "table1", &[]);
    assert!(r.ok, "{}", r.stderr);
    let s = r.summary.unwrap();
    assert!(s["refine"]["start"]["note"]
        .as_str()
        .unwrap()
        .contains("one window needs"));
    let m = param(&s, "m")["estimate"].as_f64().unwrap();
    let se = param(&s, "m")["std_error"].as_f64().unwrap();
    assert!(
        ((m - 14.29) / se).abs() < 4.0 && se / m < 0.05,
        "m = {m} +- {se}"
    );
    assert_eq!(s["refine"]["identifiable"], false);
    assert!(
        r.stderr.contains("warning: NOT IDENTIFIABLE"),
        "{}",
        r.stderr
    );
    assert!(
        r.stderr.contains("warning: cx is undetermined"),
        "{}",
        r.stderr
    );
    let row = estimates_row(&r.csv);
    assert!(row[1].is_some() && row[3].is_some(), "m_x, k_x determined");
    assert!(row[2].is_none() && row[5].is_none(), "c_x, c_z withheld");
    assert!(param(&s, "cx")["value"].is_null() && param(&s, "kx")["value"].is_number());
    assert_eq!(param(&s, "cx")["determined"], false);
}

#[test]
fn a_ramp_with_measured_speed_uses_the_scenario_initial_state_for_the_bound() {
    let csv = simulate(&[
        "--scenario",
        &data("table1_ramp.toml"),
        "--snr-db",
        "40",
        "--seed",
        "5",
    ]);
    let r = refine(&csv, &data("table1_ramp.toml"), &[]);
    assert!(r.ok, "{}", r.stderr);
    let s = r.summary.unwrap();
    assert!(s["refine"]["discretisation"]
        .as_str()
        .unwrap()
        .starts_with("RK4"));
    assert_eq!(s["refine"]["crb_at"], "truth");
    for (name, truth) in TABLE1 {
        let v = param(&s, name)["estimate"].as_f64().unwrap();
        let se = param(&s, name)["std_error"].as_f64().unwrap();
        let crb = param(&s, name)["crb"].as_f64().unwrap();
        assert!(((v - truth) / se).abs() < 4.0, "{name} = {v} +- {se}");
        // Bound at the scenario's (off-centre) initial state: a wrong initial state would
        // change the free transient and the bound by far more than 5 %.
        assert!(
            (se / crb - 1.0).abs() < 0.05,
            "{name}: {se:e} vs CRB {crb:e}"
        );
    }
    // The fitted initial state is the scenario's [initial].
    for (ic, truth) in [("x0", 2e-7), ("z0", -1e-7), ("vx0", 1e-4), ("vz0", 5e-5)] {
        let v = state(&s, ic)["value"].as_f64().unwrap();
        let se = state(&s, ic)["std_error"].as_f64().unwrap();
        assert!(((v - truth) / se).abs() < 4.0, "{ic} = {v:e} +- {se:e}");
    }
}

#[test]
fn a_record_starting_later_bounds_at_the_true_parameters_and_fitted_state() {
    let csv = table1_noisy();
    let mut lines = csv.lines();
    let mut late = format!("{}\n", lines.next().unwrap());
    for l in lines.skip(1000) {
        late.push_str(l);
        late.push('\n');
    }
    let r = refine(&late, "table1", &[]);
    assert!(r.ok, "{}", r.stderr);
    let s = r.summary.unwrap();
    assert_eq!(s["record"]["samples"], 2001);
    assert_eq!(s["record"]["t_first_s"], 0.1);
    assert_eq!(s["refine"]["crb_at"], "truth_parameters");
    for (name, truth) in TABLE1 {
        let v = param(&s, name)["estimate"].as_f64().unwrap();
        let se = param(&s, name)["std_error"].as_f64().unwrap();
        assert!(((v - truth) / se).abs() < 4.0, "{name} = {v} +- {se}");
    }
}

#[test]
fn every_row_is_still_validated_with_its_line_and_column() {
    let bad = "t,x,z\n0,0,0\n0.0001,abc,0\n";
    let r = refine(bad, "table1", &[]);
    assert!(!r.ok);
    assert!(
        r.stderr
            .contains("<stdin> line 3, column 2 (x): x \"abc\" is not a number"),
        "{}",
        r.stderr
    );
}
