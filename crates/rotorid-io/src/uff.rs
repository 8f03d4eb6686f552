//! Universal File Format dataset 58 ("function at nodal DOF"), ASCII and binary (58b), in
//! `.uff`, `.unv` or `.58` files as modal and test software (Siemens Testlab, ME'scope,
//! pyuff) write them.
//!
//! Layout, after the SDRC/Siemens "Universal Dataset Number 58" description (as reproduced
//! in pyuff's `dataset_58.py`): a dataset is delimited by lines `    -1`; its first line is
//! the dataset number (`    58`, or `    58b` followed by the byte order (1 little, 2 big
//! endian), the floating-point format (2: IEEE 754), the number of ASCII header lines (11)
//! and the number of binary data bytes). Records 1-5 are ID lines (record 1 names the
//! channel here); record 6 the function type and nodes; record 7 (`3I10,3E13.5`) the
//! ordinate data type (2 real single, 4 real double, 5 complex single, 6 complex double),
//! the number of points, the abscissa spacing (1 even, 0 uneven), the abscissa minimum and
//! increment; records 8-11 (`I10,3I5,2(1X,20A1)`) the abscissa, ordinate numerator,
//! ordinate denominator and z-axis characteristics: a data type (abscissa: 17 time, 0
//! unknown), unit exponents, an axis label (columns 27-46) and a units label (columns
//! 48-67). Record 12 is the data: ASCII numbers (`E13.5` or `E20.12`, whitespace
//! separated, Fortran `D` exponents accepted) or, in 58b, the raw IEEE numbers.
//!
//! Each dataset 58 becomes a channel named by its ID line 1 (trimmed; a repeated name gets
//! `#2`, `#3`, ...), with unit the ordinate units label (`num/den` when the denominator has
//! one; `NONE` or blank is no unit) and the time axis start and increment \[s\] of record
//! 7. Other datasets (units 164, header 151, nodes 15/2411, ...) are skipped. Refused with an
//! error naming the channel and byte offset: complex data (FRFs: not a time record),
//! uneven abscissa spacing, an abscissa that is not time, a point count that differs from
//! the data, binary formats other than IEEE 754, non-UTF-8 header text.

use std::io::{BufRead, Read};

use crate::cursor::Cursor;
use crate::error::ReadError;
use crate::num::{Dtype, Endian};
use crate::table::{Channel, Table, TimeAxis};

/// Reads a UFF file's bytes; `file` names it in messages.
pub fn read(file: &str, bytes: &[u8]) -> Result<Table, ReadError> {
    read_from(file, bytes, bytes.len() as u64)
}

/// Reads the UFF file at `path` line by line (an ASCII record's values go straight into
/// its channel), a 58b record's binary data a block at a time: memory holds the channels,
/// a line and a block, never the whole file. Accepts and refuses what [`read`] does, with
/// the same messages.
pub fn read_file(file: &str, path: &std::path::Path) -> Result<Table, ReadError> {
    let disk = crate::source::DiskFile::open(file, path)?;
    let input = std::io::BufReader::with_capacity(1 << 16, disk.handle()?);
    read_from(file, input, disk.size)
}

/// Bytes of 58b binary data read at a time.
const BLOCK: u64 = 1 << 18;

/// The lines of a UFF file of `size` bytes read from `input`, with their file offsets; the
/// last line can be handed out again ([`Lines::unread`]). Errors name the file and the
/// channel being read.
struct Lines<'a, R> {
    file: &'a str,
    channel: Option<String>,
    input: R,
    size: u64,
    /// File offset of the next byte of `input`.
    pos: u64,
    /// The last line read, with its line end, and its offset.
    buf: Vec<u8>,
    at: u64,
    /// The last line is the next one.
    again: bool,
}

