//! Bounds-checked reading of a byte buffer: every length is compared with what remains
//! before anything is sliced or allocated, so a hostile length field yields
//! [`ReadError::Truncated`] instead of a panic or a huge allocation.

use crate::error::ReadError;
use crate::num::Endian;

/// A position in a buffer that is the file itself, or the decompressed bytes of one of its
/// elements (then `inflated` holds the element's file offset, and errors say so).
#[derive(Clone)]
pub(crate) struct Cursor<'a> {
    pub file: &'a str,
    pub data: &'a [u8],
    pub pos: usize,
    /// File offset of `data[0]` for a slice of the file.
    pub base: u64,
    /// `Some(offset)` when `data` is the decompressed content of the element at `offset`.
    pub inflated: Option<u64>,
    pub channel: Option<String>,
}

impl<'a> Cursor<'a> {
    pub fn new(file: &'a str, data: &'a [u8]) -> Self {
        Cursor {
            file,
            data,
            pos: 0,
            base: 0,
            inflated: None,
            channel: None,
        }
    }

    /// A cursor over decompressed bytes of the element at file offset `at`.
    pub fn inflated(file: &'a str, data: &'a [u8], at: u64) -> Self {
        Cursor {
            inflated: Some(at),
            ..Cursor::new(file, data)
        }
    }

    pub fn remaining(&self) -> usize {
        self.data.len() - self.pos
    }

    pub fn at_end(&self) -> bool {
        self.pos >= self.data.len()
    }

    /// File offset of byte `pos` (that of the compressed element when inflated).
    pub fn offset_of(&self, pos: usize) -> u64 {
        match self.inflated {
            Some(at) => at,
            None => self.base + pos as u64,
        }
    }

    pub fn offset(&self) -> u64 {
        self.offset_of(self.pos)
    }

    /// `what`, plus where in the decompressed bytes when inflated.
    pub fn describe(&self, what: &str, pos: usize) -> String {
        match self.inflated {
            Some(_) => format!("{what} (decompressed byte {pos} of the compressed element)"),
            None => what.to_string(),
        }
    }

    pub fn truncated(&self, what: &str, need: u64) -> ReadError {
        ReadError::Truncated {
            file: self.file.to_string(),
            channel: self.channel.clone(),
            offset: self.offset(),
            what: self.describe(what, self.pos),
            need,
            available: self.remaining() as u64,
        }
    }

    pub fn invalid_at(
        &self,
        pos: usize,
        what: &str,
        found: impl ToString,
        allowed: impl ToString,
    ) -> ReadError {
        ReadError::invalid(
            self.file,
            self.channel.clone(),
            self.offset_of(pos),
            self.describe(what, pos),
            found,
            allowed,
        )
    }

    pub fn invalid(&self, what: &str, found: impl ToString, allowed: impl ToString) -> ReadError {
        self.invalid_at(self.pos, what, found, allowed)
    }

    /// The next `n` bytes (`n` may come from the file: it is checked first).
    pub fn take(&mut self, n: u64, what: &str) -> Result<&'a [u8], ReadError> {
        if n > self.remaining() as u64 {
            return Err(self.truncated(what, n));
        }
        let n = n as usize;
        let s = &self.data[self.pos..self.pos + n];
        self.pos += n;
        Ok(s)
    }

    pub fn skip(&mut self, n: u64, what: &str) -> Result<(), ReadError> {
        self.take(n, what).map(|_| ())
    }

    pub fn array<const N: usize>(&mut self, what: &str) -> Result<[u8; N], ReadError> {
        let s = self.take(N as u64, what)?;
        let mut a = [0u8; N];
        a.copy_from_slice(s);
        Ok(a)
    }

    pub fn u8(&mut self, what: &str) -> Result<u8, ReadError> {
        Ok(self.array::<1>(what)?[0])
    }

    pub fn u16(&mut self, e: Endian, what: &str) -> Result<u16, ReadError> {
        let a = self.array(what)?;
        Ok(match e {
            Endian::Little => u16::from_le_bytes(a),
            Endian::Big => u16::from_be_bytes(a),
        })
    }

    pub fn u32(&mut self, e: Endian, what: &str) -> Result<u32, ReadError> {
        let a = self.array(what)?;
        Ok(match e {
            Endian::Little => u32::from_le_bytes(a),
            Endian::Big => u32::from_be_bytes(a),
        })
    }

    pub fn i32(&mut self, e: Endian, what: &str) -> Result<i32, ReadError> {
        Ok(self.u32(e, what)? as i32)
    }

    pub fn u64(&mut self, e: Endian, what: &str) -> Result<u64, ReadError> {
        let a = self.array(what)?;
        Ok(match e {
            Endian::Little => u64::from_le_bytes(a),
            Endian::Big => u64::from_be_bytes(a),
        })
    }

    /// `n` bytes of UTF-8 text.
    pub fn utf8(&mut self, n: u64, what: &str) -> Result<&'a str, ReadError> {
        let at = self.pos;
        let b = self.take(n, what)?;
        std::str::from_utf8(b).map_err(|_| self.not_utf8(at, what, b))
    }

    pub fn not_utf8(&self, pos: usize, what: &str, b: &[u8]) -> ReadError {
        ReadError::NotUtf8 {
            file: self.file.to_string(),
            channel: self.channel.clone(),
            offset: self.offset_of(pos),
            what: self.describe(what, pos),
            bytes: b.iter().take(16).copied().collect(),
        }
    }
}
