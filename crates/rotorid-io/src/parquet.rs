//! Apache Parquet files (`.parquet`, as pandas and pyarrow write them), read with the
//! `parquet` crate's column readers (no Arrow).
//!
//! Layout (Apache Parquet format specification, parquet-format 2.x): data, then the Thrift
//! footer with the schema and row groups, its length, and the magic `PAR1`. Each top-level
//! numeric column becomes a channel named after the column, its row groups concatenated in
//! order. Physical types `DOUBLE`, `FLOAT`, `INT32` (signed, or unsigned by its
//! `UINT_8/16/32` annotation) and `INT64` (signed or `UINT_64`; exact or an error) are
//! read; any encoding (plain, dictionary, RLE, delta) and the codecs uncompressed, snappy
//! (pyarrow's default) and gzip. Boolean, string, binary, `INT96`, decimal, date, time and
//! timestamp columns, and nested columns, are skipped. A null is an error naming the column
//! and row (the readers do not invent samples). Parquet carries no units.
//!
//! Bounds: before reading, the footer's row count must be at most 1032 times the file's
//! size, and every page header of every column chunk is walked (Thrift compact protocol)
//! to check that its compressed size lies within the file and its uncompressed size is at
//! most 1032 times that plus 1 KiB, since the `parquet` crate allocates a page's claimed
//! uncompressed size before decompressing. Errors of the `parquet` crate are reported as
//! [`ReadError::Container`] with its message. Each column chunk is decoded under its own
//! guard (`crate::guard`): should the crate panic on a malformed page, the error names
//! the column, the row group and the chunk's byte offset, as a null or an inexact integer
//! does.
//!
//! From 1 MiB of column chunks on, the columns are decoded side by side (`crate::par`: as
//! many threads as the machine offers, at most four), each column's chunks in order on one
//! thread; a file on disk is read at offsets (`pread`), which the threads share. Of several
//! bad columns the first in column order is the one reported, as when they are read one by
//! one.
//!
//! [`open_blocks`] reads the same file a block of rows at a time ([`crate::stream`]): the
//! same checks before decoding, then one column reader per column asked for, each advanced
//! by the rows asked for, row group after row group; memory holds a page per column and
//! the block. A column chunk must decode to the value count its metadata declares.

use bytes::Bytes;
use parquet::basic::{ConvertedType, Type as Physical};
use parquet::column::reader::ColumnReader;
use parquet::file::reader::{ChunkReader, FileReader, SerializedFileReader};

use crate::error::ReadError;
use crate::par::PARALLEL_FROM;
use crate::table::{Channel, ChannelInfo, Table};

const BATCH: usize = 65_536;

/// Reads a Parquet file's bytes; `file` names it in messages.
pub fn read(file: &str, bytes: &[u8]) -> Result<Table, ReadError> {
    read_with(file, bytes, PARALLEL_FROM)
}

/// [`read`], its columns side by side from `parallel_from` bytes on ([`read_inner`]).
fn read_with(file: &str, bytes: &[u8], parallel_from: u64) -> Result<Table, ReadError> {
    let data = Bytes::copy_from_slice(bytes);
    let size = bytes.len() as u64;
    let chunk = |start: u64, len: u64| Ok(bytes[start as usize..(start + len) as usize].to_vec());
    guarded(file, || read_inner(file, data, size, &chunk, parallel_from))
}

/// Reads the Parquet file at `path` column chunk by column chunk: memory holds the channels
/// and a column chunk per thread (and the `parquet` crate's page buffers), never the whole
/// file.
pub fn read_file(file: &str, path: &std::path::Path) -> Result<Table, ReadError> {
    read_file_with(file, path, PARALLEL_FROM)
}

/// [`read_file`], its columns side by side from `parallel_from` bytes on ([`read_inner`]).
fn read_file_with(
    file: &str,
    path: &std::path::Path,
    parallel_from: u64,
) -> Result<Table, ReadError> {
    let disk = crate::source::DiskFile::open(file, path)?;
    let handle = Positional {
        f: std::sync::Arc::new(disk.handle()?),
        size: disk.size,
    };
    let chunk = |start: u64, len: u64| disk.read_at(start, len);
    guarded(file, || {
        read_inner(file, handle, disk.size, &chunk, parallel_from)
    })
}

/// Opens the Parquet file at `path` to be read a block of rows at a time
/// ([`crate::stream`]): every check of [`read_file`] that comes before decoding runs here
/// (footer, row count, page headers); then each column is decoded as its rows are asked
/// for, one `parquet` crate column reader per column read, so memory holds a page per
/// column and the rows asked for, never the whole column.
///
/// A column's length is the sum of its column chunks' value counts (`num_values`); a chunk
/// that decodes to another count is an error naming the column, the row group and the
/// chunk's offset (the whole-file reader takes what the chunk decodes to; a file that
/// differs between the two has a footer that contradicts its pages).
pub fn open_blocks(file: &str, path: &std::path::Path) -> Result<ParquetBlocks, ReadError> {
    let disk = crate::source::DiskFile::open(file, path)?;
    let handle = Positional {
        f: std::sync::Arc::new(disk.handle()?),
        size: disk.size,
    };
    let chunk = |start: u64, len: u64| disk.read_at(start, len);
    let opened = crate::guard::quietly(|| open(file, handle, disk.size, &chunk))
        .unwrap_or_else(|| Err(malformed(file)))?;
    let meta = opened.reader.metadata();
    let mut channels = Vec::with_capacity(opened.wanted.len());
    for c in &opened.wanted {
        let len = meta
            .row_groups()
            .iter()
            .map(|g| g.column(c.col).num_values().max(0) as u64)
            .fold(0, u64::saturating_add);
        if len > opened.limit {
            return Err(err(
                file,
                Some(&c.name),
                format!(
                    "its column chunks declare {len} values, more than {} (1032 times the \
                     file's size)",
                    opened.limit
                ),
            ));
        }
        channels.push(ChannelInfo {
            name: c.name.clone(),
            unit: None,
            len: len as usize,
            axis: None,
        });
    }
    let cursors = opened.wanted.iter().map(|_| None).collect();
    Ok(ParquetBlocks {
        file: file.to_string(),
        opened,
        channels,
        cursors,
    })
}

/// A Parquet file read a block of rows at a time ([`open_blocks`]).
pub struct ParquetBlocks {
    file: String,
    opened: Opened<Positional>,
    channels: Vec<ChannelInfo>,
    /// Per column: where its reading stands, once asked for.
    cursors: Vec<Option<ColumnCursor>>,
}

