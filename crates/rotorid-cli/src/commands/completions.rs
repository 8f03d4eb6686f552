//! `rotorid completions SHELL`: the shell's completion script on stdout (clap_complete),
//! to be sourced or installed where the shell looks for completions (README, "Shell
//! completions and manual pages").

use std::io::Write as _;

/// Arguments of `rotorid completions`.
#[derive(Debug, clap::Args)]
pub struct CompletionsArgs {
    /// The shell: bash, zsh, fish, powershell or elvish. Install, e.g.:
    /// `rotorid completions bash > ~/.local/share/bash-completion/completions/rotorid`,
    /// `rotorid completions zsh > ~/.zfunc/_rotorid` (with ~/.zfunc in fpath),
    /// `rotorid completions fish > ~/.config/fish/completions/rotorid.fish`.
    #[arg(value_name = "SHELL")]
    pub shell: clap_complete::Shell,
}

/// Print the completion script of `cmd` (the whole `rotorid` command) for the shell.
pub fn run(args: CompletionsArgs, mut cmd: clap::Command) -> anyhow::Result<()> {
    let mut script = Vec::new();
    clap_complete::generate(args.shell, &mut cmd, "rotorid", &mut script);
    std::io::stdout()
        .lock()
        .write_all(&script)
        .map_err(crate::io::stdout_error)?;
    Ok(())
}
