//! TDMS files read a block of rows at a time ([`crate::stream::RowBlocks`]).
//!
//! [`open_blocks`] makes one pass over the file's segments that reads their lead-ins and
//! metadata only, never their raw data: the same pass, with the same checks and messages,
//! as the whole-file reader's ([`super::read_file`]), down to the layout of each segment's
//! raw data (chunks that divide it, DAQmx buffers that agree, interleaved channels of one
//! count) and the notes on an interrupted last segment. Properties set in any segment
//! count, the last value winning, so the catalogue (each numeric `group/channel`, its
//! `unit_string`, its length and its time axis) and the scaling are the whole file's; what
//! the whole-file reader refuses on those grounds is refused here, at open.
//!
//! It keeps, per channel, where its values lie: for each segment that holds some, the
//! chunk size and count and the runs of values in a chunk (one for plain or interleaved
//! data, one per DAQmx scaler), a few dozen bytes per channel and segment, or per run of
//! segments of one layout (a recording written a block per segment keeps one).
//! [`next_rows`](crate::stream::RowBlocks::next_rows) then reads each channel asked for
//! from where it stopped, a block of at most 256 KiB of the file at a time (the reads of
//! the whole-file reader), scales the block as it is read and hands out the rows every
//! channel asked for has. Every NI scale rotorid applies (`tdms/scaling.rs`) works value
//! by value, so a block scales as the whole channel does, bit for bit: none needs the
//! whole channel, and there is no fallback. Memory holds the catalogue and, per channel
//! asked for, a queue of fewer than `max_rows` values plus one block (at most 2^18 values,
//! 2 MiB, for a one-byte type; 32,768 values, 256 KiB, for `f64`), never the channel.
//!
//! Differences from the whole-file reader, all on files both refuse: a fault in the layout
//! of a later segment's raw data (interleaved channels of unequal counts among them), or a
//! scaling it refuses, is reported at open, where the whole-file reader reports first a
//! sample of an earlier segment that `f64` cannot hold ([`ReadError::InexactInteger`],
//! found only when samples are read); and only the channels asked for are read, so such a
//! sample in another channel (or in values the channel's scaling does not use) is not
//! reported, and of two channels that have one the first asked for is named.

use std::collections::HashMap;

use super::{
    no_channels, raw_cursor, source, unequal, unequal_error, Chain, DaqmxLayout, Input, Layout,
    Walk, BLOCK,
};
use crate::error::ReadError;
use crate::num::{Dtype, Endian};
use crate::source::{DiskFile, Source};
use crate::table::ChannelInfo;

/// Values of one channel in each chunk of a segment: `count` of them, the first at byte
/// `at` of the file in the segment's first chunk, `stride` bytes apart.
#[derive(Debug, Clone, Copy)]
struct Run {
    at: u64,
    count: u64,
    stride: u64,
    dtype: Dtype,
}

/// One channel's values in one segment, or in `reps` segments of the same layout `step`
/// bytes apart (a recording written a block per segment): in each of `chunks` chunks of
/// `chunk` bytes of each, its runs in order.
#[derive(Debug, Clone)]
struct Part {
    e: Endian,
    chunk: u64,
    chunks: u64,
    runs: Vec<Run>,
    reps: u64,
    step: u64,
}

impl Part {
    /// Values in the part (at most one per byte of its raw data).
    fn len(&self) -> u64 {
        let per_chunk = self
            .runs
            .iter()
            .map(|r| r.count)
            .fold(0u64, u64::saturating_add);
        per_chunk
            .saturating_mul(self.chunks)
            .saturating_mul(self.reps)
    }

    /// Takes in `next`, the channel's part of the segment after this part's last, when it
    /// repeats that segment's layout further on in the file (so that a file of many small
    /// segments keeps a part per channel and layout, not per segment); false otherwise.
    fn absorb(&mut self, next: &Part) -> bool {
        let same = self.e == next.e
            && self.chunk == next.chunk
            && self.chunks == next.chunks
            && self.runs.len() == next.runs.len()
            && self
                .runs
                .iter()
                .zip(&next.runs)
                .all(|(a, b)| (a.count, a.stride, a.dtype) == (b.count, b.stride, b.dtype));
        if !same {
            return false;
        }
        // where the last segment absorbed has each run
        let last = (self.reps - 1) * self.step;
        let d = next.runs[0].at.checked_sub(self.runs[0].at + last);
        let Some(d) = d.filter(|&d| d > 0 && (self.reps == 1 || d == self.step)) else {
            return false;
        };
        let shifted = self
            .runs
            .iter()
            .zip(&next.runs)
            .all(|(a, b)| a.at + last + d == b.at);
        if shifted {
            self.step = d;
            self.reps += 1;
        }
        shifted
    }
}

