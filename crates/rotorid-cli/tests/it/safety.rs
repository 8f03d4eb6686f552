//! `rotorid` never destroys what the user points at and never takes unbounded resources,
//! tried as a careless and as a hostile user would, through the real binary:
//!
//! - outputs: a device node, a FIFO and a symbolic link named as the output are written
//!   in place or followed, never replaced; a full device, a full disk, a closed stdout
//!   are errors naming the output; after an error the output holds whole rows or nothing;
//!   SIGINT and SIGTERM leave no temporary file;
//! - same files: an output that is an input, or another output, is refused;
//! - inputs: an endless line is refused in bounded memory, messages quote short prefixes,
//!   line numbers are exact for LF, CRLF and CR files, huge numbers are printed readably;
//! - resources: `plot` of two million rows in bounded memory, a small SVG; progress lines
//!   on a non-terminal stderr for a slow simulation.
//!
//! Device nodes, FIFOs and links are made in temporary directories, never in /dev; the
//! full disk is a 64 KiB tmpfs (skipped with a note where mounting is not permitted).

use std::ffi::CString;
use std::io::{Read, Write};
use std::os::unix::ffi::OsStrExt;
use std::os::unix::fs::FileTypeExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::{data, rotorid, simulate};

fn bin() -> PathBuf {
    assert_cmd::cargo::cargo_bin("rotorid")
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// A character device `major,minor` at `path` (1,3: null; 1,5: zero; 1,7: full), or
/// `None` (with a note) where this process may not make one.
fn char_device(path: &Path, major: u32, minor: u32) -> Option<()> {
    let c = CString::new(path.as_os_str().as_bytes()).unwrap();
    // SAFETY: mknod on a path we own, in a temporary directory.
    let r = unsafe {
        libc::mknod(
            c.as_ptr(),
            libc::S_IFCHR | 0o666,
            libc::makedev(major, minor),
        )
    };
    if r != 0 {
        eprintln!(
            "note: cannot make a device node ({}): skipping this case",
            std::io::Error::last_os_error()
        );
        return None;
    }
    Some(())
}

fn fifo(path: &Path) {
    let c = CString::new(path.as_os_str().as_bytes()).unwrap();
    // SAFETY: mkfifo on a path we own.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
}

fn is_char_device(path: &Path) -> bool {
    std::fs::symlink_metadata(path)
        .unwrap()
        .file_type()
        .is_char_device()
}

fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// The result of a run measured by `wait4`.
struct Measured {
    ok: bool,
    signal: Option<i32>,
    stdout: Vec<u8>,
    stderr: String,
    /// Peak resident set (KiB).
    peak_kib: i64,
}

/// Run `cmd` to its end, collecting its output and its peak resident set. The peak is
/// `ru_maxrss` of `wait4`, taken by a small Python parent that forks and execs `cmd`:
/// measured from this (large, multi-test) process directly, the child's figure would
/// start from this process's own high-water mark, which Linux records at exec.
fn measured(cmd: &mut Command) -> Measured {
    const PARENT: &str = "import os, sys\n\
pid = os.fork()\n\
if pid == 0:\n    os.execv(sys.argv[1], sys.argv[1:])\n\
_, status, ru = os.wait4(pid, 0)\n\
sys.stderr.write('\\nPEAK_KIB %d\\n' % ru.ru_maxrss)\n\
sys.stderr.flush()\n\
os._exit(128 + os.WTERMSIG(status) if os.WIFSIGNALED(status) else os.WEXITSTATUS(status))\n";
    let mut wrapped = Command::new("python3");
    wrapped
        .arg("-c")
        .arg(PARENT)
        .arg(cmd.get_program())
        .args(cmd.get_args());
    for (k, v) in cmd.get_envs() {
        match v {
            Some(v) => wrapped.env(k, v),
            None => wrapped.env_remove(k),
        };
    }
    if let Some(d) = cmd.get_current_dir() {
        wrapped.current_dir(d);
    }
    let out = wrapped.stdin(Stdio::null()).output().unwrap();
    let mut stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    let peak_kib = match stderr.rfind("\nPEAK_KIB ") {
        Some(i) => {
            let v = stderr[i + 10..].trim().parse().unwrap();
            stderr.truncate(i);
            v
        }
        None => panic!("no peak reported: {stderr}"),
    };
    assert!(!stderr.contains("panicked"), "panic: {stderr}");
    let code = out.status.code().unwrap_or(-1);
    Measured {
        ok: code == 0,
        signal: (code > 128).then_some(code - 128),
        stdout: out.stdout,
        stderr,
        peak_kib,
    }
}

/// Wait for `pid`: its raw status and peak RSS (KiB).
fn wait4(pid: u32) -> (i32, i64) {
    let mut status = 0;
    // SAFETY: wait4 on our own child, into locals.
    let peak = unsafe {
        let mut ru: libc::rusage = std::mem::zeroed();
        assert_eq!(libc::wait4(pid as i32, &mut status, 0, &mut ru), pid as i32);
        ru.ru_maxrss
    };
    (status, peak)
}

/// A 64 KiB tmpfs mounted on a temporary directory, unmounted on drop.
struct SmallDisk {
    dir: tempfile::TempDir,
}

impl SmallDisk {
    fn mount() -> Option<Self> {
        let dir = tempfile::tempdir().unwrap();
        let ok = Command::new("mount")
            .args(["-t", "tmpfs", "-o", "size=64k", "tmpfs", s(dir.path())])
            .stderr(Stdio::null())
            .status()
            .is_ok_and(|st| st.success());
        if !ok {
            eprintln!("note: cannot mount a small tmpfs here: skipping the full-disk case");
            return None;
        }
        Some(Self { dir })
    }

    fn path(&self) -> &Path {
        self.dir.path()
    }
}

impl Drop for SmallDisk {
    fn drop(&mut self) {
        let _ = Command::new("umount").arg(self.dir.path()).status();
    }
}

/// A response CSV of `duration` seconds of table1 in `dir`.
fn response(dir: &Path, duration: &str) -> PathBuf {
    let p = dir.join("in.csv");
    std::fs::write(
        &p,
        simulate(&["--scenario", "table1", "--duration", duration]),
    )
    .unwrap();
    p
}

fn stderr_of(out: &std::process::Output) -> String {
    let e = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!e.contains("panicked"), "panic: {e}");
    e
}

