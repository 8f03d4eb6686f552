//! Where commands write and read: `-` (stdout / stdin) or a file. Nothing the user names
//! is destroyed by accident:
//!
//! - A **regular file** (or a name that does not exist yet) is written per [`FileMode`]:
//!   - [`FileMode::Atomic`]: into a temporary file in the target's directory, synced and
//!     renamed over the target by [`Output::commit`] once everything is written
//!     ([`atomic`]: unnamed where the file system allows, so that even SIGKILL leaves
//!     nothing; a named one is removed on SIGINT, SIGTERM and SIGHUP). A run that fails
//!     never leaves a truncated file that looks complete, and a previous file of the same
//!     name stays untouched. Used by `simulate` (a shortened response would silently look
//!     like a shorter record), for JSON summaries and for figures.
//!   - [`FileMode::Direct`]: straight into the target, so that it can be followed while it
//!     grows (`tail -f` on a live identification). Writers in this crate emit each CSV row
//!     with one `write_all`, and the output hands the file whole lines only; after a write
//!     error (a full disk) the file is cut back to its last whole row.
//! - A **symbolic link** is followed: its target is written as above, the link is kept.
//! - A **device, FIFO or other special file** is opened and written in place, never
//!   replaced (`--out /dev/null`, a named pipe to a consumer, a tape).
//! - **stdout** (`-`) is written through a duplicate of descriptor 1: a closed stdout is
//!   an error, not a silent success.
//!
//! Every write error (ENOSPC, EPIPE, EBADF) is an error naming the output; the command
//! treats a broken pipe on stdout ([`is_broken_pipe`]) as a reader that stopped reading
//! (`| head`) and ends quietly. An output that is the same file as an input or another
//! output is refused ([`check_distinct_files`], and a process-wide record as a safety net;
//! see [`same_file`]).
//!

mod atomic;
mod same_file;

use std::fs::{File, OpenOptions};
use std::io::{self, Read, Write};
use std::os::fd::AsFd as _;
use std::os::unix::fs::FileTypeExt as _;
use std::path::Path;

use anyhow::Context as _;

pub use rotorid_io::csv::WriteFailure;
pub use same_file::check_distinct_files;

/// How a regular file output is written (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileMode {
    /// Temporary file renamed over the target by [`Output::commit`].
    Atomic,
    /// Written in place, whole rows at a time.
    Direct,
}

/// Where the bytes go.
enum Dest {
    /// A duplicate of descriptor 1.
    Stdout,
    /// Written in place: a special file, or a regular file in [`FileMode::Direct`]
    /// (`cut`: truncated back to its last whole row after a write error).
    InPlace { cut: bool },
    /// A temporary renamed over the target at commit.
    Replace(atomic::Pending),
}

/// Bytes collected before they are handed to the file.
const BUFFER: usize = 64 * 1024;

/// A buffered output: stdout for `-`, else a file written as the module doc says. Call
/// [`Output::commit`] at the end of a successful run; dropping it without committing
/// discards an atomic output's temporary file (the target is never created or replaced)
/// and hands a direct one its remaining whole rows.
pub struct Output {
    name: String,
    dest: Option<Dest>,
    file: File,
    buf: Vec<u8>,
    /// Bytes handed to the file so far.
    written: u64,
    /// Offset just past the last line end handed to the file.
    row_end: u64,
    /// The first write error, repeated to every later call.
    failed: Option<(io::ErrorKind, String)>,
}

impl Output {
    /// Open `arg` (`-` for stdout) for writing, after checking that this run has neither
    /// read it nor written it already.
    pub fn create(arg: &str, mode: FileMode) -> anyhow::Result<Self> {
        same_file::claim_output(arg)?;
        Self::open(arg, mode)
    }

    /// [`Self::create`] without the check against what this run read and wrote.
    fn open(arg: &str, mode: FileMode) -> anyhow::Result<Self> {
        let (file, dest) = if arg == "-" {
            (open_stdout()?, Dest::Stdout)
        } else {
            open_file(Path::new(arg), mode)?
        };
        Ok(Self {
            name: arg.to_owned(),
            dest: Some(dest),
            file,
            buf: Vec::with_capacity(BUFFER),
            written: 0,
            row_end: 0,
            failed: None,
        })
    }

