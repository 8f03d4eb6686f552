//! TDMS files streamed a block of rows at a time (`rotorid_io::tdms::open_blocks`) against
//! the whole-file reader (`rotorid_io::tdms::read_file`): the fixtures and the fuzz corpus
//! give the same catalogue, notes and values bit for bit, whatever the block size; the
//! same files cut, with bytes flipped or lengths blown up are refused whenever the
//! whole-file reader refuses them, and never panic; and a long file of many segments is
//! streamed holding a few blocks, never a channel.

// (ReadError is returned once per failed read: its size costs nothing here)
#![allow(clippy::result_large_err)]

use std::path::{Path, PathBuf};

use rotorid_io::tdms::{open_blocks, read_file, TdmsBlocks};
use rotorid_io::{ReadError, RowBlocks, Table};

/// Block sizes streamed: one row, a few, many, all.
const MAX_ROWS: [usize; 4] = [1, 7, 4096, usize::MAX];

/// The TDMS fixtures and the fuzz corpus's files.
fn files() -> Vec<(String, Vec<u8>)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut out = Vec::new();
    for dir in [
        root.join("fixtures"),
        root.join("tests/data"),
        root.join("../../fuzz/corpus/read_tdms"),
    ] {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        let mut paths: Vec<PathBuf> = entries.map(|e| e.unwrap().path()).collect();
        paths.sort();
        for p in paths {
            if p.extension().is_some_and(|e| e == "tdms") {
                let name = format!(
                    "{}/{}",
                    dir.file_name().unwrap().to_string_lossy(),
                    p.file_name().unwrap().to_string_lossy()
                );
                out.push((name, std::fs::read(&p).unwrap()));
            }
        }
    }
    assert!(out.len() >= 8, "TDMS files found: {}", out.len());
    out
}

