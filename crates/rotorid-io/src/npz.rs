//! NumPy `.npz` archives: a zip file (PKWARE APPNOTE 6.3) whose members `NAME.npy` are NPY
//! arrays ([`crate::npy`]), stored (`numpy.savez`) or deflated (`numpy.savez_compressed`).
//!
//! Each member is one array: a 1-D array is the channel `NAME`, a 2-D array the channels
//! `NAME.0`, `NAME.1`, ... (its columns). Members not ending in `.npy` are skipped.
//!
//! The zip directory is read by the `zip` crate (stored and deflate only; encrypted,
//! bzip2, zstd and other methods are refused). A member's declared uncompressed size is
//! checked before anything is allocated: at most its compressed size when stored, and at
//! most 1032 times it (deflate's largest ratio) plus 1 KiB when deflated, so an archive
//! cannot make the reader allocate more than about a thousand times its own size; the
//! bytes actually inflated must equal the declared size.

use std::io::Read;

use crate::cursor::Cursor;
use crate::error::ReadError;
use crate::npy;
use crate::source::Source;
use crate::table::Table;

/// Deflate cannot expand more than this (RFC 1951: 258 bytes per two-bit code, ~1032:1).
const MAX_DEFLATE_RATIO: u64 = 1032;

/// Reads an `.npz` file's bytes; `file` names it in messages.
pub fn read(file: &str, bytes: &[u8]) -> Result<Table, ReadError> {
    read_from(file, std::io::Cursor::new(bytes), bytes.len() as u64, bytes)
}

/// Reads the `.npz` file at `path` member by member: memory holds the channels and one
/// member, never the whole file.
pub fn read_file(file: &str, path: &std::path::Path) -> Result<Table, ReadError> {
    let disk = crate::source::DiskFile::open(file, path)?;
    read_from(
        file,
        std::io::BufReader::new(disk.handle()?),
        disk.size,
        &disk,
    )
}

/// The table of the archive `input` of `size` bytes; a stored member's bytes are read from
/// `direct` (the same archive, in memory or on disk).
fn read_from<R: Read + std::io::Seek, S: Source + ?Sized>(
    file: &str,
    input: R,
    size_of_file: u64,
    direct: &S,
) -> Result<Table, ReadError> {
    let mut channels = Vec::new();
    members(file, input, size_of_file, direct, |name, c| {
        channels.extend(npy::parse(c, name, true)?);
        Ok(())
    })?;
    if channels.is_empty() {
        return Err(ReadError::NoChannels {
            file: file.to_string(),
            why: "no member NAME.npy".into(),
        });
    }
    Ok(Table {
        file: file.to_string(),
        channels,
        notes: Vec::new(),
    })
}

/// Calls `each(NAME, cursor)` on every member `NAME.npy` of the archive `input` of
/// `size_of_file` bytes, in the archive's order, the cursor over the member's bytes (read
/// from `direct` when stored, inflated when deflated, each checked as the module doc says);
/// other members are skipped.
pub(crate) fn members<R: Read + std::io::Seek, S: Source + ?Sized>(
    file: &str,
    input: R,
    size_of_file: u64,
    direct: &S,
    mut each: impl FnMut(&str, &mut Cursor) -> Result<(), ReadError>,
) -> Result<(), ReadError> {
    let zerr = |channel: Option<&str>, e: zip::result::ZipError| ReadError::Container {
        file: file.to_string(),
        channel: channel.map(str::to_string),
        container: "zip",
        message: e.to_string(),
    };
    let mut zip = zip::ZipArchive::new(input).map_err(|e| zerr(None, e))?;
    let mut scratch = Vec::new();
    for i in 0..zip.len() {
        let mut member = zip.by_index(i).map_err(|e| zerr(None, e))?;
        let Some(name) = member.name().strip_suffix(".npy").map(str::to_string) else {
            continue;
        };
        let at = member.header_start();
        let (packed, size) = (member.compressed_size(), member.size());
        let limit = match member.compression() {
            zip::CompressionMethod::Stored => packed,
            zip::CompressionMethod::Deflated => packed
                .saturating_mul(MAX_DEFLATE_RATIO)
                .saturating_add(1024),
            m => {
                return Err(ReadError::Invalid {
                    file: file.to_string(),
                    channel: Some(name),
                    offset: at,
                    what: "zip compression method".into(),
                    found: m.to_string(),
                    allowed: "stored or deflated (what numpy.savez and savez_compressed write)"
                        .into(),
                })
            }
        };
        let file_size = size_of_file;
        if size > limit || packed > file_size {
            return Err(ReadError::Invalid {
                file: file.to_string(),
                channel: Some(name),
                offset: at,
                what: "zip member size".into(),
                found: format!("{size} bytes uncompressed from {packed} compressed"),
                allowed: format!("at most {limit} (the file is {file_size} bytes)"),
            });
        }
        // A stored member lying within the file, as long as its two sizes agree: its bytes
        // as they are, checked against the member's CRC-32 as the zip crate's reader would
        // (sizes that disagree go the zip crate's way below, which refuses them).
        let stored = (member.compression() == zip::CompressionMethod::Stored && size == packed)
            .then(|| member.data_start())
            .flatten()
            .filter(|&start| start.checked_add(size).is_some_and(|end| end <= file_size));
        if let Some(start) = stored {
            // (read without the zip crate's reader, which zeroes the destination and copies
            // the bytes through its buffers)
            let bytes = direct.read_at_reusing(start, size, &mut scratch)?;
            let crc = crc32fast::hash(bytes);
            if crc != member.crc32() {
                return Err(ReadError::Invalid {
                    file: file.to_string(),
                    channel: Some(name),
                    offset: start,
                    what: "zip member's CRC-32".into(),
                    found: format!("{crc:#010x} over its {size} bytes"),
                    allowed: format!("the declared {:#010x}", member.crc32()),
                });
            }
            let mut c = Cursor::inflated(file, bytes, at);
            each(&name, &mut c)?;
            continue;
        }
        let mut buf = Vec::with_capacity(size as usize);
        (&mut member)
            .take(size + 1)
            .read_to_end(&mut buf)
            .map_err(|e| ReadError::Container {
                file: file.to_string(),
                channel: Some(name.clone()),
                container: "zip",
                message: format!("member at byte {at}: {e}"),
            })?;
        if buf.len() as u64 != size {
            return Err(ReadError::Invalid {
                file: file.to_string(),
                channel: Some(name),
                offset: at,
                what: "zip member's inflated size".into(),
                found: format!("{} bytes", buf.len()),
                allowed: format!("the declared {size}"),
            });
        }
        let mut c = Cursor::inflated(file, &buf, at);
        each(&name, &mut c)?;
    }
    Ok(())
}
