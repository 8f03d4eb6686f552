//! MATLAB v7.3 MAT-files: HDF5 files (HDF Group, "HDF5 File Format Specification" 3.0)
//! with MATLAB's conventions, read with the pure-Rust `hdf5-pure` crate.
//!
//! Conventions (MathWorks, "MAT-File Versions"; as MATLAB `save -v7.3` writes them): a
//! 512-byte HDF5 user block holds the level 5 style text header (version `0x0200`); each
//! variable is a root dataset or group whose `MATLAB_class` attribute names its class
//! (`double`, `single`, `int8`..`uint64`, `logical`, `char`, `struct`, `cell`, ...); the
//! dimensions are reversed (a MATLAB `n x 1` column is an HDF5 `1 x n` dataset, since
//! MATLAB is column-major), which does not matter for a vector; an empty array is stored as
//! its dimensions with `MATLAB_empty = 1`; complex data is a compound of `real` and
//! `imag`; a struct is a group whose datasets are its fields; `#refs#` and `#subsystem#`
//! hold cell contents and objects.
//!
//! Channels as in [`crate::mat`]: root numeric vectors by name, a struct group's numeric
//! vector fields as `struct.field`. The stored HDF5 type (not the class) is converted, each
//! integer exactly or not at all. Before a dataset is read, its element count times element
//! size is checked against 1032 times the file's size (deflate's largest ratio), so a forged
//! shape cannot make the reader allocate without bound. Errors of the HDF5 layer are
//! reported as [`ReadError::Container`] with the crate's message.

use hdf5_pure::{AttrValue, DType, Dataset, File, Group};

use crate::error::ReadError;
use crate::table::{Channel, Table};

const NUMERIC: &[&str] = &[
    "double", "single", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64",
    "logical",
];

/// Reads a v7.3 MAT-file's bytes; `file` names it in messages.
pub fn read(file: &str, bytes: &[u8]) -> Result<Table, ReadError> {
    read_hdf5(file, bytes.len() as u64, || {
        File::from_bytes(bytes.to_vec())
    })
}

/// Reads the v7.3 MAT-file at `path` from disk as the HDF5 layer needs it (its streaming
/// mode: metadata and chunks read on demand), so memory holds the channels and one chunk
/// rather than the whole file as well. Accepts and refuses what [`read`] does.
pub fn read_file(file: &str, path: &std::path::Path) -> Result<Table, ReadError> {
    let len = std::fs::metadata(path)
        .map_err(|source| ReadError::Io {
            file: file.to_string(),
            source,
        })?
        .len();
    read_hdf5(file, len, || File::open_streaming(path))
}

/// The channels of the HDF5 file `open` gives, `len` bytes long.
fn read_hdf5(
    file: &str,
    len: u64,
    open: impl FnOnce() -> Result<File, hdf5_pure::Error>,
) -> Result<Table, ReadError> {
    let limit = len.saturating_mul(1032);
    let run = || -> Result<Table, ReadError> {
        let h5 = open().map_err(|e| err(file, None, e))?;
        let root = h5.root();
        let mut channels = Vec::new();
        let mut skipped = Vec::new();
        for name in root.datasets().map_err(|e| err(file, None, e))? {
            let ds = root.dataset(&name).map_err(|e| err(file, Some(&name), e))?;
            let v = vector(file, &name, &ds, limit)?;
            keep(name, v, &mut channels, &mut skipped);
        }
        for gname in root.groups().map_err(|e| err(file, None, e))? {
            if gname.starts_with('#') {
                continue;
            }
            let g: Group = root.group(&gname).map_err(|e| err(file, Some(&gname), e))?;
            let attrs = g.attrs().map_err(|e| err(file, Some(&gname), e))?;
            let class = class_of(&attrs);
            if class.as_deref() != Some("struct") {
                skipped.push(format!(
                    "{gname}: a {}",
                    class.unwrap_or_else(|| "group".into())
                ));
                continue;
            }
            for f in g.datasets().map_err(|e| err(file, Some(&gname), e))? {
                let name = format!("{gname}.{f}");
                let ds = g.dataset(&f).map_err(|e| err(file, Some(&name), e))?;
                let v = vector(file, &name, &ds, limit)?;
                keep(name, v, &mut channels, &mut skipped);
            }
        }
        if channels.is_empty() {
            return Err(ReadError::NoChannels {
                file: file.to_string(),
                why: if skipped.is_empty() {
                    "no variables".into()
                } else {
                    format!("skipped: {}", skipped.join("; "))
                },
            });
        }
        Ok(Table {
            file: file.to_string(),
            channels,
            notes: Vec::new(),
        })
    };
    // The HDF5 layer is a third-party parser of a large format: a panic there on a hostile
    // file becomes an error here rather than taking the caller down (crate::guard).
    crate::guard::quietly(run).unwrap_or_else(|| {
        Err(ReadError::Container {
            file: file.to_string(),
            channel: None,
            container: "HDF5 (MAT v7.3)",
            message: "the HDF5 reader failed on a malformed structure".into(),
        })
    })
}

