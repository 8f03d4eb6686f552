//! `rotorid publish`: send a recording to NATS JetStream as windows (crates/rotorid-fleet,
//! docs/fleet.md) for `rotorid worker` to identify.

use std::time::Duration;

use anyhow::Context as _;
use rotorid::pipeline::{TimeGrid, DEFAULT_TIME_TOLERANCE};
use rotorid_fleet::nats::Fleet;
use rotorid_fleet::publish::{publish_frames, Rate};
use rotorid_fleet::window::windows;
use rotorid_fleet::Channel;

use crate::io::{open_input, LoadScenario as _, ScenarioSpec};

/// Send a recording to NATS JetStream as windows on rotorid.raw.<ID> (stream ROTORID_RAW).
#[derive(Debug, clap::Args)]
#[command(
    after_help = "Example:\n  rotorid publish rig.csv --nats nats://127.0.0.1:4222 \
                        --machine pump-7 --rate realtime"
)]
pub struct PublishArgs {
    /// The recording: a response CSV t,x,z[,phi,phi_dot,phi_ddot] in SI (s, m, rad, rad/s,
    /// rad/s^2), uniformly sampled.
    pub file: String,
    /// The NATS servers: a URL, or several separated by commas or given with --nats
    /// again (any servers of a cluster; the first reachable one, in this order, is used,
    /// and the client reconnects to any live server of the cluster).
    #[arg(long, value_name = "URL[,URL...]", required = true)]
    pub nats: Vec<String>,
    /// The machine's id: letters, digits, '_' and '-' (one NATS subject token).
    #[arg(long, value_name = "ID")]
    pub machine: String,
    /// A scenario whose [speed] profile gives phi, phi_dot, phi_ddot channels when the
    /// file has none (else the worker's scenario must have one).
    #[arg(long, value_name = "S.toml")]
    pub scenario: Option<String>,
    /// realtime: each window when its last sample would have been measured; max: at once.
    #[arg(long, value_enum, default_value = "max")]
    pub rate: RateArg,
    /// Window length [s].
    #[arg(long, value_name = "S", default_value_t = 1.0)]
    pub window_s: f64,
    /// Replicas of the streams, buckets and consumers this command creates (1 ..= 5; on a
    /// cluster of N servers, 3 survives the loss of one server). A stream that exists
    /// with fewer is reported, not changed: `rotorid fleet replicas N` changes it.
    #[arg(long, value_name = "N", default_value_t = 1)]
    pub replicas: usize,
    /// Number of the first window (windows are numbered per machine, increasing with
    /// time: continue a machine's numbering for its next recording).
    #[arg(long, value_name = "N", default_value_t = 0)]
    pub first_window: u64,
}

/// `--rate`.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum RateArg {
    /// At the recording's pace.
    Realtime,
    /// As fast as the server acknowledges.
    Max,
}

/// The recording's channels and grid (the CSV glue; a reader of other formats gives the
/// same named SI channels).
fn read_recording(file: &str) -> anyhow::Result<(TimeGrid, Vec<Channel>)> {
    // a response CSV is streamed by its reader; any other format (or a CSV with other
    // column names) is read whole through rotorid-io, units converted to SI
    let cols = if crate::io::tables::is_tabular(file, None) {
        let table = crate::io::tables::read(file)?;
        crate::io::tables::columns(table, None)?
    } else {
        let (name, input) = open_input(file)?;
        rotorid_io::csv::ResponseReader::new(&name, input)?.read_columns()?
    };
    let grid = TimeGrid::fit(&cols.t, DEFAULT_TIME_TOLERANCE)
        .with_context(|| format!("{file}: column t"))?;
    if let Some(note) = grid.rounding_note() {
        eprintln!("note: {file}: {note}");
    }
    let mut channels = vec![("x", "m", cols.x), ("z", "m", cols.z)];
    if let Some([phi, w, wd]) = cols.speed {
        channels.extend([
            ("phi", "rad", phi),
            ("phi_dot", "rad/s", w),
            ("phi_ddot", "rad/s^2", wd),
        ]);
    }
    let channels = channels
        .into_iter()
        .map(|(n, u, data)| Channel {
            name: n.into(),
            unit: u.into(),
            data,
        })
        .collect();
    Ok((grid, channels))
}

