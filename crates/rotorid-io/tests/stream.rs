//! Files read a block of rows at a time (`rotorid_io::stream`) against the same files read
//! whole (`read_table`, and `select` for the roles): every fixture and every fuzz corpus
//! file of a format that streams, at several block sizes. The whole-file readers are the
//! reference: they are checked against the reference tools' values in tests/fixtures.rs.

// (ReadError is large by design: lib.rs)
#![allow(clippy::result_large_err)]

use std::path::{Path, PathBuf};

use rotorid_io::{open_blocks, read_table, select, ColumnMap, ReadError, SiBlocks};

/// Block sizes: one row, a prime, a typical block, and more than any file here holds.
const BLOCKS: [usize; 4] = [1, 7, 4096, usize::MAX];

fn manifest() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The files of `dir` (sorted), or none when it does not exist.
fn files_in(dir: &Path) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(dir)
        .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    v.retain(|p| p.is_file());
    v.sort();
    v
}

/// The fixtures and fuzz corpus files whose format streams, with the extension each needs
/// (corpus files have none: they are named by their target's format).
/// The corpus files are copied into the directory returned, which lives as long as it.
fn streamed_files() -> (tempfile::TempDir, Vec<PathBuf>) {
    let mut out = Vec::new();
    for p in files_in(&manifest().join("fixtures")) {
        if is_streamed(&p) {
            out.push(p);
        }
    }
    let corpus = manifest().join("../../fuzz/corpus");
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    for (target, ext) in [("read_parquet", "parquet"), ("read_tdms", "tdms")] {
        for (i, p) in files_in(&corpus.join(target)).into_iter().enumerate() {
            let named = dir.join(format!("{target}_{i}.{ext}"));
            std::fs::copy(&p, &named).unwrap();
            if is_streamed(&named) {
                out.push(named);
            }
        }
    }
    (tmp, out)
}

/// Whether `path` is of a format `open_blocks` takes (one that does not stream answers
/// `Ok(None)` whatever the file holds).
fn is_streamed(path: &Path) -> bool {
    rotorid_io::Format::from_path(path).is_ok() && !matches!(open_blocks(path), Ok(None))
}

/// Every channel of `path` read through `open_blocks`, `block` rows at a time: the
/// catalogue (name, unit, length, axis), the notes and the samples.
type Streamed = (Vec<rotorid_io::ChannelInfo>, Vec<String>, Vec<Vec<f64>>);

fn stream_all(path: &Path, block: usize) -> Result<Streamed, ReadError> {
    let mut r = open_blocks(path)?.expect("a format that streams");
    let infos = r.channels().to_vec();
    let wanted: Vec<usize> = (0..infos.len()).collect();
    let mut data: Vec<Vec<f64>> = infos.iter().map(|_| Vec::new()).collect();
    let mut calls = 0usize;
    loop {
        let before: Vec<usize> = data.iter().map(Vec::len).collect();
        let n = r.next_rows(&wanted, block, &mut data)?;
        for (d, b) in data.iter().zip(&before) {
            assert_eq!(
                d.len() - b,
                n,
                "{}: every channel gets the same rows",
                path.display()
            );
        }
        assert!(n <= block, "{}: at most the rows asked for", path.display());
        if n == 0 {
            break;
        }
        calls += 1;
        assert!(
            calls <= infos.first().map_or(0, |c| c.len) + 1,
            "{}: each call gives rows until the end",
            path.display()
        );
    }
    Ok((infos, r.notes().to_vec(), data))
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

#[test]
fn every_streamed_file_reads_as_the_whole_file_reader_reads_it() {
    let (_dir, files) = streamed_files();
    assert!(
        files
            .iter()
            .any(|p| p.extension().is_some_and(|e| e == "parquet")),
        "the Parquet fixtures stream"
    );
    let mut compared = 0;
    for path in &files {
        let whole = read_table(path);
        for block in BLOCKS {
            let streamed = stream_all(path, block);
            match (&whole, streamed) {
                (Ok(t), Ok((infos, notes, data))) => {
                    let names: Vec<_> = t.channels.iter().map(|c| &c.name).collect();
                    let got: Vec<_> = infos.iter().map(|c| &c.name).collect();
                    assert_eq!(got, names, "{}: channels", path.display());
                    for ((c, info), d) in t.channels.iter().zip(&infos).zip(&data) {
                        let at = format!("{} channel {} block {block}", path.display(), c.name);
                        assert_eq!(info.unit, c.unit, "{at}: unit");
                        assert_eq!(info.axis, c.axis, "{at}: axis");
                        assert_eq!(info.len, c.data.len(), "{at}: length");
                        assert_eq!(bits(d), bits(&c.data), "{at}: samples");
                    }
                    assert_eq!(notes, t.notes, "{}: notes", path.display());
                    compared += 1;
                }
                (Err(_), Err(_)) => {}
                (Ok(_), Err(e)) => panic!("{}: read whole, refused streamed: {e}", path.display()),
                (Err(e), Ok(_)) => panic!("{}: refused whole ({e}), read streamed", path.display()),
            }
        }
    }
    assert!(compared > 0, "some file was read both ways");
}

#[test]
fn the_roles_in_si_are_those_select_gives_bit_for_bit() {
    let mut compared = 0;
    let (_dir, files) = streamed_files();
    for path in files {
        let Ok(table) = read_table(&path) else {
            continue;
        };
        let map = ColumnMap::default();
        let whole = select(table, &map);
        for block in [1, 7, 4096, usize::MAX] {
            let blocks = SiBlocks::new(open_blocks(&path).unwrap().unwrap(), &map);
            let (cols, mut blocks) = match (&whole, blocks) {
                (Ok(c), Ok(b)) => (c, b),
                (Err(a), Err(b)) => {
                    assert_eq!(a, &b, "{}: the same refusal", path.display());
                    continue;
                }
                (a, b) => panic!(
                    "{}: select {:?}, streamed {:?}",
                    path.display(),
                    a.as_ref().err(),
                    b.err()
                ),
            };
            assert_eq!(blocks.used(), cols.used.as_slice());
            assert_eq!(blocks.time_from_axis(), cols.time_from_axis);
            assert_eq!(blocks.has_speed(), cols.speed.is_some());
            assert_eq!(blocks.len(), cols.x.len());
            let (mut t, mut x, mut z) = (Vec::new(), Vec::new(), Vec::new());
            let mut speed: [Vec<f64>; 3] = Default::default();
            while let Some(b) = blocks.next_block(block).unwrap() {
                assert_eq!(b.first, x.len(), "{}: blocks in order", path.display());
                t.extend(&b.t);
                x.extend(&b.x);
                z.extend(&b.z);
                if let Some(s) = &b.speed {
                    for (all, part) in speed.iter_mut().zip(s) {
                        all.extend(part);
                    }
                }
            }
            let at = format!("{} block {block}", path.display());
            assert_eq!(bits(&t), bits(&cols.t), "{at}: t");
            assert_eq!(bits(&x), bits(&cols.x), "{at}: x");
            assert_eq!(bits(&z), bits(&cols.z), "{at}: z");
            if let Some(s) = &cols.speed {
                for (a, b) in speed.iter().zip(s) {
                    assert_eq!(bits(a), bits(b), "{at}: speed");
                }
            }
            compared += 1;
        }
    }
    assert!(compared > 0, "some record was selected both ways");
}