    /// The argument it was opened with (`-` or the path), for messages.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// True when writing to stdout.
    pub fn is_stdout(&self) -> bool {
        matches!(self.dest, Some(Dest::Stdout))
    }

    /// Flush everything; for an atomic file, sync it and rename it over the target.
    pub fn commit(mut self) -> anyhow::Result<()> {
        let what = if self.is_stdout() {
            "cannot write to stdout".to_owned()
        } else {
            format!("cannot write {}", self.name)
        };
        self.flush().with_context(|| what.clone())?;
        if let Some(Dest::Replace(pending)) = self.dest.take() {
            let synced = self.file.sync_all();
            synced
                .and_then(|()| pending.commit(&mut self.file))
                .with_context(|| what)?;
        }
        Ok(())
    }

    /// The error of a failed output, for every call after the first failure.
    fn failure(&self, kind: io::ErrorKind, message: &str) -> io::Error {
        io::Error::new(kind, WriteFailure::new(&self.name, message))
    }

    /// Record the first write error: cut a direct file back to its last whole row, drop
    /// what is still buffered.
    fn fail(&mut self, e: io::Error) -> io::Error {
        if let Some(Dest::InPlace { cut: true }) = self.dest {
            let _ = self.file.set_len(self.row_end);
        }
        self.buf.clear();
        let (kind, message) = (e.kind(), e.to_string());
        self.failed = Some((kind, message.clone()));
        self.failure(kind, &message)
    }

    fn check(&self) -> io::Result<()> {
        match &self.failed {
            Some((kind, message)) => Err(self.failure(*kind, message)),
            None => Ok(()),
        }
    }

    /// Hand `self.buf[..upto]` to the file.
    fn write_out(&mut self, upto: usize) -> io::Result<()> {
        let mut done = 0;
        while done < upto {
            match self.file.write(&self.buf[done..upto]) {
                Ok(0) => {
                    return Err(self.fail(io::Error::new(
                        io::ErrorKind::WriteZero,
                        "the output accepted no more bytes",
                    )))
                }
                Ok(n) => {
                    if let Some(p) = memchr::memrchr(b'\n', &self.buf[done..done + n]) {
                        self.row_end = self.written + (p + 1) as u64;
                    }
                    self.written += n as u64;
                    done += n;
                }
                Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
                Err(e) => return Err(self.fail(e)),
            }
        }
        self.buf.drain(..upto);
        Ok(())
    }
}

impl Drop for Output {
    fn drop(&mut self) {
        // Not committed. An atomic output's temporary goes with `dest`; a direct file and
        // stdout get the whole rows still buffered.
        if let Some(Dest::Stdout | Dest::InPlace { .. }) = self.dest {
            if self.failed.is_none() {
                if let Some(p) = memchr::memrchr(b'\n', &self.buf) {
                    let _ = self.write_out(p + 1);
                }
            }
        }
    }
}

impl Write for Output {
    fn write(&mut self, data: &[u8]) -> io::Result<usize> {
        self.write_all(data).map(|()| data.len())
    }
    fn write_all(&mut self, data: &[u8]) -> io::Result<()> {
        self.check()?;
        self.buf.extend_from_slice(data);
        if self.buf.len() >= BUFFER {
            // whole lines only, so a reader of the file never sees half a row
            let upto = memchr::memrchr(b'\n', &self.buf).map_or(self.buf.len(), |p| p + 1);
            self.write_out(upto)?;
        }
        Ok(())
    }
    fn flush(&mut self) -> io::Result<()> {
        self.check()?;
        self.write_out(self.buf.len())
    }
}

