//! Numeric element types shared by the binary readers, and their exact conversion to `f64`.
//!
//! Every integer type up to 32 bits and both float types convert exactly. A 64-bit integer
//! converts only when `f64` holds it exactly (always for magnitudes up to 2^53); otherwise
//! the read fails with [`ReadError::InexactInteger`] rather than rounding silently.
//! Non-finite floats (NaN, ±inf) pass through as data: the readers do not judge samples,
//! the identification pipeline checks finiteness.

use crate::cursor::Cursor;
use crate::error::ReadError;
use crate::source::Source;

/// Byte order.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Endian {
    /// Least significant byte first.
    Little,
    /// Most significant byte first.
    Big,
}

/// A numeric element type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dtype {
    /// `i8`
    I8,
    /// `u8`
    U8,
    /// `i16`
    I16,
    /// `u16`
    U16,
    /// `i32`
    I32,
    /// `u32`
    U32,
    /// `i64`
    I64,
    /// `u64`
    U64,
    /// `f32`
    F32,
    /// `f64`
    F64,
}

impl Dtype {
    /// Bytes per element.
    pub fn size(self) -> usize {
        match self {
            Dtype::I8 | Dtype::U8 => 1,
            Dtype::I16 | Dtype::U16 => 2,
            Dtype::I32 | Dtype::U32 | Dtype::F32 => 4,
            Dtype::I64 | Dtype::U64 | Dtype::F64 => 8,
        }
    }
}

/// An integer that `f64` cannot hold exactly, at sample `index`.
pub(crate) struct Inexact {
    pub index: usize,
    pub value: i128,
}

fn exact(v: i128, index: usize) -> Result<f64, Inexact> {
    let f = v as f64;
    // `f as i128` is exact for every f64 of magnitude below 2^127, which covers i64 and u64.
    if f as i128 == v {
        Ok(f)
    } else {
        Err(Inexact { index, value: v })
    }
}

/// Decodes `count` elements of `N` bytes, the first at `data[start]`, one every `stride`
/// bytes, by `conv` of their bytes in little-endian order, onto the end of `out`. One small
/// function per element type (rather than one large match around the loops), so that the
/// compiler inlines `Vec::extend` into each and the loop stays a tight one whatever else
/// the crate holds: the elements' bytes as one slice cut into strides, no bounds check per
/// element, and contiguous little-endian data compiles to little more than a copy.
#[inline(never)]
fn decode<const N: usize, T>(
    data: &[u8],
    start: usize,
    count: usize,
    stride: usize,
    e: Endian,
    out: &mut Vec<T>,
    conv: impl Fn([u8; N]) -> T,
) {
    let convert = |bytes: &[u8]| {
        let mut a: [u8; N] = bytes[..N].try_into().expect("an element's bytes");
        if e == Endian::Big {
            a.reverse();
        }
        conv(a)
    };
    match count {
        0 => {}
        count if stride == N => {
            out.extend(data[start..start + count * N].chunks_exact(N).map(convert))
        }
        count if stride > N => out.extend(
            data[start..start + (count - 1) * stride + N]
                .chunks(stride)
                .map(convert),
        ),
        count => out.extend((0..count).map(|i| {
            let o = start + i * stride;
            convert(&data[o..o + N])
        })),
    }
}