/// Where one column's reading stands: its row group, that chunk's reader and batch state,
/// and the values given so far.
#[derive(Default)]
struct ColumnCursor {
    row_group: usize,
    reader: Option<ColumnReader>,
    batch: Batch,
    /// Values read from the current chunk.
    in_chunk: u64,
    /// Values given so far.
    given: usize,
}

impl crate::stream::RowBlocks for ParquetBlocks {
    fn file(&self) -> &str {
        &self.file
    }

    fn channels(&self) -> &[ChannelInfo] {
        &self.channels
    }

    fn notes(&self) -> &[String] {
        &[]
    }

    fn next_rows(
        &mut self,
        wanted: &[usize],
        max_rows: usize,
        out: &mut [Vec<f64>],
    ) -> Result<usize, ReadError> {
        crate::stream::check_wanted(&self.file, self.channels.len(), wanted, out)?;
        let Some(&first) = wanted.first() else {
            return Ok(0);
        };
        let given = self.cursors[first].as_ref().map_or(0, |c| c.given);
        let n = max_rows.min(self.channels[first].len.saturating_sub(given));
        let file = self.file.as_str();
        let opened = &self.opened;
        // each column asked for, with its cursor and output (distinct and in range: checked)
        let mut cursors: Vec<Option<&mut Option<ColumnCursor>>> =
            self.cursors.iter_mut().map(Some).collect();
        let jobs: Vec<_> = wanted
            .iter()
            .zip(out.iter_mut())
            .filter_map(|(&k, data)| Some(std::sync::Mutex::new((k, cursors[k].take()?, data))))
            .collect();
        // Columns side by side from PARALLEL_FROM bytes a block on, as the whole-file read
        // decodes them; the first error in column order is the one reported.
        let bytes = (n as u64).saturating_mul(8 * wanted.len() as u64);
        let threads = crate::par::threads_for(jobs.len(), bytes, PARALLEL_FROM);
        let results = crate::par::map_ordered(&jobs, threads, |job| {
            let mut job = job.lock().unwrap_or_else(|p| p.into_inner());
            let (k, cursor, data) = &mut *job;
            let c = &opened.wanted[*k];
            let cursor = cursor.get_or_insert_with(ColumnCursor::default);
            // A panic of the crate in this column names it (crate::guard).
            crate::guard::quietly(|| fill(file, opened, c, cursor, n, data))
                .unwrap_or_else(|| Err(cursor_undecodable(file, opened, c, cursor)))
        });
        for r in results {
            r.unwrap_or_else(|| Err(err(file, None, "a column reader failed")))?;
        }
        Ok(n)
    }
}

/// `n` more values of column `c` appended to `data`, through its `cursor`, row group after
/// row group; each finished chunk must have given its declared value count.
fn fill(
    file: &str,
    opened: &Opened<Positional>,
    c: &Column,
    cursor: &mut ColumnCursor,
    n: usize,
    data: &mut Vec<f64>,
) -> Result<(), ReadError> {
    let meta = opened.reader.metadata();
    let target = data.len() + n;
    cursor.batch.index0 = cursor.given;
    cursor.batch.data_start = data.len();
    while data.len() < target {
        if cursor.row_group >= meta.num_row_groups() {
            return Err(err(
                file,
                Some(&c.name),
                format!(
                    "the column ends after {} values, its column chunks declare more",
                    cursor.given + (data.len() - cursor.batch.data_start)
                ),
            ));
        }
        let at = chunk_at(opened, c, cursor.row_group);
        let reader = match &mut cursor.reader {
            Some(r) => r,
            None => cursor
                .reader
                .insert(column_reader(file, &opened.reader, c.col, &at)?),
        };
        let before = data.len();
        let got = cursor.batch.read(
            file,
            reader,
            c.kind,
            c.max_def,
            &at,
            target - data.len(),
            data,
        )?;
        cursor.in_chunk += (data.len() - before) as u64;
        if got == 0 {
            let declared = meta
                .row_group(cursor.row_group)
                .column(c.col)
                .num_values()
                .max(0) as u64;
            if cursor.in_chunk != declared {
                return Err(ReadError::Invalid {
                    file: file.to_string(),
                    channel: Some(c.name.clone()),
                    offset: at.offset,
                    what: format!("the Parquet column chunk of row group {}", at.row_group),
                    found: format!("{} values", cursor.in_chunk),
                    allowed: format!("the {declared} values its metadata declares"),
                });
            }
            cursor.row_group += 1;
            cursor.reader = None;
            cursor.in_chunk = 0;
            cursor.batch.row0 = 0;
        }
    }
    cursor.given += n;
    Ok(())
}

/// Column `c`'s chunk in row group `rg`, as messages name it.
fn chunk_at<'a>(opened: &Opened<Positional>, c: &'a Column, rg: usize) -> Chunk<'a> {
    let cc = opened.reader.metadata().row_group(rg).column(c.col);
    Chunk {
        name: &c.name,
        row_group: rg,
        offset: cc.dictionary_page_offset().unwrap_or(cc.data_page_offset()) as u64,
        len: cc.compressed_size() as u64,
    }
}

/// The error for the chunk a column's cursor was in when the `parquet` crate panicked.
fn cursor_undecodable(
    file: &str,
    opened: &Opened<Positional>,
    c: &Column,
    cursor: &ColumnCursor,
) -> ReadError {
    let rg = cursor
        .row_group
        .min(opened.reader.metadata().num_row_groups().saturating_sub(1));
    chunk_at(opened, c, rg).undecodable(file)
}

/// The error for a file on which the `parquet` crate panicked before any column.
fn malformed(file: &str) -> ReadError {
    ReadError::Container {
        file: file.to_string(),
        channel: None,
        container: "Parquet",
        message: "the parquet reader failed on a malformed structure".into(),
    }
}

/// The file read at offsets (`pread`), so that threads decoding column chunks side by side
/// can share it: the `parquet` crate's reader of a `File` seeks one offset shared by every
/// handle it clones.
struct Positional {
    f: std::sync::Arc<std::fs::File>,
    /// Size \[bytes\].
    size: u64,
}

impl parquet::file::reader::Length for Positional {
    fn len(&self) -> u64 {
        self.size
    }
}

impl ChunkReader for Positional {
    // (small: the crate reads a page header from here, then the page with get_bytes)
    type T = std::io::BufReader<At>;

    fn get_read(&self, start: u64) -> parquet::errors::Result<Self::T> {
        Ok(std::io::BufReader::with_capacity(
            HEADER_WINDOW as usize,
            At {
                f: std::sync::Arc::clone(&self.f),
                pos: start,
            },
        ))
    }

