//! What the errors say: the file, the channel, the byte offset, what was found and allowed.

use std::path::Path;

use rotorid_io::{read_bytes, Format, ReadError};

fn fixture(name: &str) -> Vec<u8> {
    std::fs::read(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("fixtures")
            .join(name),
    )
    .unwrap()
}

fn patch(bytes: &mut [u8], find: &[u8], at: usize, with: u8) -> usize {
    let i = bytes
        .windows(find.len())
        .position(|w| w == find)
        .expect("pattern in fixture");
    bytes[i + at] = with;
    i + at
}

fn npy(header: &str, data: &[u8]) -> Vec<u8> {
    let mut h = header.to_string();
    while !(10 + h.len() + 1).is_multiple_of(64) {
        h.push(' ');
    }
    h.push('\n');
    let mut b = b"\x93NUMPY\x01\x00".to_vec();
    b.extend((h.len() as u16).to_le_bytes());
    b.extend(h.as_bytes());
    b.extend(data);
    b
}

#[test]
fn a_dimension_larger_than_the_file_is_refused_before_allocating() {
    let b = npy(
        "{'descr': '<f8', 'fortran_order': False, 'shape': (1000000000000,), }",
        &[0; 16],
    );
    let e = read_bytes(Format::Npy, "big.npy", &b).unwrap_err();
    match &e {
        ReadError::Truncated {
            file,
            channel,
            offset,
            need,
            available,
            ..
        } => {
            assert_eq!(file, "big.npy");
            assert_eq!(channel.as_deref(), Some("big"));
            assert_eq!(
                (*offset, *need, *available),
                (b.len() as u64 - 16, 8_000_000_000_000, 16)
            );
        }
        other => panic!("{other}"),
    }
    let msg = e.to_string();
    assert!(
        msg.starts_with("big.npy, channel \"big\": ")
            && msg.contains(&format!("at byte {}", b.len() - 16)),
        "{msg}"
    );
}

#[test]
fn an_inexact_int64_names_its_sample() {
    let e = read_bytes(Format::Npy, "inexact_i8.npy", &fixture("inexact_i8.npy")).unwrap_err();
    match e {
        ReadError::InexactInteger {
            channel,
            index,
            offset,
            value,
            ..
        } => {
            assert_eq!(
                (channel.as_str(), index, value),
                ("inexact_i8", 1, (1i128 << 53) + 1)
            );
            assert_eq!(offset, 128 + 8);
        }
        other => panic!("{other}"),
    }
    let e = read_bytes(Format::Mat, "inexact_v5.mat", &fixture("inexact_v5.mat")).unwrap_err();
    assert!(
        matches!(e, ReadError::InexactInteger { ref channel, index: 0, .. } if channel == "n"),
        "{e}"
    );
}

#[test]
fn names_that_are_not_utf8_are_refused_with_their_offset() {
    let mut b = fixture("rec_v5.mat");
    let at = patch(&mut b, b"\x01\x00\x01\x00t\x00", 4, 0xff);
    let e = read_bytes(Format::Mat, "rec_v5.mat", &b).unwrap_err();
    assert!(
        matches!(e, ReadError::NotUtf8 { offset, .. } if offset == at as u64),
        "{e} (name at {at})"
    );

    let mut b = fixture("rec.tdms");
    let at = patch(&mut b, b"/'bearing1'/'x'", 13, 0xff);
    let e = read_bytes(Format::Tdms, "rec.tdms", &b).unwrap_err();
    assert!(
        matches!(e, ReadError::NotUtf8 { offset, .. } if offset == at as u64 - 13 ),
        "{e} (path at {})",
        at - 13
    );

    let mut b = fixture("rec.uff");
    let at = patch(&mut b, b"\nx      ", 1, 0xe9);
    let e = read_bytes(Format::Uff58, "rec.uff", &b).unwrap_err();
    assert!(
        matches!(e, ReadError::NotUtf8 { offset, .. } if offset == at as u64),
        "{e} (ID line at {at})"
    );
}

