//! `rotorid --version`, `rotorid completions SHELL` and `rotorid manpages --out DIR`,
//! checked by the tools that consume them: git for the commit, bash itself for the
//! completion script (syntax, and what it completes), the command's own `--help` for the
//! list of pages, and groff for the pages' roff.

use std::process::Command;

use crate::common::rotorid;

/// The commands `rotorid --help` lists (without `help`).
fn commands_in_help() -> Vec<String> {
    let out = rotorid().arg("--help").output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    text.lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .filter_map(|l| l.split_whitespace().next().map(str::to_owned))
        .filter(|c| c != "help")
        .collect()
}

/// The abbreviated commit `rotorid --version` names is HEAD or one of its ancestors (a
/// commit made while the tests run leaves the binary one behind), or `unknown commit`
/// when the source is not a git checkout.
#[test]
fn version_names_the_commit_it_was_built_from() {
    let out = rotorid().arg("--version").output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    let prefix = format!("rotorid {} (", env!("CARGO_PKG_VERSION"));
    let commit = text
        .strip_prefix(&prefix)
        .and_then(|r| r.strip_suffix(")\n"))
        .unwrap_or_else(|| panic!("--version printed {text:?}"));
    let git = |args: &[&str]| {
        Command::new("git")
            .args(args)
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .output()
            .ok()
    };
    let in_git = git(&["rev-parse", "HEAD"]).is_some_and(|o| o.status.success());
    if !in_git {
        assert_eq!(commit, "unknown commit");
        return;
    }
    assert_eq!(commit.len(), 7, "{commit:?}");
    assert!(commit.bytes().all(|b| b.is_ascii_hexdigit()), "{commit:?}");
    let ancestor = git(&["merge-base", "--is-ancestor", commit, "HEAD"]).unwrap();
    assert!(
        ancestor.status.success(),
        "{commit} is not HEAD or an ancestor of it"
    );
}

/// Runs `script` in bash with rotorid's completions sourced; its stdout.
fn bash_with_completions(script: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("rotorid.bash");
    let out = rotorid().args(["completions", "bash"]).output().unwrap();
    assert!(out.status.success());
    std::fs::write(&path, &out.stdout).unwrap();
    let check = Command::new("bash").arg("-n").arg(&path).output().unwrap();
    assert!(
        check.status.success(),
        "bash -n: {}",
        String::from_utf8_lossy(&check.stderr)
    );
    let run = Command::new("bash")
        .arg("-c")
        .arg(format!("source {}; {script}", path.display()))
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    String::from_utf8(run.stdout).unwrap()
}

#[test]
fn bash_completes_commands_options_and_values() {
    // what bash's completion machinery does on TAB: COMP_WORDS, COMP_CWORD, then the
    // function with (command, word being completed, previous word)
    let complete = |words: &[&str]| {
        let cword = words.len() - 1;
        let prev = if cword > 0 { words[cword - 1] } else { "" };
        bash_with_completions(&format!(
            "COMP_WORDS=({}); COMP_CWORD={cword}; _rotorid rotorid '{}' '{prev}'; \
             printf '%s\\n' \"${{COMPREPLY[@]}}\"",
            words
                .iter()
                .map(|w| format!("'{w}'"))
                .collect::<Vec<_>>()
                .join(" "),
            words[cword],
        ))
    };
    assert_eq!(complete(&["rotorid", "ide"]), "identify\n");
    assert_eq!(complete(&["rotorid", "tra"]), "transient\n");
    assert_eq!(complete(&["rotorid", "identify", "--meth"]), "--method\n");
    let shells = complete(&["rotorid", "completions", ""]);
    for shell in ["bash", "zsh", "fish", "powershell", "elvish"] {
        assert!(shells.lines().any(|l| l == shell), "{shell} in {shells:?}");
    }
    // every command rotorid --help lists is offered after `rotorid `
    let all = complete(&["rotorid", ""]);
    for c in commands_in_help() {
        assert!(all.lines().any(|l| l == c), "{c} in {all:?}");
    }
}

#[test]
fn every_shell_gets_a_script_naming_the_commands() {
    for shell in ["zsh", "fish", "powershell", "elvish"] {
        let out = rotorid().args(["completions", shell]).output().unwrap();
        assert!(out.status.success(), "{shell}");
        let text = String::from_utf8(out.stdout).unwrap();
        for c in ["identify", "transient", "balance", "--scenario"] {
            assert!(text.contains(c), "{shell}: {c}");
        }
    }
}

#[test]
fn an_unknown_shell_is_refused_with_the_shells_there_are() {
    let out = rotorid().args(["completions", "nushell"]).output().unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(err.contains("invalid value 'nushell'"), "{err}");
    assert!(
        err.contains("possible values: bash, elvish, fish, powershell, zsh"),
        "{err}"
    );
}

#[test]
fn one_manual_page_per_command_that_groff_reads_cleanly() {
    let dir = tempfile::tempdir().unwrap();
    let out_dir = dir.path().join("man1");
    let out = rotorid()
        .args(["manpages", "--out"])
        .arg(&out_dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let listed: Vec<String> = String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(str::to_owned)
        .collect();
    let mut want = vec!["rotorid.1".to_owned()];
    want.extend(commands_in_help().iter().map(|c| format!("rotorid-{c}.1")));
    want.extend([
        "rotorid-fleet-status.1".into(),
        "rotorid-fleet-replicas.1".into(),
    ]);
    want.sort();
    let mut on_disk: Vec<String> = std::fs::read_dir(&out_dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .collect();
    on_disk.sort();
    assert_eq!(on_disk, want);
    let mut listed_names: Vec<String> = listed
        .iter()
        .map(|p| {
            std::path::Path::new(p)
                .file_name()
                .unwrap()
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    listed_names.sort();
    assert_eq!(listed_names, want, "stdout lists the pages written");
    let identify = std::fs::read_to_string(out_dir.join("rotorid-identify.1")).unwrap();
    let version = format!("rotorid {}", env!("CARGO_PKG_VERSION"));
    assert!(
        identify
            .lines()
            .any(|l| l.starts_with(".TH rotorid-identify 1") && l.contains(&version)),
        "{identify}"
    );
    assert!(
        identify.contains("\\-\\-scenario"),
        "its options are on the page"
    );
    let groff = Command::new("groff").arg("--version").output();
    if groff.map(|o| o.status.success()).unwrap_or(false) {
        for name in &want {
            let check = Command::new("groff")
                .args(["-man", "-Tutf8", "-ww", "-z"])
                .arg(out_dir.join(name))
                .output()
                .unwrap();
            assert!(check.status.success(), "{name}");
            assert!(
                check.stderr.is_empty(),
                "{name}: {}",
                String::from_utf8_lossy(&check.stderr)
            );
        }
    } else {
        eprintln!("groff not installed: the pages' roff is not checked by groff");
    }
}

#[test]
fn manual_pages_into_an_unusable_place_say_where_and_which_option() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("a-file");
    std::fs::write(&file, "x").unwrap();
    let out = rotorid()
        .args(["manpages", "--out"])
        .arg(file.join("man1"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(1));
    let err = String::from_utf8(out.stderr).unwrap();
    assert!(
        err.contains("a-file/man1") && err.contains("--out"),
        "{err}"
    );
}