impl<'a, R: BufRead> Lines<'a, R> {
    /// Moves to the next line and returns its offset (the line is [`Lines::last`]); `None`
    /// at the end.
    fn next(&mut self) -> Result<Option<u64>, ReadError> {
        if !self.again {
            self.buf.clear();
            let n = self
                .input
                .read_until(b'\n', &mut self.buf)
                .map_err(|e| self.io(e))?;
            if n == 0 {
                return Ok(None);
            }
            self.at = self.pos;
            self.pos += n as u64;
        }
        self.again = false;
        Ok(Some(self.at))
    }

    /// The line [`Lines::next`] moved to, without `\n` or `\r\n`.
    fn last(&self) -> &[u8] {
        let l = self.buf.strip_suffix(b"\n").unwrap_or(&self.buf);
        l.strip_suffix(b"\r").unwrap_or(l)
    }

    /// Hands out the last line again.
    fn unread(&mut self) {
        self.again = true;
    }

    /// File offset of the next line.
    fn offset(&self) -> u64 {
        if self.again {
            self.at
        } else {
            self.pos
        }
    }

    fn remaining(&self) -> u64 {
        self.size.saturating_sub(self.offset())
    }

    fn io(&self, source: std::io::Error) -> ReadError {
        ReadError::Io {
            file: self.file.to_string(),
            source,
        }
    }

    /// Steps over `n` bytes (right after a line: none is to be handed out again).
    fn skip(&mut self, n: u64, what: &str) -> Result<(), ReadError> {
        if n > self.remaining() {
            return Err(self.truncated(what, n));
        }
        let got = std::io::copy(&mut (&mut self.input).take(n), &mut std::io::sink())
            .map_err(|e| self.io(e))?;
        self.pos += got;
        if got < n {
            return Err(self.io(std::io::ErrorKind::UnexpectedEof.into()));
        }
        Ok(())
    }

    /// `npts` values of `t` in byte order `e` (right after a line), for the channel.
    fn samples(&mut self, npts: u64, t: Dtype, e: Endian) -> Result<Vec<f64>, ReadError> {
        let size = t.size() as u64;
        let channel = self.channel.clone().unwrap_or_default();
        let nbytes = npts.saturating_mul(size);
        if nbytes > self.remaining() {
            return Err(self.truncated(&format!("{npts} samples of {t:?}"), nbytes));
        }
        let mut out = Vec::with_capacity(npts as usize);
        let mut block = Vec::new();
        let per = (BLOCK / size).max(1);
        let mut done = 0;
        while done < npts {
            let m = per.min(npts - done);
            block.resize((m * size) as usize, 0);
            self.input.read_exact(&mut block).map_err(|e| self.io(e))?;
            let c = Cursor {
                base: self.pos,
                ..Cursor::new(self.file, &block)
            };
            c.samples_into(0, m, size, t, e, &channel, &mut out)?;
            self.pos += m * size;
            done += m;
        }
        Ok(out)
    }

    /// The cursor's error for `need` bytes of `what` at the next line.
    fn truncated(&self, what: &str, need: u64) -> ReadError {
        ReadError::Truncated {
            file: self.file.to_string(),
            channel: self.channel.clone(),
            offset: self.offset(),
            what: what.to_string(),
            need,
            available: self.remaining(),
        }
    }

    fn invalid_at(
        &self,
        at: u64,
        what: &str,
        found: impl ToString,
        allowed: impl ToString,
    ) -> ReadError {
        ReadError::invalid(
            self.file,
            self.channel.clone(),
            at,
            what.to_string(),
            found,
            allowed,
        )
    }

    fn not_utf8(&self, at: u64, what: &str, b: &[u8]) -> ReadError {
        ReadError::NotUtf8 {
            file: self.file.to_string(),
            channel: self.channel.clone(),
            offset: at,
            what: what.to_string(),
            bytes: b.iter().take(16).copied().collect(),
        }
    }
}