    fn get_bytes(&self, start: u64, length: usize) -> parquet::errors::Result<Bytes> {
        use std::os::unix::fs::FileExt as _;
        let mut buf = vec![0u8; length];
        self.f.read_exact_at(&mut buf, start)?;
        Ok(buf.into())
    }
}

/// A reader of [`Positional`]'s file from `pos` on.
struct At {
    f: std::sync::Arc<std::fs::File>,
    pos: u64,
}

impl std::io::Read for At {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        use std::os::unix::fs::FileExt as _;
        let n = self.f.read_at(buf, self.pos)?;
        self.pos += n as u64;
        Ok(n)
    }
}

/// `run`, with a panic of the third-party parser on a hostile file made an error.
fn guarded(file: &str, run: impl FnOnce() -> Result<Table, ReadError>) -> Result<Table, ReadError> {
    // A third-party parser: a panic on a hostile file becomes an error here (crate::guard).
    crate::guard::quietly(run).unwrap_or_else(|| Err(malformed(file)))
}

fn err(file: &str, channel: Option<&str>, e: impl ToString) -> ReadError {
    ReadError::Container {
        file: file.to_string(),
        channel: channel.map(str::to_string),
        container: "Parquet",
        message: e.to_string(),
    }
}

/// How an integer column's values become `f64`.
#[derive(Clone, Copy)]
enum Kind {
    Float,
    Signed,
    Unsigned,
}

/// The bytes `[start, start + len)` of the file (within its size: checked by the caller).
type ChunkFn<'a> = dyn Fn(u64, u64) -> Result<Vec<u8>, ReadError> + 'a;

/// A Parquet file's reader and its catalogue, checked ([`open`]).
struct Opened<R: ChunkReader + 'static> {
    reader: SerializedFileReader<R>,
    /// The numeric top-level columns, in schema order.
    wanted: Vec<Column>,
    /// The declared rows of every row group together (checked against the file's size).
    rows: u64,
    /// The most values a column may hold: 1032 times the file's size.
    limit: u64,
}

/// The reader of a Parquet file of `size` bytes, read through `source`, and its numeric
/// columns, after every check that comes before decoding: the footer ([`check_footer`]),
/// its row count, every page header of every column chunk ([`check_pages`]; `chunk` gives
/// a column chunk's bytes); no numeric column is an error listing what was skipped.
fn open<R: ChunkReader + 'static>(
    file: &str,
    source: R,
    size: u64,
    chunk: &ChunkFn<'_>,
) -> Result<Opened<R>, ReadError> {
    let footer = check_footer(file, size, chunk)?;
    let reader = SerializedFileReader::new(source).map_err(|e| err(file, None, e))?;
    let meta = reader.metadata();
    let schema = meta.file_metadata().schema_descr();
    let rows: i64 = meta
        .row_groups()
        .iter()
        .map(|g| g.num_rows().max(0))
        .fold(0i64, i64::saturating_add);
    let limit = size.saturating_mul(1032);
    if rows as u64 > limit {
        return Err(ReadError::Invalid {
            file: file.to_string(),
            channel: None,
            // the row groups' counts are fields of the footer that starts there
            offset: footer,
            what: "Parquet footer row count (the row groups' num_rows together)".into(),
            found: rows.to_string(),
            allowed: format!("at most {limit} (1032 times the file's size)"),
        });
    }
    for g in meta.row_groups() {
        for cc in g.columns() {
            let start = cc.dictionary_page_offset().unwrap_or(cc.data_page_offset());
            check_pages(
                file,
                size,
                chunk,
                &cc.column_path().string(),
                start,
                cc.compressed_size(),
            )?;
        }
    }
    // The numeric top-level columns, and what is skipped.
    let mut wanted = Vec::new();
    let mut skipped = Vec::new();
    for col in 0..schema.num_columns() {
        let cd = schema.column(col);
        let name = cd.path().string();
        let kind = match (cd.physical_type(), cd.converted_type()) {
            _ if cd.max_rep_level() > 0 || cd.path().parts().len() != 1 => None,
            (Physical::DOUBLE | Physical::FLOAT, _) => Some(Kind::Float),
            (
                Physical::INT32 | Physical::INT64,
                ConvertedType::NONE
                | ConvertedType::INT_8
                | ConvertedType::INT_16
                | ConvertedType::INT_32
                | ConvertedType::INT_64,
            ) => Some(Kind::Signed),
            (
                Physical::INT32 | Physical::INT64,
                ConvertedType::UINT_8
                | ConvertedType::UINT_16
                | ConvertedType::UINT_32
                | ConvertedType::UINT_64,
            ) => Some(Kind::Unsigned),
            _ => None,
        };
        match kind {
            Some(kind) => wanted.push(Column {
                col,
                name,
                kind,
                max_def: cd.max_def_level(),
            }),
            None => skipped.push(format!(
                "{name} ({} {})",
                cd.physical_type(),
                cd.converted_type()
            )),
        }
    }
    if wanted.is_empty() {
        return Err(ReadError::NoChannels {
            file: file.to_string(),
            why: if skipped.is_empty() {
                "no columns".into()
            } else {
                format!("skipped: {}", skipped.join(", "))
            },
        });
    }
    Ok(Opened {
        reader,
        wanted,
        rows: rows as u64,
        limit,
    })
}

/// The table of a Parquet file of `size` bytes, read through `source` (checked by
/// [`open`]; `chunk` gives a column chunk's bytes). The columns are decoded side by side
/// when their chunks hold `parallel_from` bytes or more together.
fn read_inner<R: ChunkReader + 'static>(
    file: &str,
    source: R,
    size: u64,
    chunk: &ChunkFn<'_>,
    parallel_from: u64,
) -> Result<Table, ReadError> {
    let Opened {
        reader,
        wanted,
        rows,
        limit,
    } = open(file, source, size, chunk)?;
    let meta = reader.metadata();
    // The declared rows, but never more values than the file has bytes: a hostile footer
    // cannot make a column's allocation larger than 8 bytes per byte of the file.
    let capacity = rows.min(size) as usize;
    let read = |c: &Column| read_column(file, &reader, c, capacity, limit);
    // Columns side by side, each thread taking the next column not yet taken; the first
    // error in column order is the one reported, as when they are read one by one.
    let bytes: u64 = wanted
        .iter()
        .flat_map(|c| meta.row_groups().iter().map(|g| g.column(c.col)))
        .map(|cc| cc.compressed_size().max(0) as u64)
        .fold(0, u64::saturating_add);
    let threads = crate::par::threads_for(wanted.len(), bytes, parallel_from);
    let results = crate::par::map_ordered(&wanted, threads, read);
    let mut channels = Vec::with_capacity(wanted.len());
    for (c, r) in wanted.into_iter().zip(results) {
        let data = r.unwrap_or_else(|| Err(err(file, Some(&c.name), "its reader failed")))?;
        channels.push(Channel {
            name: c.name,
            unit: None,
            data,
            axis: None,
        });
    }
    Ok(Table {
        file: file.to_string(),
        channels,
        notes: Vec::new(),
    })
}

