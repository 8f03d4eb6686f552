//! CSV records split straight out of the read buffer: no allocation per row, lines numbered
//! as an editor numbers them, each line capped.
//!
//! [`RecordReader`] reads the CSV dialect the `csv` crate reads with `Trim::All`, no
//! header handling and rows of any length (what every reader here used before), record for
//! record and field for field: fields separated by `,`; records ended by LF, CRLF or a
//! lone CR; blank lines skipped; a field starting with `"` is quoted (`""` inside is one
//! `"`, line ends inside belong to the field, text after the closing quote is appended);
//! ASCII blanks trimmed around every field. A property test checks it against the `csv`
//! crate on random input.
//!
//! Most lines have no `"`: they are split in place by `memchr` over the line, and a
//! [`Record`] lends the fields out of the buffer. A line with a `"` goes through a small
//! state machine (the `csv-core` one) into a scratch buffer reused from record to record.
//!
//! Line numbers and the cap are those of [`super::lines`]: the record's line is the first
//! line it has content on (header = line 1), and a line of more than the cap (by default
//! [`MAX_LINE_BYTES`]) is refused with [`LineTooLong`], so a file that is not line-based
//! text costs at most the cap in memory.
//!
//! A read of the input happens only when the buffer holds no whole line, so a live input
//! (a pipe) gets each record as soon as its line end has arrived.

use std::io::{self, Read};
use std::ops::Range;

use super::lines::{LineTooLong, MAX_LINE_BYTES};

/// Bytes read at a time (and the buffer's size until a longer line needs more).
const CHUNK: usize = 64 * 1024;

/// One record: its fields, trimmed, borrowed from the reader.
#[derive(Debug, Clone, Copy)]
pub struct Record<'a> {
    data: &'a [u8],
    fields: &'a [Range<usize>],
    line: u64,
}

impl<'a> Record<'a> {
    /// The line the record begins on (1-based).
    pub fn line(&self) -> u64 {
        self.line
    }

    /// Number of fields.
    pub fn len(&self) -> usize {
        self.fields.len()
    }

    /// True when the record has no field (never, for a record read from a file).
    pub fn is_empty(&self) -> bool {
        self.fields.is_empty()
    }

    /// Field `i`, trimmed; `None` past the last.
    #[inline]
    pub fn get(&self, i: usize) -> Option<&'a [u8]> {
        self.fields.get(i).map(|r| &self.data[r.clone()])
    }

    /// The fields in order.
    pub fn iter(&self) -> impl Iterator<Item = &'a [u8]> + 'a {
        let data = self.data;
        self.fields.iter().map(move |r| &data[r.clone()])
    }
}

/// A record as [`RecordReader::next_raw`] gives it.
#[derive(Debug)]
pub enum RawRecord<'a> {
    /// A line without a quote, its line end excluded, not yet split or trimmed.
    Line {
        /// The line's bytes.
        text: &'a [u8],
        /// Its number (1-based).
        line: u64,
    },
    /// A record with a quoted field, unescaped and split.
    Quoted(Record<'a>),
}

/// The fields of a plain line of [`RawRecord::Line`], split and trimmed exactly as
/// [`RecordReader::next_record`] splits it; `fields` is scratch space reused from call to call.
pub fn split_line<'a>(text: &'a [u8], line: u64, fields: &'a mut Vec<Range<usize>>) -> Record<'a> {
    split(text, 0, fields);
    Record {
        data: text,
        fields,
        line,
    }
}

/// Where [`RecordReader::scan`] found the next record.
enum Scan {
    /// `buf[start..start + len]`, a line without a quote (already consumed).
    Plain { start: usize, len: usize, line: u64 },
    /// A line with a quote, from `pos`.
    Quoted { line: u64 },
}

/// An I/O error met while reading records, and the line being read then.
#[derive(Debug)]
pub struct ReadError {
    /// What failed (a line over the cap: `InvalidData` carrying [`LineTooLong`]).
    pub error: io::Error,
    /// The line being read.
    pub line: u64,
}