// ---------------------------------------------------------------- special files

#[test]
fn device_nodes_are_written_in_place_never_replaced() {
    let dir = tempfile::tempdir().unwrap();
    let null = dir.path().join("null");
    let full = dir.path().join("full");
    if char_device(&null, 1, 3).is_none() || char_device(&full, 1, 7).is_none() {
        return;
    }
    rotorid()
        .args([
            "simulate",
            "--scenario",
            "table1",
            "--duration",
            "0.01",
            "--out",
        ])
        .arg(&null)
        .assert()
        .success();
    assert!(is_char_device(&null), "the null device was replaced");

    let out = rotorid()
        .args([
            "simulate",
            "--scenario",
            "table1",
            "--duration",
            "0.01",
            "--out",
        ])
        .arg(&full)
        .output()
        .unwrap();
    let err = stderr_of(&out);
    assert!(!out.status.success(), "a full device went unnoticed");
    assert!(
        err.contains(&format!("cannot write {}", full.display()))
            && err.contains("No space left on device"),
        "{err}"
    );
    assert!(is_char_device(&full), "the full device was replaced");

    // identify: the summary on a full device, the estimates on a null device
    let input = response(dir.path(), "0.01");
    let out = rotorid()
        .args(["identify", "--scenario", "table1", "-q", "--out"])
        .arg(&null)
        .arg("--summary")
        .arg(&full)
        .arg(&input)
        .output()
        .unwrap();
    let err = stderr_of(&out);
    assert!(!out.status.success());
    assert!(
        err.contains(&format!("cannot write {}", full.display()))
            && err.contains("No space left on device"),
        "{err}"
    );
    assert!(is_char_device(&full) && is_char_device(&null));
    assert_eq!(names(dir.path()), ["full", "in.csv", "null"]);
}

