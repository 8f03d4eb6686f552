//! NI LabVIEW TDMS files (`.tdms`), versions 4712 and 4713.
//!
//! Layout, after NI's "TDMS File Format Internal Structure" (white paper 5696): a file is a
//! run of segments. Each begins with a 28-byte lead-in: the tag `TDSm`, a `u32` table of
//! contents (always little endian; `kTocMetaData` 0x02, `kTocNewObjList` 0x04,
//! `kTocRawData` 0x08, `kTocInterleavedData` 0x20, `kTocBigEndian` 0x40, `kTocDAQmxRawData`
//! 0x80), the version, the offset of the next segment and of the raw data, both counted
//! from the end of the lead-in (`0xFFFF_FFFF_FFFF_FFFF`: a last segment whose writer
//! stopped; it runs to the end of the file). Then the metadata: the object count, and per
//! object its path (`/'group'/'channel'`, quotes doubled inside names), its raw data index
//! (`0xFFFF_FFFF` none, `0` as in the previous segment, else its length followed by the
//! data type, the dimension 1, the value count, and for strings the byte size) and its
//! properties (name, type, value). Then the raw data: one or more chunks, each holding
//! every channel of the segment's object list in order, contiguous (channel after channel)
//! or interleaved (value by value). Without `kTocMetaData` a segment reuses the previous
//! object list; without `kTocNewObjList` its objects update that list.
//!
//! Channels are named `group/channel` (a channel's short name resolves when it is unique,
//! see [`crate::Table::channel`]); numbers are in the segment's byte order. The unit is the
//! `unit_string` property; the time axis is `wf_start_offset` (default 0 s) and
//! `wf_increment` \[s\] when the latter is present. Numeric types (`i8`..`u64`, `f32`,
//! `f64`, and their "with unit" variants) are read; string, boolean, timestamp, complex and
//! extended-float channels are skipped (their bytes are stepped over). DAQmx raw data
//! (scaled from raw integers by the DAQmx scaler properties) is refused: convert the file
//! in LabVIEW or npTDMS first. A truncated segment, a chunk that does not divide the raw
//! data, or interleaved channels of unequal counts are errors naming the byte offset.

use std::collections::HashMap;

use crate::cursor::Cursor;
use crate::error::ReadError;
use crate::format::Source;
use crate::num::{Dtype, Endian};
use crate::table::{Channel, Table, TimeAxis};

const TOC_META: u32 = 0x02;
const TOC_NEW_LIST: u32 = 0x04;
const TOC_RAW: u32 = 0x08;
const TOC_INTERLEAVED: u32 = 0x20;
const TOC_BIG_ENDIAN: u32 = 0x40;
const TOC_DAQMX: u32 = 0x80;
const LEAD_IN: u64 = 28;

/// How a channel's values are stored in a segment.
#[derive(Debug, Clone, Copy)]
struct RawIndex {
    /// `None` for types that are stepped over (strings, timestamps, ...).
    dtype: Option<Dtype>,
    /// Bytes per value (0 for strings, whose `bytes` is given).
    size: u64,
    count: u64,
    /// Bytes per chunk.
    bytes: u64,
}

#[derive(Default)]
struct Object {
    path: Vec<String>,
    unit: Option<String>,
    start: Option<f64>,
    increment: Option<f64>,
    numeric: bool,
    last: Option<RawIndex>,
    data: Vec<f64>,
}

impl Object {
    /// `group/channel`, as messages name the object.
    fn name(&self) -> String {
        self.path.join("/")
    }
}

/// Reads a TDMS file's bytes; `file` names it in messages.
pub fn read(file: &str, bytes: &[u8]) -> Result<Table, ReadError> {
    read_from(file, bytes)
}

/// Reads the TDMS file at `path` segment by segment: its lead-in, its metadata, then its
/// raw data a block of at most `BLOCK` (256 KiB) bytes at a time, each channel's samples appended
/// as they are read; memory holds the channels, one segment's metadata and one block,
/// never the whole file. Accepts and refuses what [`read`] does, with the same messages.
pub fn read_file(file: &str, path: &std::path::Path) -> Result<Table, ReadError> {
    let disk = crate::format::DiskFile::open(file, path)?;
    read_from(file, &disk)
}