/// Reads the datasets of `input`, a UFF file of `size` bytes.
fn read_from<R: BufRead>(file: &str, input: R, size: u64) -> Result<Table, ReadError> {
    let mut c = Lines {
        file,
        channel: None,
        input,
        size,
        pos: 0,
        buf: Vec::new(),
        at: 0,
        again: false,
    };
    let mut channels: Vec<Channel> = Vec::new();
    let mut other = Vec::new();
    // Find the next "-1" delimiter, skipping blank lines.
    while let Some(at) = c.next()? {
        let l = c.last();
        let t = trim(l);
        if t.is_empty() {
            continue;
        }
        if t != b"-1" {
            return Err(c.invalid_at(at, "UFF dataset delimiter", show(l), "a line \"    -1\""));
        }
        let hat = c
            .next()?
            .ok_or_else(|| c.truncated("UFF dataset number", 6))?;
        let head = c.last().to_vec();
        let num = trim(head.get(..6).unwrap_or(&head));
        let binary = head.get(6) == Some(&b'b');
        if num == b"-1" || num.is_empty() {
            // An empty dataset or a stray delimiter: the next line starts over.
            c.unread();
            continue;
        }
        if num == b"58" {
            let ch = dataset58(&mut c, hat, &head, binary)?;
            let mut name = ch.name.clone();
            let mut k = 1;
            while channels.iter().any(|x| x.name == name) {
                k += 1;
                name = format!("{}#{k}", ch.name);
            }
            channels.push(Channel { name, ..ch });
        } else {
            other.push(String::from_utf8_lossy(num).into_owned());
            skip_dataset(&mut c, hat, &head, binary)?;
        }
    }
    if channels.is_empty() {
        return Err(ReadError::NoChannels {
            file: file.to_string(),
            why: if other.is_empty() {
                "no UFF dataset".into()
            } else {
                format!("only datasets {}", other.join(", "))
            },
        });
    }
    Ok(Table {
        file: file.to_string(),
        channels,
        notes: Vec::new(),
    })
}

fn show(l: &[u8]) -> String {
    format!("{:?}", String::from_utf8_lossy(&l[..l.len().min(40)]))
}

fn trim(l: &[u8]) -> &[u8] {
    l.trim_ascii()
}

/// The 58b header fields after `58b`: byte order, float format, ASCII lines, data bytes.
fn binary_header<R: BufRead>(
    c: &Lines<R>,
    hat: u64,
    head: &[u8],
) -> Result<(Endian, u64, u64), ReadError> {
    let text = std::str::from_utf8(head.get(7..).unwrap_or(b""))
        .map_err(|_| c.not_utf8(hat, "UFF binary header", head))?;
    let f: Vec<u64> = text
        .split_whitespace()
        .take(4)
        .map(|w| w.parse::<u64>())
        .collect::<Result<_, _>>()
        .map_err(|_| {
            c.invalid_at(
                hat,
                "UFF binary header",
                show(head),
                "byte order, float format, ASCII line count, byte count as integers",
            )
        })?;
    if f.len() < 4 {
        return Err(c.invalid_at(
            hat,
            "UFF binary header",
            show(head),
            "byte order, float format, ASCII line count, byte count",
        ));
    }
    let e = match f[0] {
        1 => Endian::Little,
        2 => Endian::Big,
        o => {
            return Err(c.invalid_at(
                hat,
                "UFF binary byte order",
                o,
                "1 (little endian) or 2 (big endian)",
            ))
        }
    };
    if f[1] != 2 {
        return Err(c.invalid_at(
            hat,
            "UFF binary floating-point format",
            f[1],
            "2 (IEEE 754)",
        ));
    }
    Ok((e, f[2], f[3]))
}

/// Steps over a dataset other than 58, up to and including its closing `-1`.
fn skip_dataset<R: BufRead>(
    c: &mut Lines<R>,
    hat: u64,
    head: &[u8],
    binary: bool,
) -> Result<(), ReadError> {
    if binary {
        let (_, lines, nbytes) = binary_header(c, hat, head)?;
        for _ in 0..lines {
            c.next()?
                .ok_or_else(|| c.truncated("UFF binary dataset header line", 1))?;
        }
        c.skip(nbytes, "UFF binary dataset data")?;
    }
    while c.next()?.is_some() {
        if trim(c.last()) == b"-1" {
            return Ok(());
        }
    }
    Err(c.truncated("UFF closing \"    -1\"", 6))
}

