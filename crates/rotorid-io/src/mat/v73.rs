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
//! reported as [`ReadError::Container`] with the crate's message. Errors about a dataset's
//! values give the byte of the value (contiguous storage, an unfiltered chunk) or of its
//! compressed chunk; errors about the dataset as a whole, the byte its data starts at (the
//! HDF5 layer does not give the address of the object header that holds its shape).
//!
//! A dataset of IEEE little-endian doubles stored contiguously (what MATLAB and h5py write
//! for a `double` vector without compression) is read straight from its bytes in the file
//! onto the channel, a block at a time; the HDF5 layer would hold its bytes and its values
//! at once.

use hdf5_pure::{AttrValue, DType, Dataset, File, Group, Layout};

use crate::error::ReadError;
use crate::num::{samples_at, Dtype, Endian};
use crate::source::Source;
use crate::table::{Channel, Table};

const NUMERIC: &[&str] = &[
    "double", "single", "int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64",
    "logical",
];

/// Reads a v7.3 MAT-file's bytes; `file` names it in messages.
pub fn read(file: &str, bytes: &[u8]) -> Result<Table, ReadError> {
    read_hdf5(file, bytes, || File::from_bytes(bytes.to_vec()))
}

/// Reads the v7.3 MAT-file at `path` from disk as the HDF5 layer needs it (its streaming
/// mode: metadata and chunks read on demand), so memory holds the channels and one chunk
/// rather than the whole file as well. Accepts and refuses what [`read`] does.
pub fn read_file(file: &str, path: &std::path::Path) -> Result<Table, ReadError> {
    let disk = crate::source::DiskFile::open(file, path)?;
    read_hdf5(file, &disk, || File::open_streaming(path))
}

/// The channels of the HDF5 file `open` gives, whose bytes `src` reads.
fn read_hdf5<S: Source + ?Sized>(
    file: &str,
    src: &S,
    open: impl FnOnce() -> Result<File, hdf5_pure::Error>,
) -> Result<Table, ReadError> {
    let limit = src.size().saturating_mul(1032);
    let run = || -> Result<Table, ReadError> {
        let h5 = open().map_err(|e| err(file, None, e))?;
        let root = h5.root();
        let mut channels = Vec::new();
        let mut skipped = Vec::new();
        for name in root.datasets().map_err(|e| err(file, None, e))? {
            let ds = root.dataset(&name).map_err(|e| err(file, Some(&name), e))?;
            let v = vector(file, src, &name, &ds, limit)?;
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
                let v = vector(file, src, &name, &ds, limit)?;
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

/// The samples of a numeric vector dataset, `Ok(Err(why))` when it is not one; `src` reads
/// the file's bytes (module doc).
fn vector<S: Source + ?Sized>(
    file: &str,
    src: &S,
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
    let extent = Bounded {
        file,
        name,
        ds,
        size,
        limit,
    };
    extent.check(
        "HDF5 dataset extent",
        numel.and_then(|n| n.checked_mul(size)),
        &shown,
    )?;
    let numel = numel.unwrap_or(0);
    if shape.iter().filter(|&&d| d != 1).count() > 1 || numel == 0 {
        return Ok(Err(format!("a {shown} {class} matrix")));
    }
    check_storage(&extent, src.size())?;
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
                        offset: sample_offset(ds, &shape, index as u64, size),
                        value: x,
                    })
                }
            })
            .collect()
    };
    let dtype = ds.dtype().map_err(e)?;
    let data = match dtype {
        DType::F64 => match plain_doubles(src, ds, numel) {
            Some(at) => doubles_at(file, src, name, at, numel)?,
            None => ds.read_f64().map_err(e)?,
        },
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
            offset: data_start(ds),
            what: "HDF5 dataset".into(),
            found: format!("{} values", data.len()),
            allowed: format!("{numel} (its shape {shown})"),
        });
    }
    Ok(Ok(data))
}

/// The bound on what a dataset `ds` of channel `name` (elements of `size` bytes) may make
/// the reader allocate: `limit` bytes (1032 times the file's size).
struct Bounded<'a> {
    file: &'a str,
    name: &'a str,
    ds: &'a Dataset,
    size: u64,
    limit: u64,
}

