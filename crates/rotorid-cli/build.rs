//! Sets `ROTORID_COMMIT` for `rotorid --version`: the abbreviated commit of the checkout
//! being built (`git rev-parse --short=7 HEAD`), or `unknown commit` when the source is not
//! a git checkout or git is missing. Re-runs when HEAD or the branch it names moves.

use std::path::PathBuf;
use std::process::Command;

fn git(args: &[&str]) -> Option<String> {
    let out = Command::new("git").args(args).output().ok()?;
    if !out.status.success() {
        return None;
    }
    let s = String::from_utf8(out.stdout).ok()?.trim().to_owned();
    (!s.is_empty()).then_some(s)
}

fn main() {
    let commit = git(&["rev-parse", "--short=7", "HEAD"]);
    if let Some(dir) = git(&["rev-parse", "--git-dir"]).map(PathBuf::from) {
        // only files that exist: cargo re-runs a build script whose watched file is missing
        // on every build (a fresh clone has no packed-refs, a packed branch no ref file)
        let mut watch = vec![dir.join("HEAD"), dir.join("packed-refs")];
        if let Some(head) = git(&["symbolic-ref", "-q", "HEAD"]) {
            watch.push(dir.join(head));
        }
        for f in watch.iter().filter(|f| f.is_file()) {
            println!("cargo:rerun-if-changed={}", f.display());
        }
    }
    println!(
        "cargo:rustc-env=ROTORID_COMMIT={}",
        commit.as_deref().unwrap_or("unknown commit")
    );
}