#[test]
fn a_truncated_tdms_segment_names_the_segment() {
    let b = fixture("rec.tdms");
    let e = read_bytes(Format::Tdms, "rec.tdms", &b[..b.len() - 1]).unwrap_err();
    match e {
        ReadError::Truncated {
            what,
            offset,
            need,
            available,
            ..
        } => {
            assert_eq!(what, "TDMS segment");
            assert!(
                offset > 0 && need == available + 1,
                "{offset} {need} {available}"
            );
        }
        other => panic!("{other}"),
    }
}

#[test]
fn complex_uff_is_refused_naming_the_channel() {
    let e = read_bytes(Format::Uff58, "frf.uff", &fixture("frf_complex.uff")).unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains("channel \"H\"") && msg.contains("complex") && msg.contains("allowed: 2 or 4"),
        "{msg}"
    );
}

#[test]
fn parquet_nulls_are_refused_naming_the_row() {
    let e = read_bytes(Format::Parquet, "nulls.parquet", &fixture("nulls.parquet")).unwrap_err();
    let msg = e.to_string();
    assert!(
        msg.contains("channel \"x\"")
            && msg.contains("row 1 of row group 0")
            // the column chunk's first page: right after the leading magic `PAR1`
            && msg.contains("at byte 4 is a null"),
        "{msg}"
    );
}

#[test]
fn a_column_chunk_the_parquet_crate_panics_on_is_named_with_its_offset() {
    // A BYTE_STREAM_SPLIT page shorter than its value count (found by fuzzing): the crate
    // indexes out of bounds in column z's chunk of row group 0, whose first page header is
    // at byte 1569 and which the footer gives 575 bytes (the next header follows them).
    let bytes = fixture("panic_bss.parquet");
    assert_eq!(bytes[1569], 0x15, "a page header's first field");
    assert_eq!(bytes[1569 + 575], 0x15, "the next page header");
    for e in refusals(Format::Parquet, "panic_bss.parquet", &bytes) {
        match &e {
            ReadError::Invalid {
                channel: Some(channel),
                offset: 1569,
                what,
                ..
            } if channel == "z" && what.contains("row group 0 (575 bytes)") => {}
            _ => panic!("{e}"),
        }
    }
}

/// `PAR1`, `footer`, its length and `PAR1`: a Parquet file with no data.
fn parquet_with_footer(footer: &[u8]) -> Vec<u8> {
    let mut b = b"PAR1".to_vec();
    b.extend_from_slice(footer);
    b.extend_from_slice(&(footer.len() as u32).to_le_bytes());
    b.extend_from_slice(b"PAR1");
    b
}

/// The refusals of `bytes` as the file `name`, read from memory and from disk.
fn refusals(format: Format, name: &str, bytes: &[u8]) -> [ReadError; 2] {
    let tmp = tempfile::tempdir().unwrap();
    let path = tmp.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    [
        read_bytes(format, name, bytes).unwrap_err(),
        rotorid_io::read_table(&path).unwrap_err(),
    ]
}

fn assert_footer_refused(name: &str, bytes: &[u8], offset: u64) {
    for e in refusals(Format::Parquet, name, bytes) {
        match &e {
            ReadError::Invalid {
                what, offset: at, ..
            } if what == "Parquet footer" => assert_eq!(*at, offset, "{e}"),
            _ => panic!("{name}: {e}"),
        }
    }
}

