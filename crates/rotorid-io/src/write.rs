//! Writers of a [`Table`] as NPZ, MAT level 5 and Parquet (for `rotorid simulate --out`),
//! each read back by this crate's readers and by numpy, scipy and pyarrow
//! (`tests/writers.rs`, `tests/read_back.py`).
//!
//! Every channel is written as `f64` samples (no conversion, NaN kept). The unit and the
//! time axis of a channel are not written: none of the three formats has a place for them
//! that numpy, scipy and pyarrow read back, so write time as its own channel.
//!
//! - NPZ ([`npz_bytes`]): one stored (uncompressed) 1-D `<f8` member `NAME.npy` per
//!   channel, as `numpy.savez` writes; channels may differ in length.
//! - MAT level 5 ([`mat_v5_bytes`]): one `n x 1` double column per channel, uncompressed;
//!   a channel `a.b` becomes field `b` of a scalar struct `a`, as [`crate::mat`] reads it.
//!   Names (and field names) must be MATLAB identifiers: a letter, then letters, digits or
//!   `_`, at most 63 characters; channels may differ in length.
//! - Parquet ([`parquet_bytes`]): one required `DOUBLE` column per channel, snappy pages,
//!   row groups of 2^20 rows; all channels must have the same length.

use std::io::Write as _;
use std::path::Path;
use std::sync::Arc;

use crate::table::Table;

/// Why a table could not be written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum WriteError {
    /// The file could not be created or written.
    #[error("{file}: {source}")]
    Io {
        /// The file.
        file: String,
        /// The operating system's error.
        #[source]
        source: std::io::Error,
    },
    /// The extension names no format written here.
    #[error("{file}: cannot write {ext:?} files; written: .npz, .mat, .parquet")]
    UnknownFormat {
        /// The file.
        file: String,
        /// Its extension.
        ext: String,
    },
    /// The table cannot be expressed in the format.
    #[error("{file}, channel {channel:?}: {why}")]
    Unrepresentable {
        /// The file.
        file: String,
        /// The channel.
        channel: String,
        /// What the format does not allow.
        why: String,
    },
    /// The underlying library failed.
    #[error("{file}: {container}: {message}")]
    Container {
        /// The file.
        file: String,
        /// The container format.
        container: &'static str,
        /// The library's message.
        message: String,
    },
}

/// Writes `table` to `path` as the extension says (`.npz`, `.mat`, `.parquet`).
pub fn write_table(path: impl AsRef<Path>, table: &Table) -> Result<(), WriteError> {
    let path = path.as_ref();
    let file = path.display().to_string();
    let ext = path
        .extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .unwrap_or_default();
    let bytes = match ext.as_str() {
        "npz" => npz_bytes(&file, table)?,
        "mat" => mat_v5_bytes(&file, table)?,
        "parquet" => parquet_bytes(&file, table)?,
        _ => return Err(WriteError::UnknownFormat { file, ext }),
    };
    std::fs::write(path, bytes).map_err(|source| WriteError::Io { file, source })
}

/// The `.npy` bytes of a 1-D `<f8` array (NPY format version 1.0).
fn npy_bytes(data: &[f64]) -> Vec<u8> {
    let mut header = format!(
        "{{'descr': '<f8', 'fortran_order': False, 'shape': ({},), }}",
        data.len()
    );
    // Magic, version, length, header and its closing newline padded to 64 bytes.
    while (10 + header.len() + 1) % 64 != 0 {
        header.push(' ');
    }
    header.push('\n');
    let mut out = Vec::with_capacity(10 + header.len() + 8 * data.len());
    out.extend_from_slice(b"\x93NUMPY\x01\x00");
    out.extend_from_slice(&(header.len() as u16).to_le_bytes());
    out.extend_from_slice(header.as_bytes());
    for v in data {
        out.extend_from_slice(&v.to_le_bytes());
    }
    out
}

/// `table` as an NPZ archive (stored members, as `numpy.savez`); `file` names it in errors.
pub fn npz_bytes(file: &str, table: &Table) -> Result<Vec<u8>, WriteError> {
    let zerr = |e: &dyn std::fmt::Display| WriteError::Container {
        file: file.to_string(),
        container: "zip",
        message: e.to_string(),
    };
    let mut zip = zip::ZipWriter::new(std::io::Cursor::new(Vec::new()));
    let options = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Stored)
        .large_file(true);
    for c in &table.channels {
        if c.name.is_empty() {
            return Err(WriteError::Unrepresentable {
                file: file.to_string(),
                channel: c.name.clone(),
                why: "an empty name".into(),
            });
        }
        zip.start_file(format!("{}.npy", c.name), options)
            .map_err(|e| zerr(&e))?;
        zip.write_all(&npy_bytes(&c.data)).map_err(|e| zerr(&e))?;
    }
    Ok(zip.finish().map_err(|e| zerr(&e))?.into_inner())
}