/// Bytes of raw data decoded at a time (one block of one channel, or of interleaved rows).
const BLOCK: u64 = 1 << 18;

/// Reads the segments of `src`, in memory or on disk; every length is checked against
/// the bytes the file has left before anything of that length is read.
fn read_from<S: Source + ?Sized>(file: &str, src: &S) -> Result<Table, ReadError> {
    let size = src.size();
    let mut objects: Vec<Object> = Vec::new();
    let mut by_path: HashMap<String, usize> = HashMap::new();
    // The object list of the current segment: object, and its raw index there.
    let mut list: Vec<(usize, Option<RawIndex>)> = Vec::new();
    let mut seg = 0u64;
    while seg < size {
        // The lead-in, or what the file has of it (the cursor refuses a short one).
        let head = src.read_at(seg, LEAD_IN.min(size - seg))?;
        let mut c = Cursor {
            base: seg,
            ..Cursor::new(file, &head)
        };
        let tag = c.take(4, "TDMS segment tag")?;
        if tag != b"TDSm" {
            return Err(c.invalid_at(
                0,
                "TDMS segment tag",
                format!("{tag:?}"),
                "\"TDSm\" (a .tdms_index file is not read)",
            ));
        }
        let toc = c.u32(Endian::Little, "TDMS table of contents")?;
        let e = if toc & TOC_BIG_ENDIAN != 0 {
            Endian::Big
        } else {
            Endian::Little
        };
        let version = c.u32(e, "TDMS version")?;
        if version != 4712 && version != 4713 {
            return Err(c.invalid_at(8, "TDMS version", version, "4712 or 4713"));
        }
        let next = c.u64(e, "TDMS next segment offset")?;
        let raw = c.u64(e, "TDMS raw data offset")?;
        let lead_end = seg + LEAD_IN;
        let left = size - lead_end;
        let seg_len = if next == u64::MAX { left } else { next };
        if seg_len > left {
            return Err(ReadError::Truncated {
                file: file.to_string(),
                channel: None,
                offset: seg,
                what: "TDMS segment".into(),
                need: seg_len.saturating_add(LEAD_IN),
                available: left + LEAD_IN,
            });
        }
        if raw > seg_len {
            return Err(c.invalid_at(
                20,
                "TDMS raw data offset",
                raw,
                format!("at most the segment's {seg_len} bytes"),
            ));
        }
        if toc & TOC_DAQMX != 0 {
            return Err(c.invalid_at(
                4,
                "TDMS table of contents",
                format!("{toc:#x} (DAQmx raw data)"),
                "segments without kTocDAQmxRawData: DAQmx raw data is not read",
            ));
        }
        let seg_end = lead_end + seg_len;
        let raw_start = lead_end + raw;
        if toc & TOC_META != 0 {
            if toc & TOC_NEW_LIST != 0 {
                list.clear();
            }
            let meta = src.read_at(lead_end, raw)?;
            let mut m = Cursor {
                base: lead_end,
                ..Cursor::new(file, &meta)
            };
            metadata(&mut m, e, &mut objects, &mut by_path, &mut list)?;
        }
        if toc & TOC_RAW != 0 {
            let raw = Raw {
                file,
                start: raw_start,
                end: seg_end,
                e,
            };
            raw_data(src, &raw, toc & TOC_INTERLEAVED != 0, &mut objects, &list)?;
        }
        seg = seg_end;
    }
    let mut channels = Vec::new();
    for o in objects {
        if o.path.len() != 2 || !o.numeric {
            continue;
        }
        let name = o.name();
        let axis = match o.increment {
            None => None,
            Some(inc) if inc > 0.0 && inc.is_finite() => Some(TimeAxis {
                start: o.start.unwrap_or(0.0),
                increment: inc,
            }),
            Some(inc) => {
                return Err(ReadError::Invalid {
                    file: file.to_string(),
                    channel: Some(name),
                    offset: 0,
                    what: "TDMS property wf_increment".into(),
                    found: inc.to_string(),
                    allowed: "a positive finite number of seconds".into(),
                })
            }
        };
        channels.push(Channel {
            name,
            unit: o.unit,
            data: o.data,
            axis,
        });
    }
    if channels.is_empty() {
        return Err(ReadError::NoChannels {
            file: file.to_string(),
            why: "no numeric group/channel object".into(),
        });
    }
    Ok(Table {
        file: file.to_string(),
        channels,
    })
}

