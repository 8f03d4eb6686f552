//! Refusing an output that is the same file as an input or as another output.
//!
//! Files are compared by what they are, not by how they are named: device and inode (so
//! `a.csv`, `./a.csv`, a hard link and a symbolic link to it are one file) and, for an
//! output that does not exist yet, the device and inode of its directory and its file
//! name. Character devices (`/dev/null`, a terminal) and sockets are never "the same
//! file": two outputs to /dev/null destroy nothing, and a socket (or a terminal) is
//! rightly both stdin and stdout of a program run over a connection. `-` is stdin for an input and stdout for an
//! output, compared through file descriptors 0 and 1, so `identify in.csv --out - >>in.csv`
//! is refused too.
//!
//! Two layers: [`check_distinct_files`], which a command calls with all its file arguments
//! before it opens anything for writing; and a process-wide record of the inputs opened by
//! [`super::open_input`] and the outputs created by [`super::Output::create`], which refuses
//! a clash a command did not check for (later, but still before the file is touched).

use std::ffi::OsString;
use std::io;
use std::os::unix::fs::{FileTypeExt as _, MetadataExt as _};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use anyhow::bail;

/// What a file argument names (module doc).
#[derive(Debug, Clone, PartialEq, Eq)]
pub(super) struct FileId {
    /// Device and inode, when the file exists.
    node: Option<(u64, u64)>,
    /// Device and inode of the directory, and the file name (symbolic links followed).
    place: Option<(u64, u64, OsString)>,
}

impl FileId {
    fn same(&self, other: &FileId) -> bool {
        fn eq<T: PartialEq>(a: &Option<T>, b: &Option<T>) -> bool {
            a.is_some() && a == b
        }
        eq(&self.node, &other.node) || eq(&self.place, &other.place)
    }
}

/// Follow `path` through symbolic links (at most 40, as the kernel) to what it finally
/// names, which may not exist (a dangling link names the file it would create).
pub(super) fn resolve(path: &Path) -> io::Result<PathBuf> {
    let mut p = path.to_path_buf();
    for _ in 0..40 {
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.file_type().is_symlink() => {
                let to = std::fs::read_link(&p)?;
                p = match p.parent() {
                    Some(dir) if to.is_relative() => dir.join(to),
                    _ => to,
                };
            }
            _ => return Ok(p),
        }
    }
    Err(io::Error::other("too many levels of symbolic links"))
}

/// The identity of the file `path` names (module doc); `None` for a character device, a
/// socket or a path that cannot be examined.
pub(super) fn of_path(path: &Path) -> Option<FileId> {
    let path = resolve(path).ok()?;
    let node = match std::fs::metadata(&path) {
        Ok(m) if m.file_type().is_char_device() || m.file_type().is_socket() => return None,
        Ok(m) => Some((m.dev(), m.ino())),
        Err(_) => None,
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let place = match (std::fs::metadata(dir), path.file_name()) {
        (Ok(d), Some(name)) => Some((d.dev(), d.ino(), name.to_owned())),
        _ => None,
    };
    (node.is_some() || place.is_some()).then_some(FileId { node, place })
}

/// The identity of the file open as descriptor `fd` (0: stdin, 1: stdout); `None` for a
/// character device (a terminal, /dev/null), a socket or a closed descriptor.
pub(super) fn of_fd(fd: libc::c_int) -> Option<FileId> {
    // SAFETY: fstat writes into the zeroed struct we own; an invalid fd is an error return.
    let st = unsafe {
        let mut st: libc::stat = std::mem::zeroed();
        (libc::fstat(fd, &mut st) == 0).then_some(st)
    }?;
    let kind = st.st_mode & libc::S_IFMT;
    if kind == libc::S_IFCHR || kind == libc::S_IFSOCK {
        return None;
    }
    Some(FileId {
        node: Some((st.st_dev, st.st_ino)),
        place: None,
    })
}

fn id_of(arg: &str, std_fd: libc::c_int) -> Option<FileId> {
    if arg == "-" {
        of_fd(std_fd)
    } else {
        of_path(Path::new(arg))
    }
}

/// `flag value`, saying what `-` stands for.
fn describe(flag: &str, value: &str, input: bool) -> String {
    match (value, input) {
        ("-", true) => format!("{flag} - (stdin)"),
        ("-", false) => format!("{flag} - (stdout)"),
        _ => format!("{flag} {value}"),
    }
}

/// Refuse file arguments that would destroy one another, before anything is opened for
/// writing: an output that is the same file as an input, two outputs that are one file,
/// and two outputs on stdout. `inputs` and `outputs` are `(flag, value)` pairs, e.g.
/// `("the input", "in.csv")`, `("--scenario", "rig.toml")`, `("--out", "-")`; a value
/// that names no file (a built-in scenario name such as `table1`) is skipped.
pub fn check_distinct_files(
    inputs: &[(&str, &str)],
    outputs: &[(&str, &str)],
) -> anyhow::Result<()> {
    let on_stdout: Vec<&str> = outputs
        .iter()
        .filter(|(_, v)| *v == "-")
        .map(|(f, _)| *f)
        .collect();
    if on_stdout.len() > 1 {
        bail!(
            "{} would all write to stdout, one after the other: give all but one of them a \
             file name",
            on_stdout
                .iter()
                .map(|f| format!("{f} -"))
                .collect::<Vec<_>>()
                .join(" and ")
        );
    }
    let ins: Vec<_> = inputs
        .iter()
        .map(|&(f, v)| (f, v, id_of(v, libc::STDIN_FILENO)))
        .collect();
    let outs: Vec<_> = outputs
        .iter()
        .map(|&(f, v)| (f, v, id_of(v, libc::STDOUT_FILENO)))
        .collect();
    for (i, (flag, value, id)) in outs.iter().enumerate() {
        let Some(id) = id else { continue };
        for (in_flag, in_value, in_id) in &ins {
            if in_id.as_ref().is_some_and(|x| x.same(id)) {
                bail!(
                    "{} is the same file as {}: writing it would destroy that input; choose \
                     another {flag}",
                    describe(flag, value, false),
                    describe(in_flag, in_value, true)
                );
            }
        }
        for (prev_flag, prev_value, prev_id) in &outs[..i] {
            if prev_id.as_ref().is_some_and(|x| x.same(id)) {
                bail!(
                    "{} and {} are the same file: one would replace the other; give them \
                     different names",
                    describe(prev_flag, prev_value, false),
                    describe(flag, value, false)
                );
            }
        }
    }
    Ok(())
}

/// Whether a recorded file was read or written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Use {
    Input,
    Output,
}