/// Where the state machine of a quoted record is (`csv-core`'s states that matter here).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum State {
    StartField,
    InField,
    InQuoted,
    /// A `"` seen in a quoted field: `"` again is a literal quote, anything else ends it.
    QuoteInQuoted,
}

/// Reads CSV records from `R` (module doc).
pub struct RecordReader<R> {
    inner: R,
    buf: Vec<u8>,
    /// Unread bytes are `buf[pos..end]`.
    pos: usize,
    end: usize,
    eof: bool,
    cap: usize,
    /// Line of `buf[pos]`.
    line: u64,
    /// The last byte consumed was a CR: an LF now ends the same line.
    after_cr: bool,
    /// Fields of the current record, into `buf` or `quoted`.
    fields: Vec<Range<usize>>,
    /// The current record's unescaped bytes, when it had a quote.
    quoted: Vec<u8>,
}

impl<R: Read> RecordReader<R> {
    /// Read records from `inner`, lines capped at [`MAX_LINE_BYTES`].
    pub fn new(inner: R) -> Self {
        Self::with_cap(inner, MAX_LINE_BYTES)
    }

    /// Read records from `inner`, refusing lines longer than `cap` bytes.
    pub fn with_cap(inner: R, cap: usize) -> Self {
        Self {
            inner,
            buf: vec![0; CHUNK],
            pos: 0,
            end: 0,
            eof: false,
            cap,
            line: 1,
            after_cr: false,
            fields: Vec::with_capacity(16),
            quoted: Vec::new(),
        }
    }

    /// The number of the line being read (where an I/O error happened).
    pub fn line(&self) -> u64 {
        self.line
    }