fn string<'a>(c: &mut Cursor<'a>, e: Endian, what: &str) -> Result<&'a str, ReadError> {
    let n = c.u32(e, what)?;
    c.utf8(n as u64, what)
}

/// Splits `/'group'/'channel'` into its names.
fn split_path(p: &str) -> Option<Vec<String>> {
    if p == "/" {
        return Some(vec![]);
    }
    let mut out = Vec::new();
    let mut rest = p;
    while !rest.is_empty() {
        rest = rest.strip_prefix("/'")?;
        let mut name = String::new();
        loop {
            let q = rest.find('\'')?;
            name.push_str(&rest[..q]);
            rest = &rest[q + 1..];
            match rest.strip_prefix('\'') {
                Some(r) => {
                    name.push('\'');
                    rest = r;
                }
                None => break,
            }
        }
        out.push(name);
    }
    Some(out)
}

/// The element type of a TDMS data type code, and its size; `None` dtype for types that
/// are stepped over; `Err` for unknown codes.
fn data_type(t: u32) -> Result<(Option<Dtype>, u64), ()> {
    Ok(match t {
        1 => (Some(Dtype::I8), 1),
        2 => (Some(Dtype::I16), 2),
        3 => (Some(Dtype::I32), 4),
        4 => (Some(Dtype::I64), 8),
        5 => (Some(Dtype::U8), 1),
        6 => (Some(Dtype::U16), 2),
        7 => (Some(Dtype::U32), 4),
        8 => (Some(Dtype::U64), 8),
        9 | 0x19 => (Some(Dtype::F32), 4),
        10 | 0x1A => (Some(Dtype::F64), 8),
        11 | 0x1B => (None, 16),
        0x20 => (None, 0),
        0x21 => (None, 1),
        0x44 => (None, 16),
        0x08_000c => (None, 8),
        0x10_000d => (None, 16),
        _ => return Err(()),
    })
}

const TYPES: &str = "1-10 (integers, f32, f64), 11, 0x19-0x1B, 0x20 (string), 0x21 (bool), 0x44 (timestamp), 0x08000c, 0x10000d (complex)";