/// A numeric top-level column to read: its index in the schema, name, how its values
/// become `f64`, and its largest definition level (0 when it cannot hold a null).
struct Column {
    col: usize,
    name: String,
    kind: Kind,
    max_def: i16,
}

/// Every value of column `c`, its row groups in order, into a vector of `capacity`.
fn read_column<R: ChunkReader + 'static>(
    file: &str,
    reader: &SerializedFileReader<R>,
    c: &Column,
    capacity: usize,
    limit: u64,
) -> Result<Vec<f64>, ReadError> {
    let meta = reader.metadata();
    let mut data: Vec<f64> = Vec::with_capacity(capacity);
    for rg in 0..reader.num_row_groups() {
        let cc = meta.row_group(rg).column(c.col);
        let at = Chunk {
            name: &c.name,
            row_group: rg,
            offset: cc.dictionary_page_offset().unwrap_or(cc.data_page_offset()) as u64,
            len: cc.compressed_size() as u64,
        };
        // A panic of the crate in this column chunk names it (crate::guard).
        crate::guard::quietly(|| {
            read_chunk(
                file, reader, c.col, c.kind, c.max_def, limit, &at, &mut data,
            )
        })
        .unwrap_or_else(|| Err(at.undecodable(file)))?;
    }
    Ok(data)
}

/// Where a column chunk lies: its column, row group and bytes (from the footer, checked
/// against the file by [`check_pages`]).
struct Chunk<'a> {
    name: &'a str,
    row_group: usize,
    /// Byte offset of its first page (the dictionary page when it has one).
    offset: u64,
    /// Its compressed size \[bytes\].
    len: u64,
}

impl Chunk<'_> {
    /// The error for a chunk on which the `parquet` crate panicked.
    fn undecodable(&self, file: &str) -> ReadError {
        ReadError::Invalid {
            file: file.to_string(),
            channel: Some(self.name.to_string()),
            offset: self.offset,
            what: format!(
                "the Parquet column chunk of row group {} ({} bytes)",
                self.row_group, self.len
            ),
            found: "malformed: the parquet reader failed on it".into(),
            allowed: "pages as the Parquet format specifies them".into(),
        }
    }
}

/// The values of column `col` in the row group and column chunk `at`, appended to `data`.
#[allow(clippy::too_many_arguments)]
fn read_chunk<R: ChunkReader + 'static>(
    file: &str,
    reader: &SerializedFileReader<R>,
    col: usize,
    kind: Kind,
    max_def: i16,
    limit: u64,
    at: &Chunk<'_>,
    data: &mut Vec<f64>,
) -> Result<(), ReadError> {
    let mut col_reader = column_reader(file, reader, col, at)?;
    let mut batch = Batch::default();
    loop {
        let n = batch.read(file, &mut col_reader, kind, max_def, at, BATCH, data)?;
        if n == 0 {
            return Ok(());
        }
        if data.len() as u64 > limit {
            return Err(err(
                file,
                Some(at.name),
                format!("more than {limit} values"),
            ));
        }
    }
}

/// The reader of column `col` in the row group of `at`.
fn column_reader<R: ChunkReader + 'static>(
    file: &str,
    reader: &SerializedFileReader<R>,
    col: usize,
    at: &Chunk<'_>,
) -> Result<ColumnReader, ReadError> {
    reader
        .get_row_group(at.row_group)
        .and_then(|g| g.get_column_reader(col))
        .map_err(|e| err(file, Some(at.name), e))
}

/// Where a column chunk's reading stands, for [`Batch::read`] and its messages.
#[derive(Default)]
struct Batch {
    /// Definition levels of the last batch (scratch).
    defs: Vec<i16>,
    /// Rows of the row group read before the next batch.
    row0: usize,
    /// The channel's index of the value at `data[data_start]` (for messages).
    index0: usize,
    /// Where in `data` the values counted from `index0` start.
    data_start: usize,
}

impl Batch {
    /// At most `max` more values of the column chunk `at` through `col_reader`, appended
    /// to `data` as `f64` by `kind`; 0 at the chunk's end. A null (a definition level below
    /// `max_def`) or an `INT64` that no `f64` holds exactly is an error naming its row and
    /// index.
    #[allow(clippy::too_many_arguments)]
    fn read(
        &mut self,
        file: &str,
        col_reader: &mut ColumnReader,
        kind: Kind,
        max_def: i16,
        at: &Chunk<'_>,
        max: usize,
        data: &mut Vec<f64>,
    ) -> Result<usize, ReadError> {
        let (name, rg) = (at.name, at.row_group);
        let defs = &mut self.defs;
        defs.clear();
        let def = (max_def > 0).then_some(&mut *defs);
        let n = match col_reader {
            ColumnReader::DoubleColumnReader(r) => {
                // (the values are appended to `data`, decoded in place)
                let (recs, _, _) = r
                    .read_records(max, def, None, data)
                    .map_err(|e| err(file, Some(name), e))?;
                recs
            }
            ColumnReader::FloatColumnReader(r) => {
                let mut v = Vec::new();
                let (recs, _, _) = r
                    .read_records(max, def, None, &mut v)
                    .map_err(|e| err(file, Some(name), e))?;
                data.extend(v.into_iter().map(f64::from));
                recs
            }
            ColumnReader::Int32ColumnReader(r) => {
                let mut v = Vec::new();
                let (recs, _, _) = r
                    .read_records(max, def, None, &mut v)
                    .map_err(|e| err(file, Some(name), e))?;
                match kind {
                    Kind::Unsigned => data.extend(v.into_iter().map(|x| f64::from(x as u32))),
                    _ => data.extend(v.into_iter().map(f64::from)),
                }
                recs
            }
            ColumnReader::Int64ColumnReader(r) => {
                let mut v = Vec::new();
                let (recs, _, _) = r
                    .read_records(max, def, None, &mut v)
                    .map_err(|e| err(file, Some(name), e))?;
                for x in v {
                    let wide = match kind {
                        Kind::Unsigned => i128::from(x as u64),
                        _ => i128::from(x),
                    };
                    let f = wide as f64;
                    if f as i128 != wide {
                        return Err(ReadError::InexactInteger {
                            file: file.to_string(),
                            channel: name.to_string(),
                            index: self.index0 + (data.len() - self.data_start),
                            offset: at.offset,
                            value: wide,
                        });
                    }
                    data.push(f);
                }
                recs
            }
            _ => return Err(err(file, Some(name), "unexpected column reader")),
        };
        if let Some(i) = defs.iter().position(|&d| d < max_def) {
            return Err(ReadError::Invalid {
                file: file.to_string(),
                channel: Some(name.to_string()),
                offset: at.offset,
                what: format!(
                    "row {} of row group {rg}, in the Parquet column chunk",
                    self.row0 + i
                ),
                found: "a null".into(),
                allowed: "a value in every row".into(),
            });
        }
        self.row0 += n;
        Ok(n)
    }
}