struct Record {
    used: Use,
    id: FileId,
    name: String,
}

static OPENED: Mutex<Vec<Record>> = Mutex::new(Vec::new());
static STDOUT_CLAIMED: Mutex<Option<String>> = Mutex::new(None);

/// Record that this process reads `arg` (`-`: stdin).
pub(super) fn note_input(arg: &str) {
    let name = if arg == "-" { "<stdin>" } else { arg };
    if let Some(id) = id_of(arg, libc::STDIN_FILENO) {
        if let Ok(mut seen) = OPENED.lock() {
            seen.push(Record {
                used: Use::Input,
                id,
                name: name.to_owned(),
            });
        }
    }
}

/// Refuse to write `arg` (`-`: stdout) when this process has read it or written it
/// already; otherwise record it.
pub(super) fn claim_output(arg: &str) -> anyhow::Result<()> {
    if arg == "-" {
        let mut claimed = STDOUT_CLAIMED
            .lock()
            .map_err(|_| anyhow::anyhow!("internal error: output record poisoned"))?;
        if claimed.is_some() {
            bail!("refusing to write stdout twice in one run: give all but one output a file name");
        }
        *claimed = Some(arg.to_owned());
    }
    let Some(id) = id_of(arg, libc::STDOUT_FILENO) else {
        return Ok(());
    };
    let mut seen = OPENED
        .lock()
        .map_err(|_| anyhow::anyhow!("internal error: output record poisoned"))?;
    let what = if arg == "-" { "stdout" } else { arg };
    if let Some(r) = seen.iter().find(|r| r.id.same(&id)) {
        match r.used {
            Use::Input => bail!(
                "refusing to write {what}: it is the same file as the input {}, which this \
                 run reads",
                r.name
            ),
            Use::Output => bail!(
                "refusing to write {what}: it is the same file as the output {}, which this \
                 run writes too",
                r.name
            ),
        }
    }
    seen.push(Record {
        used: Use::Output,
        id,
        name: what.to_owned(),
    });
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_do_not_matter_files_do() {
        let d = tempfile::tempdir().unwrap();
        let a = d.path().join("a.csv");
        std::fs::write(&a, "t,x,z\n").unwrap();
        std::fs::hard_link(&a, d.path().join("hard.csv")).unwrap();
        std::os::unix::fs::symlink("a.csv", d.path().join("soft.csv")).unwrap();
        std::os::unix::fs::symlink("new.csv", d.path().join("dangling.csv")).unwrap();
        let p = |n: &str| d.path().join(n).to_str().unwrap().to_owned();
        let dotted = format!("{}/./a.csv", d.path().display());
        for other in [p("hard.csv"), p("soft.csv"), dotted] {
            let e = check_distinct_files(&[("the input", &p("a.csv"))], &[("--out", &other)])
                .unwrap_err()
                .to_string();
            assert!(
                e.contains("is the same file as the input") && e.ends_with("choose another --out"),
                "{e}"
            );
        }
        // a new file, named twice (once through a dangling link)
        let e = check_distinct_files(
            &[],
            &[("--out", &p("new.csv")), ("--summary", &p("dangling.csv"))],
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("are the same file"), "{e}");
        check_distinct_files(
            &[("the input", &p("a.csv")), ("--scenario", "table1")],
            &[("--out", &p("b.csv")), ("--summary", &p("c.json"))],
        )
        .unwrap();
    }

    #[test]
    fn stdout_once_and_character_devices_always() {
        let e = check_distinct_files(&[], &[("--out", "-"), ("--summary", "-")])
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "--out - and --summary - would all write to stdout, one after the other: give all \
             but one of them a file name"
        );
        check_distinct_files(
            &[("the input", "/dev/null")],
            &[("--out", "/dev/null"), ("--summary", "/dev/null")],
        )
        .unwrap();
    }

    #[test]
    fn the_process_record_refuses_what_it_read() {
        let d = tempfile::tempdir().unwrap();
        let a = d.path().join("read.csv");
        std::fs::write(&a, "t,x,z\n").unwrap();
        note_input(a.to_str().unwrap());
        let e = claim_output(a.to_str().unwrap()).unwrap_err().to_string();
        assert!(e.contains("the same file as the input"), "{e}");
        let b = d.path().join("written.csv");
        claim_output(b.to_str().unwrap()).unwrap();
        let e = claim_output(b.to_str().unwrap()).unwrap_err().to_string();
        assert!(e.contains("the same file as the output"), "{e}");
    }
}