fn metadata(
    c: &mut Cursor,
    e: Endian,
    objects: &mut Vec<Object>,
    by_path: &mut HashMap<String, usize>,
    list: &mut Vec<(usize, Option<RawIndex>)>,
) -> Result<(), ReadError> {
    let n = c.u32(e, "TDMS object count")?;
    for _ in 0..n {
        c.channel = None;
        let at = c.pos;
        let path = string(c, e, "TDMS object path")?;
        let names = split_path(path).ok_or_else(|| {
            c.invalid_at(
                at,
                "TDMS object path",
                format!("{path:?}"),
                "/'group'/'channel' with quotes doubled",
            )
        })?;
        if names.len() == 2 {
            c.channel = Some(format!("{}/{}", names[0], names[1]));
        }
        let k = match by_path.get(path) {
            Some(&k) => k,
            None => {
                objects.push(Object {
                    path: names,
                    ..Object::default()
                });
                by_path.insert(path.to_string(), objects.len() - 1);
                objects.len() - 1
            }
        };
        let iat = c.pos;
        let index_len = c.u32(e, "TDMS raw data index")?;
        let index = match index_len {
            0xFFFF_FFFF => None,
            0 => Some(objects[k].last.ok_or_else(|| {
                c.invalid_at(
                    iat,
                    "TDMS raw data index",
                    "0 (as in the previous segment)",
                    "a full index the first time an object has data",
                )
            })?),
            0x6912_0000..=0x6913_FFFF => {
                return Err(c.invalid_at(
                    iat,
                    "TDMS raw data index",
                    format!("{index_len:#x} (DAQmx raw data)"),
                    "a plain raw data index: DAQmx raw data is not read",
                ))
            }
            len => {
                let tat = c.pos;
                let t = c.u32(e, "TDMS data type")?;
                let (dtype, size) = data_type(t)
                    .map_err(|_| c.invalid_at(tat, "TDMS data type", format!("{t:#x}"), TYPES))?;
                let dim = c.u32(e, "TDMS array dimension")?;
                if dim != 1 {
                    return Err(c.invalid_at(tat + 4, "TDMS array dimension", dim, "1"));
                }
                let count = c.u64(e, "TDMS value count")?;
                let bytes = if t == 0x20 {
                    c.u64(e, "TDMS string data size")?
                } else {
                    count.checked_mul(size).ok_or_else(|| {
                        c.invalid_at(
                            tat + 8,
                            "TDMS value count",
                            count,
                            "a count whose bytes fit in 64 bits",
                        )
                    })?
                };
                // The length counts its own four bytes.
                let used = (c.pos - iat) as u64;
                if (len as u64) < used {
                    return Err(c.invalid_at(
                        iat,
                        "TDMS raw data index length",
                        len,
                        format!("at least the {used} bytes of its fields"),
                    ));
                }
                c.skip(len as u64 - used, "TDMS raw data index")?;
                if dtype.is_some() {
                    objects[k].numeric = true;
                }
                Some(RawIndex {
                    dtype,
                    size,
                    count,
                    bytes,
                })
            }
        };
        if index.is_some() {
            objects[k].last = index;
        }
        match list.iter_mut().find(|(o, _)| *o == k) {
            Some(entry) => entry.1 = index,
            None => list.push((k, index)),
        }
        let np = c.u32(e, "TDMS property count")?;
        for _ in 0..np {
            let name = string(c, e, "TDMS property name")?;
            let tat = c.pos;
            let t = c.u32(e, "TDMS property type")?;
            let o = &mut objects[k];
            match t {
                0x20 => {
                    let v = string(c, e, "TDMS property value")?;
                    if name == "unit_string" {
                        o.unit = (!v.trim().is_empty()).then(|| v.trim().to_string());
                    }
                }
                _ => {
                    let (dtype, size) = data_type(t).map_err(|_| {
                        c.invalid_at(tat, "TDMS property type", format!("{t:#x}"), TYPES)
                    })?;
                    let vat = c.pos;
                    c.skip(size, "TDMS property value")?;
                    if let (Some(d), "wf_increment" | "wf_start_offset") = (dtype, name) {
                        let ch = c.channel.clone().unwrap_or_default();
                        let v = c.samples(vat, 1, size, d, e, &ch)?[0];
                        if name == "wf_increment" {
                            o.increment = Some(v);
                        } else {
                            o.start = Some(v);
                        }
                    }
                }
            }
        }
    }
    c.channel = None;
    Ok(())
}

/// Where a segment's raw data lies: file offsets `[start, end)`, byte order `e`.
struct Raw<'a> {
    file: &'a str,
    start: u64,
    end: u64,
    e: Endian,
}

impl Raw<'_> {
    /// `n` values of `t` of `channel` at file offset `at`, one every `stride` bytes, read
    /// from `src`; the values are numbers `first..first + n` of the channel, counted from
    /// its first value in the file over every segment and chunk (as an
    /// [`ReadError::InexactInteger`] names them). The caller keeps them within the raw data.
    /// The values go onto the end of `out`; a block read from disk goes through `scratch`.
    #[allow(clippy::too_many_arguments)]
    fn samples_into<S: Source + ?Sized>(
        &self,
        src: &S,
        at: u64,
        first: u64,
        n: u64,
        stride: u64,
        t: Dtype,
        channel: &str,
        scratch: &mut Vec<u8>,
        out: &mut Vec<f64>,
    ) -> Result<(), ReadError> {
        let len = n.saturating_sub(1) * stride + t.size() as u64;
        let buf = src.read_at_reusing(at, len, scratch)?;
        let c = Cursor {
            base: at,
            ..Cursor::new(self.file, buf)
        };
        c.samples_into(0, n, stride, t, self.e, channel, out)
            .map_err(|err| match err {
                ReadError::InexactInteger {
                    file,
                    channel,
                    index,
                    offset,
                    value,
                } => ReadError::InexactInteger {
                    file,
                    channel,
                    index: index + first as usize,
                    offset,
                    value,
                },
                other => other,
            })
    }
}