/// Walks the Thrift footer (FileMetaData) the way the `parquet` crate will, before it
/// does, so that the crate's own parse of an accepted footer is linear in its length:
/// - the crate steps over an unknown field's list, set or map of booleans without reading
///   a byte per element, so a count of 2^31 there costs it 2^31 empty iterations (seconds,
///   from a footer of a few hundred bytes). Here such counts together must stay within the
///   footer's length; every other element costs a byte or more;
/// - the crate reads a field it knows as the type parquet-format declares, whatever type
///   the field header gives, and from there reads the following bytes as something else
///   than their headers say (where such a count can hide). Here every known field of every
///   structure the crate reads (`FILE_META_DATA` and below) must come with its declared
///   type, and list elements too;
/// - nesting stops at 80 levels.
///
/// A footer that does not end in `PAR1` is left to the crate's error. Returns where the
/// footer starts (0 when it is left to the crate: the crate then refuses the file).
fn check_footer(file: &str, size: u64, chunk: &ChunkFn<'_>) -> Result<u64, ReadError> {
    if size < 12 {
        return Ok(0);
    }
    let tail = chunk(size - 8, 8)?;
    if tail[4..] != *b"PAR1" {
        return Ok(0);
    }
    let len = u64::from(u32::from_le_bytes([tail[0], tail[1], tail[2], tail[3]]));
    if len > size - 8 {
        return Ok(0);
    }
    let start = size - 8 - len;
    let bytes = chunk(start, len)?;
    let mut t = Thrift::new(&bytes);
    if t.typed(&Ty::Struct(FILE_META_DATA), 0).is_none() {
        return Err(ReadError::invalid(
            file,
            None,
            start + t.i.min(bytes.len()) as u64,
            "Parquet footer".into(),
            "a malformed Thrift structure",
            format!(
                "a Thrift compact FileMetaData within the footer's {len} bytes, its fields of \
                 their declared types, nested at most {MAX_DEPTH} deep, its containers of \
                 booleans holding at most {len} elements together"
            ),
        ));
    }
    Ok(start)
}

/// Walks the page headers of a column chunk of `len` bytes at `start` (in a file of `size`
/// bytes, read by `chunk`), checking each page's sizes before the `parquet` crate
/// allocates them.
fn check_pages(
    file: &str,
    size: u64,
    chunk: &ChunkFn<'_>,
    name: &str,
    start: i64,
    len: i64,
) -> Result<(), ReadError> {
    let bad = |offset: u64, found: String, allowed: String| ReadError::Invalid {
        file: file.to_string(),
        channel: Some(name.to_string()),
        offset,
        what: "Parquet page".into(),
        found,
        allowed,
    };
    let (Ok(start), Ok(len)) = (u64::try_from(start), u64::try_from(len)) else {
        return Err(bad(
            0,
            format!("a column chunk at {start} of {len} bytes"),
            "non-negative offsets".into(),
        ));
    };
    let end = start
        .checked_add(len)
        .filter(|&e| e <= size)
        .ok_or_else(|| {
            bad(
                start,
                format!("a column chunk of {len} bytes"),
                format!("one within the file's {size} bytes"),
            )
        })?;
    let mut pos = start;
    while pos < end {
        // The page header from the first HEADER_WINDOW bytes at `pos`, or from a window 16
        // times longer each time it runs past one, up to the rest of the chunk: a walk that
        // succeeds on a prefix reads the same bytes in the whole, and the boolean budget is
        // the chunk's length either way. What is read per page stays within 16 times its
        // header plus a window, and the pages' contents are not read here (the parquet crate
        // reads them once).
        let rest = end - pos;
        let mut n = HEADER_WINDOW;
        let header = loop {
            let bytes = chunk(pos, n.min(rest))?;
            let mut t = Thrift {
                b: &bytes,
                i: 0,
                bools: len,
            };
            let header = t.page_header().map(|h| (h, t.i as u64));
            if header.is_some() || n >= rest {
                break header;
            }
            n = n.saturating_mul(16);
        };
        let ((unc, comp), header_len) = header.ok_or_else(|| {
            bad(
                pos,
                "a malformed page header".into(),
                "a Thrift compact PageHeader".into(),
            )
        })?;
        let (Ok(unc), Ok(comp)) = (u64::try_from(unc), u64::try_from(comp)) else {
            return Err(bad(
                pos,
                format!("page sizes {unc} and {comp}"),
                "non-negative sizes".into(),
            ));
        };
        let data = pos + header_len;
        if comp > end - data {
            return Err(bad(
                pos,
                format!("a page of {comp} compressed bytes"),
                format!("at most the {} left in its column chunk", end - data),
            ));
        }
        let limit = comp.saturating_mul(1032).saturating_add(1024);
        if unc > limit {
            return Err(bad(
                pos,
                format!("{unc} uncompressed bytes from {comp}"),
                format!("at most {limit}"),
            ));
        }
        pos = data + comp;
    }
    Ok(())
}

/// Bytes read at a page's start to walk its header (a page header of a numeric column is
/// tens of bytes; a longer one is walked in longer windows).
const HEADER_WINDOW: u64 = 4096;

/// Deepest nesting of Thrift structures and containers walked (the `parquet` crate's skip
/// allows 64 below the field it skips).
const MAX_DEPTH: u32 = 80;

/// Just enough of the Thrift compact protocol to read a PageHeader's sizes (fields 2 and 3)
/// and step over everything else exactly as the `parquet` crate's skip does, so that what
/// this walk accepts the crate parses in time linear in its length: a boolean element of a
/// list, set or map takes no byte there (the crate reads none), and such elements draw on
/// a budget of `bools`, the walked bytes' length.
struct Thrift<'a> {
    b: &'a [u8],
    i: usize,
    bools: u64,
}