/// Run `rotorid publish`.
pub fn run(args: PublishArgs) -> anyhow::Result<()> {
    // the arguments first: a bad id is refused before the recording is read
    rotorid_fleet::frame::check_machine_id(&args.machine)
        .map_err(|e| anyhow::anyhow!("--machine {:?}: {e}", args.machine))?;
    if !(args.window_s.is_finite() && args.window_s > 0.0) {
        anyhow::bail!(
            "--window-s = {} is out of range: must be finite and > 0 (s)",
            args.window_s
        );
    }
    let servers = rotorid_fleet::nats::join_servers(&args.nats)
        .map_err(|e| anyhow::anyhow!("--nats: {e}"))?;
    rotorid_fleet::nats::check_replicas(args.replicas)
        .map_err(|e| anyhow::anyhow!("--replicas: {e}"))?;
    let (grid, mut channels) = read_recording(&args.file)?;
    if channels.len() == 2 {
        if let Some(s) = &args.scenario {
            let spec = ScenarioSpec::load(s)?;
            if let Some(p) = spec.identification()?.speed {
                let n = channels[0].data.len();
                let states: Vec<_> = (0..n).map(|i| p.at(grid.time(i))).collect();
                for (name, unit, f) in [
                    (
                        "phi",
                        "rad",
                        (|s: &rotorid::SpeedState| s.phi) as fn(&_) -> f64,
                    ),
                    ("phi_dot", "rad/s", |s| s.omega),
                    ("phi_ddot", "rad/s^2", |s| s.omega_dot),
                ] {
                    channels.push(Channel {
                        name: name.into(),
                        unit: unit.into(),
                        data: states.iter().map(f).collect(),
                    });
                }
            }
        }
    }
    let n = (args.window_s / grid.dt).round();
    if !(n >= 1.0 && n <= rotorid_fleet::frame::MAX_SAMPLES as f64) {
        anyhow::bail!(
            "--window-s = {} s is {n} samples of {} s: must be 1 ..= {} samples",
            args.window_s,
            grid.dt,
            rotorid_fleet::frame::MAX_SAMPLES
        );
    }
    let frames = windows(
        &args.machine,
        grid.t0,
        grid.dt,
        &channels,
        n as usize,
        args.first_window,
    )?;
    let rate = match args.rate {
        RateArg::Realtime => Rate::Realtime,
        RateArg::Max => Rate::Max,
    };
    let wait_after = test_hook_wait_after()?;
    let rt = tokio::runtime::Builder::new_current_thread()
        .enable_all()
        .build()?;
    let report = rt.block_on(async {
        let fleet = Fleet::connect_reporting(&servers, Duration::from_secs(10), "publish")
            .await?
            .with_replicas(args.replicas)?;
        fleet.raw_stream().await?;
        crate::commands::fleet::report_shortfalls(&fleet, &servers, "publish").await?;
        publish_frames(&fleet, &frames, rate, |f| {
            eprintln!("window {} (t0 = {} s) acknowledged", f.window, f.t0);
            if let Some((after, path)) = &wait_after {
                if f.window == *after {
                    wait_for_file(path);
                }
            }
        })
        .await
    })?;
    eprintln!(
        "{} windows of machine {} on rotorid.raw.{} ({} already stored), {} bytes",
        report.windows, args.machine, args.machine, report.duplicates, report.bytes
    );
    Ok(())
}

/// A hook for the tests that lose a server in the middle of a recording:
/// `ROTORID_PUBLISH_WAIT_AFTER=W:PATH` makes the publisher, once window W is acknowledged,
/// say `waiting for PATH` on stderr and wait until PATH exists before the next window, so
/// that what the test does meanwhile (kill a server) provably lands mid-recording.
fn test_hook_wait_after() -> anyhow::Result<Option<(u64, std::path::PathBuf)>> {
    let Some(v) = std::env::var_os("ROTORID_PUBLISH_WAIT_AFTER") else {
        return Ok(None);
    };
    let parsed = v.to_str().and_then(|v| {
        let (w, p) = v.split_once(':')?;
        Some((w.parse::<u64>().ok()?, std::path::PathBuf::from(p)))
    });
    match parsed {
        Some(p) => Ok(Some(p)),
        None => anyhow::bail!("ROTORID_PUBLISH_WAIT_AFTER = {v:?} is not WINDOW:PATH"),
    }
}

/// Block until `path` exists (the test hook above).
fn wait_for_file(path: &std::path::Path) {
    eprintln!("publish: waiting for {}", path.display());
    while !path.exists() {
        std::thread::sleep(Duration::from_millis(20));
    }
}
