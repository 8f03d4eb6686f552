//! `rotorid identify` (not yet implemented).

/// Arguments of `rotorid identify`.
#[derive(Debug, clap::Args)]
pub struct IdentifyArgs {}

/// Run `rotorid identify`.
pub fn run(_args: IdentifyArgs) -> anyhow::Result<()> {
    anyhow::bail!("`rotorid identify` is not implemented yet")
}
