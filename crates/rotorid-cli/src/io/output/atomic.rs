//! Temporary files for atomic outputs, and their removal when the process is interrupted.
//!
//! A temporary is created in the target's directory (same file system, so the final
//! `rename` is atomic), preferably unnamed (`O_TMPFILE`): it has no name until
//! [`Pending::commit`] links it as `.NAME.tmp-PID-N` and renames that over the target
//! (microseconds), so even SIGKILL leaves nothing behind. Where the file system has no
//! `O_TMPFILE` (or `ROTORID_NO_TMPFILE=1` is set: the tests use it to exercise this path)
//! the temporary is named from the start.
//!
//! Every named temporary is registered with a handler of SIGINT, SIGTERM and SIGHUP
//! (installed on first use, unless the signal is ignored) that unlinks it and then dies of
//! the same signal: an interrupted run leaves no hidden file of up to hundreds of MB.

use std::ffi::{CString, OsString};
use std::fs::{File, OpenOptions};
use std::io;
use std::os::fd::AsRawFd;
use std::os::unix::ffi::OsStrExt;
use std::os::unix::fs::OpenOptionsExt;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicPtr, AtomicU64, Ordering};
use std::sync::Once;

/// A temporary file waiting to replace its target.
pub(super) struct Pending {
    target: PathBuf,
    /// The registered name while the temporary has one (always for the named kind; during
    /// the commit for the unnamed kind).
    name: Option<Registered>,
}

impl Pending {
    /// Create a temporary for `target` in its directory, writable (and readable, for the
    /// copy fallback of [`Self::commit`]), with the permissions of the file it will
    /// replace when there is one.
    pub(super) fn create(target: &Path) -> io::Result<(File, Self)> {
        let named = std::env::var_os("ROTORID_NO_TMPFILE").is_some_and(|v| v == "1");
        let unnamed = if named {
            None
        } else {
            OpenOptions::new()
                .read(true)
                .write(true)
                .mode(0o666)
                .custom_flags(libc::O_TMPFILE)
                .open(directory_of(target))
                .ok()
        };
        match unnamed {
            Some(f) => Ok(Self::with_permissions(f, target, None)),
            None => Self::create_named(target),
        }
    }

    /// A temporary that is named from the start (registered for removal on signals).
    fn create_named(target: &Path) -> io::Result<(File, Self)> {
        let path = temporary_name(target);
        let reg = Registered::new(path.clone());
        let f = OpenOptions::new()
            .read(true)
            .write(true)
            .create_new(true)
            .mode(0o666)
            .open(&path)?;
        Ok(Self::with_permissions(f, target, Some(reg)))
    }

    fn with_permissions(file: File, target: &Path, name: Option<Registered>) -> (File, Self) {
        if let Ok(m) = std::fs::metadata(target) {
            if m.is_file() {
                // a failure here only loses the permissions, not the data
                let _ = file.set_permissions(m.permissions());
            }
        }
        (
            file,
            Self {
                target: target.to_owned(),
                name,
            },
        )
    }

    /// Give the (synced) temporary the target's name: link an unnamed one under a
    /// temporary name first (by `/proc/self/fd`, else `AT_EMPTY_PATH`, else by copying),
    /// then rename over the target and sync the directory.
    pub(super) fn commit(mut self, file: &mut File) -> io::Result<()> {
        let reg = match self.name.take() {
            Some(reg) => reg,
            None => {
                let path = temporary_name(&self.target);
                let reg = Registered::new(path.clone());
                link_unnamed(file, &path).or_else(|_| copy_to_new(file, &path))?;
                reg
            }
        };
        let renamed = std::fs::rename(&reg.path, &self.target);
        if renamed.is_err() {
            let _ = std::fs::remove_file(&reg.path);
        }
        drop(reg);
        renamed?;
        if let Ok(d) = File::open(directory_of(&self.target)) {
            // durability of the rename; not every file system supports it
            let _ = d.sync_all();
        }
        Ok(())
    }
}

impl Drop for Pending {
    fn drop(&mut self) {
        // not committed: remove a named temporary (an unnamed one vanishes with its fd)
        if let Some(reg) = self.name.take() {
            let _ = std::fs::remove_file(&reg.path);
        }
    }
}

/// The target's directory (`.` for a bare file name).
fn directory_of(target: &Path) -> PathBuf {
    match target.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_owned(),
        _ => PathBuf::from("."),
    }
}

