//! `rotorid dashboard`: a live web page of the fleet (crates/rotorid-dashboard,
//! docs/fleet.md "Dashboard").

use std::io::Read as _;
use std::net::SocketAddr;
use std::path::PathBuf;

use anyhow::Context as _;
use rotorid_dashboard::{Config, Dashboard, Settings};
use rotorid_fleet::worker::shutdown_signal;

/// Serve a live web page of the fleet: every machine's identified parameters, trends
/// with uncertainty, alerts, orbits and 1X vectors (read-only; assets in the binary).
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Examples:\n  rotorid dashboard --nats nats://127.0.0.1:4222\n    \
                        then open http://127.0.0.1:8080/\n  rotorid dashboard --nats \
                        nats://127.0.0.1:4222 --listen 0.0.0.0:8080 --token-file \
                        /etc/rotorid/token\n    then open http://HOST:8080/?token=TOKEN once"
)]
pub struct DashboardArgs {
    /// The NATS servers the workers use: a URL, or several separated by commas or given with --nats
    /// again (any servers of a cluster; the first reachable one, in this order, is used,
    /// and the client reconnects to any live server of the cluster).
    #[arg(long, value_name = "URL[,URL...]", required = true)]
    pub nats: Vec<String>,
    /// Address and port to listen on (port 0: any free port, printed). An address other
    /// than loopback needs --token-file.
    #[arg(long, value_name = "ADDR:PORT", default_value = "127.0.0.1:8080")]
    pub listen: SocketAddr,
    /// A file holding the access token (16 to 256 letters, digits or - . _ ~ + / =):
    /// every request must carry it (Authorization: Bearer, or ?token= once, then a
    /// cookie).
    #[arg(long, value_name = "FILE")]
    pub token_file: Option<PathBuf>,
    /// Windows kept per machine for the trends (memory grows with it, about 0.3 kB per
    /// window and machine).
    #[arg(long, value_name = "N", default_value_t = 3600)]
    pub history: usize,
    /// A machine is stale after this many window lengths without a result.
    #[arg(long, value_name = "N", default_value_t = 5.0)]
    pub stale_windows: f64,
    /// Machines shown at most (windows of further machines are ignored).
    #[arg(long, value_name = "N", default_value_t = 1000)]
    pub max_machines: usize,
    /// Raw windows per machine read back at start for the 1X trend (each is a whole
    /// window of samples: 160 kB for 1 s at 10 kHz, two probes).
    #[arg(long, value_name = "N", default_value_t = 60)]
    pub raw_backfill: u64,
}

/// The token in `path`, trimmed of white space at its ends.
fn read_token(path: &PathBuf) -> anyhow::Result<String> {
    let f =
        std::fs::File::open(path).with_context(|| format!("--token-file {}", path.display()))?;
    let mut s = String::new();
    f.take(4096)
        .read_to_string(&mut s)
        .with_context(|| format!("--token-file {}", path.display()))?;
    let t = s.trim().to_owned();
    rotorid_dashboard::check_token(&t)
        .with_context(|| format!("--token-file {}", path.display()))?;
    Ok(t)
}

/// Run `rotorid dashboard`.
pub fn run(args: DashboardArgs) -> anyhow::Result<()> {
    let servers = rotorid_fleet::nats::join_servers(&args.nats)
        .map_err(|e| anyhow::anyhow!("--nats: {e}"))?;
    let token = args.token_file.as_ref().map(read_token).transpose()?;
    let config = Config {
        nats: servers.clone(),
        listen: args.listen,
        token,
        settings: Settings {
            history: args.history,
            stale_windows: args.stale_windows,
            max_machines: args.max_machines,
            ..Settings::default()
        },
        raw_backfill: args.raw_backfill,
    };
    let rt = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()?;
    rt.block_on(async {
        let d = Dashboard::bind(config).await?;
        let addr = d.addr();
        let how = if args.token_file.is_some() {
            " (open it once with ?token=TOKEN)"
        } else {
            ""
        };
        outln!("rotorid dashboard: http://{addr}/ reading {servers}{how}")?;
        d.run(shutdown_signal()).await?;
        anyhow::Ok(())
    })
}
