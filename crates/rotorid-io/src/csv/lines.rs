//! Physical lines of a text input: their numbers, and a cap on their length.
//!
//! [`LineReader`] sits between an input and the CSV parser. It
//!
//! - numbers lines as an editor does: a line ends at LF, at CRLF or at a lone CR (old Mac
//!   files), so the first data row of any of them is line 2 (the `csv` crate's own counter
//!   only counts LF: it calls every line of a CR-only file line 1, and is one short after
//!   a CRLF header);
//! - hands the parser at most one line per `read`, so that when the parser returns a
//!   record, the reader knows the line the record began on ([`LineReader::record_line`]
//!   after [`LineReader::mark`]);
//! - refuses a line longer than [`MAX_LINE_BYTES`] with [`LineTooLong`]: a file without
//!   line ends (a binary file, `/dev/zero`, a stream that never sends a newline) then costs
//!   at most the cap in memory instead of growing one record without bound.

use std::fmt;
use std::io::{self, BufRead, BufReader, Read};

/// The longest line accepted, terminator excluded: 1 MiB. A response row is ~120 bytes and
/// a header with a hundred extra columns a few KiB, so only a file that is not line-based
/// text comes near it.
pub const MAX_LINE_BYTES: usize = 1 << 20;

/// The error of a line longer than the cap (carried inside an `io::Error` of kind
/// `InvalidData`, so it travels through the CSV parser).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LineTooLong {
    /// 1-based number of the line.
    pub line: u64,
    /// The cap it exceeded, in bytes.
    pub cap: usize,
}

impl fmt::Display for LineTooLong {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "line {} is longer than {} bytes, the most one line may hold",
            self.line, self.cap
        )
    }
}

impl std::error::Error for LineTooLong {}

/// A reader that numbers lines and caps their length (module doc).
pub struct LineReader<R> {
    inner: BufReader<R>,
    cap: usize,
    /// Number of the line the next byte handed out belongs to.
    line: u64,
    /// Bytes of the current line handed out so far (terminator excluded).
    line_len: usize,
    /// The last byte handed out was a CR: an LF right after it ends the same line.
    after_cr: bool,
    /// Line of the first byte other than a line end handed out since [`Self::mark`].
    first_content: Option<u64>,
}

impl<R: Read> LineReader<R> {
    /// Wrap `inner` with the cap [`MAX_LINE_BYTES`].
    pub fn new(inner: R) -> Self {
        Self::with_cap(inner, MAX_LINE_BYTES)
    }

    /// Wrap `inner`, refusing lines longer than `cap` bytes.
    pub fn with_cap(inner: R, cap: usize) -> Self {
        Self {
            inner: BufReader::with_capacity(64 * 1024, inner),
            cap,
            line: 1,
            line_len: 0,
            after_cr: false,
            first_content: None,
        }
    }

    /// Start watching for the first line with content (call before reading a record).
    pub fn mark(&mut self) {
        self.first_content = None;
    }

    /// The line the record read since [`Self::mark`] began on: the first line with a byte
    /// other than a line end (blank lines before a record are skipped by the parser).
    pub fn record_line(&self) -> u64 {
        self.first_content.unwrap_or(self.line)
    }

    /// The number of the line being read (where an I/O error happened).
    pub fn line(&self) -> u64 {
        self.line
    }

    fn too_long(&self) -> io::Error {
        io::Error::new(
            io::ErrorKind::InvalidData,
            LineTooLong {
                line: self.line,
                cap: self.cap,
            },
        )
    }

    fn saw_content(&mut self) {
        if self.first_content.is_none() {
            self.first_content = Some(self.line);
        }
    }
}

