//! `rotorid worker`: identify the windows of every machine published to NATS JetStream
//! (crates/rotorid-fleet, docs/fleet.md); run as many as there are cores to spare.

use std::path::PathBuf;
use std::time::Duration;

use rotorid_fleet::drift::DriftSettings;
use rotorid_fleet::nats::Fleet;
use rotorid_fleet::worker::{run_prepared, shutdown_signal, Scenarios, WorkerConfig};

use crate::commands::identify::{method_of, IdentifyMethod, MethodOptions};

/// Identify the windows on rotorid.raw.> (a durable pull consumer shared by all workers).
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Examples:\n  rotorid worker --nats nats://127.0.0.1:4222 --scenarios \
                        fleet/ --method modulating\n  rotorid worker --nats \
                        nats://127.0.0.1:4222 --scenario rig.toml --method refine \
                        --unknowns m,kx,kz --window 0.05"
)]
pub struct WorkerArgs {
    /// The NATS servers: a URL, or several separated by commas or given with --nats
    /// again (any servers of a cluster; the first reachable one, in this order, is used,
    /// and the client reconnects to any live server of the cluster).
    #[arg(long, value_name = "URL[,URL...]", required = true)]
    pub nats: Vec<String>,
    /// Replicas of the streams, buckets and consumers this command creates (1 ..= 5; on a
    /// cluster of N servers, 3 survives the loss of one server). A stream that exists
    /// with fewer is reported, not changed: `rotorid fleet replicas N` changes it.
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub replicas: usize,
    /// The durable consumer's name: workers with the same name share the windows.
    #[arg(long, value_name = "NAME", default_value = rotorid_fleet::DEFAULT_DURABLE)]
    pub durable: String,
    /// The identification method; its settings are the options below, as in `rotorid
    /// identify` (the algebraic identifier's result is its last estimate).
    #[arg(long, value_enum, default_value = "modulating")]
    pub method: IdentifyMethod,
    #[command(flatten)]
    pub settings: MethodOptions,
    /// One scenario for every machine: `table1` or a TOML file.
    #[arg(
        long,
        value_name = "S.toml",
        conflicts_with = "scenarios",
        required_unless_present = "scenarios"
    )]
    pub scenario: Option<String>,
    /// A directory holding one <ID>.toml per machine.
    #[arg(long, value_name = "DIR")]
    pub scenarios: Option<PathBuf>,
    /// A directory holding <ID>.json (`rotorid identify --summary`): the machine's drift
    /// baseline (else its first --baseline-windows windows).
    #[arg(long, value_name = "DIR")]
    pub baselines: Option<PathBuf>,
    /// Windows 0 .. N-1 of a machine form its drift baseline.
    #[arg(long, value_name = "N", default_value_t = 3)]
    pub baseline_windows: u64,
    /// |z| above which a window counts as changed (an alert needs two consecutive).
    #[arg(long, value_name = "Z", default_value_t = 5.0)]
    pub z_threshold: f64,
    /// Seconds an unacknowledged window waits before another worker gets it (when this
    /// worker creates the consumer).
    #[arg(long, value_name = "S", default_value_t = 30.0)]
    pub ack_wait: f64,
    /// One line per window on stderr.
    #[arg(long, short)]
    pub verbose: bool,
}

/// Run `rotorid worker` until SIGINT or SIGTERM.
pub fn run(args: WorkerArgs) -> anyhow::Result<()> {
    let method = method_of(args.method, &args.settings, None)?;
    let scenarios = match (args.scenario, args.scenarios) {
        (Some(s), _) => Scenarios::One(s),
        (None, Some(d)) => Scenarios::Dir(d),
        (None, None) => anyhow::bail!("give --scenario S.toml or --scenarios DIR"),
    };
    if !(args.ack_wait.is_finite() && args.ack_wait >= 1.0) {
        anyhow::bail!(
            "--ack-wait = {} is out of range: must be finite and >= 1 (s)",
            args.ack_wait
        );
    }
    if args.baseline_windows == 0 || !(args.z_threshold.is_finite() && args.z_threshold > 0.0) {
        anyhow::bail!(
            "--baseline-windows = {} must be >= 1 and --z-threshold = {} finite and > 0",
            args.baseline_windows,
            args.z_threshold
        );
    }
    let servers = rotorid_fleet::nats::join_servers(&args.nats)
        .map_err(|e| anyhow::anyhow!("--nats: {e}"))?;
    rotorid_fleet::nats::check_replicas(args.replicas)
        .map_err(|e| anyhow::anyhow!("--replicas: {e}"))?;
    let mut cfg = WorkerConfig::new(method, scenarios);
    cfg.durable = args.durable;
    cfg.baselines = args.baselines;
    cfg.drift = DriftSettings {
        baseline_windows: args.baseline_windows,
        z_threshold: args.z_threshold,
    };
    cfg.ack_wait = Duration::from_secs_f64(args.ack_wait);
    cfg.verbose = args.verbose;
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .enable_all()
        .build()?;
    let stats = rt.block_on(async {
        let fleet = Fleet::connect_reporting(&servers, Duration::from_secs(10), "worker")
            .await?
            .with_replicas(args.replicas)?;
        let consumer = rotorid_fleet::worker::prepare(&fleet, &cfg).await?;
        crate::commands::fleet::report_shortfalls(&fleet, &servers, "worker").await?;
        eprintln!(
            "worker on {} (consumer {}): waiting for windows",
            fleet.server(),
            cfg.durable
        );
        run_prepared(&fleet, &cfg, consumer, shutdown_signal()).await
    })?;
    eprintln!(
        "worker stopped: {} windows identified, {} dead-lettered, {} alerts",
        stats.windows, stats.errors, stats.alerts
    );
    Ok(())
}