    /// The next record, or `None` at the end of the input. An I/O error is returned as
    /// it came (a line over the cap as an `InvalidData` error carrying [`LineTooLong`]),
    /// with the line being read.
    pub fn next_record(&mut self) -> Result<Option<Record<'_>>, ReadError> {
        match self.scan()? {
            None => Ok(None),
            Some(Scan::Quoted { line }) => self.quoted_record(line),
            Some(Scan::Plain { start, len, line }) => {
                split(&self.buf[start..start + len], start, &mut self.fields);
                Ok(Some(Record {
                    data: &self.buf,
                    fields: &self.fields,
                    line,
                }))
            }
        }
    }

    /// The next record as [`next_record`](Self::next_record) reads it, but a line without
    /// a quote comes unsplit ([`RawRecord::Line`]: a reader that knows its columns may
    /// parse it in one pass, and [`split_line`] splits it as `next_record` would).
    pub fn next_raw(&mut self) -> Result<Option<RawRecord<'_>>, ReadError> {
        match self.scan()? {
            None => Ok(None),
            Some(Scan::Quoted { line }) => Ok(self.quoted_record(line)?.map(RawRecord::Quoted)),
            Some(Scan::Plain { start, len, line }) => Ok(Some(RawRecord::Line {
                text: &self.buf[start..start + len],
                line,
            })),
        }
    }

    /// The next line parsed by `parse` straight out of the read buffer, without looking for
    /// its end first: `parse` gets the unread bytes from the line's start (running on past
    /// it) and returns its value and the length of the line it took. The line and its end
    /// are consumed, and its number returned, only when the byte after that length is a
    /// line end already read, the line is within the cap, and `parse` vouches that it holds
    /// no `"` or line end; otherwise (a blank line first, a line not whole in the buffer,
    /// `parse` declining) nothing is consumed and [`next_raw`](Self::next_raw) reads it.
    #[inline]
    pub fn try_line<T>(
        &mut self,
        parse: impl FnOnce(&[u8]) -> Option<(T, usize)>,
    ) -> Option<(T, u64)> {
        let rest = &self.buf[self.pos..self.end];
        if matches!(rest.first(), None | Some(b'\n' | b'\r')) {
            return None;
        }
        let (value, len) = parse(rest)?;
        if len > self.cap || !matches!(rest.get(len), Some(b'\n' | b'\r')) {
            return None;
        }
        let line = self.line;
        self.after_cr = false;
        self.pos += len;
        self.line_end();
        Some((value, line))
    }

    /// Skip blank lines, then find the next record's extent: a plain line (consumed with
    /// its line end) or a line with a quote (left for [`Self::quoted_record`]).
    #[inline]
    fn scan(&mut self) -> Result<Option<Scan>, ReadError> {
        // blank lines
        loop {
            if self.pos == self.end && !self.fill()? {
                return Ok(None);
            }
            match self.buf[self.pos] {
                b'\n' => {
                    self.pos += 1;
                    if !std::mem::take(&mut self.after_cr) {
                        self.line += 1;
                    }
                }
                b'\r' => {
                    self.pos += 1;
                    self.line += 1;
                    self.after_cr = true;
                }
                _ => break,
            }
        }
        self.after_cr = false;
        let line = self.line;
        // the line's end, or a quote before it
        let mut scanned = 0;
        let stop = loop {
            let rest = &self.buf[self.pos + scanned..self.end];
            if let Some(i) = memchr::memchr3(b'\n', b'\r', b'"', rest) {
                break Some(scanned + i);
            }
            scanned = self.end - self.pos;
            if scanned > self.cap {
                return Err(self.too_long());
            }
            if !self.fill()? {
                break None;
            }
        };
        let len = stop.unwrap_or(self.end - self.pos);
        if stop.is_some_and(|i| self.buf[self.pos + i] == b'"') {
            return Ok(Some(Scan::Quoted { line }));
        }
        if len > self.cap {
            return Err(self.too_long());
        }
        let start = self.pos;
        self.pos += len;
        if self.pos < self.end {
            // (consuming a line end never moves the buffer: `start` stays valid)
            self.line_end();
        }
        Ok(Some(Scan::Plain { start, len, line }))
    }

    /// Consume the line end at `pos` (LF, CR or CRLF).
    fn line_end(&mut self) {
        let c = self.buf[self.pos];
        self.pos += 1;
        self.line += 1;
        if c == b'\r' {
            if self.pos < self.end {
                if self.buf[self.pos] == b'\n' {
                    self.pos += 1;
                }
            } else {
                // an LF, if one follows, comes with the next read
                self.after_cr = true;
            }
        }
    }

    /// A record with a quote in its first line, from `pos` (module doc): field by field
    /// into `quoted`, over as many lines as its quoted fields span.
    fn quoted_record(&mut self, line: u64) -> Result<Option<Record<'_>>, ReadError> {
        self.quoted.clear();
        self.fields.clear();
        let mut state = State::StartField;
        let mut field_start = 0;
        // bytes of the current physical line, for the cap
        let mut line_len = 0usize;
        loop {
            if self.pos == self.end && !self.fill()? {
                break;
            }
            let c = self.buf[self.pos];
            let terminator = c == b'\n' || c == b'\r';
            if state != State::InQuoted && terminator {
                // the record's end: the terminator is consumed as a line end
                self.line_end();
                break;
            }
            self.pos += 1;
            if terminator {
                // a line end inside a quoted field
                if c == b'\r' || !std::mem::take(&mut self.after_cr) {
                    self.line += 1;
                }
                self.after_cr = c == b'\r';
                line_len = 0;
            } else {
                self.after_cr = false;
                line_len += 1;
                if line_len > self.cap {
                    return Err(self.too_long());
                }
            }
            state = match (state, c) {
                (State::StartField, b'"') => State::InQuoted,
                (State::StartField | State::InField | State::QuoteInQuoted, b',') => {
                    self.fields.push(field_start..self.quoted.len());
                    field_start = self.quoted.len();
                    State::StartField
                }
                (State::InQuoted, b'"') => State::QuoteInQuoted,
                (State::InQuoted, c) => {
                    self.quoted.push(c);
                    State::InQuoted
                }
                (State::QuoteInQuoted, b'"') => {
                    self.quoted.push(b'"');
                    State::InQuoted
                }
                (_, c) => {
                    self.quoted.push(c);
                    State::InField
                }
            };
        }
        self.fields.push(field_start..self.quoted.len());
        let data = &self.quoted;
        for r in &mut self.fields {
            *r = trim(data, r.clone());
        }
        Ok(Some(Record {
            data: &self.quoted,
            fields: &self.fields,
            line,
        }))
    }

    /// Read more input after `end`, keeping `buf[pos..end]`; false at the end of the input.
    fn fill(&mut self) -> Result<bool, ReadError> {
        if self.eof {
            return Ok(false);
        }
        if self.pos > 0 {
            self.buf.copy_within(self.pos..self.end, 0);
            self.end -= self.pos;
            self.pos = 0;
        }
        if self.end == self.buf.len() {
            // a long line: room for it, up to the cap and its line end
            let len = (self.buf.len() * 2).min(self.cap.saturating_add(2).max(CHUNK));
            if len <= self.buf.len() {
                return Err(self.too_long());
            }
            self.buf.resize(len, 0);
        }
        loop {
            match self.inner.read(&mut self.buf[self.end..]) {
                Ok(0) => {
                    self.eof = true;
                    return Ok(false);
                }
                Ok(n) => {
                    self.end += n;
                    return Ok(true);
                }
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(error) => {
                    return Err(ReadError {
                        error,
                        line: self.line,
                    })
                }
            }
        }
    }

    fn too_long(&self) -> ReadError {
        ReadError {
            error: io::Error::new(
                io::ErrorKind::InvalidData,
                LineTooLong {
                    line: self.line,
                    cap: self.cap,
                },
            ),
            line: self.line,
        }
    }
}

