//! MATLAB level 5 MAT-files (MATLAB `-v6`/`-v7`, `scipy.io.savemat`).
//!
//! Layout, after MathWorks' "MAT-File Format" (R2021b), chapter 1: a 128-byte header (116
//! bytes of text beginning `MATLAB 5.0 MAT-file`, an 8-byte subsystem offset, the version
//! `0x0100` and the endian indicator `IM` for a little-endian file, `MI` for big-endian),
//! then data elements. Each element is an 8-byte tag (`u32` data type, `u32` byte count)
//! and its data padded to 8 bytes; a *small* element packs a count of at most 4 bytes into
//! the tag's upper half and its data into the tag's second word. Element types: `miINT8`
//! 1, `miUINT8` 2, `miINT16` 3, `miUINT16` 4, `miINT32` 5, `miUINT32` 6, `miSINGLE` 7,
//! `miDOUBLE` 9, `miINT64` 12, `miUINT64` 13, `miMATRIX` 14, `miCOMPRESSED` 15 (a zlib
//! stream holding one element, not padded).
//!
//! A variable is an `miMATRIX`: array flags (class in the low byte, complex flag `0x0800`),
//! dimensions (`miINT32`), name (`miINT8`), then for numeric classes the real part in any
//! numeric element type (MATLAB stores a double that fits as `miUINT8`; the stored type is
//! what is converted, exactly) and an imaginary part when complex; for a struct, the field
//! name length, the names (`miINT8`, NUL-padded), then one `miMATRIX` per field.
//!
//! Every count is checked against the bytes of its enclosing element before use; a
//! compressed element inflates to at most 1032 times its size plus 1 KiB (deflate's largest
//! ratio), past which the file is refused. See [`crate::mat`] for which variables become
//! channels.

use std::io::Read;

use crate::cursor::Cursor;
use crate::error::ReadError;
use crate::num::{Dtype, Endian};
use crate::table::{Channel, Table};

const MI_INT8: u32 = 1;
const MI_INT32: u32 = 5;
const MI_UINT32: u32 = 6;
const MI_MATRIX: u32 = 14;
const MI_COMPRESSED: u32 = 15;
const MX_CELL: u8 = 1;
const MX_STRUCT: u8 = 2;
const MX_OBJECT: u8 = 3;
const MX_CHAR: u8 = 4;
const MX_SPARSE: u8 = 5;
const COMPLEX_FLAG: u32 = 0x0800;
const MAX_DEFLATE_RATIO: u64 = 1032;

/// Reads a level 5 MAT-file's bytes; `file` names it in messages.
pub fn read(file: &str, bytes: &[u8]) -> Result<Table, ReadError> {
    let mut c = Cursor::new(file, bytes);
    let endian = header(&mut c)?;
    let mut channels = Vec::new();
    let mut skipped = Vec::new();
    while !c.at_end() {
        element(&mut c, endian, &mut channels, &mut skipped)?;
    }
    finish(file, channels, skipped)
}

/// Reads the level 5 file at `path` element by element: memory holds the channels and one
/// top-level element (one variable), never the whole file. Accepts and refuses what
/// [`read`] does, with the same messages.
pub fn read_file(file: &str, path: &std::path::Path) -> Result<Table, ReadError> {
    let disk = crate::source::DiskFile::open(file, path)?;
    let (size, read_at) = (disk.size, |at, len| disk.read_at(at, len));
    let head = read_at(0, size.min(128))?;
    let endian = header(&mut Cursor::new(file, &head))?;
    let mut channels = Vec::new();
    let mut skipped = Vec::new();
    let mut pos = 128u64;
    while pos < size {
        // the element's extent from its tag, as `tag` reads it (a truncated element is
        // read to the end of the file, where `tag` refuses it as it would in memory)
        let t = read_at(pos, (size - pos).min(8))?;
        let word = |i: usize| {
            let b: [u8; 4] = t[i..i + 4].try_into().expect("four bytes");
            match endian {
                Endian::Little => u32::from_le_bytes(b),
                Endian::Big => u32::from_be_bytes(b),
            }
        };
        let total = if t.len() < 8 || word(0) >> 16 != 0 {
            8
        } else {
            let n = u64::from(word(4));
            let pad = if word(0) == MI_COMPRESSED {
                0
            } else {
                (8 - n % 8) % 8
            };
            8 + n + pad
        };
        let len = total.min(size - pos);
        let buf = read_at(pos, len)?;
        let mut c = Cursor {
            base: pos,
            ..Cursor::new(file, &buf)
        };
        while !c.at_end() {
            element(&mut c, endian, &mut channels, &mut skipped)?;
        }
        pos += len;
    }
    finish(file, channels, skipped)
}

