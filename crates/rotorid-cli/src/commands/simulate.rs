//! `rotorid simulate` (not yet implemented).

/// Arguments of `rotorid simulate`.
#[derive(Debug, clap::Args)]
pub struct SimulateArgs {}

/// Run `rotorid simulate`.
pub fn run(_args: SimulateArgs) -> anyhow::Result<()> {
    anyhow::bail!("`rotorid simulate` is not implemented yet")
}
