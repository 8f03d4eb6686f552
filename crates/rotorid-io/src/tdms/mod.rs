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
//! extended-float channels are skipped (their bytes are stepped over). DAQmx raw data, as
//! NI-DAQmx logs it, is read (`tdms/daqmx.rs`), and values stored unscaled are scaled by the
//! channel's `NI_Scale` properties, as npTDMS does (`tdms/scaling.rs`; a scale type rotorid does
//! not apply is refused, never returned unscaled). A truncated segment, a chunk that does
//! not divide the raw data, or interleaved channels of unequal counts are errors naming
//! the byte offset; except that a last segment its writer left open (next segment offset
//! all ones: a recording interrupted mid-segment) is read up to its last whole chunk, and
//! [`Table::notes`] says how many bytes of the unfinished one were not read.
//!
//! [`read_file`] reads the whole file; [`open_blocks`] reads it a block of rows at a time
//! ([`stream`]: the segments' metadata first, then each channel asked for from where it
//! stopped, so memory holds a few blocks, never a channel), with the same checks, values
//! and messages.

use std::collections::HashMap;

use crate::cursor::Cursor;
use crate::error::ReadError;
use crate::num::{Dtype, Endian};
use crate::source::Source;
use crate::table::{Channel, Table, TimeAxis};

mod daqmx;
mod scaling;
pub mod stream;

pub use stream::{open_blocks, TdmsBlocks};

use scaling::{Chain, Input, Props, Value};

const TOC_META: u32 = 0x02;
const TOC_NEW_LIST: u32 = 0x04;
const TOC_RAW: u32 = 0x08;
const TOC_INTERLEAVED: u32 = 0x20;
const TOC_BIG_ENDIAN: u32 = 0x40;
const LEAD_IN: u64 = 28;

/// How a channel's values are stored in a segment.
#[derive(Debug, Clone, Copy)]
struct RawIndex {
    /// `None` for types that are stepped over (strings, timestamps, ...).
    dtype: Option<Dtype>,
    /// Bytes per value (0 for strings, whose `bytes` is given).
    size: u64,
    count: u64,
    /// Bytes per chunk (0 for DAQmx raw data, whose chunk is laid out by raw buffers).
    bytes: u64,
    /// DAQmx raw data, described by the object's `daqmx` index.
    daqmx: bool,
}

#[derive(Default)]
struct Object {
    path: Vec<String>,
    unit: Option<String>,
    start: Option<f64>,
    /// `wf_increment` \[s\] and the file offset of its value.
    increment: Option<(f64, u64)>,
    numeric: bool,
    last: Option<RawIndex>,
    data: Vec<f64>,
    /// Its scaling properties.
    props: Props,
    /// Its last DAQmx raw data index.
    daqmx: Option<daqmx::Index>,
    /// DAQmx raw data: the values of each scaler, by scale id (the channel's values are
    /// what its scales make of them).
    scaled_from: Vec<(u32, Vec<f64>)>,
    /// Whether any of its DAQmx indexes was DAQmx raw data.
    daqmx_raw: bool,
    /// Byte offset of its last DAQmx index.
    daqmx_at: u64,
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
    let disk = crate::source::DiskFile::open(file, path)?;
    read_from(file, &disk)
}

/// Bytes of raw data decoded at a time (one block of one channel, or of interleaved rows).
const BLOCK: u64 = 1 << 18;

/// A segment's lead-in, checked against the file's size.
struct LeadIn {
    toc: u32,
    e: Endian,
    /// The next segment offset as written (all ones: left open by its writer).
    next: u64,
    /// End of the lead-in, where the metadata starts.
    lead_end: u64,
    /// The raw data offset (the metadata's length).
    raw: u64,
    raw_start: u64,
    seg_end: u64,
}

/// Reads and checks the lead-in of the segment at `seg` (< the file's size).
fn lead_in<S: Source + ?Sized>(file: &str, src: &S, seg: u64) -> Result<LeadIn, ReadError> {
    let size = src.size();
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
    // (kTocDAQmxRawData 0x80 is not relied on: the objects' raw data indexes say
    // whether the data is DAQmx, as some writers leave the flag out)
    let seg_end = lead_end + seg_len;
    Ok(LeadIn {
        toc,
        e,
        next,
        lead_end,
        raw,
        raw_start: lead_end + raw,
        seg_end,
    })
}

/// The objects a pass over the segments has met so far, the current object list, and the
/// notes; what the whole-file reader and the streaming one ([`stream`]) share.
#[derive(Default)]
struct Walk {
    objects: Vec<Object>,
    by_path: HashMap<String, usize>,
    /// The object list of the current segment: object, and its raw index there.
    list: Vec<(usize, Option<RawIndex>)>,
    notes: Vec<String>,
}

impl Walk {
    /// The segment at `seg` (< the file's size): its lead-in and metadata read and checked
    /// (the objects updated), and the layout of its raw data (checked, not read). Returns
    /// where the next segment starts.
    fn segment<'f, S: Source + ?Sized>(
        &mut self,
        file: &'f str,
        src: &S,
        seg: u64,
    ) -> Result<(u64, Option<(Raw<'f>, Layout)>), ReadError> {
        let h = lead_in(file, src, seg)?;
        if h.toc & TOC_META != 0 {
            if h.toc & TOC_NEW_LIST != 0 {
                self.list.clear();
            }
            let meta = src.read_at(h.lead_end, h.raw)?;
            let mut m = Cursor {
                base: h.lead_end,
                ..Cursor::new(file, &meta)
            };
            metadata(
                &mut m,
                h.e,
                &mut self.objects,
                &mut self.by_path,
                &mut self.list,
            )?;
        }
        if h.toc & TOC_RAW == 0 {
            return Ok((h.seg_end, None));
        }
        let raw = Raw {
            file,
            start: h.raw_start,
            end: h.seg_end,
            size: src.size(),
            e: h.e,
            open: h.next == u64::MAX,
        };
        let interleaved = h.toc & TOC_INTERLEAVED != 0;
        let l = layout(
            &raw,
            interleaved,
            &self.objects,
            &self.list,
            &mut self.notes,
        )?;
        Ok((h.seg_end, l.map(|l| (raw, l))))
    }

    /// The numeric `group/channel` objects, in the order the file introduced them.
    fn channels(&self) -> impl Iterator<Item = usize> + '_ {
        (0..self.objects.len())
            .filter(|&k| self.objects[k].path.len() == 2 && self.objects[k].numeric)
    }

    /// The object of the file (path `/`), whose properties every channel inherits.
    fn root(&self) -> Option<usize> {
        self.objects.iter().position(|o| o.path.is_empty())
    }
}

/// The error when a file has no channel to read.
fn no_channels(file: &str) -> ReadError {
    ReadError::NoChannels {
        file: file.to_string(),
        why: "no numeric group/channel object".into(),
    }
}