/// Reads the 128-byte header: the byte order of the rest.
fn header(c: &mut Cursor) -> Result<Endian, ReadError> {
    let text = c.take(116, "MAT header text")?;
    if !text.starts_with(b"MATLAB") {
        return Err(c.invalid_at(
            0,
            "MAT header text",
            format!("{:?}", String::from_utf8_lossy(&text[..text.len().min(20)])),
            "\"MATLAB 5.0 MAT-file...\" (level 4 MAT-files are not read: save with -v7)",
        ));
    }
    c.skip(8, "MAT subsystem offset")?;
    let version = c.array::<2>("MAT version")?;
    let endian = match &c.array::<2>("MAT endian indicator")? {
        b"IM" => Endian::Little,
        b"MI" => Endian::Big,
        other => {
            return Err(c.invalid_at(
                126,
                "MAT endian indicator",
                format!("{other:?}"),
                "IM or MI",
            ))
        }
    };
    let v = match endian {
        Endian::Little => u16::from_le_bytes(version),
        Endian::Big => u16::from_be_bytes(version),
    };
    if v != 0x0100 {
        return Err(c.invalid_at(124, "MAT version", format!("{v:#06x}"), "0x0100 (level 5)"));
    }
    Ok(endian)
}

/// Reads one top-level element at `c` into `channels` (or a note in `skipped`).
fn element(
    c: &mut Cursor,
    endian: Endian,
    channels: &mut Vec<Channel>,
    skipped: &mut Vec<String>,
) -> Result<(), ReadError> {
    let file = c.file;
    let el = tag(c, endian)?;
    match el.ty {
        MI_MATRIX => {
            let mut sub = el.cursor(c);
            let var = matrix(&mut sub, endian, 0, None)?;
            collect(var, channels, skipped);
        }
        MI_COMPRESSED => {
            let inflated = inflate(c, &el)?;
            let mut ic = Cursor::inflated(file, &inflated, c.offset_of(el.at));
            let inner = tag(&mut ic, endian)?;
            if inner.ty == MI_MATRIX {
                let mut sub = inner.cursor(&ic);
                let var = matrix(&mut sub, endian, 0, None)?;
                collect(var, channels, skipped);
            } else {
                skipped.push(format!("a compressed element of type {}", inner.ty));
            }
        }
        t => skipped.push(format!(
            "a top-level element of type {t} at byte {}",
            c.offset_of(el.at)
        )),
    }
    Ok(())
}

/// The table of what was read, or the error that nothing was.
fn finish(file: &str, channels: Vec<Channel>, skipped: Vec<String>) -> Result<Table, ReadError> {
    if channels.is_empty() {
        return Err(ReadError::NoChannels {
            file: file.to_string(),
            why: if skipped.is_empty() {
                "the file has no variables".into()
            } else {
                format!("skipped: {}", skipped.join("; "))
            },
        });
    }
    Ok(Table {
        file: file.to_string(),
        channels,
        notes: Vec::new(),
    })
}

/// A variable, as far as the channels care.
enum Var {
    Vector { name: String, data: Vec<f64> },
    Struct { name: String, fields: Vec<Var> },
    Skipped { name: String, why: String },
}

fn collect(var: Var, channels: &mut Vec<Channel>, skipped: &mut Vec<String>) {
    match var {
        Var::Vector { name, data } => channels.push(Channel {
            name,
            unit: None,
            data,
            axis: None,
        }),
        Var::Struct { name, fields } => {
            for f in fields {
                match f {
                    Var::Vector { name: field, data } => channels.push(Channel {
                        name: format!("{name}.{field}"),
                        unit: None,
                        data,
                        axis: None,
                    }),
                    Var::Skipped { name: field, why } => {
                        skipped.push(format!("{name}.{field}: {why}"))
                    }
                    Var::Struct { name: field, .. } => {
                        skipped.push(format!("{name}.{field}: a nested struct"))
                    }
                }
            }
        }
        Var::Skipped { name, why } => skipped.push(format!("{name}: {why}")),
    }
}

/// A data element: its type, and where its data lies in the cursor's buffer.
struct Element {
    ty: u32,
    /// Buffer position of the tag.
    at: usize,
    /// Buffer position of the data.
    start: usize,
    len: usize,
}