/// A channel being read: where its values lie, where it stopped, and what it read ahead.
struct Stream {
    /// `group/channel`, for messages.
    name: String,
    parts: Vec<Part>,
    /// Where it stopped: part, chunk (of all the part's segments), run, value of the run.
    part: usize,
    chunk: u64,
    run: usize,
    first: u64,
    /// Values read so far (the index of the next one in the channel).
    read: u64,
    /// Values read and scaled, not yet handed out.
    queue: Vec<f64>,
    /// Values handed out.
    given: usize,
    /// The scales applied to its values, if any.
    chain: Option<Chain>,
}

impl Stream {
    /// Reads the channel's next block (at most [`BLOCK`] bytes of the file) onto its queue,
    /// scaled; `false` when it has no more.
    fn refill(
        &mut self,
        src: &DiskFile<'static>,
        file: &str,
        scratch: &mut Vec<u8>,
    ) -> Result<bool, ReadError> {
        loop {
            let Some(part) = self.parts.get(self.part) else {
                return Ok(false);
            };
            // (chunk counts the chunks of every segment of the part)
            if self.chunk >= part.chunks.saturating_mul(part.reps) {
                (self.part, self.chunk, self.run, self.first) = (self.part + 1, 0, 0, 0);
                continue;
            }
            let Some(run) = part.runs.get(self.run) else {
                (self.chunk, self.run, self.first) = (self.chunk + 1, 0, 0);
                continue;
            };
            if self.first >= run.count {
                (self.run, self.first) = (self.run + 1, 0);
                continue;
            }
            let per = (BLOCK / run.stride.max(1)).max(1);
            let m = per.min(run.count - self.first);
            let (rep, chunk) = (self.chunk / part.chunks, self.chunk % part.chunks);
            let at = run.at + rep * part.step + chunk * part.chunk + self.first * run.stride;
            let start = self.queue.len();
            crate::num::samples_at(
                src,
                file,
                &self.name,
                at,
                self.read,
                m,
                run.stride,
                run.dtype,
                part.e,
                scratch,
                &mut self.queue,
            )?;
            if let Some(c) = &self.chain {
                c.apply_in_place(&mut self.queue[start..]);
            }
            self.read += m;
            self.first += m;
            return Ok(true);
        }
    }
}

/// A TDMS file read a block of rows at a time ([module doc](self)).
pub struct TdmsBlocks {
    file: String,
    src: DiskFile<'static>,
    channels: Vec<ChannelInfo>,
    notes: Vec<String>,
    /// One per channel of `channels`.
    streams: Vec<Stream>,
    scratch: Vec<u8>,
    /// The most bytes the channels' queues have held at once.
    peak: usize,
}

