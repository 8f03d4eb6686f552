//! A long TDMS file of many segments streamed a block of rows at a time
//! (`rotorid_io::tdms::open_blocks`) holds a few blocks, never a channel. (Streamed against
//! read whole, for every format that streams: tests/stream.rs.)

use rotorid_io::tdms::open_blocks;
use rotorid_io::RowBlocks;

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
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
