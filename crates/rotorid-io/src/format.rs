//! Which reader a file goes to: by its extension ([`Format::from_path`]), then for `.mat`
//! by its header (v5, or v7.3 which is HDF5).

use std::borrow::Cow;
use std::path::Path;

use crate::error::ReadError;
use crate::table::Table;

/// A file format, as told by the file's extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// MATLAB `.mat`, level 5 (v5, v6, v7) or v7.3 (HDF5): [`crate::mat`].
    Mat,
    /// NI LabVIEW `.tdms`: [`crate::tdms`].
    Tdms,
    /// Universal File Format dataset 58 or 58b, `.uff`, `.unv` or `.58`: [`crate::uff`].
    Uff58,
    /// NumPy `.npy`: [`crate::npy`].
    Npy,
    /// NumPy `.npz`: [`crate::npz`].
    Npz,
    /// Apache `.parquet`: [`crate::parquet`].
    Parquet,
    /// `.csv`, `.txt`, `.tsv`: [`crate::csv::read_csv_table`] (the response CSV is also
    /// streamed by [`crate::csv::ResponseReader`]).
    Csv,
}

/// The extensions [`Format::from_path`] knows, for messages.
pub const KNOWN: &str = ".mat, .tdms, .uff, .unv, .58, .npy, .npz, .parquet, .csv, .tsv, .txt";

impl Format {
    /// The format of `path` by its extension, case-insensitively.
    pub fn from_path(path: &Path) -> Result<Format, ReadError> {
        let ext = path
            .extension()
            .map(|e| e.to_string_lossy().to_ascii_lowercase())
            .unwrap_or_default();
        Ok(match ext.as_str() {
            "mat" => Format::Mat,
            "tdms" => Format::Tdms,
            "uff" | "unv" | "58" => Format::Uff58,
            "npy" => Format::Npy,
            "npz" => Format::Npz,
            "parquet" => Format::Parquet,
            "csv" | "tsv" | "txt" => Format::Csv,
            _ => {
                return Err(ReadError::UnknownFormat {
                    file: path.display().to_string(),
                    ext,
                    known: KNOWN,
                })
            }
        })
    }
}

/// Reads the file at `path` with the reader its extension names.
pub fn read_table(path: impl AsRef<Path>) -> Result<Table, ReadError> {
    let path = path.as_ref();
    let file = path.display().to_string();
    let format = Format::from_path(path)?;
    if format == Format::Csv {
        let f = std::fs::File::open(path).map_err(|source| ReadError::Io {
            file: file.clone(),
            source,
        })?;
        return crate::csv::read_csv_table(&file, std::io::BufReader::with_capacity(1 << 16, f))
            .map_err(|e| ReadError::Csv(Box::new(e)));
    }
    match format {
        Format::Parquet => return crate::parquet::read_file(&file, path),
        Format::Npz => return crate::npz::read_file(&file, path),
        Format::Mat => return crate::mat::read_file(&file, path),
        Format::Tdms => return crate::tdms::read_file(&file, path),
        Format::Uff58 => return crate::uff::read_file(&file, path),
        _ => {}
    }
    let bytes = std::fs::read(path).map_err(|source| ReadError::Io {
        file: file.clone(),
        source,
    })?;
    read_bytes(format, &file, &bytes)
}

/// Reads a file's bytes as `format`; `file` names it in messages (and, for NPY, names the
/// channel of a 1-D array after its stem).
pub fn read_bytes(format: Format, file: &str, bytes: &[u8]) -> Result<Table, ReadError> {
    match format {
        Format::Npy => crate::npy::read(file, bytes),
        Format::Npz => crate::npz::read(file, bytes),
        Format::Mat => crate::mat::read(file, bytes),
        Format::Tdms => crate::tdms::read(file, bytes),
        Format::Uff58 => crate::uff::read(file, bytes),
        Format::Parquet => crate::parquet::read(file, bytes),
        Format::Csv => {
            crate::csv::read_csv_table(file, bytes).map_err(|e| ReadError::Csv(Box::new(e)))
        }
    }
}

/// A file opened for reading at offsets, with its size; errors name `file`.
pub(crate) struct DiskFile<'a> {
    file: Cow<'a, str>,
    f: std::fs::File,
    /// Size \[bytes\].
    pub size: u64,
}

