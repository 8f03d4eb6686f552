//! What the fuzz targets share: the CSV readers (the response reader and its pieces are
//! `rotorid-io`'s; the estimates reader is compiled from the CLI's source, the CLI being a
//! binary crate), and a decoder of fuzz input into f64 values.
//!
//! The CLI modules are included as they are in `crates/rotorid-cli/src/io/`, at this
//! crate's root, so their `super::` paths resolve here.

#![allow(dead_code, unused_imports)]

pub use rotorid_io::csv::{
    columns, error as csv_error, lines, number, records, response as response_csv,
};

#[path = "../../crates/rotorid-cli/src/io/estimates_csv.rs"]
pub mod estimates_csv;
#[path = "../../crates/rotorid-cli/src/io/params.rs"]
pub mod params;

/// Reads fuzz input as a sequence of values, never running dry (zeros after the end).
pub struct Values<'a> {
    data: &'a [u8],
}

impl<'a> Values<'a> {
    /// Values from `data`.
    pub fn new(data: &'a [u8]) -> Self {
        Self { data }
    }

    /// True when every byte has been used.
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }

    /// The next byte (0 after the end).
    pub fn byte(&mut self) -> u8 {
        match self.data.split_first() {
            Some((b, rest)) => {
                self.data = rest;
                *b
            }
            None => 0,
        }
    }

    /// The next f64: a tag byte picks a raw bit pattern (any NaN, infinity, subnormal),
    /// a small integer, or a value of ordinary magnitude, so both the edges and the
    /// ordinary paths are reached.
    pub fn f64(&mut self) -> f64 {
        match self.byte() % 4 {
            0 => {
                let mut b = [0u8; 8];
                for x in &mut b {
                    *x = self.byte();
                }
                f64::from_le_bytes(b)
            }
            1 => f64::from(self.byte() as i8),
            _ => {
                let m = f64::from(u16::from_le_bytes([self.byte(), self.byte()])) / 65536.0;
                let e = i32::from(self.byte() as i8 % 16);
                (m - 0.5) * 2f64.powi(e)
            }
        }
    }
}