/// Opens the TDMS file at `path` (`file` names it in messages) to be read a block of rows
/// at a time: reads and checks every segment's lead-in and metadata ([module doc](self)). Refuses
/// what [`super::read_file`] refuses on those grounds, with the same messages.
pub fn open_blocks(file: &str, path: &std::path::Path) -> Result<TdmsBlocks, ReadError> {
    let src = DiskFile::open_owned(file, path)?;
    let size = src.size();
    let mut w = Walk::default();
    // Where each object's values lie, for each input they may feed.
    let mut parts: HashMap<(usize, Input), Vec<Part>> = HashMap::new();
    let mut seg = 0u64;
    while seg < size {
        let (end, raw) = w.segment(file, &src, seg)?;
        if let Some((r, l)) = raw {
            // this segment's runs of each object and input, in reading order
            let mut here: Vec<((usize, Input), Vec<Run>)> = Vec::new();
            let mut add =
                |key: (usize, Input), run: Run| match here.iter_mut().find(|(k, _)| *k == key) {
                    Some((_, runs)) => runs.push(run),
                    None => here.push((key, vec![run])),
                };
            let (chunk, chunks) = match l {
                Layout::Plain {
                    present,
                    chunk,
                    chunks,
                } => {
                    let mut at = r.start;
                    for &(k, i) in &present {
                        if let Some(dtype) = i.dtype {
                            let run = Run {
                                at,
                                count: i.count,
                                stride: i.size,
                                dtype,
                            };
                            add((k, Input::Stored), run);
                        }
                        at += i.bytes;
                    }
                    (chunk, chunks)
                }
                Layout::Interleaved {
                    present,
                    chunk,
                    chunks,
                } => {
                    if let Some(j) = unequal(&present) {
                        return Err(unequal_error(&raw_cursor(&r), &present, j, &w.objects));
                    }
                    let row: u64 = present.iter().map(|(_, i)| i.size).sum();
                    let mut col = 0;
                    for &(k, i) in &present {
                        if let Some(dtype) = i.dtype {
                            let run = Run {
                                at: r.start + col,
                                count: i.count,
                                stride: row,
                                dtype,
                            };
                            add((k, Input::Stored), run);
                        }
                        col += i.size;
                    }
                    (chunk, chunks)
                }
                Layout::Daqmx(DaqmxLayout {
                    present,
                    rows,
                    widths,
                    scalers,
                    chunk,
                    chunks,
                }) => {
                    let mut base = r.start;
                    for (b, (&count, &width)) in rows.iter().zip(&widths).enumerate() {
                        let width = u64::from(width);
                        for (&(k, _), scalers) in present.iter().zip(&scalers) {
                            let o = &mut w.objects[k];
                            for s in scalers.iter().filter(|s| s.buffer as usize == b) {
                                let Some(dtype) = s.dtype else { continue };
                                let input = if o.daqmx_raw {
                                    // (the whole-file reader's list of this object's
                                    // scalers, without their values)
                                    super::scaler_values(o, s.id);
                                    Input::Scaler(s.id)
                                } else {
                                    Input::Stored
                                };
                                let run = Run {
                                    at: base + u64::from(s.offset),
                                    count,
                                    stride: width,
                                    dtype,
                                };
                                add((k, input), run);
                            }
                        }
                        base += count * width;
                    }
                    (chunk, chunks)
                }
            };
            for (key, runs) in here {
                let runs: Vec<Run> = runs.into_iter().filter(|r| r.count > 0).collect();
                if !runs.is_empty() {
                    let part = Part {
                        e: r.e,
                        chunk,
                        chunks,
                        runs,
                        reps: 1,
                        step: 0,
                    };
                    let list = parts.entry(key).or_default();
                    if !list.last_mut().is_some_and(|last| last.absorb(&part)) {
                        list.push(part);
                    }
                }
            }
        }
        seg = end;
    }
    let root = w.root();
    let mut channels = Vec::new();
    let mut streams = Vec::new();
    for k in w.channels() {
        let (input, chain) = source(file, &w.objects, k, root)?;
        let axis = super::axis(file, &w.objects[k])?;
        let o = &w.objects[k];
        let parts = parts.remove(&(k, input)).unwrap_or_default();
        let len = parts.iter().map(Part::len).fold(0u64, u64::saturating_add);
        channels.push(ChannelInfo {
            name: o.name(),
            unit: o.unit.clone(),
            len: usize::try_from(len).unwrap_or(usize::MAX),
            axis,
        });
        streams.push(Stream {
            name: o.name(),
            parts,
            part: 0,
            chunk: 0,
            run: 0,
            first: 0,
            read: 0,
            queue: Vec::new(),
            given: 0,
            chain,
        });
    }
    if channels.is_empty() {
        return Err(no_channels(file));
    }
    Ok(TdmsBlocks {
        file: file.to_string(),
        src,
        channels,
        notes: w.notes,
        streams,
        scratch: Vec::new(),
        peak: 0,
    })
}

impl TdmsBlocks {
    /// The most bytes the queues of the channels read have held at once (their capacity):
    /// at most, per channel read, `max_rows` values plus one block of at most 2^18 values,
    /// twice over for a queue's growth, at 8 bytes a value ([module doc](self)).
    pub fn peak_queued_bytes(&self) -> usize {
        self.peak
    }
}

impl crate::stream::RowBlocks for TdmsBlocks {
    fn file(&self) -> &str {
        &self.file
    }

    fn channels(&self) -> &[ChannelInfo] {
        &self.channels
    }

    fn notes(&self) -> &[String] {
        &self.notes
    }

