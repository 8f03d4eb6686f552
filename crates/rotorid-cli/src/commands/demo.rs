//! `rotorid demo` (not yet implemented).

/// Arguments of `rotorid demo`.
#[derive(Debug, clap::Args)]
pub struct DemoArgs {}

/// Run `rotorid demo`.
pub fn run(_args: DemoArgs) -> anyhow::Result<()> {
    anyhow::bail!("`rotorid demo` is not implemented yet")
}