/// Reads the segments of `src`, in memory or on disk; every length is checked against
/// the bytes the file has left before anything of that length is read.
fn read_from<S: Source + ?Sized>(file: &str, src: &S) -> Result<Table, ReadError> {
    let size = src.size();
    let mut w = Walk::default();
    let mut seg = 0u64;
    while seg < size {
        let (end, raw) = w.segment(file, src, seg)?;
        if let Some((raw, l)) = raw {
            raw_data(src, &raw, l, &mut w.objects)?;
        }
        seg = end;
    }
    let mut channels = Vec::new();
    let root = w.root();
    let numeric: Vec<usize> = w.channels().collect();
    let objects = &mut w.objects;
    for k in numeric {
        let mut data = scaled(file, objects, k, root)?;
        // (room reserved ahead for segments that did not come: Raw::reserve)
        data.shrink_to_fit();
        let axis = axis(file, &objects[k])?;
        let o = &mut objects[k];
        channels.push(Channel {
            name: o.name(),
            unit: o.unit.take(),
            data,
            axis,
        });
    }
    if channels.is_empty() {
        return Err(no_channels(file));
    }
    Ok(Table {
        file: file.to_string(),
        channels,
        notes: w.notes,
    })
}

/// The time axis of channel `o` (`wf_increment`, `wf_start_offset`), checked.
fn axis(file: &str, o: &Object) -> Result<Option<TimeAxis>, ReadError> {
    match o.increment {
        None => Ok(None),
        Some((inc, _)) if inc > 0.0 && inc.is_finite() => Ok(Some(TimeAxis {
            start: o.start.unwrap_or(0.0),
            increment: inc,
        })),
        Some((inc, at)) => Err(ReadError::Invalid {
            file: file.to_string(),
            channel: Some(o.name()),
            offset: at,
            what: "TDMS property wf_increment".into(),
            found: inc.to_string(),
            allowed: "a positive finite number of seconds".into(),
        }),
    }
}

/// What the values of channel `objects[k]` are made of: its stored values or one of its
/// DAQmx scalers' values, and the scales applied to them (those of its properties, or its
/// group's, or the file's at `root`: [`scaling`]); refused as the reader refuses it.
fn source(
    file: &str,
    objects: &[Object],
    k: usize,
    root: Option<usize>,
) -> Result<(Input, Option<Chain>), ReadError> {
    let o = &objects[k];
    let group = &o.path[0];
    let g = objects
        .iter()
        .position(|o| o.path.len() == 1 && &o.path[0] == group);
    let none = Props::default();
    let level = |i: Option<usize>| i.map_or(&none, |i| &objects[i].props);
    let refused = |r: scaling::Refusal| ReadError::Invalid {
        file: file.to_string(),
        channel: Some(o.name()),
        offset: r.offset,
        what: r.what,
        found: r.found,
        allowed: r.allowed,
    };
    let has = |input: Input| match input {
        Input::Stored => !o.daqmx_raw,
        Input::Scaler(id) => o.scaled_from.iter().any(|(i, _)| *i == id),
    };
    match scaling::scaling([&o.props, level(g), level(root)]).map_err(refused)? {
        Some(s) => {
            let chain = s.chain();
            if !has(chain.input) {
                return Err(refused(chain.missing()));
            }
            Ok((chain.input, Some(chain)))
        }
        None if !o.daqmx_raw => Ok((Input::Stored, None)),
        None => match o.scaled_from.as_slice() {
            [(id, _)] => Ok((Input::Scaler(*id), None)),
            s => Err(ReadError::Invalid {
                file: file.to_string(),
                channel: Some(o.name()),
                offset: o.daqmx_at,
                what: "TDMS DAQmx raw data".into(),
                found: format!(
                    "{} scalers and no NI_Scale properties saying which to read",
                    s.len()
                ),
                allowed: "one scaler, or NI_Scale properties".into(),
            }),
        },
    }
}

/// The values of channel `objects[k]`, taken out of it: its stored values, or what the
/// scaling of its properties (or its group's, or the file's at `root`) makes of them and
/// of its DAQmx scalers' values ([`source`]).
fn scaled(
    file: &str,
    objects: &mut [Object],
    k: usize,
    root: Option<usize>,
) -> Result<Vec<f64>, ReadError> {
    let (input, chain) = source(file, objects, k, root)?;
    let o = &mut objects[k];
    let data = std::mem::take(&mut o.data);
    let mut scalers = std::mem::take(&mut o.scaled_from);
    let mut v = match input {
        Input::Stored => data,
        Input::Scaler(id) => match scalers.iter().position(|(i, _)| *i == id) {
            Some(at) => scalers.swap_remove(at).1,
            // (source found it)
            None => Vec::new(),
        },
    };
    if let Some(c) = chain {
        c.apply_in_place(&mut v);
    }
    Ok(v)
}

/// The values of DAQmx scaler `id` of object `o` read so far (an empty list the first
/// time: a scaler of a segment with raw data has values, if none).
fn scaler_values(o: &mut Object, id: u32) -> &mut Vec<f64> {
    let at = match o.scaled_from.iter().position(|(i, _)| *i == id) {
        Some(at) => at,
        None => {
            o.scaled_from.push((id, Vec::new()));
            o.scaled_from.len() - 1
        }
    };
    &mut o.scaled_from[at].1
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
            daqmx::FORMAT_CHANGING | daqmx::DIGITAL_LINE => {
                let d = daqmx::index(c, e, iat, index_len)?;
                let o = &mut objects[k];
                o.numeric |= d.numeric();
                o.daqmx_raw |= d.raw;
                o.daqmx_at = c.offset_of(iat);
                let count = d.count;
                o.daqmx = Some(d);
                Some(RawIndex {
                    dtype: None,
                    size: 0,
                    count,
                    bytes: 0,
                    daqmx: true,
                })
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
                    daqmx: false,
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
            let pat = c.offset();
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
                    if Props::wanted(name) {
                        o.props.set(name, Value::Text(v.to_string()), pat);
                    }
                }
                _ => {
                    let (dtype, size) = data_type(t).map_err(|_| {
                        c.invalid_at(tat, "TDMS property type", format!("{t:#x}"), TYPES)
                    })?;
                    let vat = c.pos;
                    c.skip(size, "TDMS property value")?;
                    let kept =
                        matches!(name, "wf_increment" | "wf_start_offset") || Props::wanted(name);
                    if let (Some(d), true) = (dtype, kept) {
                        let ch = c.channel.clone().unwrap_or_default();
                        let v = c.samples(vat, 1, size, d, e, &ch)?[0];
                        match name {
                            "wf_increment" => o.increment = Some((v, c.offset_of(vat))),
                            "wf_start_offset" => o.start = Some(v),
                            _ => o.props.set(name, Value::Number(v), pat),
                        }
                    }
                }
            }
        }
    }
    c.channel = None;
    Ok(())
}

/// Where a segment's raw data lies: file offsets `[start, end)`, byte order `e`; `open`
/// when its writer never closed it (next segment offset `0xFFFFFFFFFFFFFFFF`: a recording
/// interrupted mid-segment).
struct Raw<'a> {
    file: &'a str,
    start: u64,
    end: u64,
    /// The file's size \[bytes\].
    size: u64,
    e: Endian,
    open: bool,
}

impl Raw<'_> {
    /// Room in a channel's `data` for the `here` values this segment holds, of
    /// `value_bytes` bytes each in the file. On the channel's first segment, room for the
    /// rest of the file too, as if it repeated this segment's raw data (what writers that
    /// append a block per segment do), but never for more values than the bytes left can
    /// hold: a channel grown segment by segment was moved and copied at each doubling (10
    /// segments read 2x slower than one). Later segments grow it as needed; [`read_from`]
    /// trims what was not used.
    fn reserve(&self, data: &mut Vec<f64>, here: u64, value_bytes: u64) {
        if data.capacity() == 0 {
            let left = self.size - self.start;
            let segments = left.div_ceil((self.end - self.start).max(1));
            let most = left / value_bytes.max(1);
            data.reserve_exact(here.saturating_mul(segments).min(most).max(here) as usize);
        } else {
            data.reserve(here as usize);
        }
    }

    /// [`crate::num::samples_at`] in this file's name and byte order. The caller keeps the
    /// values within the raw data.
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
        let e = self.e;
        crate::num::samples_at(
            src, self.file, channel, at, first, n, stride, t, e, scratch, out,
        )
    }
}