impl<R: Read> Read for LineReader<R> {
    fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
        if buf.is_empty() {
            return Ok(0);
        }
        let avail = self.inner.fill_buf()?;
        if avail.is_empty() {
            return Ok(0);
        }
        if std::mem::take(&mut self.after_cr) && avail[0] == b'\n' {
            // the LF of a CRLF split across two reads: same line end
            buf[0] = b'\n';
            self.inner.consume(1);
            return Ok(1);
        }
        let limit = avail.len().min(buf.len());
        let n = match memchr::memchr2(b'\n', b'\r', &avail[..limit]) {
            Some(i) => {
                if self.line_len + i > self.cap {
                    return Err(self.too_long());
                }
                let mut end = i + 1;
                if avail[i] == b'\r' {
                    if end < limit && avail[end] == b'\n' {
                        end += 1;
                    } else if end == limit {
                        // an LF, if one follows, comes with the next read
                        self.after_cr = true;
                    }
                }
                buf[..end].copy_from_slice(&avail[..end]);
                if i > 0 {
                    self.saw_content();
                }
                self.line += 1;
                self.line_len = 0;
                end
            }
            None => {
                if self.line_len + limit > self.cap {
                    return Err(self.too_long());
                }
                buf[..limit].copy_from_slice(&avail[..limit]);
                self.saw_content();
                self.line_len += limit;
                limit
            }
        };
        self.inner.consume(n);
        Ok(n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every line handed out by reads of `chunk` bytes, with the line number `record_line`
    /// gives after each.
    fn lines(text: &[u8], chunk: usize, cap: usize) -> io::Result<Vec<(Vec<u8>, u64)>> {
        let mut r = LineReader::with_cap(text, cap);
        let mut out = Vec::new();
        let mut buf = vec![0u8; chunk];
        loop {
            r.mark();
            let n = r.read(&mut buf)?;
            if n == 0 {
                return Ok(out);
            }
            out.push((buf[..n].to_vec(), r.record_line()));
        }
    }

    #[test]
    fn lf_crlf_and_cr_are_numbered_alike() {
        for text in [
            &b"h\na\nb\n"[..],
            b"h\r\na\r\nb\r\n",
            b"h\ra\rb\r",
            b"h\ra\r\nb",
        ] {
            let got = lines(text, 64, 100).unwrap();
            let content: Vec<(String, u64)> = got
                .iter()
                .map(|(b, l)| (String::from_utf8_lossy(b).trim().to_owned(), *l))
                .filter(|(s, _)| !s.is_empty())
                .collect();
            assert_eq!(
                content,
                vec![("h".into(), 1), ("a".into(), 2), ("b".into(), 3)],
                "{text:?}"
            );
        }
    }

    #[test]
    fn one_line_per_read_and_blank_lines_count() {
        let got = lines(b"h\n\n\r\nx\n", 64, 100).unwrap();
        let text: Vec<&[u8]> = got.iter().map(|(b, _)| b.as_slice()).collect();
        assert_eq!(text, vec![&b"h\n"[..], b"\n", b"\r\n", b"x\n"]);
        assert_eq!(got[3].1, 4);
    }

    #[test]
    fn a_crlf_split_by_a_small_buffer_is_one_line_end() {
        let got = lines(b"ab\r\ncd\r\n", 3, 100).unwrap();
        let text: Vec<&[u8]> = got.iter().map(|(b, _)| b.as_slice()).collect();
        assert_eq!(text, vec![&b"ab\r"[..], b"\n", b"cd\r", b"\n"]);
        assert_eq!(got[2].1, 2);
    }

    #[test]
    fn long_lines_are_refused_with_their_number() {
        let text = b"short\nexactly10\n0123456789A\n";
        let e = lines(text, 4, 10).unwrap_err();
        let tl = e.get_ref().and_then(|e| e.downcast_ref::<LineTooLong>());
        assert_eq!(tl, Some(&LineTooLong { line: 3, cap: 10 }));
        assert_eq!(e.kind(), io::ErrorKind::InvalidData);
        // a line of exactly the cap is fine
        assert!(lines(b"0123456789\n", 4, 10).is_ok());
    }

    #[test]
    fn an_endless_line_stops_at_the_cap() {
        let mut r = LineReader::with_cap(io::repeat(0), 1000);
        let mut buf = [0u8; 64];
        let mut total = 0;
        let e = loop {
            match r.read(&mut buf) {
                Ok(n) => total += n,
                Err(e) => break e,
            }
        };
        assert!(total <= 1000);
        assert!(e.to_string().contains("line 1 is longer than 1000 bytes"));
    }
}
