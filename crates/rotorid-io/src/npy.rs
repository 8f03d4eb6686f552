//! NumPy `.npy` arrays.
//!
//! Layout (the NEP 1 "A simple file format for NumPy arrays", versions 1.0, 2.0 and 3.0):
//! the magic `\x93NUMPY`, a major and a minor version byte, the header length (`u16` little
//! endian in version 1, `u32` in 2 and 3), then the header: a Python dict literal such as
//! `{'descr': '<f8', 'fortran_order': False, 'shape': (300, 2), }` (ASCII in 1 and 2,
//! UTF-8 in 3), padded with spaces and a newline; then the raw elements, `shape` product of
//! them, in C (row-major) or Fortran (column-major) order.
//!
//! Read: `descr` `f8`, `f4`, `i1`..`i8`, `u1`..`u8`, either byte order (`<`, `>`, `|`, `=`
//! taken as little endian); shapes `()` (one sample), `(n,)` and `(n, m)`. A 1-D array is
//! one channel named after the file stem (an NPZ member's array name); a 2-D array is `m`
//! channels of `n` samples each, `0`, `1`, ... (`name.0`, ... in an NPZ), as a pandas
//! `DataFrame.to_numpy()` is laid out: rows are samples, columns channels.
//!
//! Refused with an error naming the field: more columns than the file has bytes (an empty
//! `(0, m)` array could otherwise claim any number of channels), structured dtypes, complex, half, bool, strings,
//! objects, datetimes, 3-D arrays, a data size that is not the shape's product (checked
//! before allocating), 64-bit integers `f64` cannot hold exactly. The samples are
//! dimensionless as far as the file knows (no unit); NaN and infinities pass through.

use crate::cursor::Cursor;
use crate::error::ReadError;
use crate::num::{Dtype, Endian};
use crate::table::{Channel, Table};

const MAGIC: &[u8] = b"\x93NUMPY";

/// Reads an `.npy` file's bytes; `file` names it in messages and its stem names a 1-D
/// array's channel.
pub fn read(file: &str, bytes: &[u8]) -> Result<Table, ReadError> {
    let stem = std::path::Path::new(file)
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("0");
    let mut c = Cursor::new(file, bytes);
    let channels = parse(&mut c, stem, false)?;
    if channels.is_empty() {
        return Err(ReadError::NoChannels {
            file: file.to_string(),
            why: "a 2-D array with no columns".into(),
        });
    }
    Ok(Table {
        file: file.to_string(),
        channels,
        notes: Vec::new(),
    })
}

/// Parses one array at the cursor into channels. A 1-D array is one channel `name`; a 2-D
/// array's columns are `0`, `1`, ... or, with `prefixed`, `name.0`, `name.1`, ...
pub(crate) fn parse(c: &mut Cursor, name: &str, prefixed: bool) -> Result<Vec<Channel>, ReadError> {
    c.channel = Some(name.to_string());
    let (h, hpos) = header(c)?;
    let (dtype, endian) = descr(&h.descr).ok_or_else(|| {
        c.invalid_at(
            hpos,
            "NPY descr",
            format!("{:?}", h.descr),
            "f8, f4, i1, i2, i4, i8, u1, u2, u4, u8 with byte order <, > or |",
        )
    })?;
    let (rows, cols) = match h.shape[..] {
        [] => (1u64, 1u64),
        [n] => (n, 1),
        [n, m] => (n, m),
        _ => {
            return Err(c.invalid_at(
                hpos,
                "NPY shape",
                format!("{:?}", h.shape),
                "(), (n,) or (n, m)",
            ))
        }
    };
    // An empty array may claim any number of columns: each becomes a channel, so their
    // number is bounded by the buffer's size.
    if cols > c.data.len() as u64 {
        return Err(c.invalid_at(
            hpos,
            "NPY shape",
            format!("{:?}", h.shape),
            format!(
                "at most {} columns (the file's size in bytes)",
                c.data.len()
            ),
        ));
    }
    let size = dtype.size() as u64;
    let start = c.pos;
    let count = rows.checked_mul(cols).and_then(|n| n.checked_mul(size));
    match count {
        Some(n) if n <= c.remaining() as u64 => {}
        _ => {
            return Err(ReadError::Truncated {
                file: c.file.to_string(),
                channel: Some(name.to_string()),
                offset: c.offset(),
                what: c.describe(&format!("NPY data of shape {:?} {dtype:?}", h.shape), start),
                need: count.unwrap_or(u64::MAX),
                available: c.remaining() as u64,
            })
        }
    }
    let mut channels = Vec::new();
    if h.shape.len() < 2 {
        let data = c.samples(start, rows, size, dtype, endian, name)?;
        channels.push(Channel {
            name: name.to_string(),
            unit: None,
            data,
            axis: None,
        });
    } else {
        for j in 0..cols {
            let cname = if prefixed {
                format!("{name}.{j}")
            } else {
                j.to_string()
            };
            // Column j: contiguous in Fortran order, every `cols` elements in C order.
            let (first, stride) = if h.fortran_order {
                (j * rows * size, size)
            } else {
                (j * size, cols * size)
            };
            let data = c.samples(start + first as usize, rows, stride, dtype, endian, &cname)?;
            channels.push(Channel {
                name: cname,
                unit: None,
                data,
                axis: None,
            });
        }
    }
    c.pos = start + (rows * cols * size) as usize;
    c.channel = None;
    Ok(channels)
}