/// A number, with a Fortran `D` exponent accepted.
fn parse_number(w: &str) -> Option<f64> {
    match w.parse::<f64>() {
        Ok(v) => Some(v),
        Err(_) if w.contains(['D', 'd']) => w.replace(['D', 'd'], "E").parse().ok(),
        Err(_) => None,
    }
}

fn field<'l, R: BufRead>(
    c: &Lines<R>,
    at: u64,
    l: &'l [u8],
    from: usize,
    to: usize,
    what: &str,
) -> Result<&'l str, ReadError> {
    let b = l.get(from.min(l.len())..to.min(l.len())).unwrap_or(b"");
    std::str::from_utf8(b)
        .map(str::trim)
        .map_err(|_| c.not_utf8(at + from as u64, what, b))
}

fn numbers<T: std::str::FromStr, R: BufRead>(
    c: &Lines<R>,
    at: u64,
    l: &[u8],
    n: usize,
    what: &str,
    allowed: &str,
) -> Result<Vec<T>, ReadError> {
    let text = std::str::from_utf8(l).map_err(|_| c.not_utf8(at, what, l))?;
    let v: Vec<T> = text
        .split_whitespace()
        .take(n)
        .map(|w| w.replace(['D', 'd'], "E").parse::<T>())
        .collect::<Result<_, _>>()
        .map_err(|_| c.invalid_at(at, what, show(l), allowed))?;
    if v.len() < n {
        return Err(c.invalid_at(at, what, show(l), allowed));
    }
    Ok(v)
}

fn units<R: BufRead>(
    c: &Lines<R>,
    at: u64,
    l: &[u8],
    what: &str,
) -> Result<Option<String>, ReadError> {
    let u = field(c, at, l, 47, 67, what)?;
    Ok((!u.is_empty() && !u.eq_ignore_ascii_case("NONE")).then(|| u.to_string()))
}

