//! Hostile files: every fixture truncated at many offsets, with bytes flipped, with length
//! fields blown up. A reader may refuse (with an error naming the file) but never panic,
//! hang, or allocate beyond the file's size (the fuzz targets in fuzz/ go further).

use std::path::{Path, PathBuf};

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;

use rotorid_io::{read_bytes, Format};

/// Records the largest single allocation made by this thread since the last reset.
struct Peak;

thread_local! {
    static PEAK: Cell<usize> = const { Cell::new(0) };
}

unsafe impl GlobalAlloc for Peak {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        let _ = PEAK.try_with(|p| p.set(p.get().max(layout.size())));
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        let _ = PEAK.try_with(|p| p.set(p.get().max(new_size)));
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static ALLOC: Peak = Peak;

/// The largest allocation a read of `len` bytes may make: 8 bytes of `f64` per input byte
/// (an `int8` sample becomes an `f64`) plus 1 MiB of slack; for formats that compress,
/// deflate's largest ratio (1032) on top.
fn allowed(format: Format, name: &str, len: usize) -> usize {
    let compressed = matches!(format, Format::Npz | Format::Parquet)
        || (format == Format::Mat && (name.contains("compressed") || name.contains("v73")));
    let k = if compressed { 1032 * 8 } else { 8 };
    k * len + (1 << 20)
}

fn fixtures() -> Vec<(PathBuf, Format, Vec<u8>)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("fixtures");
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if let Ok(f) = Format::from_path(&p) {
            if f != Format::Csv {
                out.push((p.clone(), f, std::fs::read(&p).unwrap()));
            }
        }
    }
    out.sort_by(|a, b| a.0.cmp(&b.0));
    assert!(out.len() >= 20, "fixtures found: {}", out.len());
    out
}

/// Reads, and checks that an error names the file and that the read allocated no more
/// than the file allows; true when the file was refused.
fn read(format: Format, name: &str, bytes: &[u8]) -> bool {
    // (a reader that loops for ever hangs this test, which CI's time limit ends; how fast
    // a read is depends on the machine's load and is no test's business)
    PEAK.with(|p| p.set(0));
    let r = read_bytes(format, name, bytes);
    let peak = PEAK.with(|p| p.get());
    let limit = allowed(format, name, bytes.len());
    assert!(
        peak <= limit,
        "{name} ({} bytes): allocated {peak} bytes at once, allowed {limit}",
        bytes.len()
    );
    match r {
        Ok(_) => false,
        Err(e) => {
            assert!(e.to_string().starts_with(name), "{e}");
            true
        }
    }
}

/// The offsets to cut at: every byte of the first 600, then about 400 more spread out.
fn cuts(len: usize) -> impl Iterator<Item = usize> {
    let step = (len / 400).max(1);
    (0..len.min(600)).chain((600..len).step_by(step))
}

#[test]
fn truncated_files_are_refused_without_panic() {
    for (path, format, bytes) in fixtures() {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let mut refused = 0;
        let mut n = 0;
        for cut in cuts(bytes.len()) {
            n += 1;
            if read(format, &name, &bytes[..cut]) {
                refused += 1;
            }
        }
        // Text formats may still parse a prefix, but most cuts must be noticed.
        assert!(
            refused * 2 > n,
            "{name}: only {refused} of {n} truncations refused"
        );
    }
}

#[test]
fn flipped_bytes_never_panic() {
    for (path, format, bytes) in fixtures() {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let mut b = bytes.clone();
        let step = (bytes.len() / 300).max(1);
        for i in (0..bytes.len()).step_by(step) {
            for mask in [0x01u8, 0x80, 0xff] {
                b[i] ^= mask;
                let _ = read(format, &name, &b);
                b[i] ^= mask;
            }
        }
    }
}

#[test]
fn huge_length_fields_never_allocate() {
    // Every aligned 4- and 8-byte window set to large values: a length or dimension field
    // claiming gigabytes must be refused before any allocation of that size (a failed
    // allocation would abort this test).
    for (path, format, bytes) in fixtures() {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let mut b = bytes.clone();
        let step = (bytes.len() / 200).max(1) & !3;
        for i in (0..bytes.len().saturating_sub(8)).step_by(step.max(4)) {
            for v in [0x7fff_ffffu32, 0xffff_fff0, 0x4000_0000] {
                let saved: [u8; 8] = b[i..i + 8].try_into().unwrap();
                b[i..i + 4].copy_from_slice(&v.to_le_bytes());
                let _ = read(format, &name, &b);
                b[i..i + 4].copy_from_slice(&v.to_be_bytes());
                let _ = read(format, &name, &b);
                b[i..i + 8].copy_from_slice(&(u64::from(v) << 20).to_le_bytes());
                let _ = read(format, &name, &b);
                b[i..i + 8].copy_from_slice(&saved);
            }
        }
    }
}

