//! `rotorid manpages --out DIR`: the manual pages in roff (section 1, clap_mangen):
//! `rotorid.1` and one page per command and sub-command (`rotorid-identify.1`,
//! `rotorid-fleet-status.1`, ...), written into DIR and listed on stdout.

use anyhow::Context as _;

/// Arguments of `rotorid manpages`.
#[derive(Debug, clap::Args)]
pub struct ManpagesArgs {
    /// The directory to write the pages into (created if missing). Read one with
    /// `man -l DIR/rotorid-identify.1`, or put DIR under a MANPATH directory as man1.
    #[arg(long, value_name = "DIR")]
    pub out: std::path::PathBuf,
}

/// Write the pages of `cmd` (the whole `rotorid` command) into `args.out`.
pub fn run(args: ManpagesArgs, cmd: clap::Command) -> anyhow::Result<()> {
    let dir = &args.out;
    std::fs::create_dir_all(dir)
        .with_context(|| format!("cannot create the directory {} (--out)", dir.display()))?;
    let mut cmd = cmd.disable_help_subcommand(true);
    cmd.build();
    let source = format!("rotorid {}", cmd.get_version().unwrap_or_default());
    let mut written = Vec::new();
    write_pages(&cmd, &source, dir, &mut written)?;
    written.sort();
    for p in written {
        outln!("{}", p.display())?;
    }
    Ok(())
}

/// The page of `cmd`, then those of its visible sub-commands, into `dir`; `source` (the
/// program and its version) in every page's header.
fn write_pages(
    cmd: &clap::Command,
    source: &str,
    dir: &std::path::Path,
    written: &mut Vec<std::path::PathBuf>,
) -> anyhow::Result<()> {
    for sub in cmd.get_subcommands().filter(|s| !s.is_hide_set()) {
        write_pages(sub, source, dir, written)?;
    }
    let page = clap_mangen::Man::new(cmd.clone()).source(source);
    let path = dir.join(page.get_filename());
    let mut roff = Vec::new();
    page.render(&mut roff)
        .with_context(|| format!("cannot render the manual page {}", path.display()))?;
    std::fs::write(&path, roff).with_context(|| format!("cannot write {}", path.display()))?;
    written.push(path);
    Ok(())
}