/// One whole array as the finite-element matrices file ([`crate::fe_matrices`]) takes it:
/// its shape as stored and its elements in C (row-major) order whatever the file's order.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Array {
    /// `f8` in either byte order.
    F64 {
        /// The shape.
        shape: Vec<u64>,
        /// The elements, row-major.
        data: Vec<f64>,
    },
    /// Fixed-width text: `U<w>` (UTF-32, as numpy saves a list of `str`) or `S<w>` (bytes,
    /// UTF-8 here), trailing NULs removed as numpy removes them.
    Text {
        /// The shape.
        shape: Vec<u64>,
        /// The strings, row-major.
        data: Vec<String>,
    },
    /// Any other dtype (refused by the caller, who names the member and what it allows).
    Other {
        /// The `descr` as written (`'<f4'`, `'|O'`, ...).
        descr: String,
        /// The shape.
        shape: Vec<u64>,
    },
}

/// Parses one whole array at the cursor ([`Array`]); `name` names it in messages. The data
/// size is checked against the buffer before anything is allocated.
pub(crate) fn parse_array(c: &mut Cursor, name: &str) -> Result<Array, ReadError> {
    c.channel = Some(name.to_string());
    let (h, _) = header(c)?;
    let (order, t) = h.descr.split_at_checked(1).unwrap_or(("", ""));
    let endian = match order {
        "<" | "|" | "=" => Some(Endian::Little),
        ">" => Some(Endian::Big),
        _ => None,
    };
    // the element's kind and size in bytes
    let width = |digits: &str| -> Option<u64> {
        // (a zero width, which numpy never writes, would let any count fit in no bytes)
        (!digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit()))
            .then(|| digits.parse::<u64>().ok())
            .flatten()
            .filter(|&w| w > 0)
    };
    enum Kind {
        F64,
        Utf32(u64),
        Bytes(u64),
    }
    let kind = match (endian, t) {
        (Some(_), "f8") => Some(Kind::F64),
        (Some(_), t) => match (t.strip_prefix('U'), t.strip_prefix('S')) {
            (Some(w), _) => width(w).map(Kind::Utf32),
            (_, Some(w)) => width(w).map(Kind::Bytes),
            _ => None,
        },
        _ => None,
    };
    let (Some(kind), Some(endian)) = (kind, endian) else {
        c.channel = None;
        return Ok(Array::Other {
            descr: h.descr,
            shape: h.shape,
        });
    };
    let size = match kind {
        Kind::F64 => Some(8),
        Kind::Utf32(w) => w.checked_mul(4),
        Kind::Bytes(w) => Some(w),
    };
    let start = c.pos;
    let count = h.shape.iter().try_fold(1u64, |n, &d| n.checked_mul(d));
    let need = count.and_then(|n| size.and_then(|s| n.checked_mul(s)));
    let (count, size) = match (count, size, need) {
        (Some(n), Some(s), Some(b)) if b <= c.remaining() as u64 => (n as usize, s as usize),
        _ => {
            return Err(ReadError::Truncated {
                file: c.file.to_string(),
                channel: Some(name.to_string()),
                offset: c.offset(),
                what: c.describe(
                    &format!("NPY data of shape {:?} {:?}", h.shape, h.descr),
                    start,
                ),
                need: need.unwrap_or(u64::MAX),
                available: c.remaining() as u64,
            })
        }
    };
    let bytes = c.take((count * size) as u64, "NPY data")?;
    // Fortran order: element k of the file is the one whose first index runs fastest;
    // its place in C order, from the C-order stride of each axis.
    // (with no element, no stride is needed: a zero dimension lets the others be anything)
    let fortran = h.fortran_order && h.shape.len() > 1 && count > 0;
    let dims: Vec<usize> = h.shape.iter().map(|&d| d as usize).collect();
    let mut c_strides = vec![1usize; dims.len()];
    if fortran {
        // each stride is at most the element count, which fits
        for a in (0..dims.len().saturating_sub(1)).rev() {
            c_strides[a] = c_strides[a + 1] * dims[a + 1];
        }
    }
    let row_major = |k: usize| -> usize {
        if !fortran {
            return k;
        }
        let (mut rest, mut index) = (k, 0);
        for (&d, &s) in dims.iter().zip(&c_strides) {
            index += (rest % d) * s;
            rest /= d;
        }
        index
    };
    let array = match kind {
        Kind::F64 => {
            let mut data = vec![0.0; count];
            for (k, b) in bytes.chunks_exact(8).enumerate() {
                let a: [u8; 8] = b.try_into().expect("8 bytes");
                data[row_major(k)] = match endian {
                    Endian::Little => f64::from_le_bytes(a),
                    Endian::Big => f64::from_be_bytes(a),
                };
            }
            Array::F64 {
                shape: h.shape,
                data,
            }
        }
        Kind::Utf32(_) | Kind::Bytes(_) => {
            let mut data = vec![String::new(); count];
            for (k, b) in bytes.chunks_exact(size).enumerate() {
                let at = start + k * size;
                let text = match kind {
                    Kind::Utf32(_) => {
                        let mut s = String::new();
                        for u in b.chunks_exact(4) {
                            let a: [u8; 4] = u.try_into().expect("4 bytes");
                            let v = match endian {
                                Endian::Little => u32::from_le_bytes(a),
                                Endian::Big => u32::from_be_bytes(a),
                            };
                            match char::from_u32(v) {
                                Some(ch) => s.push(ch),
                                None => {
                                    return Err(c.invalid_at(
                                        at,
                                        &format!("NPY string {k}"),
                                        format!("the code point {v:#x}"),
                                        "Unicode scalar values (UTF-32)",
                                    ))
                                }
                            }
                        }
                        s
                    }
                    _ => std::str::from_utf8(b)
                        .map_err(|_| c.not_utf8(at, &format!("NPY string {k}"), b))?
                        .to_string(),
                };
                data[row_major(k)] = text.trim_end_matches('\0').to_string();
            }
            Array::Text {
                shape: h.shape,
                data,
            }
        }
    };
    c.channel = None;
    Ok(array)
}