impl<'a> DiskFile<'a> {
    /// Opens `path`; `file` names it in errors.
    pub fn open(file: &'a str, path: &Path) -> Result<Self, ReadError> {
        let f = std::fs::File::open(path).map_err(|e| Self::io(file, e))?;
        let size = f.metadata().map_err(|e| Self::io(file, e))?.len();
        Ok(Self {
            file: Cow::Borrowed(file),
            f,
            size,
        })
    }

    /// [`DiskFile::open`], keeping its own copy of the name (for a reader that outlives
    /// the caller's).
    pub fn open_owned(file: &str, path: &Path) -> Result<DiskFile<'static>, ReadError> {
        let d = DiskFile::open(file, path)?;
        Ok(DiskFile {
            file: Cow::Owned(file.to_string()),
            f: d.f,
            size: d.size,
        })
    }

    fn io(file: &str, source: std::io::Error) -> ReadError {
        ReadError::Io {
            file: file.to_string(),
            source,
        }
    }

    /// The bytes `[at, at + len)` (the caller keeps them within the size).
    pub fn read_at(&self, at: u64, len: u64) -> Result<Vec<u8>, ReadError> {
        use std::os::unix::fs::FileExt as _;
        let mut buf = vec![0u8; len as usize];
        self.f
            .read_exact_at(&mut buf, at)
            .map_err(|e| Self::io(&self.file, e))?;
        Ok(buf)
    }

    /// The bytes `[at, at + len)` into `buf` (resized to `len`; its memory is reused, so a
    /// caller reading piece after piece faults and zeroes it once).
    pub fn read_at_into(&self, at: u64, len: u64, buf: &mut Vec<u8>) -> Result<(), ReadError> {
        use std::os::unix::fs::FileExt as _;
        buf.resize(len as usize, 0);
        self.f
            .read_exact_at(buf, at)
            .map_err(|e| Self::io(&self.file, e))
    }

    /// A second handle on the file (for readers that take ownership).
    pub fn handle(&self) -> Result<std::fs::File, ReadError> {
        self.f.try_clone().map_err(|e| Self::io(&self.file, e))
    }
}

/// A file's bytes at offsets: all of them in memory (`[u8]`, read as they lie) or a
/// [`DiskFile`] (read piece by piece), so that a reader written once over it reads both
/// ways with the same checks and messages.
pub(crate) trait Source {
    /// Size \[bytes\].
    fn size(&self) -> u64;
    /// The bytes `[at, at + len)` (the caller keeps them within the size).
    fn read_at(&self, at: u64, len: u64) -> Result<Cow<'_, [u8]>, ReadError>;
    /// The same bytes, read into `scratch` when they must be read (its memory reused from
    /// call to call by a caller reading block after block).
    fn read_at_reusing<'s>(
        &'s self,
        at: u64,
        len: u64,
        scratch: &'s mut Vec<u8>,
    ) -> Result<&'s [u8], ReadError>;
}

impl Source for [u8] {
    fn size(&self) -> u64 {
        self.len() as u64
    }

    fn read_at(&self, at: u64, len: u64) -> Result<Cow<'_, [u8]>, ReadError> {
        Ok(Cow::Borrowed(&self[at as usize..(at + len) as usize]))
    }

    fn read_at_reusing<'s>(
        &'s self,
        at: u64,
        len: u64,
        _: &'s mut Vec<u8>,
    ) -> Result<&'s [u8], ReadError> {
        Ok(&self[at as usize..(at + len) as usize])
    }
}

impl Source for DiskFile<'_> {
    fn size(&self) -> u64 {
        self.size
    }

    fn read_at(&self, at: u64, len: u64) -> Result<Cow<'_, [u8]>, ReadError> {
        DiskFile::read_at(self, at, len).map(Cow::Owned)
    }

    fn read_at_reusing<'s>(
        &'s self,
        at: u64,
        len: u64,
        scratch: &'s mut Vec<u8>,
    ) -> Result<&'s [u8], ReadError> {
        self.read_at_into(at, len, scratch)?;
        Ok(scratch)
    }
}
