//! `rotorid fleet status`: what the fleet's streams, buckets and workers hold.

use std::time::Duration;

use rotorid_fleet::nats::Fleet;

/// The fleet on a NATS server: machines, windows, latest parameters, alerts.
#[derive(Debug, clap::Args)]
pub struct FleetArgs {
    #[command(subcommand)]
    pub command: FleetCommand,
}

/// `rotorid fleet` subcommands.
#[derive(Debug, clap::Subcommand)]
pub enum FleetCommand {
    /// Machines, windows published, identified, dead-lettered and pending, the latest
    /// parameters with their standard errors (SI units), and the last alert.
    Status {
        /// The NATS server.
        #[arg(long, value_name = "URL")]
        nats: String,
        /// The workers' durable consumer.
        #[arg(long, value_name = "NAME", default_value = rotorid_fleet::DEFAULT_DURABLE)]
        durable: String,
    },
}

/// Run `rotorid fleet ...`.
pub fn run(args: FleetArgs) -> anyhow::Result<()> {
    let FleetCommand::Status { nats, durable } = args.command;
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()?;
    let status = rt.block_on(async {
        let fleet = Fleet::connect(&nats, Duration::from_secs(5)).await?;
        rotorid_fleet::status::status(&fleet, &durable).await
    })?;
    out!("{}", rotorid_fleet::status::render(&status))?;
    Ok(())
}