/// The magic, version and header of the array at the cursor, which is left at its first
/// element; with the header's position (for messages).
fn header(c: &mut Cursor) -> Result<(Header, usize), ReadError> {
    let magic = c.take(6, "NPY magic")?;
    if magic != MAGIC {
        return Err(c.invalid_at(0, "NPY magic", format!("{magic:02x?}"), "\\x93NUMPY"));
    }
    let major = c.u8("NPY major version")?;
    let _minor = c.u8("NPY minor version")?;
    let hlen = match major {
        1 => c.u16(Endian::Little, "NPY header length")? as u64,
        2 | 3 => c.u32(Endian::Little, "NPY header length")? as u64,
        v => return Err(c.invalid_at(6, "NPY major version", v, "1, 2 or 3")),
    };
    let hpos = c.pos;
    let header = c.utf8(hlen, "NPY header")?;
    let h = Header::parse(header).map_err(|e| {
        c.invalid_at(
            hpos,
            "NPY header",
            e,
            "a dict literal with 'descr', 'fortran_order' and 'shape'",
        )
    })?;
    Ok((h, hpos))
}

fn descr(d: &str) -> Option<(Dtype, Endian)> {
    let (order, t) = d.split_at_checked(1)?;
    let endian = match order {
        "<" | "|" | "=" => Endian::Little,
        ">" => Endian::Big,
        _ => return None,
    };
    let dtype = match t {
        "f8" => Dtype::F64,
        "f4" => Dtype::F32,
        "i1" => Dtype::I8,
        "u1" => Dtype::U8,
        "i2" => Dtype::I16,
        "u2" => Dtype::U16,
        "i4" => Dtype::I32,
        "u4" => Dtype::U32,
        "i8" => Dtype::I64,
        "u8" => Dtype::U64,
        _ => return None,
    };
    Some((dtype, endian))
}

/// The three keys of an NPY header.
#[derive(Debug, PartialEq)]
struct Header {
    descr: String,
    fortran_order: bool,
    shape: Vec<u64>,
}

/// A value of the header's dict literal.
#[derive(Debug)]
enum Lit {
    Str(String),
    Bool(bool),
    Int(u64),
    Tuple(Vec<Lit>),
}