/// stdout as a file of its own (a duplicate of descriptor 1): unlike `io::stdout()`, it
/// reports a closed descriptor instead of discarding what is written.
fn open_stdout() -> anyhow::Result<File> {
    let closed = || {
        anyhow::anyhow!(
            "cannot write to stdout: it is closed; redirect it (`> FILE`) or give --out a file \
             name"
        )
    };
    let fd = io::stdout()
        .as_fd()
        .try_clone_to_owned()
        .map_err(|_| closed())?;
    let file = File::from(fd);
    // Rust reopens a closed stdout as /dev/null for reading and writing before `main`; a
    // shell redirection `> /dev/null` opens it write-only. So /dev/null open O_RDWR on
    // descriptor 1 is a stdout that was closed.
    // SAFETY: fcntl(F_GETFL) only reads the descriptor's flags.
    let flags = unsafe { libc::fcntl(std::os::fd::AsRawFd::as_raw_fd(&file), libc::F_GETFL) };
    if flags >= 0 && flags & libc::O_ACCMODE == libc::O_RDONLY {
        return Err(closed());
    }
    if flags >= 0 && flags & libc::O_ACCMODE == libc::O_RDWR && is_dev_null(&file) {
        return Err(closed());
    }
    Ok(file)
}

/// True when `file` is the character device /dev/null.
fn is_dev_null(file: &File) -> bool {
    use std::os::unix::fs::MetadataExt as _;
    match (file.metadata(), std::fs::metadata("/dev/null")) {
        (Ok(a), Ok(b)) => a.file_type().is_char_device() && a.rdev() == b.rdev(),
        _ => false,
    }
}

/// Open the file output `path` (module doc).
fn open_file(path: &Path, mode: FileMode) -> anyhow::Result<(File, Dest)> {
    let target =
        same_file::resolve(path).with_context(|| format!("cannot write {}", path.display()))?;
    let shown = path.display();
    match std::fs::metadata(&target) {
        Ok(m) if m.is_dir() => {
            anyhow::bail!("cannot write {shown}: it is a directory; give a file name")
        }
        Ok(m) if !m.is_file() => {
            // device, FIFO, socket: written in place, never replaced or truncated
            let f = OpenOptions::new()
                .write(true)
                .open(&target)
                .with_context(|| format!("cannot open {shown} for writing"))?;
            Ok((f, Dest::InPlace { cut: false }))
        }
        _ => match mode {
            FileMode::Direct => {
                let f = File::create(&target).with_context(|| format!("cannot create {shown}"))?;
                Ok((f, Dest::InPlace { cut: true }))
            }
            FileMode::Atomic => {
                let (f, pending) = atomic::Pending::create(&target)
                    .with_context(|| format!("cannot create a temporary file beside {shown}"))?;
                Ok((f, Dest::Replace(pending)))
            }
        },
    }
}

/// Open `arg` for reading: `-` is stdin. Returns the name to use in messages (`<stdin>`
/// for `-`) and the reader (unbuffered: the CSV reader buffers). The file is recorded, so
/// that no output of this run replaces it.
pub fn open_input(arg: &str) -> anyhow::Result<(String, Box<dyn Read + Send>)> {
    same_file::note_input(arg);
    if arg == "-" {
        Ok(("<stdin>".to_owned(), Box::new(io::stdin())))
    } else {
        let f = File::open(arg).with_context(|| format!("cannot open {arg}"))?;
        Ok((arg.to_owned(), Box::new(f)))
    }
}

/// True when `e` (or what it wraps) is a broken pipe: the reader of our stdout went away
/// (`rotorid ... | head`), which ends the run quietly rather than as an error. A broken
/// pipe met while flushing before a read arrives wrapped in a [`super::CsvError`].
pub fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<io::Error>()
            .is_some_and(|io| io.kind() == io::ErrorKind::BrokenPipe)
            || c.downcast_ref::<super::CsvError>()
                .is_some_and(|c| c.io_kind == Some(io::ErrorKind::BrokenPipe))
    })
}

/// The reader of stdout went away (a broken pipe while printing a command's result):
/// `main` ends the run quietly with success, as `cat` does under `head`.
#[derive(Debug)]
pub struct StdoutClosed;

impl std::fmt::Display for StdoutClosed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("stdout was closed by its reader")
    }
}

impl std::error::Error for StdoutClosed {}

