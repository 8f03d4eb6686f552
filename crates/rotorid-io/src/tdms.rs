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

/// Reads a TDMS file's bytes; `file` names it in messages.
pub fn read(file: &str, bytes: &[u8]) -> Result<Table, ReadError> {
    let mut c = Cursor::new(file, bytes);
    let mut objects: Vec<Object> = Vec::new();
    let mut by_path: HashMap<String, usize> = HashMap::new();
    // The object list of the current segment: object, and its raw index there.
    let mut list: Vec<(usize, Option<RawIndex>)> = Vec::new();
    while !c.at_end() {
        let seg = c.pos;
        let tag = c.take(4, "TDMS segment tag")?;
        if tag != b"TDSm" {
            return Err(c.invalid_at(
                seg,
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
            return Err(c.invalid_at(seg + 8, "TDMS version", version, "4712 or 4713"));
        }
        let next = c.u64(e, "TDMS next segment offset")?;
        let raw = c.u64(e, "TDMS raw data offset")?;
        let lead_end = c.pos;
        let left = c.remaining() as u64;
        let seg_len = if next == u64::MAX { left } else { next };
        if seg_len > left {
            return Err(ReadError::Truncated {
                file: file.to_string(),
                channel: None,
                offset: seg as u64,
                what: "TDMS segment".into(),
                need: seg_len.saturating_add(LEAD_IN),
                available: left + LEAD_IN,
            });
        }
        if raw > seg_len {
            return Err(c.invalid_at(
                seg + 20,
                "TDMS raw data offset",
                raw,
                format!("at most the segment's {seg_len} bytes"),
            ));
        }
        if toc & TOC_DAQMX != 0 {
            return Err(c.invalid_at(
                seg + 4,
                "TDMS table of contents",
                format!("{toc:#x} (DAQmx raw data)"),
                "segments without kTocDAQmxRawData: DAQmx raw data is not read",
            ));
        }
        let seg_end = lead_end + seg_len as usize;
        let raw_start = lead_end + raw as usize;
        if toc & TOC_META != 0 {
            if toc & TOC_NEW_LIST != 0 {
                list.clear();
            }
            let mut m = Cursor {
                data: &bytes[..raw_start],
                pos: lead_end,
                ..c.clone()
            };
            metadata(&mut m, e, &mut objects, &mut by_path, &mut list)?;
        }
        if toc & TOC_RAW != 0 {
            let r = Cursor {
                data: &bytes[..seg_end],
                pos: raw_start,
                ..c.clone()
            };
            raw_data(&r, e, toc & TOC_INTERLEAVED != 0, &mut objects, &list)?;
        }
        c.pos = seg_end;
    }
    let mut channels = Vec::new();
    for o in objects {
        if o.path.len() != 2 || !o.numeric {
            continue;
        }
        let name = format!("{}/{}", o.path[0], o.path[1]);
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

fn raw_data(
    c: &Cursor,
    e: Endian,
    interleaved: bool,
    objects: &mut [Object],
    list: &[(usize, Option<RawIndex>)],
) -> Result<(), ReadError> {
    let present: Vec<(usize, RawIndex)> = list
        .iter()
        .filter_map(|&(k, i)| i.map(|i| (k, i)))
        .filter(|(_, i)| i.bytes > 0)
        .collect();
    let region = c.remaining() as u64;
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
    let name = |objects: &[Object], k: usize| objects[k].path.join("/");
    let mut pos = c.pos;
    for _ in 0..chunks {
        if interleaved {
            let count = present[0].1.count;
            let row: u64 = present.iter().map(|(_, i)| i.size).sum();
            let mut col = 0;
            for &(k, i) in &present {
                if i.count != count || i.size == 0 {
                    return Err(c.invalid(
                        "TDMS interleaved raw data",
                        format!(
                            "{} with {} values of {} bytes",
                            name(objects, k),
                            i.count,
                            i.size
                        ),
                        format!("every channel with {count} fixed-size values"),
                    ));
                }
                if let Some(d) = i.dtype {
                    let v = c.samples(pos + col as usize, count, row, d, e, &name(objects, k))?;
                    objects[k].data.extend(v);
                }
                col += i.size;
            }
        } else {
            let mut p = pos;
            for &(k, i) in &present {
                if let Some(d) = i.dtype {
                    let v = c.samples(p, i.count, i.size, d, e, &name(objects, k))?;
                    objects[k].data.extend(v);
                }
                p += i.bytes as usize;
            }
        }
        pos += chunk as usize;
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
}