impl<'a> Thrift<'a> {
    fn new(b: &'a [u8]) -> Self {
        Thrift {
            b,
            i: 0,
            bools: b.len() as u64,
        }
    }
    fn byte(&mut self) -> Option<u8> {
        let v = *self.b.get(self.i)?;
        self.i += 1;
        Some(v)
    }
    fn varint(&mut self) -> Option<u64> {
        let mut v = 0u64;
        for shift in (0..64).step_by(7) {
            let b = self.byte()?;
            v |= u64::from(b & 0x7f) << shift;
            if b & 0x80 == 0 {
                return Some(v);
            }
        }
        None
    }
    fn zigzag(&mut self) -> Option<i64> {
        let v = self.varint()?;
        Some((v >> 1) as i64 ^ -((v & 1) as i64))
    }
    /// A list or set header: its first byte (the element type in the low nibble) and the
    /// element count.
    fn list_header(&mut self) -> Option<(u8, u64)> {
        let h = self.byte()?;
        let n = match h >> 4 {
            15 => self.varint()?,
            n => u64::from(n),
        };
        Some((h, n))
    }
    /// Steps over a binary (its length, then its bytes).
    fn binary(&mut self) -> Option<()> {
        let n = usize::try_from(self.varint()?).ok()?;
        self.i = self.i.checked_add(n)?;
        Some(())
    }
    /// Draws `n` boolean elements from the budget.
    fn spend_bools(&mut self, n: u64) -> Option<()> {
        self.bools = self.bools.checked_sub(n)?;
        Some(())
    }
    fn skip(&mut self, ty: u8, depth: u32) -> Option<()> {
        if depth > MAX_DEPTH {
            return None;
        }
        match ty {
            1 | 2 => {}
            3 => self.i = self.i.checked_add(1)?,
            4..=6 => {
                self.varint()?;
            }
            7 => self.i = self.i.checked_add(8)?,
            8 => self.binary()?,
            9 | 10 => {
                let (h, n) = self.list_header()?;
                let elem = h & 0x0f;
                if elem <= 2 {
                    // the crate checks the element type (0 is none) and reads no byte
                    (elem != 0 || n == 0).then_some(())?;
                    self.spend_bools(n)?;
                } else {
                    // each element takes a byte at least: the walk ends within the bytes
                    for _ in 0..n {
                        self.skip(elem, depth + 1)?;
                    }
                }
            }
            11 => {
                let n = self.varint()?;
                if n > 0 {
                    let kv = self.byte()?;
                    let (k, v) = (kv >> 4, kv & 0x0f);
                    if k == 0 || v == 0 {
                        return None;
                    }
                    if k <= 2 && v <= 2 {
                        self.spend_bools(n.checked_mul(2)?)?;
                    } else {
                        if k <= 2 || v <= 2 {
                            self.spend_bools(n)?;
                        }
                        for _ in 0..n {
                            self.skip(k, depth + 1)?;
                            self.skip(v, depth + 1)?;
                        }
                    }
                }
            }
            12 => {
                self.fields(depth + 1, |_, _, _| Some(false))?;
            }
            13 => self.i = self.i.checked_add(16)?,
            _ => return None,
        }
        (self.i <= self.b.len()).then_some(())
    }
    /// Reads a struct's fields, giving `f` the chance to read each (it returns whether it
    /// did); the others are skipped. A field header whose type is 0 ends the struct, as in
    /// the `parquet` crate (whatever its id delta).
    fn fields(
        &mut self,
        depth: u32,
        mut f: impl FnMut(&mut Self, i16, u8) -> Option<bool>,
    ) -> Option<()> {
        let mut id: i16 = 0;
        loop {
            let h = self.byte()?;
            let ty = h & 0x0f;
            if ty == 0 {
                return Some(());
            }
            id = match h >> 4 {
                0 => i16::try_from(self.zigzag()?).ok()?,
                d => id.checked_add(i16::from(d))?,
            };
            if !f(self, id, ty)? {
                self.skip(ty, depth)?;
            }
        }
    }
    /// A struct of `schema`: each field it names must come with the wire type it declares
    /// (the `parquet` crate reads a known field as its declared type whatever the wire
    /// says, so a mismatch would put the two walks out of step) and is walked as that type,
    /// unless `take` reads it (returning true); any other field is skipped.
    fn typed_struct(
        &mut self,
        schema: &[(i16, Ty)],
        depth: u32,
        mut take: impl FnMut(&mut Self, i16) -> Option<bool>,
    ) -> Option<()> {
        if depth > MAX_DEPTH {
            return None;
        }
        self.fields(depth + 1, |t, id, wire| {
            let Some((_, ty)) = schema.iter().find(|(i, _)| *i == id) else {
                return Some(false);
            };
            ty.matches(wire).then_some(())?;
            if !take(t, id)? {
                t.typed(ty, depth + 1)?;
            }
            Some(true)
        })
    }
    /// A value of type `ty` (its field header already read).
    fn typed(&mut self, ty: &Ty, depth: u32) -> Option<()> {
        match ty {
            Ty::Bool => {}
            Ty::I8 => {
                self.byte()?;
            }
            Ty::I16 | Ty::I32 | Ty::I64 => {
                self.varint()?;
            }
            Ty::Double => self.i = self.i.checked_add(8)?,
            Ty::Binary => self.binary()?,
            Ty::List(elem) => {
                let (h, n) = self.list_header()?;
                // the crate reads an empty list from a 0 header; otherwise the element
                // type must be the declared one (no declared list holds booleans)
                if h != 0 {
                    (h & 0x0f == elem.wire()).then_some(())?;
                    for _ in 0..n {
                        self.typed(elem, depth + 1)?;
                    }
                }
            }
            Ty::Struct(schema) => self.typed_struct(schema, depth, |_, _| Some(false))?,
        }
        (self.i <= self.b.len()).then_some(())
    }
    /// A PageHeader's uncompressed and compressed sizes.
    fn page_header(&mut self) -> Option<(i64, i64)> {
        let (mut unc, mut comp) = (None, None);
        self.typed_struct(PAGE_HEADER, 0, |t, id| match id {
            2 => {
                unc = Some(t.zigzag()?);
                Some(true)
            }
            3 => {
                comp = Some(t.zigzag()?);
                Some(true)
            }
            _ => Some(false),
        })?;
        Some((unc?, comp?))
    }
}

