//! The response CSV: the rotor's measured or simulated vibration, one row per sample.
//!
//! ```text
//! t,x,z,phi,phi_dot,phi_ddot
//! s,m,m,rad,rad/s,rad/s^2          (units, not written: SI throughout)
//! ```
//!
//! Written by `rotorid simulate` ([`ResponseWriter`]) with exactly that header, every value
//! in shortest round-trip form (see [`super::number`]). Read by `rotorid identify`,
//! `rotorid plot` and `rotorid balance` ([`ResponseReader`], streaming): the reader is
//! `rotorid_io::csv::ResponseReader` (its module doc has the rules), wrapped here to give
//! the library's [`SpeedState`].

use std::io::{self, Read, Write};

use rotorid::SpeedState;
use rotorid_io::csv::number::write_row;
use rotorid_io::csv::CsvError;
pub use rotorid_io::csv::RESPONSE_HEADER;

/// Writes the response CSV, one sample per row (see the module doc).
pub struct ResponseWriter<W: Write> {
    out: W,
    scratch: Vec<u8>,
}

impl<W: Write> ResponseWriter<W> {
    /// Write the header `t,x,z,phi,phi_dot,phi_ddot` to `out`.
    pub fn new(mut out: W) -> io::Result<Self> {
        writeln!(out, "{}", RESPONSE_HEADER.join(","))?;
        Ok(Self {
            out,
            scratch: Vec::with_capacity(160),
        })
    }

    /// One row: t [s], x [m], z [m], and phi [rad], w [rad/s], w' [rad/s^2] from `speed`.
    pub fn write(&mut self, t: f64, x: f64, z: f64, speed: &SpeedState) -> io::Result<()> {
        write_row(
            &mut self.out,
            &mut self.scratch,
            &[
                Some(t),
                Some(x),
                Some(z),
                Some(speed.phi),
                Some(speed.omega),
                Some(speed.omega_dot),
            ],
        )
    }

    /// The underlying writer (not flushed).
    pub fn into_inner(self) -> W {
        self.out
    }
}

/// One validated row of a response CSV.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ResponseRow {
    /// 1-based line in the file.
    pub line: u64,
    /// Time t [s].
    pub t: f64,
    /// Horizontal displacement x [m].
    pub x: f64,
    /// Vertical displacement z [m].
    pub z: f64,
    /// phi [rad], w = phi_dot [rad/s], w' = phi_ddot [rad/s^2], when the file has them.
    pub speed: Option<SpeedState>,
}

/// Streaming reader of a response CSV (`rotorid_io::csv::ResponseReader`), rows with the
/// library's [`SpeedState`].
pub struct ResponseReader<R: Read>(rotorid_io::csv::ResponseReader<R>);

impl<R: Read> ResponseReader<R> {
    /// Read and check the header of `input`; `file` names it in messages.
    pub fn new(file: &str, input: R) -> Result<Self, CsvError> {
        rotorid_io::csv::ResponseReader::new(file, input).map(Self)
    }

    /// True when the file has the phi, phi_dot, phi_ddot columns.
    pub fn has_phi(&self) -> bool {
        self.0.has_phi()
    }

    /// Print `note: FILE: x in um, converted to m (x 1e-6)` on stderr for each column the
    /// reader converts to SI (nothing for a file in SI): the numbers the run works on are
    /// not the file's, and the user is told so.
    pub fn print_conversions(&self) {
        for note in self.0.conversion_notes() {
            eprintln!("note: {note}");
        }
    }

    /// The next validated row, or `None` at the end of the input.
    pub fn next_row(&mut self) -> Result<Option<ResponseRow>, CsvError> {
        Ok(self.0.next_row()?.map(|r| ResponseRow {
            line: r.line,
            t: r.t,
            x: r.x,
            z: r.z,
            speed: r.speed.map(|s| SpeedState {
                phi: s.phi,
                omega: s.phi_dot,
                omega_dot: s.phi_ddot,
            }),
        }))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_all(text: &str) -> Result<Vec<ResponseRow>, CsvError> {
        let mut r = ResponseReader::new("d.csv", text.as_bytes())?;
        let mut rows = Vec::new();
        while let Some(row) = r.next_row()? {
            rows.push(row);
        }
        Ok(rows)
    }

    #[test]
    fn written_rows_read_back_identically() {
        let mut w = ResponseWriter::new(Vec::new()).unwrap();
        let s = SpeedState {
            phi: 0.1,
            omega: 125.66370614359172,
            omega_dot: 0.0,
        };
        let dt = 1e-4;
        let mut expect = Vec::new();
        for i in 0..5u32 {
            let t = f64::from(i) * dt;
            let (x, z) = (1.234_567_890_123e-7 * f64::from(i), -3.3e-300);
            w.write(t, x, z, &s).unwrap();
            expect.push((t, x, z));
        }
        let text = String::from_utf8(w.into_inner()).unwrap();
        assert!(text.starts_with("t,x,z,phi,phi_dot,phi_ddot\n0,0,-3.3e-300,0.1,"));
        let rows = read_all(&text).unwrap();
        assert_eq!(rows.len(), 5);
        for (r, (t, x, z)) in rows.iter().zip(expect) {
            assert_eq!((r.t, r.x, r.z), (t, x, z));
            assert_eq!(r.speed, Some(s));
        }
        assert_eq!(rows[2].line, 4);
    }
}
