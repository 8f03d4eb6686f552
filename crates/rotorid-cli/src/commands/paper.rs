//! `rotorid paper` (not yet implemented).

/// Arguments of `rotorid paper`.
#[derive(Debug, clap::Args)]
pub struct PaperArgs {}

/// Run `rotorid paper`.
pub fn run(_args: PaperArgs) -> anyhow::Result<()> {
    anyhow::bail!("`rotorid paper` is not implemented yet")
}
