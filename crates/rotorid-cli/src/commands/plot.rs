//! `rotorid plot` (not yet implemented).

/// Arguments of `rotorid plot`.
#[derive(Debug, clap::Args)]
pub struct PlotArgs {}

/// Run `rotorid plot`.
pub fn run(_args: PlotArgs) -> anyhow::Result<()> {
    anyhow::bail!("`rotorid plot` is not implemented yet")
}