/// Decodes `count` elements of type `t`, the first at `data[start]`, one every `stride`
/// bytes, onto the end of `out`. The caller has checked that they lie within `data`. A
/// 64-bit integer `f64` cannot hold is named by its index among the `count` (what was
/// decoded before it stays in `out`).
fn gather(
    data: &[u8],
    start: usize,
    count: usize,
    stride: usize,
    t: Dtype,
    e: Endian,
    out: &mut Vec<f64>,
) -> Result<(), Inexact> {
    out.reserve(count);
    let (d, s, c) = (data, start, count);
    match t {
        Dtype::I8 => decode(d, s, c, stride, e, out, |a: [u8; 1]| a[0] as i8 as f64),
        Dtype::U8 => decode(d, s, c, stride, e, out, |a: [u8; 1]| a[0] as f64),
        Dtype::I16 => decode(d, s, c, stride, e, out, |a| i16::from_le_bytes(a) as f64),
        Dtype::U16 => decode(d, s, c, stride, e, out, |a| u16::from_le_bytes(a) as f64),
        Dtype::I32 => decode(d, s, c, stride, e, out, |a| i32::from_le_bytes(a) as f64),
        Dtype::U32 => decode(d, s, c, stride, e, out, |a| u32::from_le_bytes(a) as f64),
        Dtype::F32 => decode(d, s, c, stride, e, out, |a| f32::from_le_bytes(a) as f64),
        Dtype::F64 => decode(d, s, c, stride, e, out, f64::from_le_bytes),
        Dtype::I64 | Dtype::U64 => {
            let mut wide: Vec<i128> = Vec::with_capacity(count);
            if t == Dtype::I64 {
                decode(d, s, c, stride, e, &mut wide, |a| {
                    i64::from_le_bytes(a) as i128
                });
            } else {
                decode(d, s, c, stride, e, &mut wide, |a| {
                    u64::from_le_bytes(a) as i128
                });
            }
            for (index, v) in wide.into_iter().enumerate() {
                out.push(exact(v, index)?);
            }
        }
    }
    Ok(())
}

impl Cursor<'_> {
    /// Decodes `count` elements of type `t` starting at buffer position `start`, one every
    /// `stride` bytes, for `channel`. Checks the extent against the buffer before
    /// allocating.
    pub(crate) fn samples(
        &self,
        start: usize,
        count: u64,
        stride: u64,
        t: Dtype,
        e: Endian,
        channel: &str,
    ) -> Result<Vec<f64>, ReadError> {
        let mut out = Vec::new();
        self.samples_into(start, count, stride, t, e, channel, &mut out)?;
        Ok(out)
    }

    /// [`samples`](Self::samples) onto the end of `out` (on an error, what was decoded
    /// before the failing element stays there).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn samples_into(
        &self,
        start: usize,
        count: u64,
        stride: u64,
        t: Dtype,
        e: Endian,
        channel: &str,
        out: &mut Vec<f64>,
    ) -> Result<(), ReadError> {
        let size = t.size() as u64;
        let need = match count {
            0 => Some(0),
            // Never fewer bytes than `count` whole elements, whatever the stride: the
            // allocation below is then bounded by the buffer.
            n => (n - 1)
                .checked_mul(stride.max(size))
                .and_then(|x| x.checked_add(size)),
        };
        let avail = self.data.len().saturating_sub(start) as u64;
        match need {
            Some(n) if n <= avail => {}
            other => {
                return Err(ReadError::Truncated {
                    file: self.file.to_string(),
                    channel: Some(channel.to_string()),
                    offset: self.offset_of(start),
                    what: self.describe(&format!("{count} samples of {t:?}"), start),
                    need: other.unwrap_or(u64::MAX),
                    available: avail,
                })
            }
        }
        gather(self.data, start, count as usize, stride as usize, t, e, out).map_err(|x| {
            ReadError::InexactInteger {
                file: self.file.to_string(),
                channel: channel.to_string(),
                index: x.index,
                offset: self.offset_of(start + x.index * stride as usize),
                value: x.value,
            }
        })
    }
}

/// `n` values of `t` in byte order `e` of `channel` at byte `at` of `src` (the file `file`),
/// one every `stride` bytes, read in one piece through `scratch` and appended to `out`; the
/// values are numbers `first..first + n` of the channel, counted from its first value in the
/// file (as a [`ReadError::InexactInteger`] names them).
#[allow(clippy::too_many_arguments)]
pub(crate) fn samples_at<S: Source + ?Sized>(
    src: &S,
    file: &str,
    channel: &str,
    at: u64,
    first: u64,
    n: u64,
    stride: u64,
    t: Dtype,
    e: Endian,
    scratch: &mut Vec<u8>,
    out: &mut Vec<f64>,
) -> Result<(), ReadError> {
    let len = n.saturating_sub(1) * stride + t.size() as u64;
    let buf = src.read_at_reusing(at, len, scratch)?;
    let c = Cursor {
        base: at,
        ..Cursor::new(file, buf)
    };
    c.samples_into(0, n, stride, t, e, channel, out)
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