impl Element {
    /// A cursor over this element's data alone.
    fn cursor<'a>(&self, c: &Cursor<'a>) -> Cursor<'a> {
        Cursor {
            data: &c.data[..self.start + self.len],
            pos: self.start,
            ..c.clone()
        }
    }
}

/// Reads an element tag and moves past its data and padding.
fn tag(c: &mut Cursor, e: Endian) -> Result<Element, ReadError> {
    let at = c.pos;
    let w = c.u32(e, "MAT element tag")?;
    if w >> 16 != 0 {
        let (ty, n) = (w & 0xffff, w >> 16);
        if n > 4 {
            return Err(c.invalid_at(at, "MAT small element byte count", n, "1 to 4"));
        }
        let start = c.pos;
        c.skip(4, "MAT small element data")?;
        return Ok(Element {
            ty,
            at,
            start,
            len: n as usize,
        });
    }
    let n = c.u32(e, "MAT element byte count")? as u64;
    let start = c.pos;
    c.skip(n, "MAT element data")?;
    if w != MI_COMPRESSED {
        // Padding to 8 bytes; some writers omit it after the last element.
        let pad = (8 - n % 8) % 8;
        c.pos += (pad as usize).min(c.remaining());
    }
    Ok(Element {
        ty: w,
        at,
        start,
        len: n as usize,
    })
}

fn inflate(c: &Cursor, el: &Element) -> Result<Vec<u8>, ReadError> {
    let packed = &c.data[el.start..el.start + el.len];
    let limit = (el.len as u64)
        .saturating_mul(MAX_DEFLATE_RATIO)
        .saturating_add(1024);
    let mut out = Vec::new();
    let r = flate2::read::ZlibDecoder::new(packed)
        .take(limit + 1)
        .read_to_end(&mut out);
    let fail = |found: String| ReadError::Invalid {
        file: c.file.to_string(),
        channel: None,
        offset: c.offset_of(el.at),
        what: "MAT miCOMPRESSED element".into(),
        found,
        allowed: format!("a zlib stream inflating to at most {limit} bytes"),
    };
    match r {
        Err(e) => Err(fail(format!("a broken zlib stream ({e})"))),
        Ok(_) if out.len() as u64 > limit => Err(fail(format!("more than {limit} bytes"))),
        Ok(_) => Ok(out),
    }
}

fn dtype(ty: u32) -> Option<Dtype> {
    Some(match ty {
        1 => Dtype::I8,
        2 => Dtype::U8,
        3 => Dtype::I16,
        4 => Dtype::U16,
        5 => Dtype::I32,
        6 => Dtype::U32,
        7 => Dtype::F32,
        9 => Dtype::F64,
        12 => Dtype::I64,
        13 => Dtype::U64,
        _ => return None,
    })
}

fn class_name(class: u8) -> &'static str {
    match class {
        1 => "cell",
        2 => "struct",
        3 => "object",
        4 => "char",
        5 => "sparse",
        6 => "double",
        7 => "single",
        8 => "int8",
        9 => "uint8",
        10 => "int16",
        11 => "uint16",
        12 => "int32",
        13 => "uint32",
        14 => "int64",
        15 => "uint64",
        16 => "function handle",
        17 => "opaque",
        _ => "unknown class",
    }
}

/// Expects an element of type `ty` (any of `tys`) and returns it.
fn expect(c: &mut Cursor, e: Endian, tys: &[u32], what: &str) -> Result<Element, ReadError> {
    let el = tag(c, e)?;
    if !tys.contains(&el.ty) {
        return Err(c.invalid_at(
            el.at,
            what,
            format!("element type {}", el.ty),
            format!("element type {tys:?}"),
        ));
    }
    Ok(el)
}

