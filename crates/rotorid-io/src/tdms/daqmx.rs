//! DAQmx raw data in TDMS files, as NI-DAQmx writes it when it logs a task to disk (TDMS
//! logging, "log" and "log and read" modes): the samples are stored as the devices deliver
//! them, integers in the devices' own format, and the channel's properties say how they
//! become values (see [`super::scaling`]). Layout as npTDMS reads it (`nptdms/daqmx.py`;
//! NI documents only its existence):
//!
//! - an object's raw data index is `0x00001269` (a format-changing scaler; `0x0000126A`, a
//!   digital line scaler, is refused: digital lines are not probe signals), followed by the
//!   channel's data type (`0xFFFFFFFF`: DAQmx raw data, whose values are its scalers';
//!   otherwise a TDMS type, and the channel's values are its one scaler's), the dimension
//!   (1), the values per chunk, the scalers, each `(DAQmx type, raw buffer, byte offset in
//!   the buffer's row, sample format bitmap, scale id)` as five `u32`, and the widths in
//!   bytes of the raw buffers (one per device), the same for every object of the segment;
//! - a chunk of the raw data is each buffer in turn (buffer 0 first), as rows of its width:
//!   row r holds sample r of every scaler in that buffer, at the scaler's byte offset. A
//!   buffer has as many rows as the largest value count among the objects with a scaler in
//!   it;
//! - the segment's table of contents may lack `kTocDAQmxRawData` (npTDMS issue 226): the
//!   objects' indexes decide. DAQmx and plain raw data in one segment are refused.
//!
//! DAQmx type codes differ from TDMS ones: 0 `u8`, 1 `i8`, 2 `u16`, 3 `i16`, 4 `u32`,
//! 5 `i32`, 6 `u64`, 7 `i64`, 8 `f32`, 9 `f64`, `0xFFFFFFFF` timestamp (stepped over).

use crate::cursor::Cursor;
use crate::error::ReadError;
use crate::num::{Dtype, Endian};

/// The raw data index of a format-changing scaler.
pub(super) const FORMAT_CHANGING: u32 = 0x0000_1269;
/// The raw data index of a digital line scaler.
pub(super) const DIGITAL_LINE: u32 = 0x0000_126A;
/// The channel data type of DAQmx raw data.
const RAW_TYPE: u32 = 0xFFFF_FFFF;

/// One scaler: where its values lie in a chunk, and their type.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Scaler {
    /// `None` for a type that is stepped over (timestamps).
    pub dtype: Option<Dtype>,
    /// Bytes per value.
    pub size: u32,
    pub buffer: u32,
    /// Byte offset within a row of the buffer.
    pub offset: u32,
    /// The scale id the channel's scales name it by.
    pub id: u32,
}

/// A DAQmx raw data index.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct Index {
    /// Values per chunk.
    pub count: u64,
    pub scalers: Vec<Scaler>,
    /// Bytes per row of each raw buffer.
    pub widths: Vec<u32>,
    /// DAQmx raw data (`0xFFFFFFFF`): the values are the scalers'; else the channel's
    /// values are its one scaler's.
    pub raw: bool,
}

impl Index {
    /// Whether the channel has numbers to read.
    pub(super) fn numeric(&self) -> bool {
        self.scalers.iter().any(|s| s.dtype.is_some())
    }
}

fn daqmx_type(code: u32) -> Option<(Option<Dtype>, u32)> {
    Some(match code {
        0 => (Some(Dtype::U8), 1),
        1 => (Some(Dtype::I8), 1),
        2 => (Some(Dtype::U16), 2),
        3 => (Some(Dtype::I16), 2),
        4 => (Some(Dtype::U32), 4),
        5 => (Some(Dtype::I32), 4),
        6 => (Some(Dtype::U64), 8),
        7 => (Some(Dtype::I64), 8),
        8 => (Some(Dtype::F32), 4),
        9 => (Some(Dtype::F64), 8),
        0xFFFF_FFFF => (None, 16),
        _ => return None,
    })
}