#[test]
fn parquet_footers_the_parquet_crate_would_spin_on_are_refused_first() {
    // An unknown field (id 15) holding a list of 2^31 - 1 booleans: the crate steps over
    // it reading no byte per element, 2^31 empty iterations (seconds) before its own error.
    let list = [0xF9, 0xF1, 0xFF, 0xFF, 0xFF, 0xFF, 0x07, 0x00];
    assert_footer_refused("list.parquet", &parquet_with_footer(&list), 4 + 7);
    // the same count of boolean pairs in a map
    let map = [0xFB, 0xFF, 0xFF, 0xFF, 0xFF, 0x07, 0x11, 0x00];
    assert_footer_refused("map.parquet", &parquet_with_footer(&map), 4 + 7);
    // Found by fuzzing read_parquet: 488 bytes that took the crate 3 s in a release build.
    let found = fixture("spin_footer.parquet");
    assert_footer_refused("spin_footer.parquet", &found, 133);
    // Found by fuzzing after that: a known field of another type than its declared one
    // (the crate reads it as declared and then the following bytes out of step, into such
    // a list); 3.8 s in a release build.
    let found = fixture("spin_footer_typed.parquet");
    assert_footer_refused("spin_footer_typed.parquet", &found, 33);
    // The same out-of-step reading, hand-made: FileMetaData's field 1 (version, an i32)
    // given as a binary whose bytes hold an unknown field with a list of 2^31 - 1
    // booleans; the crate reads the length byte as the i32 and then that list.
    let typed = [
        0x18, 0x08, 0xF9, 0xF1, 0xFF, 0xFF, 0xFF, 0xFF, 0x07, 0x00, 0x00,
    ];
    assert_footer_refused("typed.parquet", &parquet_with_footer(&typed), 4 + 1);
}

/// Thrift compact's varint of the zigzag of `v`.
fn zigzag_varint(v: i64) -> Vec<u8> {
    let mut z = ((v << 1) ^ (v >> 63)) as u64;
    let mut out = Vec::new();
    loop {
        let b = (z & 0x7F) as u8;
        z >>= 7;
        if z == 0 {
            out.push(b);
            return out;
        }
        out.push(b | 0x80);
    }
}

#[test]
fn a_parquet_footer_claiming_more_rows_than_the_file_can_hold_is_named_at_the_footer() {
    // FileMetaData { version 1, schema [root "schema" of 0 children], num_rows N,
    // row_groups [RowGroup { columns [], total_byte_size 0, num_rows N }] }, N = 10^12:
    // a well-formed footer whose row count is beyond 1032 times the file's size
    let n = zigzag_varint(1_000_000_000_000);
    let mut footer = vec![0x15, 0x02, 0x19, 0x1C, 0x48, 6];
    footer.extend_from_slice(b"schema");
    footer.extend_from_slice(&[0x15, 0x00, 0x00, 0x16]);
    footer.extend_from_slice(&n);
    footer.extend_from_slice(&[0x19, 0x1C, 0x19, 0x0C, 0x16, 0x00, 0x16]);
    footer.extend_from_slice(&n);
    footer.extend_from_slice(&[0x00, 0x00]);
    let bytes = parquet_with_footer(&footer);
    for e in refusals(Format::Parquet, "rows.parquet", &bytes) {
        match &e {
            ReadError::Invalid {
                what,
                offset,
                found,
                ..
            } if what.starts_with("Parquet footer row count") => {
                // the footer starts right after the leading magic
                assert_eq!((*offset, found.as_str()), (4, "1000000000000"), "{e}");
            }
            _ => panic!("{e}"),
        }
    }
}

#[test]
fn skipped_variables_are_listed_when_nothing_is_left() {
    // The header and the variables M (a matrix), c (complex) and note (char) of rec_v5.mat:
    // NoChannels lists them.
    let b = fixture("rec_v5.mat");
    let (mut pos, mut elements) = (128, vec![]);
    while pos < b.len() {
        let n = u32::from_le_bytes(b[pos + 4..pos + 8].try_into().unwrap()) as usize;
        elements.push(pos..pos + 8 + n.div_ceil(8) * 8);
        pos += 8 + n.div_ceil(8) * 8;
    }
    let mut m = b[..128].to_vec();
    for k in 6..9 {
        m.extend(&b[elements[k].clone()]);
    }
    let e = read_bytes(Format::Mat, "m.mat", &m).unwrap_err();
    let msg = e.to_string();
    assert!(matches!(e, ReadError::NoChannels { .. }), "{msg}");
    assert!(
        msg.contains("M: a 3x4 double matrix")
            && msg.contains("c: a complex 256x1 double")
            && msg.contains("note: a 1x21 char"),
        "{msg}"
    );
}

#[test]
fn non_finite_samples_pass_through() {
    let t = read_bytes(Format::Npy, "sine.npy", &fixture("sine.npy")).unwrap();
    let d = &t.channels[0].data;
    assert!(d[5].is_nan() && d[6] == f64::INFINITY && d[7] == f64::NEG_INFINITY);
}