/// A Thrift type of the Parquet footer and page headers, as the `parquet` crate reads it.
#[derive(Debug)]
enum Ty {
    Bool,
    I8,
    I16,
    I32,
    I64,
    Double,
    Binary,
    List(&'static Ty),
    Struct(&'static [(i16, Ty)]),
}

impl Ty {
    /// Its compact-protocol type as a list element.
    fn wire(&self) -> u8 {
        match self {
            Ty::Bool => 1,
            Ty::I8 => 3,
            Ty::I16 => 4,
            Ty::I32 => 5,
            Ty::I64 => 6,
            Ty::Double => 7,
            Ty::Binary => 8,
            Ty::List(_) => 9,
            Ty::Struct(_) => 12,
        }
    }
    /// Whether a field header's type `wire` is this type.
    fn matches(&self, wire: u8) -> bool {
        match self {
            Ty::Bool => wire == 1 || wire == 2,
            t => t.wire() == wire,
        }
    }
}

// The structures of parquet-format 2.x the `parquet` crate (59) reads by their declared
// types (file/metadata/thrift/mod.rs, basic.rs there); the fields it skips (ColumnMetaData
// 3 and 8, RowGroup 6, the encryption fields without its `encryption` feature) are left
// out, so they are skipped here too.
const EMPTY: &[(i16, Ty)] = &[];
const STATISTICS: &[(i16, Ty)] = &[
    (1, Ty::Binary),
    (2, Ty::Binary),
    (3, Ty::I64),
    (4, Ty::I64),
    (5, Ty::Binary),
    (6, Ty::Binary),
    (7, Ty::Bool),
    (8, Ty::Bool),
];
const TIME_UNIT: &[(i16, Ty)] = &[
    (1, Ty::Struct(EMPTY)),
    (2, Ty::Struct(EMPTY)),
    (3, Ty::Struct(EMPTY)),
];
const TIMESTAMP: &[(i16, Ty)] = &[(1, Ty::Bool), (2, Ty::Struct(TIME_UNIT))];
const LOGICAL_TYPE: &[(i16, Ty)] = &[
    (1, Ty::Struct(EMPTY)),
    (2, Ty::Struct(EMPTY)),
    (3, Ty::Struct(EMPTY)),
    (4, Ty::Struct(EMPTY)),
    (5, Ty::Struct(&[(1, Ty::I32), (2, Ty::I32)])),
    (6, Ty::Struct(EMPTY)),
    (7, Ty::Struct(TIMESTAMP)),
    (8, Ty::Struct(TIMESTAMP)),
    (10, Ty::Struct(&[(1, Ty::I8), (2, Ty::Bool)])),
    (11, Ty::Struct(EMPTY)),
    (12, Ty::Struct(EMPTY)),
    (13, Ty::Struct(EMPTY)),
    (14, Ty::Struct(EMPTY)),
    (15, Ty::Struct(EMPTY)),
    (16, Ty::Struct(&[(1, Ty::I8)])),
    (17, Ty::Struct(&[(1, Ty::Binary)])),
    (18, Ty::Struct(&[(1, Ty::Binary), (2, Ty::I32)])),
];
const SCHEMA_ELEMENT: &[(i16, Ty)] = &[
    (1, Ty::I32),
    (2, Ty::I32),
    (3, Ty::I32),
    (4, Ty::Binary),
    (5, Ty::I32),
    (6, Ty::I32),
    (7, Ty::I32),
    (8, Ty::I32),
    (9, Ty::I32),
    (10, Ty::Struct(LOGICAL_TYPE)),
];
const KEY_VALUE: &[(i16, Ty)] = &[(1, Ty::Binary), (2, Ty::Binary)];
const BOUNDING_BOX: &[(i16, Ty)] = &[
    (1, Ty::Double),
    (2, Ty::Double),
    (3, Ty::Double),
    (4, Ty::Double),
    (5, Ty::Double),
    (6, Ty::Double),
    (7, Ty::Double),
    (8, Ty::Double),
];
const COLUMN_META_DATA: &[(i16, Ty)] = &[
    (1, Ty::I32),
    (2, Ty::List(&Ty::I32)),
    (4, Ty::I32),
    (5, Ty::I64),
    (6, Ty::I64),
    (7, Ty::I64),
    (9, Ty::I64),
    (10, Ty::I64),
    (11, Ty::I64),
    (12, Ty::Struct(STATISTICS)),
    (
        13,
        Ty::List(&Ty::Struct(&[(1, Ty::I32), (2, Ty::I32), (3, Ty::I32)])),
    ),
    (14, Ty::I64),
    (15, Ty::I32),
    (
        16,
        Ty::Struct(&[
            (1, Ty::I64),
            (2, Ty::List(&Ty::I64)),
            (3, Ty::List(&Ty::I64)),
        ]),
    ),
    (
        17,
        Ty::Struct(&[(1, Ty::Struct(BOUNDING_BOX)), (2, Ty::List(&Ty::I32))]),
    ),
];
const COLUMN_CHUNK: &[(i16, Ty)] = &[
    (1, Ty::Binary),
    (2, Ty::I64),
    (3, Ty::Struct(COLUMN_META_DATA)),
    (4, Ty::I64),
    (5, Ty::I32),
    (6, Ty::I64),
    (7, Ty::I32),
];
const ROW_GROUP: &[(i16, Ty)] = &[
    (1, Ty::List(&Ty::Struct(COLUMN_CHUNK))),
    (2, Ty::I64),
    (3, Ty::I64),
    (
        4,
        Ty::List(&Ty::Struct(&[(1, Ty::I32), (2, Ty::Bool), (3, Ty::Bool)])),
    ),
    (5, Ty::I64),
    (7, Ty::I16),
];
const FILE_META_DATA: &[(i16, Ty)] = &[
    (1, Ty::I32),
    (2, Ty::List(&Ty::Struct(SCHEMA_ELEMENT))),
    (3, Ty::I64),
    (4, Ty::List(&Ty::Struct(ROW_GROUP))),
    (5, Ty::List(&Ty::Struct(KEY_VALUE))),
    (6, Ty::Binary),
    (7, Ty::List(&Ty::Struct(&[(1, Ty::Struct(EMPTY))]))),
];
const DATA_PAGE_HEADER: &[(i16, Ty)] = &[
    (1, Ty::I32),
    (2, Ty::I32),
    (3, Ty::I32),
    (4, Ty::I32),
    (5, Ty::Struct(STATISTICS)),
];
const DATA_PAGE_HEADER_V2: &[(i16, Ty)] = &[
    (1, Ty::I32),
    (2, Ty::I32),
    (3, Ty::I32),
    (4, Ty::I32),
    (5, Ty::I32),
    (6, Ty::I32),
    (7, Ty::Bool),
    (8, Ty::Struct(STATISTICS)),
];
const PAGE_HEADER: &[(i16, Ty)] = &[
    (1, Ty::I32),
    (2, Ty::I32),
    (3, Ty::I32),
    (4, Ty::I32),
    (5, Ty::Struct(DATA_PAGE_HEADER)),
    (6, Ty::Struct(EMPTY)),
    (7, Ty::Struct(&[(1, Ty::I32), (2, Ty::I32), (3, Ty::Bool)])),
    (8, Ty::Struct(DATA_PAGE_HEADER_V2)),
];

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::RefCell;

    /// `cols` written by rotorid's own Parquet writer, read from memory one column after
    /// another and from disk side by side (threads sharing one positional file), which must
    /// agree.
    fn written_and_read(
        cols: &[(&str, crate::write::ParquetColumn<'_>)],
    ) -> Result<Table, ReadError> {
        let bytes = crate::write::parquet_columns_bytes("w.parquet", cols).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("w.parquet");
        std::fs::write(&path, &bytes).unwrap();
        let mem = read_with("w.parquet", &bytes, u64::MAX);
        let disk = read_file_with("w.parquet", &path, 0);
        assert_eq!(format!("{mem:?}"), format!("{disk:?}"));
        disk
    }

    #[test]
    fn columns_read_side_by_side_are_the_columns_written_in_order() {
        use crate::write::ParquetColumn::Required;
        let data: Vec<Vec<f64>> = (0..9)
            .map(|k| {
                (0..5000)
                    .map(|i| f64::from(i) * 0.25 + f64::from(k) * 1e4)
                    .collect()
            })
            .collect();
        let names: Vec<String> = (0..9).map(|k| format!("c{k}")).collect();
        let cols: Vec<_> = names
            .iter()
            .zip(&data)
            .map(|(n, d)| (n.as_str(), Required(d)))
            .collect();
        let t = written_and_read(&cols).unwrap();
        assert_eq!(t.channels.len(), 9);
        for (c, (n, d)) in t.channels.iter().zip(names.iter().zip(&data)) {
            assert_eq!((&c.name, &c.data), (n, d));
        }
    }

    #[test]
    fn of_two_bad_columns_the_first_is_named_whichever_thread_finishes_first() {
        use crate::write::ParquetColumn::{Optional, Required};
        let ok: Vec<f64> = (0..3000).map(f64::from).collect();
        let hole = |at: usize| -> Vec<Option<f64>> {
            (0..3000).map(|i| (i != at).then_some(i as f64)).collect()
        };
        // b's null is late in a long column, d's early: d's reader fails first
        let (b, d) = (hole(2900), hole(1));
        let cols = [
            ("a", Required(&ok)),
            ("b", Optional(&b)),
            ("c", Required(&ok)),
            ("d", Optional(&d)),
        ];
        for _ in 0..20 {
            match written_and_read(&cols) {
                Err(ReadError::Invalid { channel, what, .. }) => {
                    assert_eq!(channel.as_deref(), Some("b"));
                    assert!(what.starts_with("row 2900 of row group 0"), "{what}");
                }
                other => panic!("{other:?}"),
            }
        }
    }

    /// A compact-protocol page header: type DATA_PAGE, the two sizes, and (when `pad` > 0)
    /// an unknown binary field 20 of `pad` bytes, which the walk steps over.
    fn header(unc: u32, comp: u32, pad: usize) -> Vec<u8> {
        let zz = |v: u32| {
            let mut z = u64::from(v) << 1;
            let mut out = Vec::new();
            loop {
                let b = (z & 0x7f) as u8;
                z >>= 7;
                if z == 0 {
                    out.push(b);
                    return out;
                }
                out.push(b | 0x80);
            }
        };
        let mut h = vec![0x15, 0x00, 0x15];
        h.extend(zz(unc));
        h.push(0x15);
        h.extend(zz(comp));
        if pad > 0 {
            // long-form field header: type binary (8), then the field id 20, zigzag-encoded
            h.extend([0x08, 40]);
            let mut n = pad as u64;
            while n >= 0x80 {
                h.push((n as u8 & 0x7f) | 0x80);
                n >>= 7;
            }
            h.push(n as u8);
            h.extend(std::iter::repeat_n(b'p', pad));
        }
        h.push(0x00);
        h
    }

    /// Page headers are walked in a window at each page's start, and in the rest of the
    /// chunk when one runs past it; what the pages hold is never read.
    #[test]
    fn long_page_headers_are_walked_past_the_window() {
        let mut chunk = header(10, 10, 6000);
        let second = chunk.len() + 10;
        chunk.extend([7u8; 10]);
        chunk.extend(header(20, 20, 0));
        chunk.extend([9u8; 20]);
        let reads = RefCell::new(Vec::new());
        let bytes = chunk.clone();
        let read = |at: u64, len: u64| {
            reads.borrow_mut().push((at, len));
            Ok(bytes[at as usize..(at + len) as usize].to_vec())
        };
        let size = chunk.len() as u64;
        check_pages("f.parquet", size, &read, "x", 0, size as i64).unwrap();
        let rest = size - second as u64;
        assert_eq!(
            *reads.borrow(),
            vec![(0, HEADER_WINDOW), (0, size), (second as u64, rest)]
        );

        // a header past the first window of a long chunk: the next window, not the rest
        let mut long = header(10, 10, 6000);
        long.extend([7u8; 10]);
        long.extend(std::iter::repeat_n(0u8, 200_000));
        let reads = RefCell::new(Vec::new());
        let read = |at: u64, len: u64| {
            reads.borrow_mut().push((at, len));
            Ok(long[at as usize..(at + len) as usize].to_vec())
        };
        let page = (header(10, 10, 6000).len() + 10) as i64;
        check_pages("f.parquet", long.len() as u64, &read, "x", 0, page).unwrap();
        assert_eq!(*reads.borrow(), vec![(0, HEADER_WINDOW), (0, page as u64)]);
        reads.borrow_mut().clear();
        // over the whole buffer: the first header needs the second window (4 KiB, then
        // 64 KiB, not the 200 KB rest), and the zeros after the page are no page header
        // (refused)
        let all = long.len() as i64;
        assert!(check_pages("f.parquet", long.len() as u64, &read, "x", 0, all).is_err());
        let lens: Vec<u64> = reads.borrow().iter().map(|r| r.1).collect();
        assert_eq!(lens[..2], [HEADER_WINDOW, 16 * HEADER_WINDOW]);

        // the long header cut short: refused at its page, after the whole rest was tried
        let cut = 5000;
        let read = |at: u64, len: u64| Ok(chunk[at as usize..(at + len) as usize].to_vec());
        let e = check_pages("f.parquet", cut, &read, "x", 0, cut as i64).unwrap_err();
        assert!(e.to_string().contains("malformed page header"), "{e}");
    }
}