/// The error of a failed write to stdout (`outln!`, `out!`): [`StdoutClosed`] for a broken
/// pipe, else the I/O error.
pub fn stdout_error(e: io::Error) -> anyhow::Error {
    if e.kind() == io::ErrorKind::BrokenPipe {
        StdoutClosed.into()
    } else {
        anyhow::Error::new(e).context("cannot write to stdout")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn open(path: &Path, mode: FileMode) -> Output {
        Output::open(path.to_str().unwrap(), mode).unwrap()
    }

    fn names(d: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn atomic_output_appears_only_on_commit() {
        let d = tempfile::tempdir().unwrap();
        let target = d.path().join("r.csv");
        std::fs::write(&target, "old\n").unwrap();
        {
            let mut o = open(&target, FileMode::Atomic);
            o.write_all(b"new, unfinished\n").unwrap();
            o.flush().unwrap();
            // dropped without commit: a failed run
        }
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "old\n");
        assert_eq!(names(d.path()), ["r.csv"], "temporary file left");
        let mut o = open(&target, FileMode::Atomic);
        o.write_all(b"new\n").unwrap();
        o.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "new\n");
        assert_eq!(names(d.path()), ["r.csv"]);
    }

    #[test]
    fn replacing_keeps_the_permissions() {
        use std::os::unix::fs::PermissionsExt as _;
        let d = tempfile::tempdir().unwrap();
        let target = d.path().join("r.csv");
        std::fs::write(&target, "old\n").unwrap();
        std::fs::set_permissions(&target, std::fs::Permissions::from_mode(0o640)).unwrap();
        let mut o = open(&target, FileMode::Atomic);
        o.write_all(b"new\n").unwrap();
        o.commit().unwrap();
        let mode = std::fs::metadata(&target).unwrap().permissions().mode();
        assert_eq!(mode & 0o777, 0o640);
    }

    #[test]
    fn a_symlink_is_followed_and_kept() {
        let d = tempfile::tempdir().unwrap();
        let real = d.path().join("real.csv");
        let link = d.path().join("link.csv");
        std::fs::write(&real, "old\n").unwrap();
        std::os::unix::fs::symlink("real.csv", &link).unwrap();
        for mode in [FileMode::Atomic, FileMode::Direct] {
            let mut o = open(&link, mode);
            o.write_all(format!("{mode:?}\n").as_bytes()).unwrap();
            o.commit().unwrap();
            assert!(std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink());
            assert_eq!(
                std::fs::read_to_string(&real).unwrap(),
                format!("{mode:?}\n")
            );
        }
        // a dangling link creates its target
        let dangling = d.path().join("dangling.csv");
        std::os::unix::fs::symlink("created.csv", &dangling).unwrap();
        let mut o = open(&dangling, FileMode::Atomic);
        o.write_all(b"x\n").unwrap();
        o.commit().unwrap();
        assert_eq!(
            std::fs::read_to_string(d.path().join("created.csv")).unwrap(),
            "x\n"
        );
        let e = Output::open(d.path().to_str().unwrap(), FileMode::Atomic)
            .err()
            .unwrap();
        assert!(e
            .to_string()
            .ends_with("it is a directory; give a file name"));
    }

    #[test]
    fn direct_output_keeps_whole_rows() {
        let d = tempfile::tempdir().unwrap();
        let target = d.path().join("e.csv");
        {
            let mut o = open(&target, FileMode::Direct);
            o.write_all(b"a,b\n1,2\n").unwrap();
            o.write_all(b"3,").unwrap(); // half a row when the run stops
        }
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "a,b\n1,2\n");
    }

    #[test]
    fn a_big_buffer_is_handed_out_in_whole_lines() {
        let d = tempfile::tempdir().unwrap();
        let target = d.path().join("e.csv");
        let mut o = open(&target, FileMode::Direct);
        let row = b"0.0001,1.2345678901234567e-7,-3.3e-300\n";
        for _ in 0..(3 * BUFFER / row.len()) {
            o.write_all(row).unwrap();
        }
        o.write_all(b"partial").unwrap();
        let len = std::fs::metadata(&target).unwrap().len();
        assert!(len > 0 && len.is_multiple_of(row.len() as u64), "{len}");
        drop(o);
    }
}