#[test]
fn an_npy_without_columns_has_no_channels() {
    // Found by the read_npy fuzz target: shape (0, 0) made an Ok table with no channel.
    let b = npy(
        "{'descr': '<f8', 'fortran_order': False, 'shape': (0, 0), }",
        &[],
    );
    let e = read_bytes(Format::Npy, "empty.npy", &b).unwrap_err();
    assert!(matches!(e, ReadError::NoChannels { .. }), "{e}");
}

#[test]
fn a_uff_point_count_near_u64_max_is_truncated_not_an_overflow() {
    // Found by the read_uff fuzz target: 2 * npts overflowed in the truncation message.
    let mut b = fixture("rec.uff");
    let i = b.windows(10).position(|w| w == b"       256").unwrap();
    b[i..i + 10].copy_from_slice(b"    1.8e19");
    let e = read_bytes(Format::Uff58, "rec.uff", &b).unwrap_err();
    assert!(
        matches!(e, ReadError::Truncated { need: u64::MAX, .. }),
        "{e}"
    );
}

#[test]
fn an_empty_npy_cannot_claim_endless_columns() {
    // Found by the read_npy fuzz target: shape (0, 2.7e17) has no data but made as many
    // empty channels, until the memory ran out.
    let b = npy(
        "{'descr': '<i4', 'fortran_order': False, 'shape': (0, 266666666666666606), }",
        &[],
    );
    let e = read_bytes(Format::Npy, "wide.npy", &b).unwrap_err();
    assert!(e.to_string().contains("at most 128 columns"), "{e}");
    let b = npy(
        "{'descr': '<i4', 'fortran_order': False, 'shape': (0, 3), }",
        &[],
    );
    let t = read_bytes(Format::Npy, "three.npy", &b).unwrap();
    assert_eq!(t.channels.len(), 3);
}

/// A stored NPZ member is read without the zip crate's reader; its CRC-32 is still checked,
/// from bytes and from disk alike, and the refusal names the member and the data's offset.
#[test]
fn a_stored_npz_member_that_fails_its_crc_is_refused() {
    let good = fixture("rec.npz");
    // x.npy's local header is at 2231; its data start after the 30-byte header, the name and
    // the 20-byte zip64 extra field numpy writes
    let mut bad = good.clone();
    let data = 2231 + 30 + "x.npy".len() + 20;
    let at = data + 200;
    bad[at] ^= 0x40;
    for e in refusals(Format::Npz, "bad.npz", &bad) {
        let msg = e.to_string();
        assert!(msg.contains("CRC-32"), "{msg}");
        assert!(msg.contains("channel \"x\""), "{msg}");
        assert!(msg.contains(&format!("at byte {data} ")), "{msg}");
    }
    assert!(read_bytes(Format::Npz, "good.npz", &good).is_ok());
}

/// A stored NPZ member whose central directory declares fewer uncompressed bytes than it
/// stores is refused (it is not read short), from bytes and from disk.
#[test]
fn a_stored_npz_member_with_disagreeing_sizes_is_refused() {
    let mut bad = fixture("rec.npz");
    // x.npy's central directory entry is at 7955; its uncompressed size at +24
    assert_eq!(&bad[7955 + 46..7955 + 51], b"x.npy");
    bad[7955 + 24..7955 + 28].copy_from_slice(&2000u32.to_le_bytes());
    // ... and a CRC-32 that fits the first 2000 stored bytes (data at 2231 + 30 + 5 + 20),
    // so that only the sizes' disagreement can refuse it
    let crc = crc32fast::hash(&bad[2286..2286 + 2000]);
    bad[7955 + 16..7955 + 20].copy_from_slice(&crc.to_le_bytes());
    for e in refusals(Format::Npz, "bad.npz", &bad) {
        let msg = e.to_string();
        assert!(msg.contains("channel \"x\""), "{msg}");
        assert!(msg.contains("inflated size"), "{msg}");
        assert!(msg.contains("the declared 2000"), "{msg}");
    }
}