/// `.NAME.tmp-PID-N` beside the target.
fn temporary_name(target: &Path) -> PathBuf {
    static N: AtomicU64 = AtomicU64::new(0);
    let mut name = OsString::from(".");
    name.push(target.file_name().unwrap_or_else(|| "output".as_ref()));
    name.push(format!(
        ".tmp-{}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    ));
    target.with_file_name(name)
}

fn c_path(path: &Path) -> io::Result<CString> {
    CString::new(path.as_os_str().as_bytes())
        .map_err(|_| io::Error::new(io::ErrorKind::InvalidInput, "path contains a NUL byte"))
}

/// Link the unnamed file `file` as `path`.
fn link_unnamed(file: &File, path: &Path) -> io::Result<()> {
    let to = c_path(path)?;
    let fd = file.as_raw_fd();
    let proc_path = c_path(Path::new(&format!("/proc/self/fd/{fd}")))?;
    // SAFETY: both paths are valid NUL-terminated strings that outlive the calls.
    let r = unsafe {
        libc::linkat(
            libc::AT_FDCWD,
            proc_path.as_ptr(),
            libc::AT_FDCWD,
            to.as_ptr(),
            libc::AT_SYMLINK_FOLLOW,
        )
    };
    if r == 0 {
        return Ok(());
    }
    // SAFETY: as above; the empty path with AT_EMPTY_PATH names `fd` itself.
    let r = unsafe {
        libc::linkat(
            fd,
            c"".as_ptr(),
            libc::AT_FDCWD,
            to.as_ptr(),
            libc::AT_EMPTY_PATH,
        )
    };
    if r == 0 {
        Ok(())
    } else {
        Err(io::Error::last_os_error())
    }
}

/// Copy the unnamed file `file` into a new file `path` and sync it.
fn copy_to_new(file: &mut File, path: &Path) -> io::Result<()> {
    use std::io::Seek as _;
    file.seek(io::SeekFrom::Start(0))?;
    let mut out = OpenOptions::new()
        .write(true)
        .create_new(true)
        .mode(0o666)
        .open(path)?;
    let copied = io::copy(file, &mut out).and_then(|_| out.sync_all());
    if copied.is_err() {
        let _ = std::fs::remove_file(path);
    }
    copied
}

/// Slots of the named temporaries the signal handler removes.
const SLOTS: usize = 16;
static TEMPORARIES: [AtomicPtr<libc::c_char>; SLOTS] =
    [const { AtomicPtr::new(std::ptr::null_mut()) }; SLOTS];

/// A temporary name registered for removal on SIGINT, SIGTERM and SIGHUP.
struct Registered {
    path: PathBuf,
    slot: Option<usize>,
}

impl Registered {
    fn new(path: PathBuf) -> Self {
        install_handlers();
        let slot = c_path(&path).ok().and_then(|c| {
            let raw = c.into_raw();
            let slot = TEMPORARIES.iter().position(|s| {
                s.compare_exchange(
                    std::ptr::null_mut(),
                    raw,
                    Ordering::SeqCst,
                    Ordering::SeqCst,
                )
                .is_ok()
            });
            if slot.is_none() {
                // SAFETY: `raw` came from `into_raw` above and was not shared.
                drop(unsafe { CString::from_raw(raw) });
            }
            slot
        });
        Self { path, slot }
    }
}

impl Drop for Registered {
    /// Unregister (the name is gone: renamed or removed, or was never created).
    fn drop(&mut self) {
        if let Some(s) = self.slot {
            // The string is leaked, not freed: a handler running on another thread may
            // still be reading it. A few bytes per output file.
            TEMPORARIES[s].swap(std::ptr::null_mut(), Ordering::SeqCst);
        }
    }
}

extern "C" fn remove_temporaries_and_die(sig: libc::c_int) {
    for slot in &TEMPORARIES {
        let p = slot.load(Ordering::SeqCst);
        if !p.is_null() {
            // SAFETY: a registered pointer is a leaked, never freed C string; unlink is
            // async-signal-safe.
            unsafe { libc::unlink(p) };
        }
    }
    // SA_RESETHAND restored the default action: die of the same signal once we return.
    // SAFETY: raise is async-signal-safe.
    unsafe { libc::raise(sig) };
}

fn install_handlers() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        for sig in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
            // SAFETY: sigaction with a zeroed struct is the documented way to query and
            // set a handler; the handler only calls async-signal-safe functions.
            unsafe {
                let mut old: libc::sigaction = std::mem::zeroed();
                if libc::sigaction(sig, std::ptr::null(), &mut old) != 0
                    || old.sa_sigaction == libc::SIG_IGN
                {
                    continue; // keep an ignored signal ignored (nohup, background jobs)
                }
                let mut new: libc::sigaction = std::mem::zeroed();
                new.sa_sigaction = remove_temporaries_and_die as *const () as usize;
                new.sa_flags = libc::SA_RESETHAND | libc::SA_RESTART;
                libc::sigemptyset(&mut new.sa_mask);
                libc::sigaction(sig, &new, std::ptr::null_mut());
            }
        }
    });
}

#[cfg(test)]
mod tests {
    use std::io::Write as _;

    use super::*;

    fn names(d: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn named_temporaries_are_registered_while_they_exist() {
        let d = tempfile::tempdir().unwrap();
        let target = d.path().join("r.csv");
        let registered = || {
            TEMPORARIES
                .iter()
                .filter(|s| !s.load(Ordering::SeqCst).is_null())
                .count()
        };
        let before = registered();
        let (mut f, p) = Pending::create_named(&target).unwrap();
        f.write_all(b"x\n").unwrap();
        assert_eq!(names(d.path()).len(), 1);
        assert!(registered() > before);
        drop(p);
        assert!(names(d.path()).is_empty(), "the temporary stays");
        let (mut f, p) = Pending::create_named(&target).unwrap();
        f.write_all(b"y\n").unwrap();
        p.commit(&mut f).unwrap();
        assert_eq!(names(d.path()), ["r.csv"]);
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "y\n");
    }

    #[test]
    fn unnamed_temporaries_have_no_name_until_committed() {
        let d = tempfile::tempdir().unwrap();
        let target = d.path().join("r.csv");
        let (mut f, p) = Pending::create(&target).unwrap();
        f.write_all(b"z\n").unwrap();
        if p.name.is_none() {
            assert!(names(d.path()).is_empty());
        }
        p.commit(&mut f).unwrap();
        assert_eq!(std::fs::read_to_string(&target).unwrap(), "z\n");
        assert_eq!(names(d.path()), ["r.csv"]);
        // the copy fallback gives the same file
        let (mut f, _p) = Pending::create(&target).unwrap();
        f.write_all(b"copied\n").unwrap();
        let copy = d.path().join("copy.csv");
        copy_to_new(&mut f, &copy).unwrap();
        assert_eq!(std::fs::read_to_string(&copy).unwrap(), "copied\n");
    }
}