/// Parses an `miMATRIX` element's data (the cursor spans exactly that data).
/// `label` names a struct field (`rec.x`) in messages, whose own name is empty.
fn matrix(c: &mut Cursor, e: Endian, depth: u32, label: Option<&str>) -> Result<Var, ReadError> {
    let flags_el = expect(c, e, &[MI_UINT32], "MAT array flags")?;
    if flags_el.len < 4 {
        return Err(c.invalid_at(
            flags_el.at,
            "MAT array flags",
            format!("{} bytes", flags_el.len),
            "8 bytes",
        ));
    }
    let mut fc = flags_el.cursor(c);
    let flags = fc.u32(e, "MAT array flags")?;
    let class = (flags & 0xff) as u8;
    let dims_el = expect(c, e, &[MI_INT32], "MAT dimensions")?;
    let mut dc = dims_el.cursor(c);
    let mut dims = Vec::new();
    for _ in 0..dims_el.len / 4 {
        dims.push(dc.i32(e, "MAT dimension")?);
    }
    let name_el = expect(c, e, &[MI_INT8, 2], "MAT array name")?;
    let mut nc = name_el.cursor(c);
    c.channel = None;
    let name = nc.utf8(name_el.len as u64, "MAT array name")?.to_string();
    let shown = label.map_or_else(|| name.clone(), str::to_string);
    c.channel = Some(shown.clone());
    if dims.len() < 2 || dims.iter().any(|&d| d < 0) {
        return Err(c.invalid_at(
            dims_el.at,
            "MAT dimensions",
            format!("{dims:?}"),
            "two or more non-negative sizes",
        ));
    }
    let numel = dims.iter().try_fold(1u64, |a, &d| a.checked_mul(d as u64));
    let shape = dims
        .iter()
        .map(|d| d.to_string())
        .collect::<Vec<_>>()
        .join("x");
    let skip = |why: String| {
        Ok(Var::Skipped {
            name: name.clone(),
            why,
        })
    };
    match class {
        MX_STRUCT => {
            if depth > 0 {
                return Ok(Var::Struct {
                    name,
                    fields: vec![],
                });
            }
            if numel != Some(1) {
                return skip(format!(
                    "a {shape} struct array (only a scalar struct's fields are read)"
                ));
            }
            let len_el = expect(c, e, &[MI_INT32], "MAT struct field name length")?;
            let mut lc = len_el.cursor(c);
            let flen = lc.i32(e, "MAT struct field name length")?;
            let names_el = expect(c, e, &[MI_INT8, 2], "MAT struct field names")?;
            if flen <= 0 || names_el.len % flen as usize != 0 {
                return Err(c.invalid_at(
                    len_el.at,
                    "MAT struct field name length",
                    flen,
                    format!("a positive divisor of the names' {} bytes", names_el.len),
                ));
            }
            let mut fields = Vec::new();
            for k in 0..names_el.len / flen as usize {
                let at = names_el.start + k * flen as usize;
                let raw = &c.data[at..at + flen as usize];
                let raw = &raw[..raw.iter().position(|&b| b == 0).unwrap_or(raw.len())];
                let fname = std::str::from_utf8(raw)
                    .map_err(|_| c.not_utf8(at, "MAT struct field name", raw))?
                    .to_string();
                let fel = expect(c, e, &[MI_MATRIX], "MAT struct field")?;
                let mut fcur = fel.cursor(c);
                let label = format!("{name}.{fname}");
                fields.push(match matrix(&mut fcur, e, depth + 1, Some(&label))? {
                    Var::Vector { data, .. } => Var::Vector { name: fname, data },
                    Var::Skipped { why, .. } => Var::Skipped { name: fname, why },
                    Var::Struct { fields, .. } => Var::Struct {
                        name: fname,
                        fields,
                    },
                });
            }
            Ok(Var::Struct { name, fields })
        }
        MX_CELL | MX_OBJECT | MX_CHAR | MX_SPARSE | 16.. | 0 => {
            skip(format!("a {shape} {}", class_name(class)))
        }
        _ if flags & COMPLEX_FLAG != 0 => skip(format!("a complex {shape} {}", class_name(class))),
        _ => {
            let numel = numel.unwrap_or(u64::MAX);
            let vector = dims.iter().filter(|&&d| d != 1).count() <= 1 && numel > 0;
            let re = tag(c, e)?;
            let t = dtype(re.ty).ok_or_else(|| {
                c.invalid_at(
                    re.at,
                    "MAT real part element type",
                    re.ty,
                    "a numeric type 1-7, 9, 12, 13",
                )
            })?;
            if re.len as u64 != numel.saturating_mul(t.size() as u64) {
                return Err(c.invalid_at(
                    re.at,
                    "MAT real part byte count",
                    re.len,
                    format!("{shape} elements of {} bytes", t.size()),
                ));
            }
            if !vector {
                return skip(format!("a {shape} {} matrix", class_name(class)));
            }
            let data = c.samples(re.start, numel, t.size() as u64, t, e, &shown)?;
            Ok(Var::Vector { name, data })
        }
    }
}
