//! Which reader a file goes to: by its extension ([`Format::from_path`]), then for `.mat`
//! by its header (v5, or v7.3 which is HDF5).

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