/// How a segment's raw data is laid out: its objects with data, and its chunks, checked
/// against the segment (nothing of the data is read to find it).
enum Layout {
    /// Channel after channel in each chunk.
    Plain {
        present: Vec<(usize, RawIndex)>,
        chunk: u64,
        chunks: u64,
    },
    /// Value by value in each chunk.
    Interleaved {
        present: Vec<(usize, RawIndex)>,
        chunk: u64,
        chunks: u64,
    },
    /// DAQmx raw buffers ([`daqmx`]).
    Daqmx(DaqmxLayout),
}

/// The raw data of a DAQmx segment: each chunk is the raw buffers in turn, buffer `b`
/// `rows[b]` rows of `widths[b]` bytes.
struct DaqmxLayout {
    present: Vec<(usize, RawIndex)>,
    rows: Vec<u64>,
    widths: Vec<u32>,
    /// The scalers of each object of `present`.
    scalers: Vec<Vec<daqmx::Scaler>>,
    chunk: u64,
    chunks: u64,
}

/// The layout of the raw data `r` of a segment with object list `list`, checked (chunks
/// that divide it, DAQmx buffers that agree); `None` when there is nothing to read. The
/// notes gain what an interrupted last segment leaves unread.
fn layout(
    r: &Raw,
    interleaved: bool,
    objects: &[Object],
    list: &[(usize, Option<RawIndex>)],
    notes: &mut Vec<String>,
) -> Result<Option<Layout>, ReadError> {
    // errors about the whole raw data name its first byte
    let c = raw_cursor(r);
    let present: Vec<(usize, RawIndex)> = list
        .iter()
        .filter_map(|&(k, i)| i.map(|i| (k, i)))
        .filter(|(_, i)| i.bytes > 0 || i.daqmx)
        .collect();
    if present.iter().any(|(_, i)| i.daqmx) {
        return Ok(daqmx_layout(r, &c, present, objects, notes)?.map(Layout::Daqmx));
    }
    let chunk = present
        .iter()
        .try_fold(0u64, |a, (_, i)| a.checked_add(i.bytes));
    let layout = "chunk its object list describes";
    let Some((chunk, chunks)) = chunk_count(&c, r, chunk, layout, notes)? else {
        return Ok(None);
    };
    Ok(Some(if interleaved {
        Layout::Interleaved {
            present,
            chunk,
            chunks,
        }
    } else {
        Layout::Plain {
            present,
            chunk,
            chunks,
        }
    }))
}

/// A cursor on no bytes whose errors name the first byte of the raw data `r`.
fn raw_cursor<'a>(r: &Raw<'a>) -> Cursor<'a> {
    Cursor {
        base: r.start,
        ..Cursor::new(r.file, &[])
    }
}

