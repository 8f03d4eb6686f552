//! `rotorid plot`: draws simulate and identify CSVs as PNG or SVG, adds the truth from a
//! scenario, honours a time window, and fails clearly on an unknown header, a bad
//! extension or an empty window.

use std::path::Path;

use crate::common::rotorid;
use predicates::str::contains;

fn png_size(path: &Path) -> (u32, u32) {
    let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
    let reader = decoder.read_info().unwrap();
    let info = reader.info();
    (info.width, info.height)
}

/// A 0.05 s simulate CSV and its identify CSV in `dir`.
fn csvs(dir: &Path) -> (std::path::PathBuf, std::path::PathBuf) {
    let sim = dir.join("sim.csv");
    let est = dir.join("est.csv");
    rotorid()
        .args([
            "simulate",
            "--scenario",
            "table1",
            "--duration",
            "0.05",
            "--out",
        ])
        .arg(&sim)
        .assert()
        .success();
    rotorid()
        .args(["identify", "--scenario", "table1", "--out"])
        .arg(&est)
        .arg(&sim)
        .assert()
        .success();
    (sim, est)
}

#[test]
fn plots_simulate_and_identify_output() {
    let dir = tempfile::tempdir().unwrap();
    let (sim, est) = csvs(dir.path());

    let png = dir.path().join("response.png");
    rotorid()
        .arg("plot")
        .arg(&sim)
        .arg("--out")
        .arg(&png)
        .assert()
        .success();
    let (w, h) = png_size(&png);
    assert!(w >= 1200 && h >= 800, "{w} x {h}");

    let svg = dir.path().join("response.svg");
    rotorid()
        .arg("plot")
        .arg(&sim)
        .args(["--from", "0.01", "--to", "0.04", "--out"])
        .arg(&svg)
        .assert()
        .success();
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.starts_with("<svg") && text.contains("orbit") && text.contains("(nm)"));

    let png = dir.path().join("estimates.png");
    rotorid()
        .arg("plot")
        .arg(&est)
        .args(["--scenario", "table1", "--out"])
        .arg(&png)
        .assert()
        .success();
    let (w, h) = png_size(&png);
    assert!(w >= 1200 && h >= 800, "{w} x {h}");

    let svg = dir.path().join("estimates.svg");
    rotorid()
        .arg("plot")
        .arg(&est)
        .args(["--scenario", "table1", "--from", "0.01", "--out"])
        .arg(&svg)
        .assert()
        .success();
    let text = std::fs::read_to_string(&svg).unwrap();
    for label in [
        "mass m (kg)",
        "damping c (N s/m)",
        "stiffness k (N/m)",
        "true m",
        "true kx = kz",
    ] {
        assert!(text.contains(label), "estimates.svg lacks {label:?}");
    }
}

#[test]
fn errors_name_the_problem() {
    let dir = tempfile::tempdir().unwrap();
    let odd = dir.path().join("odd.csv");
    std::fs::write(&odd, "time,speed\n0,1\n").unwrap();
    rotorid()
        .arg("plot")
        .arg(&odd)
        .arg("--out")
        .arg(dir.path().join("o.png"))
        .assert()
        .failure()
        .stderr(contains("odd.csv line 1: unknown header `time,speed`"));

    let sim = dir.path().join("s.csv");
    std::fs::write(&sim, "t,x,z\n0,0,0\n0.1,1e-7,2e-7\n0.2,abc,0\n").unwrap();
    rotorid()
        .arg("plot")
        .arg(&sim)
        .arg("--out")
        .arg(dir.path().join("o.png"))
        .assert()
        .failure()
        .stderr(contains("line 4, column 2 (x)"));

    std::fs::write(&sim, "t,x,z\n0,0,0\n0.1,1e-7,2e-7\n").unwrap();
    rotorid()
        .arg("plot")
        .arg(&sim)
        .arg("--out")
        .arg(dir.path().join("o.jpg"))
        .assert()
        .failure()
        .stderr(contains("o.jpg: unknown image extension `.jpg`"));
    rotorid()
        .arg("plot")
        .arg(&sim)
        .arg("--out")
        .arg(dir.path().join("missing-dir").join("o.png"))
        .assert()
        .failure()
        .stderr(contains("does not exist"));
    rotorid()
        .arg("plot")
        .arg(&sim)
        .args(["--from", "5", "--to", "6", "--out"])
        .arg(dir.path().join("o.png"))
        .assert()
        .failure()
        .stderr(contains("no sample in the window"));
    rotorid()
        .arg("plot")
        .arg(&sim)
        .args(["--from", "0.2", "--to", "0.1", "--out"])
        .arg(dir.path().join("o.png"))
        .assert()
        .failure()
        .stderr(contains("--from 0.2 must be earlier than --to 0.1"));
}