fn dataset58<R: BufRead>(
    c: &mut Lines<R>,
    hat: u64,
    head: &[u8],
    binary: bool,
) -> Result<Channel, ReadError> {
    let bin = if binary {
        Some(binary_header(c, hat, head)?)
    } else {
        None
    };
    if let Some((_, lines, _)) = bin {
        if lines != 11 {
            return Err(c.invalid_at(hat, "UFF 58b ASCII line count", lines, "11"));
        }
    }
    let mut rec = Vec::with_capacity(11);
    for k in 1..=11 {
        let at = c
            .next()?
            .ok_or_else(|| c.truncated(&format!("UFF 58 record {k}"), 1))?;
        rec.push((at, c.last().to_vec()));
    }
    let (at1, id1) = &rec[0];
    let mut name = field(c, *at1, id1, 0, 80, "UFF 58 ID line 1 (the channel name)")?.to_string();
    if name.is_empty() {
        name = format!("58@{hat}");
    }
    c.channel = Some(name.clone());
    let (at7, r7) = &rec[6];
    let at7 = *at7;
    let head7: Vec<f64> = numbers(
        c,
        at7,
        r7,
        5,
        "UFF 58 record 7",
        "ordinate type, point count, spacing, abscissa minimum and increment",
    )?;
    let (ord, npts, spacing, start, inc) = (head7[0], head7[1], head7[2], head7[3], head7[4]);
    let dtype = match ord as i64 {
        2 => Dtype::F32,
        4 => Dtype::F64,
        5 | 6 => {
            return Err(c.invalid_at(
                at7,
                "UFF 58 ordinate data type",
                format!("{ord} (complex)"),
                "2 or 4 (real single or double: a time record)",
            ))
        }
        _ => {
            return Err(c.invalid_at(
                at7,
                "UFF 58 ordinate data type",
                ord,
                "2 or 4 (real single or double)",
            ))
        }
    };
    if spacing != 1.0 {
        return Err(c.invalid_at(
            at7,
            "UFF 58 abscissa spacing",
            spacing,
            "1 (even; uneven abscissae are not read)",
        ));
    }
    if !(inc > 0.0 && inc.is_finite() && start.is_finite()) {
        return Err(c.invalid_at(
            at7,
            "UFF 58 abscissa increment",
            inc,
            "a positive finite number of seconds",
        ));
    }
    if !(npts >= 0.0 && npts.fract() == 0.0) {
        return Err(c.invalid_at(at7, "UFF 58 number of points", npts, "a whole number"));
    }
    let (at8, r8) = &rec[7];
    let xtype = field(c, *at8, r8, 0, 10, "UFF 58 abscissa data type")?;
    if !matches!(xtype, "0" | "17" | "") {
        return Err(c.invalid_at(
            *at8,
            "UFF 58 abscissa data type",
            xtype,
            "17 (time) or 0 (unknown)",
        ));
    }
    let (at9, r9) = &rec[8];
    let (at10, r10) = &rec[9];
    let unit = match (
        units(c, *at9, r9, "UFF 58 ordinate units")?,
        units(c, *at10, r10, "UFF 58 ordinate denominator units")?,
    ) {
        (Some(n), Some(d)) => Some(format!("{n}/{d}")),
        (n, _) => n,
    };
    let npts = npts as u64;
    let data = match bin {
        Some((e, _, nbytes)) => {
            let size = dtype.size() as u64;
            if npts.checked_mul(size) != Some(nbytes) {
                return Err(c.invalid_at(
                    hat,
                    "UFF 58b byte count",
                    nbytes,
                    format!("{npts} points of {size} bytes"),
                ));
            }
            c.samples(npts, dtype, e)?
        }
        None => {
            let at = c.offset();
            if npts > c.remaining() / 2 {
                return Err(c.truncated(
                    &format!("UFF 58 data of {npts} points"),
                    npts.saturating_mul(2),
                ));
            }
            // At most one value per two bytes left, checked above.
            let mut d = Vec::with_capacity(npts as usize);
            loop {
                let lat = c
                    .next()?
                    .ok_or_else(|| c.truncated("UFF closing \"    -1\"", 6))?;
                let l = c.last();
                if trim(l) == b"-1" {
                    c.unread();
                    break;
                }
                let text = std::str::from_utf8(l).map_err(|_| c.not_utf8(lat, "UFF 58 data", l))?;
                for w in text.split_whitespace() {
                    let v = parse_number(w).ok_or_else(|| {
                        c.invalid_at(lat, "UFF 58 data value", format!("{w:?}"), "a number")
                    })?;
                    // Single precision data was written from f32 values.
                    d.push(v);
                    if d.len() as u64 > npts {
                        return Err(c.invalid_at(
                            at,
                            "UFF 58 data",
                            "more values than points",
                            format!("{npts} points"),
                        ));
                    }
                }
            }
            if d.len() as u64 != npts {
                return Err(c.invalid_at(
                    at,
                    "UFF 58 data",
                    format!("{} values", d.len()),
                    format!("{npts} points"),
                ));
            }
            d
        }
    };
    // The closing delimiter, possibly after the newline ending the binary data.
    loop {
        let lat = c
            .next()?
            .ok_or_else(|| c.truncated("UFF closing \"    -1\"", 6))?;
        let l = c.last();
        match trim(l) {
            b"" => continue,
            b"-1" => break,
            _ => {
                return Err(c.invalid_at(
                    lat,
                    "UFF 58 end",
                    show(l),
                    "a line \"    -1\" after the data",
                ))
            }
        }
    }
    c.channel = None;
    Ok(Channel {
        name,
        unit,
        data,
        axis: Some(TimeAxis {
            start,
            increment: inc,
        }),
    })
}