    fn next_rows(
        &mut self,
        wanted: &[usize],
        max_rows: usize,
        out: &mut [Vec<f64>],
    ) -> Result<usize, ReadError> {
        crate::stream::check_wanted(&self.file, self.channels.len(), wanted, out)?;
        let n = wanted
            .iter()
            .map(|&k| self.channels[k].len - self.streams[k].given)
            .min()
            .unwrap_or(0)
            .min(max_rows.max(1));
        if n == 0 {
            return Ok(0);
        }
        for &k in wanted {
            let s = &mut self.streams[k];
            while s.queue.len() < n {
                if !s.refill(&self.src, &self.file, &mut self.scratch)? {
                    // (the catalogue counted the values the parts hold: not reached)
                    return Err(ReadError::Truncated {
                        file: self.file.clone(),
                        channel: Some(s.name.clone()),
                        offset: self.src.size(),
                        what: "TDMS channel values".into(),
                        need: n as u64,
                        available: s.queue.len() as u64,
                    });
                }
            }
        }
        let held: usize = wanted
            .iter()
            .map(|&k| self.streams[k].queue.capacity())
            .sum();
        self.peak = self.peak.max(held * 8);
        for (j, &k) in wanted.iter().enumerate() {
            let s = &mut self.streams[k];
            out[j].extend(s.queue.drain(..n));
            s.given += n;
        }
        Ok(n)
    }
}

#[cfg(test)]
pub(super) mod check {
    //! What the whole-file reader's tests check of every file they build: streamed, it
    //! gives the same catalogue, notes and values, or an error.
    use super::*;
    use crate::stream::RowBlocks;
    use crate::table::Table;

    /// Block sizes streamed: one row, a few, many, all.
    pub(crate) const MAX_ROWS: [usize; 4] = [1, 7, 4096, usize::MAX];

    /// The channels of `b` (all of them: [`crate::stream::for_each_block`]), `max_rows`
    /// rows at a time; once done, a further call gives nothing.
    pub(crate) fn read_all(
        b: &mut TdmsBlocks,
        max_rows: usize,
    ) -> Result<Vec<Vec<f64>>, ReadError> {
        let mut data = vec![Vec::new(); b.channels().len()];
        crate::stream::for_each_block(b, max_rows, |which, rows| {
            for (&k, r) in which.iter().zip(rows) {
                assert!(r.len() <= max_rows);
                data[k].extend_from_slice(r);
            }
        })?;
        let lens: Vec<usize> = b.channels().iter().map(|c| c.len).collect();
        let all: Vec<usize> = (0..lens.len()).collect();
        let mut out = vec![Vec::new(); lens.len()];
        if lens.iter().all(|&l| l == lens[0]) {
            assert_eq!(b.next_rows(&all, 5, &mut out)?, 0);
        }
        Ok(data)
    }

    pub(crate) fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    /// Streams the file at `path` with every block size of [`MAX_ROWS`] and checks it
    /// against the whole-file reader's `want`: the same catalogue, notes and values bit
    /// for bit; an error whenever it errs (the same one, but for the differences the
    /// module doc lists). Returns how many of the errors differed in their text.
    pub(crate) fn agrees(path: &std::path::Path, want: &Result<Table, ReadError>) -> usize {
        let mut differ = 0;
        for max_rows in MAX_ROWS {
            let got = open_blocks("x.tdms", path).and_then(|mut b| {
                let data = read_all(&mut b, max_rows)?;
                Ok((b, data))
            });
            match (want, got) {
                (Ok(t), Ok((b, data))) => {
                    assert_eq!(b.channels().len(), t.channels.len());
                    for ((info, c), d) in b.channels().iter().zip(&t.channels).zip(&data) {
                        assert_eq!(info.name, c.name);
                        assert_eq!(info.unit, c.unit);
                        assert_eq!(info.len, c.data.len(), "{}", c.name);
                        assert_eq!(info.axis, c.axis);
                        assert_eq!(bits(d), bits(&c.data), "{} by {max_rows}", c.name);
                    }
                    assert_eq!(b.notes(), t.notes.as_slice());
                }
                (Err(e), Err(g)) => {
                    if e.to_string() != g.to_string() {
                        differ += 1;
                    }
                }
                (Ok(_), Err(g)) => panic!("whole file read, streaming refused: {g}"),
                (Err(e), Ok(_)) => panic!("whole file refused ({e}), streaming read"),
            }
        }
        differ
    }

    /// [`agrees`] on `bytes`, written to a file, and no error text differs.
    pub(crate) fn agrees_exactly(bytes: &[u8], want: &Result<Table, ReadError>) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.tdms");
        std::fs::write(&path, bytes).unwrap();
        assert_eq!(agrees(&path, want), 0, "{want:?}");
    }
}

#[cfg(test)]
mod tests {
    use super::check::{agrees, bits, read_all};
    use super::*;
    use crate::stream::RowBlocks;