impl Bounded<'_> {
    /// `Ok` when `bytes` (of elements shown as `shown`; `None`: beyond 64 bits) are at most
    /// the limit, else the error naming `what` at the byte where the dataset's data starts.
    fn check(&self, what: &str, bytes: Option<u64>, shown: &str) -> Result<(), ReadError> {
        match bytes {
            Some(b) if b <= self.limit => Ok(()),
            _ => Err(ReadError::Invalid {
                file: self.file.to_string(),
                channel: Some(self.name.to_string()),
                offset: data_start(self.ds),
                what: format!("{what} (of the dataset whose data starts here)"),
                found: format!("{shown} elements of {} bytes", self.size),
                allowed: format!("at most {} bytes (1032 times the file's size)", self.limit),
            }),
        }
    }
}

/// The storage of the dataset `b.ds` checked before the HDF5 layer reads it, which sizes
/// its buffers from it: contiguous data within the file of `len` bytes; chunks within
/// [`Bounded`]'s limit, each stored within the file (a forged chunk address made the layer
/// allocate the gigabytes up to it), listed from an index that can be listed. A B-tree v2
/// index, which the layer cannot list yet, is left to its own checks.
fn check_storage(b: &Bounded<'_>, len: u64) -> Result<(), ReadError> {
    let (file, name, ds) = (b.file, b.name, b.ds);
    let beyond = |offset: u64, what: String, stored: u64| ReadError::Invalid {
        file: file.to_string(),
        channel: Some(name.to_string()),
        offset,
        what,
        found: format!(
            "{stored} bytes long, ending at byte {}",
            offset.saturating_add(stored)
        ),
        allowed: format!("within the file's {len} bytes"),
    };
    match ds.layout() {
        Ok(Layout::Contiguous {
            address: Some(a),
            size: stored,
        }) if a.checked_add(stored).is_none_or(|end| end > len) => {
            Err(beyond(a, "HDF5 contiguous dataset storage".into(), stored))
        }
        Ok(Layout::Chunked { chunk_shape, index }) => {
            let bytes = chunk_shape
                .iter()
                .try_fold(b.size, |a, &d| a.checked_mul(d));
            b.check("HDF5 chunk shape", bytes, &format!("{chunk_shape:?}"))?;
            let chunks = match ds.chunks() {
                Ok(c) => c,
                // (the layer cannot list a B-tree v2 index yet: left to its own checks)
                Err(_) if index == hdf5_pure::ChunkIndex::BTreeV2 => Vec::new(),
                // an index that cannot be listed is refused, not read
                Err(e) => return Err(err(file, Some(name), e)),
            };
            for c in chunks {
                if c.address
                    .checked_add(c.storage_size)
                    .is_none_or(|end| end > len)
                {
                    return Err(beyond(
                        c.address,
                        format!("HDF5 chunk at element {:?}", c.offset),
                        c.storage_size,
                    ));
                }
            }
            Ok(())
        }
        _ => Ok(()),
    }
}

/// Where the `numel` values of `ds` start in the file when they are IEEE little-endian
/// doubles stored contiguously within it, to be read as they lie ([`doubles_at`]).
fn plain_doubles<S: Source + ?Sized>(src: &S, ds: &Dataset, numel: u64) -> Option<u64> {
    let Ok(Layout::Contiguous {
        address: Some(at),
        size,
    }) = ds.layout()
    else {
        return None;
    };
    let ieee = matches!(
        ds.datatype(),
        Ok(hdf5_pure::Datatype::FloatingPoint {
            size: 8,
            byte_order: hdf5_pure::DatatypeByteOrder::LittleEndian,
            layout,
        }) if layout == hdf5_pure::FloatingPointLayout::IEEE754_BINARY64
    );
    let bytes = numel.checked_mul(8)?;
    (ieee && size == bytes && at.checked_add(bytes)? <= src.size()).then_some(at)
}

