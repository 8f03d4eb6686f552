//! End-to-end tests of `rotorid identify --method modulating`: on noisy data it recovers
//! the paper's rotor where the algebraic identifier's final estimate has drifted away
//! (docs/method.md section 3.8), with one estimates row and the noise level, window figures
//! and standard errors in the summary; a record without excitation withholds both
//! directions with a warning; flags of other methods and too-short records are refused.

use std::sync::OnceLock;

use crate::common::{identify_with_summary, param, simulate, Run};
use serde_json::Value;

/// table1, 0.3 s (3001 samples), SNR 40 dB per channel (seed 21).
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
            "21",
        ])
    })
}

/// `identify - --scenario table1 --out - --summary S ARGS` on `input`.
fn identify(input: &str, args: &[&str]) -> Run {
    identify_with_summary(input, &["--scenario", "table1", "--out", "-"], args)
}

const PARAMS: [&str; 6] = ["m_x", "cx", "kx", "m_z", "cz", "kz"];

#[test]
fn beats_the_algebraic_final_estimate_on_noisy_data() {
    let m = identify(table1_noisy(), &["--method", "modulating"]);
    assert!(m.ok, "{}", m.stderr);
    let a = identify(table1_noisy(), &[]);
    assert!(a.ok, "{}", a.stderr);
    let (sm, sa) = (m.summary.unwrap(), a.summary.unwrap());
    assert_eq!(sm["method"], "modulating");
    assert_eq!(sa["method"], "algebraic");
    for p in PARAMS {
        let em = param(&sm, p)["relative_error"].as_f64().unwrap();
        // the algebraic estimate itself (withheld where not physical)
        let truth = param(&sa, p)["truth"].as_f64().unwrap();
        let ea = param(&sa, p)["estimate"].as_f64().unwrap() / truth - 1.0;
        assert!(
            em.abs() < ea.abs(),
            "{p}: modulating {em:e}, algebraic {ea:e}"
        );
        // m, k to 0.1 %, c (damping ratio 0.0012) to 20 % on 0.3 s at 40 dB.
        let bound = if p.starts_with('c') { 0.2 } else { 1e-3 };
        assert!(em.abs() < bound, "{p}: modulating error {em:e}");
        // and within a few of its own standard errors
        let v = param(&sm, p)["value"].as_f64().unwrap();
        let se = param(&sm, p)["std_error"].as_f64().unwrap();
        let truth = param(&sm, p)["truth"].as_f64().unwrap();
        assert!(((v - truth) / se).abs() < 4.0, "{p} = {v} +- {se}");
    }
    // The algebraic estimate drifts under noise (docs/method.md section 3.8): its final mass is
    // off by far more than the modulating one's.
    let m_x = param(&sa, "m_x")["estimate"].as_f64().unwrap();
    assert!((m_x / 14.29 - 1.0).abs() > 1e-2);
    // ... and the summary says so
    assert!(
        a.stderr.contains("algebraic estimates of") && a.stderr.contains("never settled"),
        "{}",
        a.stderr
    );

    // One row, at the last sample, equal to the summary's final values.
    let lines: Vec<&str> = m.csv.lines().collect();
    assert_eq!(lines.len(), 2);
    // (the last field, the restart window, is empty for a batch method)
    let (fields, window) = lines[1].rsplit_once(',').unwrap();
    assert_eq!(window, "");
    let row: Vec<f64> = fields.split(',').map(|f| f.parse().unwrap()).collect();
    assert_eq!(row[0], 0.3);
    // (serde_json's reader may be 1 ulp off the written value)
    let same = |a: f64, b: &Value| {
        let b = b.as_f64().unwrap();
        assert!((a - b).abs() <= 2.0 * f64::EPSILON * a.abs(), "{a} vs {b}");
    };
    same(row[1], &param(&sm, "m_x")["value"]);
    same(row[6], &param(&sm, "kz")["value"]);
    same(row[7], &sm["modulating"]["rcond"]["x"]);
    assert!(PARAMS.iter().all(|p| param(&sm, p)["determined"] == true));

    // Batch fields: noise level near RMS * 1e-2 (~2e-9 m here), window figures; no
    // algebraic-only field.
    assert_eq!(sm["noise"]["source"], "fourth_differences");
    for ch in ["sigma_x_m", "sigma_z_m"] {
        let s = sm["noise"][ch].as_f64().unwrap();
        assert!((1.5e-9..2.5e-9).contains(&s), "{ch} = {s:e}");
    }
    assert!(sm["modulating"]["windows"].as_u64().unwrap() > 10);
    assert!(sm["algebraic"].is_null() && sm["refine"].is_null());
    assert!(PARAMS
        .iter()
        .all(|p| param(&sm, p)["identification_time_s"].is_null()));
    assert_eq!(sm["diagnostics"], Value::Array(vec![]));

    // The algebraic summary: no noise level, standard errors or batch figures.
    for key in ["noise", "covariance", "modulating", "refine"] {
        assert!(sa[key].is_null(), "algebraic {key} = {}", sa[key]);
    }
    assert!(PARAMS.iter().all(|p| param(&sa, p)["std_error"].is_null()));
    assert_eq!(sa["algebraic"]["quadrature"], "am5");
}

