//! The finite-element matrices file against numpy: the files numpy.savez and
//! savez_compressed wrote (fixtures/fe/make.py: C and Fortran order, both byte orders,
//! `dofs` as unicode and as bytes) read entry for entry, numpy's faults named, and the
//! writer's members byte for byte what numpy.savez wrote for the same arrays.

// (ReadError is large by design: it carries the file, member and values inline)
#![allow(clippy::result_large_err)]

use std::io::Read as _;
use std::path::{Path, PathBuf};

use rotorid_io::fe_matrices::{self, FeMatricesFile};
use rotorid_io::ReadError;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/fe")
        .join(name)
}

const N: usize = 8;
const DOFS: [&str; N] = ["0.x", "0.y", "0.rx", "0.ry", "3.x", "3.y", "3.rx", "3.ry"];

/// make.py's formulas, row-major.
fn formula(f: impl Fn(f64, f64) -> f64) -> Vec<f64> {
    (0..N * N)
        .map(|k| f((k / N) as f64, (k % N) as f64))
        .collect()
}

fn m() -> Vec<f64> {
    formula(|i, j| 1.0 / (1.0 + i + j) + if i == j { 1.0 } else { 0.0 })
}
fn k() -> Vec<f64> {
    formula(|i, j| 1e6 * (i + 1.0) - 3.5 * j)
}
fn g() -> Vec<f64> {
    formula(|i, j| (i - j) / 7.0)
}
fn c() -> Vec<f64> {
    formula(|i, j| 0.25 * (i + j))
}
fn ka() -> Vec<f64> {
    formula(|i, j| (8.0 * i + j) / 3.0)
}

fn read(name: &str) -> Result<FeMatricesFile, ReadError> {
    let path = fixture(name);
    let whole = fe_matrices::read(name, &std::fs::read(&path).unwrap());
    let streamed = fe_matrices::read_file(name, &path);
    // in memory and from disk, alike
    assert_eq!(
        format!("{whole:?}"),
        format!("{streamed:?}"),
        "{name}: read and read_file differ"
    );
    whole
}

fn bits(a: &[f64]) -> Vec<u64> {
    a.iter().map(|v| v.to_bits()).collect()
}

#[test]
fn numpy_files_are_read_entry_for_entry() {
    let f = read("savez.npz").unwrap();
    assert_eq!(f.dofs, DOFS);
    assert_eq!(bits(&f.m), bits(&m()));
    assert_eq!(bits(&f.k), bits(&k()));
    assert_eq!(bits(&f.g), bits(&g()));
    assert_eq!(bits(f.c.as_deref().unwrap()), bits(&c()));
    assert_eq!(bits(f.ka.as_deref().unwrap()), bits(&ka()));

    let f = read("compressed_bytes.npz").unwrap();
    assert_eq!(f.dofs, DOFS);
    assert_eq!(bits(&f.m), bits(&m()));
    assert_eq!(bits(&f.g), bits(&g()));
    assert_eq!((f.c, f.ka), (None, None));

    let f = read("fortran_big_endian.npz").unwrap();
    assert_eq!(f.dofs, DOFS);
    assert_eq!(bits(&f.m), bits(&m()), "M in Fortran order");
    assert_eq!(bits(&f.k), bits(&k()), "K big endian");
    assert_eq!(bits(&f.g), bits(&g()), "G big endian in Fortran order");
    assert_eq!(bits(f.ka.as_deref().unwrap()), bits(&ka()));
    // (G is antisymmetric: read transposed, it would be -G)
    assert_ne!(bits(&f.g), bits(&formula(|i, j| (j - i) / 7.0)));
}

#[test]
fn numpy_faults_are_named() {
    // (file, the message's start, and a part of what it allows)
    let cases = [
        (
            "bad_shape.npz",
            "bad_shape.npz: member K is 7 x 8: must be 8 x 8",
            "one row and column per entry of dofs, which has 8",
        ),
        (
            "object_dofs.npz",
            "object_dofs.npz: member dofs has dtype \"|O\"",
            "save numpy.array(dofs, dtype=str)",
        ),
        (
            "float32.npz",
            "float32.npz: member G has dtype \"<f4\": must be float64",
            "never converted",
        ),
        (
            "ksdt.npz",
            "ksdt.npz: member Ksdt is not a member of a matrices file",
            "ROSS's Ksdt is saved as Ka",
        ),
    ];
    for (file, start, part) in cases {
        let e = read(file).unwrap_err();
        assert!(matches!(e, ReadError::Member { .. }), "{file}: {e:?}");
        let e = e.to_string();
        assert!(e.starts_with(start) && e.contains(part), "{file}: {e}");
    }
}

/// The members of an archive: name -> bytes.
fn members(bytes: &[u8]) -> Vec<(String, Vec<u8>)> {
    let mut z = zip::ZipArchive::new(std::io::Cursor::new(bytes)).unwrap();
    let mut out = Vec::new();
    for i in 0..z.len() {
        let mut m = z.by_index(i).unwrap();
        let mut b = Vec::new();
        m.read_to_end(&mut b).unwrap();
        out.push((m.name().to_owned(), b));
    }
    out.sort();
    out
}

#[test]
fn the_writer_writes_the_members_numpy_writes() {
    let f = FeMatricesFile {
        file: "w.npz".into(),
        dofs: DOFS.map(String::from).to_vec(),
        m: m(),
        k: k(),
        g: g(),
        c: Some(c()),
        ka: Some(ka()),
    };
    let ours = fe_matrices::npz_bytes("w.npz", &f).unwrap();
    let numpy = std::fs::read(fixture("savez.npz")).unwrap();
    assert_eq!(members(&ours), members(&numpy));
    let back = fe_matrices::read("w.npz", &ours).unwrap();
    assert_eq!(back, f);
}