fn matlab_identifier(s: &str) -> bool {
    let mut ch = s.chars();
    ch.next().is_some_and(|c| c.is_ascii_alphabetic())
        && ch.all(|c| c.is_ascii_alphanumeric() || c == '_')
        && s.len() <= 63
}

/// An element: tag, data, padding to 8 bytes.
fn mat_element(out: &mut Vec<u8>, ty: u32, data: &[u8]) {
    out.extend_from_slice(&ty.to_le_bytes());
    out.extend_from_slice(&(data.len() as u32).to_le_bytes());
    out.extend_from_slice(data);
    out.resize(out.len() + (8 - data.len() % 8) % 8, 0);
}

/// An `miMATRIX` holding an `n x 1` double column.
fn mat_column(name: &str, data: &[f64]) -> Vec<u8> {
    let mut m = Vec::with_capacity(64 + name.len() + 8 * data.len());
    let mut flags = 6u32.to_le_bytes().to_vec(); // mxDOUBLE_CLASS, no flags
    flags.extend_from_slice(&0u32.to_le_bytes());
    mat_element(&mut m, 6, &flags);
    let mut dims = (data.len() as i32).to_le_bytes().to_vec();
    dims.extend_from_slice(&1i32.to_le_bytes());
    mat_element(&mut m, 5, &dims);
    mat_element(&mut m, 1, name.as_bytes());
    let mut re = Vec::with_capacity(8 * data.len());
    for v in data {
        re.extend_from_slice(&v.to_le_bytes());
    }
    mat_element(&mut m, 9, &re);
    let mut out = Vec::with_capacity(8 + m.len());
    mat_element(&mut out, 14, &m);
    out
}

/// A struct field's name (empty for a plain variable) and samples.
type Field<'a> = (String, &'a [f64]);

/// `table` as a level 5 MAT-file (uncompressed, little endian); `file` names it in errors.
pub fn mat_v5_bytes(file: &str, table: &Table) -> Result<Vec<u8>, WriteError> {
    let bad = |channel: &str, why: String| WriteError::Unrepresentable {
        file: file.to_string(),
        channel: channel.to_string(),
        why,
    };
    // Variables in order of first appearance: a plain channel, or a struct of fields.
    let mut vars: Vec<(String, Vec<Field>)> = Vec::new();
    for c in &table.channels {
        let (var, field) = match c.name.split_once('.') {
            Some((v, f)) => (v, Some(f)),
            None => (c.name.as_str(), None),
        };
        for part in [Some(var), field].into_iter().flatten() {
            if !matlab_identifier(part) {
                return Err(bad(&c.name, format!("{part:?} is not a MATLAB identifier (a letter, then letters, digits or _, at most 63)")));
            }
        }
        if c.data.len() > (u32::MAX / 8) as usize {
            return Err(bad(
                &c.name,
                format!(
                    "{} samples; a level 5 element holds at most {}",
                    c.data.len(),
                    u32::MAX / 8
                ),
            ));
        }
        let field = field.unwrap_or("").to_string();
        match vars.iter_mut().find(|(v, _)| v == var) {
            Some((_, fields))
                if !field.is_empty()
                    && fields.iter().all(|(f, _)| !f.is_empty() && *f != field) =>
            {
                fields.push((field, &c.data))
            }
            Some(_) => {
                return Err(bad(
                    &c.name,
                    format!("{var:?} is both a channel and a struct, or repeated"),
                ))
            }
            None => vars.push((var.to_string(), vec![(field, &c.data)])),
        }
    }
    let mut out = Vec::new();
    let mut text = b"MATLAB 5.0 MAT-file, written by rotorid-io".to_vec();
    text.resize(116, b' ');
    out.extend_from_slice(&text);
    out.extend_from_slice(&[0; 8]);
    out.extend_from_slice(&0x0100u16.to_le_bytes());
    out.extend_from_slice(b"IM");
    for (var, fields) in vars {
        if fields.len() == 1 && fields[0].0.is_empty() {
            out.extend(mat_column(&var, fields[0].1));
            continue;
        }
        let mut m = Vec::new();
        let mut flags = 2u32.to_le_bytes().to_vec(); // mxSTRUCT_CLASS
        flags.extend_from_slice(&0u32.to_le_bytes());
        mat_element(&mut m, 6, &flags);
        let mut dims = 1i32.to_le_bytes().to_vec();
        dims.extend_from_slice(&1i32.to_le_bytes());
        mat_element(&mut m, 5, &dims);
        mat_element(&mut m, 1, var.as_bytes());
        let width = 64usize;
        mat_element(&mut m, 5, &(width as i32).to_le_bytes()[..]);
        let mut names = vec![0u8; width * fields.len()];
        for (k, (f, _)) in fields.iter().enumerate() {
            names[k * width..k * width + f.len()].copy_from_slice(f.as_bytes());
        }
        mat_element(&mut m, 1, &names);
        for (_, data) in &fields {
            m.extend(mat_column("", data));
        }
        mat_element(&mut out, 14, &m);
    }
    Ok(out)
}