fn err(file: &str, channel: Option<&str>, e: hdf5_pure::Error) -> ReadError {
    ReadError::Container {
        file: file.to_string(),
        channel: channel.map(str::to_string),
        container: "HDF5 (MAT v7.3)",
        message: e.to_string(),
    }
}

fn class_of(attrs: &std::collections::HashMap<String, AttrValue>) -> Option<String> {
    match attrs.get("MATLAB_class")? {
        AttrValue::String(s) | AttrValue::AsciiString(s) => {
            Some(s.trim_end_matches('\0').to_string())
        }
        AttrValue::StringSized { value, .. } => Some(value.trim_end_matches('\0').to_string()),
        _ => None,
    }
}

/// The samples of a numeric vector dataset, `Ok(Err(why))` when it is not one.
fn vector(
    file: &str,
    name: &str,
    ds: &Dataset,
    limit: u64,
) -> Result<Result<Vec<f64>, String>, ReadError> {
    let e = |x| err(file, Some(name), x);
    let attrs = ds.attrs().map_err(e)?;
    let class = class_of(&attrs).unwrap_or_default();
    if !NUMERIC.contains(&class.as_str()) {
        return Ok(Err(format!("class {class:?}")));
    }
    if attrs.contains_key("MATLAB_empty") {
        return Ok(Err("an empty array".into()));
    }
    let shape = ds.shape().map_err(e)?;
    let numel = shape.iter().try_fold(1u64, |a, &d| a.checked_mul(d));
    let size = ds.element_size().map_err(e)?;
    let shown = shape
        .iter()
        .rev()
        .map(u64::to_string)
        .collect::<Vec<_>>()
        .join("x");
    match numel.and_then(|n| n.checked_mul(size)) {
        Some(b) if b <= limit => {}
        _ => {
            return Err(ReadError::Invalid {
                file: file.to_string(),
                channel: Some(name.to_string()),
                offset: 0,
                what: "HDF5 dataset extent".into(),
                found: format!("{shown} elements of {size} bytes"),
                allowed: format!("at most {limit} bytes (1032 times the file's size)"),
            })
        }
    }
    let numel = numel.unwrap_or(0);
    if shape.iter().filter(|&&d| d != 1).count() > 1 || numel == 0 {
        return Ok(Err(format!("a {shown} {class} matrix")));
    }
    let exact = |v: Vec<i128>| -> Result<Vec<f64>, ReadError> {
        v.into_iter()
            .enumerate()
            .map(|(index, x)| {
                let f = x as f64;
                if f as i128 == x {
                    Ok(f)
                } else {
                    Err(ReadError::InexactInteger {
                        file: file.to_string(),
                        channel: name.to_string(),
                        index,
                        offset: 0,
                        value: x,
                    })
                }
            })
            .collect()
    };
    let dtype = ds.dtype().map_err(e)?;
    let data = match dtype {
        DType::F64 => ds.read_f64().map_err(e)?,
        DType::F32 => ds
            .read_f32()
            .map_err(e)?
            .into_iter()
            .map(f64::from)
            .collect(),
        DType::I8 => ds
            .read_i8()
            .map_err(e)?
            .into_iter()
            .map(f64::from)
            .collect(),
        DType::U8 => ds
            .read_u8()
            .map_err(e)?
            .into_iter()
            .map(f64::from)
            .collect(),
        DType::I16 => ds
            .read_i16()
            .map_err(e)?
            .into_iter()
            .map(f64::from)
            .collect(),
        DType::U16 => ds
            .read_u16()
            .map_err(e)?
            .into_iter()
            .map(f64::from)
            .collect(),
        DType::I32 => ds
            .read_i32()
            .map_err(e)?
            .into_iter()
            .map(f64::from)
            .collect(),
        DType::U32 => ds
            .read_u32()
            .map_err(e)?
            .into_iter()
            .map(f64::from)
            .collect(),
        DType::I64 => exact(
            ds.read_i64()
                .map_err(e)?
                .into_iter()
                .map(i128::from)
                .collect(),
        )?,
        DType::U64 => exact(
            ds.read_u64()
                .map_err(e)?
                .into_iter()
                .map(i128::from)
                .collect(),
        )?,
        DType::Compound(_) => return Ok(Err(format!("a complex {shown} {class}"))),
        other => return Ok(Err(format!("an HDF5 {other} dataset"))),
    };
    if data.len() as u64 != numel {
        return Err(ReadError::Invalid {
            file: file.to_string(),
            channel: Some(name.to_string()),
            offset: 0,
            what: "HDF5 dataset".into(),
            found: format!("{} values", data.len()),
            allowed: format!("{numel} (its shape {shown})"),
        });
    }
    Ok(Ok(data))
}

/// A variable read as a vector becomes channel `name`; one that is not, a line of `skipped`.
fn keep(
    name: String,
    vector: Result<Vec<f64>, String>,
    channels: &mut Vec<Channel>,
    skipped: &mut Vec<String>,
) {
    match vector {
        Ok(data) => channels.push(Channel {
            name,
            unit: None,
            data,
            axis: None,
        }),
        Err(why) => skipped.push(format!("{name}: {why}")),
    }
}
