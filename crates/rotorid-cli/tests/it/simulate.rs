//! End-to-end tests of `rotorid simulate`: the CSV format (header, row count, t = i dt
//! exactly, values that parse back to the library's own bits), the methods, the noise
//! (reproducible from its seed) and the output file handling.

use crate::common::rotorid;
use rotorid::simulate::{simulate, Method};
use rotorid::Scenario;

/// Run `rotorid simulate ARGS --out -` and return stdout.
fn simulate_stdout(args: &[&str]) -> String {
    let out = rotorid()
        .arg("simulate")
        .args(args)
        .args(["--out", "-"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "simulate {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

/// Parse the CSV body into rows of f64.
fn rows(csv: &str) -> Vec<Vec<f64>> {
    csv.lines()
        .skip(1)
        .map(|l| l.split(',').map(|f| f.parse::<f64>().unwrap()).collect())
        .collect()
}

#[test]
fn table1_csv_is_the_library_response_bit_for_bit() {
    let text = simulate_stdout(&["--scenario", "table1"]);
    assert_eq!(text.lines().next(), Some("t,x,z,phi,phi_dot,phi_ddot"));
    let rows = rows(&text);
    let reference = simulate(&Scenario::table1(), Method::Exact).unwrap();
    assert_eq!(rows.len(), 10_001);
    assert_eq!(reference.len(), 10_001);
    for (i, r) in rows.iter().enumerate() {
        assert_eq!(r.len(), 6, "row {i}");
        // t = i * dt exactly as `i as f64 * dt` computes it.
        assert_eq!(r[0].to_bits(), (i as f64 * 1e-4).to_bits(), "t at row {i}");
        let want = [
            reference.t[i],
            reference.x[i],
            reference.z[i],
            reference.phi[i],
            reference.phi_dot[i],
            reference.phi_ddot[i],
        ];
        for (c, (got, want)) in r.iter().zip(want).enumerate() {
            assert_eq!(got.to_bits(), want.to_bits(), "row {i} column {c}");
        }
    }
}

#[test]
fn newmark_differs_slightly_from_exact() {
    let args = ["--scenario", "table1", "--duration", "0.3"];
    let exact = rows(&simulate_stdout(&args));
    let newmark = rows(&simulate_stdout(
        &[&args[..], &["--method", "newmark"]].concat(),
    ));
    assert_eq!(exact.len(), newmark.len());
    let amp = exact.iter().fold(0.0f64, |m, r| m.max(r[1].abs()));
    let diff = exact
        .iter()
        .zip(&newmark)
        .fold(0.0f64, |m, (e, n)| m.max((e[1] - n[1]).abs()));
    // Newmark's period error (w dt)^2 / 12 ~ 7e-5 at 289 rad/s accumulates over 0.3 s to a
    // phase drift of ~6e-3 rad: a difference of order 1e-3 of the amplitude, not 0, not 1.
    let rel = diff / amp;
    assert!((1e-5..3e-2).contains(&rel), "relative difference {rel:e}");
    // Same time grid and same speed columns.
    for (e, n) in exact.iter().zip(&newmark) {
        assert_eq!((e[0], e[3], e[4], e[5]), (n[0], n[3], n[4], n[5]));
    }
}

#[test]
fn noise_is_reproducible_from_its_seed() {
    let base = [
        "--scenario",
        "table1",
        "--duration",
        "0.2",
        "--snr-db",
        "40",
    ];
    let a = simulate_stdout(&[&base[..], &["--seed", "7"]].concat());
    let b = simulate_stdout(&[&base[..], &["--seed", "7"]].concat());
    let c = simulate_stdout(&[&base[..], &["--seed", "8"]].concat());
    let default_seed = simulate_stdout(&base);
    let seed0 = simulate_stdout(&[&base[..], &["--seed", "0"]].concat());
    assert_eq!(a, b, "same seed must give identical bytes");
    assert_ne!(a, c, "different seeds must differ");
    assert_eq!(default_seed, seed0, "the default seed is 0");

    // The noise has the requested level: sigma = RMS(x) 10^(-40/20) = RMS(x) / 100.
    let clean = rows(&simulate_stdout(&base[..4]));
    let noisy = rows(&a);
    let n = clean.len() as f64;
    let rms = (clean.iter().map(|r| r[1] * r[1]).sum::<f64>() / n).sqrt();
    let sd = (clean
        .iter()
        .zip(&noisy)
        .map(|(c, d)| (d[1] - c[1]).powi(2))
        .sum::<f64>()
        / n)
        .sqrt();
    let ratio = sd / (rms / 100.0);
    // 2001 samples: the sample standard deviation is within ~3 sigma = 5 % of the truth.
    assert!(
        (0.95..1.05).contains(&ratio),
        "noise sd / expected = {ratio}"
    );
    // Noise touches x and z only.
    for (c, d) in clean.iter().zip(&noisy) {
        assert_eq!((c[0], c[3], c[4], c[5]), (d[0], d[3], d[4], d[5]));
    }
}

#[test]
fn seed_without_snr_is_refused() {
    rotorid()
        .args([
            "simulate",
            "--scenario",
            "table1",
            "--seed",
            "3",
            "--out",
            "-",
        ])
        .assert()
        .failure()
        .stderr(predicates::str::contains("--snr-db"));
}

#[test]
fn overrides_change_grid_and_initial_state() {
    let text = simulate_stdout(&[
        "--scenario",
        "table1",
        "--duration",
        "0.01",
        "--dt",
        "1e-3",
        "--initial-x",
        "2e-7",
        "--initial-vz",
        "-1e-4",
    ]);
    let r = rows(&text);
    assert_eq!(r.len(), 11);
    assert_eq!(r[0][1], 2e-7);
    assert_eq!(r[10][0], 10.0 * 1e-3);
    assert!(r[1][2] < 0.0, "z moves down first with vz(0) < 0");
}

#[test]
fn file_output_appears_complete_or_not_at_all() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("r.csv");
    let p = path.to_str().unwrap();
    rotorid()
        .args([
            "simulate",
            "--scenario",
            "table1",
            "--duration",
            "0.05",
            "--out",
            p,
        ])
        .assert()
        .success();
    let text = std::fs::read_to_string(&path).unwrap();
    assert_eq!(text.lines().count(), 1 + 501);
    // A failing run (dt larger than the duration) leaves the previous file untouched and
    // no temporary file behind.
    let out = rotorid()
        .args(["simulate", "--scenario", "table1", "--dt", "2", "--out", p])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("shorter than one sampling period"), "{err}");
    assert!(!err.contains("panicked"), "{err}");
    assert_eq!(std::fs::read_to_string(&path).unwrap(), text);
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names.len(), 1, "left behind: {names:?}");
}

#[test]
fn help_documents_units_and_default_method() {
    let out = rotorid().args(["simulate", "--help"]).output().unwrap();
    let help = String::from_utf8(out.stdout).unwrap();
    for needle in [
        "t [s]",
        "phi_dot [rad/s]",
        "phi_ddot [rad/s^2]",
        "[default: exact]",
        "newmark",
    ] {
        assert!(help.contains(needle), "--help lacks {needle:?}:\n{help}");
    }
}