#[test]
fn the_speed_from_the_scenario_gives_the_same_estimate_as_the_phi_columns() {
    let no_phi: String = table1_noisy()
        .lines()
        .map(|l| l.split(',').take(3).collect::<Vec<_>>().join(",") + "\n")
        .collect();
    let a = identify(table1_noisy(), &["--method", "modulating", "-q"]);
    let b = identify(&no_phi, &["--method", "modulating", "-q"]);
    assert!(a.ok && b.ok, "{}{}", a.stderr, b.stderr);
    assert_eq!(a.csv, b.csv);
}

#[test]
fn a_record_without_excitation_withholds_both_directions() {
    // x = z = 0 plus a deterministic, noise-like sequence of ~1 nm.
    let mut csv = String::from("t,x,z\n");
    let mut s: u64 = 0x2545_F491_4F6C_DD1D;
    let mut next = || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 * 2e-9 - 1e-9
    };
    for i in 0..3001 {
        csv.push_str(&format!(
            "{:?},{:?},{:?}\n",
            i as f64 * 1e-4,
            next(),
            next()
        ));
    }
    let r = identify(&csv, &["--method", "modulating"]);
    assert!(r.ok, "{}", r.stderr);
    let s = r.summary.unwrap();
    assert!(PARAMS.iter().all(|p| param(&s, p)["value"].is_null()));
    assert!(PARAMS.iter().all(|p| param(&s, p)["determined"] == false));
    assert!(
        r.stderr.contains("warning: the x direction is"),
        "{}",
        r.stderr
    );
    assert!(
        r.stderr.contains("warning: the z direction is"),
        "{}",
        r.stderr
    );
    // and the record itself is said to be below any probe's resolution (peaks of 1 nm) or
    // mostly noise
    let kinds: Vec<&str> = s["diagnostics"]
        .as_array()
        .unwrap()
        .iter()
        .map(|d| d["kind"].as_str().unwrap())
        .collect();
    assert_eq!(kinds.len(), 4, "{kinds:?}");
    assert!(
        kinds[2..]
            .iter()
            .all(|k| ["implausible_displacement", "noise_dominates"].contains(k)),
        "{kinds:?}"
    );
    let row = r.csv.lines().nth(1).unwrap();
    assert!(row.starts_with("0.3,,,,,,,"), "{row}");
}

#[test]
fn a_record_shorter_than_one_window_is_refused() {
    let short: String = table1_noisy()
        .lines()
        .take(101)
        .map(|l| format!("{l}\n"))
        .collect();
    let r = identify(&short, &["--method", "modulating"]);
    assert!(!r.ok);
    assert!(
        r.stderr
            .contains("<stdin>: the record has 100 samples but one window needs"),
        "{}",
        r.stderr
    );
    assert!(r.stderr.contains("--window"), "{}", r.stderr);
    // A shorter window fits.
    let r = identify(&short, &["--method", "modulating", "--window", "0.005"]);
    assert!(r.ok, "{}", r.stderr);
    assert_eq!(r.summary.unwrap()["modulating"]["window_s"], 0.005);
}

#[test]
fn flags_of_other_methods_are_refused() {
    for (flag, value) in [("--tol", "0.1"), ("--every", "2"), ("--quadrature", "am3")] {
        let r = identify(table1_noisy(), &["--method", "modulating", flag, value]);
        assert!(!r.ok);
        assert!(
            r.stderr.contains(&format!("{flag} applies to --method")),
            "{}",
            r.stderr
        );
    }
    let r = identify(table1_noisy(), &["--window", "0.05"]);
    assert!(!r.ok);
    assert!(r
        .stderr
        .contains("--window applies to --method modulating and refine only"));
}