#[test]
fn a_fifo_gets_the_data_and_stays_a_fifo() {
    let dir = tempfile::tempdir().unwrap();
    let pipe = dir.path().join("pipe");
    fifo(&pipe);
    let reader = {
        let pipe = pipe.clone();
        std::thread::spawn(move || std::fs::read_to_string(pipe).unwrap())
    };
    rotorid()
        .args([
            "simulate",
            "--scenario",
            "table1",
            "--duration",
            "0.01",
            "--out",
        ])
        .arg(&pipe)
        .assert()
        .success();
    let got = reader.join().unwrap();
    assert!(
        got.starts_with("t,x,z,phi,phi_dot,phi_ddot\n0,"),
        "{got:.80}"
    );
    assert_eq!(got.lines().count(), 1 + 101);
    assert!(std::fs::symlink_metadata(&pipe)
        .unwrap()
        .file_type()
        .is_fifo());
}

#[test]
fn a_symlink_is_followed_and_kept() {
    let dir = tempfile::tempdir().unwrap();
    let real = dir.path().join("real.csv");
    let link = dir.path().join("link.csv");
    std::fs::write(&real, "old\n").unwrap();
    std::os::unix::fs::symlink("real.csv", &link).unwrap();
    rotorid()
        .args([
            "simulate",
            "--scenario",
            "table1",
            "--duration",
            "0.01",
            "--out",
        ])
        .arg(&link)
        .assert()
        .success();
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    let text = std::fs::read_to_string(&real).unwrap();
    assert_eq!(text.lines().count(), 1 + 101);
    assert_eq!(names(dir.path()), ["link.csv", "real.csv"]);

    // the summary through a link as well
    let input = response(dir.path(), "0.01");
    let sum_real = dir.path().join("s.json");
    let sum_link = dir.path().join("s-link.json");
    std::fs::write(&sum_real, "{}").unwrap();
    std::os::unix::fs::symlink("s.json", &sum_link).unwrap();
    rotorid()
        .args(["identify", "--scenario", "table1", "-q", "--out"])
        .arg(dir.path().join("e.csv"))
        .arg("--summary")
        .arg(&sum_link)
        .arg(&input)
        .assert()
        .success();
    assert!(std::fs::symlink_metadata(&sum_link)
        .unwrap()
        .file_type()
        .is_symlink());
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&sum_real).unwrap()).unwrap();
    assert_eq!(json["method"], "algebraic");
}

// ---------------------------------------------------------------- same files

#[test]
fn simulate_refuses_to_overwrite_its_scenario() {
    let dir = tempfile::tempdir().unwrap();
    let scenario = dir.path().join("s.toml");
    std::fs::copy(data("table1.toml"), &scenario).unwrap();
    let before = std::fs::read(&scenario).unwrap();
    let link = dir.path().join("alias.toml");
    std::fs::hard_link(&scenario, &link).unwrap();
    for out in [&scenario, &link] {
        let o = rotorid()
            .args(["simulate", "--scenario"])
            .arg(&scenario)
            .arg("--out")
            .arg(out)
            .output()
            .unwrap();
        let err = stderr_of(&o);
        assert!(!o.status.success());
        assert!(
            err.contains("is the same file as --scenario") && err.contains("choose another --out"),
            "{err}"
        );
        assert_eq!(std::fs::read(&scenario).unwrap(), before);
    }
}