/// The `n` little-endian doubles at byte `at` of the file, a block at a time.
fn doubles_at<S: Source + ?Sized>(
    file: &str,
    src: &S,
    name: &str,
    at: u64,
    n: u64,
) -> Result<Vec<f64>, ReadError> {
    const PER: u64 = (1 << 18) / 8;
    let mut out = Vec::with_capacity(n as usize);
    let mut scratch = Vec::new();
    let mut done = 0;
    while done < n {
        let m = PER.min(n - done);
        let (at, t, e) = (at + done * 8, Dtype::F64, Endian::Little);
        samples_at(
            src,
            file,
            name,
            at,
            done,
            m,
            8,
            t,
            e,
            &mut scratch,
            &mut out,
        )?;
        done += m;
    }
    Ok(out)
}

/// The byte where the data of `ds` starts: its contiguous storage, else its first chunk
/// (in index order); 0 when the layout does not say (compact storage, inside the object
/// header; storage not allocated; a chunk index the HDF5 layer cannot list).
fn data_start(ds: &Dataset) -> u64 {
    match ds.layout() {
        Ok(Layout::Contiguous {
            address: Some(a), ..
        }) => a,
        Ok(Layout::Chunked { .. }) => ds
            .chunks()
            .ok()
            .and_then(|c| c.iter().map(|c| c.address).min())
            .unwrap_or(0),
        _ => 0,
    }
}