/// `table` as a Parquet file (required DOUBLE columns, snappy); `file` names it in errors.
pub fn parquet_bytes(file: &str, table: &Table) -> Result<Vec<u8>, WriteError> {
    let columns: Vec<(&str, ParquetColumn<'_>)> = table
        .channels
        .iter()
        .map(|c| (c.name.as_str(), ParquetColumn::Required(&c.data)))
        .collect();
    parquet_columns_bytes(file, &columns)
}

/// One column for [`parquet_columns_bytes`].
#[derive(Debug, Clone, Copy)]
pub enum ParquetColumn<'a> {
    /// A `required double` column: every row has a value.
    Required(&'a [f64]),
    /// An `optional double` column: `None` is a null (pandas reads NaN, polars null), e.g.
    /// an estimate withheld as ill-conditioned.
    Optional(&'a [Option<f64>]),
}

impl ParquetColumn<'_> {
    fn len(&self) -> usize {
        match self {
            Self::Required(v) => v.len(),
            Self::Optional(v) => v.len(),
        }
    }
}

/// Named columns of equal length as a Parquet file (DOUBLE, snappy, row groups of 2^20
/// rows); `file` names it in errors.
pub fn parquet_columns_bytes(
    file: &str,
    columns: &[(&str, ParquetColumn<'_>)],
) -> Result<Vec<u8>, WriteError> {
    use parquet::basic::{Compression, Repetition, Type as Physical};
    use parquet::data_type::DoubleType;
    use parquet::file::properties::WriterProperties;
    use parquet::file::writer::SerializedFileWriter;
    use parquet::schema::types::Type;

    let perr = |e: parquet::errors::ParquetError| WriteError::Container {
        file: file.to_string(),
        container: "Parquet",
        message: e.to_string(),
    };
    let rows = columns.first().map_or(0, |(_, c)| c.len());
    let mut fields = Vec::new();
    for (name, c) in columns {
        if c.len() != rows {
            return Err(WriteError::Unrepresentable {
                file: file.to_string(),
                channel: (*name).to_string(),
                why: format!("{} samples where the first channel has {rows}: Parquet columns share their rows", c.len()),
            });
        }
        let repetition = match c {
            ParquetColumn::Required(_) => Repetition::REQUIRED,
            ParquetColumn::Optional(_) => Repetition::OPTIONAL,
        };
        fields.push(Arc::new(
            Type::primitive_type_builder(name, Physical::DOUBLE)
                .with_repetition(repetition)
                .build()
                .map_err(perr)?,
        ));
    }
    let schema = Arc::new(
        Type::group_type_builder("schema")
            .with_fields(fields)
            .build()
            .map_err(perr)?,
    );
    let props = Arc::new(
        WriterProperties::builder()
            .set_compression(Compression::SNAPPY)
            .build(),
    );
    let mut out = Vec::new();
    let mut w = SerializedFileWriter::new(&mut out, schema, props).map_err(perr)?;
    const GROUP: usize = 1 << 20;
    let mut start = 0;
    let mut values = Vec::new();
    let mut levels = Vec::new();
    while start < rows || (rows == 0 && start == 0) {
        let end = (start + GROUP).min(rows);
        let mut rg = w.next_row_group().map_err(perr)?;
        let mut k = 0;
        while let Some(mut col) = rg.next_column().map_err(perr)? {
            let typed = col.typed::<DoubleType>();
            match columns[k].1 {
                ParquetColumn::Required(v) => typed.write_batch(&v[start..end], None, None),
                ParquetColumn::Optional(v) => {
                    values.clear();
                    levels.clear();
                    for x in &v[start..end] {
                        levels.push(i16::from(x.is_some()));
                        values.extend(x);
                    }
                    typed.write_batch(&values, Some(&levels), None)
                }
            }
            .map_err(perr)?;
            col.close().map_err(perr)?;
            k += 1;
        }
        rg.close().map_err(perr)?;
        if rows == 0 {
            break;
        }
        start = end;
    }
    w.close().map_err(perr)?;
    Ok(out)
}