impl Header {
    fn parse(s: &str) -> Result<Header, String> {
        let mut p = Lexer {
            s: s.as_bytes(),
            i: 0,
        };
        p.expect(b'{')?;
        let (mut descr, mut fortran, mut shape) = (None, None, None);
        loop {
            p.ws();
            if p.eat(b'}') {
                break;
            }
            let key = match p.value(0)? {
                Lit::Str(k) => k,
                other => return Err(format!("a key {other:?} that is not a string")),
            };
            p.ws();
            p.expect(b':')?;
            let v = p.value(0)?;
            match (key.as_str(), v) {
                ("descr", Lit::Str(d)) => descr = Some(d),
                ("fortran_order", Lit::Bool(b)) => fortran = Some(b),
                ("shape", Lit::Tuple(t)) => {
                    let dims = t
                        .into_iter()
                        .map(|d| match d {
                            Lit::Int(n) => Ok(n),
                            other => Err(format!("a shape entry {other:?}")),
                        })
                        .collect::<Result<Vec<_>, _>>()?;
                    shape = Some(dims)
                }
                (k @ ("descr" | "fortran_order" | "shape"), v) => {
                    return Err(format!("{k} = {v:?} (a structured or unusual dtype?)"))
                }
                _ => {}
            }
            p.ws();
            if !p.eat(b',') {
                p.ws();
                p.expect(b'}')?;
                break;
            }
        }
        Ok(Header {
            descr: descr.ok_or("no 'descr'")?,
            fortran_order: fortran.ok_or("no 'fortran_order'")?,
            shape: shape.ok_or("no 'shape'")?,
        })
    }
}

struct Lexer<'a> {
    s: &'a [u8],
    i: usize,
}

impl Lexer<'_> {
    fn ws(&mut self) {
        while self.s.get(self.i).is_some_and(|b| b.is_ascii_whitespace()) {
            self.i += 1;
        }
    }
    fn eat(&mut self, b: u8) -> bool {
        if self.s.get(self.i) == Some(&b) {
            self.i += 1;
            true
        } else {
            false
        }
    }
    fn expect(&mut self, b: u8) -> Result<(), String> {
        if self.eat(b) {
            Ok(())
        } else {
            Err(format!(
                "{:?} expected at header byte {}",
                b as char, self.i
            ))
        }
    }
    fn value(&mut self, depth: usize) -> Result<Lit, String> {
        if depth > 4 {
            return Err("nesting deeper than 4".into());
        }
        self.ws();
        let rest = &self.s[self.i.min(self.s.len())..];
        match rest.first() {
            Some(&q @ (b'\'' | b'"')) => {
                let end = rest[1..]
                    .iter()
                    .position(|&b| b == q || b == b'\\')
                    .ok_or("an unterminated string")?;
                if rest[1 + end] == b'\\' {
                    return Err("an escape in a string".into());
                }
                let v = String::from_utf8_lossy(&rest[1..1 + end]).into_owned();
                self.i += end + 2;
                Ok(Lit::Str(v))
            }
            Some(b'(') => {
                self.i += 1;
                let mut items = Vec::new();
                loop {
                    self.ws();
                    if self.eat(b')') {
                        return Ok(Lit::Tuple(items));
                    }
                    items.push(self.value(depth + 1)?);
                    self.ws();
                    if !self.eat(b',') {
                        self.ws();
                        self.expect(b')')?;
                        return Ok(Lit::Tuple(items));
                    }
                }
            }
            Some(b) if b.is_ascii_digit() => {
                let n = rest.iter().take_while(|b| b.is_ascii_digit()).count();
                let digits = std::str::from_utf8(&rest[..n]).map_err(|e| e.to_string())?;
                let v = digits
                    .parse::<u64>()
                    .map_err(|_| format!("a dimension {digits} beyond u64"))?;
                self.i += n;
                // Python 2 headers wrote `300L`.
                self.eat(b'L');
                Ok(Lit::Int(v))
            }
            _ if rest.starts_with(b"True") => {
                self.i += 4;
                Ok(Lit::Bool(true))
            }
            _ if rest.starts_with(b"False") => {
                self.i += 5;
                Ok(Lit::Bool(false))
            }
            _ => Err(format!(
                "an unexpected {:?} at header byte {}",
                String::from_utf8_lossy(&rest[..rest.len().min(12)]),
                self.i
            )),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_literal() {
        let h = Header::parse("{'descr': '>i2', 'fortran_order': True, 'shape': (3, 4), }   \n")
            .unwrap();
        assert_eq!(
            h,
            Header {
                descr: ">i2".into(),
                fortran_order: true,
                shape: vec![3, 4]
            }
        );
        let h = Header::parse("{'descr':'<f8','fortran_order':False,'shape':(7,)}").unwrap();
        assert_eq!(h.shape, vec![7]);
        assert!(
            Header::parse("{'descr': [('a', '<f8')], 'fortran_order': False, 'shape': (2,)}")
                .is_err()
        );
        assert!(Header::parse("{'descr': '<f8', 'shape': (2,)}").is_err());
        assert!(Header::parse("((((((((((((").is_err());
    }
}