/// Reads the raw data `r` of a segment with object list `list` into the objects' data, a
/// block of at most [`BLOCK`] bytes at a time, in the order (and so with the first error)
/// of reading each chunk channel after channel.
fn raw_data<S: Source + ?Sized>(
    src: &S,
    r: &Raw,
    interleaved: bool,
    objects: &mut [Object],
    list: &[(usize, Option<RawIndex>)],
) -> Result<(), ReadError> {
    // errors about the whole raw data name its first byte
    let c = Cursor {
        base: r.start,
        ..Cursor::new(r.file, &[])
    };
    let present: Vec<(usize, RawIndex)> = list
        .iter()
        .filter_map(|&(k, i)| i.map(|i| (k, i)))
        .filter(|(_, i)| i.bytes > 0)
        .collect();
    let region = r.end - r.start;
    let Some(chunk) = present
        .iter()
        .try_fold(0u64, |a, (_, i)| a.checked_add(i.bytes))
    else {
        return Err(c.invalid(
            "TDMS chunk size",
            "beyond 64 bits",
            format!("at most the raw data's {region} bytes"),
        ));
    };
    if chunk == 0 || region == 0 {
        return Ok(());
    }
    if !region.is_multiple_of(chunk) {
        return Err(c.invalid(
            "TDMS raw data size",
            format!("{region} bytes"),
            format!("a multiple of the {chunk}-byte chunk its object list describes"),
        ));
    }
    let chunks = region / chunk;
    if interleaved {
        return interleaved_data(src, r, &c, &present, chunk, chunks, objects);
    }
    // Every value of a numeric channel lies in the raw data, so this is at most a value
    // per raw byte.
    for &(k, i) in &present {
        if i.dtype.is_some() {
            objects[k]
                .data
                .reserve(i.count.saturating_mul(chunks) as usize);
        }
    }
    let names: Vec<String> = present.iter().map(|&(k, _)| objects[k].name()).collect();
    let mut scratch = Vec::new();
    for n in 0..chunks {
        let mut p = r.start + n * chunk;
        for (&(k, i), ch) in present.iter().zip(&names) {
            if let Some(d) = i.dtype {
                let per = (BLOCK / i.size).max(1);
                let mut first = 0;
                while first < i.count {
                    let m = per.min(i.count - first);
                    let at = p + first * i.size;
                    let data = &mut objects[k].data;
                    let index = data.len() as u64;
                    r.samples_into(src, at, index, m, i.size, d, ch, &mut scratch, data)?;
                    first += m;
                }
            }
            p += i.bytes;
        }
    }
    Ok(())
}

