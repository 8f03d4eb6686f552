//! A file's bytes at offsets, from memory or from disk: what every binary reader reads
//! through (the readers import this, the format dispatch in `format` imports the readers).

use std::borrow::Cow;
use std::path::Path;

use crate::error::ReadError;

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