#[test]
fn identify_never_writes_over_its_input() {
    let dir = tempfile::tempdir().unwrap();
    let input = response(dir.path(), "0.01");
    let before = std::fs::read(&input).unwrap();
    // --out equal to the input (refused when the output is created, before it is touched)
    let o = rotorid()
        .args(["identify", "--scenario", "table1", "-q", "--out"])
        .arg(&input)
        .arg(&input)
        .output()
        .unwrap();
    let err = stderr_of(&o);
    assert!(!o.status.success());
    assert!(err.contains("same file as the input"), "{err}");
    assert!(!err.contains("empty"), "{err}");
    assert_eq!(std::fs::read(&input).unwrap(), before);
    // --summary equal to the input
    let o = rotorid()
        .args(["identify", "--scenario", "table1", "-q", "--out"])
        .arg(dir.path().join("e.csv"))
        .arg("--summary")
        .arg(&input)
        .arg(&input)
        .output()
        .unwrap();
    assert!(!o.status.success(), "{}", stderr_of(&o));
    assert_eq!(std::fs::read(&input).unwrap(), before);
    // --summary equal to --out: the estimates survive
    let est = dir.path().join("same.csv");
    let o = rotorid()
        .args(["identify", "--scenario", "table1", "-q", "--out"])
        .arg(&est)
        .arg("--summary")
        .arg(&est)
        .arg(&input)
        .output()
        .unwrap();
    let err = stderr_of(&o);
    assert!(!o.status.success());
    assert!(err.contains("same file"), "{err}");
    if let Ok(text) = std::fs::read_to_string(&est) {
        assert!(
            text.starts_with("t,m_x,"),
            "the estimates were replaced: {text:.80}"
        );
    }
    // stdout appended to the input
    let o = Command::new("sh")
        .arg("-c")
        .arg(format!(
            "exec '{}' identify '{}' --scenario table1 -q --out - >> '{}'",
            bin().display(),
            input.display(),
            input.display()
        ))
        .output()
        .unwrap();
    let err = stderr_of(&o);
    assert!(!o.status.success());
    assert!(err.contains("same file as the input"), "{err}");
    assert_eq!(std::fs::read(&input).unwrap(), before);
}

/// With `check_distinct_files` called by `identify` before it opens anything: nothing
/// at all is written, not even the estimates.
#[test]
fn identify_refuses_clashing_files_before_writing_anything() {
    let dir = tempfile::tempdir().unwrap();
    let input = response(dir.path(), "0.01");
    let est = dir.path().join("e.csv");
    let o = rotorid()
        .args(["identify", "--scenario", "table1", "-q", "--out"])
        .arg(&est)
        .arg("--summary")
        .arg(&est)
        .arg(&input)
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(stderr_of(&o).contains("--out"));
    assert!(!est.exists());
    let o = rotorid()
        .args([
            "identify",
            "--scenario",
            "table1",
            "-q",
            "--out",
            "-",
            "--summary",
            "-",
        ])
        .arg(&input)
        .output()
        .unwrap();
    let err = stderr_of(&o);
    assert!(!o.status.success());
    assert!(
        err.contains("--out - and --summary - would all write to stdout"),
        "{err}"
    );
    assert!(o.stdout.is_empty(), "wrote before refusing");
}

#[test]
fn out_and_summary_on_stdout_never_mix() {
    let dir = tempfile::tempdir().unwrap();
    let input = response(dir.path(), "0.01");
    let o = rotorid()
        .args([
            "identify",
            "--scenario",
            "table1",
            "-q",
            "--out",
            "-",
            "--summary",
            "-",
        ])
        .arg(&input)
        .output()
        .unwrap();
    let err = stderr_of(&o);
    assert!(!o.status.success());
    assert!(err.contains("stdout"), "{err}");
    let out = String::from_utf8_lossy(&o.stdout);
    assert!(!out.contains('{'), "JSON after the CSV: {out}");
}

#[test]
fn plot_refuses_to_draw_over_its_input() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("r.svg"); // a CSV named like an image
    std::fs::write(&input, "t,x,z\n0,0,0\n0.1,1e-7,2e-7\n").unwrap();
    let o = rotorid()
        .arg("plot")
        .arg(&input)
        .arg("--out")
        .arg(&input)
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(stderr_of(&o).contains("same file as the input"));
    assert_eq!(
        std::fs::read_to_string(&input).unwrap(),
        "t,x,z\n0,0,0\n0.1,1e-7,2e-7\n"
    );
}

// ---------------------------------------------------------------- stdout

