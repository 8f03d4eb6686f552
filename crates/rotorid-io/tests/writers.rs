//! The writers, read back by this crate's readers, and (when `ROTORID_IO_PYTHON` names a
//! Python with numpy, scipy and pyarrow, e.g. the fixtures venv) by the reference tools:
//!
//! ```text
//! ROTORID_IO_PYTHON=/path/to/venv/bin/python cargo test -p rotorid-io --test writers
//! ```

use rotorid_io::write::{mat_v5_bytes, npz_bytes, parquet_bytes};
use rotorid_io::{read_table, write_table, Channel, Table, WriteError};

fn ch(name: &str, data: Vec<f64>) -> Channel {
    Channel {
        name: name.into(),
        unit: None,
        data,
        axis: None,
    }
}

fn table(n: usize) -> Table {
    let t: Vec<f64> = (0..n).map(|i| i as f64 / 2048.0).collect();
    let x: Vec<f64> = t
        .iter()
        .map(|t| 1e-5 * (2.0 * std::f64::consts::PI * 25.0 * t).sin())
        .collect();
    let mut z: Vec<f64> = t
        .iter()
        .map(|t| -1e-5 * (2.0 * std::f64::consts::PI * 25.0 * t).cos())
        .collect();
    z[3] = f64::NAN;
    z[4] = f64::INFINITY;
    let speed = vec![f64::MAX, f64::MIN_POSITIVE, -0.0, 5e-324]
        .into_iter()
        .cycle()
        .take(n)
        .collect();
    Table {
        file: "w".into(),
        channels: vec![
            ch("t", t),
            ch("x", x),
            ch("rec.z", z),
            ch("rec.speed", speed),
        ],
        notes: Vec::new(),
    }
}

fn same(a: &Table, b: &Table) {
    let names = |t: &Table| {
        t.channels
            .iter()
            .map(|c| c.name.clone())
            .collect::<Vec<_>>()
    };
    assert_eq!(names(a), names(b));
    for (x, y) in a.channels.iter().zip(&b.channels) {
        assert_eq!(x.data.len(), y.data.len(), "{}", x.name);
        for (i, (p, q)) in x.data.iter().zip(&y.data).enumerate() {
            assert!(
                p.to_bits() == q.to_bits() || (p.is_nan() && q.is_nan()),
                "{}[{i}]: {p:e} vs {q:e}",
                x.name
            );
        }
    }
}

#[test]
fn each_writer_reads_back_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let t = table(1000);
    for ext in ["npz", "mat", "parquet"] {
        let p = dir.path().join(format!("w.{ext}"));
        write_table(&p, &t).unwrap();
        same(&t, &read_table(&p).unwrap());
    }
    // The reference tools, when a Python with them is named.
    if let Ok(py) = std::env::var("ROTORID_IO_PYTHON") {
        let script = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/read_back.py");
        let out = std::process::Command::new(py)
            .arg(script)
            .arg(dir.path())
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}{}",
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        );
        eprintln!("{}", String::from_utf8_lossy(&out.stdout));
    }
}

#[test]
fn unequal_lengths_and_bad_names_are_refused_where_the_format_cannot_hold_them() {
    let mut t = table(10);
    t.channels.push(ch("short", vec![1.0, 2.0]));
    assert!(npz_bytes("a.npz", &t).is_ok());
    assert!(mat_v5_bytes("a.mat", &t).is_ok());
    let e = parquet_bytes("a.parquet", &t).unwrap_err();
    assert!(
        matches!(&e, WriteError::Unrepresentable { channel, .. } if channel == "short"),
        "{e}"
    );
    let t = Table {
        file: "f".into(),
        channels: vec![ch("g/x", vec![1.0])],
        notes: Vec::new(),
    };
    let e = mat_v5_bytes("a.mat", &t).unwrap_err();
    assert!(e.to_string().contains("not a MATLAB identifier"), "{e}");
    let e = write_table("a.xlsx", &t).unwrap_err();
    assert!(matches!(e, WriteError::UnknownFormat { .. }), "{e}");
}

#[test]
fn empty_channels_round_trip() {
    let t = Table {
        file: "f".into(),
        channels: vec![ch("a", vec![]), ch("b", vec![])],
        notes: Vec::new(),
    };
    let dir = tempfile::tempdir().unwrap();
    for ext in ["npz", "parquet"] {
        let p = dir.path().join(format!("e.{ext}"));
        write_table(&p, &t).unwrap();
        same(&t, &read_table(&p).unwrap());
    }
}