/// Every channel of `b`, those of one length read together, `max_rows` rows at a time;
/// checks that each call gives every channel asked for the same rows, at most `max_rows`.
fn read_all(b: &mut TdmsBlocks, max_rows: usize) -> Result<Vec<Vec<f64>>, ReadError> {
    let lens: Vec<usize> = b.channels().iter().map(|c| c.len).collect();
    let mut data = vec![Vec::new(); lens.len()];
    let mut groups = lens.clone();
    groups.sort_unstable();
    groups.dedup();
    for len in groups {
        let wanted: Vec<usize> = (0..lens.len()).filter(|&k| lens[k] == len).collect();
        let mut out = vec![Vec::new(); wanted.len()];
        let mut total = 0;
        loop {
            let n = b.next_rows(&wanted, max_rows, &mut out)?;
            assert!(n <= max_rows);
            total += n;
            assert!(out.iter().all(|o| o.len() == total));
            if n == 0 {
                break;
            }
        }
        assert_eq!(total, len);
        for (k, o) in wanted.into_iter().zip(out) {
            data[k] = o;
        }
    }
    Ok(data)
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

/// Streams `path` with every block size and compares with `want`; returns whether an
/// error's text differed (both erring).
fn compare(name: &str, path: &Path, want: &Result<Table, ReadError>, sizes: &[usize]) -> bool {
    let mut differ = false;
    for &max_rows in sizes {
        let got = open_blocks("x.tdms", path).and_then(|mut b| {
            let data = read_all(&mut b, max_rows)?;
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
                assert!(g.to_string().starts_with("x.tdms"), "{g}");
                if e.to_string() != g.to_string() {
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
    for (name, bytes) in files() {
        let path = dir.path().join("x.tdms");
        std::fs::write(&path, &bytes).unwrap();
        let want = read_file("x.tdms", &path);
        assert!(want.is_ok(), "{name}: {want:?}");
        assert!(!compare(&name, &path, &want, &MAX_ROWS));
        // a channel read alone, or with another, is the same channel
        let t = want.as_ref().unwrap();
        let mut b = open_blocks("x.tdms", &path).unwrap();
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
    // every fixture cut at many offsets, with bytes flipped, with 4- and 8-byte windows set
    // to huge lengths: never a panic, an error whenever the whole-file reader errs, and
    // the same values when it reads
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("x.tdms");
    let (mut files_checked, mut refused, mut differ) = (0, 0, 0);
    let mut check = |name: &str, b: &[u8]| {
        std::fs::write(&path, b).unwrap();
        let want = read_file("x.tdms", &path);
        refused += usize::from(want.is_err());
        files_checked += 1;
        differ += usize::from(compare(name, &path, &want, &[7, usize::MAX]));
    };
    for (name, bytes) in files() {
        let len = bytes.len();
        let step = (len / 150).max(1);
        for cut in (0..len).step_by(step) {
            check(&format!("{name} cut at {cut}"), &bytes[..cut]);
        }
        let mut b = bytes.clone();
        for i in (0..len).step_by(step) {
            for x in [0x01u8, 0x80, 0xff] {
                b[i] ^= x;
                check(&format!("{name} byte {i} ^ {x:#x}"), &b);
                b[i] ^= x;
            }
        }
        let step = ((len / 60).max(4)) & !3;
        for i in (0..len.saturating_sub(8)).step_by(step) {
            let saved: [u8; 8] = b[i..i + 8].try_into().unwrap();
            for v in [0x7fff_ffffu32, 0xffff_fff0] {
                b[i..i + 4].copy_from_slice(&v.to_le_bytes());
                check(&format!("{name} {v:#x} at {i}"), &b);
                b[i..i + 8].copy_from_slice(&(u64::from(v) << 20).to_le_bytes());
                check(&format!("{name} {v:#x} << 20 at {i}"), &b);
                b[i..i + 8].copy_from_slice(&saved);
            }
        }
    }
    eprintln!("{files_checked} files, {refused} refused, {differ} with another error text");
    assert!(refused > files_checked / 4, "{refused} of {files_checked}");
    assert_eq!(differ, 0, "error texts that differ (see stderr)");
}

/// A TDMS segment of a new object list holding channels `(path, type code, values)` of
/// little-endian `f64` (type 10) or `i16` (type 2) contiguous raw data.
fn segment(channels: &[(&str, u32, &[f64])]) -> Vec<u8> {
    let mut meta = (channels.len() as u32).to_le_bytes().to_vec();
    let mut raw = Vec::new();
    for &(path, t, values) in channels {
        meta.extend((path.len() as u32).to_le_bytes());
        meta.extend(path.as_bytes());
        meta.extend(20u32.to_le_bytes());
        meta.extend(t.to_le_bytes());
        meta.extend(1u32.to_le_bytes());
        meta.extend((values.len() as u64).to_le_bytes());
        meta.extend(0u32.to_le_bytes());
        for &v in values {
            match t {
                10 => raw.extend(v.to_le_bytes()),
                _ => raw.extend((v as i16).to_le_bytes()),
            }
        }
    }
    let mut f = b"TDSm".to_vec();
    f.extend((0x02u32 | 0x04 | 0x08).to_le_bytes());
    f.extend(4713u32.to_le_bytes());
    f.extend(((meta.len() + raw.len()) as u64).to_le_bytes());
    f.extend((meta.len() as u64).to_le_bytes());
    f.extend(meta);
    f.extend(raw);
    f
}

#[test]
fn a_long_file_of_many_segments_streams_in_bounded_memory() {
    // 40 segments of 60,000 f64 values of x and 60,000 i16 of z (2.4 million values each,
    // 38.4 MB as f64), 4096 rows at a time: the queues hold, per channel, fewer than
    // 4096 rows plus one 256 KiB block of the file (32,768 f64 or 131,072 i16), twice
    // over for a vector's growth, at 8 bytes a value
    let per = 60_000;
    let mut f = Vec::new();
    let (mut xs, mut zs) = (Vec::new(), Vec::new());
    for s in 0..40 {
        let x: Vec<f64> = (0..per).map(|i| (s * per + i) as f64 * 0.25).collect();
        let z: Vec<f64> = (0..per).map(|i| ((s * 7 + i) % 30_000) as f64).collect();
        f.extend(segment(&[("/'g'/'x'", 10, &x), ("/'g'/'z'", 2, &z)]));
        xs.extend(x);
        zs.extend(z);
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("long.tdms");
    std::fs::write(&path, &f).unwrap();
    let max_rows = 4096;
    let mut b = open_blocks("long.tdms", &path).unwrap();
    assert_eq!(b.channels()[0].len, 40 * per);
    let mut got = [Vec::new(), Vec::new()];
    let mut out = [Vec::new(), Vec::new()];
    loop {
        let n = b.next_rows(&[0, 1], max_rows, &mut out).unwrap();
        if n == 0 {
            break;
        }
        for (g, o) in got.iter_mut().zip(&mut out) {
            g.append(o);
        }
    }
    assert_eq!(bits(&got[0]), bits(&xs));
    assert_eq!(bits(&got[1]), bits(&zs));
    let bound = 2 * (2 * (max_rows + (1 << 18) / 8) + 2 * (max_rows + (1 << 18) / 2)) * 8;
    let peak = b.peak_queued_bytes();
    eprintln!(
        "queues held at most {peak} bytes (bound {bound}; the channels: {})",
        2 * 8 * xs.len()
    );
    assert!(peak > 0 && peak <= bound, "{peak} > {bound}");
    assert!(peak * 4 < 2 * 8 * xs.len());
}

#[test]
fn rotorid_io_open_blocks_streams_tdms_into_the_si_columns_select_gives() {
    // through the registry (stream::open_blocks) and SiBlocks, by blocks of 1000 rows: the
    // SI columns select(read_table(..)) gives, bit for bit, or the same refusal
    use rotorid_io::{open_blocks, read_table, select, ColumnMap, SiBlocks};
    let dir = tempfile::tempdir().unwrap();
    let (mut compared, mut streamed) = (0, 0);
    for (name, bytes) in files() {
        let path = dir.path().join("x.tdms");
        std::fs::write(&path, &bytes).unwrap();
        let t = read_table(&path).unwrap();
        // the default names, and the first channels (as t, x, z) of the first length that
        // has three, by their full names
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
            compared += 1;
            let want = select(t.clone(), map);
            let inner = open_blocks(&path).unwrap().expect("TDMS streams");
            let got = SiBlocks::new(inner, map);
            let (want, mut got) = match (want, got) {
                (Ok(w), Ok(g)) => (w, g),
                (Err(w), Err(g)) => {
                    assert_eq!(w.to_string(), g.to_string(), "{name}");
                    continue;
                }
                (w, g) => panic!(
                    "{name}: select {:?}, streamed {:?}",
                    w.map(|_| ()),
                    g.map(|_| ())
                ),
            };
            streamed += 1;
            let (mut t_, mut x, mut z) = (Vec::new(), Vec::new(), Vec::new());
            while let Some(b) = got.next_block(1000).unwrap() {
                assert_eq!(b.first, x.len());
                t_.extend(b.t);
                x.extend(b.x);
                z.extend(b.z);
            }
            assert_eq!(bits(&t_), bits(&want.t), "{name}");
            assert_eq!(bits(&x), bits(&want.x), "{name}");
            assert_eq!(bits(&z), bits(&want.z), "{name}");
        }
    }
    eprintln!("{compared} selections compared, {streamed} streamed");
    assert!(streamed >= 2, "{streamed}");
}