#[test]
fn a_closed_or_full_stdout_is_an_error_and_a_stopped_reader_is_not() {
    let run = |redirect: &str| {
        Command::new("sh")
            .arg("-c")
            .arg(format!(
                "exec '{}' simulate --scenario table1 --duration 0.01 --out - {redirect}",
                bin().display()
            ))
            .output()
            .unwrap()
    };
    let o = run(">&-");
    let err = stderr_of(&o);
    assert!(!o.status.success(), "a closed stdout went unnoticed");
    assert!(err.contains("stdout: it is closed"), "{err}");

    let dir = tempfile::tempdir().unwrap();
    let full = dir.path().join("full");
    if char_device(&full, 1, 7).is_some() {
        let o = run(&format!("> '{}'", full.display()));
        let err = stderr_of(&o);
        assert!(!o.status.success());
        assert!(
            err.contains("cannot write to stdout") && err.contains("No space left"),
            "{err}"
        );
    }
    let null = dir.path().join("null");
    if char_device(&null, 1, 3).is_some() {
        let o = run(&format!("> '{}'", null.display()));
        assert!(o.status.success(), "{}", stderr_of(&o));
    }

    // `| head`: the reader stops, we stop quietly
    let mut child = Command::new(bin())
        .args([
            "simulate",
            "--scenario",
            "table1",
            "--duration",
            "5",
            "--out",
            "-",
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut first = [0u8; 100];
    child
        .stdout
        .as_mut()
        .unwrap()
        .read_exact(&mut first)
        .unwrap();
    drop(child.stdout.take());
    let o = child.wait_with_output().unwrap();
    assert!(o.status.success(), "{}", stderr_of(&o));
    assert!(stderr_of(&o).is_empty());
}

// ---------------------------------------------------------------- full disk

#[test]
fn a_full_disk_leaves_whole_rows_or_nothing_and_names_the_output() {
    let dir = tempfile::tempdir().unwrap();
    let input = response(dir.path(), "0.2"); // 2001 estimates, ~300 KB
    let Some(disk) = SmallDisk::mount() else {
        return;
    };
    let est = disk.path().join("e.csv");
    let o = rotorid()
        .args(["identify", "--scenario", "table1", "-q", "--out"])
        .arg(&est)
        .arg(&input)
        .output()
        .unwrap();
    let err = stderr_of(&o);
    assert!(!o.status.success(), "a full disk went unnoticed");
    assert!(err.contains("No space left on device"), "{err}");
    assert!(err.contains(&est.display().to_string()), "{err}");
    assert!(
        !err.contains(&input.display().to_string()),
        "the error blames the input: {err}"
    );
    let text = std::fs::read_to_string(&est).unwrap();
    assert!(text.is_empty() || text.ends_with('\n'), "a truncated row");
    for (i, line) in text.lines().enumerate() {
        assert_eq!(line.split(',').count(), 10, "row {i} is cut: {line}");
    }
    std::fs::remove_file(&est).unwrap();

    // simulate: atomic, so nothing at all
    let out = disk.path().join("r.csv");
    let o = rotorid()
        .args([
            "simulate",
            "--scenario",
            "table1",
            "--duration",
            "0.2",
            "--out",
        ])
        .arg(&out)
        .output()
        .unwrap();
    let err = stderr_of(&o);
    assert!(!o.status.success());
    assert!(
        err.contains(&format!("cannot write {}", out.display())) && err.contains("No space"),
        "{err}"
    );
    assert!(
        names(disk.path()).is_empty(),
        "left: {:?}",
        names(disk.path())
    );
}

// ---------------------------------------------------------------- signals

/// Whether process `pid` has a file in `dir` open (through /proc/PID/fd: an unnamed
/// O_TMPFILE shows as `DIR/#INODE (deleted)`) with data in it.
fn writing_into(pid: u32, dir: &Path) -> bool {
    let Ok(fds) = std::fs::read_dir(format!("/proc/{pid}/fd")) else {
        return false;
    };
    let dir = dir.canonicalize().unwrap_or_else(|_| dir.to_path_buf());
    fds.flatten().any(|fd| {
        let into = std::fs::read_link(fd.path()).is_ok_and(|t| t.starts_with(&dir));
        into && std::fs::metadata(fd.path()).is_ok_and(|m| m.len() > 0)
    })
}

/// Start a long `simulate` to a file in a fresh directory, send `sig` once it is writing
/// its output, and return the directory's content after it died.
#[expect(
    clippy::zombie_processes,
    reason = "reaped by wait4, which also gives the peak"
)]
fn interrupted(sig: i32, named_temporary: bool) -> (Measured, Vec<String>) {
    let dir = tempfile::tempdir().unwrap();
    let mut cmd = Command::new(bin());
    cmd.args([
        "simulate",
        "--scenario",
        "table1",
        "--duration",
        "2000",
        "--out",
    ])
    .arg(dir.path().join("r.csv"));
    if named_temporary {
        cmd.env("ROTORID_NO_TMPFILE", "1");
    }
    // The child starts with the default actions, as from a terminal: a test run started
    // in the background by a shell inherits SIGINT ignored, and simulate rightly keeps an
    // ignored signal ignored.
    // SAFETY: only async-signal-safe calls between fork and exec.
    unsafe {
        std::os::unix::process::CommandExt::pre_exec(&mut cmd, || {
            libc::signal(libc::SIGINT, libc::SIG_DFL);
            libc::signal(libc::SIGTERM, libc::SIG_DFL);
            Ok(())
        });
    }
    let child = cmd
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    // Signal it once it provably holds its temporary output open and has written to it
    // (a file descriptor of the child into the directory, of non-zero size), named or
    // not: a signal before that would leave nothing whatever the code does, and test
    // nothing. The deadline only keeps a broken build from hanging the test.
    let start = Instant::now();
    while !writing_into(child.id(), dir.path()) {
        assert!(
            start.elapsed() < Duration::from_secs(300),
            "the simulation never opened its output"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    if named_temporary {
        assert_eq!(names(dir.path()).len(), 1, "the named temporary is there");
    }
    // SAFETY: a signal to our own child.
    unsafe { libc::kill(child.id() as i32, sig) };
    let (status, peak_kib) = wait4(child.id());
    let m = Measured {
        ok: libc::WIFEXITED(status) && libc::WEXITSTATUS(status) == 0,
        signal: libc::WIFSIGNALED(status).then(|| libc::WTERMSIG(status)),
        stdout: Vec::new(),
        stderr: String::new(),
        peak_kib,
    };
    (m, names(dir.path()))
}

#[test]
fn sigint_and_sigterm_leave_no_temporary_file() {
    for sig in [libc::SIGINT, libc::SIGTERM] {
        for named in [false, true] {
            let (m, left) = interrupted(sig, named);
            assert!(!m.ok);
            assert_eq!(m.signal, Some(sig), "dies of the signal it got");
            assert!(
                left.is_empty(),
                "signal {sig}, named {named}: left {left:?}"
            );
        }
    }
    // SIGKILL cannot be caught: an unnamed temporary has nothing to leave
    let (_, left) = interrupted(libc::SIGKILL, false);
    assert!(left.is_empty(), "SIGKILL left {left:?}");
}

// ---------------------------------------------------------------- inputs

#[test]
fn an_endless_line_is_refused_in_bounded_memory() {
    let dir = tempfile::tempdir().unwrap();
    let zero = dir.path().join("zero");
    if char_device(&zero, 1, 5).is_none() {
        return;
    }
    let png = dir.path().join("p.png").to_str().unwrap().to_owned();
    for args in [
        vec!["identify", s(&zero), "--scenario", "table1", "--out", "-"],
        vec!["plot", s(&zero), "--out", &png],
    ] {
        let m = measured(Command::new(bin()).args(&args));
        assert!(!m.ok, "{args:?}");
        assert!(
            m.stderr
                .contains("line 1: the header line is longer than 1048576 bytes (1 MiB)"),
            "{}",
            m.stderr
        );
        assert!(m.stderr.len() < 1000, "{} bytes of message", m.stderr.len());
        eprintln!(
            "{}: peak RSS {} KiB on an endless line",
            args[0], m.peak_kib
        );
        assert!(m.peak_kib < 128 * 1024, "peak RSS {} KiB", m.peak_kib);
    }

    // a data line that never ends, from a pipe
    let mut child = Command::new(bin())
        .args(["identify", "-", "--scenario", "table1", "--out", "-", "-q"])
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut stdin = child.stdin.take().unwrap();
    let feeder = std::thread::spawn(move || {
        let _ = stdin.write_all(b"t,x,z\n0,0,0\n1e-4,");
        let chunk = vec![b'7'; 1 << 16];
        while stdin.write_all(&chunk).is_ok() {}
    });
    let o = child.wait_with_output().unwrap();
    feeder.join().unwrap();
    let err = stderr_of(&o);
    assert!(
        err.contains("<stdin> line 3: the line is longer than 1048576 bytes"),
        "{err}"
    );
}

#[test]
fn messages_quote_short_prefixes() {
    let dir = tempfile::tempdir().unwrap();
    let wide = dir.path().join("wide.csv");
    let header: Vec<String> = (0..20_000).map(|i| format!("column{i}")).collect();
    std::fs::write(&wide, header.join(",") + "\n").unwrap();
    let bad = dir.path().join("bad.csv");
    std::fs::write(
        &bad,
        format!("t,x,z\n0,0,0\n1e-4,{},0\n", "y".repeat(100_000)),
    )
    .unwrap();
    for (file, needle) in [
        (&wide, "the header lacks columns t, x, z"),
        (&bad, "line 3, column 2 (x): x \"yyyy"),
    ] {
        let o = rotorid()
            .args(["identify", "--scenario", "table1", "--out", "-"])
            .arg(file)
            .output()
            .unwrap();
        let err = stderr_of(&o);
        assert!(!o.status.success());
        assert!(err.contains(needle), "{err:.300}");
        assert!(err.len() < 600, "{} bytes of message", err.len());
    }
}

#[test]
fn line_numbers_are_exact_for_lf_crlf_and_cr_files() {
    let dir = tempfile::tempdir().unwrap();
    let rows = ["t,x,z", "0,0,0", "1e-4,0,0", "", "2e-4,abc,0"];
    for (name, end) in [("lf", "\n"), ("crlf", "\r\n"), ("cr", "\r")] {
        let path = dir.path().join(format!("{name}.csv"));
        std::fs::write(&path, rows.join(end) + end).unwrap();
        for cmd in ["identify", "plot"] {
            let mut c = rotorid();
            c.arg(cmd).arg(&path);
            if cmd == "identify" {
                c.args(["--scenario", "table1", "--out", "-"]);
            } else {
                c.arg("--out").arg(dir.path().join("p.png"));
            }
            let o = c.output().unwrap();
            let err = stderr_of(&o);
            assert!(
                err.contains("line 5, column 2 (x): x \"abc\" is not a number"),
                "{cmd} {name}: {err}"
            );
        }
    }
}

#[test]
fn huge_numbers_in_messages_are_readable() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("r.csv");
    std::fs::write(&input, "t,x,z\n0,0,0\n1e-4,0,0\n").unwrap();
    let o = rotorid()
        .arg("plot")
        .arg(&input)
        .args(["--from", "1e300", "--to", "1e301", "--out"])
        .arg(dir.path().join("p.png"))
        .output()
        .unwrap();
    let err = stderr_of(&o);
    assert!(
        err.contains(
            "no sample in the window 1.0e300 s to 1.0e301 s: the file spans 0 s to 0.0001 s"
        ),
        "{err}"
    );
    assert!(!err.contains("000000000000"), "{err}");
}

// ---------------------------------------------------------------- resources

#[test]
fn plot_of_two_million_rows_stays_small() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("long.csv");
    {
        let mut w = std::io::BufWriter::new(std::fs::File::create(&input).unwrap());
        writeln!(w, "t,x,z").unwrap();
        for i in 0..2_000_001u32 {
            let t = f64::from(i) * 1e-4;
            let a = t * 125.66;
            let r = 2e-7 * (1.0 - (-t).exp());
            writeln!(w, "{t},{:e},{:e}", r * a.cos(), 0.7 * r * a.sin()).unwrap();
        }
    }
    for ext in ["png", "svg"] {
        let out = dir.path().join(format!("long.{ext}"));
        let m = measured(
            Command::new(bin())
                .arg("plot")
                .arg(&input)
                .arg("--out")
                .arg(&out),
        );
        assert!(m.ok, "{}", m.stderr);
        let size = std::fs::metadata(&out).unwrap().len();
        eprintln!(
            "plot {ext} of 2,000,001 rows: peak RSS {} KiB, {size} bytes",
            m.peak_kib
        );
        assert!(m.peak_kib < 150 * 1024, "peak RSS {} KiB", m.peak_kib);
        if ext == "svg" {
            assert!(size < 4 << 20, "SVG of {size} bytes");
        }
    }
}