/// Interleaved raw data: rows of one value of every channel. The in-order reading of
/// chunk after chunk, channel after channel, is kept for its errors: the channels before
/// the first of unequal count or variable size are read from the first chunk, and the
/// first channel to fail (a 64-bit integer `f64` cannot hold) is the one reported.
fn interleaved_data<S: Source + ?Sized>(
    src: &S,
    r: &Raw,
    c: &Cursor,
    present: &[(usize, RawIndex)],
    chunk: u64,
    chunks: u64,
    objects: &mut [Object],
) -> Result<(), ReadError> {
    let count = present[0].1.count;
    let row: u64 = present.iter().map(|(_, i)| i.size).sum();
    let bad = present
        .iter()
        .position(|(_, i)| i.count != count || i.size == 0);
    // The columns read: channel, its byte within the row, its type and name.
    let mut cols = Vec::new();
    let mut col = 0;
    for &(k, i) in &present[..bad.unwrap_or(present.len())] {
        if let Some(d) = i.dtype {
            cols.push((k, col, d, objects[k].name()));
        }
        col += i.size;
    }
    let chunks = if bad.is_some() { 1 } else { chunks };
    if bad.is_none() {
        for (k, ..) in &cols {
            objects[*k]
                .data
                .reserve(count.saturating_mul(chunks) as usize);
        }
    }
    let per = (BLOCK / row.max(1)).max(1);
    let mut scratch = Vec::new();
    for n in 0..chunks {
        let base = r.start + n * chunk;
        // The first failing column of this chunk, and its error.
        let mut failed: Option<(usize, ReadError)> = None;
        let mut first = 0;
        while first < count {
            let m = per.min(count - first);
            let at = base + first * row;
            for (j, (k, col, d, ch)) in cols.iter().enumerate() {
                if failed.as_ref().is_some_and(|(f, _)| *f <= j) {
                    break;
                }
                let data = &mut objects[*k].data;
                let index = data.len() as u64;
                match r.samples_into(src, at + col, index, m, row, *d, ch, &mut scratch, data) {
                    Ok(()) => {}
                    Err(err @ ReadError::Io { .. }) => return Err(err),
                    Err(err) => {
                        // (keep the channel as it was before this block)
                        data.truncate(index as usize);
                        failed = Some((j, err));
                    }
                }
            }
            first += m;
        }
        if let Some((_, err)) = failed {
            return Err(err);
        }
    }
    if let Some(j) = bad {
        let (k, i) = present[j];
        return Err(c.invalid(
            "TDMS interleaved raw data",
            format!(
                "{} with {} values of {} bytes",
                objects[k].name(),
                i.count,
                i.size
            ),
            format!("every channel with {count} fixed-size values"),
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths() {
        assert_eq!(split_path("/"), Some(vec![]));
        assert_eq!(split_path("/'g'"), Some(vec!["g".to_string()]));
        assert_eq!(
            split_path("/'g'/'probe ''A''/1'"),
            Some(vec!["g".to_string(), "probe 'A'/1".to_string()])
        );
        assert_eq!(split_path("/g"), None);
        assert_eq!(split_path("/'g"), None);
    }

    /// A one-segment file of channels `(name, type code, value count)` whose raw data is
    /// `raw`, little endian.
    fn segment(toc: u32, channels: &[(&str, u32, u64)], raw: &[u8]) -> Vec<u8> {
        let mut meta = Vec::new();
        meta.extend((channels.len() as u32).to_le_bytes());
        for &(name, t, count) in channels {
            let path = format!("/'g'/'{name}'");
            meta.extend((path.len() as u32).to_le_bytes());
            meta.extend(path.as_bytes());
            meta.extend(20u32.to_le_bytes());
            meta.extend(t.to_le_bytes());
            meta.extend(1u32.to_le_bytes());
            meta.extend(count.to_le_bytes());
            meta.extend(0u32.to_le_bytes());
        }
        let mut f = b"TDSm".to_vec();
        f.extend((toc | TOC_META | TOC_NEW_LIST | TOC_RAW).to_le_bytes());
        f.extend(4713u32.to_le_bytes());
        f.extend(((meta.len() + raw.len()) as u64).to_le_bytes());
        f.extend((meta.len() as u64).to_le_bytes());
        f.extend(meta);
        f.extend(raw);
        f
    }

    /// Reads `bytes` in memory and from disk, which must agree.
    fn both(bytes: &[u8]) -> Result<Table, ReadError> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.tdms");
        std::fs::write(&path, bytes).unwrap();
        let mem = read("x.tdms", bytes);
        let disk = read_file("x.tdms", &path);
        assert_eq!(format!("{mem:?}"), format!("{disk:?}"));
        mem
    }

    #[test]
    fn channels_longer_than_a_block_are_read_whole_and_errors_count_from_the_channel_start() {
        // two chunks of an f64 channel of 40 000 values and an i64 channel of 100 000
        let (na, nb) = (40_000u64, 100_000u64);
        let mut raw = Vec::new();
        for chunk in 0..2u64 {
            for k in 0..na {
                raw.extend(((chunk * na + k) as f64 * 0.5).to_le_bytes());
            }
            for k in 0..nb {
                raw.extend(((chunk * nb + k) as i64 - 7).to_le_bytes());
            }
        }
        let ch = [("a", 10, na), ("b", 4, nb)];
        let t = both(&segment(0, &ch, &raw)).unwrap();
        let a: Vec<f64> = (0..2 * na).map(|k| k as f64 * 0.5).collect();
        let b: Vec<f64> = (0..2 * nb).map(|k| k as f64 - 7.0).collect();
        assert_eq!(t.channels[0].data, a);
        assert_eq!(t.channels[1].data, b);
        // an i64 f64 cannot hold, 70 000 values into the second chunk's b: value
        // nb + 70 000 of channel b, as npTDMS's channel[i] numbers it
        let at = (2 * na + nb + 70_000) as usize * 8;
        raw[at..at + 8].copy_from_slice(&((1i64 << 60) + 1).to_le_bytes());
        let f = segment(0, &ch, &raw);
        let raw_start = (f.len() - raw.len()) as u64;
        match both(&f) {
            Err(ReadError::InexactInteger { index, offset, .. }) => {
                assert_eq!(index, (nb + 70_000) as usize);
                assert_eq!(offset, raw_start + at as u64);
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn interleaved_rows_longer_than_a_block_are_read_whole() {
        // an i32 and an i64 channel of 100 000 values each, value by value
        let n = 100_000u64;
        let mut raw = Vec::new();
        for k in 0..n {
            raw.extend((k as i32 * 3).to_le_bytes());
            raw.extend((k as i64 - 5).to_le_bytes());
        }
        let ch = [("a", 3, n), ("b", 4, n)];
        let t = both(&segment(TOC_INTERLEAVED, &ch, &raw)).unwrap();
        let a: Vec<f64> = (0..n).map(|k| (k * 3) as f64).collect();
        let b: Vec<f64> = (0..n).map(|k| k as f64 - 5.0).collect();
        assert_eq!(t.channels[0].data, a);
        assert_eq!(t.channels[1].data, b);
        // b's value 90 000 is an i64 f64 cannot hold, and later a's 95 000 too: the
        // first channel's is reported, as reading channel after channel would
        let at_b = 90_000 * 12 + 4;
        raw[at_b..at_b + 8].copy_from_slice(&((1i64 << 60) + 1).to_le_bytes());
        let f = segment(TOC_INTERLEAVED, &[("a", 4, n), ("b", 4, n)], &{
            let mut r = Vec::new();
            for k in 0..n as usize {
                let a = if k == 95_000 { (1i64 << 60) + 3 } else { 0 };
                r.extend(a.to_le_bytes());
                r.extend_from_slice(&raw[k * 12 + 4..k * 12 + 12]);
            }
            r
        });
        match both(&f) {
            Err(ReadError::InexactInteger { channel, index, .. }) => {
                assert_eq!((channel.as_str(), index), ("g/a", 95_000));
            }
            other => panic!("{other:?}"),
        }
        // two chunks of rows, b's value 20 000 of the second chunk bad: value n + 20 000 of
        // channel b
        let mut two = raw[..n as usize * 12].to_vec();
        two.extend_from_slice(&raw[..n as usize * 12]);
        let at = (n as usize + 20_000) * 12 + 4;
        two[at..at + 8].copy_from_slice(&((1i64 << 60) + 1).to_le_bytes());
        // (raw holds the bad b value 90 000 from above: made good again in the first chunk)
        two[at_b..at_b + 8].copy_from_slice(&(90_000i64 - 5).to_le_bytes());
        let f = segment(TOC_INTERLEAVED, &ch, &two);
        match both(&f) {
            Err(ReadError::InexactInteger { channel, index, .. }) => {
                assert_eq!((channel.as_str(), index), ("g/b", n as usize + 20_000));
            }
            other => panic!("{other:?}"),
        }
    }
}
