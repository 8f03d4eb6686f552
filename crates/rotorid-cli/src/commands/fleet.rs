//! `rotorid fleet status`: what the fleet's streams, buckets and workers hold;
//! `rotorid fleet replicas N`: the replica count of its streams, buckets and consumers.

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
        /// The NATS servers: a URL, or several separated by commas or given with --nats
        /// again (the first reachable one, in this order, is used).
        #[arg(long, value_name = "URL[,URL...]", required = true)]
        nats: Vec<String>,
        /// The workers' durable consumer.
        #[arg(long, value_name = "NAME", default_value = rotorid_fleet::DEFAULT_DURABLE)]
        durable: String,
    },
    /// Give every stream and bucket of the fleet (ROTORID_RAW, ROTORID_IDENT,
    /// ROTORID_ALERT, ROTORID_LATEST, ROTORID_DRIFT) and the workers' durable consumers N
    /// replicas; JetStream copies the data while the fleet runs. N replicas need a
    /// JetStream cluster of at least N servers.
    #[command(after_help = "Example:\n  rotorid fleet replicas 3 --nats \
                            nats://10.0.0.1:4222,nats://10.0.0.2:4222,nats://10.0.0.3:4222")]
    Replicas {
        /// Replicas, 1 ..= 5.
        #[arg(value_name = "N")]
        replicas: usize,
        /// The NATS servers: a URL, or several separated by commas or given with --nats
        /// again.
        #[arg(long, value_name = "URL[,URL...]", required = true)]
        nats: Vec<String>,
    },
}

/// Say on stderr which of the fleet's streams have fewer replicas than `fleet` creates,
/// and the command that changes them.
pub async fn report_shortfalls(
    fleet: &Fleet,
    servers: &str,
    who: &str,
) -> Result<(), rotorid_fleet::FleetError> {
    for s in fleet.replica_shortfalls().await? {
        eprintln!(
            "{who}: warning: stream {} has {} replica(s), fewer than --replicas {}; it is \
             left as it is: `rotorid fleet replicas {} --nats {servers}` changes it",
            s.stream, s.replicas, s.wanted, s.wanted
        );
    }
    Ok(())
}

/// Run `rotorid fleet ...`.
pub fn run(args: FleetArgs) -> anyhow::Result<()> {
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()?;
    match args.command {
        FleetCommand::Status { nats, durable } => {
            let servers = rotorid_fleet::nats::join_servers(&nats)
                .map_err(|e| anyhow::anyhow!("--nats: {e}"))?;
            let status = rt.block_on(async {
                let fleet = Fleet::connect(&servers, Duration::from_secs(5)).await?;
                rotorid_fleet::status::status(&fleet, &durable).await
            })?;
            out!("{}", rotorid_fleet::status::render(&status))?;
        }
        FleetCommand::Replicas { replicas, nats } => {
            let servers = rotorid_fleet::nats::join_servers(&nats)
                .map_err(|e| anyhow::anyhow!("--nats: {e}"))?;
            rotorid_fleet::nats::check_replicas(replicas).map_err(|e| anyhow::anyhow!("N: {e}"))?;
            let changed = rt.block_on(async {
                let fleet = Fleet::connect(&servers, Duration::from_secs(5)).await?;
                fleet.set_replicas(replicas).await
            })?;
            if changed.is_empty() {
                outln!("every stream of the fleet has {replicas} replica(s) already")?;
            }
            for (stream, before) in changed {
                outln!("stream {stream}: {before} -> {replicas} replica(s)")?;
            }
        }
    }
    Ok(())
}