#[test]
fn forged_hdf5_chunk_indexes_are_refused_before_anything_is_sized_by_them() {
    // found by `cargo fuzz run read_mat` (seeds 7 and 11, 100-120 s): 12 KB MAT v7.3 files
    // whose chunk index puts a chunk of x at byte 69 900 592 742 912, or at an address that
    // overflows; the HDF5 layer sized a 3-4 GiB buffer to span it before finding the file
    // too short. Refused at once, naming the channel, from memory and from disk.
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    for (file, says) in [
        ("forged_chunk_address_v73.mat", "HDF5 chunk at element"),
        (
            "unlistable_chunk_index_v73.mat",
            "offset arithmetic overflow",
        ),
    ] {
        let path = dir.join(file);
        let bytes = std::fs::read(&path).unwrap();
        assert!(read(Format::Mat, file, &bytes));
        PEAK.with(|p| p.set(0));
        let e = rotorid_io::read_table(&path).unwrap_err();
        let peak = PEAK.with(|p| p.get());
        assert!(
            peak <= allowed(Format::Mat, "v73", bytes.len()),
            "{file}: {peak}"
        );
        let text = e.to_string();
        assert!(
            text.contains("channel \"x\"") && text.contains(says),
            "{text}"
        );
    }
}

#[test]
fn reading_from_disk_refuses_what_the_bytes_reader_refuses() {
    // `read_table` reads Parquet column chunk by column chunk, NPZ member by member, MAT
    // level 5 element by element, MAT v7.3 in the HDF5 layer's streaming mode, TDMS segment
    // by segment and UFF line by line from disk (`*::read_file`); it must accept and refuse
    // exactly what the in-memory readers do, with the same messages, and allocate no more
    // at once
    let dir = tempfile::tempdir().unwrap();
    for (path, format, bytes) in fixtures() {
        if !matches!(
            format,
            Format::Parquet | Format::Npz | Format::Mat | Format::Tdms | Format::Uff58
        ) {
            continue;
        }
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let on_disk = dir.path().join(&name);
        let on_disk_name = on_disk.display().to_string();
        let mut variants: Vec<Vec<u8>> = cuts(bytes.len()).map(|c| bytes[..c].to_vec()).collect();
        let step = (bytes.len() / 100).max(1);
        for i in (0..bytes.len()).step_by(step) {
            let mut b = bytes.clone();
            b[i] ^= 0xff;
            variants.push(b);
        }
        variants.push(bytes.clone());
        for b in variants {
            let len = b.len();
            std::fs::write(&on_disk, &b).unwrap();
            let mem = read_bytes(format, &on_disk_name, &b);
            PEAK.with(|p| p.set(0));
            let disk = rotorid_io::read_table(&on_disk);
            let peak = PEAK.with(|p| p.get());
            let limit = allowed(format, &name, len);
            assert!(
                peak <= limit,
                "{name} ({len} bytes) from disk: allocated {peak} bytes at once, allowed {limit}"
            );
            match (mem, disk) {
                (Ok(a), Ok(b)) => assert_eq!(a, b, "{name}"),
                // MAT v7.3 goes through the HDF5 layer's streaming mode from disk: it reads
                // other spans than from memory, so its own message ("need N bytes") may
                // differ; the file, the container and the kind of error may not
                (Err(a), Err(b)) if name.contains("v73") => {
                    let head = |e: &rotorid_io::ReadError| {
                        let s = e.to_string();
                        s.split(": HDF5 format error")
                            .next()
                            .unwrap_or(&s)
                            .to_owned()
                    };
                    assert_eq!(head(&a), head(&b), "{name} ({len} bytes)");
                    assert_eq!(
                        std::mem::discriminant(&a),
                        std::mem::discriminant(&b),
                        "{name} ({len} bytes): {a} / {b}"
                    );
                }
                (Err(a), Err(b)) => assert_eq!(a.to_string(), b.to_string(), "{name}"),
                (a, b) => panic!("{name} ({len} bytes): in memory {a:?}, from disk {b:?}"),
            }
        }
    }
}

#[test]
fn reading_tdms_and_uff_from_disk_refuses_huge_lengths_alike() {
    // the streaming TDMS and UFF readers check a length against the bytes left in the
    // file before reading that many: 4-byte windows set to huge lengths must be refused as
    // the in-memory readers refuse them (every cut, every byte flipped and every aligned
    // window of these fixtures were compared once too: 5 minutes, too slow for CI)
    let dir = tempfile::tempdir().unwrap();
    for (path, format, bytes) in fixtures() {
        if !matches!(format, Format::Tdms | Format::Uff58) {
            continue;
        }
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let on_disk = dir.path().join(&name);
        let on_disk_name = on_disk.display().to_string();
        let check = |b: &[u8]| {
            std::fs::write(&on_disk, b).unwrap();
            let mem = read_bytes(format, &on_disk_name, b);
            let disk = rotorid_io::read_table(&on_disk);
            match (mem, disk) {
                // as text: a changed byte may make a sample NaN
                (Ok(a), Ok(d)) => assert_eq!(format!("{a:?}"), format!("{d:?}"), "{name}"),
                (Err(a), Err(d)) => assert_eq!(a.to_string(), d.to_string(), "{name}"),
                (a, d) => panic!(
                    "{name} ({} bytes): in memory {a:?}, from disk {d:?}",
                    b.len()
                ),
            }
        };
        let step = ((bytes.len() / 100).max(4)) & !3;
        let mut b = bytes.clone();
        for i in (0..bytes.len().saturating_sub(8)).step_by(step) {
            let saved: [u8; 8] = b[i..i + 8].try_into().unwrap();
            for v in [0x7fff_ffffu32, 0xffff_fff0] {
                b[i..i + 4].copy_from_slice(&v.to_le_bytes());
                check(&b);
                b[i..i + 4].copy_from_slice(&v.to_be_bytes());
                check(&b);
                b[i..i + 8].copy_from_slice(&(u64::from(v) << 20).to_le_bytes());
                check(&b);
                b[i..i + 8].copy_from_slice(&saved);
            }
        }
    }
}