    /// A TDMS segment of a new object list holding channels `(path, type code, values)` of
    /// little-endian `f64` (type 10) or `i16` (type 2) contiguous raw data.
    fn segment(channels: &[(&str, u32, &[f64])]) -> Vec<u8> {
        let mut meta = (channels.len() as u32).to_le_bytes().to_vec();
        let mut raw = Vec::new();
        for &(path, t, values) in channels {
            meta.extend((path.len() as u32).to_le_bytes());
            meta.extend(path.as_bytes());
            meta.extend(20u32.to_le_bytes());
            meta.extend(t.to_le_bytes());
            meta.extend(1u32.to_le_bytes());
            meta.extend((values.len() as u64).to_le_bytes());
            meta.extend(0u32.to_le_bytes());
            for &v in values {
                match t {
                    10 => raw.extend(v.to_le_bytes()),
                    _ => raw.extend((v as i16).to_le_bytes()),
                }
            }
        }
        let mut f = b"TDSm".to_vec();
        f.extend((0x02u32 | 0x04 | 0x08).to_le_bytes());
        f.extend(4713u32.to_le_bytes());
        f.extend(((meta.len() + raw.len()) as u64).to_le_bytes());
        f.extend((meta.len() as u64).to_le_bytes());
        f.extend(meta);
        f.extend(raw);
        f
    }

    #[test]
    fn segments_of_one_layout_keep_one_part_and_read_as_many() {
        // 30 segments of a and b, 5 values each; then 1 of 3 values; then 30 of 5 again
        let mut f = Vec::new();
        let mut v = 0.0;
        let mut next = |n: usize| {
            (0..n)
                .map(|_| {
                    v += 1.0;
                    v
                })
                .collect::<Vec<f64>>()
        };
        for n in std::iter::repeat_n(5, 30)
            .chain([3])
            .chain(std::iter::repeat_n(5, 30))
        {
            let (a, b) = (next(n), next(n));
            f.extend(segment(&[("/'g'/'a'", 10, &a), ("/'g'/'b'", 10, &b)]));
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.tdms");
        std::fs::write(&path, &f).unwrap();
        let mut b = open_blocks("x.tdms", &path).unwrap();
        for s in &b.streams {
            let reps: Vec<u64> = s.parts.iter().map(|p| p.reps).collect();
            assert_eq!(reps, [30, 1, 30], "{}", s.name);
        }
        assert_eq!(read_all(&mut b, 4).unwrap()[0].len(), 303);
        assert_eq!(agrees(&path, &super::super::read_file("x.tdms", &path)), 0);
    }

    #[test]
    fn a_long_file_of_many_segments_streams_in_bounded_memory() {
        // 40 segments of 60,000 f64 values of x and 60,000 i16 of z (2.4 million values each,
        // 38.4 MB as f64), 4096 rows at a time: the queues hold, per channel, fewer than
        // 4096 rows plus one 256 KiB block of the file (32,768 f64 or 131,072 i16), twice
        // over for a vector's growth, at 8 bytes a value
        let per = 60_000;
        let mut f = Vec::new();
        let (mut xs, mut zs) = (Vec::new(), Vec::new());
        for s in 0..40 {
            let x: Vec<f64> = (0..per).map(|i| (s * per + i) as f64 * 0.25).collect();
            let z: Vec<f64> = (0..per).map(|i| ((s * 7 + i) % 30_000) as f64).collect();
            f.extend(segment(&[("/'g'/'x'", 10, &x), ("/'g'/'z'", 2, &z)]));
            xs.extend(x);
            zs.extend(z);
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("long.tdms");
        std::fs::write(&path, &f).unwrap();
        let max_rows = 4096;
        let mut b = open_blocks("long.tdms", &path).unwrap();
        assert_eq!(b.channels()[0].len, 40 * per);
        let mut got = [Vec::new(), Vec::new()];
        let mut out = [Vec::new(), Vec::new()];
        loop {
            let n = b.next_rows(&[0, 1], max_rows, &mut out).unwrap();
            if n == 0 {
                break;
            }
            for (g, o) in got.iter_mut().zip(&mut out) {
                g.append(o);
            }
        }
        assert_eq!(bits(&got[0]), bits(&xs));
        assert_eq!(bits(&got[1]), bits(&zs));
        let bound = 2 * (2 * (max_rows + (1 << 18) / 8) + 2 * (max_rows + (1 << 18) / 2)) * 8;
        let peak = b.peak_queued_bytes();
        eprintln!(
            "queues held at most {peak} bytes (bound {bound}; the channels: {})",
            2 * 8 * xs.len()
        );
        assert!(peak > 0 && peak <= bound, "{peak} > {bound}");
        assert!(peak * 4 < 2 * 8 * xs.len());
    }
}
