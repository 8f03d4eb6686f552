//! A bare worker for the end-to-end tests and the benchmark (the `rotorid worker` command
//! is the same library call with a full command line):
//!
//! `rotorid-fleet-worker URL DURABLE METHOD SCENARIOS_DIR ACK_WAIT_S`
//!
//! METHOD is `algebraic`, `modulating` or `refine`; SCENARIOS_DIR holds `<ID>.toml`.
//! Exits 0 after SIGINT/SIGTERM, printing `windows=N errors=N alerts=N redelivered=N`.
//! `ROTORID_FLEET_VERBOSE` (set): a line per window taken and done on stderr;
//! `ROTORID_FLEET_HOLD_AFTER=N`: hold the N-th window taken unacknowledged until killed
//! (`WorkerConfig::hold_after`).

use std::time::Duration;

use rotorid::pipeline::Method;
use rotorid_fleet::nats::Fleet;
use rotorid_fleet::worker::{run, shutdown_signal, Scenarios, WorkerConfig};

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    if a.len() != 5 {
        eprintln!("usage: rotorid-fleet-worker URL DURABLE METHOD SCENARIOS_DIR ACK_WAIT_S");
        std::process::exit(2);
    }
    let method = match a[2].as_str() {
        "algebraic" => Method::algebraic(),
        "modulating" => Method::modulating(),
        "refine" => Method::refine(),
        m => {
            eprintln!("unknown method {m} (algebraic, modulating, refine)");
            std::process::exit(2);
        }
    };
    let Ok(ack_wait) = a[4].parse::<f64>() else {
        eprintln!("ACK_WAIT_S = {} is not a number of seconds", a[4]);
        std::process::exit(2);
    };
    let mut cfg = WorkerConfig::new(method, Scenarios::Dir(a[3].clone().into()));
    cfg.durable = a[1].clone();
    cfg.ack_wait = Duration::from_secs_f64(ack_wait);
    cfg.verbose = std::env::var_os("ROTORID_FLEET_VERBOSE").is_some();
    if let Some(v) = std::env::var_os("ROTORID_FLEET_HOLD_AFTER") {
        match v.to_str().and_then(|v| v.parse::<u64>().ok()) {
            Some(n) if n >= 1 => cfg.hold_after = Some(n),
            _ => {
                eprintln!("ROTORID_FLEET_HOLD_AFTER = {v:?} is not a count of windows >= 1");
                std::process::exit(2);
            }
        }
    }
    let rt = match tokio::runtime::Builder::new_multi_thread()
        .worker_threads(1)
        .enable_all()
        .build()
    {
        Ok(rt) => rt,
        Err(e) => {
            eprintln!("cannot start the runtime: {e}");
            std::process::exit(1);
        }
    };
    let r = rt.block_on(async {
        let fleet = Fleet::connect(&a[0], Duration::from_secs(10)).await?;
        run(&fleet, &cfg, shutdown_signal()).await
    });
    match r {
        Ok(s) => println!(
            "windows={} errors={} alerts={} redelivered={}",
            s.windows, s.errors, s.alerts, s.redelivered
        ),
        Err(e) => {
            eprintln!("Error: {e}");
            std::process::exit(1);
        }
    }
}