#[test]
fn a_slow_simulation_reports_progress_without_a_terminal() {
    let dir = tempfile::tempdir().unwrap();
    // "slow" is whatever outlasts the first report's delay: set to 0 s here, so that the
    // test does not depend on the machine's speed (a 1e8 rad/s^2 run-up, once several
    // seconds, took 2.2 s of the default 2 s on a faster machine)
    let m = measured(
        Command::new(bin())
            .env("ROTORID_PROGRESS_AFTER_S", "0")
            .args(["simulate", "--scenario"])
            .arg(data("table1_ramp.toml"))
            .args(["--duration", "0.1", "--out"])
            .arg(dir.path().join("r.csv")),
    );
    assert!(m.ok, "{}", m.stderr);
    let lines: Vec<&str> = m
        .stderr
        .lines()
        .filter(|l| l.starts_with("simulate (exact): ") && l.contains("% ("))
        .collect();
    assert!(!lines.is_empty(), "no progress line: {:?}", m.stderr);
    eprintln!("{}", lines.join("\n"));
    assert!(m.stdout.is_empty());
}

#[test]
fn identify_of_a_csv_file_reports_its_reading_progress_and_not_under_q() {
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("r.csv");
    std::fs::write(&csv, simulate(&["--scenario", "table1", "--duration", "2"])).unwrap();
    let size = std::fs::metadata(&csv).unwrap().len() as f64 / 1e6;
    let run = |quiet: bool, out: &Path| {
        let mut cmd = Command::new(bin());
        // the first report at once, so that the test does not depend on the machine's speed
        cmd.env("ROTORID_PROGRESS_AFTER_S", "0")
            .arg("identify")
            .arg(&csv)
            .args(["--scenario", "table1", "--every", "100", "--out"])
            .arg(out);
        if quiet {
            cmd.arg("-q");
        }
        let out = cmd.output().unwrap();
        (
            out.status.success(),
            out.stdout,
            String::from_utf8(out.stderr).unwrap(),
        )
    };
    let (ok, stdout, stderr) = run(false, &dir.path().join("a.csv"));
    assert!(ok, "{stderr}");
    assert!(stdout.is_empty(), "stdout: {stdout:?}");
    let lines: Vec<&str> = stderr
        .lines()
        .filter(|l| l.starts_with("identify: "))
        .collect();
    assert!(!lines.is_empty(), "no progress line: {stderr}");
    let percents: Vec<u64> = lines
        .iter()
        .map(|l| l["identify: ".len()..l.find('%').unwrap()].parse().unwrap())
        .collect();
    assert!(percents.windows(2).all(|w| w[0] <= w[1]), "{lines:?}");
    assert_eq!(*percents.last().unwrap(), 100, "{lines:?}");
    assert!(
        lines
            .last()
            .unwrap()
            .contains(&format!("({size:.1} of {size:.1} MB read)")),
        "{lines:?}"
    );
    let (ok, _, quiet) = run(true, &dir.path().join("b.csv"));
    assert!(ok, "{quiet}");
    assert!(!quiet.contains("identify: "), "progress under -q: {quiet}");
    // the outputs do not depend on whether progress is shown
    assert_eq!(
        std::fs::read(dir.path().join("a.csv")).unwrap(),
        std::fs::read(dir.path().join("b.csv")).unwrap()
    );
}
