//! Where commands write and read: `-` (stdout / stdin) or a file.
//!
//! Files are written in one of two ways ([`FileMode`]):
//!
//! - [`FileMode::Atomic`]: into a temporary file beside the target
//!   (`.NAME.tmp-PID`), renamed over the target by [`Output::commit`] once everything is
//!   written and synced. A run that fails (or is killed) never leaves a truncated file that
//!   looks complete, and a previous file of the same name stays untouched. Used by
//!   `simulate` (a shortened response would silently look like a shorter record) and for
//!   JSON summaries.
//! - [`FileMode::Direct`]: straight into the target, so that it can be followed while it
//!   grows (`tail -f` on a live identification). Writers in this crate emit each CSV row
//!   with one `write_all` through a `BufWriter`, so the file only ever holds whole rows;
//!   after an error it holds the rows produced before it.
//!

use std::fs::{File, OpenOptions};
use std::io::{self, BufWriter, Read, Write};
use std::path::{Path, PathBuf};

use anyhow::Context as _;

/// How a file output is written (see the module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileMode {
    /// Temporary file renamed over the target by [`Output::commit`].
    Atomic,
    /// Written in place, whole rows at a time.
    Direct,
}

enum Sink {
    Stdout(BufWriter<io::Stdout>),
    File {
        w: BufWriter<File>,
        /// `(temporary, target)` for [`FileMode::Atomic`].
        rename: Option<(PathBuf, PathBuf)>,
    },
}

/// A buffered output: stdout for `-`, else a file written per [`FileMode`]. Call
/// [`Output::commit`] at the end of a successful run; dropping it without committing
/// removes an atomic output's temporary file (the target is never created or replaced).
pub struct Output {
    name: String,
    sink: Sink,
    committed: bool,
}

impl Output {
    /// Open `arg` (`-` for stdout) for writing.
    pub fn create(arg: &str, mode: FileMode) -> anyhow::Result<Self> {
        let sink = if arg == "-" {
            Sink::Stdout(BufWriter::with_capacity(64 * 1024, io::stdout()))
        } else {
            let target = PathBuf::from(arg);
            match mode {
                FileMode::Direct => {
                    let f = File::create(&target)
                        .with_context(|| format!("cannot create {}", target.display()))?;
                    Sink::File {
                        w: BufWriter::with_capacity(64 * 1024, f),
                        rename: None,
                    }
                }
                FileMode::Atomic => {
                    let tmp = temporary_path(&target);
                    let f = OpenOptions::new()
                        .write(true)
                        .create_new(true)
                        .open(&tmp)
                        .with_context(|| {
                            format!(
                                "cannot create the temporary file {} for {}",
                                tmp.display(),
                                target.display()
                            )
                        })?;
                    Sink::File {
                        w: BufWriter::with_capacity(64 * 1024, f),
                        rename: Some((tmp, target)),
                    }
                }
            }
        };
        Ok(Self {
            name: arg.to_owned(),
            sink,
            committed: false,
        })
    }

    /// The argument it was opened with (`-` or the path), for messages.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// True when writing to stdout.
    pub fn is_stdout(&self) -> bool {
        matches!(self.sink, Sink::Stdout(_))
    }

    /// Flush everything; for an atomic file, sync it and rename it over the target.
    pub fn commit(mut self) -> anyhow::Result<()> {
        self.committed = true;
        let name = self.name.clone();
        match &mut self.sink {
            Sink::Stdout(w) => w.flush().with_context(|| "cannot write to stdout")?,
            Sink::File { w, rename } => {
                w.flush().with_context(|| format!("cannot write {name}"))?;
                if let Some((tmp, target)) = rename.take() {
                    let r = w
                        .get_ref()
                        .sync_all()
                        .and_then(|()| std::fs::rename(&tmp, &target));
                    if let Err(e) = r {
                        let _ = std::fs::remove_file(&tmp);
                        return Err(e).with_context(|| format!("cannot write {name}"));
                    }
                }
            }
        }
        Ok(())
    }
}

impl Drop for Output {
    fn drop(&mut self) {
        if let Sink::File {
            w,
            rename: Some((tmp, _)),
        } = &mut self.sink
        {
            // Not committed: discard the temporary file, leave the target alone.
            let _ = w.flush();
            let _ = std::fs::remove_file(tmp);
        } else if !self.committed {
            // Direct files and stdout keep the whole rows written so far.
            let _ = self.flush();
        }
    }
}

impl Write for Output {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        match &mut self.sink {
            Sink::Stdout(w) => w.write(buf),
            Sink::File { w, .. } => w.write(buf),
        }
    }
    fn write_all(&mut self, buf: &[u8]) -> io::Result<()> {
        match &mut self.sink {
            Sink::Stdout(w) => w.write_all(buf),
            Sink::File { w, .. } => w.write_all(buf),
        }
    }
    fn flush(&mut self) -> io::Result<()> {
        match &mut self.sink {
            Sink::Stdout(w) => w.flush(),
            Sink::File { w, .. } => w.flush(),
        }
    }
}

/// `.NAME.tmp-PID` in the target's directory (same file system, so rename is atomic).
fn temporary_path(target: &Path) -> PathBuf {
    let file = target
        .file_name()
        .map_or_else(|| "output".into(), |f| f.to_string_lossy().into_owned());
    target.with_file_name(format!(".{file}.tmp-{}", std::process::id()))
}

/// Open `arg` for reading: `-` is stdin. Returns the name to use in messages (`<stdin>`
/// for `-`) and the reader (unbuffered: the CSV reader buffers).
pub fn open_input(arg: &str) -> anyhow::Result<(String, Box<dyn Read>)> {
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

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch_dir(tag: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("rotorid-output-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    #[test]
    fn atomic_output_appears_only_on_commit() {
        let d = scratch_dir("atomic");
        let target = d.join("r.csv");
        std::fs::write(&target, "old\n").unwrap();
        {
            let mut o = Output::create(target.to_str().unwrap(), FileMode::Atomic).unwrap();
            o.write_all(b"new, unfinished\n").unwrap();
            // dropped without commit: a failed run
        }
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "old\n");
        assert_eq!(
            std::fs::read_dir(&d).unwrap().count(),
            1,
            "temporary file left"
        );
        let mut o = Output::create(target.to_str().unwrap(), FileMode::Atomic).unwrap();
        o.write_all(b"new\n").unwrap();
        o.commit().unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "new\n");
        assert_eq!(std::fs::read_dir(&d).unwrap().count(), 1);
        std::fs::remove_dir_all(&d).unwrap();
    }

    #[test]
    fn direct_output_keeps_what_was_written() {
        let d = scratch_dir("direct");
        let target = d.join("e.csv");
        {
            let mut o = Output::create(target.to_str().unwrap(), FileMode::Direct).unwrap();
            o.write_all(b"a,b\n1,2\n").unwrap();
        }
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "a,b\n1,2\n");
        std::fs::remove_dir_all(&d).unwrap();
    }
}
