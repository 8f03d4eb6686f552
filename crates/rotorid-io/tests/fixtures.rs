//! Each reader against the values the reference tools wrote (fixtures/make.py: numpy,
//! scipy.io.savemat, h5py, npTDMS, pyuff, pyarrow), recorded in fixtures/expected.json.
//! The identifiable record ident.csv, written by every tool as ident.*, is checked here
//! channel by channel against the CSV's decimals; rotorid-cli's tests/it/formats.rs
//! identifies each of those files.

use std::path::{Path, PathBuf};

use rotorid_io::{read_table, ReadError, Table};
use serde_json::Value;

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures")
}

fn num(v: &Value) -> f64 {
    match v {
        Value::Number(n) => n.as_f64().expect("a float"),
        Value::String(s) if s == "nan" => f64::NAN,
        Value::String(s) if s == "inf" => f64::INFINITY,
        Value::String(s) if s == "-inf" => f64::NEG_INFINITY,
        other => panic!("not a sample: {other}"),
    }
}

fn variant(e: &ReadError) -> &'static str {
    match e {
        ReadError::InexactInteger { .. } => "InexactInteger",
        ReadError::Invalid { .. } => "Invalid",
        ReadError::Truncated { .. } => "Truncated",
        ReadError::NotUtf8 { .. } => "NotUtf8",
        ReadError::NoChannels { .. } => "NoChannels",
        ReadError::Container { .. } => "Container",
        _ => "other",
    }
}

/// The column a reference `"ident.csv:x"` names, parsed here with `str::parse` (correctly
/// rounded, as numpy's loadtxt that make.py checked it with), not by the CSV reader.
fn column(reference: &str) -> Vec<f64> {
    let (file, name) = reference.split_once(':').expect("FILE:COLUMN");
    let text = std::fs::read_to_string(dir().join(file)).unwrap();
    let mut lines = text.lines();
    let k = lines
        .next()
        .unwrap()
        .split(',')
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("{reference}: no such column"));
    lines
        .map(|l| l.split(',').nth(k).unwrap().parse().unwrap())
        .collect()
}

/// Checks every fixture whose name ends with one of `exts`; returns how many.
fn check(exts: &[&str]) -> usize {
    let text = std::fs::read_to_string(dir().join("expected.json")).unwrap();
    let expected: serde_json::Map<String, Value> = serde_json::from_str(&text).unwrap();
    let mut n = 0;
    for (file, want) in &expected {
        if !exts.iter().any(|e| file.ends_with(e)) {
            continue;
        }
        n += 1;
        let got = read_table(dir().join(file));
        if let Some(err) = want.get("error") {
            let e = match got {
                Err(e) => e,
                Ok(t) => panic!("{file}: expected {err}, read {} channels", t.channels.len()),
            };
            assert_eq!(variant(&e), err.as_str().unwrap(), "{file}: {e}");
            assert!(
                e.to_string().contains(file.as_str()),
                "{file}: message {e} names the file"
            );
            continue;
        }
        let table: Table = got.unwrap_or_else(|e| panic!("{file}: {e}"));
        let want = want["channels"].as_array().unwrap();
        let mut names: Vec<_> = table.channels.iter().map(|c| c.name.as_str()).collect();
        let mut want_names: Vec<_> = want.iter().map(|c| c["name"].as_str().unwrap()).collect();
        names.sort();
        want_names.sort();
        assert_eq!(names, want_names, "{file}: channel names");
        for w in want {
            let name = w["name"].as_str().unwrap();
            let c = table.channels.iter().find(|c| c.name == name).unwrap();
            assert_eq!(c.unit.as_deref(), w["unit"].as_str(), "{file}/{name}: unit");
            match w["axis"].as_array() {
                None => assert_eq!(c.axis, None, "{file}/{name}: axis"),
                Some(a) => {
                    let axis = c.axis.unwrap_or_else(|| panic!("{file}/{name}: no axis"));
                    assert_eq!(
                        axis.start.to_bits(),
                        num(&a[0]).to_bits(),
                        "{file}/{name}: start"
                    );
                    assert_eq!(
                        axis.increment.to_bits(),
                        num(&a[1]).to_bits(),
                        "{file}/{name}: increment"
                    );
                }
            }
            let data: Vec<f64> = match &w["data"] {
                Value::String(r) => column(r),
                d => d.as_array().unwrap().iter().map(num).collect(),
            };
            assert_eq!(c.data.len(), data.len(), "{file}/{name}: length");
            for (i, (a, b)) in c.data.iter().zip(&data).enumerate() {
                assert!(
                    a.to_bits() == b.to_bits() || (a.is_nan() && b.is_nan()),
                    "{file}/{name}[{i}]: read {a:e}, expected {b:e}"
                );
            }
        }
    }
    n
}

#[test]
fn npy_matches_numpy() {
    assert_eq!(check(&[".npy"]), 6);
}

#[test]
fn npz_matches_numpy() {
    assert_eq!(check(&[".npz"]), 3);
}

#[test]
fn mat_v5_matches_scipy() {
    assert_eq!(check(&["_v5.mat", "_v5_compressed.mat"]), 6);
}

#[test]
fn mat_v73_matches_h5py() {
    assert_eq!(check(&["_v73.mat"]), 2);
}

#[test]
fn tdms_matches_nptdms() {
    assert_eq!(check(&[".tdms"]), 4);
}

#[test]
fn uff58_matches_pyuff() {
    assert_eq!(check(&[".uff"]), 4);
}

#[test]
fn parquet_matches_pyarrow() {
    assert_eq!(check(&[".parquet"]), 3);
}

#[test]
fn csv_matches_the_decimals() {
    assert_eq!(check(&[".csv"]), 1);
}

#[test]
fn short_names_resolve_in_tdms_groups() {
    let t = read_table(dir().join("rec.tdms")).unwrap();
    assert_eq!(t.channel("speed").unwrap().name, "drive/speed");
    assert!(t.channel("x").is_none(), "x is in bearing1 and bearing2");
    assert_eq!(t.channel("bearing2/x").unwrap().name, "bearing2/x");
}

#[test]
fn extensions_pick_readers() {
    use rotorid_io::Format;
    for (p, f) in [
        ("a.MAT", Format::Mat),
        ("a.tdms", Format::Tdms),
        ("a.unv", Format::Uff58),
        ("a.58", Format::Uff58),
        ("a.uff", Format::Uff58),
        ("a.npy", Format::Npy),
        ("a.npz", Format::Npz),
        ("a.parquet", Format::Parquet),
        ("a.csv", Format::Csv),
    ] {
        assert_eq!(Format::from_path(Path::new(p)).unwrap(), f, "{p}");
    }
    let e = Format::from_path(Path::new("rec.xlsx")).unwrap_err();
    assert!(
        e.to_string().contains("rec.xlsx") && e.to_string().contains(".tdms"),
        "{e}"
    );
    // a CSV goes to the CSV table reader; a missing one is an I/O error naming it
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("rec.csv");
    std::fs::write(&p, "t [ms],x [um]\n0,1.5\n0.1,2\n").unwrap();
    let t = read_table(&p).unwrap();
    assert_eq!(t.channels[1].name, "x");
    assert_eq!(t.channels[1].unit.as_deref(), Some("um"));
    assert_eq!(t.channels[1].data, [1.5, 2.0]);
    let e = read_table(dir.path().join("none.csv")).unwrap_err();
    assert!(
        matches!(e, ReadError::Io { .. }) && e.to_string().contains("none.csv"),
        "{e}"
    );
}
