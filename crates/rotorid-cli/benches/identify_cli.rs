//! End-to-end time of `rotorid identify` on a 1,000,000-row response CSV, for each method.
//! The CSV is written once by `rotorid simulate` (table1, 1200 rpm, 100 s at 0.1 ms) into a
//! temporary directory; each iteration runs the release binary as a user would, output to
//! /dev/null.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion, Throughput};

const ROWS: u64 = 1_000_000;

fn rotorid() -> &'static str {
    env!("CARGO_BIN_EXE_rotorid")
}

fn write_input(dir: &Path) -> PathBuf {
    let csv = dir.join("response.csv");
    // duration = (ROWS - 1) * dt, so the file has exactly ROWS data rows.
    let status = Command::new(rotorid())
        .args([
            "simulate",
            "--scenario",
            "table1",
            "--duration",
            "99.9999",
            "--out",
        ])
        .arg(&csv)
        .status()
        .expect("run rotorid simulate");
    assert!(status.success(), "rotorid simulate failed");
    csv
}

fn identify(c: &mut Criterion) {
    let dir = tempfile::tempdir().expect("temporary directory");
    let csv = write_input(dir.path());
    let mut group = c.benchmark_group("cli_identify_1M_rows");
    group.throughput(Throughput::Elements(ROWS));
    group.sample_size(10);
    group.measurement_time(Duration::from_secs(20));
    for method in ["algebraic", "modulating"] {
        group.bench_function(method, |b| {
            b.iter(|| {
                let status = Command::new(rotorid())
                    .args(["identify", "--scenario", "table1", "--method", method])
                    .args(["--out", "/dev/null", "--quiet"])
                    .arg(&csv)
                    .status()
                    .expect("run rotorid identify");
                assert!(status.success());
            })
        });
    }
    group.finish();
}

criterion_group!(benches, identify);
criterion_main!(benches);