/// The DAQmx index after its header (read by the caller at `iat`, `header`): everything
/// up to and including the raw buffer widths.
pub(super) fn index(
    c: &mut Cursor,
    e: Endian,
    iat: usize,
    header: u32,
) -> Result<Index, ReadError> {
    if header == DIGITAL_LINE {
        return Err(c.invalid_at(
            iat,
            "TDMS raw data index",
            format!("{header:#010x} (DAQmx digital line data)"),
            "plain or DAQmx format-changing (0x00001269) raw data: digital lines are not read",
        ));
    }
    let tat = c.pos;
    let channel_type = c.u32(e, "TDMS DAQmx data type")?;
    let channel = if channel_type == RAW_TYPE {
        None
    } else {
        let (dtype, _) = super::data_type(channel_type).map_err(|_| {
            c.invalid_at(
                tat,
                "TDMS DAQmx data type",
                format!("{channel_type:#x}"),
                format!("0xffffffff (DAQmx raw data) or {}", super::TYPES),
            )
        })?;
        Some(dtype)
    };
    let dim = c.u32(e, "TDMS array dimension")?;
    if dim != 1 {
        return Err(c.invalid_at(tat + 4, "TDMS array dimension", dim, "1"));
    }
    let count = c.u64(e, "TDMS DAQmx values per chunk")?;
    let n = c.u32(e, "TDMS DAQmx scaler count")?;
    let mut scalers = Vec::new();
    let mut at = Vec::new();
    for _ in 0..n {
        let sat = c.pos;
        let code = c.u32(e, "TDMS DAQmx scaler data type")?;
        let (dtype, size) = daqmx_type(code).ok_or_else(|| {
            c.invalid_at(
                sat,
                "TDMS DAQmx scaler data type",
                code,
                "0 to 9 (u8, i8, u16, i16, u32, i32, u64, i64, f32, f64) or 0xffffffff",
            )
        })?;
        let buffer = c.u32(e, "TDMS DAQmx raw buffer index")?;
        let offset = c.u32(e, "TDMS DAQmx raw byte offset")?;
        c.u32(e, "TDMS DAQmx sample format bitmap")?;
        let id = c.u32(e, "TDMS DAQmx scale id")?;
        scalers.push(Scaler {
            dtype,
            size,
            buffer,
            offset,
            id,
        });
        at.push(sat);
    }
    let nw = c.u32(e, "TDMS DAQmx raw buffer count")?;
    let mut widths = Vec::new();
    for _ in 0..nw {
        widths.push(c.u32(e, "TDMS DAQmx raw buffer width")?);
    }
    for (s, &sat) in scalers.iter().zip(&at) {
        let size = s.size;
        let fits = widths
            .get(s.buffer as usize)
            .is_some_and(|&w| u64::from(s.offset) + u64::from(size) <= u64::from(w));
        if !fits {
            return Err(c.invalid_at(
                sat,
                "TDMS DAQmx scaler",
                format!(
                    "{size}-byte values at byte {} of raw buffer {}",
                    s.offset, s.buffer
                ),
                format!(
                    "values within a row of one of the {nw} raw buffers (widths {widths:?} \
                     bytes)"
                ),
            ));
        }
    }
    if let Some(dtype) = channel {
        // The channel holds its one scaler's values: they must be of its type.
        if scalers.len() != 1 || scalers[0].dtype != dtype {
            return Err(c.invalid_at(
                tat,
                "TDMS DAQmx data type",
                format!(
                    "{channel_type:#x} with {} scaler(s) of type(s) {:?}",
                    scalers.len(),
                    scalers.iter().map(|s| s.dtype).collect::<Vec<_>>()
                ),
                "one scaler of the channel's own type (or 0xffffffff, DAQmx raw data)",
            ));
        }
    }
    Ok(Index {
        count,
        scalers,
        widths,
        raw: channel.is_none(),
    })
}