/// Reads the raw data `r` of a segment laid out as `layout` into the objects' data, a
/// block of at most [`BLOCK`] bytes at a time, in the order (and so with the first error)
/// of reading each chunk channel after channel.
fn raw_data<S: Source + ?Sized>(
    src: &S,
    r: &Raw,
    layout: Layout,
    objects: &mut [Object],
) -> Result<(), ReadError> {
    let (present, chunk, chunks) = match layout {
        Layout::Daqmx(d) => return daqmx_data(src, r, d, objects),
        Layout::Interleaved {
            present,
            chunk,
            chunks,
        } => return interleaved_data(src, r, &raw_cursor(r), &present, chunk, chunks, objects),
        Layout::Plain {
            present,
            chunk,
            chunks,
        } => (present, chunk, chunks),
    };
    // Every value of a numeric channel lies in the raw data, so this is at most a value
    // per raw byte.
    for &(k, i) in &present {
        if i.dtype.is_some() {
            r.reserve(&mut objects[k].data, i.count.saturating_mul(chunks), i.size);
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

/// The chunk size and count of the raw data `r` in chunks of `chunk` bytes (`None`: beyond
/// 64 bits), `layout` saying what lays them out; `Ok(None)` when there is nothing to read.
/// The chunks must divide the raw data, except in a segment its writer left open (an
/// interrupted recording): there the whole chunks are read, and a note says how many bytes
/// of an unfinished chunk were not.
fn chunk_count(
    c: &Cursor,
    r: &Raw,
    chunk: Option<u64>,
    layout: &str,
    notes: &mut Vec<String>,
) -> Result<Option<(u64, u64)>, ReadError> {
    let region = r.end - r.start;
    let Some(chunk) = chunk else {
        return Err(c.invalid(
            "TDMS chunk size",
            "beyond 64 bits",
            format!("at most the raw data's {region} bytes"),
        ));
    };
    if chunk == 0 || region == 0 {
        return Ok(None);
    }
    let rest = region % chunk;
    if rest != 0 && !r.open {
        return Err(c.invalid(
            "TDMS raw data size",
            format!("{region} bytes"),
            format!("a multiple of the {chunk}-byte {layout}"),
        ));
    }
    if rest != 0 {
        notes.push(format!(
            "the segment whose raw data starts at byte {} was left open by its writer (an \
             interrupted recording): its last {rest} bytes, less than one {chunk}-byte chunk, \
             were not read",
            r.start
        ));
    }
    let chunks = region / chunk;
    Ok((chunks > 0).then_some((chunk, chunks)))
}

/// The layout of DAQmx raw data ([`daqmx`]), checked: every object DAQmx, of the same
/// raw buffers, scalers that do not overlap, chunks that divide the raw data.
fn daqmx_layout(
    r: &Raw,
    c: &Cursor,
    present: Vec<(usize, RawIndex)>,
    objects: &[Object],
    notes: &mut Vec<String>,
) -> Result<Option<DaqmxLayout>, ReadError> {
    if let Some(&(k, _)) = present.iter().find(|(_, i)| !i.daqmx) {
        return Err(c.invalid(
            "TDMS segment objects",
            format!(
                "{} with plain raw data beside DAQmx raw data",
                objects[k].name()
            ),
            "DAQmx raw data for every object of a segment, or for none",
        ));
    }
    let index = |k: usize| {
        objects[k]
            .daqmx
            .as_ref()
            .expect("a DAQmx object has its index")
    };
    let widths = index(present[0].0).widths.clone();
    let mut rows = vec![0u64; widths.len()];
    for &(k, i) in &present {
        let d = index(k);
        if d.widths != widths {
            return Err(c.invalid(
                "TDMS DAQmx raw buffer widths",
                format!("{:?} bytes for {}", d.widths, objects[k].name()),
                format!("those of every object of the segment ({widths:?} bytes)"),
            ));
        }
        for s in &d.scalers {
            let b = s.buffer as usize;
            rows[b] = rows[b].max(i.count);
        }
    }
    // Scalers of one buffer hold distinct bytes of its rows (as DAQmx lays them out), so
    // the values read are at most one per raw byte.
    let mut used = vec![0u64; widths.len()];
    for &(k, _) in &present {
        for s in &index(k).scalers {
            used[s.buffer as usize] += u64::from(s.size);
        }
    }
    if let Some(b) = (0..widths.len()).find(|&b| used[b] > u64::from(widths[b])) {
        return Err(c.invalid(
            "TDMS DAQmx scalers",
            format!("{} bytes of values in raw buffer {b}", used[b]),
            format!(
                "at most its row's {} bytes (scalers that do not overlap)",
                widths[b]
            ),
        ));
    }
    let scalers: Vec<Vec<daqmx::Scaler>> = present
        .iter()
        .map(|&(k, _)| index(k).scalers.clone())
        .collect();
    let chunk = rows.iter().zip(&widths).try_fold(0u64, |a, (&n, &w)| {
        a.checked_add(n.checked_mul(u64::from(w))?)
    });
    let layout = "DAQmx chunk its raw buffers describe";
    let Some((chunk, chunks)) = chunk_count(c, r, chunk, layout, notes)? else {
        return Ok(None);
    };
    Ok(Some(DaqmxLayout {
        present,
        rows,
        widths,
        scalers,
        chunk,
        chunks,
    }))
}

/// DAQmx raw data ([`daqmx`]): each chunk is the raw buffers in turn, rows of their width;
/// each scaler's values are read from its buffer's rows, block by block, onto its channel
/// (or, for DAQmx raw data, onto the channel's values of that scaler).
fn daqmx_data<S: Source + ?Sized>(
    src: &S,
    r: &Raw,
    d: DaqmxLayout,
    objects: &mut [Object],
) -> Result<(), ReadError> {
    let DaqmxLayout {
        present,
        rows,
        widths,
        scalers,
        chunk,
        chunks,
    } = d;
    let names: Vec<String> = present.iter().map(|&(k, _)| objects[k].name()).collect();
    let mut scratch = Vec::new();
    for n in 0..chunks {
        let mut base = r.start + n * chunk;
        for (b, (&count, &width)) in rows.iter().zip(&widths).enumerate() {
            let width = u64::from(width);
            let per = (BLOCK / width.max(1)).max(1);
            for ((&(k, _), ch), scalers) in present.iter().zip(&names).zip(&scalers) {
                let o = &mut objects[k];
                for s in scalers.iter().filter(|s| s.buffer as usize == b) {
                    let Some(d) = s.dtype else { continue };
                    let out = if o.daqmx_raw {
                        scaler_values(o, s.id)
                    } else {
                        &mut o.data
                    };
                    let mut first = 0;
                    while first < count {
                        let m = per.min(count - first);
                        let at = base + first * width + u64::from(s.offset);
                        let index = out.len() as u64;
                        r.samples_into(src, at, index, m, width, d, ch, &mut scratch, out)?;
                        first += m;
                    }
                }
            }
            base += count * width;
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
    let bad = unequal(present);
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
        for (k, _, d, _) in &cols {
            r.reserve(
                &mut objects[*k].data,
                count.saturating_mul(chunks),
                d.size() as u64,
            );
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
        return Err(unequal_error(c, present, j, objects));
    }
    Ok(())
}

/// The first object of interleaved raw data whose values are not of the first one's count
/// or of a fixed size (interleaved rows need both).
fn unequal(present: &[(usize, RawIndex)]) -> Option<usize> {
    let count = present.first()?.1.count;
    present
        .iter()
        .position(|(_, i)| i.count != count || i.size == 0)
}

/// The error for object `present[j]` of interleaved raw data, found by [`unequal`].
fn unequal_error(
    c: &Cursor,
    present: &[(usize, RawIndex)],
    j: usize,
    objects: &[Object],
) -> ReadError {
    let count = present[0].1.count;
    let (k, i) = present[j];
    c.invalid(
        "TDMS interleaved raw data",
        format!(
            "{} with {} values of {} bytes",
            objects[k].name(),
            i.count,
            i.size
        ),
        format!("every channel with {count} fixed-size values"),
    )
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
            meta.extend(channel_meta(name, t, count, &[]));
        }
        one_segment(toc, &meta, raw)
    }

    /// The metadata of channel `/'g'/'name'`: a raw data index of `count` values of type
    /// code `t`, then its properties.
    fn channel_meta(name: &str, t: u32, count: u64, props: &[Prop]) -> Vec<u8> {
        let path = format!("/'g'/'{name}'");
        let mut meta = (path.len() as u32).to_le_bytes().to_vec();
        meta.extend(path.as_bytes());
        meta.extend(20u32.to_le_bytes());
        meta.extend(t.to_le_bytes());
        meta.extend(1u32.to_le_bytes());
        meta.extend(count.to_le_bytes());
        meta.extend(props_bytes(props));
        meta
    }

    /// A file of one segment (a new object list with metadata and raw data, plus the `toc`
    /// bits given) holding `meta` and `raw`, little endian.
    fn one_segment(toc: u32, meta: &[u8], raw: &[u8]) -> Vec<u8> {
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
        // and streamed, block by block, alike
        stream::check::agrees_exactly(bytes, &mem);
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
    fn channels_across_segments_of_other_layouts_are_whole_and_trimmed() {
        // a and b in a small first segment (room is reserved ahead as if the file repeated
        // it), then b alone in a larger one (more than reserved: grown), then a alone
        // (less than reserved: trimmed at the end)
        let f64s = |v: &[f64]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
        let a1: Vec<f64> = (0..10).map(f64::from).collect();
        let b1: Vec<f64> = (1000..1010).map(f64::from).collect();
        let b2: Vec<f64> = (2000..3000).map(f64::from).collect();
        let a3: Vec<f64> = (100..105).map(f64::from).collect();
        let mut f = segment(
            0,
            &[("a", 10, 10), ("b", 10, 10)],
            &[f64s(&a1), f64s(&b1)].concat(),
        );
        f.extend(segment(0, &[("b", 10, 1000)], &f64s(&b2)));
        f.extend(segment(0, &[("a", 10, 5)], &f64s(&a3)));
        let t = both(&f).unwrap();
        assert_eq!(t.channels[0].data, [a1, a3].concat());
        assert_eq!(t.channels[1].data, [b1, b2].concat());
        for c in &t.channels {
            assert_eq!(c.data.capacity(), c.data.len(), "{}", c.name);
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

    #[test]
    fn a_bad_wf_increment_is_named_at_its_value() {
        // one f64 channel of 2 values whose wf_increment (a double) is -1: the error names
        // the byte where that double starts
        let mut meta = 1u32.to_le_bytes().to_vec();
        let increment = ("wf_increment", 10, (-1.0f64).to_le_bytes().to_vec());
        meta.extend(channel_meta("a", 10, 2, &[increment]));
        let raw: Vec<u8> = [0.5f64, 1.5].iter().flat_map(|v| v.to_le_bytes()).collect();
        let f = one_segment(0, &meta, &raw);
        let value_at = f
            .windows(8)
            .position(|w| w == (-1.0f64).to_le_bytes())
            .unwrap() as u64;
        match both(&f) {
            Err(ReadError::Invalid {
                channel, offset, ..
            }) => {
                assert_eq!(channel.as_deref(), Some("g/a"));
                assert_eq!(offset, value_at);
            }
            other => panic!("{other:?}"),
        }
    }

    /// Bytes of a hex string as npTDMS's tests write them ("01 00" "FF FF").
    fn hex(h: &str) -> Vec<u8> {
        let digits: Vec<u8> = h.bytes().filter(u8::is_ascii_hexdigit).collect();
        digits
            .chunks(2)
            .map(|p| u8::from_str_radix(std::str::from_utf8(p).unwrap(), 16).unwrap())
            .collect()
    }

    /// A property: name, TDMS type and value bytes.
    type Prop<'a> = (&'a str, u32, Vec<u8>);

    fn props_bytes(props: &[Prop]) -> Vec<u8> {
        let mut b = (props.len() as u32).to_le_bytes().to_vec();
        for (name, t, v) in props {
            b.extend((name.len() as u32).to_le_bytes());
            b.extend(name.as_bytes());
            b.extend(t.to_le_bytes());
            b.extend(v);
        }
        b
    }

    fn text(v: &str) -> Vec<u8> {
        let mut b = (v.len() as u32).to_le_bytes().to_vec();
        b.extend(v.as_bytes());
        b
    }

    /// npTDMS's `daqmx_scaler_metadata(scale_id, type_id, byte_offset, raw_buffer_index)`.
    fn scaler(id: u32, ty: u32, offset: u32, buffer: u32) -> Vec<u8> {
        [ty, buffer, offset, 0, id]
            .iter()
            .flat_map(|v| v.to_le_bytes())
            .collect()
    }

    /// npTDMS's `daqmx_channel_metadata`: channel `/'Group'/'name'` with a format-changing
    /// (or digital line) DAQmx index.
    fn daqmx_channel(
        name: &str,
        count: u64,
        widths: &[u32],
        scalers: &[Vec<u8>],
        props: &[Prop],
        data_type: u32,
        header: u32,
    ) -> Vec<u8> {
        let path = format!("/'Group'/'{name}'");
        let mut b = (path.len() as u32).to_le_bytes().to_vec();
        b.extend(path.as_bytes());
        b.extend(header.to_le_bytes());
        b.extend(data_type.to_le_bytes());
        b.extend(1u32.to_le_bytes());
        b.extend(count.to_le_bytes());
        b.extend((scalers.len() as u32).to_le_bytes());
        for s in scalers {
            b.extend(s);
        }
        b.extend((widths.len() as u32).to_le_bytes());
        for w in widths {
            b.extend(w.to_le_bytes());
        }
        b.extend(props_bytes(props));
        b
    }

    fn raw_channel(name: &str, count: u64, widths: &[u32], scalers: &[Vec<u8>]) -> Vec<u8> {
        daqmx_channel(name, count, widths, scalers, &[], 0xFFFF_FFFF, 0x1269)
    }

    /// A one-segment file: the root, the group `/'Group'` and `objects`, then `data`
    /// (npTDMS's GeneratedFile.add_segment with segment_objects_metadata).
    fn daqmx_file(toc: u32, objects: &[Vec<u8>], data: &[u8]) -> Vec<u8> {
        file_with_group(toc, &[], objects, data)
    }

    /// [`daqmx_file`] with properties on the group.
    fn file_with_group(
        toc: u32,
        group_props: &[Prop],
        objects: &[Vec<u8>],
        data: &[u8],
    ) -> Vec<u8> {
        let mut meta = ((objects.len() + 2) as u32).to_le_bytes().to_vec();
        meta.extend(hex("01 00 00 00 2F FF FF FF FF 00 00 00 00"));
        let group = "/'Group'";
        meta.extend((group.len() as u32).to_le_bytes());
        meta.extend(group.as_bytes());
        meta.extend(hex("FF FF FF FF"));
        meta.extend(props_bytes(group_props));
        for o in objects {
            meta.extend(o);
        }
        one_segment(toc, &meta, data)
    }

    const DAQMX: u32 = 0x80;

    fn values(t: &Table, channel: &str) -> Vec<f64> {
        t.channels
            .iter()
            .find(|c| c.name == format!("Group/{channel}"))
            .unwrap_or_else(|| panic!("no {channel} in {:?}", t.channels))
            .data
            .clone()
    }

    // The DAQmx cases below are npTDMS's (nptdms/test/test_daqmx.py), with its data and
    // expected values.

    #[test]
    fn daqmx_single_channels_of_each_integer_type() {
        let i16_data = "01 00 02 00 FF FF FE FF";
        let i32_data = "01 00 00 00 02 00 00 00 FF FF FF FF FE FF FF FF";
        for (ty, width, data, want) in [
            (3, 2, i16_data, vec![1.0, 2.0, -1.0, -2.0]),
            (2, 2, i16_data, vec![1.0, 2.0, 65535.0, 65534.0]),
            (5, 4, i32_data, vec![1.0, 2.0, -1.0, -2.0]),
            (4, 4, i32_data, vec![1.0, 2.0, 4294967295.0, 4294967294.0]),
        ] {
            let ch = raw_channel("Channel1", 4, &[width], &[scaler(0, ty, 0, 0)]);
            let t = both(&daqmx_file(DAQMX, &[ch], &hex(data))).unwrap();
            assert_eq!(values(&t, "Channel1"), want, "DAQmx type {ty}");
        }
    }

    #[test]
    fn daqmx_two_channels_with_and_without_the_toc_flag() {
        let data = hex("01 00 11 00 02 00 12 00 03 00 13 00 04 00 14 00");
        for toc in [DAQMX, 0] {
            let chans = [
                raw_channel("Channel1", 4, &[4], &[scaler(0, 3, 0, 0)]),
                raw_channel("Channel2", 4, &[4], &[scaler(0, 3, 2, 0)]),
            ];
            let t = both(&daqmx_file(toc, &chans, &data)).unwrap();
            assert_eq!(values(&t, "Channel1"), [1.0, 2.0, 3.0, 4.0]);
            assert_eq!(values(&t, "Channel2"), [17.0, 18.0, 19.0, 20.0]);
        }
    }

    #[test]
    fn daqmx_index_of_plain_types_and_its_type_checks() {
        // channels of a TDMS type hold their one scaler's values; a timestamp is skipped
        let mut data = Vec::new();
        for k in 1..=4u64 {
            data.extend([0x5Au8; 16]);
            data.extend(k.to_le_bytes());
            data.extend((k as f64).to_le_bytes());
        }
        let chans = [
            daqmx_channel(
                "Channel1",
                4,
                &[32],
                &[scaler(0, 0xFFFF_FFFF, 0, 0)],
                &[],
                0x44,
                0x1269,
            ),
            daqmx_channel("Channel2", 4, &[32], &[scaler(0, 7, 16, 0)], &[], 4, 0x1269),
            daqmx_channel(
                "Channel3",
                4,
                &[32],
                &[scaler(0, 9, 24, 0)],
                &[],
                10,
                0x1269,
            ),
        ];
        let t = both(&daqmx_file(0, &chans, &data)).unwrap();
        assert_eq!(t.channels.len(), 2);
        assert_eq!(values(&t, "Channel2"), [1.0, 2.0, 3.0, 4.0]);
        assert_eq!(values(&t, "Channel3"), [1.0, 2.0, 3.0, 4.0]);
        // a u16 channel with an i16 scaler, an i32 channel with two scalers: refused
        for (ty, scalers) in [
            (6, vec![scaler(0, 3, 0, 0)]),
            (3, vec![scaler(0, 3, 0, 0), scaler(0, 3, 2, 0)]),
        ] {
            let ch = daqmx_channel("Channel1", 2, &[4], &scalers, &[], ty, 0x1269);
            match both(&daqmx_file(0, &[ch], &hex("01 00 02 00"))) {
                Err(ReadError::Invalid { what, channel, .. }) => {
                    assert_eq!(what, "TDMS DAQmx data type");
                    assert_eq!(channel.as_deref(), Some("Group/Channel1"));
                }
                other => panic!("{other:?}"),
            }
        }
    }

    #[test]
    fn daqmx_mixed_widths_and_several_raw_buffers() {
        // one buffer, rows of 7 bytes: an i8, an i16 and an i32
        let chans = [
            raw_channel("Channel1", 4, &[7], &[scaler(0, 1, 0, 0)]),
            raw_channel("Channel2", 4, &[7], &[scaler(0, 3, 1, 0)]),
            raw_channel("Channel3", 4, &[7], &[scaler(0, 5, 3, 0)]),
        ];
        let data = hex(
            "01 11 00 21 00 00 00 02 12 00 22 00 00 00 03 13 00 23 00 00 00 04 14 00 24 00 00 00",
        );
        let t = both(&daqmx_file(DAQMX, &chans, &data)).unwrap();
        assert_eq!(values(&t, "Channel1"), [1.0, 2.0, 3.0, 4.0]);
        assert_eq!(values(&t, "Channel2"), [17.0, 18.0, 19.0, 20.0]);
        assert_eq!(values(&t, "Channel3"), [33.0, 34.0, 35.0, 36.0]);
        // two buffers of widths 6 and 8
        let w = [6, 8];
        let chans = [
            raw_channel("Channel1", 4, &w, &[scaler(0, 3, 0, 0)]),
            raw_channel("Channel2", 4, &w, &[scaler(0, 3, 2, 0)]),
            raw_channel("Channel3", 4, &w, &[scaler(0, 3, 4, 0)]),
            raw_channel("Channel4", 4, &w, &[scaler(0, 5, 0, 1)]),
            raw_channel("Channel5", 4, &w, &[scaler(0, 5, 4, 1)]),
        ];
        let mut data = Vec::new();
        for v in 1..=12u16 {
            data.extend(v.to_le_bytes());
        }
        for v in 13..=20u32 {
            data.extend(v.to_le_bytes());
        }
        let t = both(&daqmx_file(DAQMX, &chans, &data)).unwrap();
        assert_eq!(values(&t, "Channel1"), [1.0, 4.0, 7.0, 10.0]);
        assert_eq!(values(&t, "Channel2"), [2.0, 5.0, 8.0, 11.0]);
        assert_eq!(values(&t, "Channel3"), [3.0, 6.0, 9.0, 12.0]);
        assert_eq!(values(&t, "Channel4"), [13.0, 15.0, 17.0, 19.0]);
        assert_eq!(values(&t, "Channel5"), [14.0, 16.0, 18.0, 20.0]);
    }

    #[test]
    fn daqmx_buffers_of_different_lengths_over_two_chunks() {
        let scales = [("NI_Number_Of_Scales", 3, hex("01 00 00 00"))];
        let w = [6, 6, 6];
        let ch = |name: &str, count, s| {
            daqmx_channel(name, count, &w, &[s], &scales, 0xFFFF_FFFF, 0x1269)
        };
        let chans = [
            ch("Channel1", 4, scaler(0, 3, 0, 0)),
            ch("Channel2", 4, scaler(0, 5, 2, 0)),
            ch("Channel3", 2, scaler(0, 3, 0, 1)),
            ch("Channel4", 2, scaler(0, 5, 2, 1)),
            ch("Channel5", 1, scaler(0, 3, 0, 2)),
            ch("Channel6", 1, scaler(0, 5, 2, 2)),
        ];
        let chunk = "01 00 02 00 00 00 01 00 02 00 00 00 01 00 02 00 00 00 01 00 02 00 00 00 \
                     03 00 04 00 00 00 03 00 04 00 00 00 05 00 06 00 00 00";
        let data = hex(&format!("{chunk} {chunk}"));
        let t = both(&daqmx_file(DAQMX, &chans, &data)).unwrap();
        assert_eq!(values(&t, "Channel1"), [1.0; 8]);
        assert_eq!(values(&t, "Channel2"), [2.0; 8]);
        assert_eq!(values(&t, "Channel3"), [3.0; 4]);
        assert_eq!(values(&t, "Channel4"), [4.0; 4]);
        assert_eq!(values(&t, "Channel5"), [5.0; 2]);
        assert_eq!(values(&t, "Channel6"), [6.0; 2]);
        // a third chunk cut short (npTDMS reads the part; rotorid refuses, as for plain
        // data, naming the raw data's offset)
        let mut cut = data.clone();
        cut.extend(hex("01 00 02 00 00 00"));
        let f = daqmx_file(DAQMX, &chans, &cut);
        match both(&f) {
            Err(ReadError::Invalid { what, offset, .. }) => {
                assert_eq!(what, "TDMS raw data size");
                assert_eq!(offset, (f.len() - cut.len()) as u64);
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn daqmx_scalers_are_scaled_by_the_channel_properties() {
        // A voltage channel as DAQmx logs it: scale 0 is the device's raw i16 codes (no
        // type: the scaler with id 0), scale 1 the polynomial that makes volts of them.
        let c = [0.0012, 3.0517578125e-4, 1.5e-11, -2.5e-15];
        let f64b = |v: f64| v.to_le_bytes().to_vec();
        let props = vec![
            ("NI_Scaling_Status", 0x20, text("unscaled")),
            ("NI_Number_Of_Scales", 7, 2u32.to_le_bytes().to_vec()),
            ("NI_Scale[1]_Scale_Type", 0x20, text("Polynomial")),
            (
                "NI_Scale[1]_Polynomial_Coefficients_Size",
                3,
                4i32.to_le_bytes().to_vec(),
            ),
            ("NI_Scale[1]_Polynomial_Coefficients[0]", 10, f64b(c[0])),
            ("NI_Scale[1]_Polynomial_Coefficients[1]", 10, f64b(c[1])),
            ("NI_Scale[1]_Polynomial_Coefficients[2]", 10, f64b(c[2])),
            ("NI_Scale[1]_Polynomial_Coefficients[3]", 10, f64b(c[3])),
            (
                "NI_Scale[1]_Polynomial_Input_Source",
                7,
                0u32.to_le_bytes().to_vec(),
            ),
            ("unit_string", 0x20, text("Volts")),
        ];
        let codes = [-32768i16, -1, 0, 1, 12345, 32767];
        let ch = daqmx_channel(
            "probe x",
            6,
            &[2],
            &[scaler(0, 3, 0, 0)],
            &props,
            0xFFFF_FFFF,
            0x1269,
        );
        let data: Vec<u8> = codes.iter().flat_map(|v| v.to_le_bytes()).collect();
        let t = both(&daqmx_file(DAQMX, &[ch], &data)).unwrap();
        let want: Vec<f64> = codes
            .iter()
            .map(|&x| {
                let x = f64::from(x);
                c[0] + (c[1] + (c[2] + c[3] * x) * x) * x
            })
            .collect();
        let got = values(&t, "probe x");
        assert_eq!(
            got.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            want.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        );
        assert_eq!(t.channels[0].unit.as_deref(), Some("Volts"));
        // a scale of a type rotorid does not apply is refused, naming the property's byte
        let mut bad = props.clone();
        bad[2] = ("NI_Scale[1]_Scale_Type", 0x20, text("Thermocouple"));
        let ch = daqmx_channel(
            "probe x",
            6,
            &[2],
            &[scaler(0, 3, 0, 0)],
            &bad,
            0xFFFF_FFFF,
            0x1269,
        );
        let f = daqmx_file(DAQMX, &[ch], &data);
        let at = f
            .windows(22)
            .position(|w| w == b"NI_Scale[1]_Scale_Type")
            .unwrap() as u64
            - 4;
        match both(&f) {
            Err(ReadError::Invalid {
                what,
                found,
                offset,
                channel,
                ..
            }) => {
                assert_eq!(what, "TDMS property NI_Scale[1]_Scale_Type");
                assert_eq!(found, "\"Thermocouple\"");
                assert_eq!(offset, at);
                assert_eq!(channel.as_deref(), Some("Group/probe x"));
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn a_plain_channel_stored_unscaled_is_scaled_never_returned_as_its_codes() {
        // i16 codes with a linear scale (npTDMS's test_linear_scaling), on the channel,
        // then on its group
        let scale = vec![
            ("NI_Scaling_Status", 0x20, text("unscaled")),
            ("NI_Number_Of_Scales", 3, 1i32.to_le_bytes().to_vec()),
            ("NI_Scale[0]_Scale_Type", 0x20, text("Linear")),
            (
                "NI_Scale[0]_Linear_Slope",
                10,
                2.0f64.to_le_bytes().to_vec(),
            ),
            (
                "NI_Scale[0]_Linear_Y_Intercept",
                10,
                10.0f64.to_le_bytes().to_vec(),
            ),
        ];
        let channel = |props: &[Prop]| {
            let path = "/'Group'/'v'";
            let mut b = (path.len() as u32).to_le_bytes().to_vec();
            b.extend(path.as_bytes());
            b.extend(20u32.to_le_bytes());
            b.extend(2u32.to_le_bytes()); // i16
            b.extend(1u32.to_le_bytes());
            b.extend(3u64.to_le_bytes());
            b.extend(props_bytes(props));
            b
        };
        let data: Vec<u8> = [1i16, 2, 3].iter().flat_map(|v| v.to_le_bytes()).collect();
        let t = both(&daqmx_file(0, &[channel(&scale)], &data)).unwrap();
        assert_eq!(values(&t, "v"), [12.0, 14.0, 16.0]);
        let t = both(&file_with_group(0, &scale, &[channel(&[])], &data)).unwrap();
        assert_eq!(values(&t, "v"), [12.0, 14.0, 16.0]);
        // marked scaled: the values as stored
        let mut done = scale.clone();
        done[0] = ("NI_Scaling_Status", 0x20, text("scaled"));
        let t = both(&daqmx_file(0, &[channel(&done)], &data)).unwrap();
        assert_eq!(values(&t, "v"), [1.0, 2.0, 3.0]);
    }

    #[test]
    fn daqmx_digital_lines_and_a_mix_with_plain_data_are_refused() {
        let ch = daqmx_channel(
            "d",
            4,
            &[1],
            &[scaler(0, 0, 0, 0)],
            &[],
            0xFFFF_FFFF,
            0x126A,
        );
        match both(&daqmx_file(DAQMX, &[ch], &hex("01 00 01 00"))) {
            Err(ReadError::Invalid { found, .. }) => {
                assert!(found.contains("digital line"), "{found}")
            }
            other => panic!("{other:?}"),
        }
        // two scalers and no scales to say which is the channel's
        let ch = raw_channel("two", 2, &[4], &[scaler(0, 3, 0, 0), scaler(1, 3, 2, 0)]);
        match both(&daqmx_file(DAQMX, &[ch], &hex("01 00 02 00 03 00 04 00"))) {
            Err(ReadError::Invalid { found, .. }) => {
                assert!(found.contains("2 scalers"), "{found}")
            }
            other => panic!("{other:?}"),
        }
        // two channels' scalers on the same bytes (a value per raw byte at most)
        let chans = [
            raw_channel("a", 2, &[2], &[scaler(0, 3, 0, 0)]),
            raw_channel("b", 2, &[2], &[scaler(0, 3, 0, 0)]),
        ];
        match both(&daqmx_file(DAQMX, &chans, &hex("01 00 02 00"))) {
            Err(ReadError::Invalid { what, .. }) => assert_eq!(what, "TDMS DAQmx scalers"),
            other => panic!("{other:?}"),
        }
        // a scaler beyond its buffer's row
        let ch = raw_channel("far", 2, &[2], &[scaler(0, 3, 1, 0)]);
        match both(&daqmx_file(DAQMX, &[ch], &hex("01 00 02 00"))) {
            Err(ReadError::Invalid { what, .. }) => assert_eq!(what, "TDMS DAQmx scaler"),
            other => panic!("{other:?}"),
        }
    }

    /// A segment of table of contents `toc` (as given), byte order `e`, holding `meta`
    /// and `raw`.
    fn raw_segment(toc: u32, e: Endian, meta: &[u8], raw: &[u8]) -> Vec<u8> {
        let u64b = |v: u64| match e {
            Endian::Little => v.to_le_bytes(),
            Endian::Big => v.to_be_bytes(),
        };
        let mut f = b"TDSm".to_vec();
        f.extend(toc.to_le_bytes());
        f.extend(match e {
            Endian::Little => 4713u32.to_le_bytes(),
            Endian::Big => 4713u32.to_be_bytes(),
        });
        f.extend(u64b((meta.len() + raw.len()) as u64));
        f.extend(u64b(meta.len() as u64));
        f.extend(meta);
        f.extend(raw);
        f
    }

    #[test]
    fn streaming_follows_object_lists_across_segments_of_every_layout() {
        // Each file is read whole, from memory and disk, and streamed by blocks of 1, 7,
        // 4096 and all rows (both): the same catalogue, notes and values bit for bit.
        let f64s = |v: &[f64]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
        let i16s = |v: &[i16]| v.iter().flat_map(|x| x.to_le_bytes()).collect::<Vec<u8>>();
        // b is i16 codes scaled by its group's linear scale; a has a unit and a time axis
        let group = {
            let path = "/'g'";
            let mut b = 1u32.to_le_bytes().to_vec();
            b.extend((path.len() as u32).to_le_bytes());
            b.extend(path.as_bytes());
            b.extend(0xFFFF_FFFFu32.to_le_bytes());
            b.extend(props_bytes(&[
                ("NI_Number_Of_Scales", 3, 1i32.to_le_bytes().to_vec()),
                ("NI_Scale[0]_Scale_Type", 0x20, text("Linear")),
                (
                    "NI_Scale[0]_Linear_Slope",
                    10,
                    0.5f64.to_le_bytes().to_vec(),
                ),
                (
                    "NI_Scale[0]_Linear_Y_Intercept",
                    10,
                    (-3.0f64).to_le_bytes().to_vec(),
                ),
            ]));
            b
        };
        let a_props = [
            ("unit_string", 0x20, text("um")),
            ("wf_increment", 10, 0.001f64.to_le_bytes().to_vec()),
        ];
        let mut meta = 2u32.to_le_bytes().to_vec();
        meta.extend(channel_meta("a", 10, 3, &a_props));
        meta.extend(channel_meta("b", 2, 2, &[]));
        // (the group's scale comes in a later segment: the whole file's properties count)
        let mut f = Vec::new();
        let seg1_raw = [f64s(&[1.0, 2.0, 3.0]), i16s(&[10, 11])].concat();
        f.extend(raw_segment(
            TOC_META | TOC_NEW_LIST | TOC_RAW,
            Endian::Little,
            &meta,
            &seg1_raw,
        ));
        // 2: no metadata, the same list, two chunks
        let seg2_raw = [
            f64s(&[4.0, 5.0, 6.0]),
            i16s(&[12, 13]),
            f64s(&[7.0, 8.0, 9.0]),
            i16s(&[14, 15]),
        ]
        .concat();
        f.extend(raw_segment(TOC_RAW, Endian::Little, &[], &seg2_raw));
        // 3: the list updated (not new): a as before (index 0), b without data, and the
        // group's scale
        let mut meta3 = 3u32.to_le_bytes().to_vec();
        for (path, index) in [("/'g'/'a'", 0u32), ("/'g'/'b'", 0xFFFF_FFFF)] {
            meta3.extend((path.len() as u32).to_le_bytes());
            meta3.extend(path.as_bytes());
            meta3.extend(index.to_le_bytes());
            meta3.extend(0u32.to_le_bytes());
        }
        meta3.extend_from_slice(&group[4..]);
        f.extend(raw_segment(
            TOC_META | TOC_RAW,
            Endian::Little,
            &meta3,
            &f64s(&[10.0, 11.0, 12.0]),
        ));
        // 4: interleaved, a new list: b then a, 2 rows
        let mut meta4 = 2u32.to_le_bytes().to_vec();
        meta4.extend(channel_meta("b", 2, 2, &[]));
        meta4.extend(channel_meta("a", 10, 2, &[]));
        let mut rows = Vec::new();
        for (b, a) in [(16i16, 13.0f64), (17, 14.0)] {
            rows.extend(b.to_le_bytes());
            rows.extend(a.to_le_bytes());
        }
        f.extend(raw_segment(
            TOC_META | TOC_NEW_LIST | TOC_RAW | TOC_INTERLEAVED,
            Endian::Little,
            &meta4,
            &rows,
        ));
        // 5: big endian, a alone, a value 100 000 rows long (blocks of 256 KiB)
        let n = 100_000u64;
        let path = "/'g'/'a'";
        let mut meta5 = 1u32.to_be_bytes().to_vec();
        meta5.extend((path.len() as u32).to_be_bytes());
        meta5.extend(path.as_bytes());
        meta5.extend(20u32.to_be_bytes());
        meta5.extend(10u32.to_be_bytes());
        meta5.extend(1u32.to_be_bytes());
        meta5.extend(n.to_be_bytes());
        meta5.extend(0u32.to_be_bytes());
        let big: Vec<u8> = (0..n)
            .flat_map(|k| (k as f64 * 1.5).to_be_bytes())
            .collect();
        f.extend(raw_segment(
            TOC_META | TOC_NEW_LIST | TOC_RAW | TOC_BIG_ENDIAN,
            Endian::Big,
            &meta5,
            &big,
        ));
        let t = both(&f).unwrap();
        // (the group's scale applies to both)
        let scale = |v: f64| v * 0.5 - 3.0;
        let a = &t.channels[0].data;
        assert_eq!(a.len(), 14 + n as usize);
        let first: Vec<f64> = (1..=14).map(|v| scale(f64::from(v))).collect();
        assert_eq!(a[..14], first);
        assert_eq!(a[14 + 99_999], scale(99_999.0 * 1.5));
        let b: Vec<f64> = (10..18).map(|c| scale(f64::from(c))).collect();
        assert_eq!(t.channels[1].data, b);
        assert_eq!(t.channels[0].unit.as_deref(), Some("um"));
        // and left open by its writer, cut inside the big-endian segment: its whole rows
        let open = {
            let mut g = f.clone();
            let last = g.len() - big.len() - meta5.len() - 28;
            g[last + 12..last + 20].copy_from_slice(&u64::MAX.to_be_bytes());
            g.truncate(g.len() - 8 * 50_000 - 3);
            g
        };
        let t = both(&open).unwrap();
        // (one chunk of 100 000 values: less than a chunk is left, so no value of it)
        assert_eq!(t.notes.len(), 1);
        assert_eq!(t.channels[0].data[..], a[..14]);
    }

    /// `f` (one segment) as its writer leaves it when the recording is interrupted: the
    /// next segment offset all ones, and the raw data cut `cut` bytes short.
    fn interrupted(mut f: Vec<u8>, cut: usize) -> Vec<u8> {
        f[12..20].copy_from_slice(&u64::MAX.to_le_bytes());
        f.truncate(f.len() - cut);
        f
    }

    #[test]
    fn an_interrupted_recording_keeps_its_whole_chunks_and_says_what_was_not_read() {
        // two chunks of (a: 3 f64, b: 2 i32): 32 bytes each, the second cut 5 bytes short
        let mut raw = Vec::new();
        for k in 0..2i32 {
            for v in 0..3 {
                raw.extend(f64::from(10 * k + v).to_le_bytes());
            }
            for v in 0..2 {
                raw.extend((100 * k + v).to_le_bytes());
            }
        }
        let ch = [("a", 10, 3), ("b", 3, 2)];
        let whole = segment(0, &ch, &raw);
        let raw_start = whole.len() - raw.len();
        let t = both(&interrupted(whole.clone(), 5)).unwrap();
        assert_eq!(t.channels[0].data, [0.0, 1.0, 2.0]);
        assert_eq!(t.channels[1].data, [0.0, 1.0]);
        assert_eq!(
            t.notes,
            [format!(
                "the segment whose raw data starts at byte {raw_start} was left open by its \
                 writer (an interrupted recording): its last 27 bytes, less than one 32-byte \
                 chunk, were not read"
            )]
        );
        // the same cut in a segment its writer closed is an error, as before
        let mut closed = whole.clone();
        closed.truncate(closed.len() - 5);
        let len = (closed.len() - 28) as u64;
        closed[12..20].copy_from_slice(&len.to_le_bytes());
        match both(&closed) {
            Err(ReadError::Invalid { what, .. }) => assert_eq!(what, "TDMS raw data size"),
            other => panic!("{other:?}"),
        }
        // whole chunks only: no note; less than one chunk: no data, and the note
        assert!(both(&interrupted(whole.clone(), 0))
            .unwrap()
            .notes
            .is_empty());
        let t = both(&interrupted(whole, 40)).unwrap();
        assert!(t.channels.iter().all(|c| c.data.is_empty()));
        assert!(t.notes[0].contains("its last 24 bytes"), "{:?}", t.notes);
        // DAQmx: rows of a 4-byte buffer, the last row cut
        let data = hex("01 00 11 00 02 00 12 00 03 00 13 00 04 00 14");
        let chans = [
            raw_channel("Channel1", 4, &[4], &[scaler(0, 3, 0, 0)]),
            raw_channel("Channel2", 4, &[4], &[scaler(0, 3, 2, 0)]),
        ];
        // (one chunk of 4 rows; with 2-row chunks the second one is cut)
        let chans2 = [
            raw_channel("Channel1", 2, &[4], &[scaler(0, 3, 0, 0)]),
            raw_channel("Channel2", 2, &[4], &[scaler(0, 3, 2, 0)]),
        ];
        let f = interrupted(daqmx_file(DAQMX, &chans2, &data), 0);
        let t = both(&f).unwrap();
        assert_eq!(values(&t, "Channel1"), [1.0, 2.0]);
        assert_eq!(values(&t, "Channel2"), [17.0, 18.0]);
        assert_eq!(t.notes.len(), 1, "{:?}", t.notes);
        assert!(both(&daqmx_file(DAQMX, &chans, &data)).is_err());
    }
}