/// The fields of `line` (no line end, no quote), as trimmed ranges offset by `offset`.
#[inline]
fn split(line: &[u8], offset: usize, fields: &mut Vec<Range<usize>>) {
    fields.clear();
    let mut start = 0;
    for comma in memchr::memchr_iter(b',', line) {
        let f = trim(line, start..comma);
        fields.push(f.start + offset..f.end + offset);
        start = comma + 1;
    }
    let f = trim(line, start..line.len());
    fields.push(f.start + offset..f.end + offset);
}

/// `r` without the ASCII blanks at either end of `data[r]`.
#[inline]
fn trim(data: &[u8], mut r: Range<usize>) -> Range<usize> {
    while r.start < r.end && data[r.start].is_ascii_whitespace() {
        r.start += 1;
    }
    while r.end > r.start && data[r.end - 1].is_ascii_whitespace() {
        r.end -= 1;
    }
    r
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::super::lines::LineReader;
    use super::*;

    type Records = Vec<(u64, Vec<Vec<u8>>)>;

    /// Every record of `text` as (line, fields), read `chunk` bytes at a time.
    fn ours(text: &[u8], chunk: usize, cap: usize) -> io::Result<Records> {
        let mut r = RecordReader::with_cap(Chunked(text, chunk), cap);
        let mut out = Vec::new();
        while let Some(rec) = r.next_record().map_err(|e| e.error)? {
            out.push((rec.line(), rec.iter().map(<[u8]>::to_vec).collect()));
        }
        Ok(out)
    }

    /// The `csv` crate's records of `text` with the line each begins on, as the readers
    /// here read them before this module: `Trim::All`, behind a [`LineReader`] numbering
    /// the lines.
    fn reference(text: &[u8]) -> Records {
        let mut csv = ::csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .trim(::csv::Trim::All)
            .from_reader(LineReader::new(text));
        let mut rec = ::csv::ByteRecord::new();
        let mut out = Vec::new();
        loop {
            csv.get_mut().mark();
            if !csv.read_byte_record(&mut rec).unwrap() {
                return out;
            }
            let line = csv.get_ref().record_line();
            out.push((line, rec.iter().map(<[u8]>::to_vec).collect()));
        }
    }

    /// A reader that hands out at most `n` bytes per read.
    struct Chunked<'a>(&'a [u8], usize);

    impl Read for Chunked<'_> {
        fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
            let n = self.0.len().min(self.1).min(buf.len());
            buf[..n].copy_from_slice(&self.0[..n]);
            self.0 = &self.0[n..];
            Ok(n)
        }
    }

    #[test]
    fn lines_and_fields_whatever_the_line_ends() {
        for text in [
            &b"h,i\n1, 2 \n\n3,4\n"[..],
            b"h,i\r\n1, 2 \r\n\r\n3,4\r\n",
            b"h,i\r1, 2 \r\r3,4\r",
            b"h,i\n1, 2 \n\n3,4",
        ] {
            for chunk in [1, 2, 3, 64] {
                let got = ours(text, chunk, 100).unwrap();
                let lines: Vec<u64> = got.iter().map(|(l, _)| *l).collect();
                assert_eq!(lines, [1, 2, 4], "{text:?} by {chunk}");
                assert_eq!(got, reference(text), "{text:?} by {chunk}");
                assert_eq!(got[1].1, [b"1".to_vec(), b"2".to_vec()]);
            }
        }
    }

    #[test]
    fn quoted_fields_as_the_csv_crate_reads_them() {
        let text = b"a,\"b,c\",\" d \"\"e\"\"\"x\n\"multi\nline\r\nfield\",2\n3,\"\"\n\"open";
        for chunk in [1, 5, 64] {
            let got = ours(text, chunk, 100).unwrap();
            assert_eq!(got, reference(text), "by {chunk}");
            let lines: Vec<u64> = got.iter().map(|(l, _)| *l).collect();
            assert_eq!(lines, [1, 2, 5, 6], "by {chunk}");
        }
        assert_eq!(ours(text, 64, 100).unwrap()[0].1[2], b"d \"e\"x".to_vec());
    }

    #[test]
    fn long_lines_are_refused_with_their_number() {
        for chunk in [1, 4, 64] {
            let e = ours(b"short\nexactly10\n0123456789A\n", chunk, 10).unwrap_err();
            let tl = e.get_ref().and_then(|e| e.downcast_ref::<LineTooLong>());
            assert_eq!(tl, Some(&LineTooLong { line: 3, cap: 10 }), "by {chunk}");
            let e = ours(b"a\n\"0123456789A\"\n", chunk, 10).unwrap_err();
            let tl = e.get_ref().and_then(|e| e.downcast_ref::<LineTooLong>());
            assert_eq!(tl, Some(&LineTooLong { line: 2, cap: 10 }), "by {chunk}");
            assert!(ours(b"0123456789\n", chunk, 10).is_ok());
            assert!(ours(b"0123456789", chunk, 10).is_ok());
        }
    }

    #[test]
    fn an_endless_line_stops_at_the_cap() {
        let mut r = RecordReader::with_cap(io::repeat(b'7'), 100_000);
        let e = r.next_record().err().unwrap().error;
        assert!(e.to_string().contains("line 1 is longer than 100000 bytes"));
        assert!(r.buf.len() <= 2 * 100_000);
    }

    #[test]
    fn a_live_input_gets_each_record_when_its_line_ends() {
        // the reader must not ask for more input once a line is whole
        struct Lines(Vec<&'static [u8]>);
        impl Read for Lines {
            fn read(&mut self, buf: &mut [u8]) -> io::Result<usize> {
                let next = self.0.pop().expect("read past the available lines");
                buf[..next.len()].copy_from_slice(next);
                Ok(next.len())
            }
        }
        let mut r = RecordReader::new(Lines(vec![b"\n3\r", b"1,2\r"]));
        assert_eq!(r.next_record().unwrap().unwrap().get(1), Some(&b"2"[..]));
        let rec = r.next_record().unwrap().unwrap();
        assert_eq!((rec.line(), rec.get(0)), (2, Some(&b"3"[..])));
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(4000))]

        /// Records, fields and line numbers equal those of the `csv` crate behind a
        /// LineReader on any mix of separators, quotes, line ends and blanks, whatever
        /// the read sizes.
        #[test]
        fn same_records_as_the_csv_crate(
            text in proptest::collection::vec(
                prop_oneof![
                    Just(b','), Just(b'"'), Just(b'\n'), Just(b'\r'), Just(b' '),
                    Just(b'\t'), Just(b'a'), Just(b'1'), Just(b'.'), Just(0xC3u8)
                ],
                0..60,
            ),
            chunk in 1usize..9,
        ) {
            prop_assert_eq!(ours(&text, chunk, 1000).unwrap(), reference(&text));
        }
    }
}