/// The byte where sample `index` (row-major over `shape`, elements of `size` bytes) of `ds`
/// is stored: its own bytes in contiguous storage or in a chunk stored unfiltered, the start
/// of its chunk when that chunk is compressed; else as [`data_start`].
fn sample_offset(ds: &Dataset, shape: &[u64], index: u64, size: u64) -> u64 {
    let within = |start: u64, k: u64| start.saturating_add(k.saturating_mul(size));
    match ds.layout() {
        Ok(Layout::Contiguous {
            address: Some(a), ..
        }) => within(a, index),
        Ok(Layout::Chunked { chunk_shape, .. }) if chunk_shape.len() == shape.len() => {
            // the sample's coordinates, last dimension fastest
            let mut coords = vec![0u64; shape.len()];
            let mut rest = index;
            for (c, &d) in coords.iter_mut().zip(shape).rev() {
                if d > 0 {
                    *c = rest % d;
                    rest /= d;
                }
            }
            let filters = ds.filters().len();
            let chunk = ds.chunks().ok().and_then(|chunks| {
                chunks.into_iter().find(|c| {
                    c.offset.len() == coords.len()
                        && coords
                            .iter()
                            .zip(&c.offset)
                            .zip(&chunk_shape)
                            .all(|((&x, &o), &n)| x >= o && x - o < n)
                })
            });
            match chunk {
                Some(c) => {
                    let raw = filters == 0 || c.filter_mask.count_ones() as usize >= filters;
                    if raw {
                        // position in the chunk, row-major over the chunk's shape
                        let k = coords
                            .iter()
                            .zip(&c.offset)
                            .zip(&chunk_shape)
                            .fold(0u64, |k, ((&x, &o), &n)| {
                                k.saturating_mul(n).saturating_add(x - o)
                            });
                        within(c.address, k)
                    } else {
                        c.address
                    }
                }
                None => data_start(ds),
            }
        }
        _ => data_start(ds),
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use std::io::Read;

    const BAD: i64 = (1 << 53) + 1;

    /// A MAT v7.3 layout (512-byte user block) holding the int64 column `n` = [1, 2, BAD,
    /// 4, 5, 6] stored as `store` sets it up.
    fn file(store: impl Fn(&mut hdf5_pure::DatasetBuilder)) -> Vec<u8> {
        let mut b = hdf5_pure::FileBuilder::new();
        b.with_userblock(512);
        let ds = b
            .create_dataset("n")
            .with_i64_data(&[1, 2, BAD, 4, 5, 6])
            .with_shape(&[1, 6])
            .set_attr("MATLAB_class", AttrValue::String("int64".into()));
        store(ds);
        b.finish().unwrap()
    }

    #[test]
    fn contiguous_doubles_are_read_as_they_lie_and_equal_the_hdf5_layers_values() {
        // 300 000 doubles (several blocks), contiguous and chunked; from memory and disk
        let v: Vec<f64> = (0..300_000)
            .map(|i| (f64::from(i) * 0.37).sin() * 1e-5)
            .collect();
        let mut b = hdf5_pure::FileBuilder::new();
        b.with_userblock(512);
        for (name, chunked) in [("plain", false), ("chunked", true)] {
            let ds = b
                .create_dataset(name)
                .with_f64_data(&v)
                .with_shape(&[1, 300_000])
                .set_attr("MATLAB_class", AttrValue::String("double".into()));
            if chunked {
                ds.with_chunks(&[1, 4096]);
            }
        }
        let bytes = b.finish().unwrap();
        let h5 = File::from_bytes(bytes.clone()).unwrap();
        let plain = h5.root().dataset("plain").unwrap();
        let chunked = h5.root().dataset("chunked").unwrap();
        let src: &[u8] = &bytes;
        let at = plain_doubles(src, &plain, 300_000).expect("read as it lies");
        assert_eq!(&bytes[at as usize..at as usize + 8], &v[0].to_le_bytes());
        assert_eq!(plain_doubles(src, &chunked, 300_000), None);
        // the direct path against the HDF5 layer's own read, and the table from disk
        assert_eq!(
            doubles_at("p.mat", src, "plain", at, 300_000).unwrap(),
            plain.read_f64().unwrap()
        );
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.mat");
        std::fs::write(&path, &bytes).unwrap();
        for t in [
            read("p.mat", &bytes).unwrap(),
            read_file("p.mat", &path).unwrap(),
        ] {
            assert_eq!(t.channels.len(), 2);
            assert!(t.channels.iter().all(|c| c.data == v), "{:?}", t.file);
        }
        // a file cut inside the data: not read as it lies (the HDF5 layer decides)
        let cut = &bytes[..at as usize + 1000];
        assert_eq!(plain_doubles(cut, &plain, 300_000), None);
    }

    fn inexact_offset(bytes: &[u8]) -> u64 {
        match read("n.mat", bytes) {
            Err(ReadError::InexactInteger {
                channel,
                index,
                offset,
                value,
                ..
            }) => {
                assert_eq!((channel.as_str(), index, value), ("n", 2, i128::from(BAD)));
                offset
            }
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn an_inexact_integer_is_named_at_its_bytes_when_stored_plain() {
        for (what, bytes) in [
            ("contiguous", file(|_| {})),
            (
                "chunked",
                file(|d| {
                    d.with_chunks(&[1, 2]);
                }),
            ),
        ] {
            let at = inexact_offset(&bytes) as usize;
            assert_eq!(bytes[at..at + 8], BAD.to_le_bytes(), "{what}");
        }
    }

    #[test]
    fn an_inexact_integer_in_a_compressed_chunk_is_named_at_that_chunk() {
        let bytes = file(|d| {
            d.with_chunks(&[1, 2]).with_deflate(6);
        });
        let at = inexact_offset(&bytes) as usize;
        // a zlib stream starts there, and it inflates to the second chunk: [BAD, 4]
        let mut chunk = Vec::new();
        flate2::read::ZlibDecoder::new(&bytes[at..])
            .read_to_end(&mut chunk)
            .unwrap();
        let want: Vec<u8> = [BAD, 4].iter().flat_map(|v| v.to_le_bytes()).collect();
        assert_eq!(chunk, want);
    }

    #[test]
    fn the_data_start_is_the_first_values_bytes() {
        // what an error about a whole dataset names (a forged extent, a short read): the
        // file's object headers are checksummed, so this is checked on good files
        let first: Vec<u8> = [1i64, 2].iter().flat_map(|v| v.to_le_bytes()).collect();
        for bytes in [
            file(|_| {}),
            file(|d| {
                d.with_chunks(&[1, 2]);
            }),
        ] {
            let want = bytes.windows(16).position(|w| w == first).unwrap() as u64;
            let h5 = File::from_bytes(bytes).unwrap();
            let ds = h5.root().dataset("n").unwrap();
            assert_eq!(data_start(&ds), want);
        }
    }
}
