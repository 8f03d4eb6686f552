//! Files read a block of rows at a time (`rotorid_io::stream`: Parquet, TDMS) against the
//! same files read whole (`read_table`, and `select` for the roles): every fixture and fuzz
//! corpus file of a format that streams, at several block sizes, gives the same catalogue
//! (names, units, lengths, time axes), notes and samples bit for bit; the same files cut,
//! with bytes flipped or lengths blown up are refused streamed whenever they are refused
//! whole (TDMS with the same message), and never panic. The whole-file readers are the reference:
//! tests/fixtures.rs checks them against the reference tools' values.

// (ReadError is large by design: lib.rs)
#![allow(clippy::result_large_err)]

use std::path::{Path, PathBuf};

use rotorid_io::{
    open_blocks, read_table, select, ColumnMap, ReadError, RowBlocks, SiBlocks, Table,
};

/// Block sizes: one row, a prime, a typical block, and more than any file here holds.
const BLOCKS: [usize; 4] = [1, 7, 4096, usize::MAX];

/// The formats that stream, with the fuzz target whose corpus holds such files.
const STREAMED: [(&str, &str); 2] = [("parquet", "read_parquet"), ("tdms", "read_tdms")];

/// Every fixture and fuzz corpus file of a format that streams: (name, extension, bytes).
fn files() -> Vec<(String, &'static str, Vec<u8>)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut out = Vec::new();
    for (ext, target) in STREAMED {
        for dir in [
            root.join("fixtures"),
            root.join("tests/data"),
            root.join("../../fuzz/corpus").join(target),
        ] {
            let Ok(entries) = std::fs::read_dir(&dir) else {
                continue;
            };
            let mut paths: Vec<PathBuf> = entries.map(|e| e.unwrap().path()).collect();
            paths.sort();
            for p in paths {
                if p.extension().is_some_and(|e| e == ext) {
                    let name = format!(
                        "{}/{}",
                        dir.file_name().unwrap().to_string_lossy(),
                        p.file_name().unwrap().to_string_lossy()
                    );
                    out.push((name, ext, std::fs::read(&p).unwrap()));
                }
            }
        }
    }
    for (ext, _) in STREAMED {
        let n = out.iter().filter(|f| f.1 == ext).count();
        assert!(n >= 4, "{n} .{ext} files found");
    }
    out
}

/// Every channel of `b` (`stream::for_each_block`), `max_rows` rows at a time; checks that
/// each block holds at most `max_rows` rows.
fn read_all(b: &mut dyn RowBlocks, max_rows: usize) -> Result<Vec<Vec<f64>>, ReadError> {
    let mut data = vec![Vec::new(); b.channels().len()];
    rotorid_io::stream::for_each_block(b, max_rows, |which, rows| {
        for (&k, r) in which.iter().zip(rows) {
            assert!(r.len() <= max_rows);
            data[k].extend_from_slice(r);
        }
    })?;
    Ok(data)
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// Streams `path` with every block size of `sizes` and compares with `want`, its whole
/// read; returns whether an error's text differed (both erring), for a format whose
/// refusals must read the same both ways (TDMS). A Parquet file with several faults may
/// name another one streamed than read whole (whole, a column is decoded to its end before
/// the next; streamed, every column a block at a time), and the `parquet` crate's own
/// message may give another value index (it depends on how many values a call asks for).
fn compare(name: &str, path: &Path, want: &Result<Table, ReadError>, sizes: &[usize]) -> bool {
    let same_refusal = path.extension().is_some_and(|e| e == "tdms");
    let mut differ = false;
    let file = path.display().to_string();
    for &max_rows in sizes {
        let got = open_blocks(path).and_then(|b| {
            let mut b = b.expect("a format that streams");
            let data = read_all(&mut *b, max_rows)?;
            Ok((b, data))
        });
        match (want, got) {
            (Ok(t), Ok((b, data))) => {
                assert_eq!(b.channels().len(), t.channels.len(), "{name}");
                for ((info, c), d) in b.channels().iter().zip(&t.channels).zip(&data) {
                    assert_eq!(
                        (&info.name, &info.unit, info.len, info.axis),
                        (&c.name, &c.unit, c.data.len(), c.axis),
                        "{name}"
                    );
                    assert_eq!(bits(d), bits(&c.data), "{name}: {} by {max_rows}", c.name);
                }
                assert_eq!(b.notes(), t.notes.as_slice(), "{name}");
            }
            (Err(e), Err(g)) => {
                assert!(g.to_string().starts_with(&file), "{g}");
                if same_refusal && e.to_string() != g.to_string() {
                    eprintln!("{name}: whole file: {e}\n  streamed: {g}");
                    differ = true;
                }
            }
            (Ok(_), Err(g)) => panic!("{name}: read whole, refused streamed: {g}"),
            (Err(e), Ok(_)) => panic!("{name}: refused whole ({e}), read streamed"),
        }
    }
    differ
}

#[test]
fn fixtures_and_corpus_stream_as_they_read_whole() {
    let dir = tempfile::tempdir().unwrap();
    for (name, ext, bytes) in files() {
        let path = dir.path().join(format!("x.{ext}"));
        std::fs::write(&path, &bytes).unwrap();
        let want = read_table(&path);
        assert!(!compare(&name, &path, &want, &BLOCKS), "{name}");
        let Ok(t) = want else {
            continue;
        };
        // a channel read alone, or before another, is the same channel
        let mut b = open_blocks(&path).unwrap().unwrap();
        let last = t.channels.len() - 1;
        let wanted = if t.channels[last].data.len() == t.channels[0].data.len() && last > 0 {
            vec![last, 0]
        } else {
            vec![last]
        };
        let mut out = vec![Vec::new(); wanted.len()];
        while b.next_rows(&wanted, 1000, &mut out).unwrap() > 0 {}
        for (k, o) in wanted.iter().zip(&out) {
            assert_eq!(bits(o), bits(&t.channels[*k].data), "{name}");
        }
    }
}

#[test]
fn hostile_files_are_refused_streamed_whenever_they_are_whole() {
    // every file cut at many offsets, with bytes flipped, with 4- and 8-byte windows set
    // to huge lengths: never a panic, an error whenever the whole-file reader errs (with
    // its message), and the same values when it reads
    let dir = tempfile::tempdir().unwrap();
    let (mut files_checked, mut refused, mut differ) = (0, 0, 0);
    for (name, ext, bytes) in files() {
        let path = dir.path().join(format!("x.{ext}"));
        let mut check = |what: &str, b: &[u8]| {
            std::fs::write(&path, b).unwrap();
            let want = read_table(&path);
            refused += usize::from(want.is_err());
            files_checked += 1;
            differ += usize::from(compare(
                &format!("{name} {what}"),
                &path,
                &want,
                &[7, 1 << 20],
            ));
        };
        let len = bytes.len();
        let step = (len / 150).max(1);
        for cut in (0..len).step_by(step) {
            check(&format!("cut at {cut}"), &bytes[..cut]);
        }
        let mut b = bytes.clone();
        for i in (0..len).step_by(step) {
            for x in [0x01u8, 0x80, 0xff] {
                b[i] ^= x;
                check(&format!("byte {i} ^ {x:#x}"), &b);
                b[i] ^= x;
            }
        }
        let step = ((len / 60).max(4)) & !3;
        for i in (0..len.saturating_sub(8)).step_by(step) {
            let saved: [u8; 8] = b[i..i + 8].try_into().unwrap();
            for v in [0x7fff_ffffu32, 0xffff_fff0] {
                b[i..i + 4].copy_from_slice(&v.to_le_bytes());
                check(&format!("{v:#x} at {i}"), &b);
                b[i..i + 8].copy_from_slice(&(u64::from(v) << 20).to_le_bytes());
                check(&format!("{v:#x} << 20 at {i}"), &b);
                b[i..i + 8].copy_from_slice(&saved);
            }
        }
    }
    eprintln!("{files_checked} files, {refused} refused, {differ} with another error text");
    assert!(refused > files_checked / 4, "{refused} of {files_checked}");
    assert_eq!(differ, 0, "error texts that differ (see stderr)");
}

#[test]
fn the_roles_in_si_are_those_select_gives_bit_for_bit() {
    // through the registry (stream::open_blocks) and SiBlocks: the SI columns
    // select(read_table(..)) gives, bit for bit, or the same refusal; by the default names,
    // and by the full names of the first three channels of one length
    let dir = tempfile::tempdir().unwrap();
    let (mut compared, mut streamed) = (0, 0);
    for (name, ext, bytes) in files() {
        let path = dir.path().join(format!("x.{ext}"));
        std::fs::write(&path, &bytes).unwrap();
        let Ok(t) = read_table(&path) else {
            continue;
        };
        let mut maps = vec![ColumnMap::default()];
        for c in &t.channels {
            let same: Vec<&str> = t
                .channels
                .iter()
                .filter(|d| d.data.len() == c.data.len())
                .map(|d| d.name.as_str())
                .collect();
            if same.len() >= 3 {
                maps.push(ColumnMap::parse(&same[..3].join(",")).unwrap());
                break;
            }
        }
        for map in &maps {
            for block in BLOCKS {
                compared += 1;
                let want = select(t.clone(), map);
                let got = SiBlocks::new(open_blocks(&path).unwrap().unwrap(), map);
                let (want, mut got) = match (want, got) {
                    (Ok(w), Ok(g)) => (w, g),
                    (Err(w), Err(g)) => {
                        assert_eq!(w, g, "{name}");
                        continue;
                    }
                    (w, g) => panic!(
                        "{name}: select {:?}, streamed {:?}",
                        w.map(|_| ()),
                        g.map(|_| ())
                    ),
                };
                streamed += 1;
                assert_eq!(got.used(), want.used.as_slice(), "{name}");
                assert_eq!(got.time_from_axis(), want.time_from_axis, "{name}");
                assert_eq!(got.has_speed(), want.speed.is_some(), "{name}");
                assert_eq!(got.len(), want.x.len(), "{name}");
                let (mut t_, mut x, mut z) = (Vec::new(), Vec::new(), Vec::new());
                let mut speed: [Vec<f64>; 3] = Default::default();
                while let Some(b) = got.next_block(block).unwrap() {
                    assert_eq!(b.first, x.len(), "{name}: blocks in order");
                    t_.extend(b.t);
                    x.extend(b.x);
                    z.extend(b.z);
                    for (all, part) in speed.iter_mut().zip(b.speed.into_iter().flatten()) {
                        all.extend(part);
                    }
                }
                let at = format!("{name} block {block}");
                assert_eq!(bits(&t_), bits(&want.t), "{at}: t");
                assert_eq!(bits(&x), bits(&want.x), "{at}: x");
                assert_eq!(bits(&z), bits(&want.z), "{at}: z");
                for (a, w) in speed.iter().zip(want.speed.iter().flatten()) {
                    assert_eq!(bits(a), bits(w), "{at}: speed");
                }
            }
        }
    }
    eprintln!("{compared} selections compared, {streamed} streamed");
    assert!(streamed >= 8, "{streamed}");
}
